//! The whole calibration of the paper's sections II.C and III: registration of the measurement
//! frame, identifiability, identification (eq. 4), uncertainty, and the error tables before and
//! after (Tables II and IV).
//!
//! The tracker frame F and the robot's base frame B are the same unknown seen twice. As in the
//! paper, F is fitted once to the nominal model (registration) and then held, and B (six
//! parameters) is identified with the rest, absorbing whatever rigid motion remains. The result's
//! `tracker_frame` is that F, and the calibrated model includes B, so that
//! `pose(tracker_frame) * m` compared with the calibrated model's tool point gives the "after"
//! errors, for the calibration and for the validation points alike.

use crate::error::{Error, Result};
use crate::identification::bounds;
use crate::identification::covariance::Covariance;
use crate::identification::identifiability::{
    analyze_reduced, jacobian_r, FixReason, Identifiability, IdentifiabilityOptions,
    MAX_CONDITION_NUMBER, MIN_RANK_TOLERANCE,
};
use crate::identification::model_choice::{ModelChoice, ModelSelection};
use crate::identification::objective::{
    robust_sigma, Loss, Objective, RobustLoss, ADAPTIVE_THRESHOLD_SIGMAS, ROBUST_SCALE_SIGMAS,
    SUM_OF_NORMS_SMOOTHING_MM,
};
use crate::identification::param_vector::ParamVector;
use crate::identification::plausibility::{self, Plausibility};
use crate::identification::precision;
use crate::identification::prediction::{predict, Prediction};
pub use crate::identification::set_errors::{DownWeighted, SetErrors};
use crate::identification::solver::{solve, SolverOptions, SolverReport, Termination};
use crate::identification::system::{Level, Problem};
use crate::model::Robot;
use crate::observations::AppliedWeighting;
use crate::observations::Observations;
use crate::observations::Weighting;
use crate::progress::{self, Observer};
use crate::registration::{
    fit_tools, register, Registration, RegistrationObjective, RegistrationOptions, ToolFit,
};

/// Everything that steers a calibration.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CalibrationSettings {
    /// The objective (default: [`Objective::Adaptive`]; the paper's is
    /// [`Objective::SumOfNorms`]).
    pub objective: Objective,
    /// Scale of the robust loss (mm); `None`: from the residuals (see [`RobustLoss`]).
    pub robust_scale_mm: Option<f64>,
    /// Also fit and report the paper's affine Tr (eq. 8-11).
    pub affine_registration: bool,
    /// Identifiability threshold and `--fix`/`--free`.
    pub identifiability: IdentifiabilityOptions,
    /// Solver settings.
    pub solver: SolverOptions,
    /// How observations are weighted (uncertainties, tracker model, orientation rows).
    pub weighting: Weighting,
    /// The validation points were measured from another tracker station: fit them a frame of
    /// their own (the errors then show the model's shape, not where the tracker stood).
    pub validation_refit_frame: bool,
    /// Which model to fit: the robot as given, or the families the data support
    /// ([`super::selection`]).
    pub model: ModelChoice,
}

/// The measured points of a calibration.
#[derive(Debug, Clone, Copy)]
pub struct CalibrationData<'a> {
    /// Points the parameters are identified from (the paper's 75).
    pub calibration: &'a Observations,
    /// The paper's plane points for the initial frame (3), if measured.
    pub plane: Option<&'a Observations>,
    /// Points held out to validate the calibrated model (the paper's 73), if any.
    pub validation: Option<&'a Observations>,
}

/// One solver run of the identification.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage {
    /// The loss minimized.
    pub loss: Loss,
    /// What the solver did.
    pub report: SolverReport,
}

