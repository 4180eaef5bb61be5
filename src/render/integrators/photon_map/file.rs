//! Photon maps on disk, so the expensive pass can be reused: a small header
//! (format version, the scene's content key, a key of the photon settings),
//! both trees in heap order, little-endian, and a checksum of everything
//! before it. The gather radius is not the map's: the render resolves it
//! from its own settings and scene. A map for another scene, other
//! settings or another format version is refused, saying which; so is a
//! damaged one, before anything renders with it: the checksum catches bit
//! flips, and each photon and the trees' order are checked as they are read.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use crate::fileio::{self, FileError};
use crate::limits;
use crate::render::integrators::photon_map::kdtree::PhotonKdTree;
use crate::render::integrators::photon_map::maps::{MapStats, PhotonMapStats, PhotonMaps};
use crate::render::integrators::photon_map::record::Photon;
use crate::render::PhotonSettings;

/// The file's first bytes; also what marks a photon map as this program's.
pub const MAGIC: &[u8; 8] = b"GIPHOTON";
/// 2: giant emitters emit only from the cap the camera can see.
/// 3: a checksum at the end.
/// 4: no gather radius (a file's could only be wrong: the render's settings
/// and scene say it).
pub const FORMAT_VERSION: u32 = 4;
const HEADER_BYTES: u64 = 8 + 4 + 8 + 8;
const MAP_HEADER_BYTES: u64 = 16;
const PHOTON_BYTES: u64 = 28;

#[derive(Debug, thiserror::Error)]
pub enum PhotonFileError {
    #[error(transparent)]
    File(#[from] FileError),
    #[error("{path}: not a GI Studio photon map")]
    NotAPhotonMap { path: PathBuf },
    #[error("{path}: photon map format version {found}, this program reads version {expected} (trace the maps again with `gi-studio photons`)")]
    Version { path: PathBuf, found: u32, expected: u32 },
    #[error("{path}: this photon map was made for another scene (or an edited version of it)")]
    OtherScene { path: PathBuf },
    #[error("{path}: this photon map was made with other photon settings (photon counts, seed or path depth)")]
    OtherSettings { path: PathBuf },
    #[error("{path}: the file is truncated or damaged: {reason}")]
    Damaged { path: PathBuf, reason: String },
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

/// A 64-bit checksum over a stream of bytes, eight at a time: each step
/// (xor, odd multiply, rotate) is a bijection of the state, so changing any
/// one word always changes the result.
#[derive(Clone, Copy)]
struct Checksum {
    state: u64,
    pending: [u8; 8],
    filled: usize,
}

impl Checksum {
    fn new() -> Self {
        Self { state: 0x243f_6a88_85a3_08d3, pending: [0; 8], filled: 0 }
    }

    fn mix(&mut self, word: u64) {
        self.state = (self.state ^ word).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
    }

    fn update(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            let take = (8 - self.filled).min(bytes.len());
            self.pending[self.filled..self.filled + take].copy_from_slice(&bytes[..take]);
            self.filled += take;
            bytes = &bytes[take..];
            if self.filled == 8 {
                self.mix(u64::from_le_bytes(self.pending));
                self.filled = 0;
            }
        }
    }

    fn finish(mut self) -> u64 {
        let length = self.filled as u64;
        self.pending[self.filled..].fill(0);
        self.mix(u64::from_le_bytes(self.pending));
        self.mix(length);
        self.state
    }
}

/// The checksum a map file ends with, of the bytes before it.
pub fn checksum(bytes: &[u8]) -> u64 {
    let mut sum = Checksum::new();
    sum.update(bytes);
    sum.finish()
}

/// Write both maps, atomically: a failed save leaves no partial file.
pub fn save_photon_maps(
    maps: &PhotonMaps,
    scene_key: u64,
    settings_key: u64,
    path: &Path,
) -> Result<(), PhotonFileError> {
    Ok(fileio::write_atomic(path, |out| {
        let mut sum = Checksum::new();
        let mut put = |out: &mut dyn Write, bytes: &[u8]| {
            sum.update(bytes);
            out.write_all(bytes)
        };
        put(out, MAGIC)?;
        put(out, &FORMAT_VERSION.to_le_bytes())?;
        put(out, &scene_key.to_le_bytes())?;
        put(out, &settings_key.to_le_bytes())?;
        for (tree, stats) in [(&maps.global, &maps.stats.global), (&maps.caustic, &maps.stats.caustic)] {
            put(out, &stats.emitted.to_le_bytes())?;
            put(out, &(tree.len() as u64).to_le_bytes())?;
            for photon in tree.photons() {
                put(out, &photon.to_bytes())?;
            }
        }
        out.write_all(&sum.finish().to_le_bytes())
    })?)
}

/// A file's bytes read in order, summed, bounded by what the file holds.
struct Reader<'a> {
    input: std::io::BufReader<std::fs::File>,
    left: u64,
    /// The most photons a map may hold (`limits::STORED_PHOTONS`).
    most_photons: u64,
    sum: Checksum,
    path: &'a Path,
}

