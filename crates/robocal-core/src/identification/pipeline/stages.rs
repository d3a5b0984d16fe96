//! The pipeline's fourth step: the identification itself (paper, eq. 4), as one or more solver
//! runs ([`Stage`]s): a robust or adaptive objective starts from a least-squares fit and
//! re-estimates its scale from the residuals until it settles.
//!
//! A large set (from [`crate::identification::solver::WARM_START_MIN_POINTS`] points, [`SolverOptions::warm_start_min_points`])
//! starts on an even subsample of about [`crate::identification::solver::WARM_START_POINTS`]: the same runs there reach a model within the subsample's noise of the
//! minimum, from which the runs on every point need an iteration or two instead of the whole
//! way (each iteration a pass over a million points). The minimum is the same: the last runs
//! are on every point, to the solver's own tolerance.

use super::{CalibrationSettings, Stage};
use crate::error::{Error, Result};
use crate::identification::objective::{
    robust_sigma, Loss, Objective, RobustLoss, ADAPTIVE_THRESHOLD_SIGMAS, ROBUST_SCALE_SIGMAS,
    SUM_OF_NORMS_SMOOTHING_MM,
};
use crate::identification::solver::{solve_keeping, SolverOptions};
use crate::identification::system::Accumulated;
use crate::identification::system::Problem;
use crate::model::Robot;
use crate::progress::Observer;

/// The identified model and how it was reached.
pub(super) struct Solved {
    /// The calibrated model.
    pub robot: Robot,
    /// The solver runs, in order.
    pub stages: Vec<Stage>,
    /// The loss of the last run (the objective the result minimizes).
    pub loss: Loss,
    /// The robust loss's scale (mm), for robust objectives.
    pub robust_scale: Option<f64>,
    /// The last run's full pass at `robot` with `loss`, when it ended on one (the covariance's
    /// pass, not repeated then).
    pub final_pass: Option<Accumulated>,
    /// The fit's residual norms at `robot` ([`Problem::fit_norms`]), when the reweighting
    /// computed them there (the down-weighted points' list, not computed again then).
    pub final_norms: Option<Vec<f64>>,
}

/// The solver runs of one identification, with the iteration limit shared by all.
struct Runs<'p, 'a> {
    problem: &'p Problem<'a>,
    settings: &'p CalibrationSettings,
    observer: &'p dyn Observer,
    robot: Robot,
    stages: Vec<Stage>,
    /// The last run's full pass at `robot`, when it ended on one.
    final_pass: Option<Accumulated>,
    /// The full pass at the start with the squared loss, for a first run of least squares.
    first_pass: Option<Accumulated>,
}

/// The norm up to which `loss` is least squares (the same value, weight and curvature at
/// every residual up to it); `None` for losses that differ from it everywhere.
fn squared_up_to(loss: &Loss) -> Option<f64> {
    match *loss {
        Loss::Squared => Some(f64::INFINITY),
        Loss::Huber { k } | Loss::Adaptive { k } => Some(k),
        Loss::SumOfNorms { .. } | Loss::Cauchy { .. } => None,
    }
}

impl Runs<'_, '_> {
    /// One solver run minimizing `loss` from the current model. The iteration limit is the whole
    /// solve's: each stage gets what the earlier left.
    fn run(&mut self, loss: Loss) -> Result<()> {
        let used: usize = self.stages.iter().map(|s| s.report.iterations).sum();
        let opts = SolverOptions {
            max_iterations: self.settings.solver.max_iterations.saturating_sub(used),
            ..self.settings.solver
        };
        let first = match self.first_pass.take() {
            Some(pass) if self.stages.is_empty() && loss == Loss::Squared => Some(pass),
            _ => self.pass_for(&loss),
        };
        let (report, pass) = solve_keeping(
            self.problem,
            &mut self.robot,
            &loss,
            &opts,
            self.observer,
            first,
        );
        self.final_pass = pass;
        if let crate::identification::solver::Termination::Failed(m) = &report.termination {
            return Err(Error::Numerical(format!(
                "identification ({}) failed after {} iterations: {m}",
                loss.name(),
                report.iterations
            )));
        }
        self.stages.push(Stage {
            loss,
            report,
            points: None,
        });
        Ok(())
    }

    /// The last run's pass at the current model, as the next run's first with `loss`, when it
    /// is that run's exactly: both losses are least squares up to a threshold that every
    /// residual is within (the weights, curvatures and values are then the same, bit for bit:
    /// an adaptive run after a least-squares fit without outliers needs no pass of its own).
    fn pass_for(&mut self, loss: &Loss) -> Option<Accumulated> {
        let before = squared_up_to(&self.stages.last()?.loss)?;
        let limit = before.min(squared_up_to(loss)?);
        let pass = self.final_pass.as_ref()?;
        let within = pass.norms.as_ref()?.iter().all(|&r| r <= limit);
        within.then(|| self.final_pass.take()).flatten()
    }

    /// The fit's residual norms at the current model ([`Problem::fit_norms`]): the last run's
    /// pass's (taken from it) when it ended on one that kept them, else a pass of their own.
    fn norms(&mut self) -> Vec<f64> {
        match self.final_pass.as_mut().and_then(|p| p.norms.take()) {
            Some(n) => n,
            None => self.problem.fit_norms(&self.robot),
        }
    }

    /// Puts `norms`, the fit's at the current model, back in the last run's pass (for
    /// [`Runs::pass_for`]).
    fn restore_norms(&mut self, norms: Vec<f64>) {
        if let Some(pass) = self.final_pass.as_mut() {
            pass.norms = Some(norms);
        }
    }

