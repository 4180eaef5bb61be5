//! Eight-lane path tracing is `path::radiance` lane by lane: the same
//! samples give the same radiance, bit for bit, whatever the lane a path
//! lands in and however long its neighbours live.

use gi_studio::render::integrators::Counters;
use gi_studio::render::integrators::{path, path_lanes};
use gi_studio::render::world::camera::CameraModel;
use gi_studio::render::world::camera::CameraTile;
use gi_studio::render::world::camera::TileRect;
use gi_studio::render::world::lane_world::LaneWorld;
use gi_studio::render::world::rng::PassStreams;
use gi_studio::render::world::World;
use gi_studio::scene::mesh::load_mesh;
use gi_studio::scene::{
    presets, Attenuation, Light, LightKind, MaterialModel, Metal, Object, Rgb, Scene, Shape, ValidScene,
};
use glam::Vec3;

fn light(kind: LightKind, intensity: f32) -> Light {
    let name = format!("extra {}", kind.kind_name());
    Light { name, kind, color: Rgb::ONE, intensity, attenuation: Attenuation::default(), enabled: true }
}

fn preset(name: &str) -> Scene {
    presets::preset(name).and_then(Result::ok).expect("preset").into_scene()
}

fn world(scene: &Scene, width: u32, height: u32) -> (World, CameraModel) {
    let camera = CameraModel::new(&scene.camera, width, height);
    let valid = ValidScene::new(scene.clone()).expect("a valid scene");
    let (world, _) = World::for_view(&valid, &camera, width, height);
    (world, camera)
}

/// Lanes against the scalar tracer over `passes` passes of the whole image
/// (and of one ragged tile off its corner); returns how many samples
/// carried light (so a test cannot pass on a black image).
fn assert_lanes_match_scalar(scene: &Scene, max_depth: u32, passes: u64) -> usize {
    let (width, height) = (40, 30);
    let (world, camera) = world(scene, width, height);
    let lanes = LaneWorld::new(&world).expect("a scene the lanes trace");
    let whole = TileRect { x: 0, y: 0, width, height };
    // 13 × 7: rows that do not split into eights, away from the origin
    let ragged = TileRect { x: 21, y: 17, width: 13, height: 7 };
    let mut lit = 0;
    for pass in 0..passes {
        for rect in [whole, ragged] {
            let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(pass, 7) };
            let mut scalar_counters = Counters::default();
            let expected: Vec<Rgb> = (0..tile.len())
                .map(|i| {
                    let (ray, mut sampler) = tile.sample(i);
                    path::radiance(&world, &ray, max_depth, &mut sampler, &mut scalar_counters)
                })
                .collect();
            let mut got = vec![Rgb::splat(-1.0); tile.len()];
            let mut lane_counters = Counters::default();
            path_lanes::radiance(&lanes, &world, &tile, max_depth, &mut |i, v| got[i] = v, &mut lane_counters);
            for (i, (e, g)) in expected.iter().zip(&got).enumerate() {
                let bits = |v: &Rgb| v.to_array().map(f32::to_bits);
                assert_eq!(bits(e), bits(g), "sample {i} of {rect:?}, pass {pass}: scalar {e} vs lanes {g}");
            }
            assert_eq!(scalar_counters.rays, lane_counters.rays, "rays traced in pass {pass}");
            lit += expected.iter().filter(|v| v.max_element() > 0.0).count();
        }
    }
    lit
}

#[test]
fn smallpt_bit_for_bit() {
    let lit = assert_lanes_match_scalar(&preset("smallpt"), 32, 3);
    assert!(lit > 3000, "only {lit} samples carried light");
}

/// A thin lens draws its rays one at a time; the lanes take them as they come.
#[test]
fn thin_lens_bit_for_bit() {
    let mut scene = preset("smallpt");
    scene.camera.aperture_radius = 2.0;
    scene.camera.focus_distance = 200.0;
    let lit = assert_lanes_match_scalar(&scene, 32, 1);
    assert!(lit > 1000, "only {lit} samples carried light");
}

