//! `--backlash` and `--thermal`: the families of a real cell's conditions (approach directions,
//! temperature), enabled on the model and checked against the data.

use crate::exit;
use robocal_core::identification::{selection, CalibrationData, SplitData};
use robocal_core::model::family::{backlash, thermal};
use robocal_core::Robot;
use std::path::Path;

/// Applies `--backlash auto|none|J,..` and `--thermal auto|per-link|none` to `robot` (the thermal
/// reference is set from the data by [`fit_to_data`]).
pub(super) fn apply(
    robot: &mut Robot,
    backlash_arg: Option<&str>,
    thermal_arg: Option<&str>,
) -> anyhow::Result<()> {
    let joints = super::joint_list::joint_list("--backlash", backlash_arg, robot, |r| {
        (0..r.dof()).collect()
    })?;
    backlash::enable(robot, &joints).map_err(|e| exit::usage(e.to_string()))?;
    match thermal_arg {
        Some("auto") => thermal::enable(robot, thermal::DEFAULT_REFERENCE_C),
        Some("per-link") => thermal::enable_per_link(robot, thermal::DEFAULT_REFERENCE_C),
        _ => Ok(()),
    }
    .map_err(|e| exit::usage(e.to_string()))?;
    Ok(())
}

/// The model fitted to `data` (read from `path`): with thermal expansion, its lengths referred to
/// the calibration rows' mean temperature (an error without `temperature_c`); with backlash and
/// no `dir1..dirN`, the directions derived from the row order (said on standard error).
pub(super) fn fit_to_data(
    robot: &Robot,
    data: &mut SplitData,
    path: &Path,
) -> anyhow::Result<Robot> {
    let mut r = robot.clone();
    if thermal::reference_c(&r).is_some() {
        let cd = CalibrationData {
            calibration: &data.calibration,
            plane: None,
            validation: None,
        };
        let Some(t) = selection::reference_temperature_c(&cd) else {
            return Err(exit::input(format!(
                "--thermal: {} has no temperature_c column (the arm's temperature at each \
                 row, deg C)",
                path.display()
            )));
        };
        thermal::set_reference_c(&mut r, t)?;
        errln!("thermal expansion referred to {t:.1} deg C (the calibration rows' mean)")?;
    }
    if !backlash::joints(&r).is_empty() && !data.calibration.has_directions() {
        data.calibration.derive_directions();
        errln!(
            "note: {} has no dir1..dirN: approach directions derived from the row order (the \
             motion from the previous calibration row; the first row's unknown)",
            path.display()
        )?;
    }
    Ok(r)
}
