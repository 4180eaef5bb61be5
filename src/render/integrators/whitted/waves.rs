//! A tile's Whitted rays traced wave by wave: the camera rays, then every
//! ray their hits spawn, and so on, each wave's rays eight at a time through
//! the paths' hit loop (`flying`). What spawns what needs no random numbers,
//! so a pixel's tree of rays is known before any light is sampled; then
//! every shading hit samples its lights in the order the recursion would
//! (the tree depth first), every shadow ray is traced together, eight at a
//! time, and each pixel's tree is summed from its leaves as the recursion
//! sums it: the same light, bit for bit (`radiance`).

use super::shading::{branches, combine, light_term, lit_cosine, Branches};
use crate::geometry::Ray;
use crate::render::integrators::flying;
use crate::render::integrators::next_event::PathScope;
use crate::render::integrators::shadow_batch::ShadowBatch;
use crate::render::integrators::Counters;
use crate::render::world::camera::CameraTile;
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::light::LightSource;
use crate::render::world::materials::Bsdf;
use crate::render::world::occluders::Shadow;
use crate::render::world::{Hit, World};
use crate::scene::Rgb;

/// One ray of a pixel's tree.
struct Node {
    ray: Ray,
    /// The tree's root: its pixel, whose scope the ray shares.
    root: u32,
    depth_left: u32,
    weight: f32,
    hit: Option<Hit>,
    branches: Branches,
    /// The nodes its branches led to.
    children: [Option<u32>; 2],
    /// Its lights' terms in `Terms` (first, count).
    terms: (u32, u32),
}

/// The local model's term toward one light, nothing if its shadow ray is blocked.
struct Term {
    value: Rgb,
    shadow: u32,
}

/// Every sample of `tile`, rays `max_depth` deep, into `out`.
pub fn render_tile(
    world: &World,
    lanes: Option<&LaneWorld>,
    tile: &CameraTile,
    max_depth: u32,
    out: &mut [Rgb],
    counters: &mut Counters,
) {
    let count = out.len();
    let (mut samplers, mut scopes, mut nodes) = (Vec::with_capacity(count), Vec::with_capacity(count), Vec::new());
    for i in 0..count {
        let (ray, sampler) = tile.sample(i);
        samplers.push(sampler);
        scopes.push(PathScope::new(world, ray.origin));
        let root = i as u32;
        nodes.push(Node {
            ray,
            root,
            depth_left: max_depth,
            weight: 1.0,
            hit: None,
            branches: Branches::default(),
            children: [None; 2],
            terms: (0, 0),
        });
    }
    // The trees, wave by wave
    let mut wave: Vec<u32> = (0..count as u32).collect();
    let mut hits = Vec::new();
    while !wave.is_empty() {
        counters.rays += wave.len() as u64;
        hits.clear();
        hits.resize(wave.len(), None);
        let launch = |k: u64| Some(wave[k as usize]);
        let ray = |&node: &u32| (nodes[node as usize].ray, scopes[nodes[node as usize].root as usize].held);
        let bounce = |place: u32, _: &mut u32, hit: Option<&Hit>| {
            hits[place as usize] = hit.copied();
            false
        };
        flying::fly(lanes, world, 0..wave.len() as u64, launch, ray, bounce);
        let mut next = Vec::new();
        for (&node, hit) in wave.iter().zip(&hits) {
            let Some(hit) = *hit else { continue };
            let n = &mut nodes[node as usize];
            n.hit = Some(hit);
            n.branches = branches(world, &n.ray, &hit, n.depth_left, n.weight);
            let (root, depth_left, found) = (n.root, n.depth_left, n.branches);
            for (slot, branch) in [found.reflected, found.refracted].into_iter().enumerate() {
                if let Some((ray, weight)) = branch {
                    let child = nodes.len() as u32;
                    nodes[node as usize].children[slot] = Some(child);
                    let depth_left = depth_left - 1;
                    nodes.push(Node {
                        ray,
                        root,
                        depth_left,
                        weight,
                        hit: None,
                        branches: Branches::default(),
                        children: [None; 2],
                        terms: (0, 0),
                    });
                    next.push(child);
                }
            }
        }
        wave = next;
    }
    // Each tree's lights sampled depth first, as the recursion samples them
    let (mut terms, mut shadows) = (Vec::new(), ShadowBatch::default());
    let mut stack = Vec::new();
    for root in 0..count {
        stack.push(root as u32);
        while let Some(node) = stack.pop() {
            let n = &nodes[node as usize];
            // The reflection's tree before the refraction's
            let [first, second] = n.children;
            stack.extend(second);
            stack.extend(first);
            let Some(hit) = n.hit else { continue };
            // The material once a hit, not once a light
            let bsdf = Bsdf::new(world.material_of(&hit));
            if !bsdf.thesis_lit() {
                continue;
            }
            let at = super::shading::at(&n.ray, &hit);
            let normal = at.facing.into();
            let (scope, sampler) = (&scopes[root], &mut samplers[root]);
            let first = terms.len() as u32;
            for light in world.lights.iter().filter(|l| !matches!(l, LightSource::Background { .. })) {
                let lit = |sample: &_| lit_cosine(normal, sample);
                if let Some((sample, cos)) =
                    scope.unshadowed_light_sample(light, &hit, sampler.next_2d(), counters, lit)
                {
                    let shadow = shadows.push(Shadow::toward(&sample, scope.held));
                    terms.push(Term { value: light_term(&bsdf, &at, &sample, cos), shadow });
                }
            }
            nodes[node as usize].terms = (first, terms.len() as u32 - first);
        }
    }
    shadows.trace(lanes, world);
    for (root, value) in out.iter_mut().enumerate() {
        *value = radiance(world, &nodes, &terms, &shadows, root as u32);
    }
}

