//! Path tracing eight paths at a time: each sphere, plane and triangle is
//! tested against eight rays in one SIMD pass (a triangle behind a test of
//! where the rays cross its plane, `geometry::cull`), and the shading, the BSDFs and
//! light sampling run in the same lanes. A lane whose path ends takes the
//! next sample, so lanes stay busy however long the paths are.
//!
//! It is `path::radiance` lane by lane, not an approximation of it: the
//! same operations in the same order on the same random streams, so the
//! image is bit for bit the scalar one (`tests/path_lanes.rs` checks it).
//! Rare cases call the scalar code for that lane: a BSDF-sampled ray
//! reaching a light, the background sampled as a light, a ray exactly on a
//! triangle's edge.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

mod draws;
mod glossy;
mod lights;
mod samples;
mod scatter;
mod surface_table;
mod wall_exits;

pub(crate) use draws::{Given, PickedLight, Want};
pub(crate) use lights::EmittedLanes;
use lights::{LaneLights, LightLanes};
use samples::CameraSamples;
pub(crate) use scatter::{LaneSurfaces, Scattered};
use surface_table::SurfaceTable;
use wall_exits::WallExits;

use super::{Counters, ROULETTE_DEPTH};
use crate::faults::{self, Fault};
use crate::geometry::sphere::{nearest_root, wall_exit_hit, wall_slack, AnchoredSphere};
use crate::geometry::{edges_of, ray_shear_of, triangle_hit_of, watertight_finish_of, watertight_range_of, RayShear};
use crate::geometry::{gamma, intersect_triangle, offset_origin, Ray, SurfaceHit, Triangle};
use crate::geometry::{plane_exit_of, plane_point_of, plane_t_of, Crossing, CullEdges, CullPlane};
use crate::render::world::bsdf::{blinn_normalisation, Bsdf, Transport};
use crate::render::world::camera::CameraTile;
use crate::render::world::lanes::{self, Column, Column3, Count8, Index8, Rng8, F8, LANES, M8, V8};
use crate::render::world::light::{Emitter, LightSource};
use crate::render::world::occluders::Shadow;
use crate::render::world::sampling::{power_heuristic, power_heuristic_of, uniform_sphere_pdf};
use crate::render::world::{Hit, ShapeRef, World};
use crate::scene::{MaterialModel, Rgb};

/// The `Bsdf` each shape's lanes run, as a float to compare eight at a
/// time.
const LAMBERT: f32 = 0.0;
const MIRROR: f32 = 1.0;
const GLASS: f32 = 2.0;
const EMITTER: f32 = 3.0;
const PHONG: f32 = 4.0;
const BLINN_PHONG: f32 = 5.0;

/// What shading needs of a shape's material.
#[derive(Clone, Copy, Debug)]
struct Surface {
    object: u32,
    /// `LAMBERT`, `MIRROR`, `GLASS`, `EMITTER`, `PHONG` or `BLINN_PHONG`.
    kind: f32,
    /// Albedo, tint, radiance or a glossy surface's diffuse part.
    color: Rgb,
    ior: f32,
    /// A glossy surface's lobe: its colour, exponent, the chance of
    /// sampling the diffuse part and Blinn–Phong's normalisation.
    specular: Rgb,
    exponent: f32,
    diffuse_probability: f32,
    normalisation: f32,
}

/// One sphere, as the hit loop meets it.
#[derive(Clone, Copy, Debug)]
struct SphereInfo {
    center: Vec3,
    radius2: f32,
    /// Its index among the shapes, as the lanes count them.
    shape: f32,
    /// A wall (`occluders::Walls`), about its point nearest the camera:
    /// paths inside every wall meet it only on their way out (`wall_exit`).
    wall: Option<AnchoredSphere>,
}

/// What a sphere's hit is rebuilt from, a column per field, indexed by
/// shape (`PathLanes::sphere_hits`).
#[derive(Clone, Debug)]
struct SphereColumns {
    center: Column3,
    radius: Column,
    /// 1 for a wall, 0 for any other sphere.
    wall: Column,
    /// Bound on the error of points computed on it (as `sphere_hit` gives).
    error: Column,
    /// A wall's `wall_slack` (0 for any other sphere).
    wall_slack: Column,
}

impl SphereColumns {
    /// For `spheres`, of radii `radii`.
    fn new(spheres: &[SphereInfo], radii: &[f32]) -> Self {
        let column = |field: &dyn Fn(&SphereInfo, f32) -> f32| {
            Column::new(spheres.iter().zip(radii).map(|(sphere, &radius)| field(sphere, radius)))
        };
        SphereColumns {
            center: Column3::new(spheres.iter().map(|s| s.center)),
            radius: column(&|_, radius| radius),
            wall: column(&|s, _| s.wall.map_or(0.0, |_| 1.0)),
            error: column(&|s, radius| gamma(6) * (s.center.abs().max_element() + radius)),
            wall_slack: column(&|s, _| s.wall.map_or(0.0, |w| wall_slack(&w))),
        }
    }
}

/// One plane, as the hit loop and shadow rays meet it.
#[derive(Clone, Copy, Debug)]
struct PlaneInfo {
    normal: Vec3,
    offset: f32,
    /// A wall (`occluders::WallPlane`): its inside `inward · x > offset`,
    /// which paths inside every wall leave only through it.
    wall: Option<(Vec3, f32)>,
}

/// A sphere as shadow rays test it.
#[derive(Clone, Copy, Debug)]
struct Occluder {
    center: Vec3,
    radius2: f32,
    /// Its index in the world, if a light lies on it: that light's shadow
    /// rays skip it (`occluders`: they meet it only at their end).
    emitter: Option<u32>,
}

/// What `PathLanes::nearest` finds for eight rays.
pub(crate) struct LaneHits {
    pub(crate) found: M8,
    t: F8,
    /// Spheres, then planes, then triangles: an index into `surfaces`.
    shape: Index8,
    pub(crate) point: V8,
    /// The geometric normal.
    pub(crate) normal: V8,
    pub(crate) error: F8,
}

