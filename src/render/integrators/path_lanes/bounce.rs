//! One bounce of eight paths: `path::radiance`'s loop body lane by lane,
//! and the loop that keeps the lanes busy with the tile's samples.

use super::samples::CameraSamples;
use super::state::Lanes;
use crate::faults::{self, Fault};
use crate::geometry::{offset_origin, SurfaceHit};
use crate::render::integrators::{Counters, ROULETTE_DEPTH};
use crate::render::world::camera::CameraTile;
use crate::render::world::lane_world::{LaneHits, LaneSurfaces, LaneWorld, LightLanes, Scattered, Skips};
use crate::render::world::lanes::{self, F8, LANES, M8, V8};
use crate::render::world::materials::Transport;
use crate::render::world::sampling::{power_heuristic, power_heuristic_of, uniform_sphere_pdf};
use crate::render::world::World;
use crate::scene::Rgb;

/// The radiance of every camera sample of `tile`, each handed to `out`
/// with its index as its path ends. The film adds it there and then, so
/// fetching the pixel's sums overlaps the other lanes' work, where a pass
/// over an array of samples after the tile would wait on each cache line.
pub fn radiance(
    lane_world: &LaneWorld,
    world: &World,
    tile: &CameraTile,
    max_depth: u32,
    out: &mut impl FnMut(usize, Rgb),
    counters: &mut Counters,
) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the CPU has AVX2: a `LaneWorld` is made only where it does.
    #[allow(unsafe_code)]
    unsafe {
        radiance_avx2(lane_world, world, tile, max_depth, out, counters)
    };
    #[cfg(not(target_arch = "x86_64"))]
    radiance_lanes(lane_world, world, tile, max_depth, out, counters);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn radiance_avx2(
    lane_world: &LaneWorld,
    world: &World,
    tile: &CameraTile,
    max_depth: u32,
    out: &mut impl FnMut(usize, Rgb),
    counters: &mut Counters,
) {
    radiance_lanes(lane_world, world, tile, max_depth, out, counters);
}

#[inline(always)]
fn radiance_lanes(
    lane_world: &LaneWorld,
    world: &World,
    tile: &CameraTile,
    max_depth: u32,
    out: &mut impl FnMut(usize, Rgb),
    counters: &mut Counters,
) {
    if max_depth == 0 {
        (0..tile.len()).for_each(|i| out(i, Rgb::ZERO));
        return;
    }
    let samples = CameraSamples::new(tile, world);
    let mut state = Lanes::new();
    // Which sample each lane traces: apart from the lanes' registers, as
    // indexing it by lane would keep them all in memory
    let mut slots = [0; LANES];
    let mut next = 0;
    loop {
        state.start_idle(&samples, &mut slots, &mut next, tile.len());
        if !state.active.any() {
            return;
        }
        bounce(lane_world, world, &mut state, &slots, max_depth, out, counters);
    }
}

/// One bounce of every active path: `path::radiance`'s loop body. The
/// paths that end here hand their radiance out.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn bounce(
    lane_world: &LaneWorld,
    world: &World,
    st: &mut Lanes,
    slots: &[usize; LANES],
    max_depth: u32,
    out: &mut impl FnMut(usize, Rgb),
    counters: &mut Counters,
) {
    let done = bounce_live(lane_world, world, st, max_depth, counters);
    st.finish(done, slots, out);
}

