//! The plausibility gate: checks run after every fit that tell a calibration from a fit that
//! cannot be right.
//!
//! A flexible model fits almost anything: positions in metres, a mirrored tracker frame or the
//! wrong robot all end in a small Table IV, with parameters moved by metres or 180 degrees. The
//! gate measures what no calibration of a real robot produces:
//!
//! - **convergence**: the solver's termination;
//! - **units**: a uniform scale fits the measured points to the nominal model clearly better
//!   than scale 1 (positions in metres: about 1000; inches: 25.4);
//! - **handedness**: a reflection fits them better than a rotation (a left-handed tracker frame);
//! - **nominal error**: Table II (the nominal model after the frame fit) larger than any plausible
//!   geometric error of the robot, relative to its reach (also on the validation points);
//! - **parameter moves**: a length or an angle moved further than calibration corrects.
//!
//! The limits are the constants below, each with the margins measured on good and bad data. A
//! failed check carries the likely cause, found by undoing the usual mistakes one at a time
//! ([`diagnosis`]).

mod causes;
pub mod diagnosis;
mod ranges;
mod shape;
pub mod similarity;
pub mod statistics;

#[cfg(test)]
mod tests;

use crate::identification::solver::SolverReport;
use crate::io::result_plausibility::{CauseEntry, CheckEntry, PlausibilitySection};
use crate::model::family::plausible;
use crate::model::{Param, Robot, Unit};
use crate::observations::Observations;
use crate::registration::Registration;
use crate::stats::ErrorStats;
use causes::Causes;
use diagnosis::{explain, Explanation};
use shape::Shape;
pub(crate) use shape::ShapeChecks;

// The margins quoted below were measured with the release build on 148 good fits — the demo
// (KR 480, seeds 1-30), the real UR5 and WAM grid sets (with their random sets as validation,
// also with `--beta parallel` and the robust objective), and simulated random robots (KR 480,
// UR5, WAM; seeds 1-8; realistic errors of 0.5 mm and 0.03 deg per parameter, 4 and 10 times
// larger; 30-pose sets; gravity sag with 5% outliers) — and on 23 bad ones: the KR 480, UR5 and
// WAM data with positions in metres, centimetres and inches, one axis mirrored, joints in
// radians, a missing J2/J3 coupling, joint 1 or 2 reversed, and the KR 480 model on UR5 data and
// the UR5 model on KR 480 data. Every bad fit fails at least two checks; no good one fails any.

/// Units check: the best uniform scale must lie within this factor of 1 ...
///
/// Good data: at most 1.003 (real WAM), 1.002 (simulated, realistic errors), 1.017 (10 times
/// realistic errors); bad: 9.97 (centimetres) to 1001 (metres); a wrong robot 3.4 to 4.5.
pub const SCALE_LIMIT: f64 = 1.05;
/// ... unless the scaled fit is not at least this many times better than the rigid one (a poorly
/// spread pose set leaves the scale loosely determined, without any gain from it).
pub const SCALE_GAIN: f64 = 2.0;

/// Handedness check: the RMS of the best reflection over that of the best rotation (both with a
/// free scale) must be at least this. Good data: at least 24.7 (real WAM), 166 (simulated,
/// realistic errors), 16.4 (10 times realistic); mirrored data: 0.0008 to 0.04; joint 1
/// reversed (nearly a mirror image): 0.26 to 0.33. Points on a plane fit both equally (ratio 1)
/// and pass.
pub const HANDEDNESS_LIMIT: f64 = 0.5;

/// Nominal-error check: the RMS of Table II must stay below this fraction of the robot's reach
/// ([`reach_mm`]). 5% of the reach is the tool displacement of a 2.9 degree rotation at full
/// reach: a joint zero off by degrees (an unmastered axis) is still a calibration's job, but
/// every joint's zero off by degrees at once, where mastering errors are hundredths of a degree
/// and link errors millimetres, is not this robot. Good data: at most 0.57% (real WAM, a
/// cable-driven arm sagging under gravity), 0.25% (simulated, realistic errors), 2.5% (10 times
/// realistic); bad data: 14.3% and more.
pub const NOMINAL_ERROR_LIMIT: f64 = 0.05;

