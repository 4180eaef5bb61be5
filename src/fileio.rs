//! Files as the program reads and writes them, so that nothing a user has is
//! lost: every write goes to a temporary file in the target's folder, is
//! synced, and only then renamed over the target (a full disk or a crash
//! leaves the old file whole); reads take only regular files of a bounded
//! size (a FIFO or `/dev/zero` given as a scene is refused, not waited on);
//! and what the program writes carries its signature, so a file it did not
//! write is never replaced without the user saying so.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Written into every PNG (a `Software` text chunk), EXR (its `software`
/// attribute) and metadata file the program makes.
pub const SIGNATURE: &str = "GI Studio";

/// How far into a file its signature is looked for.
const SIGNATURE_WINDOW: u64 = 4096;

#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The OS's reason, said once (it is not also this error's source).
    #[error("{path}: {cause}")]
    Io { path: PathBuf, cause: io::Error },
    #[error("{path}: not a regular file")]
    NotRegular { path: PathBuf },
    #[error("{path}: {size} bytes, more than the {max} this program reads")]
    TooLarge { path: PathBuf, size: u64, max: u64 },
}

impl FileError {
    fn io(path: &Path, cause: io::Error) -> Self {
        Self::Io { path: path.to_owned(), cause }
    }
}

/// Write `path` through `write`, atomically: the old file (if any) stays
/// whole until the new one is complete and synced. A target that exists
/// and is not a regular file (a device such as `/dev/full`, a pipe) is
/// written straight into, since there is nothing there to replace.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> Result<(), FileError> {
    let fail = |cause| FileError::io(path, cause);
    match fs::metadata(path) {
        Ok(meta) if meta.is_dir() => {
            return Err(fail(io::Error::new(io::ErrorKind::IsADirectory, "is a folder")));
        }
        Ok(meta) if !meta.is_file() => {
            let file = OpenOptions::new().write(true).open(path).map_err(fail)?;
            let mut out = BufWriter::new(file);
            return write(&mut out).and_then(|()| out.flush()).map_err(fail);
        }
        _ => {}
    }
    // Replace what a symbolic link points at, not the link
    let target = match fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => fs::canonicalize(path).map_err(fail)?,
        _ => path.to_owned(),
    };
    let temporary = temporary_beside(&target);
    let result = (|| {
        let file = OpenOptions::new().write(true).create_new(true).open(&temporary)?;
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
        if let Ok(old) = fs::metadata(&target) {
            file.set_permissions(old.permissions())?;
        }
        file.sync_all()?;
        drop(file);
        fs::rename(&temporary, &target)?;
        sync_folder(&target)
    })();
    result.map_err(|cause| {
        // The write already failed; what is left of its temporary file goes
        let _ = fs::remove_file(&temporary);
        fail(cause)
    })
}

/// Write `bytes` to `path` atomically.
/// The file beside `path` named as it is plus `suffix`: `x.exr` and
/// `.meta.ron` give `x.exr.meta.ron` (a file's metadata, kept beside it).
pub fn beside(path: &Path, suffix: &str) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_owned();
    name.push(suffix);
    path.with_file_name(name)
}

pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_atomic(path, |out| out.write_all(bytes))
}

/// `.name.<pid>.<n>.partial` in the target's folder: the same file system,
/// so the rename is atomic; hidden, and never a name a user would pick.
fn temporary_beside(target: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = target.file_name().map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    target.with_file_name(format!(".{name}.{}.{n}.partial", std::process::id()))
}

/// Make the rename itself durable.
fn sync_folder(target: &Path) -> io::Result<()> {
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    File::open(folder)?.sync_all()
}

/// Whether writing `path` loses nothing of the user's: it does not exist, is
/// not a regular file (written through, see `write_atomic`), or carries one
/// of `signatures` near its start (the program wrote it).
pub fn replaceable(path: &Path, signatures: &[&[u8]]) -> Result<bool, FileError> {
    let meta = match fs::metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(true),
        Err(e) => return Err(FileError::io(path, e)),
    };
    if !meta.is_file() {
        return Ok(!meta.is_dir());
    }
    let mut head = Vec::new();
    File::open(path)
        .and_then(|f| f.take(SIGNATURE_WINDOW).read_to_end(&mut head))
        .map_err(|e| FileError::io(path, e))?;
    Ok(signatures.iter().any(|s| !s.is_empty() && head.windows(s.len()).any(|w| w == *s)))
}

/// The whole of a regular file of at most `max` bytes.
pub fn read_bounded(path: &Path, max: u64) -> Result<Vec<u8>, FileError> {
    let file = open_regular(path, max)?;
    let mut bytes = Vec::new();
    // Read one byte past the limit: a file that grew since it was measured
    file.take(max + 1).read_to_end(&mut bytes).map_err(|e| FileError::io(path, e))?;
    if bytes.len() as u64 > max {
        return Err(FileError::TooLarge { path: path.to_owned(), size: bytes.len() as u64, max });
    }
    Ok(bytes)
}