    /// Whether the last run converged (a run stopped by the iteration limit ends the
    /// identification: the result is partial, and later stages would only restart from a
    /// point that is not a minimum).
    fn converged(&self) -> bool {
        self.stages
            .last()
            .is_some_and(|s| s.report.termination.converged())
    }
}

/// Identifies the parameters of `problem` from `start` with the settings' objective. `tools_fit`:
/// whether the start model fits the data (the tools fitted to the nominal geometry were applied).
/// A large problem starts on a subsample (see the module docs). `start_pass`: the full pass at
/// `start` with the squared loss, when computed before (the first least-squares run's).
pub(super) fn solve_stages(
    problem: &Problem,
    start: &Robot,
    tools_fit: bool,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
    start_pass: Option<Accumulated>,
) -> Result<Solved> {
    let n = problem.len();
    if n >= settings.solver.warm_start_min_points {
        let step = n.div_ceil(settings.solver.warm_start_points);
        let kept: Vec<usize> = (0..n).step_by(step).collect();
        let sub_obs = problem.observations().rows_where(|i| i % step == 0)?;
        let sub = problem.restricted(&sub_obs, &kept);
        let warm = solve_from(&sub, start, tools_fit, settings, observer, None, None)?;
        if warm
            .stages
            .last()
            .is_some_and(|s| s.report.termination.converged())
        {
            let mut stages = warm.stages;
            stages.iter_mut().for_each(|s| s.points = Some(kept.len()));
            return solve_from(
                problem,
                &warm.robot,
                tools_fit,
                settings,
                observer,
                Some(stages),
                None,
            );
        }
        // A subsample that does not converge says nothing of the whole: the whole way then.
    }
    solve_from(
        problem, start, tools_fit, settings, observer, None, start_pass,
    )
}

/// The runs of [`solve_stages`] from `start`; after a warm start (its runs `warm`), the
/// objective's last runs only: the model is already near the starting fit's minimum.
fn solve_from(
    problem: &Problem,
    start: &Robot,
    tools_fit: bool,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
    warm: Option<Vec<Stage>>,
    start_pass: Option<Accumulated>,
) -> Result<Solved> {
    let warm_started = warm.is_some();
    let mut runs = Runs {
        problem,
        settings,
        observer,
        robot: start.clone(),
        stages: warm.unwrap_or_default(),
        final_pass: None,
        first_pass: start_pass,
    };
    let son = Loss::SumOfNorms {
        delta: SUM_OF_NORMS_SMOOTHING_MM,
    };
    let mut final_norms = None;
    let (loss, robust_scale) = match settings.objective {
        Objective::LeastSquares => {
            runs.run(Loss::Squared)?;
            (Loss::Squared, None)
        }
        Objective::SumOfNorms => {
            runs.run(son)?;
            (son, None)
        }
        Objective::Robust(_) | Objective::Adaptive => {
            // Least squares gives the start: Gauss-Newton reaches its minimum in a few
            // iterations, and the scale comes from the median residual, which gross outliers
            // do not move. Where the nominal geometry misses the data (the tool fit not
            // applied: another robot, wrong units) the sum of norms, which huge residuals do
            // not dominate, finds the way. After a warm start the model is past that.
            let start_loss = if tools_fit { Loss::Squared } else { son };
            if !warm_started {
                runs.run(start_loss)?;
            }
            if runs.converged() {
                let (loss, c, norms) = robust_rounds(&mut runs)?;
                final_norms = norms;
                (loss, Some(c))
            } else {
                (start_loss, None)
            }
        }
    };
    Ok(Solved {
        robot: runs.robot,
        stages: runs.stages,
        loss,
        robust_scale,
        final_pass: runs.final_pass,
        final_norms,
    })
}

/// The robust or adaptive runs after the starting fit: the scale follows the residuals,
/// re-estimated after every reweighted fit until it settles (within 5%; the adaptive objective,
/// whose threshold decides which points count fully, within 1%). Returns the last loss and its
/// scale (mm).
fn robust_rounds(runs: &mut Runs) -> Result<(Loss, f64, Option<Vec<f64>>)> {
    let settings = runs.settings;
    let make = |c: f64| match settings.objective {
        Objective::Robust(RobustLoss::Cauchy) => Loss::Cauchy { c },
        Objective::Robust(RobustLoss::Huber) => Loss::Huber { k: c },
        _ => Loss::Adaptive { k: c },
    };
    let (rounds, settle, sigmas) = match settings.objective {
        Objective::Adaptive => (8, 0.01, ADAPTIVE_THRESHOLD_SIGMAS),
        _ => (3, 0.05, ROBUST_SCALE_SIGMAS),
    };
    let problem = runs.problem;
    let rows = problem.kind().rows();
    let scale_of =
        |norms: &[f64]| (sigmas * robust_sigma(norms, rows)).max(SUM_OF_NORMS_SMOOTHING_MM);
    let mut c = match settings.robust_scale_mm {
        Some(c) => c,
        None => {
            let at_start = runs.norms();
            let c = scale_of(&at_start);
            runs.restore_norms(at_start);
            c
        }
    };
    let mut loss = make(c);
    // The fit's residual norms at the current model, once a run has been followed by them.
    let mut norms = None;
    for _ in 0..rounds {
        loss = make(c);
        runs.run(loss)?;
        norms = None;
        if settings.robust_scale_mm.is_some() || !runs.converged() {
            break;
        }
        let at_model = runs.norms();
        let c2 = scale_of(&at_model);
        if (c2 - c).abs() <= settle * c {
            norms = Some(at_model);
            break;
        }
        runs.restore_norms(at_model);
        c = c2;
    }
    Ok((loss, c, norms))
}

#[cfg(test)]
#[path = "stages_tests.rs"]
mod tests;
