//! The camera model: a pinhole or thin lens, with smallpt's near clip.

use glam::{Vec2, Vec3};

use super::sampling::concentric_disk;
use crate::geometry::Ray;
use crate::scene::Camera;

#[derive(Clone, Debug)]
pub struct CameraModel {
    position: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Half extents of the image plane at distance 1.
    half_width: f32,
    half_height: f32,
    near_clip: f32,
    aperture_radius: f32,
    focus_distance: f32,
    width: f32,
    height: f32,
}

impl CameraModel {
    /// Assumes a validated camera (non-degenerate view and up).
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.look_at - camera.position).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let half_height = (camera.fov_y_degrees.to_radians() * 0.5).tan();
        let focus_distance = if camera.focus_distance > 0.0 {
            camera.focus_distance
        } else {
            (camera.look_at - camera.position).dot(forward)
        };
        Self {
            position: camera.position,
            right,
            up,
            forward,
            half_width: half_height * width as f32 / height as f32,
            half_height,
            near_clip: camera.near_clip,
            aperture_radius: camera.aperture_radius,
            focus_distance,
            width: width as f32,
            height: height as f32,
        }
    }

    /// The primary ray through film position `film` (in pixels, y down) with
    /// lens sample `lens` in [0,1)².
    #[inline]
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let sx = (2.0 * film.x / self.width - 1.0) * self.half_width;
        let sy = (1.0 - 2.0 * film.y / self.height) * self.half_height;
        // Unit depth along the view axis, so scaling by a depth lands on that plane
        let through = self.forward + self.right * sx + self.up * sy;
        let (origin, direction) = if self.aperture_radius > 0.0 {
            let l = concentric_disk(lens) * self.aperture_radius;
            let on_lens = self.position + self.right * l.x + self.up * l.y;
            let in_focus = self.position + through * self.focus_distance;
            (on_lens, (in_focus - on_lens).normalize())
        } else {
            (self.position, through.normalize())
        };
        let origin = origin + direction * (self.near_clip / direction.dot(self.forward));
        Ray::new(origin, direction)
    }

    /// Film position (pixels) where a world point appears, if in front.
    pub fn project(&self, point: Vec3) -> Option<Vec2> {
        let v = point - self.position;
        let depth = v.dot(self.forward);
        if depth <= 0.0 {
            return None;
        }
        let sx = v.dot(self.right) / depth / self.half_width;
        let sy = v.dot(self.up) / depth / self.half_height;
        Some(Vec2::new((sx + 1.0) * 0.5 * self.width, (1.0 - sy) * 0.5 * self.height))
    }

    /// Where primary rays start: every origin lies within `margin` of the
    /// quadrilateral `corners`. Origins sit on the near-clip plane at
    /// `lens·(1 − k) + pinhole·k`, k = near / focus, so the set is the pinhole
    /// rectangle widened by the lens disc scaled by |1 − k|.
    pub fn origin_hull(&self) -> ([Vec3; 4], f32) {
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(sx, sy): (f32, f32)| {
            self.position
                + (self.forward + self.right * (sx * self.half_width) + self.up * (sy * self.half_height))
                    * self.near_clip
        });
        let k = if self.focus_distance > 0.0 { self.near_clip / self.focus_distance } else { 0.0 };
        (corners, self.aperture_radius * (1.0 - k).abs())
    }

    /// The ray through the centre of pixel (x, y), for picking.
    pub fn pixel_ray(&self, x: f32, y: f32) -> Ray {
        let saved = Self { aperture_radius: 0.0, ..self.clone() };
        saved.generate_ray(Vec2::new(x, y), Vec2::splat(0.5))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_degrees: 90.0,
            near_clip: 2.0,
            aperture_radius: 0.0,
            focus_distance: 0.0,
        }
    }

    #[test]
    fn centre_ray_looks_at_target_and_starts_at_near_clip() {
        let model = CameraModel::new(&camera(), 200, 100);
        let ray = model.generate_ray(Vec2::new(100.0, 50.0), Vec2::ZERO);
        assert!((ray.direction - -Vec3::Z).length() < 1e-6);
        assert!((ray.origin - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-5);
        // Top edge at 45° for a 90° vertical field of view; left edge at 2:1 aspect
        let top = model.generate_ray(Vec2::new(100.0, 0.0), Vec2::ZERO);
        assert!((top.direction.y - top.direction.z.abs()).abs() < 1e-5);
        let left = model.generate_ray(Vec2::new(0.0, 50.0), Vec2::ZERO);
        assert!((left.direction.x / left.direction.z - 2.0).abs() < 1e-5);
        // Near clip measured along the view axis, not along the ray
        assert!((top.origin.z - 3.0).abs() < 1e-5);
        // Projection inverts ray generation
        let film = model.project(left.at(7.0)).unwrap();
        assert!((film - Vec2::new(0.0, 50.0)).length() < 1e-3, "{film}");
        assert!(model.project(Vec3::new(0.0, 0.0, 9.0)).is_none());
    }

    /// Every primary ray origin, pinhole or thin lens, lies in the hull.
    #[test]
    fn ray_origins_lie_in_the_origin_hull() {
        use crate::render::rng::Sampler;
        for aperture in [0.0, 0.4] {
            let mut cam = camera();
            cam.aperture_radius = aperture;
            let model = CameraModel::new(&cam, 64, 48);
            let (corners, margin) = model.origin_hull();
            // The hull is a rectangle in the near-clip plane: its centre and half extents
            let centre = corners.iter().copied().sum::<Vec3>() / 4.0;
            let (half_x, half_y) = ((corners[1] - corners[0]).length() * 0.5, (corners[3] - corners[0]).length() * 0.5);
            let mut s = Sampler::new(0, 0, 3);
            let outside_of = |origin: Vec3| {
                let origin = origin - centre;
                (origin, Vec2::new((origin.x.abs() - half_x).max(0.0), (origin.y.abs() - half_y).max(0.0)).length())
            };
            for _ in 0..10_000 {
                let film = Vec2::new(s.next_f32() * 64.0, s.next_f32() * 48.0);
                let (origin, outside) = outside_of(model.generate_ray(film, s.next_2d()).origin);
                assert!(origin.z.abs() < 1e-5, "origin off the near-clip plane: {origin}");
                assert!(outside <= margin + 1e-5, "origin {origin} outside the hull by {outside}");
            }
            // The margin is tight: the left edge seen through the lens' left edge reaches it
            let (_, outside) = outside_of(model.generate_ray(Vec2::new(0.0, 24.0), Vec2::new(0.0, 0.5)).origin);
            assert!((outside - margin).abs() < 1e-5, "margin {margin}, reached {outside}");
        }
    }

    #[test]
    fn thin_lens_rays_converge_on_the_focus_plane() {
        let mut cam = camera();
        cam.aperture_radius = 0.5;
        cam.near_clip = 0.0;
        let model = CameraModel::new(&cam, 64, 64);
        let film = Vec2::new(20.0, 40.0);
        let a = model.generate_ray(film, Vec2::new(0.1, 0.2));
        let b = model.generate_ray(film, Vec2::new(0.9, 0.7));
        // Focus plane: z = 0, at the look-at distance
        let pa = a.at(a.origin.z / -a.direction.z);
        let pb = b.at(b.origin.z / -b.direction.z);
        assert!((pa - pb).length() < 1e-4, "{pa} vs {pb}");
        assert!((a.origin - b.origin).length() > 0.1);
    }
}