/// A regular file of at most `max` bytes as UTF-8 text.
pub fn read_text(path: &Path, max: u64) -> Result<String, FileError> {
    String::from_utf8(read_bounded(path, max)?)
        .map_err(|_| FileError::io(path, io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text")))
}

/// Open a regular file of at most `max` bytes; anything else is refused
/// before it is opened (opening a FIFO would wait for a writer).
pub fn open_regular(path: &Path, max: u64) -> Result<File, FileError> {
    let meta = fs::metadata(path).map_err(|e| FileError::io(path, e))?;
    if !meta.is_file() {
        return Err(FileError::NotRegular { path: path.to_owned() });
    }
    if meta.len() > max {
        return Err(FileError::TooLarge { path: path.to_owned(), size: meta.len(), max });
    }
    File::open(path).map_err(|e| FileError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh folder, removed when the test ends.
    fn folder(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new().prefix(&format!("gi-fileio-{name}-")).tempdir().unwrap()
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> =
            fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_whole_and_no_partial_file() {
        let temp = folder("fail");
        let dir = temp.path();
        let path = dir.join("image.png");
        fs::write(&path, b"the user's image").unwrap();
        let error = write_atomic(&path, |out| {
            out.write_all(&[7; 100_000])?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(error.to_string(), format!("{}: disk full", path.display()));
        assert_eq!(fs::read(&path).unwrap(), b"the user's image");
        assert_eq!(entries(dir), vec!["image.png"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_completed_write_replaces_the_file_keeping_its_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let temp = folder("ok");
        let dir = temp.path();
        let path = dir.join("scene.ron");
        fs::write(&path, b"old").unwrap();
        fs::set_permissions(&path, fs::Permissions::from_mode(0o600)).unwrap();
        write_bytes(&path, b"new").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"new");
        assert_eq!(fs::metadata(&path).unwrap().permissions().mode() & 0o777, 0o600);
        assert_eq!(entries(dir), vec!["scene.ron"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_keeps_pointing_at_the_replaced_file() {
        let temp = folder("link");
        let dir = temp.path();
        let real = dir.join("real.png");
        fs::write(&real, b"old").unwrap();
        std::os::unix::fs::symlink(&real, dir.join("link.png")).unwrap();
        write_bytes(&dir.join("link.png"), b"new").unwrap();
        assert!(fs::symlink_metadata(dir.join("link.png")).unwrap().file_type().is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_device_is_written_through_and_its_error_reported() {
        use std::os::unix::fs::FileTypeExt;
        let error = write_bytes(Path::new("/dev/full"), &[0; 10_000]).unwrap_err();
        let message = error.to_string();
        assert!(message.starts_with("/dev/full: ") && message.contains("No space left"), "{message}");
        // Still the device, not a file renamed over it
        assert!(fs::metadata("/dev/full").unwrap().file_type().is_char_device());
        write_bytes(Path::new("/dev/null"), b"gone").unwrap();
    }

    #[test]
    fn only_signed_files_are_replaceable() {
        let temp = folder("sign");
        let dir = temp.path();
        let ours = dir.join("ours.png");
        fs::write(&ours, [b"\x89PNG....tEXtSoftware\0".as_slice(), SIGNATURE.as_bytes()].concat()).unwrap();
        let theirs = dir.join("theirs.png");
        fs::write(&theirs, b"\x89PNG someone else's").unwrap();
        let sign: &[&[u8]] = &[SIGNATURE.as_bytes()];
        assert!(replaceable(&ours, sign).unwrap());
        assert!(!replaceable(&theirs, sign).unwrap());
        assert!(replaceable(&dir.join("new.png"), sign).unwrap());
        assert!(replaceable(Path::new("/dev/null"), sign).unwrap());
        assert!(!replaceable(dir, sign).unwrap());
    }

    #[test]
    fn reads_refuse_what_is_not_a_bounded_regular_file() {
        let temp = folder("read");
        let dir = temp.path();
        let path = dir.join("scene.ron");
        fs::write(&path, "(camera: ())").unwrap();
        assert_eq!(read_text(&path, 100).unwrap(), "(camera: ())");
        assert!(matches!(read_text(&path, 5), Err(FileError::TooLarge { size: 12, max: 5, .. })));
        assert!(matches!(read_text(Path::new("/dev/zero"), 100), Err(FileError::NotRegular { .. })));
        assert!(matches!(read_text(dir, 100), Err(FileError::NotRegular { .. })));
        fs::write(&path, [0xff, 0xfe]).unwrap();
        assert!(read_text(&path, 100).unwrap_err().to_string().ends_with("not UTF-8 text"));
        let missing = read_text(&dir.join("missing.ron"), 100).unwrap_err().to_string();
        assert_eq!(missing.matches("No such file").count(), 1, "{missing}");
    }
}
