//! Engine speed: ray–sphere intersections per second, nearest hits on a
//! quarter-million-triangle mesh, worlds compiled, shadow rays one and
//! eight at a time, and path-traced samples per second on every preset at
//! 512×384 (run with `cargo bench`).

use std::f32::consts::PI;
use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gi_studio::geometry::{intersect_sphere, Ray};
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::uniform_sphere;
use gi_studio::render::{render_blocking, Algorithm, RenderEvent, RenderJob, RenderSession, RenderSettings};
use gi_studio::scene::presets;
use glam::Vec3;

fn ray_sphere(c: &mut Criterion) {
    let mut s = Sampler::new(0, 0, 1);
    let rays: Vec<Ray> =
        (0..4096).map(|_| Ray::new(uniform_sphere(s.next_2d()) * 10.0, uniform_sphere(s.next_2d()))).collect();
    let mut group = c.benchmark_group("geometry");
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("ray_sphere_intersections", |b| {
        b.iter(|| {
            let mut hits = 0u32;
            for ray in &rays {
                hits += intersect_sphere(black_box(ray), Vec3::ZERO, 3.0, f32::INFINITY).is_some() as u32;
            }
            hits
        })
    });
    group.finish();
}

/// The blob `benches/embree_mesh.py` gives Embree: a sphere of `rings` ×
/// 2·`rings` quads, its radius rippled, as triangles.
fn blob(rings: u32) -> Vec<[Vec3; 3]> {
    let at = |i: u32, j: u32| {
        let (theta, phi) = (PI * i as f32 / rings as f32, PI * j as f32 / rings as f32);
        let r = 1.0 + 0.1 * (7.0 * theta).sin() * (5.0 * phi).cos();
        Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()) * r
    };
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..2 * rings {
            let [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            triangles.extend([[a, c, b], [a, d, c]]);
        }
    }
    triangles
}

/// The thesis preset's camera and materials with the blob of `rings` alone.
fn blob_scene(rings: u32) -> gi_studio::scene::ValidScene {
    use gi_studio::scene::mesh::MeshData;
    use gi_studio::scene::{Object, Shape, ValidScene};
    let mut scene = presets::preset("thesis").unwrap().unwrap().into_scene();
    scene.objects = vec![Object {
        name: "blob".into(),
        shape: Shape::Mesh { file: "blob".into(), translate: Vec3::ZERO, scale: 1.0, rotate_degrees: Vec3::ZERO },
        material: scene.materials[0].name.clone(),
    }];
    scene.meshes.insert("blob".into(), Arc::new(MeshData::new(blob(rings))));
    ValidScene::new(scene).expect("the blob's scene")
}

/// Nearest hits of rays from a sphere of radius 3 aimed into a ball of
/// radius 0.9 about a mesh of a quarter of a million triangles, one
/// thread, through the world's hierarchy: against Embree's, same mesh and
/// rays, by `benches/embree_mesh.py`.
fn mesh_rays(c: &mut Criterion) {
    use gi_studio::render::world::World;
    let world = World::new(&blob_scene(256));
    let mut s = Sampler::new(0, 0, 3);
    let rays: Vec<Ray> = (0..100_000)
        .map(|_| {
            let origin = uniform_sphere(s.next_2d()) * 3.0;
            let target = uniform_sphere(s.next_2d()) * 0.9 * s.next_f32().cbrt();
            Ray::new(origin, (target - origin).normalize())
        })
        .collect();
    let mut group = c.benchmark_group("geometry");
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.sample_size(20);
    group.bench_function("mesh_262k_triangles_nearest_hits", |b| {
        b.iter(|| rays.iter().filter(|ray| world.intersect(black_box(ray), f32::INFINITY).is_some()).count())
    });
    group.finish();
}

/// Compiling a scene's world: the knot preset's (36,864 triangles) with
/// its triangles built, and with them shared by a world still held (what
/// the studio does at each edit that leaves the triangles alone); and a
/// world of a million triangles (the blob of `rings` 512), built.
fn world_builds(c: &mut Criterion) {
    use gi_studio::render::world::World;
    let knot = presets::preset("knot").unwrap().unwrap();
    let mut group = c.benchmark_group("world");
    group.sample_size(10);
    group.bench_function("knot_built", |b| b.iter(|| World::new(black_box(&knot)).lights.len()));
    let held = World::new(&knot);
    group.bench_function("knot_shared", |b| b.iter(|| World::new(black_box(&knot)).lights.len()));
    drop(held);
    let million = blob_scene(512);
    group.bench_function("blob_1m_triangles_built", |b| b.iter(|| World::new(black_box(&million)).lights.len()));
    group.finish();
}

