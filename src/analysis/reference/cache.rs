//! References kept between runs, in the platform's cache folder under their
//! key (`reference_key`): an edit undone, or a file reopened, finds its
//! reference at once. The cache holds at most `limits::REFERENCE_CACHE_BYTES`
//! and drops the least recently used first (a reference read is touched).

use std::fs;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use super::file::info_path;
use super::{Reference, ReferenceError};
use crate::limits;

/// `$XDG_CACHE_HOME/gistudio/references`, or `~/.cache/gistudio/references`.
pub fn cache_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME").filter(|v| !v.is_empty()).map(PathBuf::from).or_else(|| {
        std::env::var_os("HOME").filter(|v| !v.is_empty()).map(|home| PathBuf::from(home).join(".cache"))
    })?;
    Some(base.join("gistudio").join("references"))
}

/// A folder of references by key, bounded in size.
#[derive(Clone, Debug)]
pub struct ReferenceCache {
    dir: PathBuf,
    limit_bytes: u64,
}

impl ReferenceCache {
    /// The platform's cache (`cache_dir`), if there is a home to put it in.
    pub fn open_default() -> Option<Self> {
        cache_dir().map(|dir| Self::new(dir, limits::REFERENCE_CACHE_BYTES))
    }

    pub fn new(dir: PathBuf, limit_bytes: u64) -> Self {
        Self { dir, limit_bytes }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Where the reference of `key` is kept.
    pub fn path_of(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.exr"))
    }

    /// The reference kept under `key`, marked as just used. A damaged entry
    /// is as good as none: it is made again (and replaces it).
    pub fn get(&self, key: &str) -> Option<Reference> {
        let path = self.path_of(key);
        let reference = Reference::load(&path).ok().filter(|r| r.info.key == key)?;
        // Least recently used goes first: reading counts as use. A cache we
        // cannot touch still serves.
        let _ = fs::File::options().append(true).open(&path).and_then(|f| f.set_modified(SystemTime::now()));
        Some(reference)
    }

    /// Keep `reference` under its key (`info.key`), then drop the least
    /// recently used others until the cache is within its limit. Returns
    /// where it was written.
    pub fn put(&self, reference: &Reference) -> Result<PathBuf, ReferenceError> {
        let key = &reference.info.key;
        let valid_key = !key.is_empty() && key.bytes().all(|b| b.is_ascii_hexdigit());
        let path = self.path_of(if valid_key { key } else { "invalid" });
        if !valid_key {
            let cause = std::io::Error::other("a reference without a key cannot be cached");
            return Err(crate::fileio::FileError::Io { path, cause }.into());
        }
        fs::create_dir_all(&self.dir)
            .map_err(|cause| crate::fileio::FileError::Io { path: self.dir.clone(), cause })?;
        reference.save(&path)?;
        self.prune(&path);
        Ok(path)
    }

    /// Every entry: (image path, bytes of it and its metadata, last use).
    fn entries(&self) -> Vec<(PathBuf, u64, SystemTime)> {
        let Ok(listing) = fs::read_dir(&self.dir) else { return Vec::new() };
        listing
            .filter_map(Result::ok)
            .map(|entry| entry.path())
            .filter(|path| path.extension().is_some_and(|e| e == "exr"))
            .filter_map(|path| {
                let meta = fs::metadata(&path).ok()?;
                let info = fs::metadata(info_path(&path)).map(|m| m.len()).unwrap_or(0);
                Some((path, meta.len() + info, meta.modified().ok()?))
            })
            .collect()
    }

    /// Drop the least recently used entries (never `keep`) until the cache
    /// is within its limit. A file that will not go is left; the next put
    /// tries again.
    fn prune(&self, keep: &Path) {
        let mut entries = self.entries();
        let mut total: u64 = entries.iter().map(|e| e.1).sum();
        entries.sort_by_key(|e| e.2);
        for (path, bytes, _) in entries {
            if total <= self.limit_bytes {
                break;
            }
            if path != keep && fs::remove_file(&path).is_ok() {
                let _ = fs::remove_file(info_path(&path));
                total -= bytes;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::reference::ReferenceInfo;
    use crate::render::LinearImage;

    fn reference(key: &str, side: u32) -> Reference {
        let info = ReferenceInfo {
            scene: "s".into(),
            key: key.into(),
            algorithm: "path".into(),
            width: side,
            height: side,
            samples_per_pixel: 1,
            seconds: 0.0,
            seed: 0,
            program_version: "0".into(),
        };
        Reference { image: LinearImage::new(side, side), variance: None, info }
    }

    #[test]
    fn the_cache_finds_by_key_and_drops_the_least_recently_used() {
        let dir = tempfile::tempdir().unwrap();
        let one = ReferenceCache::new(dir.path().to_owned(), u64::MAX).put(&reference("aa", 64)).unwrap();
        let size = fs::metadata(&one).unwrap().len() + fs::metadata(info_path(&one)).unwrap().len();
        // Room for two entries
        let cache = ReferenceCache::new(dir.path().to_owned(), 2 * size + size / 2);
        let old = SystemTime::now() - std::time::Duration::from_secs(100);
        cache.put(&reference("bb", 64)).unwrap();
        for key in ["aa", "bb"] {
            fs::File::options().append(true).open(cache.path_of(key)).unwrap().set_modified(old).unwrap();
        }
        // Reading "aa" makes "bb" the least recently used
        assert_eq!(cache.get("aa").unwrap().info.key, "aa");
        cache.put(&reference("cc", 64)).unwrap();
        assert!(cache.get("bb").is_none(), "the least recently used went");
        assert!(cache.get("aa").is_some() && cache.get("cc").is_some());
        assert!(!info_path(&cache.path_of("bb")).exists());
        // An entry whose metadata names another key is not it
        fs::copy(cache.path_of("aa"), cache.path_of("dd")).unwrap();
        fs::copy(info_path(&cache.path_of("aa")), info_path(&cache.path_of("dd"))).unwrap();
        assert!(cache.get("dd").is_none());
        assert!(cache.put(&reference("../x", 4)).is_err(), "keys are hexadecimal");
    }
}
