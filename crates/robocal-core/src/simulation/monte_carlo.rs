//! Monte Carlo studies: many simulated sessions (or whole simulated calibrations) in parallel
//! with rayon, one seed per trial, reproducible whatever the number of threads.

use super::config::SimulationConfig;
use super::session::{simulate, Simulation};
use super::truth::TruthSpec;
use crate::error::Result;
use crate::model::Robot;
use crate::progress::{Observer, Stage};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The seed of trial `trial` of a study with base seed `base`: `base + trial` (wrapping), so a
/// single trial can be re-run alone, e.g. `robocal simulate --seed <base + trial>`.
pub fn trial_seed(base: u64, trial: usize) -> u64 {
    base.wrapping_add(trial as u64)
}

/// Runs `f(trial, seed)` for `trials` trials in parallel and returns the results in trial
/// order. Each trial gets its own seed ([`trial_seed`]) and must draw all its randomness from
/// it; the results then do not depend on the thread count or scheduling. `observer`
/// hears [`Stage::Trials`] (from worker threads) as trials finish.
pub fn run_trials<T, F>(trials: usize, base_seed: u64, observer: &dyn Observer, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize, u64) -> T + Sync,
{
    let done = AtomicUsize::new(0);
    (0..trials)
        .into_par_iter()
        .map(|i| {
            let r = f(i, trial_seed(base_seed, i));
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            observer.progress(Stage::Trials, d, trials);
            r
        })
        .collect()
}

/// Simulates `trials` sessions of the same cell design in parallel: trial i is
/// [`simulate`] with `config.seed = trial_seed(config.seed, i)` (so a `random` truth robot is
/// drawn anew per trial). The first error, in trial order, is returned.
pub fn simulate_trials(
    nominal: &Robot,
    truth: &TruthSpec,
    config: &SimulationConfig,
    trials: usize,
    observer: &dyn Observer,
) -> Result<Vec<Simulation>> {
    run_trials(trials, config.seed, observer, |_, seed| {
        let cfg = SimulationConfig {
            seed,
            ..config.clone()
        };
        simulate(nominal, truth, &cfg, &())
    })
    .into_iter()
    .collect()
}
