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
fn a_missing_mesh_is_refused_naming_the_line() {
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

/// An emissive mesh is one area light, a triangle drawn by its area: the
/// Cornell box (its balls diffuse, a triangle screening the cube from the
/// left wall) lit by its panel and a glowing cube renders, by path
/// tracing, the mean of the same box with the cube's twelve triangles typed
/// one by one as twelve lights, and every other algorithm renders path
/// tracing's mean too (Welch's t-test over eight replicas each, two-sided
/// 1e-4 a comparison; photon mapping and SPPM, whose blur is a bias,
/// within 2%).
#[test]
fn an_emissive_mesh_lights_the_scene_in_every_algorithm() {
    use common::detectors::{mean_and_error, replicas};
    use common::stats::student_t_quantile;
    let dir = tempfile::tempdir().expect("a temporary folder");
    write(dir.path(), "cube.obj", cube_obj());
    let (path, typed) = cube_scenes(dir.path(), "cube.obj");
    // The balls made diffuse: light tracing cannot see a mirror or glass
    // The cube lifted off the floor: where a light touches a surface the
    // direct light photon mapping samples without MIS has no variance to
    // speak of (its mean would come from rare, huge samples)
    let glowing = |mut scene: gi_studio::scene::Scene| {
        let lift = Vec3::new(0.0, 0.15, 0.0);
        for object in scene.objects.iter_mut().filter(|o| o.name.starts_with("cube")) {
            object.material = "panel".into();
            match &mut object.shape {
                Shape::Mesh { translate, .. } => *translate += lift,
                Shape::Triangle { a, b, c } => [a, b, c].into_iter().for_each(|v| *v += lift),
                other => panic!("{other:?}"),
            }
        }
        for material in scene.materials.iter_mut().filter(|m| matches!(m.name.as_str(), "mirror" | "glass")) {
            material.model = gi_studio::scene::MaterialModel::Lambert { albedo: Vec3::splat(0.5) };
        }
        // A screen between the cube and the left wall: shadow rays toward
        // the cube must find it
        let (a, b, c) = (Vec3::new(-0.55, 0.0, -0.6), Vec3::new(-0.55, 0.0, 0.6), Vec3::new(-0.55, 0.8, 0.0));
        scene.objects.push(Object {
            name: "screen".into(),
            shape: Shape::Triangle { a, b, c },
            material: "white".into(),
        });
        scene
    };
    let mesh = glowing(load_scene(&path).expect("the scene beside its mesh").into_scene());
    let typed = glowing(typed.into_scene());
    let (width, height, k) = (24, 18, 8);
    let means = |scene: &gi_studio::scene::Scene, settings: RenderSettings| {
        let images = replicas(scene, settings, k);
        mean_and_error(&images.iter().map(|image| common::mean_luminance(&image.pixels)).collect::<Vec<_>>())
    };
    let critical = student_t_quantile(1e-4, (k - 1) as f64);
    let agree = |what: &str, (a, a_error): (f64, f64), (b, b_error): (f64, f64)| {
        let t = (a - b) / (a_error * a_error + b_error * b_error).sqrt();
        println!("{what}: {a:.5} ± {a_error:.1e} against {b:.5} ± {b_error:.1e}");
        assert!(t.abs() < critical, "{what}: {a} ± {a_error} against {b} ± {b_error} (t = {t:.1})");
    };
    let path_tracing = means(&mesh, common::settings(Algorithm::Path, width, height, 128));
    agree("typed triangles", means(&typed, common::settings(Algorithm::Path, width, height, 128)), path_tracing);
    for algorithm in [Algorithm::LightTracing, Algorithm::Bdpt, Algorithm::Bpm, Algorithm::Vcm] {
        let spp = if algorithm == Algorithm::LightTracing { 128 } else { 32 };
        agree(&algorithm.to_string(), means(&mesh, common::settings(algorithm, width, height, spp)), path_tracing);
    }
    for algorithm in [Algorithm::Photon, Algorithm::Sppm] {
        let mut s = common::settings(algorithm, width, height, if algorithm == Algorithm::Sppm { 64 } else { 16 });
        s.set_photons(if algorithm == Algorithm::Sppm { 20_000 } else { 200_000 });
        let mean = common::mean_luminance(&common::render(&mesh, s).0.pixels);
        println!("{algorithm}: {mean:.5} against {:.5}", path_tracing.0);
        assert!((mean / path_tracing.0 - 1.0).abs() < 0.02, "{algorithm}: {mean} against {}", path_tracing.0);
    }
}

/// Shadow rays toward a mesh light skip nothing (they stop short of their
/// point): under a glowing cube screened by a triangle, every light sample
/// from the floor below is blocked, by the scalar occluders and by the
/// lanes' shadow test alike; without the screen none is, not even by the
/// cube's own triangle the sample lies on.
#[test]
fn a_screen_blocks_a_mesh_light() {
    use gi_studio::geometry::SurfaceHit;
    use gi_studio::render::world::lane_world::LaneWorld;
    use gi_studio::render::world::light::{AreaLight, LightSource};
    use gi_studio::render::world::occluders::Shadow;
    use gi_studio::render::world::rng::Sampler;
    use gi_studio::render::world::shapes::Emitter;
    use gi_studio::render::world::World;
    let dir = tempfile::tempdir().expect("a temporary folder");
    write(dir.path(), "cube.obj", cube_obj());
    let (path, _) = cube_scenes(dir.path(), "cube.obj");
    let mut scene = load_scene(&path).expect("the scene beside its mesh").into_scene();
    scene.objects.retain(|o| o.name != "mirror ball" && o.name != "glass ball");
    let cube = scene.objects.iter_mut().find(|o| o.name == "cube").expect("the cube");
    cube.material = "panel".into();
    let Shape::Mesh { translate, .. } = &mut cube.shape else { panic!("a mesh") };
    *translate = Vec3::new(-0.2, 1.2, 0.0);
    let screened = {
        let mut scene = scene.clone();
        let (a, b, c) = (Vec3::new(-3.0, 0.6, -3.0), Vec3::new(3.0, 0.6, -3.0), Vec3::new(0.0, 0.6, 3.0));
        scene.objects.push(Object {
            name: "screen".into(),
            shape: Shape::Triangle { a, b, c },
            material: "white".into(),
        });
        scene
    };
    let at = SurfaceHit { t: 1.0, point: Vec3::new(0.0, 0.0, 0.1), normal: Vec3::Y, error: 0.0 };
    for (scene, blocked) in [(screened, true), (scene, false)] {
        let world = World::new(&common::valid(scene));
        let of_mesh = |l: &&LightSource| matches!(l, LightSource::Area(AreaLight { emitter: Emitter::Mesh(_), .. }));
        let lights: Vec<&LightSource> = world.lights.iter().filter(of_mesh).collect();
        assert_eq!(lights.len(), 1, "one light for the mesh");
        let mut s = Sampler::new(1, 1, 1);
        // The cube's bottom faces the floor: a sixth of its area
        let samples: Vec<_> = (0..300).filter_map(|_| lights[0].sample(&at, s.next_2d())).collect();
        assert!(samples.len() > 25, "only {} samples face the floor", samples.len());
        let occluders = world.occluders(false);
        assert!(samples.iter().all(|sample| occluders.blocks(sample) == blocked), "scalar, screened {blocked}");
        let shadows: Vec<Shadow> = samples.iter().map(|sample| Shadow::toward(sample, false)).collect();
        let mut in_lanes = vec![!blocked; shadows.len()];
        LaneWorld::new(&world).expect("lanes").shadows_blocked(&shadows, &mut in_lanes);
        assert!(in_lanes.iter().all(|&b| b == blocked), "lanes, screened {blocked}");
    }
}

/// The built-in scenes' meshes are compiled in and named `builtin:`: such a
/// scene saved in any folder keeps the name, and opens there.
#[test]
fn built_in_meshes_open_and_save_anywhere() {
    let dir = tempfile::tempdir().expect("a folder");
    for name in ["cornell-mesh", "knot"] {
        let scene = gi_studio::scene::presets::preset(name).expect("a preset").expect("it loads").into_scene();
        let files: Vec<&str> = (scene.objects.iter())
            .filter_map(|o| match &o.shape {
                Shape::Mesh { file, .. } => Some(file.as_str()),
                _ => None,
            })
            .collect();
        assert!(!files.is_empty() && files.iter().all(|f| f.starts_with("builtin:")), "{name}: {files:?}");
        let path = dir.path().join(format!("{name}.ron"));
        save_scene(&scene, &path).expect("saved");
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(files.iter().all(|f| text.contains(&format!("file: \"{f}\""))), "{text}");
        let reopened = load_scene(&path).expect("it opens from another folder").into_scene();
        assert_eq!(reopened.objects, scene.objects, "{name}");
        assert_eq!(reopened.meshes, scene.meshes, "{name}");
    }
}

#[test]
fn an_unknown_built_in_mesh_is_refused_naming_the_line() {
    let text = gi_studio::scene::presets::PRESETS.iter().find(|(n, _)| *n == "knot").expect("the knot").1;
    let broken = text.replace("builtin:torus-knot.ply", "builtin:teapot.obj");
    let line = 1 + broken.lines().position(|l| l.contains("teapot")).expect("the mesh's line");
    match gi_studio::scene::parse_scene(&broken, Path::new("knot.ron")) {
        Err(SceneFileError::Mesh { line: found, error, .. }) => {
            assert_eq!(found, line, "{error}");
            let message = error.to_string();
            assert!(message.contains("builtin:teapot.obj") && message.contains("builtin:torus-knot.ply"), "{message}");
        }
        other => panic!("a scene naming a built-in mesh that is not: {other:?}"),
    }
}

/// The knot is a closed surface wound outward: every edge is met once in
/// each direction by the triangles beside it (so no ray slips between
/// two), and its signed volume is positive (its normals point out).
#[test]
fn the_built_in_knot_is_closed_and_wound_outward() {
    let mesh = gi_studio::scene::mesh::builtin_mesh("builtin:torus-knot.ply").expect("the knot");
    let key = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut edges = std::collections::HashMap::new();
    for [a, b, c] in &mesh.triangles {
        for (from, to) in [(a, b), (b, c), (c, a)] {
            *edges.entry((key(*from), key(*to))).or_insert(0u32) += 1;
        }
    }
    assert!(edges.iter().all(|(&(from, to), &n)| n == 1 && edges.get(&(to, from)) == Some(&1)), "an open edge");
    let volume: f64 =
        (mesh.triangles.iter()).map(|[a, b, c]| a.as_dvec3().dot(b.as_dvec3().cross(c.as_dvec3())) / 6.0).sum();
    // A tube of radius 0.35 along a knot about 2π·√(p²(2²+…)) long: some tens of units³
    assert!(volume > 1.0, "the knot's volume {volume}: wound inward");
}

/// A finely tessellated sphere (a UV sphere of 24,576 triangles, its
/// vertices on the sphere) in place of the diffuse Cornell box's ball
/// renders the analytic ball's image in mean, by path tracing and the
/// same seed: within 0.1% (the issue asks 0.5%; with one seed the two
/// images' noise is alike, measured 0.002% apart, while a ball 3% smaller
/// moves the mean 0.2%). Without the ball the image differs.
#[test]
fn a_finely_tessellated_sphere_renders_as_the_sphere() {
    let scene = common::detectors::diffuse_cornell();
    let ball = scene.objects.iter().position(|o| o.name == "glass ball").expect("the glass ball");
    let Shape::Sphere { center, radius } = scene.objects[ball].shape else { panic!("a sphere") };
    let (rings, segments) = (96, 128);
    let point = |i: u32, j: u32| {
        let (theta, phi) =
            (std::f32::consts::PI * i as f32 / rings as f32, std::f32::consts::TAU * j as f32 / segments as f32);
        Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let [a, b, c, d] = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)];
            // Outward: (b − a) × (c − a) points away from the centre
            triangles
                .extend([[a, c, b], [a, d, c]].into_iter().filter(|[a, b, c]| (*b - *a).cross(*c - *a).length() > 0.0));
        }
    }
    let mut tessellated = scene.clone();
    tessellated.meshes.insert("sphere.obj".into(), Arc::new(gi_studio::scene::mesh::MeshData::new(triangles)));
    tessellated.objects[ball].shape =
        Shape::Mesh { file: "sphere.obj".into(), translate: center, scale: radius, rotate_degrees: Vec3::ZERO };
    let mut bare = scene.clone();
    bare.objects.remove(ball);
    let settings = common::settings(Algorithm::Path, 96, 72, 64);
    let mean =
        |scene: &gi_studio::scene::Scene| common::mean_luminance(&common::render(scene, settings.clone()).0.pixels);
    let (analytic, mesh, without) = (mean(&scene), mean(&tessellated), mean(&bare));
    println!("mean luminance: analytic {analytic}, tessellated {mesh}, without the ball {without}");
    assert!((mesh / analytic - 1.0).abs() < 0.001, "tessellated {mesh} against analytic {analytic}");
    assert!((without / analytic - 1.0).abs() > 0.02, "the ball barely shows: {without} against {analytic}");
}