/// A world compiled for eight-lane path tracing.
#[derive(Clone, Debug)]
pub struct PathLanes {
    spheres: Vec<SphereInfo>,
    sphere_columns: SphereColumns,
    planes: Vec<PlaneInfo>,
    /// The planes' normals and offsets, indexed by shape (zeros before
    /// the first plane).
    plane_normals: Column3,
    plane_offsets: Column,
    triangles: Vec<Triangle>,
    /// What the cull reads of each triangle, in one record (read from the
    /// triangle and a list of runs beside it, its loads and bounds checks
    /// were 5% of gap-room's instructions).
    triangle_culls: Vec<LaneCull>,
    /// Each triangle's light plane (`World::light_plane`): a shadow ray
    /// toward a light on a triangle skips the triangles of its plane.
    triangle_planes: Vec<u32>,
    /// Spheres, then planes, then triangles: what shading needs of each.
    surfaces: SurfaceTable,
    /// Shadow rays test these always, and the walls only for paths not
    /// inside every wall (see `occluders::Walls`).
    others: Vec<Occluder>,
    walls: Vec<Occluder>,
    lights: LaneLights,
    /// The sphere each light lies on, if any.
    light_spheres: Vec<Option<u32>>,
    /// The light plane of the triangle each light lies on, if any.
    light_planes: Vec<Option<u32>>,
    background: Rgb,
    /// The walls, as held rays ask where they leave.
    wall_exits: WallExits,
    /// The spheres that are not walls, which is all a held ray asks of
    /// the spheres but where it leaves them.
    inner_spheres: Vec<SphereInfo>,
}

impl PathLanes {
    /// For worlds of spheres, planes and triangles on a CPU that runs the
    /// lanes (`None` for a world of none, or a CPU without AVX2).
    pub fn new(world: &World) -> Option<Self> {
        // Its methods run AVX2 without asking again
        if !lanes::supported() {
            return None;
        }
        let surface = |object: u32| {
            let material = &world.materials[world.objects[object as usize].material as usize];
            let plain = |kind, color, ior| Surface {
                object,
                kind,
                color,
                ior,
                specular: Rgb::ZERO,
                exponent: 0.0,
                diffuse_probability: 1.0,
                normalisation: 0.0,
            };
            let glossy = |kind, kd, ks, exponent, normalisation| Surface {
                specular: ks,
                exponent,
                diffuse_probability: Bsdf::diffuse_probability(kd, ks),
                normalisation,
                ..plain(kind, kd, 1.0)
            };
            match (Bsdf::new(material), material) {
                (Bsdf::Lambert { albedo }, _) => plain(LAMBERT, albedo, 1.0),
                (Bsdf::Mirror { tint }, _) => plain(MIRROR, tint, 1.0),
                (Bsdf::Glass { ior, tint }, _) => plain(GLASS, tint, ior),
                (Bsdf::Phong { kd, ks, exponent }, _) => glossy(PHONG, kd, ks, exponent, 0.0),
                (Bsdf::BlinnPhong { kd, ks, exponent }, _) => {
                    glossy(BLINN_PHONG, kd, ks, exponent, blinn_normalisation(exponent))
                }
                (Bsdf::Black, MaterialModel::Emissive { radiance }) => plain(EMITTER, *radiance, 1.0),
                // Reflects nothing, emits nothing: an emitter gone dark
                (Bsdf::Black, _) => plain(EMITTER, Rgb::ZERO, 1.0),
            }
        };
        let s = &world.spheres;
        let objects = s.object.iter().copied();
        let objects = objects.chain(world.planes.iter().map(|p| p.object));
        let surfaces = objects.chain(world.triangles.iter().map(|(_, object)| *object)).map(surface);
        let surfaces: Vec<_> = surfaces.collect();
        if surfaces.is_empty() {
            return None;
        }
        let wall = |i: usize| world.walls.wall_spheres.iter().find(|(j, _)| *j as usize == i).map(|(_, w)| *w);
        let spheres: Vec<SphereInfo> = (0..s.radius.len())
            .map(|i| {
                let radius = s.radius[i];
                SphereInfo { center: s.center(i), radius2: radius * radius, shape: i as f32, wall: wall(i) }
            })
            .collect();
        let planes: Vec<PlaneInfo> = (world.planes.iter())
            .map(|plane| PlaneInfo {
                normal: plane.normal,
                offset: plane.offset,
                wall: (world.walls.wall_planes.iter())
                    .find(|wall| wall.plane.object == plane.object)
                    .map(|wall| (wall.inward, wall.offset)),
            })
            .collect();
        let light_planes = (world.lights.iter())
            .map(|light| match *light {
                LightSource::Area { emitter: Emitter::Triangle { triangle, .. }, .. } => {
                    Some(world.light_plane[triangle as usize])
                }
                _ => None,
            })
            .collect();
        // The sphere each light lies on
        let light_spheres: Vec<Option<u32>> = (world.lights.iter())
            .map(|light| match *light {
                LightSource::Area { object, .. } => match world.objects[object as usize].shape {
                    ShapeRef::Sphere(i) => Some(i),
                    _ => None,
                },
                _ => None,
            })
            .collect();
        let occluder = |i: usize| Occluder {
            center: spheres[i].center,
            radius2: spheres[i].radius2,
            emitter: light_spheres.contains(&Some(i as u32)).then_some(i as u32),
        };
        let (walls, others) = (0..spheres.len()).partition::<Vec<_>, _>(|&i| spheres[i].wall.is_some());
        let before_planes = std::iter::repeat_n(None, spheres.len());
        let by_shape = || before_planes.clone().chain(planes.iter().map(Some));
        let inner_spheres = spheres.iter().filter(|s| s.wall.is_none()).copied().collect();
        Some(PathLanes {
            inner_spheres,
            others: others.into_iter().map(occluder).collect(),
            walls: walls.into_iter().map(occluder).collect(),
            sphere_columns: SphereColumns::new(&spheres, &s.radius),
            spheres,
            plane_normals: Column3::new(by_shape().map(|p| p.map_or(Vec3::ZERO, |p| p.normal))),
            plane_offsets: Column::new(by_shape().map(|p| p.map_or(0.0, |p| p.offset))),
            planes,
            triangles: world.triangles.iter().map(|(triangle, _)| *triangle).collect(),
            triangle_culls: lane_culls(&world.triangles),
            triangle_planes: world.light_plane.clone(),
            surfaces: SurfaceTable::new(surfaces),
            lights: LaneLights::new(world),
            light_spheres,
            light_planes,
            background: world.background,
            wall_exits: WallExits::new(&world.walls.wall_spheres),
        })
    }