#[test]
fn short_paths_end_at_the_depth_cap() {
    for depth in [0, 1, 2, 4] {
        assert_lanes_match_scalar(&preset("smallpt"), depth, 1);
    }
}

/// A second light of each other kind (lit lane by lane through the scalar
/// code), a whole-sphere light in the open, and a light outside the walls.
#[test]
fn other_lights_bit_for_bit() {
    let mut scene = preset("smallpt");
    scene.lights.push(light(LightKind::Point { position: Vec3::new(30.0, 60.0, 90.0) }, 2000.0));
    let spot = LightKind::Spot {
        position: Vec3::new(70.0, 70.0, 60.0),
        direction: Vec3::new(0.0, -1.0, 0.2),
        cone_angle_degrees: 30.0,
        falloff_exponent: 4.0,
    };
    scene.lights.push(light(spot, 3000.0));
    // A hard-edged spot (exponent 0) and a point light with the thesis'
    // attenuation, 1/(a·d² + b·d + c)
    let hard = LightKind::Spot {
        position: Vec3::new(20.0, 75.0, 90.0),
        direction: Vec3::new(0.3, -1.0, 0.0),
        cone_angle_degrees: 40.0,
        falloff_exponent: 0.0,
    };
    scene.lights.push(Light { name: "hard spot".into(), ..light(hard, 2000.0) });
    let mut near = light(LightKind::Point { position: Vec3::new(50.0, 20.0, 120.0) }, 50.0);
    near.name = "near point".into();
    near.attenuation = Attenuation { a: 0.001, b: 0.05, c: 0.5 };
    scene.lights.push(near);
    // Emitters of smallpt's light's material (object 8)
    let glowing = |scene: &mut Scene, name: &str, shape: Shape| {
        scene.objects.push(Object { name: name.into(), shape, ..scene.objects[8].clone() });
    };
    let triangle = |a: [f32; 3], b: [f32; 3], c: [f32; 3]| Shape::Triangle {
        a: Vec3::from(a),
        b: Vec3::from(b),
        c: Vec3::from(c),
    };
    // A small glowing ball inside the room (sampled as a whole sphere) and a
    // glowing triangle facing down: caps, triangles and whole spheres drawn
    // in one batch of lanes
    glowing(&mut scene, "glow", Shape::Sphere { center: Vec3::new(60.0, 40.0, 100.0), radius: 4.0 });
    glowing(&mut scene, "panel", triangle([20.0, 70.0, 60.0], [40.0, 70.0, 60.0], [30.0, 70.0, 80.0]));
    // A second of each kind of area light, so each kind is one of two
    // blended by lane: another ball, another light through the ceiling (a
    // cap), another triangle
    glowing(&mut scene, "second glow", Shape::Sphere { center: Vec3::new(35.0, 55.0, 120.0), radius: 3.0 });
    glowing(&mut scene, "second cap", Shape::Sphere { center: Vec3::new(25.0, 681.0, 120.0), radius: 600.0 });
    glowing(&mut scene, "second panel", triangle([60.0, 75.0, 110.0], [80.0, 75.0, 110.0], [70.0, 75.0, 130.0]));
    assert_lanes_match_scalar(&scene, 32, 2);
    // A third of each, so each kind is gathered lane by lane
    glowing(&mut scene, "third glow", Shape::Sphere { center: Vec3::new(75.0, 30.0, 110.0), radius: 2.0 });
    glowing(&mut scene, "third cap", Shape::Sphere { center: Vec3::new(75.0, 681.0, 50.0), radius: 600.0 });
    glowing(&mut scene, "third panel", triangle([30.0, 60.0, 130.0], [50.0, 60.0, 130.0], [40.0, 60.0, 150.0]));
    assert_lanes_match_scalar(&scene, 32, 1);
    scene.lights.push(light(LightKind::Directional { direction: Vec3::new(0.1, -1.0, 0.3) }, 1.0));
    assert_lanes_match_scalar(&scene, 32, 1);
}

