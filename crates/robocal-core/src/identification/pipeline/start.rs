//! The pipeline's second step: the measurement frame (paper, section II.C), the tool points
//! fitted to the nominal geometry, and the weights: the model and frame the identification
//! starts from.

use super::{CalibrationData, CalibrationSettings};
use crate::error::Result;
use crate::frame::TrackerFrame;
use crate::identification::objective::Objective;
use crate::identification::plausibility;
use crate::model::Robot;
use crate::observations::{AppliedWeighting, Observations, Weighting};
use crate::progress::{self, Observer};
use crate::registration::{
    fit_tools_from, nominal_flanges, register_to, tool_points, Registration, RegistrationObjective,
    RegistrationOptions, ToolFit,
};

/// Where the identification starts.
pub(super) struct StartModel {
    /// The fitted measurement frame and Table II.
    pub registration: Registration,
    /// The tools fitted to the nominal geometry (applied or not).
    pub tool_fit: ToolFit,
    /// The weighting resolved for these data.
    pub weighting: AppliedWeighting,
    /// The calibration points with their weights.
    pub observations: Observations,
    /// The nominal geometry, with the fitted tools when they were applied.
    pub robot: Robot,
    /// The frame the identification holds (the tool fit's when applied, else the
    /// registration's).
    pub frame: TrackerFrame,
}

impl StartModel {
    /// The per-axis noise bound of the precision analysis
    /// ([`crate::identification::precision`]): the nominal geometry's per-axis RMS error with the
    /// fitted tools; zero when the tools were not applied (the estimate, and the bound, then
    /// mean nothing).
    pub fn noise_bound(&self) -> f64 {
        if self.tool_fit.applied {
            self.tool_fit.stats.rms_mm / 3f64.sqrt()
        } else {
            0.0
        }
    }
}

/// The measurement frame registered to the nominal model and the tools fitted to it: what
/// every model the calibration compares shares when they have the same tool points at the
/// start (the candidates of a model selection: the nominal with families at zero).
#[derive(Debug, Clone)]
pub(crate) struct Registered {
    /// The fitted measurement frame and Table II.
    pub registration: Registration,
    /// The tools fitted to the nominal geometry (applied or not).
    pub tool_fit: ToolFit,
}

/// Registers the measurement frame to `nominal` and fits the tools.
pub(crate) fn register_nominal(
    nominal: &Robot,
    data: &CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
) -> Result<Registered> {
    let cal = data.calibration;
    observer.progress(progress::Stage::Registration, 0, 1);
    let reg_opts = RegistrationOptions {
        objective: match settings.objective {
            Objective::LeastSquares => RegistrationObjective::LeastSquares,
            _ => RegistrationObjective::SumOfNorms,
        },
        affine: settings.affine_registration,
        ..Default::default()
    };
    // One forward pass per point for both fits: the tool fit holds the flange frames, the
    // registration their tool points.
    let flanges = nominal_flanges(nominal, cal);
    let points = tool_points(nominal, cal, &flanges);
    let registration = register_to(nominal, cal, data.plane, &reg_opts, points)?;
    let mut tool_fit = fit_tools_from(nominal, cal, &registration.frame, flanges)?;
    // Only where the nominal geometry with the fitted tools fits the data as a calibration's
    // start can (the gate's nominal-error limit): on data in the wrong unit or of another robot
    // the fitted tools mean nothing, and the gate names the cause.
    tool_fit.applied = tool_fit.converged
        && tool_fit.stats.rms_mm
            <= plausibility::NOMINAL_ERROR_LIMIT * plausibility::reach_mm(nominal);
    Ok(Registered {
        registration,
        tool_fit,
    })
}

/// The model the identification starts from: `registered` (the frame and tools fitted to
/// `nominal`, or to a model with the same tool points), the weights resolved.
pub(super) fn prepare(
    nominal: &Robot,
    data: &CalibrationData,
    settings: &CalibrationSettings,
    registered: &Registered,
) -> Result<StartModel> {
    let cal = data.calibration;
    let Registered {
        registration,
        tool_fit,
    } = registered.clone();
    // The weights, from here on: the registration and the tool fit weight no point, and the
    // automatic tracker model needs what they tell (where the tracker stands, whether the
    // nominal model fits the data at all).
    let weighting =
        settings
            .weighting
            .resolve(cal, registration.frame.origin().norm(), tool_fit.applied);
    let observations = Weighting {
        tracker: weighting.tracker,
        ..settings.weighting
    }
    .apply(cal)?;
    // The identification starts from the nominal geometry with the fitted tools, in the frame
    // fitted with them: neither it nor the identifiability depends on the nominal tool's guess.
    let (robot, frame) = if tool_fit.applied {
        (tool_fit.apply(nominal), tool_fit.frame)
    } else {
        (nominal.clone(), registration.frame)
    };
    Ok(StartModel {
        registration,
        tool_fit,
        weighting,
        observations,
        robot,
        frame,
    })
}
