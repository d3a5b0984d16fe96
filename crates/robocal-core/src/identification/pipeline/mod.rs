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

//! Its steps, in order: `inputs` (checks), `start` (registration, tool fit, weights),
//! `identify` (identifiability), `stages` (the solver runs), `outcome` (uncertainty,
//! errors, prediction, validation, the gate).

mod identify;
mod inputs;
mod outcome;
mod shared;
mod stages;
pub(crate) mod start;

pub(crate) use shared::Shared;

use crate::error::{Error, Result};
use crate::identification::bounds;
use crate::identification::covariance::Covariance;
use crate::identification::folds::{pose_folds, FOLDS};
use crate::identification::identifiability::{FixReason, Identifiability, IdentifiabilityOptions};
use crate::identification::model_choice::{ModelChoice, ModelSelection};
use crate::identification::objective::{Loss, Objective};
use crate::identification::param_vector::ParamVector;
use crate::identification::plausibility::{Plausibility, ShapeChecks};
use crate::identification::prediction::Prediction;
pub use crate::identification::set_errors::{DownWeighted, SetErrors};
use crate::identification::solver::{SolverOptions, SolverReport};
use crate::identification::system::Problem;
use crate::model::{Param, Robot};
use crate::observations::AppliedWeighting;
use crate::observations::Observations;
use crate::observations::Weighting;
use crate::progress::Observer;
use crate::registration::{Registration, ToolFit};
use std::borrow::Cow;

/// Everything that steers a calibration.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CalibrationSettings {
    /// The objective (default: [`Objective::Adaptive`]; the paper's is
    /// [`Objective::SumOfNorms`]).
    pub objective: Objective,
    /// Scale of the robust loss (mm); `None`: from the residuals (see [`crate::identification::objective::RobustLoss`]).
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
    /// The points the run used when fewer than all: a large set's solve starts on an even
    /// subsample of this many ([`WARM_START_MIN_POINTS`]); `None`: every point.
    pub points: Option<usize>,
}

pub use crate::identification::solver::{WARM_START_MIN_POINTS, WARM_START_POINTS};

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
    /// The plausibility gate's outcome (see [`crate::identification::plausibility`]): a converged fit that fails it is
    /// not a calibration.
    pub plausibility: Plausibility,
    /// The settings used.
    pub settings: CalibrationSettings,
    /// The weighting the fit used (with an automatic tracker model, which).
    pub weighting: AppliedWeighting,
    /// The automatic model choice, when the settings asked for it.
    pub model_selection: Option<ModelSelection>,
    /// A model selection's candidate: each cross-validation fold's share of the objective's
    /// Hessian and gradient at the calibrated model ([`crate::identification::folds`]), from the
    /// solver's last pass, when it ended on one (the cross-validation's, not repeated then).
    pub(crate) fold_passes: Option<Vec<(nalgebra::DMatrix<f64>, nalgebra::DVector<f64>)>>,
    /// A model selection's candidate: the solver's last full pass at the calibrated model, when
    /// it ended on one (the covariance's; [`complete`] does not repeat it).
    pub(crate) last_pass: Option<crate::identification::system::Accumulated>,
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
    calibrate_model_for(nominal, data, settings, Purpose::Result, observer, None)
}

/// What a calibration is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Purpose {
    /// The result: everything, the prediction's workspace map included.
    Result,
    /// A model selection's candidate: the prediction without its map.
    Candidate,
}

/// One calibration's inputs, as the steps after the solve read them.
#[derive(Clone, Copy)]
pub(super) struct Job<'a> {
    nominal: &'a Robot,
    data: CalibrationData<'a>,
    settings: &'a CalibrationSettings,
    purpose: Purpose,
    observer: &'a dyn Observer,
    /// The gate's shape checks, when shared among a selection's candidates.
    shape: Option<&'a ShapeChecks>,
}

/// The frame and tools registered to `nominal` for a calibration of `data` (the inputs checked
/// first), to share among models with its tool points ([`calibrate_model_for`], [`Shared`]).
pub(crate) fn register_for(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
) -> Result<start::Registered> {
    inputs::check(nominal, &data, settings)?;
    start::register_nominal(nominal, &data, settings, &())
}

/// [`calibrate_model`] for a `purpose`; `shared`: the frame, tools and start passes shared by
/// the candidates of a model selection, for a model with the same tool points at the start as
/// the robot they were registered to (see [`Shared::same_tool_points`]), not computed again.
pub(crate) fn calibrate_model_for(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    purpose: Purpose,
    observer: &dyn Observer,
    shared: Option<&Shared>,
) -> Result<Calibration> {
    calibrate_model_from(nominal, data, settings, purpose, observer, shared, None)
}