/// Parameter moves: no identified length may move by more than this fraction of the reach
/// (see [`plausible::LENGTH_MOVE_FRACTION`], the families' table).
pub const LENGTH_MOVE_LIMIT: f64 = plausible::LENGTH_MOVE_FRACTION;

/// Parameter moves: no identified geometric angle may move by more than this (degrees; see
/// [`plausible::ANGLE_MOVE_DEG`]).
pub const ANGLE_MOVE_LIMIT_DEG: f64 = plausible::ANGLE_MOVE_DEG;

/// What a check measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckKind {
    /// The solver converged.
    Convergence,
    /// The best uniform scale (units).
    Units,
    /// Reflection against rotation.
    Handedness,
    /// Table II on the calibration points, relative to the reach.
    NominalError,
    /// Table II on the validation points, relative to the reach.
    ValidationNominalError,
    /// The largest move of an identified length.
    LengthMoves,
    /// The largest move of an identified angle.
    AngleMoves,
    /// Every identified parameter of a family acting through the joints (compliance,
    /// transmission errors) within its family's plausible range.
    ParameterRanges,
    /// The calibrated model no worse than the model it started from.
    Improvement,
    /// The share of points beyond the robust loss's threshold.
    DiscardedPoints,
    /// The residuals against the noise model.
    Residuals,
    /// The largest share of the total weight on one point.
    WeightShare,
}

impl CheckKind {
    /// The check's name in the result JSON and messages.
    pub fn name(self) -> &'static str {
        match self {
            CheckKind::Convergence => "convergence",
            CheckKind::Units => "units",
            CheckKind::Handedness => "handedness",
            CheckKind::NominalError => "nominal_error",
            CheckKind::ValidationNominalError => "validation_nominal_error",
            CheckKind::LengthMoves => "length_moves",
            CheckKind::AngleMoves => "angle_moves",
            CheckKind::ParameterRanges => "parameter_ranges",
            CheckKind::Improvement => "improvement",
            CheckKind::DiscardedPoints => "discarded_points",
            CheckKind::Residuals => "residuals",
            CheckKind::WeightShare => "weight_share",
        }
    }
}

/// One check's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What it measures.
    pub kind: CheckKind,
    /// The measured value.
    pub measured: f64,
    /// Its limit.
    pub limit: f64,
    /// Unit of both (`"mm"`, `"deg"`, `"factor"`, `"ratio"`, `"iterations"`).
    pub unit: &'static str,
    /// Whether the fit passed.
    pub passed: bool,
    /// What was measured, as a sentence with the numbers and the limit.
    pub detail: String,
    /// For a failure: the likely cause.
    pub cause: Option<String>,
}

/// The outcome of the gate.
#[derive(Debug, Clone, PartialEq)]
pub struct Plausibility {
    /// The robot's reach (mm), the scale of the length limits ([`reach_mm`]).
    pub reach_mm: f64,
    /// Every check, in a fixed order.
    pub checks: Vec<Check>,
    /// For a failure: the corrections of the data that make the nominal model fit, best first
    /// (empty when none does).
    pub explanations: Vec<Explanation>,
}

