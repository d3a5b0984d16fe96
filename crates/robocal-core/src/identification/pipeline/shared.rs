//! What the candidates of a model selection share at the start: the frame and tools registered
//! to the robot as given ([`Registered`]), and the start model's passes over the data for the
//! identifiability analysis, computed once for a model with every family the selection may try.
//!
//! Every candidate starts from the robot as given with its families at zero: the same tool
//! points, and at each pose the same Jacobian column for every parameter they have in common
//! (a family at zero adds nothing to the forward kinematics, nor to another parameter's
//! derivative). The reduced Jacobian of a candidate is therefore the reduced Jacobian of the
//! widest model's columns it has ([`Reduced::columns`]), and the precision analysis's
//! least-squares pass at the start the widest pass restricted to its parameters
//! ([`Accumulated::restricted`]): one pass over the data each for the whole search instead of one
//! each per candidate.

use super::start::{self, Registered};
use super::{CalibrationData, CalibrationSettings};
use crate::error::Result;
use crate::identification::identifiability::{jacobian_r, Reduced};
use crate::identification::objective::Loss;
use crate::identification::plausibility::ShapeChecks;
use crate::identification::system::{Accumulated, Level, Problem};
use crate::model::{Param, Robot};
use crate::observations::Observations;
use nalgebra::Vector3;

/// What the candidates of a model selection share (see the module docs).
pub(crate) struct Shared {
    /// The frame and tools registered to the robot as given.
    pub registered: Registered,
    /// The robot as given's targets, and its tool point at each calibration point.
    given_points: (usize, Vec<Vector3<f64>>),
    /// The widest model's start passes, when it has the robot as given's tool points.
    passes: Option<StartPasses>,
    /// The plausibility gate's shape checks of the calibration points against those tool
    /// points (with the start passes).
    shape: Option<ShapeChecks>,
}

/// The start passes of the widest model (see the module docs).
struct StartPasses {
    /// The widest model's parameters (its [`Robot::param_list`]).
    params: Vec<Param>,
    /// Its reduced Jacobian at the start model, over `params`.
    reduced: Reduced,
    /// Its least-squares pass ([`Level::Full`]) at the start model over `params`, when the
    /// precision analysis runs (the tools fitted).
    pass: Option<Accumulated>,
}

/// A candidate's share of the [`Shared`] start passes: its reduced Jacobian, and its
/// precision pass over given parameters.
pub(super) struct CandidateStart<'s> {
    passes: &'s StartPasses,
    /// The reduced Jacobian over the candidate's parameters.
    pub reduced: Reduced,
}

impl CandidateStart<'_> {
    /// The least-squares pass at the start model over `params` (all among the candidate's), if
    /// the shared passes have one.
    pub fn pass(&self, params: &[Param]) -> Option<Accumulated> {
        let cols: Vec<usize> = params
            .iter()
            .map(|p| self.passes.params.iter().position(|q| q == p))
            .collect::<Option<_>>()?;
        self.passes.pass.as_ref().map(|a| a.restricted(&cols))
    }
}

impl Shared {
    /// The frame and tools registered to `given` (the robot as given), and the start passes of
    /// `widest` (`given` with every family the selection may try, at zero) when it has the same
    /// tool points; `given`'s inputs are checked first.
    pub fn new(
        given: &Robot,
        widest: &Robot,
        data: CalibrationData,
        settings: &CalibrationSettings,
    ) -> Result<Shared> {
        let registered = super::register_for(given, data, settings)?;
        let obs = data.calibration;
        let given_points = (
            given.target_count(),
            (0..obs.len())
                .map(|i| given.target_position_in(obs.q(i), obs.target(i), &obs.conditions(i)))
                .collect(),
        );
        let mut shared = Shared {
            registered,
            given_points,
            passes: None,
            shape: None,
        };
        if shared.same_tool_points(widest, obs) {
            let start = start::prepare(widest, &data, settings, &shared.registered)?;
            let params = start.robot.param_list().to_vec();
            let reduced = jacobian_r(&start.robot, &start.observations);
            let sigma0 = start.noise_bound();
            let pass =
                (sigma0 > 0.0 && sigma0.is_finite()).then(|| {
                    Problem::new(&start.robot, &params, &start.observations, &start.frame)
                        .accumulate(&start.robot, &Loss::Squared, Level::Full)
                });
            shared.shape = Some(ShapeChecks::of(&start.observations, &start.robot));
            shared.passes = Some(StartPasses {
                params,
                reduced,
                pass,
            });
        }
        Ok(shared)
    }

    /// The gate's shape checks for a candidate that shares the start (see [`Shared::new`]).
    pub(super) fn shape(&self) -> Option<&ShapeChecks> {
        self.shape.as_ref()
    }

    /// Whether `robot` puts the tool points of `obs` (the calibration points) where the robot
    /// as given does, bit for bit: then it shares the start.
    pub fn same_tool_points(&self, robot: &Robot, obs: &Observations) -> bool {
        let (targets, points) = &self.given_points;
        robot.target_count() == *targets
            && obs.len() == points.len()
            && (0..obs.len()).all(|i| {
                robot.target_position_in(obs.q(i), obs.target(i), &obs.conditions(i)) == points[i]
            })
    }

    /// The share of a candidate starting from `start` (the robot as given's tool points, its
    /// families at zero), when the widest model has all its parameters.
    pub(super) fn candidate(&self, start: &Robot) -> Option<CandidateStart<'_>> {
        let passes = self.passes.as_ref()?;
        let cols: Vec<usize> = start
            .param_list()
            .iter()
            .map(|p| passes.params.iter().position(|q| q == p))
            .collect::<Option<_>>()?;
        Some(CandidateStart {
            reduced: passes.reduced.columns(&cols),
            passes,
        })
    }
}
