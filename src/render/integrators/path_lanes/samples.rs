//! A tile's camera samples as the lanes take them up: rays and random
//! streams made eight at a time for a pinhole, and whether each starts
//! inside every wall.

use glam::Vec3;

use crate::geometry::Ray;
use crate::render::world::camera::CameraTile;
use crate::render::world::lanes::{self, Rng8, F8, LANES, M8, V8};
use crate::render::world::rng::Sampler;
use crate::render::world::World;

/// One camera sample, as a lane takes it up.
#[derive(Clone, Copy, Debug)]
pub(super) struct CameraSample {
    pub(super) origin: Vec3,
    pub(super) direction: Vec3,
    pub(super) stream: u64,
    /// `Walls::hold` of the origin.
    pub(super) inside_walls: bool,
}

/// A tile's camera samples, a whole number of eights (the last eight repeat
/// the last sample).
pub(super) struct CameraSamples(pub(super) Vec<CameraSample>);

impl CameraSamples {
    #[inline(always)]
    pub(super) fn new(tile: &CameraTile, world: &World) -> Self {
        let mut samples = Self::rays(tile);
        // Camera rays of a tile start close together: mostly all inside the walls
        let (mut low, mut high) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for sample in &samples.0 {
            (low, high) = (low.min(sample.origin), high.max(sample.origin));
        }
        if !world.walls.hold_box(low, high) {
            for entry in samples.0.chunks_exact_mut(LANES) {
                let held = world.walls.hold_lanes(V8::from_fn(|i| entry[i].origin)).to_array();
                for (sample, held) in entry.iter_mut().zip(held) {
                    sample.inside_walls = held != 0;
                }
            }
        }
        samples
    }

    /// The rays and their streams.
    #[inline(always)]
    fn rays(tile: &CameraTile) -> Self {
        let entries = tile.len().div_ceil(LANES);
        let mut samples = CameraSamples(Vec::with_capacity(entries * LANES));
        let last = tile.len().saturating_sub(1);
        if tile.camera.has_lens() {
            for entry in 0..entries {
                let rays: [(Ray, Sampler); LANES] = lanes::each(|i| tile.sample((entry * LANES + i).min(last)));
                let origin = V8::from_fn(|i| rays[i].0.origin);
                samples.push(origin, V8::from_fn(|i| rays[i].0.direction), rays.map(|(_, s)| s.state()));
            }
            return samples;
        }
        // A pinhole's eight at a time: `sample_ray` lane by lane
        let rect = tile.rect;
        let (mut x, mut y) = (rect.x, rect.y);
        for entry in 0..entries {
            let (mut column, mut row) = ([0; LANES], [0; LANES]);
            for lane in 0..LANES {
                (column[lane], row[lane]) = (x, y);
                if entry * LANES + lane < last {
                    x += 1;
                    if x == rect.x + rect.width {
                        (x, y) = (rect.x, y + 1);
                    }
                }
            }
            let stream = |i: usize| tile.streams.sampler(tile.camera.pixel_index(column[i], row[i])).state();
            let mut rng = Rng8::from_states(lanes::each(stream));
            let (u0, u1) = rng.next_2d(M8::ALL);
            let film_x = F8::from_fn(|i| column[i] as f32) + u0;
            let film_y = F8::from_fn(|i| row[i] as f32) + u1;
            let (origin, direction) = tile.camera.pinhole_rays_of(film_x, film_y);
            samples.push(origin, direction, rng.states());
        }
        samples
    }

    /// Eight samples, taken to be inside the walls until `new` knows better.
    #[inline(always)]
    fn push(&mut self, origin: V8, direction: V8, stream: [u64; LANES]) {
        let (ox, oy, oz) = (origin.x.to_array(), origin.y.to_array(), origin.z.to_array());
        let (dx, dy, dz) = (direction.x.to_array(), direction.y.to_array(), direction.z.to_array());
        for i in 0..LANES {
            self.0.push(CameraSample {
                origin: Vec3::new(ox[i], oy[i], oz[i]),
                direction: Vec3::new(dx[i], dy[i], dz[i]),
                stream: stream[i],
                inside_walls: true,
            });
        }
    }
}
