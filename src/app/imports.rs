//! Meshes read on threads of their own: a file of millions of triangles
//! takes seconds to read, which the window spent frozen. The status bar
//! says what is being read and offers to cancel; a mesh joins the scene
//! once it is read, as one edit.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, TryRecvError};

use eframe::egui;

use crate::scene::mesh::{load_mesh, MeshData, MeshError};

/// What reads a mesh file (`load_mesh`, or a test's stand-in).
type Reader = fn(&Path) -> Result<MeshData, MeshError>;

/// A read that ended: the file and what it gave.
pub type Imported = (PathBuf, Result<MeshData, String>);

#[derive(Default)]
pub struct Imports {
    reading: Vec<(PathBuf, Receiver<Result<MeshData, MeshError>>)>,
}

impl Imports {
    /// Start reading `path`; a frame is asked for when it is read.
    pub fn start(&mut self, path: PathBuf, ctx: &egui::Context) {
        self.start_with(path, ctx, load_mesh);
    }

    /// `start`, the file read by `read`.
    fn start_with(&mut self, path: PathBuf, ctx: &egui::Context, read: Reader) {
        let (send, receive) = mpsc::channel();
        let (file, ctx) = (path.clone(), ctx.clone());
        let thread = move || {
            // Nobody waits for a cancelled read's mesh: it is dropped here
            let _ = send.send(read(&file));
            ctx.request_repaint();
        };
        match std::thread::Builder::new().name("import".into()).spawn(thread) {
            Ok(_) => self.reading.push((path, receive)),
            // No thread to be had: read it here, as before
            Err(_) => {
                let (send, receive) = mpsc::channel();
                let _ = send.send(read(&path));
                self.reading.push((path, receive));
            }
        }
    }

    /// The reads that ended since the last call, in the order they began.
    pub fn finished(&mut self) -> Vec<Imported> {
        let mut done = Vec::new();
        self.reading.retain(|(path, receive)| match receive.try_recv() {
            Ok(read) => {
                done.push((path.clone(), read.map_err(|e| e.to_string())));
                false
            }
            Err(TryRecvError::Empty) => true,
            Err(TryRecvError::Disconnected) => {
                done.push((path.clone(), Err(format!("{}: the import stopped", path.display()))));
                false
            }
        });
        done
    }

    pub fn is_reading(&self) -> bool {
        !self.reading.is_empty()
    }

    /// "Reading bunny.ply…" and a button that cancels every read.
    pub fn reading_ui(&mut self, ui: &mut egui::Ui) {
        if self.reading.is_empty() {
            return;
        }
        let names: Vec<String> = self
            .reading
            .iter()
            .map(|(path, _)| path.file_name().unwrap_or_default().to_string_lossy().into())
            .collect();
        ui.spinner();
        ui.label(format!("Reading {}…", names.join(", ")));
        if ui.small_button("Cancel").clicked() {
            self.cancel();
        }
    }

    /// Stop waiting for every read: their threads finish the file, and
    /// their meshes are dropped.
    pub fn cancel(&mut self) {
        self.reading.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Held until the test lets the read end.
    static GATE: std::sync::Mutex<()> = std::sync::Mutex::new(());

    fn gated(_: &Path) -> Result<MeshData, MeshError> {
        drop(GATE.lock());
        Ok(MeshData::new(vec![[glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z]]))
    }

    /// A read in progress says so; one cancelled gives nothing when it
    /// ends; one not cancelled gives its mesh, once.
    #[test]
    fn a_cancelled_read_gives_nothing() {
        let ctx = egui::Context::default();
        let mut imports = Imports::default();
        let held = GATE.lock().expect("the gate");
        imports.start_with("a.obj".into(), &ctx, gated);
        assert!(imports.is_reading() && imports.finished().is_empty());
        imports.cancel();
        drop(held);
        imports.start_with("b.obj".into(), &ctx, gated);
        let mut done = Vec::new();
        while done.is_empty() {
            done = imports.finished();
            std::thread::yield_now();
        }
        assert_eq!(done.len(), 1);
        assert_eq!(done[0].0, PathBuf::from("b.obj"));
        assert!(matches!(&done[0].1, Ok(mesh) if mesh.triangles.len() == 1), "{:?}", done[0].1.as_ref().err());
        assert!(!imports.is_reading() && imports.finished().is_empty());
    }
}
