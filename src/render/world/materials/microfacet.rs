//! GGX (Trowbridge–Reitz) microfacets, what every rough material is made
//! of: the distribution of normals D, Smith's masking G1, and the normals
//! a direction sees drawn in proportion to what it sees of them (Dupuy &
//! Benyoub 2023's spherical caps, the density of Heitz 2018's visible
//! normals). Vectors are in the surface's frame, z along its normal.
//! The roughness is α itself (the width of the slopes' distribution), not
//! a remapped "roughness", as Mitsuba and pbrt-v4 take it.

use std::f32::consts::{FRAC_1_PI, PI};

use crate::geometry::real::{Real, V3};
use crate::render::world::sampling::sin_cos_of;

/// α along the frame's x and y axes (equal for an isotropic surface).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx<R: Real> {
    pub alpha_x: R,
    pub alpha_y: R,
}

impl<R: Real> Ggx<R> {
    /// D(h): the density of microfacet normals per projected area, for a
    /// unit `h` above the surface.
    #[inline(always)]
    pub fn d(&self, h: V3<R>) -> R {
        let (x, y) = (h.x / self.alpha_x, h.y / self.alpha_y);
        let s = x * x + y * y + h.z * h.z;
        R::splat(FRAC_1_PI) / (self.alpha_x * self.alpha_y * s * s)
    }

    /// Smith's Λ(w) for a unit `w` above the surface.
    #[inline(always)]
    pub fn lambda(&self, w: V3<R>) -> R {
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        let tan2 = (x * x + y * y) / (w.z * w.z);
        ((tan2 + 1.0).sqrt() - 1.0) * 0.5
    }

    /// G1(w): the share of the microfacets facing `w` that it sees.
    #[inline(always)]
    pub fn g1(&self, w: V3<R>) -> R {
        R::splat(1.0) / (self.lambda(w) + 1.0)
    }

    /// A microfacet normal seen from `wo` (above the surface), drawn with
    /// density G1(wo) max(0, wo·h) D(h) / wo.z from `u0`, `u1`: the
    /// direction stretched to a surface of α = 1, where the visible normals
    /// are a spherical cap about it shifted by it, and squeezed back.
    #[inline(always)]
    pub fn sample_visible(&self, wo: V3<R>, u0: R, u1: R) -> V3<R> {
        let zero = R::splat(0.0);
        let stretched = V3::new(wo.x * self.alpha_x, wo.y * self.alpha_y, wo.z).normalize();
        let (sin_phi, cos_phi) = sin_cos_of(u0 * (2.0 * PI));
        let z = (R::splat(1.0) - u1) * (stretched.z + 1.0) - stretched.z;
        let sin_theta = (R::splat(1.0) - z * z).max(zero).sqrt();
        let h = V3::new(sin_theta * cos_phi, sin_theta * sin_phi, z) + stretched;
        V3::new(h.x * self.alpha_x, h.y * self.alpha_y, h.z.max(zero)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::real::V3;
    use crate::render::world::rng::Sampler;
    use glam::Vec3;

    fn ggx(alpha_x: f32, alpha_y: f32) -> Ggx<f32> {
        Ggx { alpha_x, alpha_y }
    }

    /// ∫ f(θ, φ) over the hemisphere by the midpoint rule in f64.
    fn hemisphere(steps: usize, f: impl Fn(Vec3) -> f64) -> f64 {
        let (d_theta, d_phi) = (std::f64::consts::FRAC_PI_2 / steps as f64, 2.0 * std::f64::consts::PI / steps as f64);
        let mut sum = 0.0;
        for i in 0..steps {
            let theta = (i as f64 + 0.5) * d_theta;
            for j in 0..steps {
                let phi = (j as f64 + 0.5) * d_phi;
                let w =
                    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                sum += f(w) * theta.sin() * d_theta * d_phi;
            }
        }
        sum
    }

    /// The normals' projected areas make the surface's: ∫ D(h) cos θh dω = 1;
    /// and what `wo` sees of them is its own projected area: ∫ G1(wo)
    /// max(0, wo·h) D(h) dω = wo.z (Heitz 2014, eq. 7), isotropic and not.
    #[test]
    fn the_normals_make_the_surface_and_masking_keeps_its_projection() {
        for (ax, ay) in [(0.1f32, 0.1f32), (0.5, 0.5), (1.0, 1.0), (0.2, 0.7)] {
            let g = ggx(ax, ay);
            let area = hemisphere(1200, |h| g.d(h.into()) as f64 * h.z as f64);
            assert!((area - 1.0).abs() < 2e-3, "α {ax}, {ay}: ∫ D cos = {area}");
            for theta in [0.0f32, 45.0, 80.0] {
                let wo =
                    Vec3::new(theta.to_radians().sin() * 0.6, theta.to_radians().sin() * 0.8, theta.to_radians().cos());
                let seen = hemisphere(1200, |h| (g.g1(wo.into()) * wo.dot(h).max(0.0) * g.d(h.into())) as f64);
                assert!((seen - wo.z as f64).abs() < 3e-3, "α {ax}, {ay} at {theta}°: {seen} against {}", wo.z);
            }
        }
    }

    /// The visible normals are drawn with their density: the mean of a test
    /// function of h under `sample_visible` equals its integral against
    /// D_wo by quadrature (h.x², h.z and h.y·h.x tell a stretched or
    /// turned sample), within 5 standard errors.
    #[test]
    fn visible_normals_are_drawn_with_their_density() {
        let mut s = Sampler::new(3, 1, 4);
        for (ax, ay) in [(0.1f32, 0.1f32), (0.6, 0.6), (0.2, 0.8)] {
            let g = ggx(ax, ay);
            for theta in [0.0f32, 50.0, 85.0] {
                let wo =
                    Vec3::new(theta.to_radians().sin() * 0.8, theta.to_radians().sin() * 0.6, theta.to_radians().cos());
                let density = |h: Vec3| (g.g1(wo.into()) * wo.dot(h).max(0.0) * g.d(h.into()) / wo.z) as f64;
                let tests: [fn(Vec3) -> f64; 3] = [|h| (h.x * h.x) as f64, |h| h.z as f64, |h| (h.x * h.y) as f64];
                for test in tests {
                    let expected = hemisphere(1500, |h| test(h) * density(h));
                    let n = 100_000;
                    let values: Vec<f64> = (0..n)
                        .map(|_| {
                            let u = s.next_2d();
                            let h: Vec3 = g.sample_visible(V3::from(wo), u.x, u.y).into();
                            assert!((h.length() - 1.0).abs() < 1e-4 && h.z >= 0.0, "{h}");
                            test(h)
                        })
                        .collect();
                    let mean = values.iter().sum::<f64>() / n as f64;
                    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
                    let error = (variance / n as f64).sqrt();
                    assert!(
                        (mean - expected).abs() < 5.0 * error + 2e-4,
                        "α {ax}, {ay} at {theta}°: sampled {mean} ± {error}, integral {expected}"
                    );
                }
            }
        }
    }
}