impl Reader<'_> {
    fn damaged(&self, reason: impl Into<String>) -> PhotonFileError {
        PhotonFileError::Damaged { path: self.path.to_owned(), reason: reason.into() }
    }

    fn bytes(&mut self, buffer: &mut [u8]) -> Result<(), PhotonFileError> {
        if (buffer.len() as u64) > self.left {
            return Err(self.damaged("it ends early"));
        }
        self.input.read_exact(buffer).map_err(|cause| FileError::Io { path: self.path.to_owned(), cause })?;
        self.left -= buffer.len() as u64;
        self.sum.update(buffer);
        Ok(())
    }

    fn u64(&mut self) -> Result<u64, PhotonFileError> {
        let mut word = [0; 8];
        self.bytes(&mut word)?;
        Ok(u64::from_le_bytes(word))
    }

    fn u32(&mut self) -> Result<u32, PhotonFileError> {
        let mut word = [0; 4];
        self.bytes(&mut word)?;
        Ok(u32::from_le_bytes(word))
    }

    /// One map's counts and records: the count checked against what is
    /// left of the file before anything is allocated for it.
    fn map(&mut self, name: &str) -> Result<RawMap, PhotonFileError> {
        let emitted = self.u64()?;
        let count = self.u64()?;
        if count > self.most_photons {
            let most = self.most_photons;
            return Err(
                self.damaged(format!("the {name} map claims {count} photons, more than the {most} a map may hold"))
            );
        }
        if count * PHOTON_BYTES > self.left {
            return Err(self.damaged(format!("the {name} map claims {count} photons, more than the file holds")));
        }
        let mut records = vec![0u8; (count * PHOTON_BYTES) as usize];
        self.bytes(&mut records)?;
        Ok(RawMap { emitted, records })
    }
}

/// A map as read, before its photons are checked (after the checksum).
struct RawMap {
    emitted: u64,
    records: Vec<u8>,
}

impl RawMap {
    /// Each photon, then the tree's order.
    fn tree(
        &self,
        name: &str,
        damaged: impl Fn(String) -> PhotonFileError,
    ) -> Result<(PhotonKdTree, MapStats), PhotonFileError> {
        let mut photons = Vec::with_capacity(self.records.len() / PHOTON_BYTES as usize);
        for (i, record) in self.records.chunks_exact(PHOTON_BYTES as usize).enumerate() {
            let record: &[u8; 28] = record.try_into().map_err(|_| damaged("a photon record is cut short".into()))?;
            let photon = Photon::from_bytes(record)
                .map_err(|what| damaged(format!("photon {i} of the {name} map has {what}")))?;
            photons.push(photon);
        }
        // Photons leave their lights in directions of their own: no traced
        // map of two or more has them all land on one point
        if let Some(first) = photons.first() {
            if photons.len() > 1 && photons.iter().all(|p| p.position == first.position) {
                let n = photons.len();
                return Err(damaged(format!("all {n} photons of the {name} map lie at one point")));
            }
        }
        let tree = PhotonKdTree::from_heap_order(photons)
            .map_err(|i| damaged(format!("photon {i} of the {name} map is out of the tree's order")))?;
        let stats = MapStats {
            emitted: self.emitted,
            stored: tree.len() as u64,
            bytes: tree.bytes() as u64,
            depth: tree.depth() as u32,
            ..MapStats::default()
        };
        Ok((tree, stats))
    }
}

pub fn load_photon_maps(path: &Path, scene_key: u64, settings_key: u64) -> Result<PhotonMaps, PhotonFileError> {
    load_bounded(path, scene_key, settings_key, limits::STORED_PHOTONS)
}