/// The outcome of [`calibrate_model`].
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The nominal model (as given, beta parameters included).
    pub nominal: Robot,
    /// The calibrated model.
    pub calibrated: Robot,
    /// The fitted measurement frame and Table II.
    pub registration: Registration,
    /// The frame and tool points fitted to the nominal geometry before identification (Table
    /// II with the fitted tool); its frame is the one the identification holds, the result's
    /// tracker frame.
    pub tool_fit: ToolFit,
    /// The frame the identification held (the tool fit's when it was applied, else the
    /// registration's): the result's `tracker_frame`.
    pub frame: crate::frame::TrackerFrame,
    /// Which parameters were identified, which fixed and why.
    pub identifiability: Identifiability,
    /// The solver runs, in order (robust and adaptive objectives start from a least-squares fit, or
    /// a sum-of-norms fit where the nominal geometry misses the data).
    pub stages: Vec<Stage>,
    /// Uncertainty of the identified parameters.
    pub covariance: Covariance,
    /// The predicted accuracy at new poses spread like the calibration poses (`None` when the
    /// standard deviations are unavailable).
    pub prediction: Option<Prediction>,
    /// Errors on the calibration points.
    pub calibration: SetErrors,
    /// Errors on the validation points.
    pub validation: Option<SetErrors>,
    /// The frame fitted to the validation points of their own, when they come from another
    /// tracker station ([`CalibrationSettings::validation_refit_frame`]).
    pub validation_frame: Option<crate::frame::TrackerFrame>,
    /// The robust loss's scale (mm), for robust objectives.
    pub robust_scale_mm: Option<f64>,
    /// Points whose error exceeds the robust scale (Cauchy weight below 1/2, Huber weight below
    /// 1), largest error first.
    pub downweighted: Vec<DownWeighted>,
    /// The plausibility gate's outcome (see [`plausibility`]): a converged fit that fails it is
    /// not a calibration.
    pub plausibility: Plausibility,
    /// The settings used.
    pub settings: CalibrationSettings,
    /// The weighting the fit used (with an automatic tracker model, which).
    pub weighting: AppliedWeighting,
    /// The automatic model choice, when the settings asked for it.
    pub model_selection: Option<ModelSelection>,
}

impl Calibration {
    /// The tracker frame of the calibrated model (the frame the identification held): a
    /// measured point m maps to `tracker_frame().to_base(m)`.
    pub fn tracker_frame(&self) -> &crate::frame::TrackerFrame {
        &self.frame
    }

    /// The last solver run.
    pub fn solver(&self) -> &SolverReport {
        &self.stages.last().expect("at least one stage").report
    }

    /// The whole solve, every stage together (see [`whole_solve`]).
    pub fn whole_solve(&self) -> SolverReport {
        whole_solve(&self.stages)
    }

    /// Every parameter with its values and verdicts (see [`ParamVector`]).
    pub fn param_vector(&self) -> ParamVector {
        ParamVector::of_calibration(
            &self.nominal,
            &self.calibrated,
            &self.identifiability,
            &self.covariance,
        )
    }
}

/// Runs a calibration of `nominal` as given, whatever `settings.model` says (see the module
/// docs; [`crate::identification::calibrate`] chooses the model first). `observer` hears the
/// stages (registration, identifiability, the solver's iterations per objective, uncertainty,
/// plausibility) as the work advances.
///
/// A bounded parameter (a physical compliance) that the fit puts just beyond its bound is held
/// at it and the calibration repeated ([`bounds`]).
pub fn calibrate_model(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
) -> Result<Calibration> {
    let first = calibrate_once(nominal, data, settings, observer)?;
    let start = if first.tool_fit.applied {
        first.tool_fit.apply(nominal)
    } else {
        nominal.clone()
    };
    let held = bounds::to_hold(&start, &first.calibrated, &first.covariance);
    if held.is_empty() {
        return Ok(first);
    }
    let mut again = settings.clone();
    again
        .identifiability
        .fix
        .extend(held.iter().map(|h| h.param));
    let mut c = calibrate_once(nominal, data, &again, observer)?;
    for f in &mut c.identifiability.fixed {
        if let Some(h) = held.iter().find(|h| h.param == f.param) {
            f.reason = FixReason::AtBound {
                value: h.value,
                std: h.std,
                bound: h.bound,
            };
        }
    }
    c.settings = settings.clone();
    Ok(c)
}

