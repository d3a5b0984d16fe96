//! Compensation (paper, section V.A, eq. 12-14): commanded joint values that put the *calibrated*
//! model's tool where the controller's *nominal* model believes it to be.
//!
//! Two kinds of target: the tool **pose** (position and orientation; [`Compensator::compensate_pose`],
//! [`Compensator::reach_pose`], solved by [`PoseNewton`]), the default of `robocal compensate`,
//! and the tool **position** only (the paper's eq. 13-14 as written; [`Compensator::compensate`],
//! [`Compensator::reach`], solved by [`DampedLeastSquares`]). A full-pose compensation also keeps
//! the desired configuration (branch, see [`configuration`]) and says when it cannot
//! ([`IkStatus::ConfigurationChange`], [`IkStatus::Singular`]).
//!
//! For a desired joint vector `theta_des` (eq. 12) the target is its nominal tool position
//! `P_des = FK_nominal(theta_des)` (eq. 13); numerical inverse kinematics on the calibrated model,
//! started from `theta_des`, finds the commanded joints `theta_com` (eq. 14) with
//! `FK_calibrated(theta_com) = P_des`. Sent to the real robot (whose geometry the calibrated model
//! describes), `theta_com` puts the tool at `P_des`. Targets can also be given directly as points in
//! the base frame ([`Compensator::reach`]).
//!
//! The inverse kinematics sits behind the [`IkSolver`] trait; [`DampedLeastSquares`] is the
//! method provided. Every solve ends with an [`IkStatus`] and its residual: nothing is dropped or
//! hidden, a caller decides what to do with rows that did not converge.

mod checks;
pub mod commanded;
pub mod configuration;
mod damped;
mod dls;
mod pose;
mod stop;
mod targets;

pub use dls::DampedLeastSquares;
pub use pose::PoseNewton;

/// The angle (rad) of a rotation matrix, accurate to rounding near the identity (the norm of its
/// rotation vector; `acos` of the trace loses half the digits there).
pub fn rotation_angle(r: &nalgebra::Matrix3<f64>) -> f64 {
    crate::frame::rotation_vector(r).norm()
}
pub use targets::{parse_targets, read_targets, Target, TargetSet};

use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::{JointType, Robot, MAX_JOINTS};
use crate::progress::{Observer, Stage};
use nalgebra::{Rotation3, Vector3};

/// How an inverse-kinematics solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum IkStatus {
    /// The tool point is within the tolerance of the target, all joints within their limits.
    Converged,
    /// The target is reachable only with some joint outside its limits: stopped at a limit that
    /// blocks the way, and the same solve continued without limits reaches the target.
    JointLimit,
    /// The target lies outside the workspace: the solver stopped at the arm's nearest approach
    /// (a stationary point of the distance, even without joint limits). The residual is the
    /// distance from the closest point reached within the limits.
    Unreachable,
    /// Neither of the above: the iteration limit was reached while the error was still
    /// decreasing.
    NotConverged,
    /// Full pose only: the pose is reached within the tolerances, but on another configuration
    /// (branch: shoulder, elbow or wrist, see [`configuration`]) than the desired joints'. The
    /// nearest solution lies on another branch; the robot would flip to get there.
    ConfigurationChange,
    /// Full pose only: the pose is reached within the tolerances, but the desired or the
    /// commanded joints lie in the neighbourhood of a singularity
    /// ([`PoseNewton::singular_margin`]), where the configuration is undecided and small pose
    /// changes need large joint motions.
    Singular,
}

impl IkStatus {
    /// Every status, in the order used for summaries.
    pub const ALL: [IkStatus; 6] = [
        IkStatus::Converged,
        IkStatus::JointLimit,
        IkStatus::Unreachable,
        IkStatus::NotConverged,
        IkStatus::ConfigurationChange,
        IkStatus::Singular,
    ];

