//! Rigid frames and KUKA-style frame vectors `[x, y, z, A, B, C]`.
//!
//! `pose(v) = Trans(x, y, z) * Rz(A) * Ry(B) * Rx(C)` (DESIGN.md). Inside the library angles are in
//! radians; the conversion to degrees happens at the interfaces.
//!
//! [`TrackerFrame`] is the one way a measured point (or frame) gets from the laser tracker's
//! frame into the robot's base frame.

use nalgebra::{IsometryMatrix3, Matrix3, Point3, Rotation3, Translation3, Vector3};

/// A rigid transform (rotation matrix + translation), the type every frame in robocal uses.
pub type Frame = IsometryMatrix3<f64>;

/// Rotation about x by `t` radians.
#[inline]
pub(crate) fn rot_x(t: f64) -> Matrix3<f64> {
    let (s, c) = t.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation about y by `t` radians.
#[inline]
pub(crate) fn rot_y(t: f64) -> Matrix3<f64> {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about z by `t` radians.
#[inline]
pub(crate) fn rot_z(t: f64) -> Matrix3<f64> {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Builds a frame from a rotation matrix (assumed orthonormal) and a translation.
#[inline]
pub(crate) fn frame(r: Matrix3<f64>, p: Vector3<f64>) -> Frame {
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
        // With A = 0, Ry(±90°) Rx(C) has r11 = cos C and r12 = -sin C at either sign of B.
        (0.0, (-r[(1, 2)]).atan2(r[(1, 1)]))
    };
    [p.x, p.y, p.z, a, b, c]
}

/// The rotation vector `log(R)` (axis times angle, rad) of a rotation matrix, accurate to
/// rounding at small angles: the angle from `atan2` of the skew and symmetric parts (nalgebra's
/// `scaled_axis` goes through `acos` of the trace, whose error near the identity is about 1e-8
/// rad, above a 1e-6 degree tolerance's reach). Orientation errors of 6-DoF fits and of full-pose
/// compensation both use it.
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    if s < 1e-3 && c > 0.0 {
        // theta / sin(theta) by its series: accurate where the ratio is about 1.
        return v * (1.0 + s * s / 6.0 + 3.0 * s.powi(4) / 40.0);
    }
    if c > -0.99 {
        return v * (s.atan2(c) / s);
    }
    // Near a half turn the skew part vanishes (and nalgebra's `scaled_axis` returns zero at an
    // exact half turn): the axis from the symmetric part, (R + R^T)/2 - c I = (1 - c) n n^T,
    // its column of largest diagonal; the sign from the skew part, sin(theta) n.
    let b = (r + r.transpose()) * 0.5 - Matrix3::identity() * c;
    let k = (0..3)
        .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
        .expect("three columns");
    let mut n = b.column(k).into_owned();
    n /= n.norm();
    if n.dot(&v) < 0.0 {
        n = -n;
    }
    n * s.atan2(c)
}

/// Converts a frame vector from mm/degrees to mm/radians.
pub(crate) fn vec_deg_to_rad(v: &[f64; 6]) -> [f64; 6] {
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
pub(crate) fn euler_axes(a: f64, b: f64) -> [Vector3<f64>; 3] {
    // The robot keeps those of its base and of each target with their frames
    // (`Robot::base_euler_axes`, `Robot::target_euler_axes`): the Jacobian passes read them there.
    let rz = rot_z(a);
    let rzy = rz * rot_y(b);
    [Vector3::z(), rz.column(1).into(), rzy.column(0).into()]
}

/// The pose of the laser tracker's frame in the robot's base frame (the paper's measurement frame
/// MF in the ACS, section II.C; the result JSON's `tracker_frame`): a point `m` measured in the
/// tracker frame is `pose(tracker_frame) * m` in the base frame.
///
/// Every mapping of measurements into the base frame goes through this type, so that the
/// direction of the transform is written down once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerFrame(Frame);

impl TrackerFrame {
    /// The tracker frame whose pose in the base frame is `pose`.
    pub fn new(pose: Frame) -> Self {
        TrackerFrame(pose)
    }

    /// A tracker frame that coincides with the base frame.
    pub fn identity() -> Self {
        TrackerFrame(Frame::identity())
    }

    /// From its frame vector `[x, y, z, A, B, C]` in mm and **degrees** (the files' units).
    pub fn from_vector_deg(v: &[f64; 6]) -> Self {
        TrackerFrame(pose(&vec_deg_to_rad(v)))
    }

    /// Its frame vector `[x, y, z, A, B, C]` in mm and **degrees** (see [`frame_vector`]).
    pub fn vector_deg(&self) -> [f64; 6] {
        vec_rad_to_deg(&frame_vector(&self.0))
    }

    /// Its pose in the base frame.
    pub fn pose(&self) -> &Frame {
        &self.0
    }

    /// The tracker's origin in the base frame (mm).
    pub fn origin(&self) -> Vector3<f64> {
        self.0.translation.vector
    }

    /// A point measured in the tracker frame, in the base frame: `pose * m`.
    pub fn to_base(&self, m: &Vector3<f64>) -> Vector3<f64> {
        (self.0 * Point3::from(*m)).coords
    }

    /// Points measured in the tracker frame, in the base frame ([`TrackerFrame::to_base`]).
    pub fn points_to_base(&self, measured: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
        measured.iter().map(|m| self.to_base(m)).collect()
    }

    /// A frame measured in the tracker frame (a 6-DoF measurement), in the base frame:
    /// `pose * f`.
    pub fn frame_to_base(&self, f: &Frame) -> Frame {
        self.0 * f
    }

    /// A point given in the base frame, as the tracker measures it: `pose^-1 * p` (the inverse of
    /// [`TrackerFrame::to_base`]).
    pub fn to_tracker(&self, p: &Vector3<f64>) -> Vector3<f64> {
        (self.0.inverse() * Point3::from(*p)).coords
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rotation vectors at, near and far from a half turn give their rotation back (an exact
    /// half turn used to come back as no rotation at all).
    #[test]
    fn rotation_vectors_round_trip_through_a_half_turn() {
        let axes = [
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, -0.9, 0.2),
            Vector3::new(-0.5, 0.1, -0.8),
        ];
        let pi = std::f64::consts::PI;
        for a in axes {
            let n = a.normalize();
            for theta in [pi, pi - 1e-12, pi - 1e-7, pi - 1e-3, 3.0, 2.0, 1e-4, 0.7] {
                let r = nalgebra::Rotation3::from_scaled_axis(n * theta);
                let v = rotation_vector(r.matrix());
                let back = nalgebra::Rotation3::from_scaled_axis(v);
                // The matrices' difference (about sqrt(2) times the angle between them, which
                // `angle_to` computes through an arc cosine, good to 1e-8 only).
                let d = (r.matrix() - back.matrix()).norm();
                assert!(d < 1e-12, "{n:?} {theta}: {v:?} is {d} off");
                assert!(v.norm() <= pi + 1e-12);
            }
        }
    }

    #[test]
    fn frame_vector_roundtrip() {
        let v = [1.0, -2.0, 3.0, 0.3, -0.7, 2.5];
        let w = frame_vector(&pose(&v));
        for k in 0..6 {
            assert!((v[k] - w[k]).abs() < 1e-12, "{k}: {} vs {}", v[k], w[k]);
        }
    }

    /// At the singularity B = ±90° the vector's A is 0 and its C takes the whole turn: the frame
    /// it gives back is the same (B = -90° used to come back with C of the wrong sign).
    #[test]
    fn frame_vector_roundtrip_at_the_singularity() {
        for b in [-90f64, 90.0] {
            for (a, c) in [(0.0f64, 90.0f64), (30.0, -20.0), (-120.0, 45.0)] {
                let v = [
                    1.0,
                    2.0,
                    3.0,
                    a.to_radians(),
                    b.to_radians(),
                    c.to_radians(),
                ];
                let f = pose(&v);
                let g = pose(&frame_vector(&f));
                let gap = (f.rotation.matrix() - g.rotation.matrix()).norm();
                assert!(gap < 1e-12, "B = {b}, A = {a}, C = {c}: {gap}");
            }
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

    #[test]
    fn tracker_frame_maps_points_and_frames_into_the_base_frame() {
        // A tracker 2 m in front of the robot, turned to face it: its x axis is the base's -x.
        let t = TrackerFrame::from_vector_deg(&[2000.0, 0.0, 500.0, 180.0, 0.0, 0.0]);
        let m = Vector3::new(100.0, 20.0, -30.0);
        let p = t.to_base(&m);
        assert!(
            (p - Vector3::new(1900.0, -20.0, 470.0)).norm() < 1e-9,
            "{p}"
        );
        assert!((t.to_tracker(&p) - m).norm() < 1e-9);
        assert_eq!(t.points_to_base(&[m, m]), vec![p, p]);
        assert_eq!(t.origin(), Vector3::new(2000.0, 0.0, 500.0));
        // A measured frame: its origin maps as a point, its axes turn with the tracker.
        let f = pose(&[100.0, 20.0, -30.0, 0.0, 0.0, 0.0]);
        let g = t.frame_to_base(&f);
        assert!((g.translation.vector - p).norm() < 1e-9);
        assert!((g.rotation.matrix() * Vector3::x() + Vector3::x()).norm() < 1e-12);
        // The frame vector round trip (degrees at the interface).
        let v = [10.0, -20.0, 30.0, 40.0, -50.0, 60.0];
        let w = TrackerFrame::from_vector_deg(&v).vector_deg();
        for k in 0..6 {
            assert!((v[k] - w[k]).abs() < 1e-9, "{k}: {v:?} vs {w:?}");
        }
        assert_eq!(TrackerFrame::identity().to_base(&m), m);
    }
}