fn calibrate_once(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
) -> Result<Calibration> {
    let cal = data.calibration;
    for obs in [Some(cal), data.plane, data.validation]
        .into_iter()
        .flatten()
    {
        if obs.dof() != nominal.dof() {
            return Err(Error::JointCount {
                context: obs
                    .source()
                    .map_or("measurements".into(), |p| p.display().to_string()),
                expected: nominal.dof(),
                got: obs.dof(),
            });
        }
    }
    if cal.is_empty() {
        return Err(Error::invalid("calibration data", "no calibration points"));
    }
    for obs in [Some(cal), data.plane, data.validation]
        .into_iter()
        .flatten()
    {
        obs.check_targets(nominal)?;
    }
    cal.check_no_duplicate_poses()?;
    let idopts = &settings.identifiability;
    if let Some(p) = idopts.fix.iter().find(|p| idopts.free.contains(p)) {
        return Err(Error::invalid(
            "identifiability.fix",
            format!(
                "`{}` is given both to `identifiability.fix` and to `identifiability.free`",
                p.name()
            ),
        ));
    }
    if !(idopts.rank_tolerance >= MIN_RANK_TOLERANCE && idopts.rank_tolerance < 1.0) {
        return Err(Error::invalid(
            "identifiability.rank_tolerance",
            format!(
                "{:e} is not in [{MIN_RANK_TOLERANCE:e}, 1): it is the smallest independence \
                 (sine of the angle between a parameter's effect and the others') accepted, and \
                 below {MIN_RANK_TOLERANCE:e} double precision cannot tell a parameter from an \
                 exact duplicate (whose independence computes as 1e-17 to 1e-14 from rounding)",
                idopts.rank_tolerance
            ),
        ));
    }
    if let Some(c) = settings.robust_scale_mm {
        if !(c > 0.0 && c.is_finite()) {
            return Err(Error::invalid(
                "robust_scale_mm",
                format!("{c} is not a positive length (mm)"),
            ));
        }
    }

    observer.progress(progress::Stage::Registration, 0, 1);
    let reg_opts = RegistrationOptions {
        objective: match settings.objective {
            Objective::LeastSquares => RegistrationObjective::LeastSquares,
            _ => RegistrationObjective::SumOfNorms,
        },
        affine: settings.affine_registration,
        ..Default::default()
    };
    let registration = register(nominal, cal, data.plane, &reg_opts)?;
    let mut tool_fit = fit_tools(nominal, cal, &registration.frame)?;
    // Only where the nominal geometry with the fitted tools fits the data as a calibration's
    // start can (the gate's nominal-error limit): on data in the wrong unit or of another robot
    // the fitted tools mean nothing, and the gate names the cause.
    tool_fit.applied = tool_fit.converged
        && tool_fit.stats.rms_mm
            <= plausibility::NOMINAL_ERROR_LIMIT * plausibility::reach_mm(nominal);
    // The weights, from here on: the registration and the tool fit weight no point, and the
    // automatic tracker model needs what they tell (where the tracker stands, whether the
    // nominal model fits the data at all).
    let weighting =
        settings
            .weighting
            .resolve(cal, registration.frame.origin().norm(), tool_fit.applied);
    let weighted = Weighting {
        tracker: weighting.tracker,
        ..settings.weighting
    }
    .apply(cal)?;
    let cal = &weighted;
    // The identification starts from the nominal geometry with the fitted tools, in the frame
    // fitted with them: neither it nor the identifiability depends on the nominal tool's guess.
    let (start, frame) = if tool_fit.applied {
        (tool_fit.apply(nominal), tool_fit.frame)
    } else {
        (nominal.clone(), registration.frame)
    };

    observer.progress(progress::Stage::Identifiability, 0, 1);
    let reduced = jacobian_r(&start, cal);
    let mut ident = analyze_reduced(&start, cal, idopts, &reduced)?;
    // Parameters independent in principle that these data cannot pin (precision.rs).
    // Only with the tools fitted (see above): otherwise the bound means nothing.
    let sigma0 = if tool_fit.applied {
        tool_fit.stats.rms_mm / 3f64.sqrt()
    } else {
        0.0
    };
    let undetermined = precision::undetermined(
        &start,
        &Problem::new(&start, &ident.identified, cal, &frame),
        sigma0,
        &idopts.free,
    );
    if !undetermined.is_empty() {
        let mut opts = idopts.clone();
        opts.fix.extend(undetermined.iter().map(|u| u.param));
        ident = analyze_reduced(&start, cal, &opts, &reduced)?;
        for f in &mut ident.fixed {
            if let Some(u) = undetermined.iter().find(|u| u.param == f.param) {
                f.reason = FixReason::Undetermined {
                    std: u.std,
                    limit: u.limit,
                };
            }
        }
    }
    let k = ident.identified.len();
    let ill_conditioned = ident.ill_conditioned().then(|| {
        let (p, ind) = ident
            .least_independent()
            .expect("analyze identifies at least one parameter");
        format!(
            "the identified parameters are too nearly dependent for double precision: the \
             condition number of their scaled Jacobian is {:.3e}, above {MAX_CONDITION_NUMBER:e}, \
             where the normal equations (condition {:.1e}) leave the estimates' uncertainty \
             without reliable digits; the least independent is {} ({ind:.1e}, rank tolerance \
             {:e})",
            ident.condition_number,
            ident.condition_number * ident.condition_number,
            p.name(),
            ident.rank_tolerance
        )
    });
    if let Some(why) = &ill_conditioned {
        if !ident.condition_number.is_finite() || !idopts.allow_ill_conditioned {
            let hint = if plausibility::joints_look_like_radians(nominal, cal) {
                " (but first check the joint values: they all lie within ±2π while the joint \
                 limits span far more, as if they were radians)"
            } else {
                ""
            };
            return Err(Error::Numerical(format!(
                "{why}. Raise the rank tolerance above {:.1e} to fix it{hint}",
                ident.least_independent().map_or(0.0, |(_, i)| i)
            )));
        }
    }
    if cal.len() < k {
        return Err(Error::Numerical(format!(
            "{} calibration points for {k} identifiable parameters: at least {k} points are \
                 needed (the paper uses 75)",
            cal.len()
        )));
    }

    let problem = Problem::new(&start, &ident.identified, cal, &frame);
    let mut robot = start.clone();
    let mut stages = Vec::new();
    let run = |robot: &mut Robot, loss: Loss, stages: &mut Vec<Stage>| -> Result<()> {
        let name = loss.name();
        // The iteration limit is the whole solve's: each stage gets what the earlier left.
        let used: usize = stages.iter().map(|s| s.report.iterations).sum();
        let opts = SolverOptions {
            max_iterations: settings.solver.max_iterations.saturating_sub(used),
            ..settings.solver
        };
        let report = solve(&problem, robot, &loss, &opts, observer);
        if let Termination::Failed(m) = &report.termination {
            return Err(Error::Numerical(format!(
                "identification ({name}) failed after {} iterations: {m}",
                report.iterations
            )));
        }
        stages.push(Stage { loss, report });
        Ok(())
    };
    let son = Loss::SumOfNorms {
        delta: SUM_OF_NORMS_SMOOTHING_MM,
    };
    let mut robust_scale = None;
    let final_loss = match settings.objective {
        Objective::LeastSquares => {
            run(&mut robot, Loss::Squared, &mut stages)?;
            Loss::Squared
        }
        Objective::SumOfNorms => {
            run(&mut robot, son, &mut stages)?;
            son
        }
        Objective::Robust(_) | Objective::Adaptive => 'staged: {
            // Least squares gives the start: Gauss-Newton reaches its minimum in a few
            // iterations, and the scale below comes from the median residual, which gross
            // outliers do not move. Where the nominal geometry misses the data (the tool fit not
            // applied: another robot, wrong units) the sum of norms, which huge residuals do not
            // dominate, finds the way.
            let start_loss = if tool_fit.applied { Loss::Squared } else { son };
            run(&mut robot, start_loss, &mut stages)?;
            // A stage stopped by the iteration limit ends the identification: the result is
            // partial, and the later stages would only restart from a point that is not a
            // minimum.
            let converged =
                |st: &[Stage]| st.last().is_some_and(|s| s.report.termination.converged());
            if !converged(&stages) {
                break 'staged start_loss;
            }
            let make = |c: f64| match settings.objective {
                Objective::Robust(RobustLoss::Cauchy) => Loss::Cauchy { c },
                Objective::Robust(RobustLoss::Huber) => Loss::Huber { k: c },
                _ => Loss::Adaptive { k: c },
            };
            // The scale follows the residuals: re-estimated after every reweighted fit until
            // it settles (within 5%; the adaptive objective, whose threshold decides which
            // points count fully, within 1%).
            let (rounds, settle) = match settings.objective {
                Objective::Adaptive => (8, 0.01),
                _ => (3, 0.05),
            };
            let rows = problem.kind().rows();
            let sigmas = match settings.objective {
                Objective::Adaptive => ADAPTIVE_THRESHOLD_SIGMAS,
                _ => ROBUST_SCALE_SIGMAS,
            };
            let scale_of = |r: &Robot| {
                (sigmas * robust_sigma(&problem.fit_norms(r), rows)).max(SUM_OF_NORMS_SMOOTHING_MM)
            };
            let mut c = settings.robust_scale_mm.unwrap_or_else(|| scale_of(&robot));
            let mut loss = make(c);
            for _ in 0..rounds {
                loss = make(c);
                run(&mut robot, loss, &mut stages)?;
                if settings.robust_scale_mm.is_some() || !converged(&stages) {
                    break;
                }
                let c2 = scale_of(&robot);
                if (c2 - c).abs() <= settle * c {
                    break;
                }
                c = c2;
            }
            robust_scale = Some(c);
            loss
        }
    };

    observer.progress(progress::Stage::Uncertainty, 0, 1);
    let acc = problem.accumulate(&robot, &final_loss, Level::Full);
    let mut covariance = Covariance::from_accumulated(&ident.identified, &acc);
    if let Some(why) = ill_conditioned {
        covariance.mark_unavailable(why);
    }

    let held = frame;
    let frame = &held;
    let calibration = SetErrors::new(cal, &registration, nominal, frame, &robot);
    // Points beyond the robust threshold are outliers, not noise a new measurement shares.
    let threshold = robust_scale.unwrap_or_else(|| {
        ROBUST_SCALE_SIGMAS * robust_sigma(&calibration.after, problem.kind().rows())
    });
    let prediction = predict(
        &robot,
        &covariance,
        cal,
        &calibration.after,
        Some(threshold),
    );
    let mut validation_frame = None;
    let validation = match data.validation.filter(|v| !v.is_empty()) {
        None => None,
        Some(v) if settings.validation_refit_frame => {
            let (e, f) = SetErrors::refit(v, nominal, &robot)?;
            validation_frame = Some(f);
            Some(e)
        }
        Some(v) => {
            let e = SetErrors::new(v, &registration, nominal, frame, &robot);
            check_same_station(v, &e, &robot)?;
            Some(e)
        }
    };
    let downweighted = robust_scale.map_or_else(Vec::new, |c| {
        DownWeighted::list(&problem, &robot, &calibration, &final_loss, c)
    });
    observer.progress(progress::Stage::Plausibility, 0, 1);
    // The gate judges the model the identification started from (the nominal geometry with
    // the fitted tools): Table II's second line, and the validation points under it.
    let (nominal_rms_mm, validation_start) = if tool_fit.applied {
        let v = data
            .validation
            .filter(|v| !v.is_empty() && !settings.validation_refit_frame)
            .map(|v| Problem::new(&start, &[], v, frame).error_norms(&start));
        (tool_fit.stats.rms_mm, v)
    } else {
        (registration.stats.rms_mm, None)
    };
    let plausibility = plausibility::assess(&plausibility::Fit {
        nominal,
        start: &start,
        calibrated: &robot,
        identified: &ident.identified,
        calibration: cal,
        registration: &registration,
        nominal_rms_mm,
        validation_before: validation_start
            .as_deref()
            .or(validation.as_ref().map(|v| v.before.as_slice())),
        validation_after: validation.as_ref().map(|v| v.after.as_slice()),
        calibration_before: if tool_fit.applied {
            &tool_fit.residuals
        } else {
            &calibration.before
        },
        downweighted: downweighted.len(),
        prediction_mean_mm: prediction.as_ref().map(|p| p.mean_mm),
        noise_sigma_mm: prediction.as_ref().map(|p| p.noise_sigma_mm),
        solver: &whole_solve(&stages),
        max_iterations: settings.solver.max_iterations,
    });
    Ok(Calibration {
        nominal: nominal.clone(),
        calibrated: robot,
        registration,
        tool_fit,
        frame: held,
        identifiability: ident,
        stages,
        covariance,
        prediction,
        calibration,
        validation,
        validation_frame,
        robust_scale_mm: robust_scale,
        downweighted,
        plausibility,
        settings: settings.clone(),
        weighting,
        model_selection: None,
    })
}

