//! Full-pose inverse kinematics: joint values that put a tool frame at a target frame, position
//! *and* orientation (the paper's eq. 14 with the whole pose as the target).
//!
//! The residual of a pose is six numbers: the position error `e_p = p_target - p` (mm, base
//! frame) and the orientation error as a rotation vector `e_w = log(R_target R^T)` (rad, base
//! frame): never differences of A, B, C angles, which are unstable near B = ±90 degrees
//! (DESIGN.md). The Jacobian is the 6 x n spatial Jacobian at the tool point: column `i` is
//! `[z_i x (p - o_i); z_i]` for a revolute joint (`z_i` the axis, `o_i` a point on it) and
//! `[z_i; 0]` for a prismatic one. Position rows are divided by
//! [`PoseNewton::length_scale_mm`] so that a millimetre and a milliradian weigh comparably.
//!
//! Each step is the damped minimum-norm step `dq = J^T (J J^T + lambda I)^-1 e` (Levenberg–
//! Marquardt, the damping adapted by the gain ratio and driven to 1e-14 of the mean eigenvalue
//! after good steps):
//! - **6 joints**: the system is square and the step tends to the Newton step `J^-1 e`, which
//!   converges quadratically from the desired joints (a compensation moves the joints by
//!   milliradians): 2 to 4 iterations;
//! - **more than 6 joints** (a 6R arm on a track, a 7-joint arm): the minimum-norm step keeps the
//!   joints as close to the start as the pose allows (the redundancy is spent on staying near
//!   the desired joints), and still converges quadratically away from singularities;
//! - **fewer than 6 joints**: a general pose is out of reach (6 equations, fewer unknowns); the
//!   iteration ends at the least-squares pose of the weighted residual and reports
//!   [`IkStatus::Unreachable`] unless the pose happens to be reachable. Use position-only
//!   compensation ([`super::DampedLeastSquares`]) for such robots.
//!
//! Joint limits, the trust region and the classification of a stop ([`IkStatus::JointLimit`],
//! [`IkStatus::Unreachable`], [`IkStatus::NotConverged`]) work as in the position solver; the
//! configuration statuses are added by the caller, which knows the desired branch
//! (see [`super::configuration`]).
//!
//! Allocation-free: everything lives on the stack (`Matrix6`, `Vector6`, arrays of
//! [`MAX_JOINTS`]).

use super::damped::{self, Iteration};
use super::{IkReport, IkStatus};
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::{JointType, Robot, MAX_JOINTS};
use nalgebra::{Vector3, Vector6};

/// Damped Newton inverse kinematics for the whole tool pose (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseNewton {
    /// Position tolerance (mm). Default 1e-6.
    pub tolerance_mm: f64,
    /// Orientation tolerance (deg): the angle of `R_target R^T`. Default 1e-6.
    pub tolerance_deg: f64,
    /// Most Jacobian evaluations per solve. Default 200.
    pub max_iterations: usize,
    /// Largest change of any joint in one step (rad; times
    /// [`PoseNewton::prismatic_scale_mm`] for a prismatic joint). Default 0.25.
    pub max_step_rad: f64,
    /// How many mm of a prismatic joint weigh as much as one radian of a revolute joint in the
    /// step norm. Default 1000.
    pub prismatic_scale_mm: f64,
    /// How many mm of position error weigh as much as one radian of orientation error. Default
    /// 1000 (a metre-sized arm: a milliradian turns the tool point by about a millimetre).
    pub length_scale_mm: f64,
    /// Initial damping, relative to the mean eigenvalue of `J J^T`. Default 1e-9.
    pub initial_damping: f64,
    /// A stop counts as a stationary point of the residual when no free joint's motion has a
    /// direction cosine with the (scaled) residual larger than this. Default 1e-3.
    pub stationary_cosine: f64,
    /// The neighbourhood of a singularity: a configuration margin
    /// ([`super::configuration::Configuration::margin`]) below this gives
    /// [`IkStatus::Singular`]. Default 0.01 (about 0.6 degrees from a wrist or elbow
    /// singularity, 1% of the reach from the shoulder singularity).
    pub singular_margin: f64,
}

impl Default for PoseNewton {
    fn default() -> Self {
        PoseNewton {
            tolerance_mm: 1e-6,
            tolerance_deg: 1e-6,
            max_iterations: 200,
            max_step_rad: 0.25,
            prismatic_scale_mm: 1000.0,
            length_scale_mm: 1000.0,
            initial_damping: 1e-9,
            stationary_cosine: 1e-3,
            singular_margin: 0.01,
        }
    }
}

/// Where one run stopped: the position (mm) and orientation (rad) residuals.
type Run = damped::Run<(f64, f64)>;

impl PoseNewton {
    /// The defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// Checks the settings: positive finite tolerances, step, scales and damping, at least one
    /// iteration, a stationary cosine in (0, 1), a non-negative singular margin.
    pub fn validate(&self) -> Result<()> {
        super::checks::positive("tolerance_mm", self.tolerance_mm)?;
        super::checks::positive("tolerance_deg", self.tolerance_deg)?;
        super::checks::positive("max_step_rad", self.max_step_rad)?;
        super::checks::positive("prismatic_scale_mm", self.prismatic_scale_mm)?;
        super::checks::positive("length_scale_mm", self.length_scale_mm)?;
        super::checks::positive("initial_damping", self.initial_damping)?;
        super::checks::iterations_and_stationary(self.max_iterations, self.stationary_cosine)?;
        if !(self.singular_margin.is_finite() && self.singular_margin >= 0.0) {
            return Err(Error::invalid(
                "singular_margin",
                format!("{} must be a non-negative number", self.singular_margin),
            ));
        }
        Ok(())
    }

