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
