//! The pipeline's fourth step: the identification itself (paper, eq. 4), as one or more solver
//! runs ([`Stage`]s): a robust or adaptive objective starts from a least-squares fit and
//! re-estimates its scale from the residuals until it settles.

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
        let (report, pass) =
            solve_keeping(self.problem, &mut self.robot, &loss, &opts, self.observer);
        self.final_pass = pass;
        if let crate::identification::solver::Termination::Failed(m) = &report.termination {
            return Err(Error::Numerical(format!(
                "identification ({}) failed after {} iterations: {m}",
                loss.name(),
                report.iterations
            )));
        }
        self.stages.push(Stage { loss, report });
        Ok(())
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
pub(super) fn solve_stages(
    problem: &Problem,
    start: &Robot,
    tools_fit: bool,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
) -> Result<Solved> {
    let mut runs = Runs {
        problem,
        settings,
        observer,
        robot: start.clone(),
        stages: Vec::new(),
        final_pass: None,
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
            // not dominate, finds the way.
            let start_loss = if tools_fit { Loss::Squared } else { son };
            runs.run(start_loss)?;
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
    let mut c = settings
        .robust_scale_mm
        .unwrap_or_else(|| scale_of(&problem.fit_norms(&runs.robot)));
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
        let at_model = problem.fit_norms(&runs.robot);
        let c2 = scale_of(&at_model);
        norms = Some(at_model);
        if (c2 - c).abs() <= settle * c {
            break;
        }
        c = c2;
    }
    Ok((loss, c, norms))
}
