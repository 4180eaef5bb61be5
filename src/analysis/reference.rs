//! Converged reference images and the metadata stored beside them.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceInfo {
    pub scene: String,
    pub algorithm: String,
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    pub seconds: f64,
    pub seed: u64,
    pub program_version: String,
}

/// `x.exr` → `x.ron`.
pub fn info_path(image: &Path) -> PathBuf {
    image.with_extension("ron")
}

pub fn save_info(info: &ReferenceInfo, image: &Path) -> std::io::Result<()> {
    let text = ron::ser::to_string_pretty(info, ron::ser::PrettyConfig::new()).map_err(std::io::Error::other)?;
    std::fs::write(info_path(image), text + "\n")
}

pub fn load_info(image: &Path) -> Option<ReferenceInfo> {
    ron::from_str(&std::fs::read_to_string(info_path(image)).ok()?).ok()
}
