//! Engine speed: ray–sphere intersections per second, and path-traced
//! samples per second on smallpt at 512×384 (run with `cargo bench`).

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gi_studio::geometry::{intersect_sphere, Ray};
use gi_studio::render::rng::Sampler;
use gi_studio::render::sampling::uniform_sphere;
use gi_studio::render::{render_blocking, Algorithm, RenderJob, RenderSettings};
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

fn path_smallpt(c: &mut Criterion) {
    let scene = Arc::new(presets::preset("smallpt").and_then(Result::ok).expect("smallpt preset"));
    let settings = RenderSettings {
        width: 512,
        height: 384,
        samples_per_pixel: Some(4),
        ..RenderSettings::for_algorithm(Algorithm::Path)
    };
    let job = RenderJob::new(scene, settings);
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.throughput(Throughput::Elements(512 * 384 * 4));
    group.bench_function("path_smallpt_512x384_samples", |b| b.iter(|| render_blocking(&job).map(|r| r.1.rays)));
    group.finish();
}

criterion_group!(benches, ray_sphere, path_smallpt);
criterion_main!(benches);
