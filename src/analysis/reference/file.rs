//! A reference on disk: one EXR holding the image (its first layer, what
//! any viewer shows) and each pixel's variance (a layer named `variance`),
//! with its metadata beside it in `<image>.meta.ron` (a name no scene file
//! has, so writing it can never replace the scene it was made from).

use std::path::{Path, PathBuf};

use super::{Reference, ReferenceInfo};
use crate::fileio::{self, FileError, SIGNATURE};
use crate::limits;
use crate::render::layers::encode_layers;
use crate::render::LinearImage;

#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error(transparent)]
    File(#[from] FileError),
    #[error("{path}: not a reference image: {reason}")]
    Decode { path: String, reason: String },
    #[error("{path}: line {line}: {reason}")]
    Info { path: PathBuf, line: usize, reason: String },
    #[error("{path}: could not encode the reference: {reason}")]
    Encode { path: PathBuf, reason: String },
}

/// The name of the variance layer.
const VARIANCE: &str = "variance";

/// `x.exr` → `x.exr.meta.ron`.
pub fn info_path(image: &Path) -> PathBuf {
    crate::fileio::beside(image, ".meta.ron")
}

/// The first line of every metadata file: what it is, and whose.
fn header() -> String {
    format!("// {SIGNATURE} reference metadata\n")
}

impl Reference {
    /// Write the EXR and its metadata (each atomically: a failed save
    /// leaves what was there).
    pub fn save(&self, path: &Path) -> Result<(), ReferenceError> {
        let bytes = self.encode().map_err(|reason| ReferenceError::Encode { path: path.to_owned(), reason })?;
        fileio::write_bytes(path, &bytes)?;
        let text = ron::ser::to_string_pretty(&self.info, ron::ser::PrettyConfig::new())
            .map_err(|e| ReferenceError::Encode { path: info_path(path), reason: e.to_string() })?;
        fileio::write_bytes(&info_path(path), (header() + &text + "\n").as_bytes())?;
        Ok(())
    }

    /// The EXR's bytes: the image, then the variance layer if there is one.
    pub fn encode(&self) -> Result<Vec<u8>, String> {
        let mut layers = vec![("reference", &self.image)];
        layers.extend(self.variance.iter().map(|v| (VARIANCE, v)));
        encode_layers(&layers)
    }

    /// Read a reference: its EXR (a variance layer if it has one) and the
    /// metadata beside it, which must be there and whole.
    pub fn load(path: &Path) -> Result<Self, ReferenceError> {
        let bytes = fileio::read_bounded(path, max_bytes())?;
        let info_path = info_path(path);
        let text = fileio::read_text(&info_path, limits::TEXT_FILE_BYTES)?;
        let info = parse_info(&text, &info_path)?;
        Self::decode(&bytes, info, &path.display().to_string())
    }

    /// A reference from its EXR's bytes and its metadata; `name` says
    /// where they came from in errors.
    pub fn decode(bytes: &[u8], info: ReferenceInfo, name: &str) -> Result<Self, ReferenceError> {
        let fail = |reason: String| ReferenceError::Decode { path: name.to_owned(), reason };
        let (image, variance) = decode_layers(bytes).map_err(fail)?;
        if (image.width, image.height) != (info.width, info.height) {
            return Err(fail(format!(
                "{}×{} pixels where its metadata says {}×{}",
                image.width, image.height, info.width, info.height
            )));
        }
        Ok(Self { image, variance, info })
    }
}

/// The largest reference file read: the largest image, two layers of it.
fn max_bytes() -> u64 {
    2 * limits::IMAGE_PIXELS * 16 + (1 << 20)
}

/// The metadata in `text` (from `path`): a parse error names its line.
pub fn parse_info(text: &str, path: &Path) -> Result<ReferenceInfo, ReferenceError> {
    ron::from_str(text).map_err(|e| ReferenceError::Info {
        path: path.to_owned(),
        line: e.span.start.line,
        reason: e.code.to_string(),
    })
}

/// The metadata beside `image`.
pub fn load_info(image: &Path) -> Result<ReferenceInfo, ReferenceError> {
    let path = info_path(image);
    parse_info(&fileio::read_text(&path, limits::TEXT_FILE_BYTES)?, &path)
}

/// The image layer and the variance layer (if any) of an EXR.
fn decode_layers(bytes: &[u8]) -> Result<(LinearImage, Option<LinearImage>), String> {
    let mut layers = crate::render::layers::decode_layers(bytes)?.into_iter();
    let (_, first) = layers.next().ok_or("no layers")?;
    let variance = layers
        .find(|(name, image)| name == VARIANCE && (image.width, image.height) == (first.width, first.height))
        .map(|(_, image)| image);
    Ok((first, variance))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(variance: bool) -> Reference {
        let mut image = LinearImage::new(5, 3);
        image.pixels[7] = [1.5, 0.25, 3.0];
        let variance = variance.then(|| LinearImage { pixels: vec![[1e-4, 2e-4, 3e-4]; 15], ..image.clone() });
        let info = ReferenceInfo {
            scene: "my.ron".into(),
            key: "0123".into(),
            algorithm: "path".into(),
            width: 5,
            height: 3,
            samples_per_pixel: 16,
            seconds: 0.5,
            seed: 1,
            program_version: "0".into(),
        };
        Reference { image, variance, info }
    }

    #[test]
    fn a_reference_comes_back_as_it_was_saved_with_or_without_variance() {
        let dir = tempfile::tempdir().unwrap();
        for with_variance in [true, false] {
            let path = dir.path().join(format!("r{with_variance}.exr"));
            let saved = reference(with_variance);
            saved.save(&path).unwrap();
            assert_eq!(Reference::load(&path).unwrap(), saved);
            assert!(fileio::replaceable(&info_path(&path), &[SIGNATURE.as_bytes()]).unwrap());
            // Any EXR reader shows the image: it is the first layer
            assert_eq!(LinearImage::load(&path).unwrap(), saved.image);
        }
        assert_eq!(info_path(Path::new("refs/my.exr")), Path::new("refs/my.exr.meta.ron"));
    }

    #[test]
    fn a_broken_reference_says_which_file_and_what() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.exr");
        reference(true).save(&path).unwrap();
        std::fs::write(
            info_path(&path),
            "// GI Studio reference metadata\n(\n    scene: \"x\",\n    width: \"wide\",\n)",
        )
        .unwrap();
        let message = Reference::load(&path).unwrap_err().to_string();
        assert!(message.contains("r.exr.meta.ron: line 4"), "{message}");
        std::fs::remove_file(info_path(&path)).unwrap();
        assert!(Reference::load(&path).unwrap_err().to_string().contains("r.exr.meta.ron"));
        let err = Reference::decode(b"not an exr", reference(false).info, "x.exr").unwrap_err();
        assert!(err.to_string().starts_with("x.exr: not a reference image"), "{err}");
        let wrong_size = ReferenceInfo { width: 6, ..reference(false).info };
        let bytes = reference(false).encode().unwrap();
        assert!(Reference::decode(&bytes, wrong_size, "x.exr").unwrap_err().to_string().contains("5×3 pixels"));
    }
}
