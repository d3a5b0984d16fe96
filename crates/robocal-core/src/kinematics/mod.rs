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

pub mod conditions;
pub mod poe;
pub use crate::trig;

pub use conditions::Conditions;

use crate::frame::Frame;
use crate::model::family::{self, PoseFrames, RigidPose};
use crate::model::{mul_rot_z, Convention, JointType, Robot, MAX_JOINTS};
use nalgebra::{Matrix3, Vector3};

/// Calls the `<MIXED, N>` instance of a forward pass for the chain of `q`: all-revolute chains
/// (the common case) run a loop without the per-joint type test, and six joints (the common
/// arm) take arrays of their own size, nothing of a sixteen-joint buffer to clear and copy per
/// pass; a chain with a prismatic joint takes the type test.
macro_rules! for_chain {
    ($robot:expr, $q:expr, $pass:ident($($arg:expr),*)) => {
        match ($robot.joint_space().any_prismatic(), $q.len()) {
            (false, 6) => $robot.$pass::<false, 6>($($arg),*),
            (false, _) => $robot.$pass::<false, MAX_JOINTS>($($arg),*),
            (true, _) => $robot.$pass::<true, MAX_JOINTS>($($arg),*),
        }
    };
}

impl Robot {
    /// The flange frame `pose(B) * T1(q1) * ... * Tn(qn)` (direct DH product).
    pub fn flange_pose(&self, q: &[f64]) -> Frame {
        let mut buf = [0.0; MAX_JOINTS];
        let q = self.deflected(q, &mut buf);
        for_chain!(self, q, flange_pose_with(q))
    }

    #[inline(always)]
    fn flange_pose_with<const MIXED: bool, const N: usize>(&self, q: &[f64]) -> Frame {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut f = *self.base_frame();
        let motion = self.joint_motions::<MIXED, N>(q);
        for i in 0..q.len() {
            let (s, co, d) = motion.of(i);
            match self.convention() {
                Convention::Mdh => {
                    self.apply_link_constant(i, &mut f);
                    rotate_z_translate(&mut f, s, co, d);
                }
                Convention::Dh => {
                    rotate_z_translate(&mut f, s, co, d);
                    self.apply_link_constant(i, &mut f);
                }
            }
        }
        f
    }

    /// The tool frame `flange * pose(T0 + T)` at joint values `q` (rad).
    pub fn tool_pose(&self, q: &[f64]) -> Frame {
        self.flange_pose(q) * self.tool_frame()
    }

    /// Target `t`'s tool frame `flange * pose(T0_t + T_t)` (0-based target; see
    /// [`Robot::target_count`]).
    pub fn target_pose(&self, q: &[f64], t: usize) -> Frame {
        self.flange_pose(q) * self.target_tool_frame(t)
    }

    /// Target `t`'s tool point (mm, ACS; 0-based target).
    pub fn target_position(&self, q: &[f64], t: usize) -> Vector3<f64> {
        self.target_point_on(&self.flange_pose(q), t)
    }

    /// Target `t`'s point (mm, ACS; 0-based) with the flange at `f`: the origin of
    /// `f * pose(T0_t + T_t)`.
    #[inline(always)]
    pub(crate) fn target_point_on(&self, f: &Frame, t: usize) -> Vector3<f64> {
        f.rotation * self.target_tool_frame(t).translation.vector + f.translation.vector
    }

    /// The tool point (mm, base frame = ACS) at joint values `q` (rad): the paper's P_nom (eq. 1)
    /// for the nominal model.
    pub fn tool_position(&self, q: &[f64]) -> Vector3<f64> {
        self.target_point_on(&self.flange_pose(q), 0)
    }

    /// The joint values forward kinematics evaluates: `q` itself, or `q + dq` when a family
    /// deflects the joints (see [`family::ParameterFamily::add_joint_deflection`]), written to
    /// `buf`.
    #[inline]
    pub fn deflected<'a>(&self, q: &'a [f64], buf: &'a mut [f64; MAX_JOINTS]) -> &'a [f64] {
        if !self.deflects_joints() {
            return q;
        }
        let rigid = self.rigid_for_families(q);
        self.deflect_with(&rigid, q, buf)
    }

