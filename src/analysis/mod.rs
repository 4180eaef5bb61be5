//! Analysis: how wrong an image still is (metrics against a reference),
//! references, and convergence logs. Used by the CLI and the studio.

pub mod metrics;
