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
    check_settings(settings)
}

/// The settings' own checks (independent of the data).
fn check_settings(settings: &CalibrationSettings) -> Result<()> {
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
    let idopts = &settings.identifiability;
    if let Some(p) = idopts.fix.iter().find(|p| idopts.free.contains(p)) {
        return Err(Error::invalid(
            "identifiability.fix",
            format!(
                "`{}` is given both to `identifiability.fix` and to `identifiability.free`",
                p.name()
            ),
        ));
    }
    if !(idopts.rank_tolerance >= MIN_RANK_TOLERANCE && idopts.rank_tolerance < 1.0) {
        return Err(Error::invalid(
            "identifiability.rank_tolerance",
            format!(
                "{:e} is not in [{MIN_RANK_TOLERANCE:e}, 1): it is the smallest independence \
                 (sine of the angle between a parameter's effect and the others') accepted, and \
                 below {MIN_RANK_TOLERANCE:e} double precision cannot tell a parameter from an \
                 exact duplicate (whose independence computes as 1e-17 to 1e-14 from rounding)",
                idopts.rank_tolerance
            ),
        ));
    }
    if let Some(c) = settings.robust_scale_mm {
        if !(c > 0.0 && c.is_finite()) {
            return Err(Error::invalid(
                "robust_scale_mm",
                format!("{c} is not a positive length (mm)"),
            ));
        }
    }
    Ok(())
}