    /// Whether `radiance` traces eight lanes at once on this CPU (AVX2 on
    /// x86-64), rather than falling back to the scalar tracer.
    pub fn runs_in_lanes() -> bool {
        lanes::supported()
    }

    /// The nearest hits of up to eight rays, each `held` or not as
    /// `World::intersect_held` takes it, still in the lanes (`hits_of`
    /// gives them lane by lane: that function's hits, bit for bit), and the
    /// rays' directions; for callers that go on lane by lane (photons,
    /// light and camera subpaths, `flying`). Fast only inlined into code
    /// built for AVX2.
    #[inline(always)]
    pub(crate) fn lane_hits(&self, rays: &[Option<(Ray, bool)>; LANES]) -> (LaneHits, V8) {
        let active = M8::from_fn(|i| rays[i].is_some());
        let held = M8::from_fn(|i| rays[i].is_some_and(|(_, held)| held));
        let ray = |i: usize| rays[i].map_or(Ray::new(Vec3::ZERO, Vec3::Z), |(ray, _)| ray);
        let origin = V8::from_fn(|i| ray(i).origin);
        let direction = V8::from_fn(|i| ray(i).direction);
        (self.nearest(active, held, origin, direction), direction)
    }

    /// `lane_hits`' hits lane by lane, as `World::intersect_held` gives them.
    #[inline(always)]
    pub(crate) fn hits_of(&self, world: &World, hits: &LaneHits) -> [Option<Hit>; LANES] {
        // Out of the registers first: the closure below does not inherit AVX2
        let found = hits.found.bits();
        let shape = hits.shape.to_array();
        let t = hits.t.to_array();
        let error = hits.error.to_array();
        let point = [hits.point.x.to_array(), hits.point.y.to_array(), hits.point.z.to_array()];
        let normal = [hits.normal.x.to_array(), hits.normal.y.to_array(), hits.normal.z.to_array()];
        lanes::each(|i| {
            (found & 1 << i != 0).then(|| {
                let object = self.surfaces.records[shape[i] as usize].object;
                let surface = SurfaceHit {
                    t: t[i],
                    point: Vec3::new(point[0][i], point[1][i], point[2][i]),
                    normal: Vec3::new(normal[0][i], normal[1][i], normal[2][i]),
                    error: error[i],
                };
                Hit { surface, object, material: world.objects[object as usize].material }
            })
        })
    }

    /// The nearest hits of the rays of `active` (`held` those inside every
    /// wall) and the surfaces there, for callers that bounce in the lanes
    /// (photons). Fast only inlined into code built for AVX2.
    #[inline(always)]
    pub(crate) fn hit_surfaces(&self, active: M8, held: M8, origin: V8, direction: V8) -> (LaneHits, LaneSurfaces<'_>) {
        let hits = self.nearest(active, held, origin, direction);
        let surfaces = LaneSurfaces::new(&self.surfaces, hits.shape, hits.found);
        (hits, surfaces)
    }

    /// `LightSource::emit` for each lane's light (`pick`, an index into
    /// the world's lights) in the lanes of `mask`, from the draws `u1`, `u2`.
    /// Fast only inlined into code built for AVX2.
    #[inline(always)]
    pub(crate) fn emit(
        &self,
        world: &World,
        pick: &[usize; LANES],
        mask: M8,
        u1: (F8, F8),
        u2: (F8, F8),
    ) -> EmittedLanes {
        self.lights.emit(world, pick, mask, u1, u2)
    }

    /// The radiance of every camera sample of `tile`, each handed to `out`
    /// with its index as its path ends. The film adds it there and then, so
    /// fetching the pixel's sums overlaps the other lanes' work (a pass over
    /// an array of samples after the tile waited on each cache line: 3% of
    /// smallpt's time).
    pub fn radiance(
        &self,
        world: &World,
        tile: &CameraTile,
        max_depth: u32,
        out: &mut impl FnMut(usize, Rgb),
        counters: &mut Counters,
    ) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has AVX2: a `PathLanes` is made only where it does.
        #[allow(unsafe_code)]
        unsafe {
            self.radiance_avx2(world, tile, max_depth, out, counters)
        };
        #[cfg(not(target_arch = "x86_64"))]
        self.radiance_lanes(world, tile, max_depth, out, counters);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn radiance_avx2(
        &self,
        world: &World,
        tile: &CameraTile,
        max_depth: u32,
        out: &mut impl FnMut(usize, Rgb),
        counters: &mut Counters,
    ) {
        self.radiance_lanes(world, tile, max_depth, out, counters);
    }

