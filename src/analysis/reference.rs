//! Converged reference images and the metadata stored beside them, in
//! `<image>.meta.ron` (a name no scene file has, so writing it can never
//! replace the scene the reference was made from).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::fileio::{self, FileError, SIGNATURE};
use crate::limits;

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

/// `x.exr` → `x.exr.meta.ron`.
pub fn info_path(image: &Path) -> PathBuf {
    let mut name = image.file_name().unwrap_or_default().to_owned();
    name.push(".meta.ron");
    image.with_file_name(name)
}

/// The first line of every metadata file: what it is, and whose.
fn header() -> String {
    format!("// {SIGNATURE} reference metadata\n")
}

pub fn save_info(info: &ReferenceInfo, image: &Path) -> Result<(), FileError> {
    let text = ron::ser::to_string_pretty(info, ron::ser::PrettyConfig::new())
        .map_err(|e| FileError::Io { path: info_path(image), cause: std::io::Error::other(e) })?;
    fileio::write_bytes(&info_path(image), (header() + &text + "\n").as_bytes())
}

/// The metadata beside `image`, if it is there and readable.
pub fn load_info(image: &Path) -> Option<ReferenceInfo> {
    ron::from_str(&fileio::read_text(&info_path(image), limits::TEXT_FILE_BYTES).ok()?).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metadata_sits_beside_the_image_under_a_name_no_scene_has() {
        assert_eq!(info_path(Path::new("refs/my.exr")), Path::new("refs/my.exr.meta.ron"));
        let dir = std::env::temp_dir().join(format!("gi-reference-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let image = dir.join("my.exr");
        let info = ReferenceInfo {
            scene: "my.ron".into(),
            algorithm: "path".into(),
            width: 4,
            height: 3,
            samples_per_pixel: 16,
            seconds: 0.5,
            seed: 1,
            program_version: "0".into(),
        };
        save_info(&info, &image).unwrap();
        assert_eq!(load_info(&image), Some(info));
        assert!(fileio::replaceable(&info_path(&image), &[SIGNATURE.as_bytes()]).unwrap());
    }
}
