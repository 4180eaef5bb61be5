//! The studio's state on disk: one RON map of keys to strings (the shape of
//! eframe's storage, in the file eframe used, so layouts and autosaves of
//! earlier versions are found), read once at start and written atomically.
//! eframe's own persistence is off: it wrote in place, and restored egui's
//! memory (zoom and all) before the app could check it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::pane::Pane;
use super::panes::Panes;
use crate::fileio::{self, FileError};
use crate::limits;
use crate::render::RenderSettings;
use crate::scene::Scene;

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

impl Persisted {
    /// What the studio keeps of its panes, panels and recent files.
    pub fn of(panes: &Panes, show_plots: bool, recent: &[PathBuf]) -> Self {
        let panes = panes.list();
        Self {
            panes: panes.iter().map(|p| p.settings().clone()).collect(),
            exposures: panes.iter().map(Pane::exposure).collect(),
            show_plots,
            recent: recent.to_vec(),
        }
    }
}

/// `path` first among the recent files, once, and no more of them than kept.
pub fn remember(recent: &mut Vec<PathBuf>, path: &Path) {
    recent.retain(|p| p != path);
    recent.insert(0, path.to_owned());
    recent.truncate(RECENT_FILES);
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

    /// The state as the file holds it.
    pub fn text(&self) -> Result<String, String> {
        ron::ser::to_string_pretty(&self.values, ron::ser::PrettyConfig::new()).map_err(|e| e.to_string())
    }

    /// Write the state, atomically.
    pub fn write(&self) -> Result<(), String> {
        self.write_text(&self.text()?)
    }

    fn write_text(&self, text: &str) -> Result<(), String> {
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

/// The two keys of the studio's state.
const STATE_KEY: &str = "studio";
const AUTOSAVE_KEY: &str = "autosave_scene";
/// How often the studio writes its state while it runs.
pub const SAVE_INTERVAL: std::time::Duration = std::time::Duration::from_secs(10);

/// What the autosave should hold after a save.
pub enum Autosave {
    /// Leave it as it is (a crashed session's scene is still on offer).
    Keep,
    /// No unsaved edits: nothing to offer back.
    Clear,
    Scene(String),
}

/// The saved layout and the autosaved scene, as a start reads them.
pub fn read_state(storage: Option<&dyn eframe::Storage>) -> (Restored, Option<String>) {
    let persisted: Persisted =
        storage.and_then(|s| s.get_string(STATE_KEY)).and_then(|text| ron::from_str(&text).ok()).unwrap_or_default();
    let autosave = storage.and_then(|s| s.get_string(AUTOSAVE_KEY)).filter(|t| !t.is_empty());
    (persisted.restore(), autosave)
}

/// A crashed session's unsaved scene, offered back.
pub struct AutosaveOffer {
    pub scene: Scene,
    /// What it has that the scene the studio opened on has not.
    pub edits: Vec<String>,
}

/// The autosaved scene, if it parses and differs from `scene`: what a
/// crashed session left unsaved.
pub fn autosave_offer(autosaved: Option<String>, scene: &Scene) -> Option<AutosaveOffer> {
    // Meshes are read back as the scene the studio opened on holds them
    let valid = crate::scene::parse_scene_with(&autosaved?, Path::new("autosave.ron"), &scene.meshes).ok()?;
    let offered = valid.into_scene();
    let edits = crate::scene::differences(scene, &offered, 6);
    (!edits.is_empty()).then_some(AutosaveOffer { scene: offered, edits })
}

/// Put the layout and the autosave into `storage`.
pub fn write_state(storage: &mut dyn eframe::Storage, persisted: &Persisted, autosave: Autosave) -> Result<(), String> {
    let text = ron::to_string(persisted).map_err(|e| format!("could not save the studio's layout: {e}"))?;
    storage.set_string(STATE_KEY, text);
    match autosave {
        Autosave::Keep => {}
        Autosave::Clear => storage.set_string(AUTOSAVE_KEY, String::new()),
        Autosave::Scene(text) => storage.set_string(AUTOSAVE_KEY, text),
    }
    Ok(())
}

/// The state file and when it was last written: every few seconds while
/// the studio runs (a crash loses at most that), and when it closes; never
/// by a `--screenshot` run, which only reads it. A state that has not
/// changed since it was last written is not written again.
pub struct StateKeeper {
    file: Option<StateFile>,
    last_write: std::time::Instant,
    interval: std::time::Duration,
    read_only: bool,
    /// The text last written (or read): the file holds it already.
    on_disk: Option<String>,
}

impl StateKeeper {
    pub fn new(read_only: bool) -> Self {
        Self { file: None, last_write: std::time::Instant::now(), interval: SAVE_INTERVAL, read_only, on_disk: None }
    }

    /// Keep the state in `file`, written every `interval`.
    pub fn keep_in(&mut self, file: StateFile, interval: std::time::Duration) {
        self.on_disk = file.text().ok();
        self.file = Some(file);
        self.interval = interval;
    }

    pub fn read_only(&self) -> bool {
        self.read_only
    }

    /// How long until the next write is due (None: the studio writes none).
    pub fn due_in(&self) -> Option<std::time::Duration> {
        let writes = self.file.is_some() && !self.read_only;
        writes.then(|| self.interval.saturating_sub(self.last_write.elapsed()))
    }

    /// The file to fill, if a write is due (or `now`): taken out until
    /// `put_back`, so the studio can fill it while it holds the keeper.
    pub fn take(&mut self, now: bool) -> Option<StateFile> {
        if self.due_in().is_none_or(|wait| !now && !wait.is_zero()) {
            return None;
        }
        self.last_write = std::time::Instant::now();
        self.file.take()
    }

    /// Keep `file` again, and write it if it changed since the last write.
    pub fn put_back(&mut self, file: StateFile) -> Result<(), String> {
        let text = file.text();
        self.file = Some(file);
        let text = text.map_err(|e| format!("could not save the studio's state: {e}"))?;
        if self.on_disk.as_ref() == Some(&text) {
            return Ok(());
        }
        let Some(file) = &self.file else { return Ok(()) };
        file.write_text(&text).map_err(|e| format!("could not save the studio's state: {e}"))?;
        self.on_disk = Some(text);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use eframe::Storage as _;

    #[test]
    fn state_round_trips_and_a_broken_file_gives_a_notice() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
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