    #[inline(always)]
    fn radiance_lanes(
        &self,
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
            self.bounce(world, &mut state, &slots, max_depth, out, counters);
        }
    }

    /// One bounce of every active path: `path::radiance`'s loop body. The
    /// paths that end here hand their radiance out.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn bounce(
        &self,
        world: &World,
        st: &mut Lanes,
        slots: &[usize; LANES],
        max_depth: u32,
        out: &mut impl FnMut(usize, Rgb),
        counters: &mut Counters,
    ) {
        let done = self.bounce_live(world, st, max_depth, counters);
        st.finish(done, slots, out);
    }

    /// `bounce` short of handing out: returns the lanes whose paths ended.
    #[inline(always)]
    fn bounce_live(&self, world: &World, st: &mut Lanes, max_depth: u32, counters: &mut Counters) -> M8 {
        let active = st.active;
        counters.rays += active.count();
        let (origin, direction) = (st.origin, st.direction);

        let held = st.inside_walls;
        let light_count = world.lights.len();
        // The one light's point for the light draw ahead (a lane's first
        // draw this bounce), where it does not depend on the hit
        let light_ahead = if light_count == 1 { self.lights.drawn_ahead(st.rng.peek_2d()) } else { None };
        let LaneHits { found, t: t_hit, shape, point, normal, error } = self.nearest(active, held, origin, direction);
        let missed = active.and_not(found);
        let pick_pdf = 1.0 / light_count.max(1) as f32;
        if missed.any() {
            // The background, weighted against sampling it as a light
            let mis = power_heuristic_of(st.last_pdf, F8::splat(pick_pdf * uniform_sphere_pdf()));
            let weight = st.after_delta.select(F8::splat(1.0), mis);
            let lit = st.radiance + st.throughput * V8::splat(self.background) * weight;
            st.radiance = missed.select_v(lit, st.radiance);
        }
        let alive = found;
        if !alive.any() {
            return missed;
        }
        let surfaces = LaneSurfaces::new(&self.surfaces, shape, alive);
        let LaneSurfaces { emissive, ref glossy, color, .. } = surfaces;
        // What next-event estimation shades
        let diffuse = surfaces.lambert.or(glossy.mask());
        let wo = -direction;
        let hit = |i: usize| SurfaceHit {
            t: t_hit.lane(i),
            point: point.lane(i),
            normal: normal.lane(i),
            error: error.lane(i),
        };

        // Emission reached by this ray, weighted against light sampling (rare: lane by lane)
        let glowing = emissive.and(normal.dot(wo).gt(F8::splat(0.0))).and(color.nonzero());
        let shapes = if glowing.any() { shape.to_array() } else { [0; LANES] };
        for lane in glowing.lanes() {
            let surface = &self.surfaces.records[shapes[lane] as usize];
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
                LightLanes::sample(&self.lights, world, &pick, diffuse, point, normal, error, u, light_ahead, &hit),
            ))
        } else {
            None
        };
        // Scattering, each material drawing what it uses (`Bsdf::sample`)
        let Scattered { go, wi, weight, pdf, .. } =
            surfaces.scatter(&mut st.rng, wo, normal, facing, Transport::Radiance);
        if let Some((pick, light)) = shading {
            // f (Lambert's albedo / π) where both directions are above the surface
            let above = !light.wi.dot(facing).le(zero).or(wo.dot(facing).le(zero));
            let mut f = color * F8::splat(FRAC_1_PI);
            let mut glossy_pdf = None;
            if glossy.mask().and(light.valid).and(above).any() {
                let (glossy_f, pdf) = glossy.f_pdf(wo, light.wi, facing);
                f = glossy.mask().select_v(glossy_f, f);
                glossy_pdf = Some(pdf);
            }
            let shade = light.valid.and(above).and(f.nonzero());
            counters.rays += shade.count();
            if shade.any() {
                let skips = if light_count == 1 {
                    Skips::All { sphere: self.light_spheres[0], plane: self.light_planes[0] }
                } else {
                    let spheres = lanes::each(|i| self.light_spheres[pick[i]]);
                    Skips::Lanes { spheres, planes: lanes::each(|i| self.light_planes[pick[i]]) }
                };
                let blocked = self.blocked(shade, st.inside_walls, light.origin, light.wi, light.t_max, &skips);
                let lit = shade.and_not(blocked);
                if lit.any() {
                    let cos = light.wi.dot(facing);
                    let mut bsdf_pdf = cos.max(zero) * FRAC_1_PI;
                    if let Some(pdf) = glossy_pdf {
                        bsdf_pdf = glossy.mask().select(pdf, bsdf_pdf);
                    }
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
        done.or(killed).or(go.and(st.depth.ge(max_depth)))
    }

    /// The nearest hit of each ray of `active` (`held` those inside every
    /// wall): `World::intersect_held`, eight rays at a time, bit for bit.
    #[inline(always)]
    fn nearest(&self, active: M8, held: M8, origin: V8, direction: V8) -> LaneHits {
        // Spheres in index order, ties keeping the first (`SphereLanes::nearest`):
        // all of them for paths not held, all but the walls for held ones.
        // Usually every path is held: then the walls' near roots are never asked
        let every_held = !active.and_not(held).any();
        let mut t_hit = F8::splat(f32::INFINITY);
        // The index in a float lane, counted there too: one blend per sphere
        let mut index = F8::splat(0.0);
        // Of the sphere hit so far: whether by its near root, and the
        // discriminant (`sphere_hits` rebuilds the point from them)
        let (mut sphere_near, mut sphere_discriminant) = (M8::NONE, F8::splat(0.0));
        let spheres = if every_held { &self.inner_spheres } else { &self.spheres };
        for sphere in spheres {
            let f = origin - V8::splat(sphere.center);
            // No lane's line meets it: no root to solve (`roots`' discriminant)
            let b = f.dot(direction);
            let discriminant = F8::splat(sphere.radius2) - (f - direction * b).length_squared();
            if !discriminant.ge(F8::splat(0.0)).and(active).any() {
                continue;
            }
            let (t, closer, near) = nearest_root(f, direction, F8::splat(sphere.radius2), t_hit);
            let closer = if sphere.wall.is_some() { closer.and_not(held) } else { closer };
            t_hit = closer.select(t, t_hit);
            index = closer.select(F8::splat(sphere.shape), index);
            sphere_near = closer.select_mask(near, sphere_near);
            sphere_discriminant = closer.select(discriminant, sphere_discriminant);
        }
        // The walls' ways out for held paths, after every other sphere:
        // a tie with one goes to the other sphere, as in `World::intersect_held`
        if held.any() {
            self.wall_exits.leave(held, origin, direction, &mut t_hit, &mut index);
        }
        // Planes: in index order for paths not held (`World::intersect`);
        // for held ones the planes that are not walls, then the walls'
        // ways out (`World::intersect_held`)
        let first_plane = self.spheres.len() as f32;
        let mut k = F8::splat(first_plane);
        for plane in &self.planes {
            if plane.wall.is_none() || !every_held {
                let (normal, offset) = (V8::splat(plane.normal), F8::splat(plane.offset));
                let (t, hits) = plane_t_of(origin, direction, normal, offset, t_hit);
                let closer = if plane.wall.is_some() { hits.and_not(held) } else { hits };
                t_hit = closer.select(t, t_hit);
                index = closer.select(k, index);
            }
            k = k + 1.0;
        }
        if held.any() {
            let mut k = F8::splat(first_plane);
            for plane in &self.planes {
                if let Some((inward, offset)) = plane.wall {
                    let (t, exits) = plane_exit_of(origin, direction, V8::splat(inward), F8::splat(offset), t_hit);
                    let closer = exits.and(held);
                    t_hit = closer.select(t, t_hit);
                    index = closer.select(k, index);
                }
                k = k + 1.0;
            }
        }
        // Triangles last, as both do: the crossing where the cull is sure,
        // the watertight test in the other lanes it lets through
        let first_triangle = first_plane + self.planes.len() as f32;
        let (mut triangle_point, mut triangle_normal, mut triangle_error) =
            (V8::splat(Vec3::ZERO), V8::splat(Vec3::Z), F8::splat(0.0));
        let mut crossing = RunCrossing::new();
        for (j, triangle) in self.triangles.iter().enumerate() {
            let (near, sure) = Self::cull(&self.triangle_culls[j], &mut crossing, active, origin, direction, t_hit);
            if sure.any() {
                let (point, error) = triangle.cull.plane.hit_point(origin, direction, crossing.at.t);
                t_hit = sure.select(crossing.at.t, t_hit);
                index = sure.select(F8::splat(first_triangle + j as f32), index);
                triangle_point = sure.select_v(point, triangle_point);
                triangle_normal = sure.select_v(V8::splat(triangle.normal), triangle_normal);
                triangle_error = sure.select(error, triangle_error);
            }
            let near = near.and_not(sure);
            if !near.any() {
                continue;
            }
            let shear = crossing.shear(origin, direction);
            let (hits, t, point, error) = Self::triangle_hits(triangle, near, origin, direction, &shear, t_hit);
            if hits.any() {
                t_hit = hits.select(t, t_hit);
                index = hits.select(F8::splat(first_triangle + j as f32), index);
                triangle_point = hits.select_v(point, triangle_point);
                triangle_normal = hits.select_v(V8::splat(triangle.normal), triangle_normal);
                triangle_error = hits.select(error, triangle_error);
            }
        }
        let found = active.and(t_hit.lt(F8::splat(f32::INFINITY)));
        let shape = index.to_index();
        let on_sphere = found.and(index.lt(F8::splat(first_plane)));
        let on_plane = found.and_not(on_sphere).and(index.lt(F8::splat(first_triangle)));

        let (mut point, mut normal, mut error) = (V8::splat(Vec3::ZERO), V8::splat(Vec3::Z), F8::splat(0.0));
        if on_sphere.any() {
            let roots = (sphere_near, sphere_discriminant);
            self.sphere_hits(
                on_sphere,
                held,
                shape,
                roots,
                origin,
                direction,
                t_hit,
                &mut point,
                &mut normal,
                &mut error,
            );
        }
        if on_plane.any() {
            let plane_normal = self.plane_normals.get(shape);
            let offset = self.plane_offsets.get(shape);
            let (p, e) = plane_point_of(origin, direction, plane_normal, offset, t_hit);
            point = on_plane.select_v(p, point);
            normal = on_plane.select_v(plane_normal, normal);
            error = on_plane.select(e, error);
        }
        let on_triangle = found.and_not(index.lt(F8::splat(first_triangle)));
        if on_triangle.any() {
            point = on_triangle.select_v(triangle_point, point);
            normal = on_triangle.select_v(triangle_normal, normal);
            error = on_triangle.select(triangle_error, error);
        }
        LaneHits { found, t: t_hit, shape, point, normal, error }
    }

    /// The hits of lanes `on_sphere` (`shape` their sphere's index), rebuilt
    /// from the closest approach as `sphere_hit` does, given whether the
    /// search took the near root and the discriminant (`roots`); a wall
    /// holding the path is left where `wall_exit` found it.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn sphere_hits(
        &self,
        on_sphere: M8,
        held: M8,
        shape: Index8,
        (near, discriminant): (M8, F8),
        origin: V8,
        direction: V8,
        t_hit: F8,
        point: &mut V8,
        normal: &mut V8,
        error: &mut F8,
    ) {
        let columns = &self.sphere_columns;
        let center = columns.center.get(shape);
        let radius = columns.radius.get(shape);
        let leaving = held.and(columns.wall.get(shape).ne(F8::splat(0.0))).and(on_sphere);
        if on_sphere.and_not(leaving).any() {
            let f = origin - center;
            let closest = f - direction * f.dot(direction);
            let half_chord = discriminant.max(F8::splat(0.0)).sqrt();
            let from_center = near.select_v(closest - direction * half_chord, closest + direction * half_chord);
            let length = from_center.length();
            let n = length.gt(F8::splat(0.0)).select_v(from_center / length, -direction);
            *point = on_sphere.select_v(center + n * radius, *point);
            *normal = on_sphere.select_v(n, *normal);
            *error = on_sphere.select(columns.error.get(shape), *error);
        }
        if leaving.any() {
            let slack = columns.wall_slack.get(shape);
            let (p, n, e) = wall_exit_hit(origin, direction, t_hit, center, slack);
            *point = leaving.select_v(p, *point);
            *normal = leaving.select_v(n, *normal);
            *error = leaving.select(e, *error);
        }
    }

    /// `intersect_triangle` for the lanes of `near` (those `cull`
    /// lets through): which hit, and their distance, point and error bound.
    /// Lanes on an edge, where the scalar code redoes the edge functions in
    /// f64, take the scalar code.
    #[inline(always)]
    fn triangle_hits(
        triangle: &Triangle,
        near: M8,
        origin: V8,
        direction: V8,
        shear: &RayShear<F8>,
        t_max: F8,
    ) -> (M8, F8, V8, F8) {
        let [a, b, c] = triangle.vertices;
        let vertices = [V8::splat(a), V8::splat(b), V8::splat(c)];
        let (sheared, sz) = shear.vertices(vertices);
        let edges = edges_of(sheared);
        let zero = F8::splat(0.0);
        let on_edge = near.and(edges[0].eq(zero).or(edges[1].eq(zero)).or(edges[2].eq(zero)));
        let range = watertight_range_of(sheared, edges, sz, t_max);
        if !near.and_not(range.missed).or(on_edge).any() {
            return (M8::NONE, zero, V8::splat(Vec3::ZERO), zero);
        }
        let (mut t, hit, barycentrics) = watertight_finish_of(sheared, edges, range);
        let mut hits = near.and_not(on_edge).and(hit);
        let (mut point, mut error) = match hits.any() {
            true => triangle_hit_of(vertices, barycentrics),
            false => (V8::splat(Vec3::ZERO), zero),
        };
        for lane in on_edge.lanes() {
            let ray = Ray::new(origin.lane(lane), direction.lane(lane));
            if let Some(hit) = intersect_triangle(&ray, triangle, t_max.lane(lane)) {
                hits.set(lane, true);
                t.set_lane(lane, hit.t);
                point.set_lane(lane, hit.point);
                error.set_lane(lane, hit.error);
            }
        }
        (hits, t, point, error)
    }

    /// Lanes of `mask` whose ray may hit triangle `j` within (0, t_max),
    /// and those sure to (`Crossing::test`: `intersect_triangle`'s first
    /// test). `crossing` keeps where the rays cross the plane of the run
    /// the last triangle asked about.
    #[inline(always)]
    fn cull(
        triangle: &LaneCull,
        crossing: &mut RunCrossing,
        mask: M8,
        origin: V8,
        direction: V8,
        t_max: F8,
    ) -> (M8, M8) {
        if !mask.any() || triangle.degenerate {
            return (M8::NONE, M8::NONE);
        }
        if crossing.run != triangle.run {
            crossing.run = triangle.run;
            crossing.at = Crossing::of(origin, direction, &triangle.plane);
        }
        let (turned_away, surely) = crossing.at.test(&triangle.edges.load(), t_max);
        (mask.and_not(turned_away), mask.and(surely))
    }

    /// Lanes whose segment (origin, unit direction, t_max) meets `sphere`.
    #[inline(always)]
    fn hits(sphere: &Occluder, origin: V8, direction: V8, t_max: F8) -> M8 {
        let f = origin - V8::splat(sphere.center);
        nearest_root(f, direction, F8::splat(sphere.radius2), t_max).1
    }

    /// Lanes of `mask` whose shadow ray (origin, unit direction, t_max) is
    /// blocked; paths inside every wall skip the walls, and each ray what
    /// `skips` says it ends on (`Occluders::blocks_shadow`).
    #[inline(always)]
    fn blocked(&self, mask: M8, inside_walls: M8, origin: V8, direction: V8, t_max: F8, skips: &Skips) -> M8 {
        let mut blocked = M8::NONE;
        // Plain loops: a closure here would not inherit AVX2
        for sphere in &self.others {
            let aimed_at = match (sphere.emitter, skips) {
                (None, _) => M8::NONE,
                // Every ray ends on it: none can meet it
                (Some(id), Skips::All { sphere, .. }) if *sphere == Some(id) => continue,
                (Some(_), Skips::All { .. }) => M8::NONE,
                (Some(id), Skips::Lanes { spheres, .. }) => M8::from_fn(|i| spheres[i] == Some(id)),
            };
            blocked = blocked.or(Self::hits(sphere, origin, direction, t_max).and_not(aimed_at));
        }
        let outside = mask.and_not(inside_walls);
        if outside.any() {
            for sphere in &self.walls {
                blocked = blocked.or(outside.and(Self::hits(sphere, origin, direction, t_max)));
            }
        }
        for plane in &self.planes {
            if plane.wall.is_none() || outside.any() {
                let (normal, offset) = (V8::splat(plane.normal), F8::splat(plane.offset));
                let hits = plane_t_of(origin, direction, normal, offset, t_max).1;
                blocked = blocked.or(if plane.wall.is_some() { outside.and(hits) } else { hits });
            }
        }
        // Triangles where the ray may reach them, but those in the plane of
        // the light triangle a ray ends on
        let mut crossing = RunCrossing::new();
        for (j, (triangle, plane)) in self.triangles.iter().zip(&self.triangle_planes).enumerate() {
            let aimed_at = match skips {
                Skips::All { plane: skip, .. } if *skip == Some(*plane) => continue,
                Skips::All { .. } => M8::NONE,
                Skips::Lanes { planes, .. } => M8::from_fn(|i| planes[i] == Some(*plane)),
            };
            let open = mask.and_not(blocked).and_not(aimed_at);
            let (near, surely) = Self::cull(&self.triangle_culls[j], &mut crossing, open, origin, direction, t_max);
            blocked = blocked.or(surely);
            let near = near.and_not(surely);
            if near.any() {
                let shear = crossing.shear(origin, direction);
                blocked = blocked.or(Self::triangle_hits(triangle, near, origin, direction, &shear, t_max).0);
            }
        }
        mask.and(blocked)
    }

    /// Which of `shadows` something blocks (`blocked[i]` says of
    /// `shadows[i]`): `World::blocked` of each, bit for bit, eight at a time
    /// where the CPU has AVX2.
    pub fn shadows_blocked(&self, shadows: &[Shadow], blocked: &mut [bool]) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has AVX2: a `PathLanes` is made only where it does.
        #[allow(unsafe_code)]
        unsafe {
            self.shadows_blocked_avx2(shadows, blocked)
        };
        #[cfg(not(target_arch = "x86_64"))]
        self.shadows_blocked_lanes(shadows, blocked);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn shadows_blocked_avx2(&self, shadows: &[Shadow], blocked: &mut [bool]) {
        self.shadows_blocked_lanes(shadows, blocked);
    }

    #[inline(always)]
    fn shadows_blocked_lanes(&self, shadows: &[Shadow], blocked: &mut [bool]) {
        for (eight, out) in shadows.chunks(LANES).zip(blocked.chunks_mut(LANES)) {
            let n = eight.len();
            let mask = M8::from_bits((1 << n) - 1);
            let lane = |i: usize| &eight[i.min(n - 1)];
            let origin = V8::from_fn(|i| lane(i).ray.origin);
            let direction = V8::from_fn(|i| lane(i).ray.direction);
            let t_max = F8::from_fn(|i| lane(i).t_max);
            let held = M8::from_fn(|i| lane(i).held);
            let spheres = lanes::each(|i| lane(i).on_sphere);
            let planes = lanes::each(|i| lane(i).on_triangle.map(|t| self.triangle_planes[t as usize]));
            let hit = self.blocked(mask, held, origin, direction, t_max, &Skips::Lanes { spheres, planes }).bits();
            for (i, out) in out.iter_mut().enumerate() {
                *out = hit & 1 << i != 0;
            }
        }
    }
}

