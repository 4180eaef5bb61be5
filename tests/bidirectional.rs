//! Light tracing, BDPT, bidirectional photon mapping and VCM: their
//! multiple importance sampling weights sum to one over every strategy that
//! makes a path; their images agree with path tracing where it converges,
//! with the closed form in a furnace, and with SPPM on a caustic path
//! tracing cannot find; the same seed gives the same image on any number
//! of threads.

mod common;

use common::*;
use gi_studio::geometry::SurfaceHit;
use gi_studio::render::integrators::bidir::mis::{self, Partials, Strategies};
use gi_studio::render::world::bsdf::Bsdf;
use gi_studio::render::world::camera::CameraModel;
use gi_studio::render::world::emission::Bounds;
use gi_studio::render::world::light::LightSource;
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::World;
use gi_studio::render::MisHeuristic;
use gi_studio::scene::{Attenuation, MaterialModel, Shape};
use glam::Vec3;

/// A path x₀ (on a light) … x_k (the camera's pinhole) of random surface
/// vertices, each a random Lambert or Phong surface facing both its
/// neighbours.
struct RandomPath {
    points: Vec<Vec3>,
    normals: Vec<Vec3>,
    bsdfs: Vec<Bsdf>,
}

fn random_path(segments: usize, s: &mut Sampler) -> RandomPath {
    loop {
        if let Some(path) = try_random_path(segments, s) {
            return path;
        }
    }
}

/// A random path, or None where a vertex cannot face both neighbours
/// (they lie nearly opposite) by a cosine of 0.1.
fn try_random_path(segments: usize, s: &mut Sampler) -> Option<RandomPath> {
    let mut points = vec![Vec3::ZERO];
    for _ in 0..segments {
        let last = *points.last().unwrap();
        points.push(last + random_direction(s) * (0.3 + 2.0 * s.next_f32()));
    }
    let toward = |i: usize, j: usize| (points[j] - points[i]).normalize();
    let mut normals = Vec::new();
    for i in 0..=segments {
        let n = match i {
            0 => (toward(0, 1) + random_direction(s) * 0.3).normalize(),
            _ if i == segments => Vec3::ZERO,
            _ => ((toward(i, i - 1) + toward(i, i + 1)).normalize_or_zero() + random_direction(s) * 0.3).normalize(),
        };
        let neighbours = [i.checked_sub(1), (i < segments).then_some(i + 1)];
        if i < segments && neighbours.iter().flatten().any(|&j| n.dot(toward(i, j)) < 0.1) {
            return None;
        }
        normals.push(n);
    }
    let bsdfs = (0..=segments)
        .map(|_| match (s.next_f32() * 3.0) as u32 {
            0 => Bsdf::Lambert { albedo: Vec3::splat(0.2 + 0.7 * s.next_f32()) },
            1 => Bsdf::Phong { kd: Vec3::splat(0.4), ks: Vec3::splat(0.5), exponent: 1.0 + 30.0 * s.next_f32() },
            _ => Bsdf::BlinnPhong { kd: Vec3::splat(0.3), ks: Vec3::splat(0.6), exponent: 1.0 + 60.0 * s.next_f32() },
        })
        .collect();
    Some(RandomPath { points, normals, bsdfs })
}

impl RandomPath {
    fn k(&self) -> usize {
        self.points.len() - 1
    }

    fn direction(&self, from: usize, to: usize) -> Vec3 {
        (self.points[to] - self.points[from]).normalize()
    }

    fn distance2(&self, a: usize, b: usize) -> f32 {
        (self.points[a] - self.points[b]).length_squared()
    }

    fn cos(&self, at: usize, toward: usize) -> f32 {
        self.normals[at].dot(self.direction(at, toward)).abs()
    }

    fn facing(&self, at: usize, toward: usize) -> Vec3 {
        let n = self.normals[at];
        if n.dot(self.direction(at, toward)) < 0.0 {
            -n
        } else {
            n
        }
    }

