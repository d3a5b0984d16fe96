//! The result's `prediction` section: the expected error at new poses spread like the calibration
//! poses, and a map of the predicted error over the workspace
//! ([`crate::identification::prediction`]).

use crate::identification::prediction::Prediction;
use crate::io::result_sections::nullable;
use serde::{Deserialize, Serialize};

/// `prediction` (DESIGN.md "Result JSON additions").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PredictionSection {
    /// The predicted error at random poses of the workspace.
    #[serde(
        default,
        serialize_with = "crate::io::result::deferred::map",
        deserialize_with = "crate::io::result_skim::list"
    )]
    pub map: Vec<MapEntry>,
    /// Expected mean error norm at new poses spread like the calibration poses (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub mean_mm: f64,
    /// RMS error the parameters' uncertainty alone leaves at those poses (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub model_rms_mm: f64,
    /// Per-axis measurement noise the prediction assumes (mm), from the calibration residuals.
    #[serde(deserialize_with = "nullable::f64")]
    pub noise_sigma_mm: f64,
    /// Expected RMS error norm (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub rms_mm: f64,
    /// Spread (standard deviation) of the error norm over such poses (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub std_mm: f64,
}

/// One point of `prediction.map`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MapEntry {
    /// Expected error norm of a measurement there (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub mean_mm: f64,
    /// RMS error of the model alone there (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub model_mm: f64,
    /// Tool position, base frame (mm).
    pub x: f64,
    /// Tool position, base frame (mm).
    pub y: f64,
    /// Tool position, base frame (mm).
    pub z: f64,
}

impl From<&Prediction> for PredictionSection {
    fn from(p: &Prediction) -> Self {
        PredictionSection {
            mean_mm: p.mean_mm,
            std_mm: p.std_mm,
            rms_mm: p.rms_mm,
            noise_sigma_mm: p.noise_sigma_mm,
            model_rms_mm: p.model_rms_mm,
            map: p
                .map
                .iter()
                .map(|m| MapEntry {
                    x: m.position.x,
                    y: m.position.y,
                    z: m.position.z,
                    mean_mm: m.mean_mm,
                    model_mm: m.model_mm,
                })
                .collect(),
        }
    }
}