/// What shadow rays need not test (`Occluders::blocks_shadow`): the sphere
/// a light sample lies on, and the light plane of the triangle it lies on.
enum Skips {
    /// The same for every lane (path tracing toward a scene's one light).
    All {
        sphere: Option<u32>,
        plane: Option<u32>,
    },
    Lanes {
        spheres: [Option<u32>; LANES],
        planes: [Option<u32>; LANES],
    },
}

/// What `cull` reads of a triangle.
#[derive(Clone, Debug)]
struct LaneCull {
    /// Its edges, each coefficient splat into eight lanes, read straight
    /// into the test: splat afresh, they were a fifth of the cull's
    /// instructions.
    edges: LaneEdges,
    plane: CullPlane,
    /// Which run of triangles in one plane it belongs to
    /// (`Triangle::share_planes`): a run's rays cross its plane once.
    run: u32,
    degenerate: bool,
}

/// A triangle's `CullEdges`, each coefficient in every lane.
#[derive(Clone, Debug)]
#[repr(align(32))]
struct LaneEdges([[[f32; LANES]; 3]; 3]);

impl LaneEdges {
    fn of(edges: &CullEdges) -> Self {
        LaneEdges(edges.0.map(|edge| edge.map(|c| [c; LANES])))
    }

    #[inline(always)]
    fn load(&self) -> [[F8; 3]; 3] {
        // Written out: `map`'s closures are left out of line, without AVX2
        let [[a0, b0, c0], [a1, b1, c1], [a2, b2, c2]] = &self.0;
        [
            [F8::load(a0), F8::load(b0), F8::load(c0)],
            [F8::load(a1), F8::load(b1), F8::load(c1)],
            [F8::load(a2), F8::load(b2), F8::load(c2)],
        ]
    }
}