    /// Vertex `at`'s BSDF density of leaving toward `to` having come from
    /// `from`, with its continuation (as the integrator scatters).
    fn pdf(&self, at: usize, from: usize, to: usize) -> f32 {
        let bsdf = &self.bsdfs[at];
        let (wo, wi) = (self.direction(at, from), self.direction(at, to));
        bsdf.pdf(wo, wi, self.facing(at, from)) * bsdf.continuation()
    }
}

/// The light subpath's partials arriving at x_j, and the camera subpath's
/// arriving at x_i, replayed as the integrator makes them.
fn light_partials(
    path: &RandomPath,
    light: &LightSource,
    bounds: Bounds,
    s: &Strategies,
    pick: f32,
    j: usize,
) -> Partials {
    let delta = light.is_delta();
    let direction = path.direction(0, 1);
    let emission = light.emission_pdf(bounds, path.points[0], path.normals[0], direction);
    let cos = if delta { 1.0 } else { path.cos(0, 1) };
    let mut partials = Partials::light(s, emission * pick, cos, delta);
    partials.first_hit(s, pick * light.direct_pdf_a(path.points[1], path.points[0], path.normals[0]));
    partials.arrive(s, Some(path.distance2(0, 1)), path.cos(1, 0));
    for v in 1..j {
        let (forward, reverse) = (path.pdf(v, v - 1, v + 1), path.pdf(v, v + 1, v - 1));
        partials.scatter(s, forward, reverse, path.cos(v, v + 1), false);
        partials.arrive(s, Some(path.distance2(v, v + 1)), path.cos(v + 1, v));
    }
    partials
}

fn camera_partials(path: &RandomPath, camera: &CameraModel, s: &Strategies, i: usize) -> Partials {
    let k = path.k();
    let mut partials = Partials::camera(s, camera.ray_pdf(path.direction(k, k - 1)));
    partials.arrive(s, Some(path.distance2(k, k - 1)), path.cos(k - 1, k));
    for v in (i + 1..k).rev() {
        let (forward, reverse) = (path.pdf(v, v + 1, v - 1), path.pdf(v, v - 1, v + 1));
        partials.scatter(s, forward, reverse, path.cos(v, v - 1), false);
        partials.arrive(s, Some(path.distance2(v, v - 1)), path.cos(v - 1, v));
    }
    partials
}

/// Every strategy's weight for `path`: hitting the light, next-event
/// estimation, each connection, the join to the camera, each merge.
fn weights(path: &RandomPath, light: &LightSource, camera: &CameraModel, s: &Strategies) -> Vec<f32> {
    let (k, pick) = (path.k(), 0.7);
    let bounds = Bounds { center: Vec3::ZERO, radius: 100.0 };
    let mut weights = Vec::new();
    if s.connect {
        if !light.is_delta() {
            // s = 0: the camera subpath meets the light
            let camera_side = camera_partials(path, camera, s, 0);
            let direct = pick * light.direct_pdf_a(path.points[1], path.points[0], path.normals[0]);
            let emission = pick * light.emission_pdf(bounds, path.points[0], path.normals[0], path.direction(0, 1));
            weights.push(mis::hit_light(s, &camera_side, direct, emission));
        }
        // s = 1: next-event estimation at x₁
        let camera_side = camera_partials(path, camera, s, 1);
        let (bsdf_pdf, reverse) = (path.pdf(1, 2, 0), path.pdf(1, 0, 2));
        let bsdf_pdf = if light.is_delta() { 0.0 } else { bsdf_pdf };
        let (direct_pdf, cos_light) = match light {
            LightSource::Point { .. } => (path.distance2(0, 1), 1.0),
            _ => {
                let hit = SurfaceHit { t: 1.0, point: path.points[0], normal: path.normals[0], error: 0.0 };
                (light.pdf(path.points[1], &hit), path.cos(0, 1))
            }
        };
        let emission = light.emission_pdf(bounds, path.points[0], path.normals[0], path.direction(0, 1));
        let cos_camera = path.cos(1, 0);
        weights.push(mis::direct(
            s,
            &camera_side,
            bsdf_pdf,
            reverse,
            pick,
            direct_pdf,
            emission,
            cos_camera,
            cos_light,
        ));
        // 2 ≤ s ≤ k − 1: light vertex x_{s−1} to camera vertex x_s
        for t in 2..k {
            let light_side = light_partials(path, light, bounds, s, pick, t - 1);
            let camera_side = camera_partials(path, camera, s, t);
            let d2 = path.distance2(t - 1, t);
            let camera_pdf_a = path.pdf(t, t + 1, t - 1) * path.cos(t - 1, t) / d2;
            let light_pdf_a = path.pdf(t - 1, t - 2, t) * path.cos(t, t - 1) / d2;
            let (light_reverse, camera_reverse) = (path.pdf(t - 1, t, t - 2), path.pdf(t, t - 1, t + 1));
            let w =
                mis::connect(s, &light_side, &camera_side, camera_pdf_a, light_pdf_a, light_reverse, camera_reverse);
            weights.push(w);
        }
        // s = k: x_{k−1} joined to the camera
        let light_side = light_partials(path, light, bounds, s, pick, k - 1);
        let camera_pdf_a = camera.ray_pdf(path.direction(k, k - 1)) * path.cos(k - 1, k) / path.distance2(k, k - 1);
        weights.push(mis::to_camera(s, &light_side, camera_pdf_a, path.pdf(k - 1, k, k - 2)));
    }
    if s.merge {
        for i in 1..k {
            let light_side = light_partials(path, light, bounds, s, pick, i);
            let camera_side = camera_partials(path, camera, s, i);
            let (forward, reverse) = (path.pdf(i, i + 1, i - 1), path.pdf(i, i - 1, i + 1));
            weights.push(mis::merge(s, &light_side, &camera_side, forward, reverse));
        }
    }
    weights
}

