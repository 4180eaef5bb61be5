//! The photon record: 28 bytes — position (12), RGB power (12), incoming
//! direction packed in two bytes as Jensen does (θ, φ quantised to 256
//! steps, `direction`), and the kd-tree's split axis.

use glam::Vec3;

use super::direction::{phi_step, tables, theta_step};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Photon {
    pub position: Vec3,
    pub power: [f32; 3],
    theta: u8,
    phi: u8,
    axis: u8,
    _pad: u8,
}

impl Photon {
    /// `incoming_direction`: the unit direction the photon travels.
    pub fn new(position: Vec3, incoming_direction: Vec3, power: [f32; 3]) -> Self {
        let d = incoming_direction;
        Self { position, power, theta: theta_step(d.z), phi: phi_step(d.x, d.y), axis: 0, _pad: 0 }
    }

    #[inline]
    pub fn incoming_direction(&self) -> Vec3 {
        let t = tables();
        let (ti, pi) = (self.theta as usize, self.phi as usize);
        Vec3::new(t.sin_theta[ti] * t.cos_phi[pi], t.sin_theta[ti] * t.sin_phi[pi], t.cos_theta[ti])
    }

    #[inline]
    pub fn axis(&self) -> usize {
        self.axis as usize
    }

    #[inline]
    pub(super) fn set_axis(&mut self, axis: usize) {
        self.axis = axis as u8;
    }

    /// Little-endian bytes for photon-map files.
    pub fn to_bytes(&self) -> [u8; 28] {
        let mut out = [0u8; 28];
        for (i, v) in self.position.to_array().into_iter().chain(self.power).enumerate() {
            out[i * 4..i * 4 + 4].copy_from_slice(&v.to_le_bytes());
        }
        out[24] = self.theta;
        out[25] = self.phi;
        out[26] = self.axis;
        out
    }

    /// A photon read back from a file, refused (saying what is wrong)
    /// unless it is one `to_bytes` could have written: a finite position, a
    /// finite power that is not negative, a split axis of 0, 1 or 2.
    pub fn from_bytes(bytes: &[u8; 28]) -> Result<Self, &'static str> {
        let f = |i: usize| f32::from_le_bytes([bytes[i * 4], bytes[i * 4 + 1], bytes[i * 4 + 2], bytes[i * 4 + 3]]);
        let photon = Self {
            position: Vec3::new(f(0), f(1), f(2)),
            power: [f(3), f(4), f(5)],
            theta: bytes[24],
            phi: bytes[25],
            axis: bytes[26],
            _pad: bytes[27],
        };
        if !photon.position.is_finite() {
            return Err("a position that is not finite");
        }
        if !photon.power.iter().all(|p| p.is_finite() && *p >= 0.0) {
            return Err("a power that is negative or not finite");
        }
        if photon.axis > 2 || photon._pad != 0 {
            return Err("a split axis other than x, y or z");
        }
        Ok(photon)
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    #[test]
    fn damaged_records_are_refused() {
        let good = Photon::new(Vec3::new(1.0, 2.0, 3.0), Vec3::Z, [0.5; 3]).to_bytes();
        let with = |at: usize, bytes: &[u8]| {
            let mut b = good;
            b[at..at + bytes.len()].copy_from_slice(bytes);
            Photon::from_bytes(&b)
        };
        assert!(with(4, &f32::NAN.to_le_bytes()).unwrap_err().contains("position"));
        assert!(with(16, &(-1.0f32).to_le_bytes()).unwrap_err().contains("power"));
        assert!(with(20, &f32::INFINITY.to_le_bytes()).unwrap_err().contains("power"));
        assert!(with(26, &[3]).unwrap_err().contains("axis"));
        assert!(with(27, &[1]).is_err());
        assert!(with(26, &[2]).is_ok());
    }

    #[test]
    fn photon_is_28_bytes() {
        assert_eq!(std::mem::size_of::<Photon>(), 28);
    }

    #[test]
    fn direction_survives_packing_within_one_step() {
        // One θ step is π/256; φ steps shrink toward the poles, so compare angles
        let tolerance = (2.0 * PI / 256.0).cos();
        let mut s = Sampler::new(0, 0, 4);
        let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        for d in axes.into_iter().chain((0..10_000).map(|_| uniform_sphere(s.next_2d()))) {
            let p = Photon::new(Vec3::ZERO, d, [1.0; 3]);
            assert!(p.incoming_direction().dot(d) > tolerance, "{d} → {}", p.incoming_direction());
            assert_eq!(Photon::from_bytes(&p.to_bytes()), Ok(p));
        }
    }
}
