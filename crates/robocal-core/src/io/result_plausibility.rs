//! The result's `plausibility` section (the gate's checks and, for a failure, the likely causes),
//! as typed structs (moved out of [`super::result_sections`], whose [`nullable`] numbers they use).

use super::result_sections::nullable;
use serde::{Deserialize, Serialize};

/// One check of the plausibility gate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckEntry {
    /// The likely cause of a failure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cause: Option<String>,
    /// In words.
    pub detail: String,
    /// Its limit.
    #[serde(deserialize_with = "nullable::f64")]
    pub limit: f64,
    /// The measured value (`null` when not finite).
    #[serde(deserialize_with = "nullable::f64")]
    pub measured: f64,
    /// Its name.
    pub name: String,
    /// Whether it passed.
    pub passed: bool,
    /// Their unit.
    pub unit: String,
}

/// A likely cause of an implausible fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CauseEntry {
    /// In words.
    pub cause: String,
    /// RMS of the nominal model's fit under this explanation (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub fit_rms_mm: f64,
    /// A joint mistake that explains the fit.
    pub joints: Option<String>,
    /// Whether the points are mirrored.
    pub mirrored: bool,
    /// Scale of the points to the model.
    #[serde(deserialize_with = "nullable::f64")]
    pub scale: f64,
    /// A length unit that explains the scale.
    pub unit: Option<String>,
}

/// `plausibility`: the gate's checks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlausibilitySection {
    /// The checks.
    pub checks: Vec<CheckEntry>,
    /// Likely causes of a failure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub likely_causes: Option<Vec<CauseEntry>>,
    /// Whether every check passed.
    pub passed: bool,
    /// The robot's reach (mm).
    pub reach_mm: f64,
}