/// A scene lit by one triangle: its points are drawn before the hit is
/// known, as smallpt's cap's are (`LaneLights::drawn_ahead`).
#[test]
fn one_triangle_light_bit_for_bit() {
    let mut scene = preset("cornell");
    scene.objects.retain(|object| object.name != "panel b");
    let lit = assert_lanes_match_scalar(&scene, 16, 2);
    assert!(lit > 1000, "only {lit} samples carried light");
}

/// A path off a black surface can carry no more light: it ends there (one
/// ray a sample), not after the bounces before Russian roulette may end it.
#[test]
fn paths_end_on_black_surfaces() {
    let mut scene = preset("smallpt");
    for material in &mut scene.materials {
        if !matches!(material.model, MaterialModel::Emissive { .. }) {
            material.model = MaterialModel::Lambert { albedo: Rgb::ZERO };
        }
    }
    let (world, camera) = world(&scene, 40, 30);
    let rect = TileRect { x: 0, y: 0, width: 40, height: 30 };
    let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(0, 7) };
    let mut counters = Counters::default();
    for i in 0..tile.len() {
        let (ray, mut sampler) = tile.sample(i);
        path::radiance(&world, &ray, 32, &mut sampler, &mut counters);
    }
    assert_eq!(counters.rays, tile.len() as u64);
    // The lanes trace as many rays (the helper compares the counts)
    let lit = assert_lanes_match_scalar(&scene, 32, 1);
    assert!(lit > 0, "the light is in view");
}

/// Planes (walls and not) and triangles (lights among them, shadow rays
/// skipping the light's own plane), with area, point, spot and
/// directional lights: every preset the lanes take.
#[test]
fn presets_of_planes_and_triangles_bit_for_bit() {
    for (name, least) in
        [("cornell", 1500), ("caustics", 1500), ("gap-room", 200), ("lights", 1500), ("mirror-caustic", 1000)]
    {
        let lit = assert_lanes_match_scalar(&preset(name), 32, 2);
        assert!(lit > least, "{name}: only {lit} samples carried light");
    }
}

/// More shapes than two permutes of eight hold: the lanes read the
/// spheres', planes' and surfaces' fields by hardware gathers
/// (`lanes::Column`), here the Cornell box with sixteen small balls of
/// every material on its floor (18 spheres, 23 surfaces).
#[test]
fn more_than_sixteen_shapes_bit_for_bit() {
    let mut scene = preset("cornell");
    let materials = ["white", "red", "green", "mirror", "glass"];
    for k in 0..16 {
        let (x, z) = (-0.8 + 0.2 * (k % 8) as f32 + 0.05, if k < 8 { 0.6 } else { -0.8 });
        scene.objects.push(Object {
            name: format!("ball {k}"),
            shape: Shape::Sphere { center: Vec3::new(x, 0.08, z), radius: 0.08 },
            material: materials[k % materials.len()].to_string(),
        });
    }
    let lit = assert_lanes_match_scalar(&scene, 32, 2);
    assert!(lit > 1500, "only {lit} samples carried light");
}

