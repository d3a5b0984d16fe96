//! Rigid frames and KUKA-style frame vectors `[x, y, z, A, B, C]`.
//!
//! `pose(v) = Trans(x, y, z) * Rz(A) * Ry(B) * Rx(C)` (DESIGN.md). Inside the library angles are in
//! radians; the conversion to degrees happens at the interfaces.

use nalgebra::{IsometryMatrix3, Matrix3, Rotation3, Translation3, Vector3};

/// A rigid transform (rotation matrix + translation), the type every frame in robocal uses.
pub type Frame = IsometryMatrix3<f64>;

/// Rotation about x by `t` radians.
#[inline]
pub fn rot_x(t: f64) -> Matrix3<f64> {
    let (s, c) = t.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation about y by `t` radians.
#[inline]
pub fn rot_y(t: f64) -> Matrix3<f64> {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about z by `t` radians.
#[inline]
pub fn rot_z(t: f64) -> Matrix3<f64> {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Builds a frame from a rotation matrix (assumed orthonormal) and a translation.
#[inline]
pub fn frame(r: Matrix3<f64>, p: Vector3<f64>) -> Frame {
    Frame::from_parts(Translation3::from(p), Rotation3::from_matrix_unchecked(r))
}

/// `pose(v)` for a frame vector `[x, y, z, A, B, C]` in mm and **radians**.
pub fn pose(v: &[f64; 6]) -> Frame {
    frame(
        rot_z(v[3]) * rot_y(v[4]) * rot_x(v[5]),
        Vector3::new(v[0], v[1], v[2]),
    )
}

/// The frame vector `[x, y, z, A, B, C]` (mm, radians) of a frame; inverse of [`pose`].
/// At the singularity `B = ±90°` the split between A and C is arbitrary; A is set to 0 there.
pub fn frame_vector(f: &Frame) -> [f64; 6] {
    let r = f.rotation.matrix();
    let p = f.translation.vector;
    let cb = (r[(0, 0)] * r[(0, 0)] + r[(1, 0)] * r[(1, 0)]).sqrt();
    let b = (-r[(2, 0)]).atan2(cb);
    let (a, c) = if cb > 1e-12 {
        (r[(1, 0)].atan2(r[(0, 0)]), r[(2, 1)].atan2(r[(2, 2)]))
    } else {
        (0.0, (-r[(1, 2)]).atan2(r[(1, 1)]) * b.signum())
    };
    [p.x, p.y, p.z, a, b, c]
}

/// Converts a frame vector from mm/degrees to mm/radians.
pub fn vec_deg_to_rad(v: &[f64; 6]) -> [f64; 6] {
    [
        v[0],
        v[1],
        v[2],
        v[3].to_radians(),
        v[4].to_radians(),
        v[5].to_radians(),
    ]
}

/// Converts a frame vector from mm/radians to mm/degrees.
pub fn vec_rad_to_deg(v: &[f64; 6]) -> [f64; 6] {
    [
        v[0],
        v[1],
        v[2],
        v[3].to_degrees(),
        v[4].to_degrees(),
        v[5].to_degrees(),
    ]
}

/// The axes about which the three angles of a frame vector rotate, in the frame's parent:
/// `[z, Rz(A) y, Rz(A) Ry(B) x]`. Used for the analytic derivatives of `pose(v)` with respect to A,
/// B and C.
pub fn euler_axes(a: f64, b: f64) -> [Vector3<f64>; 3] {
    let rz = rot_z(a);
    let rzy = rz * rot_y(b);
    [Vector3::z(), rz.column(1).into(), rzy.column(0).into()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_vector_roundtrip() {
        let v = [1.0, -2.0, 3.0, 0.3, -0.7, 2.5];
        let w = frame_vector(&pose(&v));
        for k in 0..6 {
            assert!((v[k] - w[k]).abs() < 1e-12, "{k}: {} vs {}", v[k], w[k]);
        }
    }

    #[test]
    fn euler_axes_match_finite_difference() {
        let v = [0.0, 0.0, 0.0, 0.4, -0.3, 1.1];
        let axes = euler_axes(v[3], v[4]);
        let p = Vector3::new(0.3, -0.2, 0.9);
        for k in 0..3 {
            let h = 1e-6;
            let mut vp = v;
            vp[3 + k] += h;
            let mut vm = v;
            vm[3 + k] -= h;
            let fd = (pose(&vp) * nalgebra::Point3::from(p)
                - pose(&vm) * nalgebra::Point3::from(p))
                / (2.0 * h);
            let q = pose(&v) * nalgebra::Point3::from(p);
            let an = axes[k].cross(&q.coords);
            assert!((fd - an).norm() < 1e-8, "{k}: {fd} vs {an}");
        }
    }
}
