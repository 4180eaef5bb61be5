//! What items flying eight at a time (`flying`) draw at their hits, in the
//! lanes: at a surface that is not specular, a light sample for next-event
//! estimation, how the camera sees the hit (through a point drawn on its
//! lens) and a scattered direction (`LightSource::sample`,
//! `CameraModel::connect` and `Bsdf::sample`), from each item's own stream
//! in the order the scalar code draws them, so the items go on as if they
//! had drawn them alone.

use glam::{Vec2, Vec3};

use super::lights::LightLanes;
use super::{LaneHits, LaneSurfaces, LaneWorld, Scattered};
use crate::geometry::{Ray, SurfaceHit};
use crate::render::world::camera::{CameraConnection, CameraModel, ConnectionOf};
use crate::render::world::lanes::{self, Rng8, F8, LANES, M8, V8};
use crate::render::world::light::{self, Emitter, LightSample, LightSource};
use crate::render::world::materials::{BsdfSample, Transport};
use crate::render::world::rng::Sampler;
use crate::render::world::World;

/// What an item asks to draw (and to have computed) at its next hit, if
/// that is not specular, in this order.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Want {
    /// Its stream's state (`Sampler::state`).
    pub(crate) state: u64,
    /// A light for next-event estimation: its pick, and a sample of it if
    /// one is picked.
    pub(crate) light: bool,
    /// How the camera sees the hit (`CameraModel::connect`), through a
    /// point drawn on its lens if it has one.
    pub(crate) join: bool,
    /// The direction it scatters into.
    pub(crate) scatter: bool,
}

/// A light drawn for next-event estimation: its index, the probability it
/// was picked with, and its sample (None: it gives none at the point).
pub(crate) type PickedLight = (usize, f32, Option<LightSample>);

/// What an item drew at its hit, as its scalar code would have.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Given {
    /// Its stream's state after the draws.
    pub(crate) state: u64,
    /// None where no light was picked (or none asked for).
    pub(crate) light: Option<PickedLight>,
    /// How the camera sees the hit, if asked for (None: it does not).
    pub(crate) seen: Option<CameraConnection>,
    /// None where the drawn direction goes nowhere (below the surface).
    pub(crate) scattered: Option<BsdfSample>,
}

impl Given {
    /// Where its item goes on from: its stream after the draws, and the
    /// direction drawn (None: it goes nowhere).
    pub(crate) fn resume(&self, sampler: &mut Sampler) -> Option<BsdfSample> {
        *sampler = Sampler::from_state(self.state);
        self.scattered
    }
}

impl LaneWorld {
    /// The draws of the lanes that `wants` asks for and that `hits` found on
    /// a surface that is not specular, the rays arriving along `direction`,
    /// into `given` (None in every other lane); `pick` chooses a light from
    /// a uniform number (`LightPicker::pick`), `camera` sees the joins.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn draw_at_hits(
        &self,
        world: &World,
        hits: &LaneHits,
        direction: V8,
        wants: &[Option<Want>; LANES],
        pick: &impl Fn(f32) -> Option<(usize, f32)>,
        camera: Option<&CameraModel>,
        given: &mut [Option<Given>; LANES],
    ) {
        let wanted = hits.found.and(M8::from_fn(|i| wants[i].is_some()));
        let surfaces = LaneSurfaces::new(&self.surfaces, hits.shape, wanted);
        let drawing = surfaces.shaded();
        if !drawing.any() {
            given.iter_mut().for_each(|g| *g = None);
            return;
        }
        let asking = |what: fn(&Want) -> bool| drawing.and(M8::from_fn(|i| wants[i].as_ref().is_some_and(what)));
        let mut rng = Rng8::from_states(lanes::each(|i| wants[i].map_or(0, |want| want.state)));
        let (point, normal, error) = (hits.point, hits.normal, hits.error);
        // A light: its pick, then (if one was picked) its sample
        let sampling = asking(|want| want.light);
        let u_pick = rng.next_f32(sampling).to_array();
        let mut picked = [None; LANES];
        for lane in sampling.lanes() {
            picked[lane] = pick(u_pick[lane]);
        }
        let sampled = M8::from_fn(|i| picked[i].is_some());
        let u = rng.next_2d(sampled);
        let light = match sampled.any() {
            true => {
                let hit = |i: usize| SurfaceHit {
                    t: hits.t.lane(i),
                    point: point.lane(i),
                    normal: normal.lane(i),
                    error: error.lane(i),
                };
                let index = lanes::each(|i| picked[i].map_or(0, |(index, _)| index));
                Some(LightLanes::sample(&self.lights, world, &index, sampled, point, normal, error, u, None, &hit))
            }
            false => None,
        };
        // The camera, through a point on its lens if it has one
        let joining = match camera {
            Some(_) => asking(|want| want.join),
            None => M8::NONE,
        };
        let seen = match camera {
            Some(camera) if joining.any() => {
                let lens = if camera.has_lens() { rng.next_2d(joining) } else { (F8::splat(0.0), F8::splat(0.0)) };
                Some(Seen::of(camera.connect_of(point, lens), joining))
            }
            _ => None,
        };
        // The direction it scatters into; radiance or importance alike,
        // only glass tells them apart
        let scattering = asking(|want| want.scatter);
        let surfaces = match scattering.bits() == drawing.bits() {
            true => surfaces,
            false => LaneSurfaces::new(&self.surfaces, hits.shape, scattering),
        };
        let wo = -direction;
        let facing = normal.dot(wo).lt(F8::splat(0.0)).select_v(-normal, normal);
        let Scattered { go, wi, weight, pdf, .. } = surfaces.scatter(&mut rng, wo, normal, facing, Transport::Radiance);
        // Out of the registers first: closures do not inherit AVX2
        let states = rng.states();
        #[allow(clippy::manual_map)] // a closure here would not inherit AVX2
        let light = match light {
            Some(light) => Some(Columns::of(&light)),
            None => None,
        };
        let go = go.and(scattering).bits();
        let (wi, weight, pdf) = (columns_of(wi), columns_of(weight), pdf.to_array());
        let drawing = drawing.bits();
        for (lane, given) in given.iter_mut().enumerate() {
            if drawing & 1 << lane == 0 {
                *given = None;
                continue;
            }
            *given = Some(Given {
                state: states[lane],
                light: picked[lane].map(|(index, probability)| {
                    let sample = light.as_ref().and_then(|light| light.sample(lane, &world.lights[index]));
                    (index, probability, sample)
                }),
                seen: seen.as_ref().and_then(|seen| seen.connection(lane)),
                scattered: (go & 1 << lane != 0).then(|| BsdfSample {
                    wi: lane_of(&wi, lane),
                    weight: lane_of(&weight, lane),
                    pdf: pdf[lane],
                    delta: false,
                }),
            });
        }
    }
}

