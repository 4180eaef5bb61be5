//! Scene files in RON: load with errors that name file, line, column and
//! field; save in a form that loads back to an equal scene.

use std::path::{Path, PathBuf};

use std::sync::Arc;

use super::mesh::{builtin_mesh, is_builtin, load_mesh, MeshError, Meshes};
use super::{Invalid, Scene, Shape, ValidScene};
use crate::fileio::{self, FileError};
use crate::limits;

#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    /// Not read or not written: the path and the OS's reason.
    #[error(transparent)]
    File(#[from] FileError),
    /// The text is not a well-formed scene (bad syntax, unknown or missing field).
    #[error("{path}:{line}:{column}: {message}")]
    Syntax { path: PathBuf, line: usize, column: usize, message: String },
    /// Well-formed but a value is unusable; the position is the field's.
    #[error("{path}:{line}:{column}: {invalid}{more}", more = more_note(*.others))]
    Invalid { path: PathBuf, line: usize, column: usize, invalid: Box<Invalid>, others: usize },
    #[error("could not write the scene: {0}")]
    Serialize(String),
    /// A mesh the scene names could not be read; the position is its `file`.
    #[error("{path}:{line}:{column}: {error}")]
    Mesh { path: PathBuf, line: usize, column: usize, error: Box<MeshError> },
}

fn more_note(others: usize) -> String {
    match others {
        0 => String::new(),
        n => format!(" (and {n} more problem{})", if n == 1 { "" } else { "s" }),
    }
}

/// Read and validate a scene file: a regular file of at most
/// `limits::TEXT_FILE_BYTES`, UTF-8.
pub fn load_scene(path: &Path) -> Result<ValidScene, SceneFileError> {
    let text = fileio::read_text(path, limits::TEXT_FILE_BYTES)?;
    parse_scene(&text, path)
}

/// Parse and validate scene text, reading the meshes it names from beside
/// `path`.
pub fn parse_scene(text: &str, path: &Path) -> Result<ValidScene, SceneFileError> {
    parse_scene_with(text, path, &Meshes::default())
}

/// `parse_scene`, taking the meshes `loaded` holds from it rather than
/// from their files (an autosave read back beside the scene it was made from).
pub fn parse_scene_with(text: &str, path: &Path, loaded: &Meshes) -> Result<ValidScene, SceneFileError> {
    let mut scene: Scene = ron::Options::default().from_str(text).map_err(|e| SceneFileError::Syntax {
        path: path.to_owned(),
        line: e.span.start.line,
        column: e.span.start.col,
        message: e.code.to_string(),
    })?;
    load_meshes(&mut scene, text, path, loaded)?;
    let mut problems = match ValidScene::new(scene) {
        Ok(valid) => return Ok(valid),
        Err(problems) => problems,
    };
    let others = problems.len() - 1;
    let invalid = problems.swap_remove(0);
    let (line, column) = locate(text, invalid.section, invalid.index, invalid.key);
    Err(SceneFileError::Invalid { path: path.to_owned(), line, column, invalid: Box::new(invalid), others })
}

/// Read each mesh file the scene's objects name, once, from beside `path`
/// (or take it from `loaded`), within `limits::MESH_TRIANGLES` all told.
/// Once read, a mesh is named by its full path: the scene can be saved in
/// any folder, and its autosave restored from anywhere (`save_scene`
/// writes the name relative again where it can). A built-in mesh keeps
/// its name.
fn load_meshes(scene: &mut Scene, text: &str, path: &Path, loaded: &Meshes) -> Result<(), SceneFileError> {
    let folder = folder_of(path);
    for index in 0..scene.objects.len() {
        let Shape::Mesh { file, .. } = &mut scene.objects[index].shape else { continue };
        if let Some(full) = folder.join(&*file).to_str().filter(|_| !is_builtin(file)) {
            *file = full.to_owned();
        }
        let file = file.clone();
        if scene.meshes.get(&file).is_some() {
            continue;
        }
        let mesh = match loaded.get(&file) {
            Some(mesh) => Ok(mesh.clone()),
            None if is_builtin(&file) => builtin_mesh(&file).map(Arc::new),
            None => load_mesh(&folder.join(&file)).map(Arc::new),
        };
        let mesh = mesh.and_then(|mesh| match scene.meshes.triangles() + mesh.triangles.len() {
            count if count > limits::MESH_TRIANGLES => Err(MeshError::TooMany { path: folder.join(&file), count }),
            _ => Ok(mesh),
        });
        match mesh {
            Ok(mesh) => scene.meshes.insert(file, mesh),
            Err(error) => {
                let (line, column) = locate(text, "objects", Some(index), "file");
                return Err(SceneFileError::Mesh { path: path.to_owned(), line, column, error: Box::new(error) });
            }
        }
    }
    Ok(())
}