/// `bounce` short of handing out: returns the lanes whose paths ended.
#[inline(always)]
fn bounce_live(lane_world: &LaneWorld, world: &World, st: &mut Lanes, max_depth: u32, counters: &mut Counters) -> M8 {
    let active = st.active;
    counters.rays += active.count();
    let (origin, direction) = (st.origin, st.direction);

    let held = st.inside_walls;
    let light_count = world.lights.len();
    // The one light's point for the light draw ahead (a lane's first
    // draw this bounce), where it does not depend on the hit
    let light_ahead = if light_count == 1 { lane_world.lights.drawn_ahead(st.rng.peek_2d()) } else { None };
    let LaneHits { found, t: t_hit, shape, point, normal, error } = lane_world.nearest(active, held, origin, direction);
    let missed = active.and_not(found);
    let pick_pdf = 1.0 / light_count.max(1) as f32;
    if missed.any() {
        // The background, weighted against sampling it as a light
        let mis = power_heuristic_of(st.last_pdf, F8::splat(pick_pdf * uniform_sphere_pdf()));
        let weight = st.after_delta.select(F8::splat(1.0), mis);
        let lit = st.radiance + st.throughput * V8::splat(lane_world.background) * weight;
        st.radiance = missed.select_v(lit, st.radiance);
    }
    let alive = found;
    if !alive.any() {
        return missed;
    }
    let mut surfaces = LaneSurfaces::new(&lane_world.surfaces, shape, alive);
    let (emissive, color) = (surfaces.emissive, surfaces.color);
    let wo = -direction;
    let hit =
        |i: usize| SurfaceHit { t: t_hit.lane(i), point: point.lane(i), normal: normal.lane(i), error: error.lane(i) };

    // Emission reached by this ray, weighted against light sampling (rare: lane by lane)
    let glowing = emissive.and(normal.dot(wo).gt(F8::splat(0.0))).and(color.nonzero());
    let shapes = if glowing.any() { shape.to_array() } else { [0; LANES] };
    for lane in glowing.lanes() {
        let surface = &lane_world.surfaces.records[shapes[lane] as usize];
        let object = surface.object;
        let weight = match world.objects[object as usize].light {
            Some(light) if !st.after_delta.test(lane) => power_heuristic(
                st.last_pdf.lane(lane),
                pick_pdf * world.lights[light as usize].pdf(st.last_point.lane(lane), &hit(lane)),
            ),
            _ => 1.0,
        };
        let sum = st.radiance.lane(lane) + st.throughput.lane(lane) * surface.color * weight;
        st.radiance.set_lane(lane, sum);
    }
    // A path at its last segment's end neither samples a light nor scatters
    let last = alive.and(st.depth.ge(max_depth - 1));
    if last.any() {
        surfaces.keep(alive.and_not(last));
    }
    // What next-event estimation shades
    let diffuse = surfaces.shaded();

    let facing = normal.dot(wo).lt(F8::splat(0.0)).select_v(-normal, normal);
    let zero = F8::splat(0.0);

    // Next-event estimation toward one light, chosen uniformly: its
    // draws and its point, then the scattering (drawing after the
    // light, as each lane has always drawn), then the shadow ray. So
    // ordered, each long chain of dependent work (the light's point,
    // the next ray) starts before the work that waits on the other
    let shading = if light_count > 0 && diffuse.any() {
        let pick: [usize; LANES] = if light_count == 1 {
            [0; LANES]
        } else {
            let u_pick = st.rng.next_f32(diffuse);
            let u_pick = u_pick.to_array();
            lanes::each(|i| ((u_pick[i] * light_count as f32) as usize).min(light_count - 1))
        };
        let u = st.rng.next_2d(diffuse);
        Some((
            pick,
            LightLanes::sample(&lane_world.lights, world, &pick, diffuse, point, normal, error, u, light_ahead, &hit),
        ))
    } else {
        None
    };
    // Scattering, each material drawing what it uses (`Bsdf::sample`)
    let Scattered { go, wi, weight, pdf, .. } = surfaces.scatter(&mut st.rng, wo, normal, facing, Transport::Radiance);
    if let Some((pick, light)) = shading {
        // f where both directions are above the surface
        let above = !light.wi.dot(facing).le(zero).or(wo.dot(facing).le(zero));
        let (f, bsdf_pdf) = surfaces.eval_pdf(light.valid.and(above), wo, light.wi, facing);
        let shade = light.valid.and(above).and(f.nonzero());
        counters.rays += shade.count();
        if shade.any() {
            let skips = if light_count == 1 {
                Skips::All { sphere: lane_world.light_spheres[0], plane: lane_world.light_planes[0] }
            } else {
                let spheres = lanes::each(|i| lane_world.light_spheres[pick[i]]);
                Skips::Lanes { spheres, planes: lanes::each(|i| lane_world.light_planes[pick[i]]) }
            };
            let blocked = lane_world.blocked(shade, st.inside_walls, light.origin, light.wi, light.t_max, &skips);
            let lit = shade.and_not(blocked);
            if lit.any() {
                let cos = light.wi.dot(facing);
                let mis = power_heuristic_of(pick_pdf * light.pdf, bsdf_pdf);
                let weight = light.delta.select(F8::splat(1.0), mis);
                let term = st.throughput * f * light.value * (cos * weight / pick_pdf);
                st.radiance = lit.select_v(st.radiance + term, st.radiance);
            }
        }
    }
    let done = missed.or(alive.and_not(go));
    if !go.any() {
        return done;
    }
    st.throughput = go.select_v(st.throughput * weight, st.throughput);
    st.after_delta = diffuse.select_mask(M8::NONE, go.select_mask(M8::ALL, st.after_delta));
    st.last_pdf = go.select(pdf, st.last_pdf);
    st.last_point = go.select_v(point, st.last_point);

    // Paths that can carry no more light end now; Russian roulette
    // after the first bounces
    let survive = st.throughput.max_element().min(F8::splat(0.95));
    let mut killed = go.and(survive.le(zero));
    let roulette = st.depth.ge(ROULETTE_DEPTH - 1).and(go).and_not(killed);
    if roulette.any() {
        let u = st.rng.next_f32(roulette);
        let stop = roulette.and(u.ge(survive));
        let kept = roulette.and_not(stop);
        killed = killed.or(stop);
        if !faults::active(Fault::RouletteUndivided) {
            st.throughput = kept.select_v(st.throughput / survive, st.throughput);
        }
    }
    let go = go.and_not(killed);
    st.origin = go.select_v(offset_origin(point, error, normal, wi), st.origin);
    st.direction = go.select_v(wi, st.direction);
    st.depth = st.depth.count_in(go);
    done.or(killed)
}
