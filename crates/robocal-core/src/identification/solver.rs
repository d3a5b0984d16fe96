//! A small Levenberg–Marquardt solver with iteratively reweighted steps, written for the
//! identification problem (masks, robust weights and the covariance need more control than a
//! generic least-squares crate gives).
//!
//! Each iteration solves `(A + lambda D) delta = b` with `A = sum w J^T J`, `b = sum w J^T e` at
//! the current weights `w = l'(r)/r` (see [`Loss`]), `D` the running maximum of `diag(A)`
//! (Marquardt's scaling, which makes the step independent of the parameters' units), and accepts
//! the step when the true objective decreases by a fair share of the decrease the weighted
//! quadratic model predicts (gain ratio above 1e-4, Nielsen's update of lambda). Because the
//! weighted model majorizes every loss used here, an accepted step always lowers the objective.

use crate::identification::objective::Loss;
use crate::identification::system::{Accumulated, Level, Problem};
use crate::model::Robot;
use crate::progress::{Observer, Stage};
use nalgebra::{DMatrix, DVector};

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Largest number of iterations (each with one Jacobian pass).
    pub max_iterations: usize,
    /// Converged when no parameter of the step moves the tool by more than this, in RMS over
    /// the points (mm).
    pub step_tolerance_mm: f64,
    /// Converged when, for every parameter, the cosine between its (weighted) Jacobian column and
    /// the (weighted) residual vector is below this (MINPACK's gtol).
    pub gradient_tolerance: f64,
    /// Converged when an accepted step lowered the objective by less than this fraction of it and
    /// the model predicted no more (MINPACK's ftol), or when the next step, lightly damped
    /// (lambda at most `initial_lambda`), is predicted to gain less (checked before the step is
    /// taken, so that a solve restarted at the solution does not move). The sum of norms creeps towards its minimum when some points are fitted
    /// exactly (its kinks, smoothed by 1e-6 mm): without this test the steps shrink below a
    /// micrometre but not below `step_tolerance_mm`, and the solver runs into the iteration
    /// limit with nothing left to gain.
    pub objective_tolerance: f64,
    /// Initial damping, relative to `diag(A)`.
    pub initial_lambda: f64,
    /// From this many observations, a calibration's solve starts on an even subsample of them
    /// (see [`crate::identification::pipeline`]'s stages); `usize::MAX`: never.
    pub warm_start_min_points: usize,
    /// About this many observations make that subsample (at least
    /// [`MIN_WARM_START_POINTS`]).
    pub warm_start_points: usize,
}

/// Most iterations a calibration's solve may be given: it converges in 5 to 350; a million
/// iterations of a 75-point problem already run for tens of minutes, and a solver that has not
/// converged by then will not.
pub const MAX_ITERATIONS: usize = 1_000_000;

/// From this many points, the solve starts on an even subsample (see [`crate::identification::pipeline`]'s stages).
pub const WARM_START_MIN_POINTS: usize = 100_000;

/// About this many points make the subsample of a warm start: enough that its minimum is within
/// a fraction of the noise of the whole set's, few enough that its runs cost a few passes over
/// the whole set.
pub const WARM_START_POINTS: usize = 25_000;

/// The smallest warm-start subsample accepted: fewer points would leave its minimum too far
/// from the whole set's for the last runs to be short.
pub const MIN_WARM_START_POINTS: usize = 1_000;

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            max_iterations: 1000,
            step_tolerance_mm: 1e-9,
            gradient_tolerance: 1e-10,
            objective_tolerance: 1e-9,
            initial_lambda: 1e-3,
            warm_start_min_points: WARM_START_MIN_POINTS,
            warm_start_points: WARM_START_POINTS,
        }
    }
}

/// Why the solver stopped.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The last step moved the tool by less than `step_tolerance_mm`.
    ConvergedStep,
    /// The gradient vanished (relative to `gradient_tolerance`), or the fit is exact.
    ConvergedGradient,
    /// The objective changes by less than `objective_tolerance` (relative): an accepted step
    /// gained less and the model predicted no more, or the next step is predicted to gain less.
    ConvergedObjective,
    /// `max_iterations` reached before convergence.
    MaxIterations,
    /// Numerical failure (non-finite values, no descent direction); see the message.
    Failed(String),
}

impl Termination {
    /// Whether the solver converged.
    pub fn converged(&self) -> bool {
        matches!(
            self,
            Termination::ConvergedStep
                | Termination::ConvergedGradient
                | Termination::ConvergedObjective
        )
    }

