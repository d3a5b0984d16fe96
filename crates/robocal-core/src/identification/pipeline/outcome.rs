//! The pipeline's last steps: the uncertainty of the estimates, the errors before and after
//! (Tables II and IV), the predicted accuracy, the validation and the plausibility gate.

use super::identify::Identified;
use super::stages::Solved;
use super::start::StartModel;
use super::{
    check_same_station, whole_solve, Calibration, CalibrationData, CalibrationSettings, Job,
    Purpose,
};
use crate::error::Result;
use crate::identification::covariance::Covariance;
use crate::identification::objective::{robust_sigma, ROBUST_SCALE_SIGMAS};
use crate::identification::plausibility::{self, Plausibility};
use crate::identification::prediction::{predict, predict_for_candidate, Prediction};
use crate::identification::set_errors::{DownWeighted, SetErrors};
use crate::identification::system::{Level, Problem};
use crate::model::Robot;
use crate::progress;

/// The validation points' errors, and the frame fitted to them of their own when they come from
/// another station.
type ValidationErrors = (Option<SetErrors>, Option<crate::frame::TrackerFrame>);

/// The fit's errors and prediction, as the gate reads them.
#[derive(Clone, Copy)]
struct Errors<'e> {
    calibration: &'e SetErrors,
    validation: Option<&'e SetErrors>,
    prediction: Option<&'e Prediction>,
    downweighted: usize,
}

/// Everything after the solve, into one [`Calibration`].
pub(super) fn assemble(
    job: &Job,
    start: StartModel,
    identified: Identified,
    mut solved: Solved,
) -> Result<Calibration> {
    let Job {
        nominal,
        data,
        settings,
        purpose,
        observer,
        shape: _,
    } = *job;
    let data = &data;
    let problem = Problem::new(
        &start.robot,
        &identified.identifiability.identified,
        &start.observations,
        &start.frame,
    );
    let robot = &solved.robot;
    observer.progress(progress::Stage::Uncertainty, 0, 1);
    let fold_passes = solved.final_pass.as_mut().and_then(|p| p.groups.take());
    // The solver's last pass when it is at the solution, else a pass of its own.
    let acc = match &solved.final_pass {
        Some(pass) => std::borrow::Cow::Borrowed(pass),
        None => std::borrow::Cow::Owned(problem.accumulate(robot, &solved.loss, Level::Full)),
    };
    let mut covariance = Covariance::from_accumulated(&identified.identifiability.identified, &acc);
    if let Some(why) = &identified.ill_conditioned {
        covariance.mark_unavailable(why.clone());
    }
    let cal = &start.observations;
    let calibration =
        SetErrors::of_calibration(cal, &start.registration, nominal, &start.frame, robot);
    // Points beyond the robust threshold are outliers, not noise a new measurement shares.
    let threshold = solved.robust_scale.unwrap_or_else(|| {
        ROBUST_SCALE_SIGMAS * robust_sigma(&calibration.after, problem.kind().rows())
    });
    let prediction = match purpose {
        Purpose::Result => predict(robot, &covariance, cal, &calibration.after, Some(threshold)),
        // Only the candidate's gate reads it (see `predict_for_candidate`).
        Purpose::Candidate => {
            predict_for_candidate(robot, &covariance, cal, &calibration.after, Some(threshold))
        }
    };
    let (validation, validation_frame) = validation_errors(nominal, data, settings, &start, robot)?;
    let downweighted = solved.robust_scale.map_or_else(Vec::new, |c| {
        // The reweighting's last norms, else the last pass's, else a pass of their own.
        let norms = match solved.final_norms.as_ref().or(acc.norms.as_ref()) {
            Some(n) => std::borrow::Cow::Borrowed(n),
            None => std::borrow::Cow::Owned(problem.fit_norms(robot)),
        };
        DownWeighted::list(&norms, &calibration, &solved.loss, c)
    });
    observer.progress(progress::Stage::Plausibility, 0, 1);
    let errors = Errors {
        calibration: &calibration,
        validation: validation.as_ref(),
        prediction: prediction.as_ref(),
        downweighted: downweighted.len(),
    };
    let plausibility = gate(job, &start, &identified, &solved, &errors);
    // A candidate keeps its last pass for its completion ([`super::complete`]).
    let own_pass = match acc {
        std::borrow::Cow::Owned(pass) => Some(pass),
        std::borrow::Cow::Borrowed(_) => None,
    };
    let last_pass = match purpose {
        Purpose::Candidate => own_pass.or(solved.final_pass.take()),
        Purpose::Result => None,
    };
    Ok(Calibration {
        nominal: nominal.clone(),
        calibrated: solved.robot,
        registration: start.registration,
        tool_fit: start.tool_fit,
        frame: start.frame,
        identifiability: identified.identifiability,
        stages: solved.stages,
        covariance,
        prediction,
        calibration,
        validation,
        validation_frame,
        robust_scale_mm: solved.robust_scale,
        downweighted,
        plausibility,
        settings: settings.clone(),
        weighting: start.weighting,
        model_selection: None,
        fold_passes,
        last_pass,
    })
}

