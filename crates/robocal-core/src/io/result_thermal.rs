//! The result's `reference_temperature_c` key: the temperature (deg C) at which the calibrated
//! model's lengths hold, written when the model has the thermal expansion family
//! ([`crate::model::family::thermal`]); reading the result sets the calibrated model's reference
//! to it.

use crate::error::{Error, Result};
use crate::io::CalibrationResult;
use crate::model::family::thermal;
use crate::model::Robot;
use std::path::Path;

/// The key.
pub const KEY: &str = "reference_temperature_c";

/// Writes `reference_temperature_c` into `result` when `calibrated` models thermal expansion.
pub fn record(result: &mut CalibrationResult, calibrated: &Robot) {
    if let Some(t) = thermal::reference_c(calibrated) {
        result.extra.insert(KEY.to_owned(), serde_json::json!(t));
    }
}

/// Sets the reference temperature of `robot` (the result's calibrated model) from the result's
/// `reference_temperature_c`. A model with the `thermal_k` parameter needs the key; a model
/// without must not have it.
pub fn apply(result: &CalibrationResult, robot: &mut Robot, path: &Path) -> Result<()> {
    let bad = |msg: String| Error::parse(path, None, Some(KEY), msg);
    match (result.extra.get(KEY), thermal::reference_c(robot).is_some()) {
        (None, false) => Ok(()),
        (Some(_), false) => Err(bad(
            "the result has no `thermal_k` parameter: a reference temperature belongs to a \
             calibration with thermal expansion"
                .to_owned(),
        )),
        (None, true) => Err(bad(
            "missing: the `thermal_k` parameter refers the lengths to a temperature this key \
             gives (deg C)"
                .to_owned(),
        )),
        (Some(v), true) => {
            let t = v
                .as_f64()
                .ok_or_else(|| bad(format!("{v} is not a temperature (deg C)")))?;
            thermal::set_reference_c(robot, t).map_err(|e| bad(e.to_string()))
        }
    }
}
