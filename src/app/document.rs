//! The document: the scene being edited, its file, its history and its
//! revision. Every edit bumps the revision (the widgets say when they
//! changed something), so nothing compares scenes frame by frame; the scene
//! is checked once per revision, and each valid revision becomes one
//! `ValidScene` snapshot for the panes and one `World` for picking.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::history::History;
use crate::render::world::camera::CameraModel;
use crate::render::world::World;
use crate::scene::mesh::MeshData;
use crate::scene::presets::default_scene;
use crate::scene::{load_scene, save_scene, to_ron, Invalid, Object, Scene, SceneFileError, Shape, ValidScene};
use glam::Vec3;

/// `base`, or `base 2`, `base 3`, … : the first that `taken` does not hold.
pub fn unique_name(base: &str, taken: impl Fn(&str) -> bool) -> String {
    (1..).map(|n| if n == 1 { base.to_owned() } else { format!("{base} {n}") }).find(|n| !taken(n)).unwrap_or_default()
}

/// A place in view to put a new object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    pub point: glam::Vec3,
    /// The surface's normal there, toward the camera.
    pub normal: glam::Vec3,
    /// How far it is from the camera.
    pub distance: f32,
}

pub struct Document {
    scene: Scene,
    path: Option<PathBuf>,
    revision: u64,
    /// Revisions are never reused: an undo returns to an old number.
    next_revision: u64,
    /// The revision the file holds (None: nothing saved matches).
    saved: Option<u64>,
    history: History,
    /// The revision last checked, what was wrong with it, and the newest
    /// valid snapshot with its world.
    checked: u64,
    problems: Vec<Invalid>,
    valid: Option<(Arc<ValidScene>, Arc<World>)>,
}

impl Document {
    /// A document holding `scene`, saved (`path`) or not; `clean` when it
    /// is what its source holds (a file, a preset).
    pub fn new(scene: Scene, path: Option<PathBuf>, clean: bool) -> Self {
        let history = History::new(&scene, 1);
        let mut document = Self {
            scene,
            path,
            revision: 1,
            next_revision: 2,
            saved: clean.then_some(1),
            history,
            checked: 0,
            problems: Vec::new(),
            valid: None,
        };
        document.check();
        document
    }

    /// The document the studio opens on: `--scene`'s file, else the
    /// built-in Cornell box (and why, if the file would not load).
    pub fn starting(scene_file: Option<&Path>) -> (Self, Option<String>) {
        match scene_file.map(|path| (path, load_scene(path))) {
            Some((path, Ok(scene))) => (Self::new(scene.into_scene(), Some(path.to_owned()), true), None),
            Some((_, Err(e))) => (Self::new(default_scene(), None, true), Some(e.to_string())),
            None => (Self::new(default_scene(), None, true), None),
        }
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The scene to edit in place; say `changed` when something was.
    pub fn scene_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }

    /// The revision of the scene as it stands (a new one at every edit).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The scene was edited: a new revision.
    pub fn changed(&mut self) {
        self.revision = self.next_revision;
        self.next_revision += 1;
    }