    /// `q + dq` written to `buf`, the families' deflection computed on `rigid`, the pass at `q`
    /// without deflection.
    fn deflect_with<'a>(
        &self,
        rigid: &RigidPose,
        q: &[f64],
        buf: &'a mut [f64; MAX_JOINTS],
    ) -> &'a [f64] {
        let mut dq = [0.0; MAX_JOINTS];
        for fam in family::all() {
            if fam.deflects_joints(self) {
                fam.add_joint_deflection(self, rigid, &mut dq[..q.len()]);
            }
        }
        for (i, v) in q.iter().enumerate() {
            buf[i] = v + dq[i];
        }
        &buf[..q.len()]
    }

    /// The frames of one forward pass at joint values `q` (deflected, see
    /// [`Robot::deflected`]), with the tool point; when a family deflects the joints, `rigid`
    /// keeps the pass at `q` without deflection.
    pub fn pose_frames(&self, q: &[f64]) -> PoseFrames {
        self.pose_frames_target(q, 0)
    }

    /// [`Robot::pose_frames`] with the point of target `t` (0-based) as the tool point.
    pub fn pose_frames_target(&self, q: &[f64], t: usize) -> PoseFrames {
        let mut ch = PoseFrames::identity();
        self.pose_frames_target_into(q, t, &mut ch);
        ch
    }

    /// The frames of one forward pass at exactly the joint values `q`, without any family's
    /// deflection (`rigid` left empty), with the point of target `t` (0-based).
    pub fn rigid_pose_frames(&self, q: &[f64], t: usize) -> PoseFrames {
        let mut ch = PoseFrames::identity();
        self.rigid_pose_frames_into(q, t, &mut ch);
        ch
    }

    /// [`Robot::rigid_pose_frames`] written into `out` (a forward pass's frames reused from
    /// call to call instead of a new one made and copied: four kilobytes for three numbers'
    /// worth of work per joint). Only the first [`Robot::dof`] axis and link frames are
    /// written; of `rigid`, only its conditions (unknown): its other fields are read only by the
    /// families that deflect the joints, whose passes ([`Robot::pose_frames_target`]) fill them.
    #[inline]
    pub(crate) fn rigid_pose_frames_into(&self, q: &[f64], t: usize, out: &mut PoseFrames) {
        for_chain!(self, q, chain_into(q, out));
        out.point = self.target_point_on(&out.flange, t);
        out.target = t;
        out.rigid.conditions = crate::model::Conditions::UNKNOWN;
    }

    /// [`Robot::pose_frames_target`] written into `out` (see [`Robot::rigid_pose_frames_into`]).
    #[inline]
    pub(crate) fn pose_frames_target_into(&self, q: &[f64], t: usize, out: &mut PoseFrames) {
        if !self.deflects_joints() {
            return self.rigid_pose_frames_into(q, t, out);
        }
        let rigid = self.rigid_for_families(q);
        let mut buf = [0.0; MAX_JOINTS];
        self.rigid_pose_frames_into(self.deflect_with(&rigid, q, &mut buf), t, out);
        out.rigid = rigid;
    }

    /// What the families' deflections read at the commanded joints `q`: the rigid forward pass
    /// ([`Robot::rigid_pose`]) when one of them reads its axes (compliance), else the commanded
    /// joints alone (transmission errors and backlash need no forward pass).
    pub(crate) fn rigid_for_families(&self, q: &[f64]) -> RigidPose {
        let axes = family::all()
            .iter()
            .any(|f| f.deflects_joints(self) && f.deflection_reads_axes(self));
        if axes {
            return self.rigid_pose(q);
        }
        let mut out = RigidPose::default();
        out.commanded[..q.len()].copy_from_slice(q);
        out
    }

    /// The joint axes and the tool point at exactly the joint values `q`, without deflection: a
    /// lean forward pass for the families that deflect the joints.
    pub fn rigid_pose(&self, q: &[f64]) -> RigidPose {
        for_chain!(self, q, rigid_pose_with(q))
    }

    #[inline(always)]
    fn rigid_pose_with<const MIXED: bool, const N: usize>(&self, q: &[f64]) -> RigidPose {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut out = RigidPose::default();
        out.commanded[..q.len()].copy_from_slice(q);
        let motion = self.joint_motions::<MIXED, N>(q);
        let mut f = *self.base_frame();
        for i in 0..q.len() {
            let (s, co, d) = motion.of(i);
            if self.convention() == Convention::Mdh {
                self.apply_link_constant(i, &mut f);
            }
            out.axes[i] = (f.rotation.matrix().column(2).into(), f.translation.vector);
            rotate_z_translate(&mut f, s, co, d);
            if self.convention() == Convention::Dh {
                self.apply_link_constant(i, &mut f);
            }
        }
        out.point = self.target_point_on(&f, 0);
        out
    }

    #[inline(always)]
    fn chain_into<const MIXED: bool, const N: usize>(&self, q: &[f64], ch: &mut PoseFrames) {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut f = *self.base_frame();
        let motion = self.joint_motions::<MIXED, N>(q);
        for i in 0..q.len() {
            let (s, co, d) = motion.of(i);
            match self.convention() {
                Convention::Mdh => {
                    ch.link[i] = f;
                    self.apply_link_constant(i, &mut f);
                    ch.axis[i] = f;
                    rotate_z_translate(&mut f, s, co, d);
                }
                Convention::Dh => {
                    ch.axis[i] = f;
                    rotate_z_translate(&mut f, s, co, d);
                    ch.link[i] = f;
                    self.apply_link_constant(i, &mut f);
                }
            }
        }
        ch.flange = f;
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
    #[inline]
    pub fn tool_position_jacobians(
        &self,
        q: &[f64],
        jq: Option<&mut [Vector3<f64>]>,
        jp: Option<&mut [Vector3<f64>]>,
    ) -> Vector3<f64> {
        self.tool_screw_jacobians(q, jq, jp, None)
    }

    /// [`Robot::tool_position_jacobians`] with, in `jw`, each parameter's angular column: the
    /// tool frame's angular velocity (rad per internal unit, ACS) under a unit change of the
    /// parameter. `(jp[k], jw[k])` is parameter k's screw at the tool; every parameter family
    /// contributes its own (see [`family`]). Joint columns are taken at the deflected joint values
    /// and treat the deflection as independent of `q`.
    pub fn tool_screw_jacobians(
        &self,
        q: &[f64],
        jq: Option<&mut [Vector3<f64>]>,
        jp: Option<&mut [Vector3<f64>]>,
        jw: Option<&mut [Vector3<f64>]>,
    ) -> Vector3<f64> {
        self.target_screws(q, 0, jq, jp, jw).0
    }

    /// [`Robot::tool_screw_jacobians`] for target `t` (0-based, see [`Robot::target_count`]):
    /// the target's point and the flange frame, with the screws at that point. Parameters of
    /// another target's tool have zero columns.
    pub fn target_screws(
        &self,
        q: &[f64],
        t: usize,
        jq: Option<&mut [Vector3<f64>]>,
        jp: Option<&mut [Vector3<f64>]>,
        jw: Option<&mut [Vector3<f64>]>,
    ) -> (Vector3<f64>, Frame) {
        with_scratch_frames(|pose| {
            self.pose_frames_target_into(q, t, pose);
            self.screws_at(pose, jq, jp, jw)
        })
    }

    /// `pose`'s frames seen through target `t` (0-based): the same forward pass (deflection
    /// included: it does not depend on the target), the point of target `t`. Several
    /// reflectors measured at one pose share one pass this way.
    pub(crate) fn retarget(&self, pose: &mut PoseFrames, t: usize) {
        pose.point = self.target_point_on(&pose.flange, t);
        pose.target = t;
    }

    /// [`Robot::target_screws`] from a forward pass already made ([`Robot::pose_frames_target`]).
    pub(crate) fn screws_at(
        &self,
        pose: &PoseFrames,
        jq: Option<&mut [Vector3<f64>]>,
        jp: Option<&mut [Vector3<f64>]>,
        mut jw: Option<&mut [Vector3<f64>]>,
    ) -> (Vector3<f64>, Frame) {
        let n = self.dof();
        let p = pose.point;
        if let Some(jq) = jq {
            assert_eq!(jq.len(), n, "joint Jacobian length");
            for (j, f) in jq.iter_mut().zip(&pose.axis[..n]) {
                let z: Vector3<f64> = f.rotation.matrix().column(2).into();
                *j = z.cross(&(p - f.translation.vector));
            }
            if self.joint_space().any_prismatic() {
                for ((j, f), t) in jq.iter_mut().zip(&pose.axis[..n]).zip(self.joint_types()) {
                    if *t == JointType::Prismatic {
                        *j = f.rotation.matrix().column(2).into();
                    }
                }
            }
        }
        let Some(jp) = jp else {
            return (p, pose.flange);
        };
        assert_eq!(jp.len(), self.param_count(), "parameter Jacobian length");
        if let Some(jw) = jw.as_deref() {
            assert_eq!(jw.len(), jp.len(), "angular Jacobian length");
        }
        for (id, span) in self.family_spans() {
            family::get(*id).columns(
                self,
                pose,
                &mut jp[span.clone()],
                jw.as_deref_mut().map(|w| &mut w[span.clone()]),
            );
        }
        (p, pose.flange)
    }

    /// Each joint's axis in the ACS at joint values `q` (rad or mm): its unit direction and the
    /// origin of its axis frame (a point on the axis; for a prismatic joint, where its motion
    /// starts: the frame before the joint's translation).
    pub fn joint_axes(&self, q: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let ch = self.pose_frames(q);
        ch.axis[..self.dof()]
            .iter()
            .map(|f| (f.rotation.matrix().column(2).into(), f.translation.vector))
            .collect()
    }

    /// Joint `i`'s axis (0-based) at joint values `q`: as one entry of [`Robot::joint_axes`],
    /// without allocating.
    pub(crate) fn joint_axis(&self, q: &[f64], i: usize) -> (Vector3<f64>, Vector3<f64>) {
        let f = &self.pose_frames(q).axis[i];
        (f.rotation.matrix().column(2).into(), f.translation.vector)
    }
}

