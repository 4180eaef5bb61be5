//! Photon maps on disk, so the expensive pass can be reused: a small header
//! (format version, the scene's content key, a key of the photon settings)
//! and both trees in heap order, little-endian. A map for another scene,
//! other settings or another format version is refused, saying which.

use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use super::kdtree::PhotonKdTree;
use super::maps::{MapStats, PhotonMapStats, PhotonMaps};
use super::record::Photon;
use crate::render::PhotonSettings;

const MAGIC: &[u8; 8] = b"GIPHOTON";
/// 2: giant emitters emit only from the cap the camera can see.
pub const FORMAT_VERSION: u32 = 2;

#[derive(Debug, thiserror::Error)]
pub enum PhotonFileError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: not a GI Studio photon map")]
    NotAPhotonMap { path: PathBuf },
    #[error("{path}: photon map format version {found}, this program reads version {expected}")]
    Version { path: PathBuf, found: u32, expected: u32 },
    #[error("{path}: this photon map was made for another scene (or an edited version of it)")]
    OtherScene { path: PathBuf },
    #[error("{path}: this photon map was made with other photon settings (photon counts, seed or path depth)")]
    OtherSettings { path: PathBuf },
    #[error("{path}: the file is truncated or damaged")]
    Damaged { path: PathBuf },
}

/// What a map depends on besides the scene: the settings that change which
/// photons are traced (not those that only change how they are gathered).
pub fn settings_key(settings: &PhotonSettings, seed: u64, max_depth: u32) -> u64 {
    let words = [settings.global_photons as u64, settings.caustic_photons as u64, seed, max_depth as u64];
    words
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3))
}

pub fn save_photon_maps(
    maps: &PhotonMaps,
    scene_key: u64,
    settings_key: u64,
    path: &Path,
) -> Result<(), PhotonFileError> {
    let io = |source| PhotonFileError::Io { path: path.to_owned(), source };
    let mut out = BufWriter::new(std::fs::File::create(path).map_err(io)?);
    let mut header = Vec::with_capacity(40);
    header.extend_from_slice(MAGIC);
    header.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    header.extend_from_slice(&scene_key.to_le_bytes());
    header.extend_from_slice(&settings_key.to_le_bytes());
    header.extend_from_slice(&maps.max_radius.to_le_bytes());
    out.write_all(&header).map_err(io)?;
    for (tree, stats) in [(&maps.global, &maps.stats.global), (&maps.caustic, &maps.stats.caustic)] {
        out.write_all(&stats.emitted.to_le_bytes()).map_err(io)?;
        out.write_all(&(tree.len() as u64).to_le_bytes()).map_err(io)?;
        for photon in tree.photons() {
            out.write_all(&photon.to_bytes()).map_err(io)?;
        }
    }
    out.flush().map_err(io)
}

pub fn load_photon_maps(path: &Path, scene_key: u64, settings_key: u64) -> Result<PhotonMaps, PhotonFileError> {
    let file = std::fs::File::open(path).map_err(|source| PhotonFileError::Io { path: path.to_owned(), source })?;
    let mut input = BufReader::new(file);
    let damaged = || PhotonFileError::Damaged { path: path.to_owned() };
    let mut magic = [0u8; 8];
    input.read_exact(&mut magic).map_err(|_| PhotonFileError::NotAPhotonMap { path: path.to_owned() })?;
    if &magic != MAGIC {
        return Err(PhotonFileError::NotAPhotonMap { path: path.to_owned() });
    }
    let mut word = [0u8; 4];
    input.read_exact(&mut word).map_err(|_| damaged())?;
    let version = u32::from_le_bytes(word);
    if version != FORMAT_VERSION {
        return Err(PhotonFileError::Version { path: path.to_owned(), found: version, expected: FORMAT_VERSION });
    }
    let read_u64 = |input: &mut BufReader<std::fs::File>| -> Result<u64, PhotonFileError> {
        let mut bytes = [0u8; 8];
        input.read_exact(&mut bytes).map_err(|_| damaged())?;
        Ok(u64::from_le_bytes(bytes))
    };
    if read_u64(&mut input)? != scene_key {
        return Err(PhotonFileError::OtherScene { path: path.to_owned() });
    }
    if read_u64(&mut input)? != settings_key {
        return Err(PhotonFileError::OtherSettings { path: path.to_owned() });
    }
    input.read_exact(&mut word).map_err(|_| damaged())?;
    let max_radius = f32::from_le_bytes(word);
    let read_tree = |input: &mut BufReader<std::fs::File>| -> Result<(PhotonKdTree, MapStats), PhotonFileError> {
        let emitted = read_u64(input)?;
        let count = read_u64(input)?;
        // Refuse absurd counts before allocating for them
        if count > 1 << 34 {
            return Err(damaged());
        }
        let mut photons = Vec::with_capacity(count as usize);
        let mut record = [0u8; 28];
        for _ in 0..count {
            input.read_exact(&mut record).map_err(|_| damaged())?;
            photons.push(Photon::from_bytes(&record));
        }
        let tree = PhotonKdTree::from_heap_order(photons);
        let stats = MapStats {
            emitted,
            stored: count,
            bytes: tree.bytes() as u64,
            depth: tree.depth() as u32,
            ..MapStats::default()
        };
        Ok((tree, stats))
    };
    let (global, global_stats) = read_tree(&mut input)?;
    let (caustic, caustic_stats) = read_tree(&mut input)?;
    Ok(PhotonMaps {
        global,
        caustic,
        stats: PhotonMapStats { global: global_stats, caustic: caustic_stats },
        max_radius,
    })
}