/// Path tracing on every preset at 512×384, 4 spp a job: the eight lanes
/// on every shape, material and light (#17's goal: each preset at 80% or
/// more of smallpt's samples per second).
fn path_presets(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.throughput(Throughput::Elements(512 * 384 * 4));
    for &(name, _) in presets::PRESETS {
        let scene = Arc::new(presets::preset(name).and_then(Result::ok).expect("a preset"));
        let settings = RenderSettings {
            width: 512,
            height: 384,
            samples_per_pixel: Some(4),
            ..RenderSettings::for_algorithm(Algorithm::Path)
        };
        let job = RenderJob::new(scene, settings);
        group.bench_function(format!("path_{name}_512x384_samples"), |b| {
            b.iter(|| render_blocking(&job).map(|r| r.1.rays))
        });
    }
    group.finish();
}

/// Whitted on cornell.ron at 640×480: one anti-aliased pass is one frame.
fn whitted_cornell(c: &mut Criterion) {
    let scene = Arc::new(presets::preset("cornell").and_then(Result::ok).expect("cornell preset"));
    let settings = RenderSettings {
        width: 640,
        height: 480,
        samples_per_pixel: Some(1),
        ..RenderSettings::for_algorithm(Algorithm::Whitted)
    };
    let job = RenderJob::new(scene.clone(), settings.clone());
    let mut group = c.benchmark_group("render");
    group.sample_size(20);
    group.bench_function("whitted_cornell_640x480_frame", |b| b.iter(|| render_blocking(&job).map(|r| r.1.rays)));
    // The studio's case: a long-lived session restarted by an edit; time
    // until the whole coarse preview has arrived
    let session = RenderSession::new(gi_studio::render::Workers::shared().unwrap(), None).unwrap();
    let preview = RenderJob::new(scene, RenderSettings { preview: true, samples_per_pixel: Some(0), ..settings });
    group.bench_function("whitted_cornell_640x480_first_coarse_frame_after_edit", |b| {
        b.iter(|| {
            let generation = session.start(preview.clone());
            for event in session.events().iter() {
                if let RenderEvent::Finished { generation: g, .. } = event {
                    if g == generation {
                        break;
                    }
                }
            }
        })
    });
    group.finish();
}

/// SPPM on caustics.ron at 512×384 with 1 M photons per pass: one pass.
fn sppm_caustics(c: &mut Criterion) {
    let scene = Arc::new(presets::preset("caustics").and_then(Result::ok).expect("caustics preset"));
    let mut settings = RenderSettings {
        width: 512,
        height: 384,
        samples_per_pixel: Some(1),
        ..RenderSettings::for_algorithm(Algorithm::Sppm)
    };
    settings.set_photons(1_000_000);
    let job = RenderJob::new(scene, settings);
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.bench_function("sppm_caustics_512x384_1M_photons_pass", |b| {
        b.iter(|| render_blocking(&job).map(|r| r.1.rays))
    });
    group.finish();
}

/// The shadow rays of random paths through gap-room (its partition's six
/// triangles), the Cornell box and smallpt: toward a sample of each light
/// and between the path's vertices, as the bidirectional methods trace
/// them. One at a time (`World::blocked`) and eight at a time
/// (`LaneWorld::shadows_blocked`).
fn shadow_rays(c: &mut Criterion) {
    use gi_studio::render::world::camera::{CameraModel, CameraTile, TileRect};
    use gi_studio::render::world::lane_world::LaneWorld;
    use gi_studio::render::world::occluders::Shadow;
    use gi_studio::render::world::rng::PassStreams;
    use gi_studio::render::world::World;
    let mut group = c.benchmark_group("shadow_rays");
    for name in ["gap-room", "cornell", "smallpt"] {
        let scene = presets::preset(name).and_then(Result::ok).expect("a preset");
        let camera = CameraModel::new(&scene.camera, 64, 48);
        let (world, _) = World::for_view(&scene, &camera, 64, 48);
        let lanes = LaneWorld::new(&world).expect("a world the lanes trace");
        let rect = TileRect { x: 0, y: 0, width: 64, height: 48 };
        let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(0, 9) };
        let mut s = Sampler::new(0, 0, 9);
        let mut shadows = Vec::new();
        for i in 0..rect.pixels() {
            let mut ray = tile.sample(i).0;
            let held = world.holds(ray.origin);
            let mut vertices = Vec::new();
            for _ in 0..4 {
                let Some(hit) = world.intersect_held(&ray, f32::INFINITY, held) else { break };
                for light in &world.lights {
                    shadows.extend(light.sample(&hit.surface, s.next_2d()).map(|l| Shadow::toward(&l, held)));
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
        group.throughput(Throughput::Elements(shadows.len() as u64));
        group.bench_function(format!("{name}/one_at_a_time"), |b| {
            b.iter(|| shadows.iter().filter(|shadow| world.blocked(black_box(shadow))).count())
        });
        let mut blocked = vec![false; shadows.len()];
        group.bench_function(format!("{name}/eight_at_a_time"), |b| {
            b.iter(|| {
                lanes.shadows_blocked(black_box(&shadows), &mut blocked);
                blocked.iter().filter(|&&b| b).count()
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    ray_sphere,
    mesh_rays,
    world_builds,
    shadow_rays,
    path_presets,
    whitted_cornell,
    sppm_caustics
);
criterion_main!(benches);
