//! Converged references: what every pane's error is measured against. A
//! reference is its image, each pixel's estimated variance (when the method
//! that made it is unbiased, so its noise can be taken out of the error),
//! and what made it. References are found (`find`) among the presets' own,
//! compiled into the binary, then in the cache (`ReferenceCache`), by a key
//! of the scene's content, the size and the method (`reference_key`);
//! nothing depends on the folder the program runs in.

mod cache;
mod embedded;
mod file;
mod method;

pub use cache::{cache_dir, ReferenceCache};
pub use embedded::embedded;
pub use file::{info_path, load_info, ReferenceError};
pub use method::{
    reference_method, reference_settings, reference_size, ReferenceMethod, REFERENCE_PASSES, REFERENCE_SEED,
};

use serde::{Deserialize, Serialize};

use crate::render::{Algorithm, LinearImage};
use crate::scene::Scene;

/// A converged image of a scene, and what made it.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    pub image: LinearImage,
    /// Each pixel's estimated variance of its mean (unbiased methods only).
    pub variance: Option<LinearImage>,
    pub info: ReferenceInfo,
}

/// What made a reference, stored beside it (`info_path`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceInfo {
    /// The scene's file or preset name, for people reading the file.
    pub scene: String,
    /// `reference_key` of the scene, size and method: what finds it.
    #[serde(default)]
    pub key: String,
    pub algorithm: String,
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    pub seconds: f64,
    pub seed: u64,
    pub program_version: String,
}

/// Changes whenever references made before would measure wrongly now
/// (a change of the estimator, of what the key covers).
const REFERENCE_VERSION: u64 = 2;

/// The key that finds the reference of `scene` at `width × height` made by
/// `algorithm`: FNV-1a over the scene's content key, the size, the method.
pub fn reference_key(scene: &Scene, width: u32, height: u32, algorithm: Algorithm) -> String {
    reference_key_of(scene.content_key(), width, height, algorithm)
}

/// `reference_key` of a scene known by its content key (`Scene::content_key`).
pub fn reference_key_of(content_key: u64, width: u32, height: u32, algorithm: Algorithm) -> String {
    let words = [content_key, width as u64, height as u64, REFERENCE_VERSION];
    let bytes = words.iter().flat_map(|w| w.to_le_bytes()).chain(algorithm.name().bytes());
    let hash = bytes.fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    format!("{hash:016x}")
}

/// The reference of `scene` at `width × height`, wherever the program
/// keeps one: the presets' own, then `cache` (if there is one).
pub fn find(scene: &Scene, width: u32, height: u32, cache: Option<&ReferenceCache>) -> Option<Reference> {
    if let Some(reference) = embedded(scene).filter(|r| (r.image.width, r.image.height) == (width, height)) {
        return Some(reference);
    }
    let key = reference_key(scene, width, height, reference_method(scene).algorithm);
    cache?.get(&key)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets;

    #[test]
    fn the_key_changes_with_the_scene_the_size_and_the_method() {
        let scene = presets::preset("cornell").unwrap().unwrap().into_scene();
        let key = reference_key(&scene, 320, 240, Algorithm::Path);
        assert_eq!(key, reference_key(&scene.clone(), 320, 240, Algorithm::Path));
        assert_ne!(key, reference_key(&scene, 320, 241, Algorithm::Path));
        assert_ne!(key, reference_key(&scene, 320, 240, Algorithm::Sppm));
        let mut moved = scene.clone();
        moved.camera.position.x += 1e-3;
        assert_ne!(key, reference_key(&moved, 320, 240, Algorithm::Path));
    }
}