    /// Joint values (rad, mm for a prismatic joint) that put `robot`'s target `t` frame (0-based;
    /// 0 is the tool, [`Robot::target_pose`]) at `target` (base frame), starting from `start`
    /// (moved into the limits first). Writes them to `q` and reports how the solve ended with
    /// one of [`IkStatus::Converged`], [`IkStatus::JointLimit`], [`IkStatus::Unreachable`],
    /// [`IkStatus::NotConverged`]; the residuals are the position error (mm) and the angle of the
    /// orientation error (deg).
    ///
    /// Panics if `start` or `q` do not have `robot.dof()` entries or `t` is not a target of the
    /// robot (programming errors).
    pub fn solve(
        &self,
        robot: &Robot,
        target: &Frame,
        t: usize,
        start: &[f64],
        q: &mut [f64],
    ) -> IkReport {
        let n = robot.dof();
        assert_eq!(start.len(), n, "start joint vector length");
        assert_eq!(q.len(), n, "output joint vector length");
        assert!(t < robot.target_count(), "target index");
        for (i, l) in robot.limits().iter().enumerate() {
            q[i] = start[i].clamp(l.min, l.max);
        }
        let run = self.run(robot, target, t, q, true);
        let report = |status| IkReport {
            status,
            residual_mm: run.at.0,
            residual_deg: run.at.1.to_degrees(),
            iterations: run.iterations,
            joints_at_limit: run.at_limit,
        };
        if self.within_tolerance(run.at.0, run.at.1) {
            return report(IkStatus::Converged);
        }
        let unc = if run.blocking != 0 {
            let mut free = [0.0; MAX_JOINTS];
            free[..n].copy_from_slice(q);
            self.run(robot, target, t, &mut free[..n], false)
        } else {
            run
        };
        if self.within_tolerance(unc.at.0, unc.at.1) {
            report(IkStatus::JointLimit)
        } else if unc.stationary {
            report(IkStatus::Unreachable)
        } else {
            report(IkStatus::NotConverged)
        }
    }

    fn within_tolerance(&self, mm: f64, rad: f64) -> bool {
        mm <= self.tolerance_mm && rad.to_degrees() <= self.tolerance_deg
    }

    /// The residual at `q` (position rows in units of the length scale) with its position (mm)
    /// and orientation (rad) norms, and the scaled Jacobian columns (one per joint, per scaled
    /// joint unit) into `cols`.
    fn eval(
        &self,
        robot: &Robot,
        target: &Frame,
        t: usize,
        q: &[f64],
        sc: &[f64; MAX_JOINTS],
        cols: &mut [Vector6<f64>; MAX_JOINTS],
    ) -> (Vector6<f64>, (f64, f64)) {
        let n = robot.dof();
        let frames = robot.pose_frames_target(q, t);
        let tool = frames.flange * robot.target_tool_frame(t);
        let p = tool.translation.vector;
        let ep = target.translation.vector - p;
        let ew = crate::frame::rotation_vector(
            &(target.rotation.matrix() * tool.rotation.matrix().transpose()),
        );
        let l = self.length_scale_mm;
        let types = robot.joint_types();
        for i in 0..n {
            let f = &frames.axis[i];
            let z: Vector3<f64> = f.rotation.matrix().column(2).into();
            let (v, w) = if types[i] == JointType::Prismatic {
                (z, Vector3::zeros())
            } else {
                (z.cross(&(p - f.translation.vector)), z)
            };
            let s = sc[i];
            cols[i] = Vector6::new(
                v.x * s / l,
                v.y * s / l,
                v.z * s / l,
                w.x * s,
                w.y * s,
                w.z * s,
            );
        }
        let e = Vector6::new(ep.x / l, ep.y / l, ep.z / l, ew.x, ew.y, ew.z);
        (e, (ep.norm(), ew.norm()))
    }

    /// The iteration on `q` (in place); with `limits`, joints stay within the robot's limits.
    fn run(&self, robot: &Robot, target: &Frame, t: usize, q: &mut [f64], limits: bool) -> Run {
        let mut sc = [1.0; MAX_JOINTS];
        for (s, ty) in sc.iter_mut().zip(robot.joint_types()) {
            if *ty == JointType::Prismatic {
                *s = self.prismatic_scale_mm;
            }
        }
        let iteration = Iteration {
            max_iterations: self.max_iterations,
            max_step: self.max_step_rad,
            initial_damping: self.initial_damping,
            stationary_cosine: self.stationary_cosine,
        };
        damped::run(
            robot.dof(),
            robot.limits(),
            &sc,
            q,
            limits,
            &iteration,
            |q, cols| self.eval(robot, target, t, q, &sc, cols),
            |&(mm, rad)| self.within_tolerance(mm, rad),
        )
    }
}