/// A ball of `rings` × 2·`rings` flat facets (two triangles each, one at
/// the poles), of `material`.
fn faceted_ball(center: Vec3, radius: f32, rings: u32, material: &str) -> Vec<Object> {
    let at = |ring: u32, step: u32| {
        let (theta, phi) =
            (std::f32::consts::PI * ring as f32 / rings as f32, std::f32::consts::PI * step as f32 / rings as f32);
        center + radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut objects = Vec::new();
    for ring in 0..rings {
        for step in 0..2 * rings {
            let [a, b, c, d] = [at(ring, step), at(ring + 1, step), at(ring + 1, step + 1), at(ring, step + 1)];
            let facets = [(a, c, b), (a, d, c)];
            for (k, (a, b, c)) in facets.into_iter().enumerate() {
                objects.push(Object {
                    name: format!("{material} facet {ring} {step} {k} at {center}"),
                    shape: Shape::Triangle { a, b, c },
                    material: material.to_string(),
                });
            }
        }
    }
    objects
}

/// The Cornell box with a faceted glass ball and a faceted white one: more
/// triangles than a ray tests one by one, so every lane finds its
/// triangle, and its shadow rays their blockers, through the hierarchy
/// (`shapes::bvh`), the light's two triangles among them.
fn cornell_of_facets() -> Scene {
    let mut scene = preset("cornell");
    scene.objects.extend(faceted_ball(Vec3::new(-0.35, 0.3, -0.2), 0.3, 8, "glass"));
    scene.objects.extend(faceted_ball(Vec3::new(0.4, 0.25, 0.3), 0.25, 6, "white"));
    scene
}

#[test]
fn triangles_found_through_the_hierarchy_bit_for_bit() {
    let scene = cornell_of_facets();
    let (world, _) = world(&scene, 40, 30);
    assert!(world.shapes.triangles.list.len() > gi_studio::render::world::shapes::GROUPED_TRIANGLES);
    let lit = assert_lanes_match_scalar(&scene, 32, 2);
    assert!(lit > 1500, "only {lit} samples carried light");
}

/// A glowing cube read from a file: a mesh light, which the lanes leave to
/// the scalar code lane by lane, bit for bit, beside the panel they draw.
#[test]
fn a_mesh_light_bit_for_bit() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let file = dir.path().join("cube.obj");
    let corners = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
    let faces = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
    std::fs::write(&file, format!("{corners}{faces}")).expect("the cube's file");
    let mut scene = preset("cornell");
    let key = file.display().to_string();
    scene.meshes.insert(key.clone(), std::sync::Arc::new(load_mesh(&file).expect("the cube")));
    let (translate, rotate_degrees) = (Vec3::new(-0.3, 0.3, 0.2), Vec3::new(0.0, 25.0, 0.0));
    let shape = Shape::Mesh { file: key, translate, scale: 0.3, rotate_degrees };
    scene.objects.push(Object { name: "glowing cube".into(), shape, material: "panel".into() });
    let lit = assert_lanes_match_scalar(&scene, 32, 2);
    assert!(lit > 1500, "only {lit} samples carried light");
}

/// Paths that start outside a wall (a wide lens beside the Cornell box's
/// right wall: some rays start beyond it) meet every plane from either
/// side and test walls for their shadow rays, beside paths held inside.
#[test]
fn paths_outside_the_walls_bit_for_bit() {
    let mut scene = preset("cornell");
    scene.camera.position = Vec3::new(0.9, 1.0, 3.4);
    scene.camera.aperture_radius = 0.3;
    scene.camera.focus_distance = 3.0;
    let (world, camera) = world(&scene, 40, 30);
    let tile = CameraTile {
        camera: &camera,
        rect: TileRect { x: 0, y: 0, width: 40, height: 30 },
        streams: PassStreams::new(0, 7),
    };
    let outside = (0..tile.len()).filter(|&i| !world.holds(tile.sample(i).0.origin)).count();
    assert!(outside > 100 && outside < tile.len() - 100, "{outside} of {} rays start outside", tile.len());
    let lit = assert_lanes_match_scalar(&scene, 32, 2);
    assert!(lit > 500, "only {lit} samples carried light");
}

