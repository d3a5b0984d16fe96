//! Which model a calibration fits (`--model`): the robot as given, or the families the data
//! support, and the outcome of that choice ([`super::selection`] makes it).

use crate::model::Robot;

/// Which model a calibration fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ModelChoice {
    /// The robot as given, with the families it has (`--model geometric` and explicit flags).
    #[default]
    Given,
    /// Choose the families the data support (see the module docs).
    Auto(AutoFamilies),
}

/// The families the automatic choice selects; a family the user fixed is not selected (the
/// given robot carries it, or not, in every candidate).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AutoFamilies {
    /// Select the transmission harmonics (none, 1 or 2 per revolute joint).
    pub harmonics: bool,
    /// Select joint compliance under gravity (none, or every joint `compliance auto` takes).
    pub compliance: bool,
    /// Select backlash on every revolute joint (tried only when the calibration data have
    /// approach directions).
    pub backlash: bool,
    /// Select thermal expansion (tried only when the calibration data have temperatures).
    pub thermal: bool,
}

impl Default for AutoFamilies {
    fn default() -> Self {
        AutoFamilies {
            harmonics: true,
            compliance: true,
            backlash: true,
            thermal: true,
        }
    }
}

/// One candidate model and its cross-validation.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Its non-geometric families, e.g. `["compliance", "harmonics 2"]` (empty: geometric).
    pub families: Vec<String>,
    /// Parameters its full fit identified (a screened candidate's: those its fit would start
    /// from, before any compliance held at its bound).
    pub identified: usize,
    /// Cross-validated mean position error (mm); `None` when the candidate was rejected before
    /// (its full fit failed, did not converge or failed the plausibility gate).
    pub cv_mean_mm: Option<f64>,
    /// Its standard error (mm).
    pub cv_std_error_mm: Option<f64>,
    /// Why it cannot be chosen (fit failed, did not converge, failed the plausibility gate).
    pub rejected: Option<String>,
    /// Whether it is the chosen model.
    pub chosen: bool,
    /// Whether its cross-validated error is estimated from the fit of the model it extends
    /// instead of a fit of its own ([`crate::identification::screen`]): far from lowering that
    /// model's error, it was not fitted (it is never the chosen model).
    pub screened: bool,
    /// A model compared but never chosen: the geometric model, beside families the user gave
    /// explicitly, to tell whether they lower the error at all ([`ModelSelection::remark`]).
    pub reference: bool,
}

impl Candidate {
    /// Its name for tables: `geometric` or `geometric + ...`.
    pub fn name(&self) -> String {
        if self.families.is_empty() {
            "geometric".into()
        } else {
            format!("geometric + {}", self.families.join(" + "))
        }
    }
}

/// The outcome of the automatic choice.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSelection {
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Every candidate, simplest first.
    pub candidates: Vec<Candidate>,
    /// The chosen model (the robot to calibrate).
    pub robot: Robot,
    /// Set when the families the user gave explicitly do not lower the cross-validated error
    /// below the geometric model's (the reference candidate) by more than their standard error:
    /// they likely fit the noise.
    pub remark: Option<String>,
}

impl ModelSelection {
    /// The chosen candidate.
    pub fn chosen(&self) -> &Candidate {
        self.candidates
            .iter()
            .find(|c| c.chosen)
            .expect("one candidate is chosen")
    }
}
