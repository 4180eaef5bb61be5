use glam::Vec3;

use super::real::{Real, V3};

/// An orthonormal basis around a unit normal, for turning local sample
/// directions (z up) into world space.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

impl Frame {
    /// Duff et al. 2017, "Building an orthonormal basis, revisited": branchless
    /// and continuous except at one pole.
    #[inline]
    pub fn from_z(z: Vec3) -> Self {
        let [x, y, _] = frame_from_z(V3::from(z));
        Self { x: x.into(), y: y.into(), z }
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }
}

/// An orthonormal basis [x, y, z] about the unit vector `z` (Duff et al.
/// 2017: branchless, and continuous but for the sign of z.z).
#[inline(always)]
pub fn frame_from_z<R: Real>(z: V3<R>) -> [V3<R>; 3] {
    let sign = R::splat(1.0).copysign(z.z);
    let a = R::splat(-1.0) / (sign + z.z);
    let b = z.x * z.y * a;
    let x = V3::new(R::splat(1.0) + sign * z.x * z.x * a, sign * b, -sign * z.x);
    let y = V3::new(b, sign + z.y * z.y * a, -z.y);
    [x, y, z]
}

/// `v` (in the frame's coordinates) in the world's.
#[inline(always)]
pub fn to_world<R: Real>(frame: [V3<R>; 3], v: V3<R>) -> V3<R> {
    frame[0] * v.x + frame[1] * v.y + frame[2] * v.z
}

/// `v` (in the world's coordinates) in the frame's.
#[inline(always)]
pub fn to_local<R: Real>(frame: [V3<R>; 3], v: V3<R>) -> V3<R> {
    V3::new(v.dot(frame[0]), v.dot(frame[1]), v.dot(frame[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_for_awkward_normals() {
        for z in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(1.0, 2.0, -3.0).normalize()] {
            let f = Frame::from_z(z);
            for (a, b) in [(f.x, f.y), (f.y, f.z), (f.x, f.z)] {
                assert!(a.dot(b).abs() < 1e-6);
            }
            for v in [f.x, f.y, f.z] {
                assert!((v.length() - 1.0).abs() < 1e-6);
            }
            assert!((f.to_local(f.to_world(Vec3::new(0.3, -0.2, 0.9))) - Vec3::new(0.3, -0.2, 0.9)).length() < 1e-6);
        }
    }
}