thread_local! {
    /// Each thread's forward pass reused by [`with_scratch_frames`]: held in the thread's own
    /// storage, not on the heap (the compensation loop allocates nothing, even on a thread's
    /// first pass).
    static SCRATCH_FRAMES: std::cell::RefCell<PoseFrames> =
        std::cell::RefCell::new(PoseFrames::identity());
}

/// Runs `f` on this thread's reusable [`PoseFrames`] (a fresh one when it is in use higher up
/// the stack): the Jacobian passes make one forward pass per observation, and a pass made in
/// place costs a fraction of one made, returned and copied.
#[inline]
pub(crate) fn with_scratch_frames<R>(f: impl FnOnce(&mut PoseFrames) -> R) -> R {
    let mut f = Some(f);
    let out = SCRATCH_FRAMES.try_with(|cell| {
        let mut frames = cell.try_borrow_mut().ok()?;
        Some((f.take().expect("run once"))(&mut frames))
    });
    match out {
        Ok(Some(r)) => r,
        _ => (f.take().expect("not run"))(&mut PoseFrames::identity()),
    }
}

/// Every joint's rotation (sin, cos) and translation along its axis at the joint values of one
/// pass: `Rz(q + phi) Tz(d)` for a revolute joint, `Rz(phi) Tz(d + q)` for a prismatic one.
struct JointMotions<const N: usize> {
    sin: [f64; N],
    cos: [f64; N],
    d: [f64; N],
}