/// Where eight rays cross the plane of a run of triangles, and their
/// shear for the watertight test once one needs it.
struct RunCrossing {
    run: u32,
    at: Crossing<F8>,
    /// Worked out for every batch before the triangles (a division and the
    /// axes' selects), it was 3.5% of the instructions of smallpt, which
    /// has none; only a batch the cull lets through needs it.
    shear: Option<RayShear<F8>>,
}

impl RunCrossing {
    /// Of no run yet.
    #[inline(always)]
    fn new() -> Self {
        let zero = F8::splat(0.0);
        RunCrossing { run: u32::MAX, at: Crossing { t: zero, u: zero, v: zero, slack: zero }, shear: None }
    }

    /// The rays' shear, worked out the first time it is asked for.
    #[inline(always)]
    fn shear(&mut self, origin: V8, direction: V8) -> RayShear<F8> {
        // A match, not `get_or_insert_with`: a closure would lose AVX2
        match self.shear {
            Some(shear) => shear,
            None => *self.shear.insert(ray_shear_of(origin, direction)),
        }
    }
}

/// What the cull reads of each triangle, its run of triangles in one plane
/// counted from 0 (`Triangle::share_planes` gave a run one plane).
fn lane_culls(triangles: &[(Triangle, u32)]) -> Vec<LaneCull> {
    let mut run = 0;
    (0..triangles.len())
        .map(|j| {
            let triangle = &triangles[j].0;
            run += (j > 0 && triangle.cull.plane != triangles[j - 1].0.cull.plane) as u32;
            LaneCull {
                edges: LaneEdges::of(&triangle.cull.edges),
                plane: triangle.cull.plane,
                run,
                degenerate: triangle.is_degenerate(),
            }
        })
        .collect()
}