/// For random paths of 3 to 7 segments between a light (an emitting
/// triangle, or a point light) and a pinhole, with random diffuse and
/// glossy surfaces between: the weights of all strategies that make the
/// path, as the integrator computes them from its running sums, add up to
/// one — for connections alone (BDPT), merges alone (bidirectional photon
/// mapping) and both (VCM), with either heuristic. A weight built from the
/// wrong density (a forward pdf for a reverse one, a continuation left
/// out, a missing cosine) breaks the sum.
#[test]
fn the_weights_of_every_strategy_sum_to_one() {
    let mut s = Sampler::new(5, 0, 55);
    let (mut checked, mut worst) = (0, 0.0f64);
    for _ in 0..400 {
        let path = random_path(3 + (s.next_f32() * 5.0) as usize, &mut s);
        let k = path.k();
        // A camera at x_k looking at x_{k−1}, 64 × 48
        let look = camera(path.points[k], path.points[k - 1]);
        let model = CameraModel::new(&look, 64, 48);
        // An emitting triangle about x₀ with normal n₀
        let frame = gi_studio::geometry::Frame::from_z(path.normals[0]);
        let a = path.points[0];
        let (b, c) = (a + frame.x * 0.6, a + frame.y * 0.6 - frame.x * 0.2);
        let world = World::new(&valid(scene(
            look.clone(),
            vec![material("light", MaterialModel::Emissive { radiance: Vec3::ONE })],
            vec![object("panel", Shape::Triangle { a: a - (b - a) * 0.3 - (c - a) * 0.3, b, c }, "light")],
            vec![],
        )));
        let area = world.lights[0].clone();
        let point =
            LightSource::Point { position: path.points[0], intensity: Vec3::ONE, attenuation: Attenuation::default() };
        for light in [&area, &point] {
            for heuristic in [MisHeuristic::Power, MisHeuristic::Balance] {
                for (connect, merge) in [(true, false), (false, true), (true, true)] {
                    let strategies = Strategies::new(heuristic, connect, merge, 3072.0, 0.01 + 0.2 * s.next_f32());
                    let sum: f64 = weights(&path, light, &model, &strategies).iter().map(|w| *w as f64).sum();
                    let error = (sum - 1.0).abs();
                    assert!(
                        error < 1e-4,
                        "{k} segments, {light:?}, {heuristic:?}, connect {connect} merge {merge}: weights sum to {sum}"
                    );
                    worst = worst.max(error);
                    checked += 1;
                }
            }
        }
    }
    println!("{checked} paths, worst |Σw − 1| = {worst:.1e}");
}