/// Phong and Blinn–Phong surfaces (thesis, glossy), rough metals (metals)
/// and a sky as a light (thesis, and the Cornell box open to one) take the
/// lanes, bit for bit.
#[test]
fn glossy_lobes_and_skies_bit_for_bit() {
    for (name, least) in [("thesis", 1000), ("glossy", 1000), ("metals", 300)] {
        let lit = assert_lanes_match_scalar(&preset(name), 32, 2);
        assert!(lit > least, "{name}: only {lit} samples carried light");
    }
    let mut sky = preset("cornell");
    sky.background = Rgb::new(0.2, 0.3, 0.4);
    // Open the box to the sky
    sky.objects.retain(|object| object.name != "ceiling");
    let lit = assert_lanes_match_scalar(&sky, 32, 2);
    assert!(lit > 1000, "a sky: only {lit} samples carried light");
    // The red and green walls polished and rough metal, the mirror ball
    // anisotropic, beside white walls and glass
    let mut metals = preset("cornell");
    for (material, (alpha_u, alpha_v)) in metals.materials.iter_mut().skip(1).zip([(0.0, 0.0), (0.3, 0.3), (0.05, 0.5)])
    {
        material.model = MaterialModel::Conductor { metal: Metal::Copper, alpha_u, alpha_v };
    }
    let lit = assert_lanes_match_scalar(&metals, 32, 2);
    assert!(lit > 1000, "metals: only {lit} samples carried light");
}

/// The tests above compare the eight lanes with the scalar code only where
/// the lanes run: on an x86-64 CPU without AVX2 the tracer falls back to
/// the scalar code and they would compare it with itself. Say so loudly
/// instead of passing.
#[test]
fn the_lanes_under_test_are_the_eight_lane_tracer() {
    assert!(
        LaneWorld::runs_in_lanes(),
        "this CPU lacks AVX2: the lane tests would compare the scalar tracer with itself"
    );
}

/// Where smallpt's light, a ball poking through the ceiling, meets it: rays
/// that reach both at the same distance, in f32, take the light, as
/// `World::intersect_held` meets the walls after every other sphere. The
/// lanes once took the ceiling, a wall, earlier in index order.
#[test]
fn the_seam_of_the_light_and_the_ceiling_bit_for_bit() {
    let mut scene = preset("smallpt");
    // The cap meets the ceiling (y = 81.6) on a circle of radius ~18 about x = 50
    let rim = (600.0f32 * 600.0 - (681.33f32 - 81.6).powi(2)).sqrt();
    scene.camera.position = Vec3::new(50.0, 40.0, 81.6);
    scene.camera.look_at = Vec3::new(50.0 + rim, 81.6, 81.6);
    scene.camera.near_clip = 0.0;
    scene.camera.fov_y_degrees = 0.02;
    let lit = assert_lanes_match_scalar(&scene, 4, 2);
    assert!(lit > 100, "only {lit} samples carried light");
}

