//! The result's `model_selection` section: the automatic model choice (`--model auto`), each
//! candidate with its cross-validated error.

use crate::identification::ModelSelection;
use serde::{Deserialize, Serialize};

/// One candidate model (`model_selection.candidates[]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateEntry {
    /// Its non-geometric families (empty: the geometric model), e.g. `["harmonics 2"]`.
    pub families: Vec<String>,
    /// Parameters its fit to all calibration points identified (when `screened`, those its fit
    /// would start from).
    pub identified: usize,
    /// Cross-validated mean position error (mm); null when it could not be fitted.
    #[serde(default)]
    pub cv_mean_mm: Option<f64>,
    /// Standard error of that mean (mm).
    #[serde(default)]
    pub cv_std_error_mm: Option<f64>,
    /// Why it could not be chosen, if so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rejected: Option<String>,
    /// Whether it is the chosen model.
    pub chosen: bool,
    /// Its cross-validated error estimated from the fit of the model it extends, not fitted
    /// (far from lowering that model's error).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub screened: bool,
    /// A model compared but never chosen (the geometric model beside explicit families).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reference: bool,
}

/// `model_selection`: how the model was chosen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSelectionSection {
    /// How: `cross-validation by pose, one-standard-error rule`.
    pub method: String,
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Every candidate, simplest first.
    pub candidates: Vec<CandidateEntry>,
    /// Why the families given explicitly look like overfitting, if they do.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub remark: Option<String>,
}

impl ModelSelectionSection {
    /// The section of a selection.
    pub fn of(s: &ModelSelection) -> ModelSelectionSection {
        ModelSelectionSection {
            method: "cross-validation by pose, one-standard-error rule".into(),
            folds: s.folds,
            candidates: s
                .candidates
                .iter()
                .map(|c| CandidateEntry {
                    families: c.families.clone(),
                    identified: c.identified,
                    cv_mean_mm: c.cv_mean_mm,
                    cv_std_error_mm: c.cv_std_error_mm,
                    rejected: c.rejected.clone(),
                    chosen: c.chosen,
                    screened: c.screened,
                    reference: c.reference,
                })
                .collect(),
            remark: s.remark.clone(),
        }
    }
}
