//! The result's `payload_kg` key: the payload (kg) the measurements were taken with, written when
//! the joint compliance family identified physical compliances
//! ([`crate::model::family::compliance`]); reading the result sets the calibrated model's payload
//! to it, so that its deflection is the one that was fitted until another payload is given.

use crate::error::{Error, Result};
use crate::io::CalibrationResult;
use crate::model::family::compliance;
use crate::model::Robot;
use std::path::Path;

/// The key.
pub const KEY: &str = "payload_kg";

/// Writes `payload_kg` into `result` when `calibrated` has physical compliances.
pub fn record(result: &mut CalibrationResult, calibrated: &Robot) {
    if let Some(m) = compliance::payload_kg(calibrated) {
        result.extra.insert(KEY.to_owned(), serde_json::json!(m));
    }
}

/// Sets the payload of `robot` (the result's calibrated model) from the result's `payload_kg`.
/// A model with physical compliances needs the key (a positive mass); a model without must not
/// have it.
pub fn apply(result: &CalibrationResult, robot: &mut Robot, path: &Path) -> Result<()> {
    let bad = |msg: String| Error::parse(path, None, Some(KEY), msg);
    let value = result.extra.get(KEY);
    let physical = compliance::payload_kg(robot).is_some();
    match (value, physical) {
        (None, false) => Ok(()),
        (Some(_), false) => Err(bad(
            "the result has no `compliance{j}` parameter: a payload belongs to a calibration \
             with joint compliances"
                .to_owned(),
        )),
        (None, true) => Err(bad(
            "missing: the `compliance{j}` parameters were identified at a payload this key \
             gives (kg)"
                .to_owned(),
        )),
        (Some(v), true) => {
            let m = v
                .as_f64()
                .ok_or_else(|| bad(format!("{v} is not a number of kg")))?;
            if m.is_nan() || m <= 0.0 {
                return Err(bad(format!("{m} kg: the payload must be positive")));
            }
            compliance::set_payload_kg(robot, m).map_err(|e| bad(e.to_string()))
        }
    }
}
