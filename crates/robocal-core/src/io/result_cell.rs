//! Result sections for what a real cell adds (issue: several reflectors, 6-DoF data, new
//! stations): orientation errors of 6-DoF data, the tool points fitted before identification
//! (Table II with the fitted tool) and the frame validation points fitted of their own.

use crate::io::result_sections::FrameVec;
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

/// `registration.tool_fit`: the frame and tool vectors fitted to the nominal geometry before
/// identification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToolFitEntry {
    /// The frame fitted with the tools (the result's `tracker_frame`).
    pub frame: FrameVec,
    /// Every target's fitted tool vector (mm, deg).
    pub tools: Vec<[f64; 6]>,
    /// Alternations run.
    pub iterations: usize,
    /// Whether they converged.
    pub converged: bool,
    /// Whether the calibration started from them (not when the nominal geometry misses the
    /// data by more than the plausibility gate's nominal-error limit).
    #[serde(default)]
    pub applied: bool,
    /// Errors of the nominal geometry with the fitted tools (Table II with the fitted tool).
    pub stats: ErrorStats,
}