/// Shadow rays traced together, eight at a time (what the bidirectional
/// methods do with their connections and light samples), are blocked
/// exactly where `World::blocked` blocks each alone: on every preset, on
/// the Cornell box seen from outside its walls (which its shadow rays must
/// then test) and with a second, triangle, light; toward light samples
/// (skipping the light's own sphere or plane of triangles), between the
/// vertices of a path, and in batches that do not split into eights.
#[test]
fn shadow_rays_in_lanes_are_blocked_as_one_at_a_time() {
    use gi_studio::geometry::Ray;
    use gi_studio::render::world::light::{AreaLight, Emitter, LightSource};
    use gi_studio::render::world::occluders::Shadow;
    use gi_studio::render::world::rng::Sampler;
    use gi_studio::render::world::sampling::uniform_sphere;
    let mut scenes: Vec<(String, Scene)> = presets::names().map(|n| (n.to_string(), preset(n))).collect();
    // A lens reaching past the right wall's plane: paths not held inside the walls
    let mut outside = preset("cornell");
    outside.camera.position = Vec3::new(0.9, 1.0, 3.4);
    outside.camera.aperture_radius = 0.3;
    outside.camera.focus_distance = 3.0;
    scenes.push(("cornell from outside".into(), outside));
    let mut lamps = preset("gap-room");
    let lamp = lamps.objects.iter().position(|o| o.name == "lamp").expect("gap-room's lamp");
    let shape =
        Shape::Triangle { a: Vec3::new(-2.9, 2.4, -1.0), b: Vec3::new(-2.9, 2.4, 0.0), c: Vec3::new(-2.9, 1.6, -0.5) };
    lamps.objects.push(Object { name: "panel".into(), shape, ..lamps.objects[lamp].clone() });
    scenes.push(("gap-room with a panel".into(), lamps));
    scenes.push(("cornell of facets".into(), cornell_of_facets()));
    for (name, scene) in &scenes {
        let (world, camera) = world(scene, 64, 48);
        let lanes = LaneWorld::new(&world).expect("a scene the lanes trace");
        let mut s = Sampler::new(0, 0, 9);
        let mut shadows = Vec::new();
        // Straight through each light triangle to beyond it: only what it
        // ends on (its plane's triangles) is skipped
        for light in &world.lights {
            if let LightSource::Area(AreaLight { emitter: Emitter::Triangle { triangle, shape }, .. }) = light {
                let [a, b, c] = shape.vertices;
                for k in 0..40 {
                    let target = (a + b + c) / 3.0 + (b - a) * (k as f32 / 100.0);
                    let from = target + shape.normal * 0.5 + Vec3::new(0.01, 0.02, 0.03) * k as f32;
                    let (segment, t_max) =
                        (Ray::new(from, (target - from).normalize()), 2.0 * (target - from).length());
                    let held = world.holds(from);
                    shadows.push(Shadow { on_triangle: Some(*triangle), ..Shadow::segment(segment, t_max, held) });
                }
            }
        }
        let tile = CameraTile {
            camera: &camera,
            rect: TileRect { x: 0, y: 0, width: 64, height: 48 },
            streams: PassStreams::new(0, 9),
        };
        for i in 0..600 {
            let mut ray = tile.sample(i * 5).0;
            let held = world.holds(ray.origin);
            let mut vertices = Vec::new();
            for _ in 0..4 {
                let Some(hit) = world.intersect_held(&ray, f32::INFINITY, held) else { break };
                for light in &world.lights {
                    if let Some(sample) = light.sample(&hit.surface, s.next_2d()) {
                        shadows.push(Shadow::toward(&sample, held));
                    }
                }
                for earlier in &vertices {
                    let (segment, t_max) = hit.surface.spawn_ray_to(*earlier, 0.0);
                    shadows.push(Shadow::segment(segment, t_max, held));
                }
                vertices.push(hit.surface.point);
                let mut direction = uniform_sphere(s.next_2d());
                if direction.dot(hit.surface.normal) * (-ray.direction).dot(hit.surface.normal) < 0.0 {
                    direction = -direction;
                }
                ray = hit.surface.spawn_ray(direction);
            }
        }
        let expected: Vec<bool> = shadows.iter().map(|shadow| world.blocked(shadow)).collect();
        // Batches of every length up to three eights and a bit
        let (mut at, mut length) = (0, 1);
        while at < shadows.len() {
            let end = (at + length).min(shadows.len());
            let mut got = vec![false; end - at];
            lanes.shadows_blocked(&shadows[at..end], &mut got);
            assert_eq!(got, expected[at..end], "{name}: shadow rays {at}..{end}");
            (at, length) = (end, length % 27 + 1);
        }
        let blocked = expected.iter().filter(|&&b| b).count();
        let loose = shadows.iter().filter(|shadow| !shadow.held).count();
        if name.ends_with("from outside") {
            assert!(loose > shadows.len() / 4, "{name}: only {loose} shadow rays not held");
        }
        assert!(
            blocked > shadows.len() / 50 && blocked < shadows.len() * 49 / 50,
            "{name}: {blocked} of {} blocked",
            shadows.len()
        );
    }
}
