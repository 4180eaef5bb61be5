//! GI Studio: global illumination with four light-transport algorithms on one
//! engine. Layers depend one way: geometry → scene → render → analysis →
//! (cli | app).
#![deny(unsafe_code)]

pub mod analysis;
pub mod app;
pub mod cli;
pub mod faults;
pub mod fileio;
pub mod geometry;
pub mod limits;
pub mod render;
pub mod scene;
