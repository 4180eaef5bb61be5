//! What a command may write, decided before it starts any work: never one
//! of its inputs, never the same file twice, and never a file GI Studio did
//! not write unless the user passes `--force`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use crate::fileio;

/// The inputs of one command and the outputs it has claimed so far.
pub struct Outputs {
    force: bool,
    inputs: Vec<(PathBuf, Identity)>,
    claimed: Vec<PathBuf>,
}

/// A file's identity on disk: hard links and other spellings of one file
/// are the same file.
#[derive(Clone, Copy, PartialEq, Eq)]
struct Identity {
    device: u64,
    inode: u64,
}

fn identity(path: &Path) -> Option<Identity> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| Identity { device: m.dev(), inode: m.ino() })
}

/// `path` spelled one way: its folder resolved, its name kept.
fn normalised(path: &Path) -> PathBuf {
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::canonicalize(folder).map_or_else(|_| path.to_owned(), |f| f.join(name))
}

impl Outputs {
    pub fn new(force: bool) -> Self {
        Self { force, inputs: Vec::new(), claimed: Vec::new() }
    }

    /// A file the command reads.
    pub fn input(&mut self, path: &Path) {
        if let Some(id) = identity(path) {
            self.inputs.push((path.to_owned(), id));
        }
    }

    /// Claim `path` as an output, which the program marks with one of
    /// `signatures` (see `fileio::replaceable`).
    pub fn claim(&mut self, path: &Path, signatures: &[&[u8]]) -> Result<()> {
        let shown = path.display();
        if let Some(id) = identity(path) {
            if let Some((input, _)) = self.inputs.iter().find(|(_, i)| *i == id) {
                bail!("{shown}: is this command's input {}; choose another output", input.display());
            }
        }
        let key = normalised(path);
        if self.claimed.contains(&key) {
            bail!("{shown}: this command would write it twice; give each output its own name");
        }
        if !self.force && !fileio::replaceable(path, signatures)? {
            bail!("{shown}: exists and was not written by GI Studio; pass --force to replace it");
        }
        self.claimed.push(key);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fileio::SIGNATURE;

    #[test]
    fn inputs_others_files_and_twice_written_outputs_are_refused() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("scene.ron");
        std::fs::write(&scene, "()").unwrap();
        let theirs = dir.join("theirs.png");
        std::fs::write(&theirs, "a photo").unwrap();
        let ours = dir.join("ours.png");
        std::fs::write(&ours, format!("...{SIGNATURE}...")).unwrap();
        let sign: &[&[u8]] = &[SIGNATURE.as_bytes()];

        let mut outputs = Outputs::new(false);
        outputs.input(&scene);
        let another_spelling = dir.join(".").join("scene.ron");
        assert!(outputs.claim(&another_spelling, sign).unwrap_err().to_string().contains("input"));
        assert!(outputs.claim(&theirs, sign).unwrap_err().to_string().contains("--force"));
        outputs.claim(&ours, sign).unwrap();
        outputs.claim(&dir.join("new.exr"), sign).unwrap();
        let again = dir.join("x").join("..").join("new.exr");
        std::fs::create_dir_all(dir.join("x")).unwrap();
        assert!(outputs.claim(&again, sign).unwrap_err().to_string().contains("twice"));

        let mut forced = Outputs::new(true);
        forced.input(&scene);
        forced.claim(&theirs, sign).unwrap();
        assert!(forced.claim(&scene, sign).is_err(), "--force never replaces an input");
    }
}