pub fn to_ron(scene: &Scene) -> Result<String, SceneFileError> {
    let config = ron::ser::PrettyConfig::new().depth_limit(4).struct_names(false);
    ron::ser::to_string_pretty(scene, config).map_err(|e| SceneFileError::Serialize(e.to_string()))
}

/// Write the scene atomically: a failed save leaves the old file whole.
/// A mesh inside the file's folder is named relative to it, so the folder
/// can move as a whole; any other by its full path.
pub fn save_scene(scene: &Scene, path: &Path) -> Result<(), SceneFileError> {
    let folder = folder_of(path);
    let mut written = scene.clone();
    for object in &mut written.objects {
        let Shape::Mesh { file, .. } = &mut object.shape else { continue };
        if is_builtin(file) {
            continue;
        }
        let full = folder.join(&*file);
        if let Some(inside) = full.strip_prefix(&folder).ok().and_then(Path::to_str) {
            *file = inside.to_owned();
        }
    }
    let text = to_ron(&written)? + "\n";
    Ok(fileio::write_bytes(path, text.as_bytes())?)
}

/// The full path of the folder `path` is in.
fn folder_of(path: &Path) -> PathBuf {
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::path::absolute(folder).unwrap_or_else(|_| folder.to_owned())
}

/// Where an invalid value sits in the text: the section, then its list's
/// item by place (RON gives no spans after deserialising; names can repeat
/// and be written in any field order), then `key:` within that item.
fn locate(text: &str, section: &str, index: Option<usize>, key: &str) -> (usize, usize) {
    let section = if section == "scene" { Some(0) } else { find_key(text, 0, section) };
    let mut at = section.unwrap_or(0);
    let mut end = text.len();
    if let (Some(section), Some(index)) = (section, index) {
        if let Some(item) = list_item(text, section, index) {
            (at, end) = (item.start, item.end);
        }
    }
    if let Some(found) = find_key(&text[..end], at, key) {
        at = found;
    }
    line_column(text, at)
}

/// The `index`th item of the first list after `from`: what lies between
/// its commas at the list's own depth, strings and comments skipped.
fn list_item(text: &str, from: usize, index: usize) -> Option<std::ops::Range<usize>> {
    let bytes = text.as_bytes();
    let open = from + text[from..].find('[')?;
    let (mut depth, mut item, mut start) = (0usize, 0usize, open + 1);
    let mut i = open;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                // To the closing quote, over escapes
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => i = text[i..].find('\n').map_or(bytes.len(), |n| i + n),
            b'/' if bytes.get(i + 1) == Some(&b'*') => i = text[i + 2..].find("*/").map_or(bytes.len(), |n| i + n + 3),
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    return (item == index).then_some(start..i);
                }
            }
            b',' if depth == 1 => {
                if item == index {
                    return Some(start..i);
                }
                item += 1;
                start = i + 1;
            }
            _ => {}
        }
        i += 1;
    }
    None
}

/// Byte offset of `key` followed by optional spaces and `:` at or after `from`.
fn find_key(text: &str, from: usize, key: &str) -> Option<usize> {
    let mut start = from;
    while let Some(found) = text[start..].find(key) {
        let at = start + found;
        let before_ok = at == 0 || !text.as_bytes()[at - 1].is_ascii_alphanumeric() && text.as_bytes()[at - 1] != b'_';
        let after = text[at + key.len()..].trim_start();
        if before_ok && after.starts_with(':') {
            return Some(at);
        }
        start = at + key.len();
    }
    None
}

fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(offset, |nl| offset - nl - 1) + 1;
    (line, column)
}
