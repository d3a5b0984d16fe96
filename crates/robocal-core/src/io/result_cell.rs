//! Result sections for 6-DoF data: orientation errors (deg). (The tool points fitted before
//! identification and the validation's own frame belong to the registration section,
//! [`super::result_sections::Registration`].)

use crate::stats::ErrorStats;
use serde::{Deserialize, Serialize};

/// Statistics of orientation errors (deg): the angle of `R_meas R_model^T`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AngleStats {
    /// Number of observations.
    pub n: usize,
    /// Mean (deg).
    pub mean_deg: f64,
    /// Sample standard deviation (deg).
    pub std_deg: f64,
    /// Largest (deg).
    pub max_deg: f64,
    /// Root mean square (deg).
    pub rms_deg: f64,
}

impl AngleStats {
    /// The statistics of `angles` (deg).
    pub fn of(angles: &[f64]) -> AngleStats {
        let s = ErrorStats::from_norms(angles);
        AngleStats {
            n: s.n,
            mean_deg: s.mean_mm,
            std_deg: s.std_mm,
            max_deg: s.max_mm,
            rms_deg: s.rms_mm,
        }
    }
}

/// Orientation errors before and after calibration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AngleBeforeAfter {
    /// Nominal model.
    pub before: AngleStats,
    /// Calibrated model.
    pub after: AngleStats,
}

/// The `orientation_errors` object (6-DoF data only).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrientationErrors {
    /// On the calibration points.
    pub calibration: AngleBeforeAfter,
    /// On the validation points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation: Option<AngleBeforeAfter>,
}
