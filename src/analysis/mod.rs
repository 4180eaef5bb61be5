//! Analysis: how wrong an image still is (metrics against a reference),
//! references, convergence logs and their plot. Used by the CLI and the studio.

pub mod convergence;
pub mod metrics;
pub mod plot;
pub mod reference;
