//! Meshes from files: OBJ and PLY (ASCII, binary of both byte orders)
//! read to the same triangles; a scene's `Mesh` placed as its transform
//! says renders exactly as the same triangles typed one by one; a broken
//! or missing mesh is refused with the scene's line and the mesh's file.

mod common;

use std::path::Path;
use std::sync::Arc;

use gi_studio::render::{render_blocking, Algorithm, LinearImage, RenderJob, RenderSettings};
use gi_studio::scene::mesh::{load_mesh, MeshError};
use gi_studio::scene::{
    load_scene, parse_scene_with, save_scene, to_ron, Object, Problem, SceneFileError, Shape, ValidScene,
};
use glam::Vec3;

/// A unit cube's corners and its six faces as quads, wound outward.
const CORNERS: [[f32; 3]; 8] =
    [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
const QUADS: [[u32; 4]; 6] = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]];

fn cube_obj() -> String {
    let mut text = String::from("# a cube\no cube\n");
    for [x, y, z] in CORNERS {
        text += &format!("v {x} {y} {z}\n");
    }
    for quad in QUADS {
        text += &format!("f {} {} {} {}\n", quad[0] + 1, quad[1] + 1, quad[2] + 1, quad[3] + 1);
    }
    text
}

/// The cube as PLY in `format`, its faces' list named `list` with indices
/// of `index_type`.
fn cube_ply(format: &str, list: &str, index_type: &str) -> Vec<u8> {
    let header = format!(
        "ply\nformat {format} 1.0\ncomment a cube\nelement vertex 8\nproperty float x\nproperty float y\n\
         property float z\nelement face 6\nproperty list uchar {index_type} {list}\nend_header\n"
    );
    let mut bytes = header.into_bytes();
    let big = format == "binary_big_endian";
    let float = |bytes: &mut Vec<u8>, v: f32| bytes.extend(if big { v.to_be_bytes() } else { v.to_le_bytes() });
    for corner in CORNERS {
        match format {
            "ascii" => bytes.extend(format!("{} {} {}\n", corner[0], corner[1], corner[2]).bytes()),
            _ => corner.into_iter().for_each(|v| float(&mut bytes, v)),
        }
    }
    for quad in QUADS {
        match format {
            "ascii" => bytes.extend(format!("4 {} {} {} {}\n", quad[0], quad[1], quad[2], quad[3]).bytes()),
            _ => {
                bytes.push(4);
                for i in quad {
                    match (index_type, big) {
                        ("uchar", _) => bytes.push(i as u8),
                        (_, true) => bytes.extend((i as i32).to_be_bytes()),
                        (_, false) => bytes.extend((i as i32).to_le_bytes()),
                    }
                }
            }
        }
    }
    bytes
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("a temporary file");
    path
}

/// The cube's faces as fans: what every reader must give, in order.
fn cube_triangles() -> Vec<[Vec3; 3]> {
    let corner = |i: u32| Vec3::from_array(CORNERS[i as usize]);
    QUADS
        .iter()
        .flat_map(|q| [[corner(q[0]), corner(q[1]), corner(q[2])], [corner(q[0]), corner(q[2]), corner(q[3])]])
        .collect()
}

#[test]
fn obj_and_every_ply_form_read_the_same_triangles() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let expected = cube_triangles();
    let obj = load_mesh(&write(dir.path(), "cube.obj", cube_obj())).expect("the OBJ cube");
    assert_eq!(obj.triangles, expected);
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        for (list, index_type) in [("vertex_indices", "int"), ("vertex_index", "uchar"), ("vertex_indices", "uint")] {
            let name = format!("cube {format} {list} {index_type}.ply");
            let ply = load_mesh(&write(dir.path(), &name, cube_ply(format, list, index_type)));
            assert_eq!(ply.expect(&name).triangles, expected, "{name}");
        }
    }
}

#[test]
fn broken_mesh_files_are_refused_with_their_reason() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let message = |name: &str, bytes: &[u8]| match load_mesh(&write(dir.path(), name, bytes)) {
        Ok(mesh) => panic!("{name} read as {} triangles", mesh.triangles.len()),
        Err(e) => e.to_string(),
    };
    // A header declaring a billion vertices in a file of a few hundred bytes:
    // refused before anything is allocated for them
    let huge =
        String::from_utf8(cube_ply("ascii", "vertex_indices", "int")).unwrap().replace("vertex 8", "vertex 1000000000");
    assert!(message("huge.ply", huge.as_bytes()).contains("more than the file holds"));
    let out_of_range = cube_obj().replace("f 1 4 3 2", "f 1 4 3 99");
    let found = message("far.obj", out_of_range.as_bytes());
    assert!(found.contains("far.obj"), "{found}");
    let ply_far =
        String::from_utf8(cube_ply("ascii", "vertex_indices", "int")).unwrap().replace("4 0 3 2 1", "4 0 3 2 80");
    assert!(message("far.ply", ply_far.as_bytes()).contains("face 0 names vertex 80"));
    assert!(message("empty.obj", b"# nothing\n").contains("no triangles"));
    assert!(matches!(load_mesh(&write(dir.path(), "cube.stl", b"solid")), Err(MeshError::Kind { .. })));
    assert!(matches!(load_mesh(&dir.path().join("absent.obj")), Err(MeshError::File(_))));
}

