//! The true robot of a simulation expressed in the parameters a calibration identified, so that
//! each calibrated value has a true value to be compared with.
//!
//! A calibration cannot recover the true value of a parameter it fixes: `d1` stays nominal and
//! `base_z` absorbs its error, `d6` and `phi6` go into the tool position, and so on (see
//! [`crate::identification::identifiability`]). The base frame also absorbs the error of the
//! fitted measurement frame. Compared parameter by parameter with the raw truth, a perfect
//! calibration would look wrong. The *equivalent truth* is the model the calibration would find
//! from exact measurements of the true geometry: the nominal robot with the same parameters
//! fixed, the identified ones fitted by least squares to the true tool points (no deflection, no
//! noise), read through the same fitted measurement frame.

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::identification::{
    solve, Calibration, Loss, Observations, Problem, SolverOptions, Termination,
};
use crate::model::Robot;
use crate::stats::ErrorStats;

/// The truth expressed in the calibration's parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthComparison {
    /// The equivalent truth: the nominal robot with the calibration's fixed parameters at their
    /// nominal values and its identified parameters fitted to the true geometry.
    pub equivalent: Robot,
    /// Largest distance between the equivalent model and the true tool points it was fitted to
    /// (mm): close to zero when the fixed parameters' effects are absorbed exactly.
    pub fit_max_mm: f64,
    /// Distance between the calibrated model's and the equivalent truth's tool points at the
    /// check poses (mm): how far the calibrated geometry is from the true one.
    pub model_error: ErrorStats,
}

/// Expresses `truth` in the parameters of `calibration` (see the module docs). The tracker of
/// the simulation stands at `tracker` (its true pose in the base frame); the equivalent is fitted
/// at the poses of `fit` and `check`, and the calibrated model is compared with it at the poses
/// of `check` (e.g. the validation points).
pub fn compare_with_truth(
    calibration: &Calibration,
    truth: &Robot,
    tracker: &TrackerFrame,
    fit: &Observations,
    check: &Observations,
) -> Result<TruthComparison> {
    let nominal = &calibration.nominal;
    // Exact tracker readings of the true geometry at every pose.
    let mut exact = Observations::new(nominal.dof());
    for obs in [fit, check] {
        for i in 0..obs.len() {
            let p = truth.tool_position(obs.q(i));
            exact.push(obs.q(i), tracker.to_tracker(&p), obs.line(i))?;
        }
    }
    let frame = calibration.tracker_frame();
    let problem = Problem::new(
        nominal,
        &calibration.identifiability.identified,
        &exact,
        frame,
    );
    let mut equivalent = nominal.clone();
    let report = solve(
        &problem,
        &mut equivalent,
        &Loss::Squared,
        &SolverOptions::default(),
        &(),
    );
    if let Termination::Failed(m) = &report.termination {
        return Err(Error::Numerical(format!(
            "expressing the truth in the identified parameters failed: {m}"
        )));
    }
    let fit_max_mm = problem
        .error_norms(&equivalent)
        .into_iter()
        .fold(0.0, f64::max);
    let diffs: Vec<f64> = (0..check.len())
        .map(|i| {
            (calibration.calibrated.tool_position(check.q(i))
                - equivalent.tool_position(check.q(i)))
            .norm()
        })
        .collect();
    Ok(TruthComparison {
        equivalent,
        fit_max_mm,
        model_error: ErrorStats::from_norms(&diffs),
    })
}
