//! The camera model: a pinhole or thin lens, with smallpt's near clip.

use glam::{Vec2, Vec3};

use crate::geometry::real::{Mask, Real, V3};
use crate::geometry::Ray;
use crate::render::world::rng::{PassStreams, Sampler};
use crate::render::world::sampling::{concentric_disk, concentric_disk_of};
use crate::scene::{Camera, ClipAlong};

#[derive(Clone, Debug)]
pub struct CameraModel {
    position: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Half extents of the image plane at distance 1.
    half_width: f32,
    half_height: f32,
    /// A pixel's extent on that plane.
    pixel_size: Vec2,
    near_clip: f32,
    /// `near_clip` along each ray rather than along the view axis.
    clip_along_ray: bool,
    aperture_radius: f32,
    focus_distance: f32,
    width: f32,
    height: f32,
    /// Pixels in a row, to number them for their random streams.
    columns: u32,
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
        let half_width = half_height * width as f32 / height as f32;
        Self {
            position: camera.position,
            right,
            up,
            forward,
            half_width,
            half_height,
            pixel_size: Vec2::new(2.0 * half_width / width as f32, 2.0 * half_height / height as f32),
            near_clip: camera.near_clip,
            clip_along_ray: camera.near_clip_along == ClipAlong::Ray,
            aperture_radius: camera.aperture_radius,
            focus_distance,
            width: width as f32,
            height: height as f32,
            columns: width,
        }
    }

    /// The primary ray through film position `film` (in pixels, y down) with
    /// lens sample `lens` in [0,1)².
    #[inline]
    pub fn generate_ray(&self, film: Vec2, lens: Vec2) -> Ray {
        if self.aperture_radius > 0.0 {
            let through = Vec3::from(self.through_of(film.x, film.y));
            let l = concentric_disk(lens) * self.aperture_radius;
            let on_lens = self.position + self.right * l.x + self.up * l.y;
            let in_focus = self.position + through * self.focus_distance;
            let direction = (in_focus - on_lens).normalize();
            let start = self.clip_distance(direction);
            Ray::new(on_lens + direction * start, direction)
        } else {
            let (origin, direction) = self.pinhole_rays_of(film.x, film.y);
            Ray::new(origin.into(), direction.into())
        }
    }

    /// Pixel (x, y)'s camera ray in one pass, with the stream it leaves:
    /// jittered within the pixel, the stream fixed by (pixel, pass).
    #[inline]
    pub fn sample_ray(&self, x: u32, y: u32, streams: PassStreams) -> (Ray, Sampler) {
        let mut sampler = streams.sampler(self.pixel_index(x, y));
        let film = Vec2::new(x as f32, y as f32) + sampler.next_2d();
        // A pinhole needs no lens sample: its stream keeps two numbers
        let lens = if self.has_lens() { sampler.next_2d() } else { Vec2::ZERO };
        (self.generate_ray(film, lens), sampler)
    }

    /// The number of pixel (x, y), row by row.
    #[inline(always)]
    pub(crate) fn pixel_index(&self, x: u32, y: u32) -> u64 {
        y as u64 * self.columns as u64 + x as u64
    }

    /// From the eye through film positions (pixels, y down), one or
    /// several: the film maps to the image plane by multiplications by a
    /// pixel's extent, at unit depth along the view axis, so scaling by a
    /// depth lands on that plane.
    #[inline(always)]
    fn through_of<R: Real>(&self, film_x: R, film_y: R) -> V3<R> {
        let sx = film_x * self.pixel_size.x - self.half_width;
        let sy = R::splat(self.half_height) - film_y * self.pixel_size.y;
        V3::splat(self.forward) + V3::splat(self.right) * sx + V3::splat(self.up) * sy
    }

    /// A pinhole's rays through film positions: (origins, directions).
    #[inline(always)]
    pub(crate) fn pinhole_rays_of<R: Real>(&self, film_x: R, film_y: R) -> (V3<R>, V3<R>) {
        let through = self.through_of(film_x, film_y);
        let direction = through.normalize();
        // `through` is 1 deep along the view axis, `direction` 1 long
        let start = if self.clip_along_ray { direction } else { through };
        (V3::splat(self.position) + start * R::splat(self.near_clip), direction)
    }

    /// Whether rays start across a lens (and so need a lens sample).
    pub fn has_lens(&self) -> bool {
        self.aperture_radius > 0.0
    }

    /// Film position (pixels) where a world point appears, if in front.
    pub fn project(&self, point: Vec3) -> Option<Vec2> {
        let (x, y, behind) = self.project_of::<f32>(point.into());
        (!behind).then(|| Vec2::new(x, y))
    }

    /// `project` for one point or several: the film positions, and the
    /// points behind the camera (whose positions mean nothing).
    #[inline(always)]
    fn project_of<R: Real>(&self, point: V3<R>) -> (R, R, R::Mask) {
        let v = point - V3::splat(self.position);
        let depth = v.dot(V3::splat(self.forward));
        let sx = v.dot(V3::splat(self.right)) / depth / R::splat(self.half_width);
        let sy = v.dot(V3::splat(self.up)) / depth / R::splat(self.half_height);
        let x = (sx + 1.0) * 0.5 * self.width;
        let y = (R::splat(1.0) - sy) * 0.5 * self.height;
        (x, y, depth.le(R::splat(0.0)))
    }

    /// The density of the camera's rays along `direction` from the lens,
    /// per solid angle and per pixel: a pixel samples the image plane at
    /// unit depth uniformly over its area A, and dA = cos³θ dω there, so
    /// 1/(A cos³θ) (0 behind the camera).
    #[inline]
    pub fn ray_pdf(&self, direction: Vec3) -> f32 {
        self.ray_pdf_of::<f32>(direction.into())
    }

    /// `ray_pdf` for one direction or several.
    #[inline(always)]
    fn ray_pdf_of<R: Real>(&self, direction: V3<R>) -> R {
        let cos = direction.dot(V3::splat(self.forward));
        let pdf = R::splat(1.0) / (R::splat(self.pixel_size.x * self.pixel_size.y) * cos * cos * cos);
        R::select(cos.le(R::splat(0.0)), R::splat(0.0), pdf)
    }

    /// How far from the lens a camera ray along `direction` starts (the
    /// near clip, along the ray or the view axis).
    #[inline]
    pub fn clip_distance(&self, direction: Vec3) -> f32 {
        self.clip_distance_of::<f32>(direction.into())
    }

    /// `clip_distance` for one direction or several.
    #[inline(always)]
    fn clip_distance_of<R: Real>(&self, direction: V3<R>) -> R {
        if self.clip_along_ray {
            R::splat(self.near_clip)
        } else {
            R::splat(self.near_clip) / direction.dot(V3::splat(self.forward))
        }
    }

    /// How `point` is seen from the lens point `lens` picks (a pinhole: its
    /// position), for paths from the lights: the film position it lands on,
    /// the way to the lens, and the density of the camera's ray there. None
    /// if it lands off the film, behind the camera, or before the near clip.
    pub fn connect(&self, point: Vec3, lens: Vec2) -> Option<CameraConnection> {
        let seen = self.connect_of::<f32>(point.into(), (lens.x, lens.y));
        seen.valid.then(|| {
            let film = Vec2::new(seen.film.0, seen.film.1);
            CameraConnection::new(
                film,
                seen.lens.into(),
                seen.start,
                seen.distance,
                seen.to_camera.into(),
                seen.ray_pdf,
            )
        })
    }

    /// `connect` for one point or several, each with its lens sample:
    /// the connections, valid in the lanes of `valid`. Written once for
    /// both, so the lanes see what `connect` sees, bit for bit.
    #[inline(always)]
    pub(crate) fn connect_of<R: Real>(&self, point: V3<R>, lens: (R, R)) -> ConnectionOf<R> {
        let zero = R::splat(0.0);
        let position = V3::splat(self.position);
        let on_lens = if self.aperture_radius > 0.0 {
            let (x, y) = concentric_disk_of(lens.0, lens.1);
            let (x, y) = (x * self.aperture_radius, y * self.aperture_radius);
            position + V3::splat(self.right) * x + V3::splat(self.up) * y
        } else {
            position
        };
        let to_point = point - on_lens;
        let distance = to_point.length();
        let direction = to_point / distance;
        let forward = V3::splat(self.forward);
        let cos = direction.dot(forward);
        // A lens images the point where its ray through the lens centre
        // crosses the focus plane
        let imaged = if self.aperture_radius > 0.0 {
            on_lens + direction * (R::splat(self.focus_distance) / cos)
        } else {
            point
        };
        let (film_x, film_y, behind) = self.project_of(imaged);
        let on_film = (film_x.ge(zero).and(film_x.lt(R::splat(self.width))))
            .and(film_y.ge(zero).and(film_y.lt(R::splat(self.height))));
        let start = self.clip_distance_of(direction);
        // Seen: ahead of the lens and the camera, on the film, past the near clip
        let ahead = distance.is_finite().and_not(cos.le(zero)).and_not(behind);
        ConnectionOf {
            valid: ahead.and(on_film).and(distance.gt(start)),
            film: (film_x, film_y),
            lens: on_lens,
            start,
            distance,
            to_camera: -direction,
            ray_pdf: self.ray_pdf_of(direction),
        }
    }

    /// Where the central ray starts: the middle of the near-clip rectangle
    /// (the lens centre when there is no near clip).
    pub fn central_origin(&self) -> Vec3 {
        self.position + self.forward * self.near_clip
    }

    /// The ray through the centre of pixel (x, y), for picking.
    pub fn pixel_ray(&self, x: f32, y: f32) -> Ray {
        let saved = Self { aperture_radius: 0.0, ..self.clone() };
        saved.generate_ray(Vec2::new(x, y), Vec2::splat(0.5))
    }
}

