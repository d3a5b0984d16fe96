//! `--temperature-c` and the approach direction: a calibration with the thermal or backlash
//! family compensates for one state of the cell, folded into the model before solving.

use crate::exit;
use robocal_core::kinematics::Conditions;
use robocal_core::model::family::{backlash, thermal};
use robocal_core::Robot;

/// The calibrated model at the cell's temperature (`--temperature-c`; default: the calibration's
/// reference temperature, with a note) and with every modelled backlash taken from below (each
/// pose approached with the joints moving in the positive direction, said on standard error).
pub(super) fn fold(calibrated: &Robot, temperature_c: Option<f64>) -> anyhow::Result<Robot> {
    let mut c = Conditions::UNKNOWN;
    match (thermal::reference_c(calibrated), temperature_c) {
        (Some(_), Some(t)) => {
            let (lo, hi) = robocal_core::io::row_conditions::TEMPERATURE_RANGE_C;
            if !(t.is_finite() && (lo..=hi).contains(&t)) {
                return Err(exit::usage(format!(
                    "--temperature-c {t}: not a robot's temperature within {lo}..{hi} deg C"
                )));
            }
            c.temperature_c = t;
        }
        (Some(r), None) => {
            errln!(
                "note: the calibration models thermal expansion; compensating at its reference \
                 temperature {r} deg C (give the arm's current temperature with --temperature-c)"
            )?;
        }
        (None, Some(_)) => {
            return Err(exit::usage(
                "--temperature-c: the calibration has no thermal expansion (thermal_k); \
                 calibrate with --thermal auto on data with temperature_c",
            ));
        }
        (None, None) => {}
    }
    let joints = backlash::joints(calibrated);
    if !joints.is_empty() {
        c.dir = [1; robocal_core::model::MAX_JOINTS];
        errln!(
            "note: the calibration models backlash on joint(s) {}: the commanded joints assume \
             every joint approaches its pose from below (moving in the positive direction; \
             dir = +1)",
            joints
                .iter()
                .map(|j| (j + 1).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    Ok(calibrated.at_conditions(&c)?)
}

/// Whether the commanded joints of `calibrated` assume every pose approached from below: the
/// calibration models backlash (see [`fold`]).
pub(super) fn approached_from_below(calibrated: &Robot) -> bool {
    !backlash::joints(calibrated).is_empty()
}

/// The output's further columns: the input's, and with `from_below` the approach directions
/// `dir1..dirN` the commanded joints assume, unless the input has them; the count of columns
/// added (each row's value +1).
pub(super) fn direction_columns(
    extra: &[String],
    dof: usize,
    from_below: bool,
) -> (Vec<String>, usize) {
    let mut columns = extra.to_vec();
    if from_below {
        for j in 0..dof {
            let name = robocal_core::simulation::direction_column(j);
            if !columns.contains(&name) {
                columns.push(name);
            }
        }
    }
    let added = columns.len() - extra.len();
    (columns, added)
}

/// A row's further values with `added` approach directions (+1) appended.
pub(super) fn with_directions(extra: &[String], added: usize) -> std::borrow::Cow<'_, [String]> {
    if added == 0 {
        return std::borrow::Cow::Borrowed(extra);
    }
    let mut v = extra.to_vec();
    v.resize(extra.len() + added, "1".to_owned());
    std::borrow::Cow::Owned(v)
}
