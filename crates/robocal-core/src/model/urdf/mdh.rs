//! A URDF chain as a modified-DH robot (Craig; DESIGN.md): the joint axes at q = 0 are lines in
//! the base link's frame, the MDH frames are built from their common normals, and what is left
//! goes into the base frame and the tool.
//!
//! Frame i (1..n) has z along joint i's URDF axis (same sense, so the joint values and limits are
//! the URDF's own), its origin where the common normal to axis i+1 meets axis i, and x along that
//! normal. Where two axes are parallel the normal's position along them is free: it is placed so
//! that d stays zero (where the previous normal meets the axis, or for the first joint at its
//! URDF origin). Where they intersect, x = z_i × z_(i+1). Frame 0 is frame 1 at q = 0 (so alpha1,
//! a1, d1 and phi1 are zero and the base frame carries them); frame n's x continues frame n-1's
//! normal. The base frame vector is frame 0 in the base link, the tool vector T0 the tip link in
//! frame n; each link's (alpha, a, phi, d) is read off `F(i-1)^-1 F(i)` at q = 0.

use super::chain::{Step, UrdfChain};
use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use crate::model::{Convention, JointLimit, JointType, Link, Robot};
use nalgebra::{Matrix3, Rotation3, Translation3, Vector3};

/// Below this sine of the angle between two axes they are taken as parallel.
pub const PARALLEL_SIN: f64 = 1e-9;
/// Below this distance (mm) two axes are taken as intersecting.
const INTERSECT_MM: f64 = 1e-9;
/// A common normal's foot this far (mm) from the axes' URDF origins means nearly parallel axes
/// that MDH cannot hold without huge, cancelling offsets.
const FAR_MM: f64 = 1e6;

/// One joint axis at q = 0 in the base link's frame.
struct Axis {
    name: String,
    point: Vector3<f64>,
    dir: Vector3<f64>,
    kind: JointType,
    limit: JointLimit,
}

/// Some unit vector perpendicular to `z`.
fn perpendicular(z: &Vector3<f64>) -> Vector3<f64> {
    let e = if z.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (e - z * z.dot(&e)).normalize()
}

/// `v` made perpendicular to the unit vector `z` and normalized, if it is not (almost) along it.
fn perpendicular_part(v: &Vector3<f64>, z: &Vector3<f64>) -> Option<Vector3<f64>> {
    let p = v - z * z.dot(v);
    let n = p.norm();
    (n > 1e-12).then(|| p / n)
}

fn frame_of(origin: Vector3<f64>, x: Vector3<f64>, z: Vector3<f64>) -> Frame {
    let y = z.cross(&x);
    Frame::from_parts(
        Translation3::from(origin),
        Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z])),
    )
}

/// The MDH robot of a URDF chain (see the module documentation). `err` builds the errors that
/// name the file.
pub(super) fn to_robot(chain: &UrdfChain, err: impl Fn(String) -> Error) -> Result<Robot> {
    // The axes at q = 0 and the tip.
    let mut axes = Vec::new();
    let mut f = Frame::identity();
    for s in &chain.steps {
        match s {
            Step::Fixed(t) => f *= t,
            Step::Motion {
                name,
                kind,
                axis,
                limit,
            } => axes.push(Axis {
                name: name.clone(),
                point: f.translation.vector,
                dir: (f.rotation * axis.into_inner()).normalize(),
                kind: *kind,
                limit: *limit,
            }),
        }
    }
    let tip = f;
    let n = axes.len();
    // Frames 1..n (index 0..n-1).
    let mut frames: Vec<Frame> = Vec::with_capacity(n);
    // Where the previous common normal meets this axis.
    let mut foot = axes[0].point;
    let mut prev_x: Option<Vector3<f64>> = None;
    for i in 0..n {
        let z = axes[i].dir;
        let (origin, x, next_foot) = if i + 1 == n {
            let x = prev_x
                .and_then(|x| perpendicular_part(&x, &z))
                .unwrap_or_else(|| perpendicular(&z));
            (foot, x, foot)
        } else {
            let (p2, z2) = (axes[i + 1].point, axes[i + 1].dir);
            let w = z.cross(&z2);
            let s = w.norm();
            if s < PARALLEL_SIN {
                // Parallel: the normal through this axis' foot.
                let to_next = p2 - foot;
                let across = to_next - z * z.dot(&to_next);
                let dist = across.norm();
                if dist < INTERSECT_MM {
                    // The same line: continue the previous normal's direction.
                    let x = prev_x
                        .and_then(|x| perpendicular_part(&x, &z))
                        .unwrap_or_else(|| perpendicular(&z));
                    (foot, x, foot)
                } else {
                    let x = across / dist;
                    (foot, x, foot + across)
                }
            } else {
                // Skew or intersecting: the closest points of the two lines.
                let r = p2 - axes[i].point;
                let b = z.dot(&z2);
                let (dr1, dr2) = (z.dot(&r), z2.dot(&r));
                let den = 1.0 - b * b;
                let t1 = (dr1 - b * dr2) / den;
                let t2 = (b * dr1 - dr2) / den;
                let c1 = axes[i].point + z * t1;
                let c2 = p2 + z2 * t2;
                if t1.abs() > FAR_MM || t2.abs() > FAR_MM {
                    return Err(err(format!(
                        "the axes of joints `{}` and `{}` are nearly parallel ({:.3e} deg): a \
                         modified DH table cannot hold them",
                        axes[i].name,
                        axes[i + 1].name,
                        s.asin().to_degrees()
                    )));
                }
                let wn = w / s;
                let d = c2 - c1;
                let x = if d.norm() < INTERSECT_MM || d.dot(&wn) >= 0.0 {
                    wn
                } else {
                    -wn
                };
                (c1, x, c2)
            }
        };
        frames.push(frame_of(origin, x, z));
        foot = next_foot;
        prev_x = Some(x);
    }
    let mut links = Vec::with_capacity(n);
    let mut prev = frames[0];
    for fr in &frames {
        links.push(mdh_link(&(prev.inverse() * fr)));
        prev = *fr;
    }
    let base = frame::frame_vector(&frames[0]);
    let tool = frame::frame_vector(&(frames[n - 1].inverse() * tip));
    let limits = axes.iter().map(|a| a.limit).collect();
    let mut robot = Robot::new(
        chain.name.clone(),
        Convention::Mdh,
        links,
        limits,
        base,
        tool,
    )
    .map_err(|e| err(e.to_string()))?;
    robot
        .set_joint_types(axes.iter().map(|a| a.kind).collect())
        .map_err(|e| err(e.to_string()))?;
    Ok(robot)
}

/// The MDH parameters of a transform `Rx(alpha) Tx(a) Rz(phi) Tz(d)` (frame i in frame i-1).
fn mdh_link(t: &Frame) -> Link {
    let r = t.rotation.matrix();
    let p = t.translation.vector;
    let z = r.column(2);
    let alpha = (-z[1]).atan2(z[2]);
    let (sa, ca) = alpha.sin_cos();
    // x_i turned back by Rx(-alpha) is (cos phi, sin phi, 0).
    let x = r.column(0);
    let phi = (ca * x[1] + sa * x[2]).atan2(x[0]);
    Link {
        alpha,
        a: p.x,
        d: -sa * p.y + ca * p.z,
        phi,
        beta: 0.0,
    }
}
