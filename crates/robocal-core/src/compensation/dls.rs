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

use super::stop::{stop_point, StopPoint};
use super::{IkReport, IkSolver, IkStatus};
use crate::error::Result;
use crate::model::{JointType, Robot, MAX_JOINTS};
use nalgebra::{Matrix3, Vector3};

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

/// Largest relative damping before a solve is declared stalled.
const MAX_DAMPING: f64 = 1e8;
/// Smallest relative damping (keeps `J J^T + lambda^2 I` positive definite).
const MIN_DAMPING: f64 = 1e-14;

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

/// Relative decrease of the residual over the second half of the iteration budget below which a
/// run that used up its budget counts as stopped at a stationary point (a plateau).
const PLATEAU: f64 = 1e-3;

/// Where one run of the iteration stopped.
#[derive(Clone, Copy)]
struct Run {
    residual: f64,
    iterations: usize,
    /// The joints at a limit whose descent direction points out of the range (bit mask).
    blocking: u32,
    /// The joints at a limit (bit mask).
    at_limit: u32,
    /// Whether the run stopped at a stationary point of the distance: no step with any damping
    /// reduced the error, or no free joint's tool motion has a direction cosine with the error
    /// above [`DampedLeastSquares::stationary_cosine`], or the residual reached a plateau.
    stationary: bool,
}

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
        let lim = robot.limits();
        // Joint i's change is measured in units of sc[i]: rad, or prismatic_scale_mm mm.
        let mut sc = [1.0; MAX_JOINTS];
        for (s, t) in sc.iter_mut().zip(robot.joint_types()) {
            if *t == JointType::Prismatic {
                *s = self.prismatic_scale_mm;
            }
        }
        let mut jq = [Vector3::zeros(); MAX_JOINTS];
        let mut jt = [Vector3::zeros(); MAX_JOINTS];
        let mut qt = [0.0; MAX_JOINTS];
        let mut e = target - robot.tool_position_jacobians(q, Some(&mut jq[..n]), None);
        let mut r = e.norm();
        let mut mu = self.initial_damping;
        let mut iterations = 1;
        let mut stalled = false;
        let mut r_half = f64::INFINITY;
        loop {
            if r_half.is_infinite() && 2 * iterations >= self.max_iterations {
                r_half = r;
            }
            // Free joints: those not held at a limit by the descent direction g_i = j_i . e.
            let mut free = 0u32;
            for i in 0..n {
                let g = jq[i].dot(&e);
                let blocked =
                    limits && ((q[i] <= lim[i].min && g < 0.0) || (q[i] >= lim[i].max && g > 0.0));
                if !blocked {
                    free |= 1 << i;
                }
            }
            if r <= self.tolerance_mm || iterations >= self.max_iterations {
                break;
            }
            let mut a = Matrix3::zeros();
            for i in (0..n).filter(|i| free & (1 << i) != 0) {
                a += jq[i] * jq[i].transpose() * (sc[i] * sc[i]);
            }
            let scale = a.trace() / 3.0;
            if scale <= 0.0 || !scale.is_finite() {
                stalled = true;
                break;
            }
            // Levenberg–Marquardt: retry with more damping until the error decreases; the
            // damping follows the gain ratio (Nielsen's update).
            let mut accepted = false;
            let mut nu = 2.0;
            while mu <= MAX_DAMPING {
                let m = a + Matrix3::identity() * (mu * scale);
                let Some(ch) = m.cholesky() else {
                    mu *= nu;
                    nu *= 2.0;
                    continue;
                };
                let y = ch.solve(&e);
                // The step in scaled units u = S J^T y (S = diag(sc)); the joints move by S u.
                let mut largest = 0.0f64;
                for i in 0..n {
                    qt[i] = if free & (1 << i) != 0 {
                        sc[i] * jq[i].dot(&y)
                    } else {
                        0.0
                    };
                    largest = largest.max(qt[i].abs());
                }
                let shrink = if largest > self.max_step_rad {
                    self.max_step_rad / largest
                } else {
                    1.0
                };
                // Predicted error after the step actually taken (after shrinking and clamping).
                let mut predicted = e;
                for i in 0..n {
                    let mut v = q[i] + sc[i] * qt[i] * shrink;
                    if limits {
                        v = v.clamp(lim[i].min, lim[i].max);
                    }
                    predicted -= jq[i] * (v - q[i]);
                    qt[i] = v;
                }
                let pt = robot.tool_position_jacobians(&qt[..n], Some(&mut jt[..n]), None);
                iterations += 1;
                let et = target - pt;
                let rt = et.norm();
                if rt < r {
                    let gain = (r * r - rt * rt) / (r * r - predicted.norm_squared()).max(1e-300);
                    q.copy_from_slice(&qt[..n]);
                    std::mem::swap(&mut jq, &mut jt);
                    e = et;
                    r = rt;
                    mu = (mu * (1.0 / 3.0f64).max(1.0 - (2.0 * gain - 1.0).powi(3)))
                        .max(MIN_DAMPING);
                    accepted = true;
                    break;
                }
                mu *= nu;
                nu *= 2.0;
                if iterations >= self.max_iterations {
                    break;
                }
            }
            if !accepted {
                stalled = mu > MAX_DAMPING;
                break;
            }
        }
        // Classify the stopping point.
        let StopPoint {
            blocking,
            at_limit,
            max_cosine,
        } = stop_point(
            &jq[..n],
            &e,
            r,
            &q[..n],
            lim,
            limits,
            self.stationary_cosine,
        );
        let plateau = iterations >= self.max_iterations && r_half - r < PLATEAU * r_half;
        Run {
            residual: r,
            iterations,
            blocking,
            at_limit,
            stationary: stalled || plateau || max_cosine < self.stationary_cosine,
        }
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
            residual_mm: run.residual,
            residual_deg: 0.0,
            iterations: run.iterations,
            joints_at_limit: run.at_limit,
        };
        if run.residual <= self.tolerance_mm {
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
        if unc.residual <= self.tolerance_mm {
            report(IkStatus::JointLimit)
        } else if unc.stationary {
            report(IkStatus::Unreachable)
        } else {
            report(IkStatus::NotConverged)
        }
    }
}