/// A point as the camera sees it (`CameraModel::connect`).
#[derive(Clone, Copy, Debug)]
pub struct CameraConnection {
    /// Film position, in pixels (y down), and the pixel that holds it.
    pub film: Vec2,
    pub pixel: (u32, u32),
    /// The point on the lens the connection goes to.
    pub lens: Vec3,
    /// How far from the lens along the ray camera rays start (the near clip).
    pub start: f32,
    /// From the lens point to the point.
    pub distance: f32,
    /// Unit direction from the point toward the lens.
    pub to_camera: Vec3,
    /// `CameraModel::ray_pdf` of the ray from the lens to the point.
    pub ray_pdf: f32,
}

/// `CameraConnection`s of one point or several (`connect_of`), valid in
/// the lanes of `valid`.
pub(crate) struct ConnectionOf<R: Real> {
    pub(crate) valid: R::Mask,
    pub(crate) film: (R, R),
    pub(crate) lens: V3<R>,
    pub(crate) start: R,
    pub(crate) distance: R,
    pub(crate) to_camera: V3<R>,
    pub(crate) ray_pdf: R,
}

impl CameraConnection {
    /// The connection landing at `film`, in the pixel that holds it.
    #[inline(always)]
    pub(crate) fn new(film: Vec2, lens: Vec3, start: f32, distance: f32, to_camera: Vec3, ray_pdf: f32) -> Self {
        CameraConnection { film, pixel: (film.x as u32, film.y as u32), lens, start, distance, to_camera, ray_pdf }
    }
}

