//! Triangle meshes from files: Wavefront OBJ (polygons triangulated as
//! fans, through `tobj`; its MTL files are not read, the object's material
//! is the scene's) and PLY (ASCII and binary of either byte order, faces
//! in `vertex_indices` or `vertex_index`, through `ply-rs-bw`). What is
//! read is bounded by `limits`: the file's size first, then the counts a
//! PLY header declares against what that size can hold. The meshes the
//! built-in scenes use are compiled in and named `builtin:` and their file's
//! name, so that those scenes open, and save, anywhere.

use std::collections::BTreeMap;
use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

use crate::fileio::{self, FileError};
use crate::limits;

/// A mesh's triangles as its file gives them (before the object's
/// placement), front side by the winding.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    pub triangles: Vec<[Vec3; 3]>,
    /// FNV-1a of the triangles' bits: what `Scene::content_key` holds of it.
    pub key: u64,
}

impl MeshData {
    pub fn new(triangles: Vec<[Vec3; 3]>) -> Self {
        let bits = triangles.iter().flatten().flat_map(|v| v.to_array()).flat_map(|c| c.to_bits().to_le_bytes());
        let key = bits.fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
        MeshData { triangles, key }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error(transparent)]
    File(#[from] FileError),
    #[error("{path}: {message}")]
    Format { path: PathBuf, message: String },
    #[error("{path}: {count} triangles, more than the {} a scene may hold", limits::MESH_TRIANGLES)]
    TooMany { path: PathBuf, count: usize },
    #[error("{path}: no triangles")]
    Empty { path: PathBuf },
    #[error("{path}: \"{extension}\" is not a mesh file this reads (.obj or .ply)")]
    Kind { path: PathBuf, extension: String },
    #[error("\"{name}\" is not a built-in mesh (those are {})", builtin_names().collect::<Vec<_>>().join(", "))]
    NotBuiltIn { name: String },
}

/// What names a compiled-in mesh rather than a file.
pub const BUILTIN: &str = "builtin:";

/// (file name, bytes) of the meshes the built-in scenes use, written by
/// `assets/meshes/make_meshes.py`.
const BUILTIN_MESHES: &[(&str, &[u8])] = &[
    ("cornell-white.obj", include_bytes!("../../assets/meshes/cornell-white.obj")),
    ("cornell-red.obj", include_bytes!("../../assets/meshes/cornell-red.obj")),
    ("cornell-green.obj", include_bytes!("../../assets/meshes/cornell-green.obj")),
    ("torus-knot.ply", include_bytes!("../../assets/meshes/torus-knot.ply")),
];

/// Every built-in mesh's name as a scene writes it (`builtin:torus-knot.ply`).
pub fn builtin_names() -> impl Iterator<Item = String> {
    BUILTIN_MESHES.iter().map(|(name, _)| format!("{BUILTIN}{name}"))
}

/// Whether a scene's `file` names a compiled-in mesh.
pub fn is_builtin(file: &str) -> bool {
    file.starts_with(BUILTIN)
}

/// The meshes a scene's objects name, loaded, by the name as written.
#[derive(Clone, Debug, Default)]
pub struct Meshes(BTreeMap<String, Arc<MeshData>>);

impl PartialEq for Meshes {
    fn eq(&self, other: &Self) -> bool {
        self.0.len() == other.0.len()
            // By each mesh's key: comparing scenes never walks millions of triangles
            && (self.0.iter().zip(&other.0)).all(|((a, x), (b, y))| a == b && x.key == y.key)
    }
}

impl Meshes {
    pub fn get(&self, file: &str) -> Option<&Arc<MeshData>> {
        self.0.get(file)
    }

    pub fn insert(&mut self, file: String, mesh: Arc<MeshData>) {
        self.0.insert(file, mesh);
    }

    /// Each mesh's key (`MeshData::key`), in the order of their names.
    pub fn keys(&self) -> impl Iterator<Item = u64> + '_ {
        self.0.values().map(|mesh| mesh.key)
    }

    /// Triangles in every mesh held.
    pub fn triangles(&self) -> usize {
        self.0.values().map(|mesh| mesh.triangles.len()).sum()
    }
}

/// The mesh in `path`, by its extension.
pub fn load_mesh(path: &Path) -> Result<MeshData, MeshError> {
    let extension = extension_of(path);
    let bytes = match extension.as_str() {
        "obj" | "ply" => fileio::read_bounded(path, limits::MESH_FILE_BYTES)?,
        _ => return Err(MeshError::Kind { path: path.to_owned(), extension }),
    };
    read_mesh(&bytes, &extension, path)
}

/// The compiled-in mesh a scene names `builtin:name`.
pub fn builtin_mesh(file: &str) -> Result<MeshData, MeshError> {
    let name = file.strip_prefix(BUILTIN).unwrap_or(file);
    let Some((_, bytes)) = BUILTIN_MESHES.iter().find(|(n, _)| *n == name) else {
        return Err(MeshError::NotBuiltIn { name: file.to_owned() });
    };
    let path = Path::new(file);
    read_mesh(bytes, &extension_of(path), path)
}