/// Eight paths in flight.
struct Lanes {
    active: M8,
    depth: Count8,
    inside_walls: M8,
    origin: V8,
    direction: V8,
    throughput: V8,
    radiance: V8,
    after_delta: M8,
    last_pdf: F8,
    last_point: V8,
    rng: Rng8,
}

impl Lanes {
    fn new() -> Self {
        let zero = V8::splat(Vec3::ZERO);
        Lanes {
            active: M8::NONE,
            depth: Count8::ZERO,
            inside_walls: M8::NONE,
            origin: zero,
            direction: zero,
            throughput: zero,
            radiance: zero,
            after_delta: M8::NONE,
            last_pdf: F8::splat(0.0),
            last_point: zero,
            rng: Rng8::new(),
        }
    }

    /// Idle lanes take the next samples (from `next` on, below `count`):
    /// each sample's fields blended into its lane, the registers staying
    /// registers (gathered for all eight lanes, or written lane by lane
    /// into arrays and loaded back, they were 4% of smallpt's time).
    #[inline(always)]
    fn start_idle(&mut self, samples: &CameraSamples, slots: &mut [usize; LANES], next: &mut usize, count: usize) {
        let mut idle = (!self.active).bits();
        let mut started = M8::NONE;
        let (mut origin, mut direction, mut inside_walls) = (self.origin, self.direction, self.inside_walls);
        while idle != 0 && *next < count {
            let lane = idle.trailing_zeros() as usize;
            idle &= idle - 1;
            let (eight, i) = (&samples.0[*next / LANES], *next % LANES);
            let (sample_origin, sample_direction) = eight.ray(i);
            let here = M8::only(lane);
            started = started.or(here);
            origin = here.select_v(V8::splat(sample_origin), origin);
            direction = here.select_v(V8::splat(sample_direction), direction);
            inside_walls = here.select_mask(M8::splat(eight.inside_walls >> i & 1 != 0), inside_walls);
            self.rng.start(lane, eight.stream[i], eight.ahead[i]);
            slots[lane] = *next;
            *next += 1;
        }
        if !started.any() {
            return;
        }
        self.active = self.active.or(started);
        self.depth = self.depth.reset(started);
        self.inside_walls = inside_walls;
        self.origin = origin;
        self.direction = direction;
        self.throughput = started.select_v(V8::splat(Rgb::ONE), self.throughput);
        self.radiance = started.select_v(V8::splat(Rgb::ZERO), self.radiance);
        self.after_delta = self.after_delta.or(started);
        self.last_pdf = started.select(F8::splat(0.0), self.last_pdf);
        self.last_point = started.select_v(origin, self.last_point);
    }

