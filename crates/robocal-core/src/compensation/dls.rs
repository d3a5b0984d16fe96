//! Damped least squares (Levenberg–Marquardt) inverse kinematics for the tool position.
//!
//! Position-only IK of a 6R arm is redundant: 3 equations, 6 unknowns. Each step is the
//! *minimum-norm* damped step `dq = J^T (J J^T + lambda^2 I)^-1 e` (J the analytic 3 x n joint
//! Jacobian, e the position error), so the iteration stays close to its start: in compensation the
//! start is the desired joint vector (eq. 12), and the commanded joints (eq. 14) differ from it by
//! about the smallest joint motion that moves the tool by the model difference, which also keeps the
//! tool orientation close to the desired one. The norm is the Euclidean norm of the joint changes
//! in radians, with a prismatic joint's change (mm) divided by
//! [`DampedLeastSquares::prismatic_scale_mm`]: one radian of a revolute joint weighs as much as
//! that many millimetres of a prismatic one (by default 1000 mm, the size of an industrial arm,
//! so that a radian and a metre move the tool by comparable amounts). The same scaling applies
//! to the trust region ([`DampedLeastSquares::max_step_rad`]) and the damping.
//!
//! Joint limits: an active set. A joint at a limit whose descent direction points out of the range
//! is removed from the step (the others take over the motion, redundancy permitting); every step is
//! projected back into the limits. The damping adapts as in Levenberg–Marquardt: divided by 10
//! after a step that reduced the error, multiplied by 10 and the step retried otherwise.
//!
//! When a solve stops short of the tolerance, it is classified (see [`IkStatus`]). If a joint held
//! at a limit blocks the way, the solve continues from there without limits. Then: the target
//! reached without limits gives [`IkStatus::JointLimit`]; a stop at a stationary point of the
//! distance (no damped step reduces the error, no free joint moves the tool towards the target, or
//! the residual has stopped decreasing over the second half of the iteration budget) gives
//! [`IkStatus::Unreachable`]; a run still making progress when the budget ran out gives
//! [`IkStatus::NotConverged`].

use super::damped::{self, Iteration};
use super::{IkReport, IkSolver, IkStatus};
use crate::error::Result;
use crate::model::{JointType, Robot, MAX_JOINTS};
use nalgebra::Vector3;

/// Damped least-squares / Levenberg–Marquardt position IK (see the module documentation).
///
/// The fields are public tolerances and limits; [`DampedLeastSquares::validate`] checks them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedLeastSquares {
    /// A solve has converged when the tool point is this close to the target (mm). Default 1e-6.
    pub tolerance_mm: f64,
    /// Most Jacobian evaluations per solve. Default 500 (a few near the workspace boundary need a
    /// few hundred; most poses take 3 to 5).
    pub max_iterations: usize,
    /// Largest change of any joint in one step (rad): a trust region. Default 0.25. For a
    /// prismatic joint the bound is this times [`DampedLeastSquares::prismatic_scale_mm`] (mm).
    pub max_step_rad: f64,
    /// How many mm of a prismatic joint's motion weigh as much as one radian of a revolute
    /// joint's in the step norm, the trust region and the damping. Default 1000.
    pub prismatic_scale_mm: f64,
    /// Initial damping, relative to the mean eigenvalue of `J J^T`. Default 1e-3.
    pub initial_damping: f64,
    /// A stop counts as a stationary point of the distance (target unreachable from there) when no
    /// free joint's motion has a direction cosine with the error larger than this. Default 1e-3.
    pub stationary_cosine: f64,
}

impl Default for DampedLeastSquares {
    fn default() -> Self {
        DampedLeastSquares {
            tolerance_mm: 1e-6,
            max_iterations: 500,
            max_step_rad: 0.25,
            prismatic_scale_mm: 1000.0,
            initial_damping: 1e-3,
            stationary_cosine: 1e-3,
        }
    }
}

/// Where one run stopped: the residual (mm).
type Run = damped::Run<f64>;

impl DampedLeastSquares {
    /// The defaults (tolerance 1e-6 mm, 500 iterations).
    pub fn new() -> Self {
        Self::default()
    }

    /// Checks the settings: positive finite tolerance, step and damping, at least one iteration,
    /// a stationary cosine in (0, 1).
    pub fn validate(&self) -> Result<()> {
        super::checks::positive("tolerance_mm", self.tolerance_mm)?;
        super::checks::positive("max_step_rad", self.max_step_rad)?;
        super::checks::positive("prismatic_scale_mm", self.prismatic_scale_mm)?;
        super::checks::positive("initial_damping", self.initial_damping)?;
        super::checks::iterations_and_stationary(self.max_iterations, self.stationary_cosine)?;
        Ok(())
    }

    /// The iteration on `q[..n]` (in place). With `limits`, joints stay within the robot's limits.
    fn run(&self, robot: &Robot, target: &Vector3<f64>, q: &mut [f64], limits: bool) -> Run {
        let n = robot.dof();
        // Joint i's change is measured in units of sc[i]: rad, or prismatic_scale_mm mm.
        let mut sc = [1.0; MAX_JOINTS];
        for (s, t) in sc.iter_mut().zip(robot.joint_types()) {
            if *t == JointType::Prismatic {
                *s = self.prismatic_scale_mm;
            }
        }
        let iteration = Iteration {
            max_iterations: self.max_iterations,
            max_step: self.max_step_rad,
            initial_damping: self.initial_damping,
            stationary_cosine: self.stationary_cosine,
        };
        // The residual (mm) and the columns per scaled joint unit, c_i = sc_i j_i.
        let eval = |q: &[f64], cols: &mut [Vector3<f64>; MAX_JOINTS]| {
            let e = target - robot.tool_position_jacobians(q, Some(&mut cols[..n]), None);
            for (c, s) in cols[..n].iter_mut().zip(&sc) {
                *c *= *s;
            }
            (e, e.norm())
        };
        damped::run(n, robot.limits(), &sc, q, limits, &iteration, eval, |&r| {
            r <= self.tolerance_mm
        })
    }
}

impl IkSolver for DampedLeastSquares {
    fn solve(
        &self,
        robot: &Robot,
        target: &Vector3<f64>,
        start: &[f64],
        q: &mut [f64],
    ) -> IkReport {
        let n = robot.dof();
        assert_eq!(start.len(), n, "start joint vector length");
        assert_eq!(q.len(), n, "output joint vector length");
        for (i, l) in robot.limits().iter().enumerate() {
            q[i] = start[i].clamp(l.min, l.max);
        }
        let run = self.run(robot, target, q, true);
        let report = |status| IkReport {
            status,
            residual_mm: run.at,
            residual_deg: 0.0,
            iterations: run.iterations,
            joints_at_limit: run.at_limit,
        };
        if run.at <= self.tolerance_mm {
            return report(IkStatus::Converged);
        }
        // Where would the solve end without the limits? Continue from here, unconstrained.
        let unc = if run.blocking != 0 {
            let mut free = [0.0; MAX_JOINTS];
            free[..n].copy_from_slice(q);
            self.run(robot, target, &mut free[..n], false)
        } else {
            run
        };
        if unc.at <= self.tolerance_mm {
            report(IkStatus::JointLimit)
        } else if unc.stationary {
            report(IkStatus::Unreachable)
        } else {
            report(IkStatus::NotConverged)
        }
    }
}
