//! Forward kinematics and analytic Jacobians of the tool point.
//!
//! Two equivalent formulations: the direct product of link transforms ([`Robot::tool_pose`],
//! the reference), and the product of exponentials of eq. 6 ([`poe::Poe`]); a test holds them
//! equal to rounding. The identification Jacobian ([`Robot::tool_position_jacobians`]) gives
//! `d p_tool / d parameter` for every parameter of [`Robot::params`] and `d p_tool / d q` in one
//! pass, allocation-free: each parameter moves the tool point by a known screw (a translation
//! along, or a rotation about, an axis of one of the chain's frames), so every column is a cross
//! product with frames the forward pass computes anyway.
//!
//! Joint values are model values in internal units: **radians** for a revolute joint, mm for a
//! prismatic one (its value adds to the row's d, its phi is a constant); lengths in mm.

pub mod poe;

use crate::frame::{euler_axes, Frame};
use crate::model::{mul_rot_z, Convention, JointType, Link, Robot, MAX_JOINTS};
use nalgebra::{Matrix3, Vector3};

/// The frames of one forward pass: for each joint i, the frame whose z axis is joint i's axis
/// (origin on the axis) and the link frame the next joint builds on.
struct Chain {
    /// `axis[i]`: joint i's axis frame (MDH: `F_{i-1} Rx Tx Ry`; DH: `F_{i-1}`).
    axis: [Frame; MAX_JOINTS],
    /// `link[i]`: the frame from which link i's constant part is applied (MDH: `F_{i-1}`;
    /// DH: `F_{i-1} Rz Tz`).
    link: [Frame; MAX_JOINTS],
    /// The flange frame `F_n`.
    flange: Frame,
}

impl Robot {
    /// The flange frame `pose(B) * T1(q1) * ... * Tn(qn)` (direct DH product).
    pub fn flange_pose(&self, q: &[f64]) -> Frame {
        // All-revolute chains (the common case) run a loop without the per-joint type test.
        if self.joint_space().any_prismatic() {
            self.flange_pose_with::<true>(q)
        } else {
            self.flange_pose_with::<false>(q)
        }
    }

    #[inline(always)]
    fn flange_pose_with<const MIXED: bool>(&self, q: &[f64]) -> Frame {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut f = *self.base_frame();
        let types = self.joint_types();
        for (i, &qi) in q.iter().enumerate() {
            let l = &self.links()[i];
            let c = self.link_constant(i);
            let (s, co, d) = joint_motion::<MIXED>(types, i, l, qi);
            match self.convention() {
                Convention::Mdh => {
                    f *= c;
                    rotate_z_translate(&mut f, s, co, d);
                }
                Convention::Dh => {
                    rotate_z_translate(&mut f, s, co, d);
                    f *= c;
                }
            }
        }
        f
    }

    /// The tool frame `flange * pose(T0 + T)` at joint values `q` (rad).
    pub fn tool_pose(&self, q: &[f64]) -> Frame {
        self.flange_pose(q) * self.tool_frame()
    }

    /// The tool point (mm, base frame = ACS) at joint values `q` (rad): the paper's P_nom (eq. 1)
    /// for the nominal model.
    pub fn tool_position(&self, q: &[f64]) -> Vector3<f64> {
        let f = self.flange_pose(q);
        f.rotation * self.tool_frame().translation.vector + f.translation.vector
    }

    fn chain(&self, q: &[f64]) -> Chain {
        if self.joint_space().any_prismatic() {
            self.chain_with::<true>(q)
        } else {
            self.chain_with::<false>(q)
        }
    }

    #[inline(always)]
    fn chain_with<const MIXED: bool>(&self, q: &[f64]) -> Chain {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut ch = Chain {
            axis: [Frame::identity(); MAX_JOINTS],
            link: [Frame::identity(); MAX_JOINTS],
            flange: *self.base_frame(),
        };
        let mut f = *self.base_frame();
        let types = self.joint_types();
        for (i, &qi) in q.iter().enumerate() {
            let l = &self.links()[i];
            let c = self.link_constant(i);
            let (s, co, d) = joint_motion::<MIXED>(types, i, l, qi);
            match self.convention() {
                Convention::Mdh => {
                    ch.link[i] = f;
                    f *= c;
                    ch.axis[i] = f;
                    rotate_z_translate(&mut f, s, co, d);
                }
                Convention::Dh => {
                    ch.axis[i] = f;
                    rotate_z_translate(&mut f, s, co, d);
                    ch.link[i] = f;
                    f *= c;
                }
            }
        }
        ch.flange = f;
        ch
    }

