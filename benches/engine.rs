//! Engine speed: ray–sphere intersections per second, and path-traced
//! samples per second on every preset at 512×384 (run with `cargo bench`).

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

criterion_group!(benches, ray_sphere, path_presets, whitted_cornell, sppm_caustics);
criterion_main!(benches);