/// `CameraModel::connect_of`'s connections out of the registers.
struct Seen {
    valid: u32,
    film: ([f32; LANES], [f32; LANES]),
    lens: [[f32; LANES]; 3],
    start: [f32; LANES],
    distance: [f32; LANES],
    to_camera: [[f32; LANES]; 3],
    ray_pdf: [f32; LANES],
}

impl Seen {
    /// The connections of the lanes of `joining`.
    #[inline(always)]
    fn of(seen: ConnectionOf<F8>, joining: M8) -> Self {
        Seen {
            valid: seen.valid.and(joining).bits(),
            film: (seen.film.0.to_array(), seen.film.1.to_array()),
            lens: columns_of(seen.lens),
            start: seen.start.to_array(),
            distance: seen.distance.to_array(),
            to_camera: columns_of(seen.to_camera),
            ray_pdf: seen.ray_pdf.to_array(),
        }
    }

    /// Lane `i`'s, as `CameraModel::connect` gives it.
    fn connection(&self, i: usize) -> Option<CameraConnection> {
        if self.valid & 1 << i == 0 {
            return None;
        }
        let film = Vec2::new(self.film.0[i], self.film.1[i]);
        let (lens, to_camera) = (lane_of(&self.lens, i), lane_of(&self.to_camera, i));
        Some(CameraConnection::new(film, lens, self.start[i], self.distance[i], to_camera, self.ray_pdf[i]))
    }
}

/// `LightLanes` out of the registers, lane by lane.
struct Columns {
    valid: u32,
    wi: [[f32; LANES]; 3],
    value: [[f32; LANES]; 3],
    pdf: [f32; LANES],
    origin: [[f32; LANES]; 3],
    t_max: [f32; LANES],
    point: [[f32; LANES]; 3],
    normal: [[f32; LANES]; 3],
}

impl Columns {
    #[inline(always)]
    fn of(light: &LightLanes) -> Self {
        Columns {
            valid: light.valid.bits(),
            wi: columns_of(light.wi),
            value: columns_of(light.value),
            pdf: light.pdf.to_array(),
            origin: columns_of(light.origin),
            t_max: light.t_max.to_array(),
            point: columns_of(light.point),
            normal: columns_of(light.light_normal),
        }
    }

    /// Lane `i` as `LightSource::sample` gives it for `light`.
    fn sample(&self, i: usize, light: &LightSource) -> Option<LightSample> {
        if self.valid & 1 << i == 0 {
            return None;
        }
        let (on_triangle, on_sphere) = match *light {
            LightSource::Area(light::AreaLight { emitter: Emitter::Triangle { triangle, .. }, .. }) => {
                (Some(triangle), None)
            }
            LightSource::Area(light::AreaLight { emitter: Emitter::Sphere { sphere, .. }, .. }) => (None, Some(sphere)),
            _ => (None, None),
        };
        let wi = lane_of(&self.wi, i);
        Some(LightSample {
            wi,
            value: lane_of(&self.value, i),
            pdf: self.pdf[i],
            shadow: Ray::new(lane_of(&self.origin, i), wi),
            shadow_t_max: self.t_max[i],
            on_triangle,
            on_sphere,
            point: lane_of(&self.point, i),
            normal: lane_of(&self.normal, i),
        })
    }
}

/// A vector's eight lanes out of the registers, as columns.
#[inline(always)]
fn columns_of(v: V8) -> [[f32; LANES]; 3] {
    [v.x.to_array(), v.y.to_array(), v.z.to_array()]
}

/// Lane `i` of a vector's columns.
fn lane_of(columns: &[[f32; LANES]; 3], i: usize) -> Vec3 {
    Vec3::new(columns[0][i], columns[1][i], columns[2][i])
}