/// The validation points' errors under the calibrated model `robot`: in the calibration's
/// frame (failing when they look measured from another station), or in a frame of their own
/// when the settings say they are.
fn validation_errors(
    nominal: &Robot,
    data: &CalibrationData,
    settings: &CalibrationSettings,
    start: &StartModel,
    robot: &Robot,
) -> Result<ValidationErrors> {
    match data.validation.filter(|v| !v.is_empty()) {
        None => Ok((None, None)),
        Some(v) if settings.validation_refit_frame => {
            let (e, f) = SetErrors::refit(v, nominal, robot)?;
            Ok((Some(e), Some(f)))
        }
        Some(v) => {
            let e = SetErrors::new(v, &start.registration, nominal, &start.frame, robot);
            check_same_station(v, &e, robot)?;
            Ok((Some(e), None))
        }
    }
}

/// The plausibility gate on the fit. It judges the model the identification started from (the
/// nominal geometry with the fitted tools): Table II's second line, and the validation points
/// under it.
fn gate(
    job: &Job,
    start: &StartModel,
    identified: &Identified,
    solved: &Solved,
    errors: &Errors,
) -> Plausibility {
    let Job {
        nominal,
        data,
        settings,
        shape,
        ..
    } = *job;
    let Errors {
        calibration,
        validation,
        prediction,
        downweighted,
    } = *errors;
    let tool_fit = &start.tool_fit;
    let (nominal_rms_mm, validation_start) = if tool_fit.applied {
        let v = data
            .validation
            .filter(|v| !v.is_empty() && !settings.validation_refit_frame)
            .map(|v| Problem::new(&start.robot, &[], v, &start.frame).error_norms(&start.robot));
        (tool_fit.stats.rms_mm, v)
    } else {
        (start.registration.stats.rms_mm, None)
    };
    let fit = plausibility::Fit {
        nominal,
        start: &start.robot,
        calibrated: &solved.robot,
        identified: &identified.identifiability.identified,
        calibration: &start.observations,
        registration: &start.registration,
        nominal_rms_mm,
        validation_before: validation_start
            .as_deref()
            .or(validation.map(|v| v.before.as_slice())),
        validation_after: validation.map(|v| v.after.as_slice()),
        calibration_before: if tool_fit.applied {
            &tool_fit.residuals
        } else {
            &calibration.before
        },
        downweighted,
        prediction_mean_mm: prediction.map(|p| p.mean_mm),
        noise_sigma_mm: prediction.map(|p| p.noise_sigma_mm),
        solver: &whole_solve(&solved.stages),
        max_iterations: settings.solver.max_iterations,
    };
    plausibility::assess_with(&fit, shape)
}
