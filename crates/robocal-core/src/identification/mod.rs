//! Identification of the calibrated parameters (paper, sections II.A and III): minimize the
//! total displacement error `sum |E_i|` (eq. 4) over the parameters the poses can identify.
//!
//! - [`split`]: a measurement file's rows sorted by role into [`Observations`]
//!   ([`crate::observations`]): calibration, validation and plane points;
//! - [`objective`]: sum of norms (eq. 4), least squares and robust losses;
//! - [`identifiability`]: which parameters are identifiable, and why the others are fixed;
//! - [`system`]: the per-observation accumulation of the normal equations (the hot loop), from
//!   the rows of the observations' measurement kind ([`kinds`], kept beside
//!   [`crate::observations`]) and the parameter families' screws ([`crate::model::family`]);
//! - [`solver`]: Levenberg–Marquardt with reweighting and a termination report;
//! - [`param_vector`]: every parameter with its name, unit, family, values and verdicts;
//! - [`covariance`]: standard deviations and correlations of the estimates;
//! - [`prediction`]: the expected error at new poses (noise plus parameter uncertainty);
//! - [`selection`], [`cross_validation`]: the model the data support, chosen by
//!   cross-validation by pose;
//! - [`pipeline`]: registration + all of the above, for the model as given ([`calibrate_model`]);
//! - [`model_choice`] and [`selection`]: which model; [`calibrate`], the entry point, chooses it
//!   (`--model auto`) and runs the pipeline;
//! - [`set_errors`]: per-point errors before and after, and the down-weighted points;
//! - [`plausibility`]: the gate run after every fit (units, handedness, nominal error, parameter
//!   moves and ranges, convergence) and the likely cause of a failure;
//! - [`bounds`]: bounded parameters (a physical compliance) held at their bound when the data
//!   cannot tell them from it;
//! - [`report`]: the result JSON.

pub mod bounds;
pub mod constraint;
pub mod covariance;
pub mod cross_validation;
pub mod folds;
pub(crate) mod householder;
pub mod identifiability;
pub mod model_choice;
pub mod objective;
pub mod param_vector;
pub mod pipeline;
pub mod plausibility;
pub mod precision;
pub mod prediction;
pub mod report;
pub mod screen;
pub mod selection;
pub mod set_errors;
pub(crate) mod simd;
pub mod solver;
pub mod split;
pub mod system;

#[cfg(test)]
mod conditioning_tests;
#[cfg(test)]
mod real_cell_tests;
#[cfg(test)]
mod selection_tests;
#[cfg(test)]
mod targets_tests;
#[cfg(test)]
mod tests;

pub use crate::observations::{kinds, Observations};
pub use covariance::{Correlation, Covariance};
pub use identifiability::{
    analyze, FixReason, FixedParam, Identifiability, IdentifiabilityOptions,
    DEFAULT_RANK_TOLERANCE, MAX_CONDITION_NUMBER, MIN_RANK_TOLERANCE,
};
pub use model_choice::{AutoFamilies, Candidate, ModelChoice, ModelSelection};
pub use objective::{Loss, Objective, RobustLoss};
pub use param_vector::{ParamEntry, ParamVector};
pub use pipeline::{
    calibrate_model, Calibration, CalibrationData, CalibrationSettings, DownWeighted, SetErrors,
    Stage,
};
pub use plausibility::{Check, CheckKind, Plausibility};
pub use prediction::{MapPoint, Prediction};
pub use selection::calibrate;
pub use solver::{solve, SolverOptions, SolverReport, Termination, MAX_ITERATIONS};
pub use split::{read_split, split_measurements, SplitData};
pub use system::Problem;