/// The Cornell box with a placed cube: as a `Mesh` of `file` in a scene
/// file, and as its twelve triangles typed one by one.
fn cube_scenes(dir: &Path, file: &str) -> (std::path::PathBuf, ValidScene) {
    let mut scene = common::valid(gi_studio::scene::presets::preset("cornell").unwrap().unwrap()).into_scene();
    let shape = Shape::Mesh {
        file: file.into(),
        translate: Vec3::new(-0.2, 0.0, 0.1),
        scale: 0.4,
        rotate_degrees: Vec3::new(0.0, 30.0, 0.0),
    };
    let mut typed = scene.clone();
    for (k, [a, b, c]) in cube_triangles().into_iter().enumerate() {
        let placement = shape.placement();
        let [a, b, c] = [a, b, c].map(|v| placement.transform_point3(v));
        let name = format!("cube {k}");
        typed.objects.push(Object { name, shape: Shape::Triangle { a, b, c }, material: "white".into() });
    }
    scene.objects.push(Object { name: "cube".into(), shape, material: "white".into() });
    let path = write(dir, "box.ron", to_ron(&scene).expect("RON") + "\n");
    (path, common::valid(typed))
}

fn render(scene: ValidScene, algorithm: Algorithm) -> LinearImage {
    let settings = RenderSettings {
        width: 48,
        height: 36,
        samples_per_pixel: Some(2),
        seed: 7,
        ..RenderSettings::for_algorithm(algorithm)
    };
    render_blocking(&RenderJob::new(Arc::new(scene), settings)).expect("a render").0
}

#[test]
fn a_placed_mesh_renders_as_its_triangles_typed_one_by_one() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    write(dir.path(), "cube.obj", cube_obj());
    let (path, typed) = cube_scenes(dir.path(), "cube.obj");
    let loaded = load_scene(&path).expect("the scene beside its mesh");
    // Photon maps and references are tied to the mesh's content, not its name
    write(dir.path(), "cube.obj", cube_obj().replace("v 1 1 1", "v 1 1 1.5"));
    let changed = load_scene(&path).expect("the scene beside its changed mesh");
    assert_ne!(loaded.content_key(), changed.content_key());
    write(dir.path(), "cube.obj", cube_obj());
    assert_eq!(load_scene(&path).expect("the scene again").content_key(), loaded.content_key());
    for algorithm in [Algorithm::Path, Algorithm::Bdpt] {
        let (mesh, triangles) = (render(loaded.clone(), algorithm), render(typed.clone(), algorithm));
        assert!(mesh.pixels == triangles.pixels, "{algorithm:?}: the mesh's image is not its triangles'");
        // The cube is in view: without it the image differs
        let mut bare = loaded.clone().into_scene();
        bare.objects.retain(|o| o.name != "cube");
        assert!(render(common::valid(bare), algorithm).pixels != mesh.pixels);
    }
}

#[test]
fn a_missing_or_emissive_mesh_is_refused_naming_the_line() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let (path, _) = cube_scenes(dir.path(), "cube.obj");
    let text = std::fs::read_to_string(&path).unwrap();
    let line = 1 + text.lines().position(|l| l.contains("cube.obj")).expect("the mesh's line");
    match load_scene(&path) {
        Err(SceneFileError::Mesh { line: found, error, .. }) => {
            assert_eq!(found, line, "{error}");
            assert!(error.to_string().contains("cube.obj"), "{error}");
        }
        other => panic!("a scene whose mesh is missing: {other:?}"),
    }
    write(dir.path(), "cube.obj", cube_obj());
    let mut scene = load_scene(&path).expect("the scene beside its mesh").into_scene();
    let mut glowing = scene.clone();
    glowing.objects.iter_mut().find(|o| o.name == "cube").expect("the cube").material = "panel".into();
    let problems = ValidScene::new(glowing).expect_err("an emissive mesh");
    assert!(problems.iter().any(|p| matches!(p.problem, Problem::EmissiveMesh)), "{problems:?}");
    // A scene naming a mesh no file gave is refused, not rendered empty
    scene.meshes = Default::default();
    let problems = ValidScene::new(scene).expect_err("a mesh not loaded");
    assert!(problems.iter().any(|p| matches!(p.problem, Problem::MeshNotLoaded(_))), "{problems:?}");
}

/// A scene with a mesh beside it, saved elsewhere, opens there: the mesh
/// is named by its full path when it is not inside the new folder, and
/// relative to the folder when it is (so the folder can move as a whole).
/// Its autosave text names the mesh by its full path: read back from any
/// folder, without the meshes in memory, it finds the file.
#[test]
fn a_scene_saved_in_another_folder_still_finds_its_mesh() {
    let (dir, other) = (tempfile::tempdir().expect("a folder"), tempfile::tempdir().expect("another"));
    write(dir.path(), "cube.obj", cube_obj());
    let (path, _) = cube_scenes(dir.path(), "cube.obj");
    let scene = load_scene(&path).expect("the scene beside its mesh").into_scene();
    let moved = other.path().join("moved.ron");
    save_scene(&scene, &moved).expect("saved elsewhere");
    let reopened = load_scene(&moved).expect("the moved scene finds its mesh").into_scene();
    assert_eq!(reopened.objects, scene.objects, "the same objects, the mesh by the same full path");
    assert!(std::fs::read_to_string(&moved).unwrap().contains(&dir.path().join("cube.obj").display().to_string()));

    // Saved back beside the mesh: the name is relative again
    save_scene(&reopened, &path).expect("saved beside the mesh");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("file: \"cube.obj\""), "{text}");
    assert_eq!(load_scene(&path).expect("and it opens").into_scene().objects, scene.objects);

    let autosave = to_ron(&scene).expect("RON");
    let restored = parse_scene_with(&autosave, Path::new("autosave.ron"), &Default::default());
    assert_eq!(restored.expect("the autosave finds its mesh").into_scene().objects, scene.objects);
}