/// A mesh placed over and over is refused once the triangles placed pass
/// `limits::PLACED_TRIANGLES`, at the placement that passes it (each
/// placement is compiled into the world: a thousand copies of a large mesh
/// asked for gigabytes), and the scene file names that object's line.
#[test]
fn placements_past_the_limit_are_refused_at_the_one_that_passes_it() {
    let mut scene = gi_studio::scene::presets::preset("knot").unwrap().unwrap().into_scene();
    let knot = scene.objects.iter().position(|o| o.name == "torus knot").expect("the knot");
    for k in 1..600 {
        let mut copy = scene.objects[knot].clone();
        copy.name = format!("knot {k}");
        scene.objects.push(copy);
    }
    // The object whose placement first passes the limit, counted here
    let mut placed = 0;
    let passing = (scene.objects.iter().position(|o| {
        if let Shape::Mesh { file, .. } = &o.shape {
            placed += scene.meshes.get(file).expect("loaded").triangles.len();
        }
        placed > gi_studio::limits::PLACED_TRIANGLES
    }))
    .expect("600 knots pass the limit");
    let problems = ValidScene::new(scene.clone()).expect_err("too many placed");
    let found: Vec<_> = problems.iter().filter(|p| matches!(p.problem, Problem::TooManyPlaced { .. })).collect();
    assert_eq!(found.len(), 1, "{problems:?}");
    assert_eq!(found[0].item.as_deref(), Some(scene.objects[passing].name.as_str()));
    let text = to_ron(&scene).expect("RON");
    match gi_studio::scene::parse_scene(&text, Path::new("copies.ron")) {
        Err(SceneFileError::Invalid { line, .. }) => {
            // Its `file:` line, in its own item
            let name = format!("\"{}\"", scene.objects[passing].name);
            let item = 1 + text.lines().position(|l| l.contains(&name)).unwrap();
            let file = item + text.lines().skip(item).position(|l| l.contains("file:")).unwrap() + 1;
            assert_eq!(line, file);
        }
        other => panic!("{other:?}"),
    }
    // Up to the one before it, the scene is valid
    scene.objects.truncate(passing);
    assert!(ValidScene::new(scene).is_ok());
}