    /// The word written to files: `converged`, `joint_limit`, `unreachable`, `not_converged`,
    /// `configuration_change`, `singular`.
    pub fn as_str(self) -> &'static str {
        match self {
            IkStatus::Converged => "converged",
            IkStatus::JointLimit => "joint_limit",
            IkStatus::Unreachable => "unreachable",
            IkStatus::NotConverged => "not_converged",
            IkStatus::ConfigurationChange => "configuration_change",
            IkStatus::Singular => "singular",
        }
    }

    /// Parses [`IkStatus::as_str`].
    pub fn parse(s: &str) -> Option<IkStatus> {
        IkStatus::ALL.into_iter().find(|x| x.as_str() == s.trim())
    }

    /// Whether the solve succeeded: [`IkStatus::Converged`] only (a configuration change or a
    /// singular neighbourhood reaches the pose but is not a compensation to send unchecked).
    pub fn is_converged(self) -> bool {
        self == IkStatus::Converged
    }

    /// Whether the returned joints reach the target within the tolerances (converged, or on
    /// another configuration, or near a singularity).
    pub fn reaches_target(self) -> bool {
        matches!(
            self,
            IkStatus::Converged | IkStatus::ConfigurationChange | IkStatus::Singular
        )
    }
}

impl std::fmt::Display for IkStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The outcome of one inverse-kinematics solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkReport {
    /// How it ended.
    pub status: IkStatus,
    /// Distance (mm) between the tool point at the returned joints and the target.
    pub residual_mm: f64,
    /// Angle (deg) of the orientation error `R_target R^T` at the returned joints (full pose;
    /// 0 for a position-only solve).
    pub residual_deg: f64,
    /// Iterations used (Jacobian evaluations of the solve within the limits).
    pub iterations: usize,
    /// Bit `i` set: joint `i` (0-based) ends at one of its limits.
    pub joints_at_limit: u32,
}

impl IkReport {
    /// The joints (0-based) that end at a limit.
    pub fn limited_joints(&self) -> impl Iterator<Item = usize> + '_ {
        (0..MAX_JOINTS).filter(move |i| self.joints_at_limit & (1 << i) != 0)
    }
}

/// An inverse-kinematics method for the tool *position* (3 equations).
///
/// Implementations must keep the returned joints within the robot's limits and must not allocate
/// per solve, so that batches run at full speed.
pub trait IkSolver {
    /// Finds joint values (rad, or mm for a prismatic joint) that put `robot`'s tool point at
    /// `target` (mm, base frame), starting from `start` (same units; moved into the limits
    /// first). Writes them to `q`, which has
    /// `robot.dof()` entries, and reports how the solve ended.
    ///
    /// Panics if `start` or `q` do not have `robot.dof()` entries (a programming error: check
    /// joint vectors from users with [`Robot::check_joints`]).
    fn solve(&self, robot: &Robot, target: &Vector3<f64>, start: &[f64], q: &mut [f64])
        -> IkReport;
}

/// The result of compensating one pose or reaching one target.
#[derive(Debug, Clone, PartialEq)]
pub struct Compensation {
    /// The desired tool position `P_des` (mm, base frame): eq. 13, or the given target.
    pub desired_position: Vector3<f64>,
    /// The desired tool orientation (base frame) of a full-pose compensation; `None` for a
    /// position-only one.
    pub desired_orientation: Option<Rotation3<f64>>,
    /// The commanded joint values `theta_com` (rad, model joint values), eq. 14. For a row that
    /// did not converge: the closest configuration found, within the limits.
    pub commanded: Vec<f64>,
    /// How the solve ended.
    pub report: IkReport,
}

/// Compensation of a nominal model by a calibrated one (eq. 12-14).
#[derive(Debug, Clone)]
pub struct Compensator<'a, S: IkSolver = DampedLeastSquares> {
    nominal: &'a Robot,
    calibrated: &'a Robot,
    /// The inverse-kinematics method for positions and its tolerances.
    pub solver: S,
    /// The inverse-kinematics method for full poses and its tolerances.
    pub pose_solver: PoseNewton,
    /// How many start configurations [`Compensator::reach`] tries for a target without a seed
    /// (see [`default_seeds`]).
    pub seeds: usize,
}

