//! The studio's state on disk: one RON map of keys to strings (the shape of
//! eframe's storage, in the file eframe used, so layouts and autosaves of
//! earlier versions are found), read once at start and written atomically.
//! eframe's own persistence is off: it wrote in place, and restored egui's
//! memory (zoom and all) before the app could check it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::fileio::{self, FileError};
use crate::limits;
use crate::render::RenderSettings;

/// What survives a restart: the layout, each pane's settings, the files.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default)]
pub struct Persisted {
    pub panes: Vec<RenderSettings>,
    pub exposures: Vec<f32>,
    pub show_plots: bool,
    pub recent: Vec<PathBuf>,
}

impl Default for Persisted {
    fn default() -> Self {
        Self { panes: Vec::new(), exposures: Vec::new(), show_plots: true, recent: Vec::new() }
    }
}

/// Saved state made safe to start from: a pane whose saved settings break
/// a limit gets its defaults (`None`), and every fallback is said.
pub struct Restored {
    pub panes: Vec<Option<RenderSettings>>,
    pub exposures: Vec<f32>,
    pub show_plots: bool,
    pub recent: Vec<PathBuf>,
    pub notices: Vec<String>,
}

impl Persisted {
    /// The saved state checked as a scene file is: whatever it holds, the
    /// studio starts, and values out of their limits fall back to defaults.
    pub fn restore(self) -> Restored {
        let mut notices = Vec::new();
        if self.panes.len() > 4 {
            notices.push(format!("{} saved panes; the studio shows at most 4", self.panes.len()));
        }
        let panes = (self.panes.into_iter().take(4).enumerate())
            .map(|(i, settings)| match settings.problems().first() {
                None => Some(settings),
                Some(problem) => {
                    notices.push(format!("pane {}'s saved {problem}; its defaults are used", i + 1));
                    None
                }
            })
            .collect();
        let exposures = (self.exposures.into_iter().take(4).enumerate())
            .map(|(i, exposure)| {
                limits::EXPOSURE_STOPS.check(exposure).unwrap_or_else(|problem| {
                    notices.push(format!("pane {}'s saved exposure {problem}; 0 is used", i + 1));
                    0.0
                })
            })
            .collect();
        let recent = self.recent.into_iter().take(RECENT_FILES).collect();
        Restored { panes, exposures, show_plots: self.show_plots, recent, notices }
    }
}

const RECENT_FILES: usize = 8;

pub struct StateFile {
    path: PathBuf,
    values: BTreeMap<String, String>,
}

/// `$XDG_DATA_HOME/gistudio` (else `~/.local/share/gistudio`), as eframe
/// named the app's folder.
pub fn state_folder() -> Option<PathBuf> {
    let data = std::env::var_os("XDG_DATA_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::home_dir().map(|home| home.join(".local").join("share")))?;
    Some(data.join("gistudio"))
}

impl StateFile {
    /// The state at `path`; an unreadable file gives an empty state and
    /// a notice saying why (it is replaced at the next save).
    pub fn open(path: PathBuf) -> (Self, Option<String>) {
        let (values, notice) = match fileio::read_text(&path, limits::TEXT_FILE_BYTES) {
            Ok(text) => match ron::from_str::<BTreeMap<String, String>>(&text) {
                Ok(values) => (values, None),
                Err(e) => {
                    (BTreeMap::new(), Some(format!("{}: unreadable saved state ({e}); defaults used", path.display())))
                }
            },
            Err(FileError::Io { cause, .. }) if cause.kind() == std::io::ErrorKind::NotFound => (BTreeMap::new(), None),
            Err(e) => (BTreeMap::new(), Some(format!("{e}; defaults used"))),
        };
        (Self { path, values }, notice)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Write the state, atomically.
    pub fn write(&self) -> Result<(), String> {
        let text =
            ron::ser::to_string_pretty(&self.values, ron::ser::PrettyConfig::new()).map_err(|e| e.to_string())?;
        if let Some(folder) = self.path.parent() {
            std::fs::create_dir_all(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
        }
        fileio::write_bytes(&self.path, text.as_bytes()).map_err(|e| e.to_string())
    }
}

impl eframe::Storage for StateFile {
    fn get_string(&self, key: &str) -> Option<String> {
        self.values.get(key).cloned()
    }

    fn set_string(&mut self, key: &str, value: String) {
        self.values.insert(key.to_owned(), value);
    }

    fn remove_string(&mut self, key: &str) {
        self.values.remove(key);
    }

    /// The studio calls `write`, which reports its error.
    fn flush(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use eframe::Storage as _;

    #[test]
    fn state_round_trips_and_a_broken_file_gives_a_notice() {
        let dir = std::env::temp_dir().join(format!("gi-state-{}", std::process::id()));
        let path = dir.join("app.ron");
        let _ = std::fs::remove_dir_all(&dir);
        let (mut state, notice) = StateFile::open(path.clone());
        assert!(notice.is_none(), "a missing file is a first start, not a problem");
        state.set_string("studio", "(panes: [])".into());
        state.write().unwrap();
        let (again, notice) = StateFile::open(path.clone());
        assert!(notice.is_none());
        assert_eq!(again.get_string("studio").as_deref(), Some("(panes: [])"));

        std::fs::write(&path, "{ not ron").unwrap();
        let (broken, notice) = StateFile::open(path.clone());
        assert!(broken.get_string("studio").is_none());
        assert!(notice.unwrap().contains("app.ron"));
    }
}
