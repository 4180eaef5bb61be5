//! A tile's camera samples as the lanes take them up: rays and random
//! streams made eight at a time for a pinhole, and whether each starts
//! inside every wall.

use glam::Vec3;

use crate::geometry::Ray;
use crate::render::world::camera::CameraTile;
use crate::render::world::lanes::{self, Rng8, F8, LANES, M8, V8};
use crate::render::world::rng::Sampler;
use crate::render::world::World;

/// Eight camera samples, a row of eight per field, as the lanes hold them.
#[derive(Clone, Copy, Debug)]
pub(super) struct CameraEight {
    origin: [[f32; LANES]; 3],
    direction: [[f32; LANES]; 3],
    pub(super) stream: [u64; LANES],
    /// Each stream's next draw, mixed (`Rng8::ahead`).
    pub(super) ahead: [u64; LANES],
    /// Bit i set: sample i starts inside every wall (`Walls::hold`).
    pub(super) inside_walls: u32,
}

/// A tile's camera samples, a whole number of eights (the last eight repeat
/// the last sample).
pub(super) struct CameraSamples(pub(super) Vec<CameraEight>);

impl CameraSamples {
    #[inline(always)]
    pub(super) fn new(tile: &CameraTile, world: &World) -> Self {
        let mut samples = Self::rays(tile);
        // Camera rays of a tile start close together: mostly all inside the walls
        let (mut low, mut high) = (V8::splat(Vec3::INFINITY), V8::splat(Vec3::NEG_INFINITY));
        for eight in &samples.0 {
            let origin = eight.origins();
            low = V8 { x: low.x.min(origin.x), y: low.y.min(origin.y), z: low.z.min(origin.z) };
            high = V8 { x: high.x.max(origin.x), y: high.y.max(origin.y), z: high.z.max(origin.z) };
        }
        // Plain loops: a closure here would not inherit AVX2
        let (mut lowest, mut highest) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for i in 0..LANES {
            (lowest, highest) = (lowest.min(low.lane(i)), highest.max(high.lane(i)));
        }
        if !world.walls.hold_box(lowest, highest) {
            for eight in &mut samples.0 {
                eight.inside_walls = world.walls.hold_lanes(eight.origins()).bits();
            }
        }
        samples
    }

    /// The rays and their streams.
    #[inline(always)]
    fn rays(tile: &CameraTile) -> Self {
        let entries = tile.len().div_ceil(LANES);
        let mut samples = CameraSamples(Vec::with_capacity(entries));
        let last = tile.len().saturating_sub(1);
        if tile.camera.has_lens() {
            for entry in 0..entries {
                let rays: [(Ray, Sampler); LANES] = lanes::each(|i| tile.sample((entry * LANES + i).min(last)));
                let origin = V8::from_fn(|i| rays[i].0.origin);
                let streams = Rng8::from_states(lanes::each(|i| rays[i].1.state()));
                samples.push(origin, V8::from_fn(|i| rays[i].0.direction), &streams);
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
            samples.push(origin, direction, &rng);
        }
        samples
    }

    /// Eight samples, taken to be inside the walls until `new` knows better.
    #[inline(always)]
    fn push(&mut self, origin: V8, direction: V8, streams: &Rng8) {
        let rows = |v: V8| [v.x.to_array(), v.y.to_array(), v.z.to_array()];
        let (origin, direction) = (rows(origin), rows(direction));
        let (stream, ahead) = (streams.states(), streams.ahead());
        self.0.push(CameraEight { origin, direction, stream, ahead, inside_walls: (1 << LANES) - 1 });
    }
}

impl CameraEight {
    #[inline(always)]
    fn origins(&self) -> V8 {
        let [x, y, z] = &self.origin;
        V8 { x: F8::load(x), y: F8::load(y), z: F8::load(z) }
    }

    /// Sample `i`'s origin and direction.
    #[inline(always)]
    pub(super) fn ray(&self, i: usize) -> (Vec3, Vec3) {
        let ([ox, oy, oz], [dx, dy, dz]) = (&self.origin, &self.direction);
        (Vec3::new(ox[i], oy[i], oz[i]), Vec3::new(dx[i], dy[i], dz[i]))
    }
}