/// How often batch functions report to their observer (rows).
const PROGRESS_EVERY: usize = 256;

impl<'a, S: IkSolver> Compensator<'a, S> {
    /// A compensator for the controller's `nominal` model and the `calibrated` model of the same
    /// robot. Fails if their joint counts differ.
    pub fn new(nominal: &'a Robot, calibrated: &'a Robot, solver: S) -> Result<Self> {
        if nominal.dof() != calibrated.dof() {
            return Err(Error::invalid(
                "calibrated model",
                format!(
                    "has {} joints, the nominal model {}",
                    calibrated.dof(),
                    nominal.dof()
                ),
            ));
        }
        Ok(Compensator {
            nominal,
            calibrated,
            solver,
            pose_solver: PoseNewton::default(),
            seeds: 8,
        })
    }

    /// The nominal model.
    pub fn nominal(&self) -> &Robot {
        self.nominal
    }

    /// The calibrated model.
    pub fn calibrated(&self) -> &Robot {
        self.calibrated
    }

    /// Compensates one desired joint vector (rad): target `P_des = FK_nominal(desired)` (eq. 13),
    /// solved on the calibrated model from `desired` (eq. 14); writes `theta_com` to `commanded`.
    /// Returns `P_des` and the solve's report. Allocation-free.
    pub fn compensate(&self, desired: &[f64], commanded: &mut [f64]) -> (Vector3<f64>, IkReport) {
        let target = self.nominal.tool_position(desired);
        let rep = self
            .solver
            .solve(self.calibrated, &target, desired, commanded);
        (target, rep)
    }

    /// Joint values (rad) that put the calibrated model's tool point at `target` (mm, base frame).
    /// With a `seed` the solve starts there (and only there); without, it tries up to
    /// [`Compensator::seeds`] start configurations ([`default_seeds`], turned towards the target)
    /// and keeps the first that converges, else the one that ends closest to the target (with its
    /// status).
    pub fn reach(&self, target: &Vector3<f64>, seed: Option<&[f64]>, q: &mut [f64]) -> IkReport {
        if let Some(s) = seed {
            return self.solver.solve(self.calibrated, target, s, q);
        }
        let n = self.calibrated.dof();
        let mut start = [0.0; MAX_JOINTS];
        let mut trial = [0.0; MAX_JOINTS];
        let mut best: Option<IkReport> = None;
        for k in 0..self.seeds.max(1) {
            seed_configuration(self.calibrated, k, &mut start[..n]);
            turn_towards(self.calibrated, target, &mut start[..n]);
            let rep = self
                .solver
                .solve(self.calibrated, target, &start[..n], &mut trial[..n]);
            let better = match &best {
                None => true,
                Some(b) => rep.status.is_converged() || rep.residual_mm < b.residual_mm,
            };
            if better {
                q.copy_from_slice(&trial[..n]);
                best = Some(rep);
            }
            if rep.status.is_converged() {
                break;
            }
        }
        best.expect("at least one seed")
    }

    /// Full-pose compensation of one desired joint vector (rad): the target is the nominal tool
    /// frame `FK_nominal(desired)` (eq. 13 with the orientation), solved on the calibrated model
    /// from `desired` ([`PoseNewton`]); writes `theta_com` to `commanded`. The status says when
    /// the solution lies on another configuration than `desired` or near a singularity (see
    /// [`Compensator::check_configuration`]). Returns the target frame and the report.
    /// Allocation-free.
    pub fn compensate_pose(&self, desired: &[f64], commanded: &mut [f64]) -> (Frame, IkReport) {
        let target = self.nominal.tool_pose(desired);
        let rep = self
            .pose_solver
            .solve(self.calibrated, &target, 0, desired, commanded);
        let rep = self.check_configuration(self.nominal, desired, commanded, rep);
        (target, rep)
    }

