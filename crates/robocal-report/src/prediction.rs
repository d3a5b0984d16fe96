//! The result's predicted accuracy (`prediction`, written by `robocal calibrate`) as a line of
//! the report's settings: the expected mean error at new poses, beside the measured validation
//! mean, and the range of the predicted error over the workspace map.

use crate::data::Setting;
use robocal_core::io::CalibrationResult;

/// The "Predicted accuracy" line, when the result has a prediction.
pub fn setting(result: &CalibrationResult) -> Option<Setting> {
    let p = result.prediction.as_ref()?;
    let measured = result
        .errors
        .validation
        .as_ref()
        .map(|v| format!("; validation measured {:.4} mm", v.after.mean_mm))
        .unwrap_or_default();
    let mut map: Vec<f64> = p
        .map
        .iter()
        .map(|m| m.mean_mm)
        .filter(|v| v.is_finite())
        .collect();
    map.sort_by(f64::total_cmp);
    let over = match (map.first(), map.get(map.len() / 2), map.last()) {
        (Some(lo), Some(mid), Some(hi)) => format!(
            "; over the workspace ({} poses) {lo:.4} / {mid:.4} / {hi:.4} mm (min / median / max)",
            map.len()
        ),
        _ => String::new(),
    };
    Some(Setting::new(
        "Predicted accuracy",
        format!(
            "mean {:.4} mm (std {:.4} mm) at new poses like the calibration poses: noise {:.4} \
             mm per axis, parameter uncertainty {:.4} mm RMS{measured}{over}",
            p.mean_mm, p.std_mm, p.noise_sigma_mm, p.model_rms_mm
        ),
    ))
}