/// [`calibrate_model_for`] from its start and identifiability steps when they were taken
/// already (`begun`, by [`begin_for`] with the same inputs: a screened candidate's). `observer`
/// then hears no identifiability stage ([`begin_for`] took it silently).
pub(crate) fn calibrate_model_from(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    purpose: Purpose,
    observer: &dyn Observer,
    shared: Option<&Shared>,
    begun: Option<Begun>,
) -> Result<Calibration> {
    inputs::check(nominal, &data, settings)?;
    let registered = &*registration(nominal, &data, settings, observer, shared)?;
    let begun = match begun {
        Some(b) => b,
        None => begin(nominal, &data, settings, observer, registered, shared)?,
    };
    let first = calibrate_once(nominal, data, settings, purpose, observer, begun, shared)?;
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
    let begun = begin(nominal, &data, &again, observer, registered, shared)?;
    let mut c = calibrate_once(nominal, data, &again, purpose, observer, begun, shared)?;
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

/// A calibration's first two steps taken: the start model and which parameters it identifies.
pub(crate) struct Begun {
    start: start::StartModel,
    identified: identify::Identified,
}

impl Begun {
    /// The parameters the calibration identifies.
    pub fn params(&self) -> &[Param] {
        &self.identified.identifiability.identified
    }
}

/// The start and identifiability steps of a calibration of `nominal` (those of
/// [`calibrate_model_for`] with the same inputs), for a model selection's candidate that is
/// screened first ([`crate::identification::screen`]) and fitted from them when it is not
/// spared ([`calibrate_model_from`]).
pub(crate) fn begin_for(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    shared: Option<&Shared>,
) -> Result<Begun> {
    // The inputs are checked by the fit that uses these steps ([`calibrate_model_from`]): a
    // step that fails here on unchecked inputs only means the candidate is fitted, and the fit
    // reports them.
    let registered = registration(nominal, &data, settings, &(), shared)?;
    begin(nominal, &data, settings, &(), &registered, shared)
}

/// The frame and tools a calibration of `nominal` starts from: `shared`'s, when given, else
/// registered to `nominal` (`observer` hears it).
fn registration<'s>(
    nominal: &Robot,
    data: &CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
    shared: Option<&'s Shared>,
) -> Result<Cow<'s, start::Registered>> {
    Ok(match shared {
        Some(s) => Cow::Borrowed(&s.registered),
        None => Cow::Owned(start::register_nominal(nominal, data, settings, observer)?),
    })
}

/// The start model from the frame and tools `registered`, and its identifiable parameters.
fn begin(
    nominal: &Robot,
    data: &CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
    registered: &start::Registered,
    shared: Option<&Shared>,
) -> Result<Begun> {
    let start = start::prepare(nominal, data, settings, registered)?;
    let identified = identify::identifiable(
        nominal,
        &start,
        &settings.identifiability,
        observer,
        shared.and_then(|s| s.candidate(&start.robot)),
    )?;
    Ok(Begun { start, identified })
}

/// One calibration of the model as given, from its start model and identifiable parameters
/// (`begun`; the gate's shape checks from `shared`, when given): its steps, each a function of
/// its own.
fn calibrate_once(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    purpose: Purpose,
    observer: &dyn Observer,
    begun: Begun,
    shared: Option<&Shared>,
) -> Result<Calibration> {
    let Begun {
        start,
        mut identified,
    } = begun;
    let solved = {
        let problem = Problem::new(
            &start.robot,
            &identified.identifiability.identified,
            &start.observations,
            &start.frame,
        )
        .keeping_norms();
        // A candidate's passes also sum each cross-validation fold's share.
        let folds = (purpose == Purpose::Candidate).then(|| pose_folds(&start.observations, FOLDS));
        let problem = match &folds {
            Some(f) => problem.grouped(f, FOLDS),
            None => problem,
        };
        stages::solve_stages(
            &problem,
            &start.robot,
            start.tool_fit.applied,
            settings,
            observer,
            identified.start_pass.take(),
        )?
    };
    let job = Job {
        nominal,
        data,
        settings,
        purpose,
        observer,
        shape: shared.and_then(Shared::shape),
    };
    outcome::assemble(&job, start, identified, solved)
}

/// Completes a calibration `cal` fitted for [`Purpose::Candidate`] without validation points
/// (a model selection's candidate) into the result [`calibrate_model`] would give for `data`
/// and `settings`: the same fit, with the prediction's workspace map, the validation points'
/// errors and the gate on them. The fit's steps are not repeated: the registration, tool fit,
/// identifiability and solve are the candidate's.
pub(crate) fn complete(
    cal: Calibration,
    data: CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
) -> Result<Calibration> {
    inputs::check(&cal.nominal, &data, settings)?;
    let nominal = cal.nominal.clone();
    let robot = if cal.tool_fit.applied {
        cal.tool_fit.apply(&nominal)
    } else {
        nominal.clone()
    };
    let observations = Weighting {
        tracker: cal.weighting.tracker,
        ..settings.weighting
    }
    .apply(data.calibration)?;
    let start = start::StartModel {
        registration: cal.registration,
        tool_fit: cal.tool_fit,
        weighting: cal.weighting,
        observations,
        robot,
        frame: cal.frame,
    };
    let identified = identify::Identified {
        ill_conditioned: identify::ill_conditioned(&cal.identifiability),
        identifiability: cal.identifiability,
        start_pass: None,
    };
    let solved = stages::Solved {
        robot: cal.calibrated,
        loss: cal.stages.last().expect("at least one stage").loss,
        stages: cal.stages,
        robust_scale: cal.robust_scale_mm,
        final_pass: cal.last_pass,
        final_norms: None,
    };
    let job = Job {
        nominal: &nominal,
        data,
        settings,
        purpose: Purpose::Result,
        observer,
        shape: None,
    };
    outcome::assemble(&job, start, identified, solved)
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
        // The objective at the start of the first run on every point (a warm start's runs on a
        // subsample have an objective of their own).
        initial_objective: stages
            .iter()
            .find(|s| s.points.is_none())
            .unwrap_or(&stages[0])
            .report
            .initial_objective,
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
