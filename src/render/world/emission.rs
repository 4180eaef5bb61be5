//! Light leaving the lights: what a start of a photon or a light path
//! carries (`Emission`; each kind of light's `emit` is in its file of
//! `light/`), and where infinite lights (directional, the background) start
//! it: on a rectangle covering the shadow of the region the camera sees
//! (`Bounds`).

use glam::{Vec2, Vec3};

use crate::geometry::{Frame, Ray};
use crate::scene::Rgb;

/// The box infinite lights must light (`World::bounds`). Light from a
/// direction starts on the rectangle, across the direction and behind the
/// box, that covers the box's shadow: a light path's power is the
/// rectangle's area times the light, so a cover no larger than the box's
/// shadow wastes few paths and gives each little power (a disc about the
/// box's ball was several times its shadow, and light subpaths that only
/// they can make — caustics seen in a mirror — that much noisier).
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub lo: Vec3,
    pub hi: Vec3,
}

/// Where light along one direction starts: `Bounds::cover`.
struct Cover {
    frame: Frame,
    x: (f32, f32),
    y: (f32, f32),
    /// The box's nearest extent along the direction.
    back: f32,
}

impl Cover {
    fn area(&self) -> f32 {
        (self.x.1 - self.x.0) * (self.y.1 - self.y.0)
    }
}

impl Bounds {
    /// The rectangle covering the box's shadow across `direction`.
    fn cover(&self, direction: Vec3) -> Cover {
        let frame = Frame::from_z(direction);
        let (mut x, mut y, mut back) =
            ((f32::INFINITY, f32::NEG_INFINITY), (f32::INFINITY, f32::NEG_INFINITY), f32::INFINITY);
        for corner in 0..8 {
            let pick = |bit: u32, lo: f32, hi: f32| if corner & bit == 0 { lo } else { hi };
            let p =
                Vec3::new(pick(1, self.lo.x, self.hi.x), pick(2, self.lo.y, self.hi.y), pick(4, self.lo.z, self.hi.z));
            let (u, v) = (p.dot(frame.x), p.dot(frame.y));
            (x, y) = ((x.0.min(u), x.1.max(u)), (y.0.min(v), y.1.max(v)));
            back = back.min(p.dot(direction));
        }
        Cover { frame, x, y, back }
    }

    /// Where light travelling along `direction` starts: `u` on the cover,
    /// a box's diagonal behind it; and the cover's area.
    pub(crate) fn start(&self, direction: Vec3, u: Vec2) -> (Ray, f32) {
        let cover = self.cover(direction);
        let Cover { frame, x, y, back } = cover;
        let (a, b) = (x.0 + (x.1 - x.0) * u.x, y.0 + (y.1 - y.0) * u.y);
        let behind = back - (self.hi - self.lo).length().max(1e-3);
        (Ray::new(frame.x * a + frame.y * b + direction * behind, direction), cover.area().max(0.0))
    }

    /// The cover's density of starts, where the line through `point` along
    /// `direction` crosses it (0 outside: no light path from it reaches
    /// `point` that way).
    pub(crate) fn start_pdf(&self, point: Vec3, direction: Vec3) -> f32 {
        let cover = self.cover(direction);
        let (u, v) = (point.dot(cover.frame.x), point.dot(cover.frame.y));
        let inside = (cover.x.0..=cover.x.1).contains(&u) && (cover.y.0..=cover.y.1).contains(&v);
        let area = cover.area();
        if inside && area > 0.0 {
            1.0 / area
        } else {
            0.0
        }
    }

    /// The cover's area across `direction`.
    pub(crate) fn area(&self, direction: Vec3) -> f32 {
        self.cover(direction).area().max(0.0)
    }

    /// The box's mean shadow over all directions: a quarter of its surface.
    pub(crate) fn mean_shadow(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        (d.x * d.y + d.y * d.z + d.z * d.x) * 0.5
    }

    /// The box grown by `factor` about its centre.
    pub fn grown(self, factor: f32) -> Bounds {
        let (centre, half) = ((self.lo + self.hi) * 0.5, (self.hi - self.lo) * 0.5 * factor);
        Bounds { lo: centre - half, hi: centre + half }
    }
}

/// One start of light: its ray, what it carries, its densities.
#[derive(Clone, Copy, Debug)]
pub struct Emission {
    pub ray: Ray,
    /// Emitted radiance times the cosine at the light over the densities
    /// (intensity for point and spot lights, irradiance for directional
    /// ones): a photon's power before it is divided by the photons emitted
    /// and by the light's pick probability.
    pub power: Rgb,
    /// Density of the start point (area; 1 for a point or spot light) times
    /// that of the direction (solid angle; 1 for a directional light).
    pub pdf: f32,
    /// Cosine between the direction and the light's normal (1 where it has none).
    pub cos: f32,
    /// The point it leaves from (an area light's, before the ray's offset;
    /// a point or spot light's position) and the light's normal there (zero
    /// where it has none).
    pub point: Vec3,
    pub normal: Vec3,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    /// Light from any direction into a box starts behind it, on a cover
    /// whose density is the same wherever it starts and nothing where no
    /// start lies: every point of the box is reached (its line crosses the
    /// cover) and the cover is no larger than the box's shadow needs (each
    /// side touched by a corner's line).
    #[test]
    fn the_cover_of_a_box_is_behind_it_holds_its_shadow_and_its_density_is_even() {
        let bounds = Bounds { lo: Vec3::new(-1.0, 0.0, -2.0), hi: Vec3::new(3.0, 0.5, 1.0) };
        let mut s = Sampler::new(0, 0, 11);
        for _ in 0..200 {
            let direction = uniform_sphere(s.next_2d());
            let area = bounds.area(direction);
            assert!(area > 0.0);
            for _ in 0..20 {
                let (start, _) = bounds.start(direction, s.next_2d());
                assert_eq!(start.direction, direction);
                let corners_ahead = (0..8).all(|c| {
                    let corner =
                        Vec3::select(glam::BVec3::new(c & 1 == 0, c & 2 == 0, c & 4 == 0), bounds.lo, bounds.hi);
                    (corner - start.origin).dot(direction) > 0.0
                });
                assert!(corners_ahead, "a start in front of the box");
                let pdf = bounds.start_pdf(start.origin + direction * 0.5, direction);
                assert!((pdf * area - 1.0).abs() < 1e-4, "density {pdf} on a cover of area {area}");
                let inside = bounds.lo + (bounds.hi - bounds.lo) * Vec3::new(s.next_f32(), s.next_f32(), s.next_f32());
                assert!(bounds.start_pdf(inside, direction) > 0.0, "{inside} unreached along {direction}");
            }
            // Far to the side of the box, across the direction: no start
            let Cover { frame, x, .. } = bounds.cover(direction);
            let beside = frame.x * (x.1 + 1.0) + (bounds.lo + bounds.hi) * 0.5
                - frame.x * frame.x.dot((bounds.lo + bounds.hi) * 0.5);
            assert_eq!(bounds.start_pdf(beside, direction), 0.0);
        }
    }
}