fn extension_of(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// A mesh from its file's bytes, read by the format `extension` names;
/// `path` names it in errors.
fn read_mesh(bytes: &[u8], extension: &str, path: &Path) -> Result<MeshData, MeshError> {
    let format = |message: String| MeshError::Format { path: path.to_owned(), message };
    let triangles = match extension {
        "obj" => obj_triangles(bytes).map_err(format)?,
        "ply" => ply_triangles(bytes).map_err(format)?,
        _ => return Err(MeshError::Kind { path: path.to_owned(), extension: extension.to_owned() }),
    };
    match triangles.len() {
        0 => Err(MeshError::Empty { path: path.to_owned() }),
        count if count > limits::MESH_TRIANGLES => Err(MeshError::TooMany { path: path.to_owned(), count }),
        _ => Ok(MeshData::new(triangles)),
    }
}

/// An OBJ's faces as triangles, each polygon as a fan.
fn obj_triangles(bytes: &[u8]) -> Result<Vec<[Vec3; 3]>, String> {
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    // Materials are the scene's: the MTL file is not opened
    let no_materials = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(Cursor::new(bytes)), &options, no_materials)
        .map_err(|e| format!("not a Wavefront OBJ file this reads: {e}"))?;
    let mut triangles = Vec::new();
    for model in &models {
        let (positions, indices) = (&model.mesh.positions, &model.mesh.indices);
        let vertex = |i: u32| {
            let at = i as usize * 3;
            (positions.get(at..at + 3)).map(|p| Vec3::new(p[0], p[1], p[2])).ok_or_else(|| {
                format!("object \"{}\": a face names vertex {} of {}", model.name, i + 1, positions.len() / 3)
            })
        };
        for face in indices.chunks_exact(3) {
            triangles.push([vertex(face[0])?, vertex(face[1])?, vertex(face[2])?]);
            if triangles.len() > limits::MESH_TRIANGLES {
                break;
            }
        }
    }
    Ok(triangles)
}

#[derive(Default)]
struct PlyVertex(Vec3);

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, key: &str, property: Property) -> PropertyAccessResult {
        let value = match property {
            Property::Float(v) => v,
            Property::Double(v) => v as f32,
            Property::Char(v) => v as f32,
            Property::UChar(v) => v as f32,
            Property::Short(v) => v as f32,
            Property::UShort(v) => v as f32,
            Property::Int(v) => v as f32,
            Property::UInt(v) => v as f32,
            _ => return PropertyAccessResult::Ignored,
        };
        match key {
            "x" => self.0.x = value,
            "y" => self.0.y = value,
            "z" => self.0.z = value,
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

/// A face's vertex indices; `None` for one whose list held a negative.
#[derive(Default)]
struct PlyFace(Option<Vec<u32>>);

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, key: &str, property: Property) -> PropertyAccessResult {
        if key != "vertex_indices" && key != "vertex_index" {
            return PropertyAccessResult::Ignored;
        }
        let unsigned = |v: Vec<i64>| v.into_iter().map(|i| u32::try_from(i).ok()).collect::<Option<Vec<u32>>>();
        self.0 = match property {
            Property::ListUInt(v) => Some(v),
            Property::ListInt(v) => unsigned(v.into_iter().map(i64::from).collect()),
            Property::ListUShort(v) => Some(v.into_iter().map(u32::from).collect()),
            Property::ListShort(v) => unsigned(v.into_iter().map(i64::from).collect()),
            Property::ListUChar(v) => Some(v.into_iter().map(u32::from).collect()),
            Property::ListChar(v) => unsigned(v.into_iter().map(i64::from).collect()),
            _ => return PropertyAccessResult::Ignored,
        };
        PropertyAccessResult::Set
    }
}

/// A PLY's faces as triangles, each polygon as a fan.
fn ply_triangles(bytes: &[u8]) -> Result<Vec<[Vec3; 3]>, String> {
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = Parser::<PlyVertex>::new().read_header(&mut reader).map_err(|e| format!("its header: {e}"))?;
    // A vertex takes at least six bytes and a face four, in either form:
    // counts beyond what the file can hold are refused before anything
    // is allocated for them
    for (name, least) in [("vertex", 6), ("face", 4)] {
        if let Some(element) = header.elements.get(name) {
            if element.count.saturating_mul(least) > bytes.len() {
                return Err(format!("its header declares {} {name} elements, more than the file holds", element.count));
            }
        }
    }
    let (Some(vertex), Some(face)) = (header.elements.get("vertex"), header.elements.get("face")) else {
        return Err("no \"vertex\" or no \"face\" element".into());
    };
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    // Elements in the file's order, each read whole
    for (name, element) in &header.elements {
        let read = |e: &dyn std::fmt::Display| format!("its {name} elements: {e}");
        if name == &vertex.name {
            vertices = (Parser::<PlyVertex>::new().read_payload_for_element(&mut reader, element, &header))
                .map_err(|e| read(&e))?;
        } else if name == &face.name {
            faces = (Parser::<PlyFace>::new().read_payload_for_element(&mut reader, element, &header))
                .map_err(|e| read(&e))?;
        } else {
            (Parser::<PlyFace>::new().read_payload_for_element(&mut reader, element, &header)).map_err(|e| read(&e))?;
        }
    }
    let mut triangles = Vec::new();
    for (k, face) in faces.iter().enumerate() {
        let indices = face.0.as_deref().ok_or_else(|| format!("face {k} names a negative vertex"))?;
        let point = |i: u32| {
            (vertices.get(i as usize).map(|v| v.0))
                .ok_or_else(|| format!("face {k} names vertex {i}, of {} vertices", vertices.len()))
        };
        for pair in indices.get(1..).unwrap_or(&[]).windows(2) {
            triangles.push([point(indices[0])?, point(pair[0])?, point(pair[1])?]);
        }
        if triangles.len() > limits::MESH_TRIANGLES {
            break;
        }
    }
    Ok(triangles)
}