/// `load_photon_maps` with maps of at most `most_photons` (a test can
/// reach the bound without gigabytes).
fn load_bounded(
    path: &Path,
    scene_key: u64,
    settings_key: u64,
    most_photons: u64,
) -> Result<PhotonMaps, PhotonFileError> {
    let most = HEADER_BYTES + 2 * (MAP_HEADER_BYTES + most_photons * PHOTON_BYTES) + 8;
    let file = fileio::open_regular(path, most)?;
    let left = file.metadata().map_err(|cause| FileError::Io { path: path.to_owned(), cause })?.len();
    let mut input = Reader { input: std::io::BufReader::new(file), left, most_photons, sum: Checksum::new(), path };
    let not_ours = || PhotonFileError::NotAPhotonMap { path: path.to_owned() };
    let mut magic = [0u8; 8];
    input.bytes(&mut magic).map_err(|_| not_ours())?;
    if &magic != MAGIC {
        return Err(not_ours());
    }
    let version = input.u32()?;
    if version != FORMAT_VERSION {
        return Err(PhotonFileError::Version { path: path.to_owned(), found: version, expected: FORMAT_VERSION });
    }
    if input.u64()? != scene_key {
        return Err(PhotonFileError::OtherScene { path: path.to_owned() });
    }
    if input.u64()? != settings_key {
        return Err(PhotonFileError::OtherSettings { path: path.to_owned() });
    }
    let (global, caustic) = (input.map("global")?, input.map("caustic")?);
    // The checksum first: a flipped bit is said as what it is, whatever it hit
    let computed = input.sum.finish();
    if input.left != 8 {
        return Err(input.damaged(format!("{} bytes where the 8 of its checksum belong", input.left)));
    }
    if input.u64()? != computed {
        return Err(input.damaged("its checksum does not match its contents"));
    }
    let damaged = |reason: String| PhotonFileError::Damaged { path: path.to_owned(), reason };
    let (global, global_stats) = global.tree("global", damaged)?;
    let (caustic, caustic_stats) = caustic.tree("caustic", damaged)?;
    Ok(PhotonMaps { global, caustic, stats: PhotonMapStats { global: global_stats, caustic: caustic_stats } })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_checksum_sees_every_single_byte_change_and_the_length() {
        let data: Vec<u8> = (0..77u32).map(|i| (i * 37 % 251) as u8).collect();
        let sum = |bytes: &[u8]| {
            let mut c = Checksum::new();
            // In uneven pieces: the result may not depend on how it is fed
            for piece in bytes.chunks(5) {
                c.update(piece);
            }
            c.finish()
        };
        let whole = sum(&data);
        assert_eq!(checksum(&data), whole);
        for i in 0..data.len() {
            for bit in 0..8 {
                let mut flipped = data.clone();
                flipped[i] ^= 1 << bit;
                assert_ne!(sum(&flipped), whole, "byte {i} bit {bit}");
            }
        }
        assert_ne!(sum(&data[..76]), whole);
        assert_ne!(sum(&[data.as_slice(), &[0]].concat()), whole);
    }

    fn maps_of(global: usize, caustic: usize) -> PhotonMaps {
        let photons = |n: usize, z: f32| -> Vec<Photon> {
            (0..n).map(|i| Photon::new(glam::Vec3::new(i as f32, 0.5, z), -glam::Vec3::Y, [1.0; 3])).collect()
        };
        PhotonMaps {
            global: PhotonKdTree::build(photons(global, 0.0)),
            caustic: PhotonKdTree::build(photons(caustic, 1.0)),
            stats: PhotonMapStats {
                global: MapStats { emitted: 50, ..MapStats::default() },
                caustic: MapStats { emitted: 40, ..MapStats::default() },
            },
        }
    }

    /// The sizes the reader trusts are the writer's: a saved file is its
    /// header, two map headers, the records and the checksum; and what is
    /// read back says how deep each tree is.
    #[test]
    fn the_layout_the_reader_expects_is_the_one_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("maps.photons");
        save_photon_maps(&maps_of(5, 3), 1, 2, &path).unwrap();
        let size = std::fs::metadata(&path).unwrap().len();
        assert_eq!(size, HEADER_BYTES + 2 * MAP_HEADER_BYTES + 8 * PHOTON_BYTES + 8);
        assert_eq!((HEADER_BYTES, MAP_HEADER_BYTES, PHOTON_BYTES), (28, 16, 28));
        let loaded = load_photon_maps(&path, 1, 2).unwrap();
        assert_eq!((loaded.global.len(), loaded.caustic.len()), (5, 3));
        assert_eq!((loaded.stats.global.depth, loaded.stats.caustic.depth), (3, 2));
        assert_eq!((loaded.stats.global.bytes, loaded.stats.caustic.stored), (5 * 28, 3));
        assert_eq!((loaded.stats.global.emitted, loaded.stats.caustic.emitted), (50, 40));
        // A map with no photons (a scene with nothing specular has no caustics)
        save_photon_maps(&maps_of(4, 0), 1, 2, &path).unwrap();
        let loaded = load_photon_maps(&path, 1, 2).unwrap();
        assert_eq!((loaded.global.len(), loaded.caustic.len()), (4, 0));
    }

    /// The largest file opened is the largest two full maps need (2 × 200 M
    /// records); one byte more is refused before a byte is read. Sparse
    /// files: nothing is written to the disk.
    #[test]
    fn files_up_to_two_full_maps_are_opened_and_larger_ones_refused() {
        const TWO_FULL_MAPS: u64 = 28 + 2 * (16 + 200_000_000 * 28) + 8;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.photons");
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(TWO_FULL_MAPS).unwrap();
        // Opened and read: zeros are not a photon map
        assert!(matches!(load_photon_maps(&path, 1, 2), Err(PhotonFileError::NotAPhotonMap { .. })));
        file.set_len(TWO_FULL_MAPS + 1).unwrap();
        let refused = load_photon_maps(&path, 1, 2);
        assert!(
            matches!(refused, Err(PhotonFileError::File(FileError::TooLarge { max: TWO_FULL_MAPS, .. }))),
            "{refused:?}"
        );
    }

    /// A count larger than the rest of the file is refused as such, before
    /// anything is allocated for it, even when it is only a little larger.
    #[test]
    fn a_map_claiming_more_photons_than_the_file_holds_is_refused_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("maps.photons");
        save_photon_maps(&maps_of(5, 3), 1, 2, &path).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        // After the global map's count, 248 bytes are left: room for 8 records
        let count_at = (HEADER_BYTES + 8) as usize;
        assert_eq!(bytes.len() - count_at - 8, 248);
        bytes[count_at..count_at + 8].copy_from_slice(&9u64.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let refused = load_photon_maps(&path, 1, 2).unwrap_err().to_string();
        assert!(refused.contains("the global map claims 9 photons, more than the file holds"), "{refused}");
    }

    /// A map of exactly the most photons a map may hold is read; one photon
    /// more is refused, with that reason, before its records are read.
    #[test]
    fn a_map_of_the_most_photons_is_read_and_one_more_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("maps.photons");
        save_photon_maps(&maps_of(5, 3), 1, 2, &path).unwrap();
        let read = load_bounded(&path, 1, 2, 5).unwrap();
        assert_eq!((read.global.len(), read.caustic.len()), (5, 3));
        let refused = load_bounded(&path, 1, 2, 4).unwrap_err().to_string();
        assert!(refused.contains("the global map claims 5 photons, more than the 4 a map may hold"), "{refused}");
    }

    /// A map whose photons were all moved to one point, its checksum made
    /// anew, is refused: no traced map is that.
    #[test]
    fn a_map_of_photons_at_one_point_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("maps.photons");
        let at_one_point = |n: usize| {
            let photons = (0..n).map(|_| Photon::new(glam::Vec3::new(1.0, 0.5, 0.0), -glam::Vec3::Y, [1.0; 3]));
            PhotonKdTree::build(photons.collect())
        };
        let maps = PhotonMaps { global: at_one_point(5), ..maps_of(0, 3) };
        save_photon_maps(&maps, 1, 2, &path).unwrap();
        let refused = load_photon_maps(&path, 1, 2).unwrap_err().to_string();
        assert!(refused.contains("all 5 photons of the global map lie at one point"), "{refused}");
        // One photon alone is a map
        let maps = PhotonMaps { global: at_one_point(1), ..maps_of(0, 3) };
        save_photon_maps(&maps, 1, 2, &path).unwrap();
        assert!(load_photon_maps(&path, 1, 2).is_ok());
    }
}
