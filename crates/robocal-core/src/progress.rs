//! Progress of long work: one observer type for every long function of the library.
//!
//! The library never prints. A function that can take a while (simulating, calibrating,
//! compensating many rows, Monte Carlo trials, a whole experiment) takes an
//! `observer: &dyn Observer` and reports `(stage, done, total)` to it as the work advances, as
//! argmin's observers watch its solvers. Pass `&()` to ignore the reports; the CLI passes its
//! progress bar. Observers are `Send + Sync`: Monte Carlo trials report from rayon's worker
//! threads.

/// The long stages the library reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Drawing and measuring simulated poses (`done` of `total` readings).
    Measurement,
    /// Fitting the measurement frame (eq. 8-11).
    Registration,
    /// Finding the identifiable parameters.
    Identifiability,
    /// The solver's iterations on one objective (`done` = iteration, `total` = the iteration
    /// budget), named as in [`crate::identification::Loss`]: `sum of norms`, `least squares`,
    /// `Huber` or `Cauchy`.
    Identification(&'static str),
    /// The parameters' standard deviations.
    Uncertainty,
    /// The plausibility gate.
    Plausibility,
    /// Choosing the model the data support (cross-validation of the candidates).
    ModelSelection,
    /// A whole calibration, as one step of an experiment.
    Calibration,
    /// Inverse kinematics of many rows (eq. 12-14).
    Compensation,
    /// Measuring commanded joints and comparing with the desired positions.
    Verification,
    /// Expressing a simulation's truth in the identified parameters.
    TruthComparison,
    /// Monte Carlo trials finished.
    Trials,
    /// Drawing candidate poses and their Jacobians for a plan.
    Candidates,
    /// Choosing a plan's poses greedily (`done` of `total` poses chosen).
    PoseSelection,
    /// A plan's exchange passes (`done` of `total` chosen poses reconsidered in this pass).
    Exchange,
}

impl Stage {
    /// A few words for a progress bar.
    pub fn describe(self) -> &'static str {
        match self {
            Stage::Measurement => "measuring",
            Stage::Registration => "registration",
            Stage::Identifiability => "identifiability",
            Stage::Identification(objective) => objective,
            Stage::Uncertainty => "uncertainty",
            Stage::Plausibility => "plausibility",
            Stage::ModelSelection => "choosing the model",
            Stage::Calibration => "calibrating",
            Stage::Compensation => "compensating",
            Stage::Verification => "verifying",
            Stage::TruthComparison => "comparing with the truth",
            Stage::Trials => "trials",
            Stage::Candidates => "candidates",
            Stage::PoseSelection => "choosing poses",
            Stage::Exchange => "exchanging poses",
        }
    }
}

/// Watches long work: called with the stage, the steps done and the steps in all (`done <=
/// total`; a stage of unknown length reports `(stage, 0, 1)` when it starts).
pub trait Observer: Send + Sync {
    /// `done` of `total` steps of `stage` are done.
    fn progress(&self, stage: Stage, done: usize, total: usize);
}

/// No observer: the reports are dropped.
impl Observer for () {
    fn progress(&self, _: Stage, _: usize, _: usize) {}
}

/// A closure is an observer (e.g. to record the reports in a test).
impl<F: Fn(Stage, usize, usize) + Send + Sync> Observer for F {
    fn progress(&self, stage: Stage, done: usize, total: usize) {
        self(stage, done, total)
    }
}

/// Reports every event of `inner` as `stage`, keeping its counts: a step made of smaller
/// steps (an experiment's calibration) shows as one.
pub(crate) struct As<'a> {
    /// The observer to report to.
    pub inner: &'a dyn Observer,
    /// The stage every event is reported as.
    pub stage: Stage,
}

impl Observer for As<'_> {
    fn progress(&self, _: Stage, done: usize, total: usize) {
        self.inner.progress(self.stage, done, total)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn closures_observe_and_as_relabels_keeping_the_counts() {
        let heard = Mutex::new(Vec::new());
        let record = |s: Stage, d: usize, t: usize| heard.lock().unwrap().push((s, d, t));
        let observer: &dyn Observer = &record;
        observer.progress(Stage::Registration, 0, 1);
        As {
            inner: observer,
            stage: Stage::Calibration,
        }
        .progress(Stage::Identification("Huber"), 3, 50);
        ().progress(Stage::Trials, 1, 2);
        assert_eq!(
            heard.into_inner().unwrap(),
            [(Stage::Registration, 0, 1), (Stage::Calibration, 3, 50)]
        );
        assert_eq!(Stage::Identification("Huber").describe(), "Huber");
    }
}