/// A rectangle of the image: what one task of a pass renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl TileRect {
    pub fn pixels(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// Pixel `i` of the tile, row by row, in image coordinates.
    #[inline]
    pub fn pixel(&self, i: usize) -> (u32, u32) {
        (self.x + i as u32 % self.width, self.y + i as u32 / self.width)
    }
}

/// The camera samples of one pass over a tile: pixel (x, y) of `rect`, row
/// by row, as `CameraModel::sample_ray` draws them.
#[derive(Clone, Copy, Debug)]
pub struct CameraTile<'a> {
    pub camera: &'a CameraModel,
    pub rect: TileRect,
    pub streams: PassStreams,
}

impl CameraTile<'_> {
    pub fn len(&self) -> usize {
        self.rect.pixels()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sample `i`'s ray and the stream it leaves, drawn one at a time.
    pub fn sample(&self, i: usize) -> (Ray, Sampler) {
        let (x, y) = self.rect.pixel(i);
        self.camera.sample_ray(x, y, self.streams)
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
            near_clip_along: ClipAlong::ViewAxis,
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

    #[test]
    fn near_clip_along_the_ray_starts_every_ray_on_a_sphere_about_the_eye() {
        for aperture in [0.0, 0.4] {
            let along_ray = Camera { near_clip_along: ClipAlong::Ray, aperture_radius: aperture, ..camera() };
            let on_plane = Camera { aperture_radius: aperture, ..camera() };
            let (sphere, plane) = (CameraModel::new(&along_ray, 200, 100), CameraModel::new(&on_plane, 200, 100));
            for film in [Vec2::new(100.0, 50.0), Vec2::new(0.0, 0.0), Vec2::new(150.0, 90.0)] {
                let lens = Vec2::new(0.3, 0.8);
                let (s, p) = (sphere.generate_ray(film, lens), plane.generate_ray(film, lens));
                assert!((s.direction - p.direction).length() < 1e-6, "same directions");
                let eye = s.origin - s.direction * 2.0;
                // The ray starts 2 along itself from where it leaves the lens
                assert!((eye.z - 5.0).abs() < 1e-5, "{eye}");
                // A corner ray on the plane starts further out than on the sphere
                let extra = (p.origin - s.origin).dot(s.direction);
                let expected = 2.0 / s.direction.dot(-Vec3::Z) - 2.0;
                assert!((extra - expected).abs() < 1e-4, "{extra} vs {expected}");
            }
        }
    }

    #[test]
    fn central_origin_is_where_the_central_ray_starts() {
        for aperture in [0.0, 0.4] {
            let model = CameraModel::new(&Camera { aperture_radius: aperture, ..camera() }, 64, 48);
            let ray = model.generate_ray(Vec2::new(32.0, 24.0), Vec2::splat(0.5));
            assert!(
                (ray.origin - model.central_origin()).length() < 1e-5,
                "{} vs {}",
                ray.origin,
                model.central_origin()
            );
        }
    }

    /// A light path reaches the film where the camera's ray to its point
    /// came from, with or without a lens and a near clip, and the density
    /// of that ray integrates to one pixel's worth over the image: Σ over
    /// pixels of ∫ pdf dω = pixels (checked at the pixel centres, where
    /// ∫_pixel pdf dω = 1 exactly: dω = cos³θ dA).
    #[test]
    fn connecting_a_point_inverts_the_camera_ray_through_it() {
        for (aperture, clip, along) in
            [(0.0, 0.0, ClipAlong::ViewAxis), (0.4, 2.0, ClipAlong::Ray), (0.0, 1.5, ClipAlong::ViewAxis)]
        {
            let cam = Camera { aperture_radius: aperture, near_clip: clip, near_clip_along: along, ..camera() };
            let model = CameraModel::new(&cam, 64, 48);
            let mut s = Sampler::new(1, 2, 3);
            for _ in 0..1000 {
                let (film, lens) = (Vec2::new(s.next_f32() * 64.0, s.next_f32() * 48.0), s.next_2d());
                let ray = model.generate_ray(film, lens);
                let point = ray.at(1.0 + 6.0 * s.next_f32());
                let seen = model.connect(point, lens).expect("in view");
                assert!((seen.film - film).length() < 2e-3, "{} vs {film}", seen.film);
                assert!((seen.to_camera + ray.direction).length() < 1e-4);
                assert!(((seen.lens + (-seen.to_camera) * seen.start) - ray.origin).length() < 1e-4);
            }
            // Before the near clip nothing is seen
            if clip > 0.0 {
                assert!(model.connect(model.position + model.forward * clip * 0.5, Vec2::splat(0.5)).is_none());
            }
        }
        // The solid angle of a pixel, exactly (Van Oosterom and Strackee's
        // formula for its two triangles), times the density at its centre,
        // is one: the camera picks one ray per pixel
        let model = CameraModel::new(&camera(), 64, 48);
        let corner = |x: f32, y: f32| Vec3::from(model.through_of(x, y)).as_dvec3();
        let triangle = |a: glam::DVec3, b: glam::DVec3, c: glam::DVec3| {
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
            2.0 * a.dot(b.cross(c)).abs().atan2(denominator)
        };
        for (x, y) in [(32.0, 24.0), (0.0, 0.0), (63.0, 10.0)] {
            let [a, b, c, d] = [corner(x, y), corner(x + 1.0, y), corner(x + 1.0, y + 1.0), corner(x, y + 1.0)];
            let solid_angle = triangle(a, b, c) + triangle(a, c, d);
            let centre = Vec3::from(model.through_of(x + 0.5, y + 0.5)).normalize();
            let pixels = model.ray_pdf(centre) as f64 * solid_angle;
            assert!((pixels - 1.0).abs() < 1e-3, "pixel ({x}, {y}): {pixels}");
        }
        assert_eq!(model.ray_pdf(-model.forward), 0.0);
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

    /// `connect_of` in eight lanes is `connect` lane by lane, bit for bit,
    /// through a pinhole and a lens, near clips along the ray and the axis,
    /// for points in front of the camera, beside it, behind it and inside
    /// the near clip.
    #[test]
    fn connect_in_the_lanes_is_connect_lane_by_lane() {
        use crate::render::world::lanes::{F8, LANES, V8};
        use crate::render::world::rng::Sampler;
        let mut sampler = Sampler::new(7, 0, 3);
        let (mut seen, mut unseen) = (0, 0);
        for (aperture_radius, near_clip_along) in
            [(0.0, ClipAlong::ViewAxis), (0.3, ClipAlong::ViewAxis), (0.3, ClipAlong::Ray)]
        {
            let model = CameraModel::new(&Camera { aperture_radius, near_clip_along, ..camera() }, 64, 48);
            for _ in 0..200 {
                // Points in a box about the camera at z = 5, most in front of it
                let points: [Vec3; LANES] = std::array::from_fn(|_| {
                    let (a, b) = (sampler.next_2d(), sampler.next_2d());
                    Vec3::new(a.x * 12.0 - 6.0, a.y * 12.0 - 6.0, b.x * 10.0 - 4.0)
                });
                let lens: [Vec2; LANES] = std::array::from_fn(|_| sampler.next_2d());
                let lanes = model
                    .connect_of(V8::from_fn(|i| points[i]), (F8::from_fn(|i| lens[i].x), F8::from_fn(|i| lens[i].y)));
                for i in 0..LANES {
                    let one = model.connect(points[i], lens[i]);
                    assert_eq!(lanes.valid.test(i), one.is_some(), "{:?} through {:?}", points[i], lens[i]);
                    let Some(one) = one else {
                        unseen += 1;
                        continue;
                    };
                    seen += 1;
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(lanes.film.0.lane(i).to_bits(), one.film.x.to_bits());
                    assert_eq!(lanes.film.1.lane(i).to_bits(), one.film.y.to_bits());
                    assert_eq!(bits(lanes.lens.lane(i)), bits(one.lens));
                    assert_eq!(lanes.start.lane(i).to_bits(), one.start.to_bits());
                    assert_eq!(lanes.distance.lane(i).to_bits(), one.distance.to_bits());
                    assert_eq!(bits(lanes.to_camera.lane(i)), bits(one.to_camera));
                    assert_eq!(lanes.ray_pdf.lane(i).to_bits(), one.ray_pdf.to_bits());
                }
            }
        }
        assert!(seen > 1000 && unseen > 1000, "{seen} seen, {unseen} not");
    }
}