/// What the gate looks at.
#[derive(Debug, Clone, Copy)]
pub struct Fit<'a> {
    /// The nominal model.
    pub nominal: &'a Robot,
    /// The model the identification started from: the nominal geometry with the tools fitted
    /// to the data (a tool the user did not know is not a move of the calibration).
    pub start: &'a Robot,
    /// The calibrated model.
    pub calibrated: &'a Robot,
    /// The identified parameters.
    pub identified: &'a [Param],
    /// The calibration points.
    pub calibration: &'a Observations,
    /// The fitted measurement frame and Table II.
    pub registration: &'a Registration,
    /// The RMS error (mm) of the model the identification started from ([`Fit::start`]) in its
    /// frame: Table II's second line (the nominal geometry with the fitted tools) when the tools
    /// were fitted, else its first. A tool the user did not know is not an error of the robot.
    pub nominal_rms_mm: f64,
    /// Error norms of the validation points under the same model (mm), if any.
    pub validation_before: Option<&'a [f64]>,
    /// Error norms of the validation points under the calibrated model (mm), if any.
    pub validation_after: Option<&'a [f64]>,
    /// Error norms of the calibration points under the model the identification started from
    /// (mm).
    pub calibration_before: &'a [f64],
    /// The number of calibration points beyond the robust loss's threshold.
    pub downweighted: usize,
    /// The predicted mean error at new poses (mm), when available.
    pub prediction_mean_mm: Option<f64>,
    /// The per-axis noise of the calibrated model's residuals (mm), when available.
    pub noise_sigma_mm: Option<f64>,
    /// The last solver run.
    pub solver: &'a SolverReport,
    /// The solver's iteration limit.
    pub max_iterations: usize,
}

/// The robot's reach ([`Robot::reach_mm`]): the scale of the gate's length limits.
pub fn reach_mm(robot: &Robot) -> f64 {
    robot.reach_mm()
}

/// Whether every joint value is within ±2π "degrees" while the limits span far more: values in
/// radians read as degrees.
pub fn joints_look_like_radians(robot: &Robot, obs: &Observations) -> bool {
    let span = robot
        .limits()
        .iter()
        .map(|l| l.max - l.min)
        .fold(0.0, f64::max);
    let two_pi_deg = std::f64::consts::TAU.to_radians();
    !obs.is_empty()
        && span > 4.0 * two_pi_deg
        && (0..obs.len()).all(|i| obs.q(i).iter().all(|v| v.abs() <= two_pi_deg))
}

fn check(
    kind: CheckKind,
    measured: f64,
    limit: f64,
    unit: &'static str,
    passed: bool,
    detail: String,
) -> Check {
    Check {
        kind,
        measured,
        limit,
        unit,
        passed,
        detail,
        cause: None,
    }
}