/// The stages of a solve as one report: the last stage's termination (a stage that does not
/// converge ends the solve), the iterations and evaluations of all stages, the first stage's
/// initial objective and the last one's final values.
pub fn whole_solve(stages: &[Stage]) -> SolverReport {
    let last = &stages.last().expect("at least one stage").report;
    SolverReport {
        termination: last.termination.clone(),
        iterations: stages.iter().map(|s| s.report.iterations).sum(),
        evaluations: stages.iter().map(|s| s.report.evaluations).sum(),
        initial_objective: stages[0].report.initial_objective,
        ..last.clone()
    }
}

pub use crate::registration::{STATION_FACTOR, STATION_MIN_MM};

/// Fails when the validation points `v` were clearly measured from another tracker station: a
/// rigid frame of their own brings the calibrated model's mean error down by [`STATION_FACTOR`]
/// and by more than [`STATION_MIN_MM`]. Their errors in the calibration's frame would then be the
/// tracker's move, not the robot's accuracy.
fn check_same_station(v: &Observations, e: &SetErrors, cal: &Robot) -> Result<()> {
    let here = e.after_stats().mean_mm;
    if let Some(there) = crate::registration::another_station(cal, v, here) {
        return Err(Error::invalid(
            v.source()
                .map_or("validation data".into(), |p| p.display().to_string()),
            format!(
                "the validation points look measured from another tracker station: in the \
                 calibration's tracker frame the calibrated model is off by {here:.3} mm on \
                 average, with a frame of their own by {there:.3} mm. If the tracker moved, \
                 let the validation fit its own frame (`validation_refit_frame`); otherwise \
                 check that the file belongs to this calibration"
            ),
        ));
    }
    Ok(())
}
