//! Photon map speed: kd-tree build (photons/s) and k-NN queries/s for 1 M
//! photons with k = 50, beside the `kiddo` crate's immutable kd-tree on the
//! same points and queries; photons traced per second on caustics.ron.

use std::hint::black_box;
use std::num::NonZero;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use gi_studio::render::integrators::photon_map::trace::{trace_photons, MapKind, PhotonBatch};
use gi_studio::render::integrators::photon_map::{Neighbours, Photon, PhotonKdTree};
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::World;
use gi_studio::scene::presets;
use glam::Vec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};

const PHOTONS: usize = 1_000_000;
const QUERIES: usize = 10_000;
const K: usize = 50;

/// Photons on the walls of a unit room, as a photon map of a box has them.
fn room_photons() -> Vec<Photon> {
    let mut s = Sampler::new(0, 0, 77);
    (0..PHOTONS)
        .map(|_| {
            let (u, v) = (s.next_f32(), s.next_f32());
            let wall = (s.next_f32() * 5.0) as u32;
            let position = match wall {
                0 => Vec3::new(u, 0.0, v),
                1 => Vec3::new(u, 1.0, v),
                2 => Vec3::new(0.0, u, v),
                3 => Vec3::new(1.0, u, v),
                _ => Vec3::new(u, v, 0.0),
            };
            Photon::new(position, -Vec3::Y, [1.0; 3])
        })
        .collect()
}

fn queries(photons: &[Photon]) -> Vec<Vec3> {
    let mut s = Sampler::new(1, 0, 78);
    (0..QUERIES)
        .map(|_| {
            photons[(s.next_f32() * photons.len() as f32) as usize].position
                + (Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) - 0.5) * 0.01
        })
        .collect()
}

fn kd_tree(c: &mut Criterion) {
    let photons = room_photons();
    let points: Vec<[f32; 3]> = photons.iter().map(|p| p.position.to_array()).collect();
    let queries = queries(&photons);

    let mut group = c.benchmark_group("kdtree_build_1M");
    group.sample_size(10);
    group.throughput(Throughput::Elements(PHOTONS as u64));
    // The photons' copy (the build takes them by value) is set-up, not timed
    group.bench_function("ours", |b| {
        b.iter_batched(|| photons.clone(), |photons| PhotonKdTree::build(photons).depth(), BatchSize::LargeInput)
    });
    group.bench_function("kiddo", |b| b.iter(|| ImmutableKdTree::<f32, 3>::new_from_slice(black_box(&points)).size()));
    group.finish();

    let ours = PhotonKdTree::build(photons.clone());
    let theirs = ImmutableKdTree::<f32, 3>::new_from_slice(&points);
    let mut group = c.benchmark_group("knn_k50_1M");
    group.sample_size(10);
    group.throughput(Throughput::Elements(QUERIES as u64));
    group.bench_function("ours", |b| {
        let mut out = Neighbours::new(K);
        b.iter(|| {
            let mut visited = 0;
            for q in &queries {
                visited += ours.k_nearest(*q, None, K, f32::INFINITY, &mut out);
            }
            visited
        })
    });
    group.bench_function("kiddo", |b| {
        let k = NonZero::new(K).expect("k > 0");
        b.iter(|| {
            let mut found = 0;
            for q in &queries {
                found += theirs.nearest_n::<SquaredEuclidean>(&q.to_array(), k).len();
            }
            found
        })
    });
    group.finish();
}

fn photon_tracing(c: &mut Criterion) {
    let scene = presets::preset("caustics").and_then(Result::ok).expect("caustics preset");
    let world = World::new(&scene);
    let count = 200_000u64;
    let mut group = c.benchmark_group("photon_tracing");
    group.sample_size(10);
    group.throughput(Throughput::Elements(count));
    group.bench_function("caustics_global_photons", |b| {
        let batch = PhotonBatch { kind: MapKind::Indirect, count, pass: 0, seed: 3, max_depth: 32 };
        b.iter(|| trace_photons(&world, batch).len())
    });
    group.finish();
}

criterion_group!(benches, kd_tree, photon_tracing);
criterion_main!(benches);