    /// The tool point and, optionally, its Jacobians with respect to the joint values
    /// (`jq`, one column per joint: mm/rad for a revolute joint, the unit axis direction (mm/mm)
    /// for a prismatic one) and to every parameter of [`Robot::params`] in that order (`jp`, mm
    /// per internal unit: mm/mm or mm/rad). Allocation-free.
    ///
    /// For a prismatic row the parameter columns keep their meaning: d moves the tool along the
    /// joint axis (like the joint value), phi turns it about the axis (a constant rotation).
    ///
    /// Panics if `q`, `jq` or `jp` have the wrong length (programming errors: validate user joint
    /// vectors with [`Robot::check_joints`] first).
    pub fn tool_position_jacobians(
        &self,
        q: &[f64],
        jq: Option<&mut [Vector3<f64>]>,
        jp: Option<&mut [Vector3<f64>]>,
    ) -> Vector3<f64> {
        let n = self.dof();
        let ch = self.chain(q);
        let rn = ch.flange.rotation.matrix();
        let t = self.tool_frame().translation.vector;
        let p = rn * t + ch.flange.translation.vector;
        let col = |f: &Frame, k: usize| -> Vector3<f64> { f.rotation.matrix().column(k).into() };
        let org = |f: &Frame| -> Vector3<f64> { f.translation.vector };
        if let Some(jq) = jq {
            assert_eq!(jq.len(), n, "joint Jacobian length");
            for (j, f) in jq.iter_mut().zip(&ch.axis[..n]) {
                *j = col(f, 2).cross(&(p - org(f)));
            }
            if self.joint_space().any_prismatic() {
                for ((j, f), t) in jq.iter_mut().zip(&ch.axis[..n]).zip(self.joint_types()) {
                    if *t == JointType::Prismatic {
                        *j = col(f, 2);
                    }
                }
            }
        }
        let Some(jp) = jp else { return p };
        assert_eq!(jp.len(), self.param_count(), "parameter Jacobian length");
        let mut k = 0;
        // alpha_i: rotation about the x axis of the link frame the constant part starts from,
        // through its origin (MDH: Rx comes first) or that origin moved by a (DH: Tx(a) Rx).
        for i in 0..n {
            let f = &ch.link[i];
            let o = match self.convention() {
                Convention::Mdh => org(f),
                Convention::Dh => org(f) + col(f, 0) * self.links()[i].a,
            };
            jp[k] = col(f, 0).cross(&(p - o));
            k += 1;
        }
        // d_i: translation along the joint axis.
        for i in 0..n {
            jp[k] = col(&ch.axis[i], 2);
            k += 1;
        }
        // a_i: translation along the x axis of the link frame.
        for i in 0..n {
            jp[k] = col(&ch.link[i], 0);
            k += 1;
        }
        // phi_i: rotation about the joint axis (the joint value's column for a revolute joint).
        for i in 0..n {
            jp[k] = col(&ch.axis[i], 2).cross(&(p - org(&ch.axis[i])));
            k += 1;
        }
        // beta_i (enabled only): rotation about the y axis after Rx(alpha) Tx(a).
        for i in 0..n {
            if !self.beta_enabled(i) {
                continue;
            }
            let (y, o) = match self.convention() {
                // M_i = F_{i-1} Rx Tx Ry: its y axis is unchanged by Ry; its origin is the pivot.
                Convention::Mdh => (col(&ch.axis[i], 1), org(&ch.axis[i])),
                // F_i = N Tx Rx Ry: y unchanged by Ry; origin of F_i is the pivot.
                // F_i = N Tx Rx Ry: y unchanged by Ry; origin of F_i is the pivot. F_i is the
                // axis frame of joint i+1, or the flange for the last joint.
                Convention::Dh => {
                    let fi = if i + 1 < n {
                        &ch.axis[i + 1]
                    } else {
                        &ch.flange
                    };
                    (col(fi, 1), org(fi))
                }
            };
            jp[k] = y.cross(&(p - o));
            k += 1;
        }
        // base: translations along the ACS axes, rotations about the Euler axes through b.
        let b = self.base();
        let bo = Vector3::new(b[0], b[1], b[2]);
        for e in 0..3 {
            let mut v = Vector3::zeros();
            v[e] = 1.0;
            jp[k] = v;
            k += 1;
        }
        for ax in euler_axes(b[3], b[4]) {
            jp[k] = ax.cross(&(p - bo));
            k += 1;
        }
        // tool: translations along the flange axes; orientation does not move the point.
        for e in 0..3 {
            jp[k] = rn.column(e).into();
            k += 1;
        }
        for _ in 0..3 {
            jp[k] = Vector3::zeros();
            k += 1;
        }
        debug_assert_eq!(k, jp.len());
        p
    }

    /// Each joint's axis in the ACS at joint values `q` (rad or mm): its unit direction and the
    /// origin of its axis frame (a point on the axis; for a prismatic joint, where its motion
    /// starts: the frame before the joint's translation).
    pub fn joint_axes(&self, q: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let ch = self.chain(q);
        ch.axis[..self.dof()]
            .iter()
            .map(|f| (f.rotation.matrix().column(2).into(), f.translation.vector))
            .collect()
    }

    /// Joint `i`'s axis (0-based) at joint values `q`: as one entry of [`Robot::joint_axes`],
    /// without allocating.
    pub(crate) fn joint_axis(&self, q: &[f64], i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let f = &self.chain(q).axis[i];
        (f.rotation.matrix().column(2).into(), f.translation.vector)
    }
}

/// Joint `i`'s rotation (sin, cos) and translation along its axis at joint value `qi`:
/// `Rz(qi + phi) Tz(d)` for a revolute joint, `Rz(phi) Tz(d + qi)` for a prismatic one. Without
/// `MIXED` every joint is revolute (the caller knows) and `types` is not read.
#[inline(always)]
fn joint_motion<const MIXED: bool>(
    types: &[JointType],
    i: usize,
    l: &Link,
    qi: f64,
) -> (f64, f64, f64) {
    if MIXED && types[i] == JointType::Prismatic {
        let (s, c) = l.phi.sin_cos();
        (s, c, l.d + qi)
    } else {
        let (s, c) = (qi + l.phi).sin_cos();
        (s, c, l.d)
    }
}

/// `f = f * Rz(theta) * Tz(d)` given `sin theta`, `cos theta`.
#[inline]
fn rotate_z_translate(f: &mut Frame, s: f64, c: f64, d: f64) {
    let m: Matrix3<f64> = mul_rot_z(f.rotation.matrix(), s, c);
    f.translation.vector += m.column(2) * d;
    f.rotation = nalgebra::Rotation3::from_matrix_unchecked(m);
}

#[cfg(test)]
mod tests;