/// The light node `node`'s tree brings, summed as the recursion sums it.
fn radiance(world: &World, nodes: &[Node], terms: &[Term], shadows: &ShadowBatch, node: u32) -> Rgb {
    let n = &nodes[node as usize];
    let Some(hit) = n.hit else { return world.background };
    let (first, count) = n.terms;
    let mut local = Rgb::ZERO;
    for term in &terms[first as usize..(first + count) as usize] {
        if !shadows.blocked(term.shadow) {
            local += term.value;
        }
    }
    let follow = |child: Option<u32>| child.map_or(Rgb::ZERO, |child| radiance(world, nodes, terms, shadows, child));
    let (reflected, refracted) = (follow(n.children[0]), follow(n.children[1]));
    combine(world, &n.ray, &hit, local, [reflected, refracted], &n.branches)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::world::camera::{CameraModel, TileRect};
    use crate::render::world::rng::PassStreams;
    use crate::scene::{presets, Scene, ValidScene};

    /// Every preset, a thin lens and a camera outside the Cornell box's
    /// walls, depth caps of one, two and twelve: the tile's waves, eight
    /// rays at a time or one, give the recursion's light bit for bit, and
    /// count the same rays.
    #[test]
    fn waves_give_the_recursions_light() {
        let mut scenes: Vec<(String, Scene)> = presets::names()
            .map(|n| (n.to_string(), presets::preset(n).and_then(Result::ok).expect("preset").into_scene()))
            .collect();
        let mut lens = scenes[0].1.clone();
        (lens.camera.position, lens.camera.aperture_radius, lens.camera.focus_distance) =
            (Vec3::new(0.9, 1.0, 3.4), 0.3, 3.0);
        scenes.push(("a lens reaching outside the walls".into(), lens));
        for (name, scene) in &scenes {
            let (width, height) = (40, 30);
            let camera = CameraModel::new(&scene.camera, width, height);
            let valid = ValidScene::new(scene.clone()).expect("valid");
            let (world, _) = World::for_view(&valid, &camera, width, height);
            let lanes = LaneWorld::new(&world);
            // Rows that do not split into eights, away from the corner
            let rect = TileRect { x: 5, y: 3, width: 27, height: 13 };
            let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(3, 7) };
            for max_depth in [1, 2, 12] {
                let mut expected_counters = Counters::default();
                let expected: Vec<Rgb> = (0..rect.pixels())
                    .map(|i| {
                        let (ray, mut sampler) = tile.sample(i);
                        super::super::radiance(&world, &ray, max_depth, &mut sampler, &mut expected_counters)
                    })
                    .collect();
                for lanes in [lanes.as_ref(), None] {
                    let (mut got, mut counters) = (vec![Rgb::splat(-1.0); rect.pixels()], Counters::default());
                    render_tile(&world, lanes, &tile, max_depth, &mut got, &mut counters);
                    let bits = |v: &[Rgb]| v.iter().map(|c| c.to_array().map(f32::to_bits)).collect::<Vec<_>>();
                    let how = if lanes.is_some() { "eight at a time" } else { "one at a time" };
                    assert!(bits(&got) == bits(&expected), "{name}, depth {max_depth}, {how}: the light differs");
                    assert_eq!(counters.rays, expected_counters.rays, "{name}, depth {max_depth}, {how}");
                }
                // (gap-room's lamp lights the camera's room through its doorway only)
                let lit = expected.iter().filter(|c| c.max_element() > 0.0).count();
                assert!(lit > rect.pixels() / 10, "{name}: only {lit} pixels lit");
            }
        }
    }
}