    /// Turns a report that reached its target into [`IkStatus::Singular`] when the reference
    /// joints `reference` (rad, of `reference_model`: the desired joints on the nominal model,
    /// or a seed on the calibrated one) or the solution `q` (on the calibrated model) lie within
    /// [`PoseNewton::singular_margin`] of a singularity, else into
    /// [`IkStatus::ConfigurationChange`] when their configurations differ
    /// ([`configuration::configuration`]). Robots without a configuration are not checked.
    pub fn check_configuration(
        &self,
        reference_model: &Robot,
        reference: &[f64],
        q: &[f64],
        mut rep: IkReport,
    ) -> IkReport {
        if rep.status != IkStatus::Converged {
            return rep;
        }
        let (Some(a), Some(b)) = (
            configuration::configuration(reference_model, reference),
            configuration::configuration(self.calibrated, q),
        ) else {
            return rep;
        };
        if a.margin().min(b.margin()) < self.pose_solver.singular_margin {
            rep.status = IkStatus::Singular;
        } else if a.flags != b.flags {
            rep.status = IkStatus::ConfigurationChange;
        }
        rep
    }

    /// Joint values (rad) that put the calibrated model's tool frame at `target` (base frame),
    /// position and orientation. With a `seed` the solve starts there and keeps its configuration
    /// (or says it could not); without, it tries up to [`Compensator::seeds`] start
    /// configurations as [`Compensator::reach`] does and keeps the first that reaches the pose
    /// (whatever its configuration; [`IkStatus::Singular`] near a singularity), else the one that
    /// ends closest (position error plus [`PoseNewton::length_scale_mm`] times the angle).
    pub fn reach_pose(&self, target: &Frame, seed: Option<&[f64]>, q: &mut [f64]) -> IkReport {
        let cal = self.calibrated;
        if let Some(s) = seed {
            let rep = self.pose_solver.solve(cal, target, 0, s, q);
            return self.check_configuration(cal, s, q, rep);
        }
        let n = cal.dof();
        let mut start = [0.0; MAX_JOINTS];
        let mut trial = [0.0; MAX_JOINTS];
        let mut best: Option<IkReport> = None;
        let cost = |r: &IkReport| {
            r.residual_mm + self.pose_solver.length_scale_mm * r.residual_deg.to_radians()
        };
        let p = target.translation.vector;
        for k in 0..self.seeds.max(1) {
            seed_configuration(cal, k, &mut start[..n]);
            turn_towards(cal, &p, &mut start[..n]);
            let rep = self
                .pose_solver
                .solve(cal, target, 0, &start[..n], &mut trial[..n]);
            let better = match &best {
                None => true,
                Some(b) => rep.status.is_converged() || cost(&rep) < cost(b),
            };
            if better {
                q.copy_from_slice(&trial[..n]);
                best = Some(rep);
            }
            if rep.status.is_converged() {
                break;
            }
        }
        let rep = best.expect("at least one seed");
        // Without a desired branch only the singular neighbourhood is checked.
        self.check_configuration(cal, q, q, rep)
    }

    /// Compensates every desired joint vector (rad), in order (eq. 12-14). `observer` hears
    /// [`Stage::Compensation`] as rows complete.
    pub fn compensate_all(
        &self,
        desired: &[Vec<f64>],
        observer: &dyn Observer,
    ) -> Result<Vec<Compensation>> {
        let n = self.nominal.dof();
        let mut out = Vec::with_capacity(desired.len());
        for (k, d) in desired.iter().enumerate() {
            self.nominal
                .check_joints(d, &format!("desired pose {}", k + 1))?;
            let mut q = vec![0.0; n];
            let (p, report) = self.compensate(d, &mut q);
            out.push(Compensation {
                desired_position: p,
                desired_orientation: None,
                commanded: q,
                report,
            });
            if (k + 1) % PROGRESS_EVERY == 0 {
                observer.progress(Stage::Compensation, k + 1, desired.len());
            }
        }
        observer.progress(Stage::Compensation, desired.len(), desired.len());
        Ok(out)
    }

