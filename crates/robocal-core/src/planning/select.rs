//! The selection of a plan's poses from the candidates' blocks: a greedy start (see
//! [`super::pooled`]), then exchange passes ([`super::design::Selector::exchange_pass`]) on a
//! shortlist of the chosen poses and the best others; and the estimate of its time that keeps
//! a plan within minutes.

use super::design::{Blocks, Criterion, Selector};
use super::pooled::{self, Fresh, POOL_MIN};
use crate::progress::Observer;
use nalgebra::DMatrix;

/// Largest number of exchange passes.
pub const MAX_EXCHANGE_PASSES: usize = 4;

/// Candidates the exchange passes consider besides the chosen poses: the best-scoring others
/// after the greedy selection, this many in all or half as many as the chosen poses, whichever
/// is more (scores change little once a design is good; passes over all candidates would cost
/// ten times as much for the same result).
const EXCHANGE_SHORTLIST: usize = 1500;

/// The longest plan run: a plan whose estimated time exceeds it is refused with the estimate.
pub const MAX_SECONDS: f64 = 600.0;

/// Arithmetic operations per second the estimate assumes (measured on two cores of a 2020s
/// laptop-class machine, see the note of [`estimated_seconds`]).
const OPS_PER_SECOND: f64 = 1.0e9;

/// How the greedy start is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Greedy {
    /// Fresh scores at checkpoints, eager updates within a pool between them (the default;
    /// see [`super::pooled`]).
    Pooled,
    /// Every candidate updated after each chosen pose (the former algorithm, `O(poses n k)`;
    /// kept to check the pooled one against).
    Eager,
}

/// What the selection produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The chosen candidates (indices into the blocks), in the order chosen.
    pub chosen: Vec<usize>,
    /// The criterion after the greedy start.
    pub greedy_value: f64,
    /// The criterion after the exchange passes.
    pub final_value: f64,
    /// Exchange passes run.
    pub passes: usize,
    /// Poses the exchange passes replaced.
    pub exchanges: usize,
}

/// The size of the exchange passes' shortlist for `poses` chosen poses out of `n` candidates.
fn shortlist_len(poses: usize, n: usize) -> usize {
    (poses + EXCHANGE_SHORTLIST.saturating_sub(poses).max(poses / 2)).min(n)
}

/// An estimate of the selection's time (s) for `poses` of `n` candidates and `k` parameters:
/// the greedy start's fresh scores (`n` at each of its checkpoints, about `6 k^2` operations
/// each) and its pools (every pose chosen against a pool, about `20 k` operations per pool
/// candidate), and the exchange passes (every chosen pose reconsidered against the
/// shortlist, about `20 k` operations per shortlisted candidate, at most
/// [`MAX_EXCHANGE_PASSES`] passes). An upper estimate: on the test machine (2 cores)
/// `plan --poses 2000 --candidates 200000` took well under it.
pub fn estimated_seconds(poses: usize, n: usize, k: usize) -> f64 {
    let (p, n, k) = (poses as f64, n as f64, k as f64);
    // Checkpoints after 0, 1, 2, 3, 4, 6, 9... poses; pools of ten per pose of the interval.
    let (mut checkpoints, mut c, mut pools) = (0.0, 0.0, 0.0);
    while c < p {
        let steps = (c / 2.0).floor().max(1.0).min(p - c);
        checkpoints += 1.0;
        pools += steps * (10.0 * steps).max(POOL_MIN as f64).min(n) * (20.0 * k + 40.0);
        c += steps;
    }
    let greedy = checkpoints * n * 6.0 * k * k + pools;
    let s = shortlist_len(poses, n as usize) as f64;
    let exchange = MAX_EXCHANGE_PASSES as f64 * p * s * (20.0 * k + 40.0);
    (greedy + exchange) / OPS_PER_SECOND
}

/// Chooses `poses` of the candidates `blocks` with the information starting at `base` (the
/// included poses and the ridge) for `criterion` (`w`: I-optimality's workspace weight).
pub fn choose(
    blocks: &Blocks,
    base: &DMatrix<f64>,
    criterion: Criterion,
    w: &DMatrix<f64>,
    poses: usize,
    greedy: Greedy,
    observer: &dyn Observer,
) -> Choice {
    let (chosen, greedy_value, scores) = match greedy {
        Greedy::Pooled => {
            let (chosen, value) = pooled::greedy(blocks, base, criterion, w, poses, observer);
            let info = base + blocks.information(&chosen);
            let scores = Fresh::new(blocks, info, criterion, w.clone()).scores();
            (chosen, value, scores)
        }
        Greedy::Eager => {
            let mut sel = Selector::new(blocks, base.clone(), criterion, Some(w.clone()));
            sel.greedy(poses);
            (sel.selected().to_vec(), sel.value(), sel.scores())
        }
    };
    // The exchange passes on a shortlist: the chosen poses first, then the best others.
    let mut taken = vec![false; blocks.len()];
    for &i in &chosen {
        taken[i] = true;
    }
    let mut others: Vec<usize> = (0..blocks.len()).filter(|&i| !taken[i]).collect();
    let extra = shortlist_len(chosen.len(), blocks.len()) - chosen.len();
    if extra < others.len() {
        let by_score = |a: &usize, b: &usize| scores[*b].total_cmp(&scores[*a]).then(a.cmp(b));
        others.select_nth_unstable_by(extra, by_score);
        others.truncate(extra);
        others.sort_by(by_score);
    }
    let short: Vec<usize> = chosen.iter().chain(&others).copied().collect();
    let sub = blocks.subset(&short);
    let mut ex = Selector::new(&sub, base.clone(), criterion, Some(w.clone()));
    ex.preselect(&(0..chosen.len()).collect::<Vec<_>>());
    let (mut passes, mut exchanges) = (0, 0);
    while passes < MAX_EXCHANGE_PASSES {
        let (swaps, gain) = ex.exchange_pass(observer);
        passes += 1;
        exchanges += swaps;
        // A pass that improves the criterion by less than 0.1% (ln det by 0.001) ends them.
        if swaps == 0 || gain < 1e-3 {
            break;
        }
    }
    Choice {
        chosen: ex.selected().iter().map(|&i| short[i]).collect(),
        greedy_value,
        final_value: ex.value(),
        passes,
        exchanges,
    }
}