impl<const N: usize> JointMotions<N> {
    /// Joint `i`'s `(sin, cos, d)`.
    #[inline(always)]
    fn of(&self, i: usize) -> (f64, f64, f64) {
        (self.sin[i], self.cos[i], self.d[i])
    }
}

impl Robot {
    /// The [`JointMotions`] at `q` (at most `N` joints): every angle first, then their sines and
    /// cosines in one loop ([`trig::sin_cos_all`]) whose iterations do not wait on each other,
    /// nor on the frames the pass then chains. Without `MIXED` every joint is revolute (the
    /// caller knows).
    #[inline(always)]
    fn joint_motions<const MIXED: bool, const N: usize>(&self, q: &[f64]) -> JointMotions<N> {
        let n = q.len();
        assert!(n <= N, "at most N joints");
        let types = self.joint_types();
        let mut angle = [0.0; N];
        let mut m = JointMotions {
            sin: [0.0; N],
            cos: [0.0; N],
            d: [0.0; N],
        };
        for (i, (l, &qi)) in self.links().iter().zip(q).enumerate() {
            let prismatic = MIXED && types[i] == JointType::Prismatic;
            angle[i] = if prismatic { l.phi } else { qi + l.phi };
            m.d[i] = if prismatic { l.d + qi } else { l.d };
        }
        trig::sin_cos_all(&angle[..n], &mut m.sin[..n], &mut m.cos[..n]);
        m
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