    /// A sentence for reports.
    pub fn describe(&self) -> String {
        match self {
            Termination::ConvergedStep => "converged (step below tolerance)".into(),
            Termination::ConvergedGradient => "converged (gradient below tolerance)".into(),
            Termination::ConvergedObjective => {
                "converged (objective change below tolerance)".into()
            }
            Termination::MaxIterations => "stopped at the iteration limit".into(),
            Termination::Failed(m) => format!("failed: {m}"),
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SolverReport {
    /// Why it stopped.
    pub termination: Termination,
    /// Iterations (Jacobian passes).
    pub iterations: usize,
    /// Objective evaluations (forward-kinematics passes for trial steps).
    pub evaluations: usize,
    /// Objective at the start.
    pub initial_objective: f64,
    /// Objective at the end.
    pub final_objective: f64,
    /// Largest gradient cosine at the end (see [`SolverOptions::gradient_tolerance`]).
    pub final_gradient: f64,
    /// Last step size, as the largest RMS tool displacement of one parameter's change (mm).
    pub last_step_mm: f64,
}

/// Smallest gain ratio (actual over predicted decrease) at which the undamped step is taken;
/// below it the iteration falls back to the damped steps.
const UNDAMPED_MIN_GAIN: f64 = 0.25;

/// Smallest damping the undamped steps' successes lower `lambda` to.
const MIN_LAMBDA: f64 = 1e-12;

/// Minimizes `sum l(|e_i|)` over the problem's parameters, starting from (and updating) `robot`.
/// `observer` hears `(Stage::Identification(name), iteration, max_iterations)` once per
/// iteration, `name` naming the loss ([`Loss::name`]).
pub fn solve(
    problem: &Problem,
    robot: &mut Robot,
    loss: &Loss,
    opts: &SolverOptions,
    observer: &dyn Observer,
) -> SolverReport {
    solve_keeping(problem, robot, loss, opts, observer, None).0
}

/// [`solve`], also returning the full pass ([`Level::Full`]) at the final `robot` when the solve
/// ended on one (a solve that stops at its start, as the last stage of a reweighted fit usually
/// does): the covariance needs exactly that pass, which is then not repeated. `first`, when
/// given, is the full pass at the starting `robot` with `loss` (computed before, by the
/// identifiability's precision analysis), not repeated either.
pub(crate) fn solve_keeping(
    problem: &Problem,
    robot: &mut Robot,
    loss: &Loss,
    opts: &SolverOptions,
    observer: &dyn Observer,
    first: Option<Accumulated>,
) -> (SolverReport, Option<Accumulated>) {
    let (report, acc, current) = solve_inner(problem, robot, loss, opts, observer, first);
    let full = current && acc.h.is_some() && acc.s.is_some();
    (report, full.then_some(acc))
}

/// The solve; also its last pass and whether that pass is at the final `robot`.
fn solve_inner(
    problem: &Problem,
    robot: &mut Robot,
    loss: &Loss,
    opts: &SolverOptions,
    observer: &dyn Observer,
    first: Option<Accumulated>,
) -> (SolverReport, Accumulated, bool) {
    let mut state = Iterate::start(problem, robot, loss, opts, first);
    let termination = state.run(robot, observer);
    let Iterate {
        mut report,
        acc,
        current,
        f_cur,
        ..
    } = state;
    report.termination = termination;
    report.final_objective = f_cur;
    (report, acc, current)
}

/// What a part of an iteration decided.
enum Next {
    /// A step was taken: on to the next iteration.
    Iterate,
    /// The solve ends, for this reason.
    Stop(Termination),
    /// The undamped step was not tried or not taken: the damped steps follow.
    Damped,
}

/// The solver's state from one iteration to the next: the parameters, the pass at them, the
/// damping, and the storage the steps reuse.
struct Iterate<'a, 'p> {
    problem: &'a Problem<'p>,
    loss: &'a Loss,
    opts: &'a SolverOptions,
    /// The pass made at a point the trial did not make one at: Newton steps need the
    /// objective's Hessian; for least squares it is `A` itself.
    level: Level,
    /// RMS tool displacement per unit change of each parameter, for the step test.
    col_rms: Vec<f64>,
    x: DVector<f64>,
    acc: Accumulated,
    /// The objective at `robot`'s current values.
    f_cur: f64,
    report: SolverReport,
    /// Marquardt's scaling: the running maximum of `diag(A)`.
    d: DVector<f64>,
    lambda: f64,
    nu: f64,
    trial: Robot,
    m: DMatrix<f64>,
    delta: DVector<f64>,
    x_new: DVector<f64>,
    /// Whether `acc` is the pass at `robot`'s current values.
    current: bool,
}

impl<'a, 'p> Iterate<'a, 'p> {
    /// The state at `robot`'s values, with `first` as the full pass there when it is one.
    fn start(
        problem: &'a Problem<'p>,
        robot: &Robot,
        loss: &'a Loss,
        opts: &'a SolverOptions,
        first: Option<Accumulated>,
    ) -> Self {
        let k = problem.params().len();
        let n = problem.len().max(1) as f64;
        let level = if matches!(loss, Loss::Squared) {
            Level::Normal
        } else {
            Level::Newton
        };
        let acc = first
            .filter(|f| f.s.is_some() && f.h.is_some() && f.a.nrows() == k)
            .unwrap_or_else(|| problem.accumulate(robot, loss, Level::Full));
        let s = acc.s.as_ref().expect("full pass");
        let col_rms: Vec<f64> = (0..k).map(|j| (s[(j, j)] / n).sqrt()).collect();
        let report = SolverReport {
            termination: Termination::MaxIterations,
            iterations: 0,
            evaluations: 1,
            initial_objective: acc.objective,
            final_objective: acc.objective,
            final_gradient: f64::NAN,
            last_step_mm: f64::NAN,
        };
        Iterate {
            problem,
            loss,
            opts,
            level,
            col_rms,
            x: problem.values(robot),
            f_cur: acc.objective,
            d: DVector::from_fn(k, |j, _| acc.a[(j, j)]),
            acc,
            report,
            lambda: opts.initial_lambda,
            nu: 2.0,
            trial: robot.clone(),
            m: DMatrix::zeros(k, k),
            delta: DVector::zeros(k),
            x_new: DVector::zeros(k),
            current: true,
        }
    }

    /// Iterates until a termination: each iteration tries the undamped step, then damped ones.
    fn run(&mut self, robot: &mut Robot, observer: &dyn Observer) -> Termination {
        let k = self.x.len();
        if k == 0 {
            self.report.final_gradient = 0.0;
            return Termination::ConvergedGradient;
        }
        for it in 1..=self.opts.max_iterations {
            self.report.iterations = it;
            observer.progress(
                Stage::Identification(self.loss.name()),
                it,
                self.opts.max_iterations,
            );
            if !self.acc.objective.is_finite() || self.acc.b.iter().any(|v| !v.is_finite()) {
                return Termination::Failed("non-finite residuals or Jacobian".to_string());
            }
            let grad = gradient_cosine(&self.acc.a, &self.acc.b, self.acc.weighted_sq);
            self.report.final_gradient = grad;
            if grad <= self.opts.gradient_tolerance {
                return Termination::ConvergedGradient;
            }
            for j in 0..k {
                self.d[j] = self.d[j].max(self.acc.a[(j, j)]).max(f64::MIN_POSITIVE);
            }
            let next = match self.undamped(robot) {
                Next::Damped => self.damped(robot),
                next => next,
            };
            if let Next::Stop(termination) = next {
                return termination;
            }
        }
        Termination::MaxIterations
    }

    /// The largest RMS tool displacement of one parameter's change in `delta` (mm).
    fn step_mm(&self) -> f64 {
        (0..self.x.len())
            .map(|j| self.delta[j].abs() * self.col_rms[j])
            .fold(0.0, f64::max)
    }

    /// The undamped step first (Gauss-Newton for least squares, Newton's model for the other
    /// losses): near the minimum it converges in a few iterations where a damped step only
    /// creeps along the weakly determined directions. Its predicted gain is the most the model
    /// can gain, so a small one means convergence.
    /// Only where the damped steps have found the model trustworthy (lambda back at or below its
    /// initial value): far from the minimum the undamped step would mostly be rejected.
    fn undamped(&mut self, robot: &mut Robot) -> Next {
        let newton_model = self.acc.h.as_ref().unwrap_or(&self.acc.a);
        if self.lambda > self.opts.initial_lambda
            || !damped_solve(
                newton_model,
                &self.d,
                0.0,
                &self.acc.b,
                &mut self.m,
                &mut self.delta,
            )
        {
            return Next::Damped;
        }
        let pred =
            self.acc.b.dot(&self.delta) - 0.5 * self.delta.dot(&(newton_model * &self.delta));
        let tol = self.opts.objective_tolerance * self.acc.objective.abs();
        if pred <= tol {
            return Next::Stop(Termination::ConvergedObjective);
        }
        self.x_new.copy_from(&self.x);
        self.x_new += &self.delta;
        self.problem.apply(&mut self.trial, &self.x_new);
        // The current pass's norms are not read once a step is tried (on a million points two
        // sets of them would be 16 MB).
        self.acc.norms = None;
        let at_trial = self.problem.accumulate(&self.trial, self.loss, Level::Full);
        let f_new = at_trial.objective;
        self.report.evaluations += 1;
        let gain = (self.acc.objective - f_new) / pred;
        if !(f_new.is_finite() && gain > UNDAMPED_MIN_GAIN) {
            self.problem.apply(&mut self.trial, &self.x);
            return Next::Damped;
        }
        let step = self.step_mm();
        self.report.last_step_mm = step;
        let small_change = self.acc.objective - f_new <= tol;
        self.f_cur = f_new;
        self.x.copy_from(&self.x_new);
        self.problem.apply(robot, &self.x);
        self.acc = at_trial;
        self.report.final_objective = self.acc.objective;
        self.lambda = (self.lambda / 3.0).max(MIN_LAMBDA);
        self.nu = 2.0;
        if step <= self.opts.step_tolerance_mm {
            Next::Stop(Termination::ConvergedStep)
        } else if small_change {
            Next::Stop(Termination::ConvergedObjective)
        } else {
            Next::Iterate
        }
    }

    /// Damped steps, raising the damping after each round that no step of lowers the objective,
    /// until one does or the damping gives up.
    fn damped(&mut self, robot: &mut Robot) -> Next {
        let mut first_try = true;
        loop {
            let best_step = match self.damped_trials(robot, &mut first_try) {
                Ok(next) => return next,
                Err(best_step) => best_step,
            };
            // Rejected: the current point stays. A rejected step below the tolerance means the
            // objective cannot be lowered at this precision.
            if best_step <= self.opts.step_tolerance_mm {
                return Next::Stop(Termination::ConvergedStep);
            }
            self.lambda *= self.nu;
            self.nu *= 2.0;
            if self.lambda > 1e30 {
                return Next::Stop(Termination::Failed(if best_step.is_finite() {
                    "no step lowers the objective".to_string()
                } else {
                    "the damped normal equations are singular".to_string()
                }));
            }
        }
    }

    /// One round of damped trials at the current damping: Newton's model first (fast near the
    /// minimum), then the reweighted one (a majorizer: reliable far from it and for exact fits).
    /// `first_try` is cleared by the first step solved. The decision when a step is accepted
    /// (or the lightly damped step predicts no gain), else the smallest of the steps tried (mm).
    fn damped_trials(&mut self, robot: &mut Robot, first_try: &mut bool) -> Result<Next, f64> {
        let mut best_step = f64::INFINITY;
        for use_newton in [true, false] {
            let model = match (use_newton, &self.acc.h) {
                (true, Some(h)) => h,
                (true, None) => continue,
                (false, _) => &self.acc.a,
            };
            if !damped_solve(
                model,
                &self.d,
                self.lambda,
                &self.acc.b,
                &mut self.m,
                &mut self.delta,
            ) {
                continue;
            }
            let pred = self.acc.b.dot(&self.delta) - 0.5 * self.delta.dot(&(model * &self.delta));
            if *first_try
                && self.lambda <= self.opts.initial_lambda
                && pred <= self.opts.objective_tolerance * self.acc.objective.abs()
            {
                return Ok(Next::Stop(Termination::ConvergedObjective));
            }
            *first_try = false;
            let step = self.step_mm();
            best_step = best_step.min(step);
            self.report.last_step_mm = step;
            self.x_new.copy_from(&self.x);
            self.x_new += &self.delta;
            self.problem.apply(&mut self.trial, &self.x_new);
            // Where the model is trusted the step is likely taken: its pass then serves the next
            // iteration.
            let near = self.lambda <= self.opts.initial_lambda;
            if near {
                self.acc.norms = None;
            }
            let (f_new, at_trial) = trial_pass(self.problem, &self.trial, self.loss, near);
            self.report.evaluations += 1;
            let gain = (self.acc.objective - f_new) / pred;
            if f_new.is_finite() && pred > 0.0 && gain > 1e-4 {
                let tol = self.opts.objective_tolerance * self.acc.objective.abs();
                let small_change = self.acc.objective - f_new <= tol && pred <= tol;
                self.lambda *= (1.0 - (2.0 * gain - 1.0).powi(3)).max(1.0 / 3.0);
                return Ok(self.accept(robot, f_new, at_trial, small_change));
            }
            self.problem.apply(&mut self.trial, &self.x);
        }
        Err(best_step)
    }

    /// Moves `robot` to the accepted damped step `x_new`, whose objective is `f_new`.
    fn accept(
        &mut self,
        robot: &mut Robot,
        f_new: f64,
        at_trial: Option<Accumulated>,
        small_change: bool,
    ) -> Next {
        self.f_cur = f_new;
        self.x.copy_from(&self.x_new);
        self.problem.apply(robot, &self.x);
        self.nu = 2.0;
        let converged = if self.report.last_step_mm <= self.opts.step_tolerance_mm {
            Some(Termination::ConvergedStep)
        } else if small_change {
            Some(Termination::ConvergedObjective)
        } else {
            None
        };
        // The pass at the new point: the trial's when it made one, else its own (not needed to
        // stop).
        match at_trial {
            Some(pass) => self.acc = pass,
            None if converged.is_none() => {
                self.acc = self.problem.accumulate(robot, self.loss, self.level);
                self.report.evaluations += 1;
            }
            None => self.current = false,
        }
        self.report.final_objective = f_new;
        match converged {
            Some(termination) => Next::Stop(termination),
            None => Next::Iterate,
        }
    }
}

/// The objective at a trial point `trial`, with the full pass ([`Level::Full`]) there when
/// `pass`: for a step likely to be taken, whose pass is then the next iteration's (or, at the
/// solution, the covariance's), at the cost of one Jacobian per point where the objective alone
/// costs the forward kinematics.
fn trial_pass(
    problem: &Problem,
    trial: &Robot,
    loss: &Loss,
    pass: bool,
) -> (f64, Option<Accumulated>) {
    if pass {
        let acc = problem.accumulate(trial, loss, Level::Full);
        (acc.objective, Some(acc))
    } else {
        (problem.objective(trial, loss), None)
    }
}

/// The largest cosine between a weighted Jacobian column and the weighted residual vector:
/// `|b_j| / sqrt(A_jj * sum w r^2)` (0 for an exact fit).
pub fn gradient_cosine(a: &DMatrix<f64>, b: &DVector<f64>, weighted_sq: f64) -> f64 {
    if weighted_sq <= 0.0 {
        return 0.0;
    }
    (0..b.len())
        .map(|j| {
            let den = (a[(j, j)] * weighted_sq).sqrt();
            if den > 0.0 {
                b[j].abs() / den
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// The undamped step `model^-1 b` (a Newton or Gauss-Newton step), as the solver takes it; `None`
/// when `model` is not positive definite or the step not finite.
pub(crate) fn undamped_step(model: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let k = b.len();
    let (mut m, mut delta) = (DMatrix::zeros(k, k), DVector::zeros(k));
    damped_solve(model, &DVector::zeros(k), 0.0, b, &mut m, &mut delta).then_some(delta)
}

/// Solves `(model + lambda diag(d)) delta = b` by Cholesky into `delta`, reusing `m`'s storage.
/// Returns false when the matrix is not positive definite or the solution not finite.
fn damped_solve(
    model: &DMatrix<f64>,
    d: &DVector<f64>,
    lambda: f64,
    b: &DVector<f64>,
    m: &mut DMatrix<f64>,
    delta: &mut DVector<f64>,
) -> bool {
    let k = b.len();
    let mut mm = std::mem::replace(m, DMatrix::zeros(0, 0));
    mm.copy_from(model);
    for j in 0..k {
        mm[(j, j)] += lambda * d[j];
    }
    delta.copy_from(b);
    match nalgebra::Cholesky::new(mm) {
        Some(ch) => {
            ch.solve_mut(delta);
            *m = ch.unpack();
            delta.iter().all(|v| v.is_finite())
        }
        None => {
            *m = DMatrix::zeros(k, k);
            false
        }
    }
}
