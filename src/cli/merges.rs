//! Where VCM merges, as the command line names it.

use crate::render::MergeSettings;

/// Where VCM merges (`MergeSettings::caustic_merges`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Merges {
    Caustics,
    Everywhere,
}

impl Merges {
    /// Into `m`.
    pub fn apply(self, m: &mut MergeSettings) {
        m.caustic_merges = self == Merges::Caustics;
    }
}