    /// Reaches every target of a target file, in order (see [`Compensator::reach`]); `observer`
    /// hears [`Stage::Compensation`] as rows complete.
    pub fn reach_all(
        &self,
        targets: &[Target],
        observer: &dyn Observer,
    ) -> Result<Vec<Compensation>> {
        let n = self.calibrated.dof();
        let mut out = Vec::with_capacity(targets.len());
        for (k, t) in targets.iter().enumerate() {
            if let Some(s) = &t.seed {
                self.calibrated
                    .check_joints(s, &format!("target on line {}", t.line))?;
            }
            if t.p.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("target on line {}", t.line),
                    "not a finite position",
                ));
            }
            let mut q = vec![0.0; n];
            let report = self.reach(&t.p, t.seed.as_deref(), &mut q);
            out.push(Compensation {
                desired_position: t.p,
                desired_orientation: None,
                commanded: q,
                report,
            });
            if (k + 1) % PROGRESS_EVERY == 0 {
                observer.progress(Stage::Compensation, k + 1, targets.len());
            }
        }
        observer.progress(Stage::Compensation, targets.len(), targets.len());
        Ok(out)
    }
}

/// The `k`-th default start configuration for a Cartesian target without a seed, written to `q`
/// (rad, mm for a prismatic joint): `k = 0` is the middle of every joint's range; further ones
/// are spread over the limits by a Halton sequence (deterministic, so the same file gives the
/// same answer). Revolute ranges wider than a full turn are sampled over one turn around their
/// middle; prismatic ranges over their whole travel.
pub fn default_seeds(robot: &Robot, count: usize) -> Vec<Vec<f64>> {
    (0..count)
        .map(|k| {
            let mut q = vec![0.0; robot.dof()];
            seed_configuration(robot, k, &mut q);
            q
        })
        .collect()
}

fn seed_configuration(robot: &Robot, k: usize, q: &mut [f64]) {
    const PRIMES: [usize; MAX_JOINTS] =
        [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];
    for (i, (v, l)) in q.iter_mut().zip(robot.limits()).enumerate() {
        let mid = 0.5 * (l.min + l.max);
        let half = match robot.joint_type(i) {
            JointType::Revolute => (0.5 * (l.max - l.min)).min(std::f64::consts::PI),
            JointType::Prismatic => 0.5 * (l.max - l.min),
        };
        // Halton value in (0, 1) shifted so that k = 0 gives the middle.
        let u = if k == 0 { 0.5 } else { halton(k, PRIMES[i]) };
        *v = mid + (2.0 * u - 1.0) * half;
    }
}

fn halton(mut k: usize, base: usize) -> f64 {
    let mut f = 1.0;
    let mut r = 0.0;
    while k > 0 {
        f /= base as f64;
        r += f * (k % base) as f64;
        k /= base;
    }
    r
}

/// Turns the first revolute joint of `q` (joint 1, or the first after prismatic ones such as a
/// linear track) so that the tool point's azimuth about its axis matches the target's (when the
/// result stays within the joint's limits, trying a full turn either way).
pub(crate) fn turn_towards(robot: &Robot, target: &Vector3<f64>, q: &mut [f64]) {
    let Some(k) = robot
        .joint_types()
        .iter()
        .position(|t| *t == JointType::Revolute)
    else {
        return;
    };
    let (axis, origin) = robot.joint_axis(q, k);
    let p = robot.tool_position(q);
    let flat = |v: Vector3<f64>| v - axis * axis.dot(&v);
    let (a, b) = (flat(p - origin), flat(target - origin));
    if a.norm() < 1e-9 || b.norm() < 1e-9 {
        return;
    }
    let angle = a.cross(&b).dot(&axis).atan2(a.dot(&b));
    let l = robot.limits()[k];
    let tau = std::f64::consts::TAU;
    for turn in [0.0, tau, -tau] {
        let v = q[k] + angle + turn;
        if l.contains(v) {
            q[k] = v;
            return;
        }
    }
}

#[cfg(test)]
mod pose_tests;
#[cfg(test)]
mod tests;