    /// Paths of `mask` are done: their radiance goes out, their lanes free up.
    #[inline(always)]
    fn finish(&mut self, mask: M8, slots: &[usize; LANES], out: &mut impl FnMut(usize, Rgb)) {
        let mut done = mask.bits();
        if done == 0 {
            return;
        }
        let (x, y, z) = (self.radiance.x.to_array(), self.radiance.y.to_array(), self.radiance.z.to_array());
        while done != 0 {
            let lane = done.trailing_zeros() as usize;
            done &= done - 1;
            out(slots[lane], Rgb::new(x[lane], y[lane], z[lane]));
        }
        self.active = self.active.and_not(mask);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shear_of;

    /// The lanes' triangle test (the crossing where the cull is sure, the
    /// watertight test in the other lanes it lets through) is
    /// `intersect_triangle`, bit for bit: on random rays, and on rays
    /// straight down onto a quad's edges and vertices, where edge functions
    /// are exactly zero and the scalar code redoes them in f64.
    #[test]
    fn triangle_hits_are_the_scalar_ones() {
        use crate::render::world::rng::Sampler;
        let quad =
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let triangles = [Triangle::new(quad[0], quad[1], quad[3]), Triangle::new(quad[1], quad[2], quad[3])];
        let mut rays = Vec::new();
        for i in 0..=16 {
            for j in 0..=16 {
                let at = Vec3::new(i as f32 / 16.0 - 0.25, j as f32 / 16.0 - 0.25, 1.0);
                rays.push((at, -Vec3::Z, if (i + j) % 3 == 0 { 0.5 } else { f32::INFINITY }));
            }
        }
        let mut rng = Sampler::new(0, 0, 7);
        while rays.len() % LANES != 0 || rays.len() < 800 {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
            let target = Vec3::new(rng.next_f32() * 1.4 - 0.2, rng.next_f32() * 1.4 - 0.2, 0.0);
            rays.push((origin, (target - origin).normalize(), 10.0));
        }
        let (mut on_edges, mut hits_seen, mut misses_seen, mut sure_seen) = (0, 0, 0, 0);
        for triangle in &triangles {
            for batch in rays.chunks(LANES) {
                let origin = V8::from_fn(|i| batch[i].0);
                let direction = V8::from_fn(|i| batch[i].1);
                let t_max = F8::from_fn(|i| batch[i].2);
                let crossing = Crossing::of(origin, direction, &triangle.cull.plane);
                let (turned_away, sure) = crossing.test(&triangle.cull.edges.splat(), t_max);
                let near = (!turned_away).and_not(sure);
                let shear = ray_shear_of(origin, direction);
                let (hits, t, point, error) =
                    PathLanes::triangle_hits(triangle, near, origin, direction, &shear, t_max);
                let (sure_point, sure_error) = triangle.cull.plane.hit_point(origin, direction, crossing.t);
                let (hits, t) = (hits.or(sure), sure.select(crossing.t, t));
                let (point, error) = (sure.select_v(sure_point, point), sure.select(sure_error, error));
                sure_seen += sure.count();
                for (i, &(o, d, t_max)) in batch.iter().enumerate() {
                    let vertices = triangle.vertices.map(crate::geometry::real::V3::from);
                    on_edges += edges_of(shear_of(o.into(), d.into(), vertices).0).contains(&0.0) as u32;
                    let expected = intersect_triangle(&Ray::new(o, d), triangle, t_max);
                    assert_eq!(hits.test(i), expected.is_some(), "ray {o} {d}");
                    if let Some(hit) = expected {
                        hits_seen += 1;
                        assert_eq!(t.lane(i).to_bits(), hit.t.to_bits());
                        assert_eq!(point.lane(i).to_array().map(f32::to_bits), hit.point.to_array().map(f32::to_bits));
                        assert_eq!(error.lane(i).to_bits(), hit.error.to_bits());
                    } else {
                        misses_seen += 1;
                    }
                }
            }
        }
        assert!(on_edges > 50 && hits_seen > 300 && misses_seen > 300, "{on_edges} {hits_seen} {misses_seen}");
        assert!(sure_seen > 100 && hits_seen >= sure_seen + 10, "{sure_seen} of {hits_seen} hits by the crossing");
    }
}