/// The largest move among the identified parameters of one unit: (parameter, |move|) in display
/// units, angles wrapped to ±180 degrees.
fn largest_move(fit: &Fit, unit: Unit) -> Option<(Param, f64)> {
    fit.identified
        .iter()
        .filter(|p| p.unit() == unit && !p.family().deflects_joints(fit.start))
        .map(|&p| {
            let nominal = if fit.start.has_param(p) {
                fit.start.get(p)
            } else {
                0.0
            };
            let mut d = fit.calibrated.get(p) - nominal;
            if unit == Unit::Deg {
                d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
            }
            (p, unit.from_internal(d.abs()))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Runs every check on a fit and, if one fails, looks for the likely cause.
pub fn assess(fit: &Fit) -> Plausibility {
    assess_with(fit, None)
}

/// [`assess`], with the shape checks of `fit`'s calibration points against its start model's
/// tool points when computed before ([`ShapeChecks::of`]).
pub(crate) fn assess_with(fit: &Fit, shape: Option<&ShapeChecks>) -> Plausibility {
    let reach = reach_mm(fit.start);
    let mut checks = vec![convergence(fit)];
    let shape = match shape {
        Some(known) => {
            checks.extend(known.checks.iter().cloned());
            known.shape
        }
        None => Shape::of(fit.calibration, fit.start, &mut checks),
    };
    let limit_mm = NOMINAL_ERROR_LIMIT * reach;
    checks.extend(nominal_errors(fit, reach));
    checks.extend(moves(fit, reach));
    checks.push(ranges::check_non_geometric(fit));
    checks.push(statistics::improvement(fit));
    checks.push(statistics::discarded(fit));
    checks.push(statistics::residuals(fit));
    checks.push(statistics::weight_share(fit));

    let data_suspect = checks
        .iter()
        .any(|c| !c.passed && c.kind != CheckKind::Convergence);
    let explanations = if data_suspect && shape.rigid_rms.is_finite() {
        explain(fit.nominal, fit.calibration, shape.rigid_rms, limit_mm)
    } else {
        Vec::new()
    };
    let causes = Causes {
        explanations: &explanations,
        radians: joints_look_like_radians(fit.nominal, fit.calibration),
        scale: shape.scale,
        failed: checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.kind)
            .collect(),
        max_iterations: fit.max_iterations,
    };
    causes.attach(&mut checks);
    Plausibility {
        reach_mm: reach,
        checks,
        explanations,
    }
}

/// Whether the solver converged within its iterations.
fn convergence(fit: &Fit) -> Check {
    check(
        CheckKind::Convergence,
        fit.solver.iterations as f64,
        fit.max_iterations as f64,
        "iterations",
        fit.solver.termination.converged(),
        format!(
            "the solver {} after {} iteration(s) (limit {})",
            fit.solver.termination.describe(),
            fit.solver.iterations,
            fit.max_iterations
        ),
    )
}

/// The nominal model's error after the frame fit (Table II) on the calibration and the
/// validation points, against a share of the robot's reach.
fn nominal_errors(fit: &Fit, reach: f64) -> Vec<Check> {
    let limit_mm = NOMINAL_ERROR_LIMIT * reach;
    let table2 = |rms: f64, what: &str| {
        format!(
            "the nominal model misses the {what} points by {rms:.3} mm RMS after the frame fit \
             (Table II), {:.2}% of the robot's reach of {reach:.0} mm; limit: {}% ({limit_mm:.1} \
             mm)",
            100.0 * rms / reach,
            100.0 * NOMINAL_ERROR_LIMIT
        )
    };
    let rms2 = fit.nominal_rms_mm;
    let mut checks = vec![check(
        CheckKind::NominalError,
        rms2,
        limit_mm,
        "mm",
        rms2 <= limit_mm,
        table2(rms2, "calibration"),
    )];
    if let Some(v) = fit.validation_before.filter(|v| !v.is_empty()) {
        let rms = ErrorStats::from_norms(v).rms_mm;
        checks.push(check(
            CheckKind::ValidationNominalError,
            rms,
            limit_mm,
            "mm",
            rms <= limit_mm,
            table2(rms, "validation"),
        ));
    }
    checks
}

/// The largest moves of an identified length (against a share of the reach) and angle.
fn moves(fit: &Fit, reach: f64) -> [Check; 2] {
    let length_limit = LENGTH_MOVE_LIMIT * reach;
    let (lp, lv) = largest_move(fit, Unit::Mm).map_or((None, 0.0), |(p, v)| (Some(p), v));
    let lengths = check(
        CheckKind::LengthMoves,
        lv,
        length_limit,
        "mm",
        lv <= length_limit,
        match lp {
            Some(p) => format!(
                "the largest move of an identified length is {} by {lv:.3} mm, {:.2}% of the \
                 reach; limit: {}% ({length_limit:.1} mm)",
                p.name(),
                100.0 * lv / reach,
                100.0 * LENGTH_MOVE_LIMIT
            ),
            None => "no length identified".into(),
        },
    );
    let (ap, av) = largest_move(fit, Unit::Deg).map_or((None, 0.0), |(p, v)| (Some(p), v));
    let angles = check(
        CheckKind::AngleMoves,
        av,
        ANGLE_MOVE_LIMIT_DEG,
        "deg",
        av <= ANGLE_MOVE_LIMIT_DEG,
        match ap {
            Some(p) => format!(
                "the largest move of an identified angle is {} by {av:.4} deg; limit: \
                 {ANGLE_MOVE_LIMIT_DEG} deg",
                p.name()
            ),
            None => "no angle identified".into(),
        },
    );
    [lengths, angles]
}

/// The gate's data checks for measurements read against an existing calibration (evaluate,
/// compensate, report): units, handedness and the error of `robot` after the best rigid fit of
/// the points (free of any tracker frame, so that another station passes), with the likely cause
/// of a failure, as [`assess`] finds them for `calibrate`.
pub fn assess_data(robot: &Robot, obs: &Observations) -> Plausibility {
    let reach = reach_mm(robot);
    let mut checks = Vec::new();
    let shape = Shape::of(obs, robot, &mut checks);
    let limit_mm = NOMINAL_ERROR_LIMIT * reach;
    let rms = shape.rigid_rms;
    checks.push(check(
        CheckKind::NominalError,
        rms,
        limit_mm,
        "mm",
        rms.is_nan() || rms <= limit_mm,
        format!(
            "the model misses the points by {rms:.3} mm RMS after the best rigid fit, {:.2}% of \
             the robot's reach of {reach:.0} mm; limit: {}% ({limit_mm:.1} mm)",
            100.0 * rms / reach,
            100.0 * NOMINAL_ERROR_LIMIT
        ),
    ));
    let failed: Vec<CheckKind> = checks
        .iter()
        .filter(|c| !c.passed)
        .map(|c| c.kind)
        .collect();
    let explanations = if !failed.is_empty() && rms.is_finite() {
        explain(robot, obs, rms, limit_mm)
    } else {
        Vec::new()
    };
    let causes = Causes {
        explanations: &explanations,
        radians: joints_look_like_radians(robot, obs),
        scale: shape.scale,
        failed,
        max_iterations: 0,
    };
    causes.attach(&mut checks);
    Plausibility {
        reach_mm: reach,
        checks,
        explanations,
    }
}

impl Plausibility {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// The failed checks.
    pub fn failures(&self) -> impl Iterator<Item = &Check> {
        self.checks.iter().filter(|c| !c.passed)
    }

    /// Whether a check other than convergence failed: the fit cannot be right (a fit that did not
    /// converge is partial; see `Termination`).
    pub fn implausible(&self) -> bool {
        self.failures().any(|c| c.kind != CheckKind::Convergence)
    }

    /// The failed checks other than convergence, one line each with its measurement and limit,
    /// then the likely cause (one line when the checks share it, else one per check).
    pub fn summary(&self) -> String {
        let failed: Vec<&Check> = self
            .failures()
            .filter(|c| c.kind != CheckKind::Convergence)
            .collect();
        let mut lines: Vec<String> = failed
            .iter()
            .map(|c| format!("{}: {}", c.kind.name(), c.detail))
            .collect();
        let mut causes: Vec<&str> = Vec::new();
        for c in &failed {
            if let Some(cause) = c.cause.as_deref() {
                if !causes.contains(&cause) {
                    causes.push(cause);
                }
            }
        }
        if causes.len() == 1 {
            lines.push(format!("likely cause: {}", causes[0]));
        } else {
            for c in &failed {
                if let Some(cause) = &c.cause {
                    lines.push(format!("likely cause ({}): {cause}", c.kind.name()));
                }
            }
        }
        lines.join("\n")
    }

    /// The `plausibility` section of the result JSON.
    pub fn to_section(&self) -> PlausibilitySection {
        let checks = self
            .checks
            .iter()
            .map(|c| CheckEntry {
                name: c.kind.name().to_owned(),
                measured: c.measured,
                limit: c.limit,
                unit: c.unit.to_owned(),
                passed: c.passed,
                detail: c.detail.clone(),
                cause: c.cause.clone(),
            })
            .collect();
        let likely_causes = (!self.explanations.is_empty()).then(|| {
            self.explanations
                .iter()
                .map(|e| CauseEntry {
                    cause: e.describe(),
                    fit_rms_mm: e.rms_mm,
                    scale: e.scale,
                    mirrored: e.mirrored,
                    unit: e.unit.map(|(u, _)| u.to_owned()),
                    joints: e.joints.map(|j| j.describe()),
                })
                .collect()
        });
        PlausibilitySection {
            passed: self.passed(),
            reach_mm: self.reach_mm,
            checks,
            likely_causes,
        }
    }
}