    /// Add `mesh`, read from `path`, as an object, in view: on the surface
    /// at the centre of the view, a quarter of its distance across.
    /// Returns the object's index.
    pub fn add_mesh(&mut self, path: &Path, mesh: MeshData) -> usize {
        // Its own full path: the scene finds it wherever the scene is saved
        let file = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()).display().to_string();
        let (lo, hi) = (mesh.triangles.iter().flatten())
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        let spot = self.spot_in_view();
        let scale = spot.distance * 0.25 / (hi - lo).max_element().max(1e-6);
        // Its box's centre half its height above the surface
        let centre = (lo + hi) * 0.5;
        let translate = spot.point + spot.normal * ((hi - lo).max_element() * 0.5 * scale) - centre * scale;
        let stem = path.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        let scene = &mut self.scene;
        let name = unique_name(&stem, |n| scene.objects.iter().any(|o| o.name == n));
        let material = scene.materials.first().map(|m| m.name.clone()).unwrap_or_default();
        scene.meshes.insert(file.clone(), Arc::new(mesh));
        let shape = Shape::Mesh { file, translate, scale, rotate_degrees: Vec3::ZERO };
        scene.objects.push(Object { name, shape, material });
        self.changed();
        self.scene.objects.len() - 1
    }

    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    pub fn is_dirty(&self) -> bool {
        self.saved != Some(self.revision)
    }

    /// Commit the edits as one undo step once the user lets go.
    pub fn commit(&mut self, interacting: bool) {
        self.history.observe(&self.scene, self.revision, interacting);
    }

    pub fn can_undo(&self) -> bool {
        self.history.can_undo()
    }

    pub fn can_redo(&self) -> bool {
        self.history.can_redo()
    }

    pub fn undo(&mut self) {
        self.history.undo(&mut self.scene, &mut self.revision);
    }

    pub fn redo(&mut self) {
        self.history.redo(&mut self.scene, &mut self.revision);
    }

    /// Check the scene if its revision is new. Returns the new valid
    /// snapshot when there is one (the panes restart with it).
    pub fn check(&mut self) -> Option<Arc<ValidScene>> {
        if self.checked == self.revision {
            return None;
        }
        self.checked = self.revision;
        match ValidScene::new(self.scene.clone()) {
            Ok(valid) => {
                self.problems.clear();
                let world = Arc::new(World::new(&valid));
                let valid = Arc::new(valid);
                self.valid = Some((valid.clone(), world));
                Some(valid)
            }
            Err(problems) => {
                self.problems = problems;
                None
            }
        }
    }

    /// What is wrong with the scene (empty when it renders).
    pub fn problems(&self) -> &[Invalid] {
        &self.problems
    }

    /// The newest valid snapshot, if the scene as it stands is valid.
    pub fn valid(&self) -> Option<&Arc<ValidScene>> {
        self.valid.as_ref().filter(|_| self.problems.is_empty()).map(|(scene, _)| scene)
    }

    /// The object seen through film position (x, y) of a `width × height`
    /// image, through the world of the scene's last valid revision.
    pub fn pick(&self, width: u32, height: u32, x: f32, y: f32) -> Option<usize> {
        let (scene, world) = self.valid.as_ref().filter(|_| self.problems.is_empty())?;
        let ray = CameraModel::new(&scene.camera, width, height).pixel_ray(x, y);
        world.intersect(&ray, f32::INFINITY).map(|hit| hit.object as usize)
    }

    /// Where the centre of the view meets the scene (its last valid
    /// revision): the point, the surface's normal turned toward the camera,
    /// and the distance from the camera. Where nothing is met, the look-at
    /// point, facing the camera.
    pub fn spot_in_view(&self) -> Spot {
        let camera = &self.scene.camera;
        let to_look_at = camera.look_at - camera.position;
        let facing = -to_look_at.normalize_or(glam::Vec3::Z);
        let at_look_at = Spot { point: camera.look_at, normal: facing, distance: to_look_at.length().max(1e-3) };
        let Some((scene, world)) = self.valid.as_ref().filter(|_| self.problems.is_empty()) else { return at_look_at };
        let (width, height) = (scene.settings.width, scene.settings.height);
        let ray = CameraModel::new(&scene.camera, width, height).pixel_ray(width as f32 / 2.0, height as f32 / 2.0);
        match world.intersect(&ray, f32::INFINITY) {
            Some(hit) => {
                let normal = hit.surface.normal;
                let normal = if normal.dot(ray.direction) > 0.0 { -normal } else { normal };
                Spot { point: hit.surface.point, normal, distance: (hit.surface.point - ray.origin).length() }
            }
            None => at_look_at,
        }
    }

    /// Write the scene to `path`; it is the document's file from then on.
    pub fn save_to(&mut self, path: &Path) -> Result<(), SceneFileError> {
        save_scene(&self.scene, path)?;
        self.path = Some(path.to_owned());
        self.saved = Some(self.revision);
        Ok(())
    }

    /// The scene as an autosave holds it, while it has unsaved edits.
    pub fn autosave_text(&self) -> Option<Result<String, SceneFileError>> {
        self.is_dirty().then(|| to_ron(&self.scene))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn revisions_track_edits_undo_returns_to_clean_and_checks_happen_once() {
        let mut document = Document::new(default_scene(), None, true);
        assert!(!document.is_dirty() && document.valid().is_some());
        assert!(document.check().is_none(), "nothing new to check");
        document.scene_mut().camera.fov_y_degrees = 50.0;
        document.changed();
        document.commit(false);
        assert!(document.is_dirty());
        let snapshot = document.check().expect("a new valid revision");
        assert_eq!(snapshot.camera.fov_y_degrees, 50.0);
        document.scene_mut().objects[5].material = "nowhere".into();
        document.changed();
        assert!(document.check().is_none() && document.valid().is_none() && !document.problems().is_empty());
        document.undo();
        assert!(document.is_dirty());
        document.undo();
        assert!(!document.is_dirty(), "back at the saved revision");
        assert!(document.check().is_some());
    }
}
