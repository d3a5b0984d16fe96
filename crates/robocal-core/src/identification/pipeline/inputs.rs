//! The pipeline's first step: the data and the settings checked before any work.

use super::{CalibrationData, CalibrationSettings};
use crate::error::{Error, Result};
use crate::identification::identifiability::MIN_RANK_TOLERANCE;
use crate::model::Robot;

/// Fails on data that cannot calibrate `nominal` (another joint count, no calibration point,
/// targets the robot lacks, a pose measured twice) and on settings out of their range (a
/// parameter both fixed and freed, a rank tolerance double precision cannot honour, a robust
/// scale that is not a positive length).
pub(super) fn check(
    nominal: &Robot,
    data: &CalibrationData,
    settings: &CalibrationSettings,
) -> Result<()> {
    let cal = data.calibration;
    let all = || {
        [Some(cal), data.plane, data.validation]
            .into_iter()
            .flatten()
    };
    for obs in all() {
        if obs.dof() != nominal.dof() {
            return Err(Error::JointCount {
                context: obs
                    .source()
                    .map_or("measurements".into(), |p| p.display().to_string()),
                expected: nominal.dof(),
                got: obs.dof(),
            });
        }
    }
    if cal.is_empty() {
        return Err(Error::invalid("calibration data", "no calibration points"));
    }
    for obs in all() {
        obs.check_targets(nominal)?;
    }
    cal.check_no_duplicate_poses()?;
    settings.check(nominal)
}

impl CalibrationSettings {
    /// The settings' own checks, independent of the data: the one place they are checked, for
    /// the command line and the Python bindings alike (each calls it before reading any data,
    /// and [`crate::identification::calibrate`] again). An error names the setting (the field,
    /// e.g. `identifiability.rank_tolerance`), which each front end shows as its flag or keyword:
    /// [`Error::Usage`] for a value out of its range, as a command line's bad flag value (the
    /// iteration limit, a robust scale that is not a positive length of at most 1 km, a rank
    /// tolerance double precision cannot honour, an orientation weight, every parameter fixed);
    /// [`Error::Invalid`] for a parameter both fixed and freed (the parameter lists contradict
    /// each other). `robot` is the nominal robot the parameter lists name.
    pub fn check(&self, robot: &Robot) -> Result<()> {
        let solver = &self.solver;
        Error::check_count(
            "solver.max_iterations",
            solver.max_iterations as u64,
            1,
            crate::identification::MAX_ITERATIONS as u64,
            "a solver that has not converged by then will not",
        )?;
        check_warm_start(self)?;
        let idopts = &self.identifiability;
        if let Some(p) = idopts.fix.iter().find(|p| idopts.free.contains(p)) {
            return Err(Error::invalid(
                "identifiability.fix",
                format!(
                    "`{}` is given both to `identifiability.fix` and to `identifiability.free`",
                    p.name()
                ),
            ));
        }
        if robot.param_list().iter().all(|p| idopts.fix.contains(p)) {
            return Err(Error::usage(
                "identifiability.fix",
                format!(
                    "names every parameter of robot `{}` ({}): nothing is left to identify",
                    robot.name(),
                    robot.param_count()
                ),
            ));
        }
        if !(idopts.rank_tolerance >= MIN_RANK_TOLERANCE && idopts.rank_tolerance < 1.0) {
            return Err(Error::usage(
                "identifiability.rank_tolerance",
                format!(
                    "{:e} is not in [{MIN_RANK_TOLERANCE:e}, 1): it is the smallest independence \
                     (sine of the angle between a parameter's effect and the others') accepted, \
                     and below {MIN_RANK_TOLERANCE:e} double precision cannot tell a parameter \
                     from an exact duplicate (whose independence computes as 1e-17 to 1e-14 from \
                     rounding)",
                    idopts.rank_tolerance
                ),
            ));
        }
        if let Some(c) = self.robust_scale_mm {
            if !(c > 0.0 && c.is_finite()) {
                return Err(Error::usage(
                    "robust_scale_mm",
                    format!("{c} is not a positive length (mm)"),
                ));
            }
            let max = crate::ranges::LENGTH.max;
            if c > max {
                return Err(Error::usage(
                    "robust_scale_mm",
                    format!("at most {max} mm, got {}", shown(c)),
                ));
            }
        }
        let w = self.weighting.mm_per_deg;
        if !(w > 0.0 && w.is_finite() && w <= MAX_ORIENTATION_WEIGHT) {
            return Err(Error::usage(
                "weighting.mm_per_deg",
                format!(
                    "{}: expected a positive number of mm per degree, at most \
                     {MAX_ORIENTATION_WEIGHT}",
                    shown(w)
                ),
            ));
        }
        Ok(())
    }
}

/// The largest orientation weight (mm per degree): a degree worth a kilometre already makes the
/// positions weightless.
const MAX_ORIENTATION_WEIGHT: f64 = 1e6;

/// A number as a message shows it: 1e300 in full would be 301 digits.
fn shown(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1e15 {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The subsample a large set's solve starts on: at least [`MIN_WARM_START_POINTS`], fewer than
/// the size from which it applies.
///
/// [`MIN_WARM_START_POINTS`]: crate::identification::solver::MIN_WARM_START_POINTS
fn check_warm_start(settings: &CalibrationSettings) -> Result<()> {
    let solver = &settings.solver;
    if solver.warm_start_points < crate::identification::solver::MIN_WARM_START_POINTS
        || solver.warm_start_points >= solver.warm_start_min_points
    {
        return Err(Error::invalid(
            "solver.warm_start_points",
            format!(
                "{} is not within [{}, solver.warm_start_min_points = {}): the subsample a \
                 large set's solve starts on",
                solver.warm_start_points,
                crate::identification::solver::MIN_WARM_START_POINTS,
                solver.warm_start_min_points
            ),
        ));
    }
    Ok(())
}
