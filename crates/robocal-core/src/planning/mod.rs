//! Pose planning: which joint configurations are worth measuring.
//!
//! Candidates are random poses under the simulation's rules ([`crate::simulation::PoseSampler`]:
//! joint limits, floor, footprint; [`TrackerRange`]: the tracker's working range). Each
//! candidate contributes the Jacobian rows `J_i` of its tool point with respect to the
//! parameters the data can identify ([`crate::identification::analyze`] on the candidates),
//! every column scaled by its RMS over the candidates. With `M = sum J_i^T J_i` over the chosen
//! poses, the parameters' covariance is `sigma^2 M^-1` for a per-axis noise sigma, and the plan
//! optimizes one of two documented indices ([`Criterion`]), first greedily, then by exchange
//! passes ([`design`]) until a pass improves nothing:
//! - I-optimality (default): minimize `tr(W M^-1)`, `W` the mean `J_i^T J_i` over the
//!   candidates: the mean squared model error `sigma^2 tr(J M^-1 J^T)` that the parameters'
//!   uncertainty leaves over the workspace, the figure a calibration is judged by;
//! - D-optimality: maximize `det M`, the smallest joint confidence region of the parameters.
//!
//! The observability index reported is Borm and Menq's O1, `det(M)^(1/2k) / sqrt(N)` of the
//! scaled Jacobian (the geometric mean of its singular values per pose). The predicted standard
//! deviations are `sigma sqrt(diag(M^-1))`, and the predicted workspace error is the RMS over the
//! candidates of `sigma sqrt(tr(J_i M^-1 J_i^T))`.

mod builder;
pub mod constraint;
pub mod constraint_features;
pub mod design;
pub mod pooled;
pub mod select;
#[cfg(test)]
mod tests;

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::identification::prediction::point_jacobian;
use crate::identification::{analyze, IdentifiabilityOptions, Observations};
use crate::model::{Param, Robot};
use crate::progress::{Observer, Stage};
use crate::simulation::{random_poses_within, PoseSampler, TrackerRange};
pub use builder::{PlanBuilder, MAX_CANDIDATES, MAX_PLAN_NOISE};
pub use design::Criterion;
use design::{log_det, Blocks, ROWS};
use nalgebra::{DMatrix, Vector3};
use rand::SeedableRng;
use rayon::prelude::*;
pub use select::{Greedy, MAX_EXCHANGE_PASSES};

/// Default number of candidates.
pub const DEFAULT_CANDIDATES: usize = 10_000;

/// Candidates the identifiability analysis looks at (the identifiable set does not change with
/// more random poses).
const ANALYSIS_POSES: usize = 1000;

/// What a plan needs.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSettings {
    /// How many poses to choose (besides the included ones).
    pub poses: usize,
    /// How many random candidates to choose them from.
    pub candidates: usize,
    /// Seed of the candidates (and of the random poses compared against).
    pub seed: u64,
    /// Joint limits, floor and footprint rules.
    pub sampler: PoseSampler,
    /// The tracker's working range, if it limits the poses.
    pub tracker_range: Option<TrackerRange>,
    /// Poses that are measured anyway (joint values, internal units): part of the design, never
    /// exchanged, not written.
    pub include: Vec<Vec<f64>>,
    /// Per-axis measurement noise, constant part (mm).
    pub noise_mm: f64,
    /// Per-axis measurement noise per metre of distance from the tracker (mm/m), with
    /// `tracker_origin`.
    pub noise_per_m: f64,
    /// Where the tracker stands (base frame, mm), if known: then a pose's noise grows with its
    /// distance (`noise_mm + noise_per_m * d`) and the design weights it accordingly;
    /// otherwise every pose has `noise_mm`.
    pub tracker_origin: Option<Vector3<f64>>,
    /// What the selection optimizes (default: the mean model error over the workspace,
    /// I-optimality).
    pub criterion: Criterion,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            poses: 75,
            candidates: DEFAULT_CANDIDATES,
            seed: 1,
            sampler: PoseSampler::default(),
            tracker_range: None,
            include: Vec::new(),
            noise_mm: crate::simulation::DEFAULT_NOISE_MM,
            noise_per_m: crate::simulation::DEFAULT_NOISE_PER_M,
            tracker_origin: None,
            criterion: Criterion::IOptimal,
        }
    }
}

/// How well a set of poses identifies the parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Quality {
    /// Borm and Menq's O1 of the scaled Jacobian (see the module docs); 0 when it is singular.
    pub observability: f64,
    /// `ln det(J^T J)` of the scaled Jacobian (`-inf` when singular).
    pub log_det: f64,
    /// Predicted standard deviation of each identified parameter at the noise of the settings
    /// (internal units; NaN when singular).
    pub std: Vec<f64>,
    /// Predicted RMS model error over the workspace (the candidates) at that noise (mm).
    pub workspace_rms_mm: f64,
}

/// A plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The chosen poses (joint values, internal units), in the order chosen.
    pub poses: Vec<Vec<f64>>,
    /// The parameters the candidates identify (the design's columns).
    pub identified: Vec<Param>,
    /// The chosen poses (with the included ones).
    pub planned: Quality,
    /// As many random poses under the same rules (with the included ones), for comparison.
    pub random: Quality,
    /// The criterion after the greedy selection (`ln det M` or `tr(W M^-1)`, ridge included).
    pub greedy_value: f64,
    /// The criterion after the exchange passes.
    pub final_value: f64,
    /// Exchange passes run, and poses replaced in all.
    pub exchange_passes: usize,
    /// Poses the exchange passes replaced.
    pub exchanges: usize,
}

/// Random candidate poses under the settings' rules, in two independent streams: the
/// candidates, and the random set compared against.
fn draw(robot: &Robot, s: &PlanSettings, n: usize, stream: u64) -> Result<Vec<Vec<f64>>> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s.seed);
    rng.set_stream(stream);
    random_poses_within(robot, n, &s.sampler, s.tracker_range.as_ref(), &mut rng)
}

/// The tracker range of a tracker frame: distances from its origin.
pub fn tracker_range(frame: &TrackerFrame, min_mm: f64, max_mm: f64) -> Result<TrackerRange> {
    if !(min_mm >= 0.0 && max_mm > min_mm && max_mm.is_finite()) {
        return Err(Error::invalid(
            "tracker_range",
            format!("{min_mm}..{max_mm} mm is not a range of distances (0 <= min < max)"),
        ));
    }
    Ok(TrackerRange {
        origin: frame.origin(),
        min_mm,
        max_mm,
    })
}

/// The unscaled Jacobian blocks of poses `qs` for the parameters at `index`.
fn jacobians(robot: &Robot, index: &[usize], qs: &[Vec<f64>]) -> Vec<f64> {
    let k = index.len();
    let mut out = vec![0.0; qs.len() * ROWS * k];
    out.par_chunks_mut(ROWS * k)
        .zip(qs.par_iter())
        .for_each_init(
            || vec![Vector3::zeros(); robot.param_count()],
            |jp, (o, q)| {
                point_jacobian(robot, index, q, jp, o);
            },
        );
    out
}

/// Scales every column of `j` (blocks of `ROWS x k`) by `1 / scale`.
pub(crate) fn scale_columns(j: &mut [f64], k: usize, scale: &[f64]) {
    for row in j.chunks_exact_mut(k) {
        for (v, s) in row.iter_mut().zip(scale) {
            *v /= s;
        }
    }
}

/// Weights every block of poses `qs` by `noise_mm / sigma(q)`: the information of a noisier
/// pose counts less (see [`PlanSettings::tracker_origin`]).
fn weight_by_noise(j: &mut [f64], k: usize, robot: &Robot, qs: &[Vec<f64>], s: &PlanSettings) {
    let Some(origin) = s.tracker_origin else {
        return;
    };
    for (b, q) in j.chunks_exact_mut(ROWS * k).zip(qs) {
        let d_m = (robot.tool_position(q) - origin).norm() / 1000.0;
        let f = s.noise_mm / (s.noise_mm + s.noise_per_m * d_m);
        for v in b {
            *v *= f;
        }
    }
}

/// The quality of the information matrix `m` (scaled, no ridge) of `n` poses.
pub(crate) fn quality(
    m: &DMatrix<f64>,
    n: usize,
    scale: &[f64],
    blocks: &Blocks,
    noise: f64,
) -> Quality {
    let k = m.nrows();
    let ld = log_det(m);
    let (std, ws) = match m.clone().cholesky() {
        Some(ch) if ld.is_finite() => {
            let inv = ch.inverse();
            let std = (0..k)
                .map(|j| noise * inv[(j, j)].max(0.0).sqrt() / scale[j])
                .collect();
            // RMS over (up to 2000 of) the candidates of sigma^2 tr(J_i M^-1 J_i^T).
            let step = blocks.len().div_ceil(2000).max(1);
            let idx: Vec<usize> = (0..blocks.len()).step_by(step).collect();
            let sum: f64 = idx
                .par_iter()
                .map(|&i| {
                    let j = DMatrix::from_row_slice(ROWS, k, blocks.block(i));
                    (&j * &inv * j.transpose()).trace()
                })
                .sum();
            (std, noise * (sum / idx.len().max(1) as f64).sqrt())
        }
        _ => (vec![f64::NAN; k], f64::NAN),
    };
    Quality {
        observability: if ld.is_finite() {
            (ld / (2.0 * k as f64)).exp() / (n.max(1) as f64).sqrt()
        } else {
            0.0
        },
        log_det: ld,
        std,
        workspace_rms_mm: ws,
    }
}

/// Plans `settings.poses` poses for `robot` (see the module docs).
pub fn plan(robot: &Robot, settings: &PlanSettings) -> Result<Plan> {
    plan_observed(robot, settings, &())
}

/// [`plan`], reporting its progress to `observer` ([`Stage::Candidates`], then
/// [`Stage::PoseSelection`] and [`Stage::Exchange`]). A plan whose estimated time
/// ([`select::estimated_seconds`]) exceeds [`select::MAX_SECONDS`] is refused with the estimate.
pub fn plan_observed(
    robot: &Robot,
    settings: &PlanSettings,
    observer: &dyn Observer,
) -> Result<Plan> {
    plan_with(robot, settings, Greedy::Pooled, observer)
}

/// [`plan_observed`] with the greedy start made as `greedy` says.
pub fn plan_with(
    robot: &Robot,
    settings: &PlanSettings,
    greedy: Greedy,
    observer: &dyn Observer,
) -> Result<Plan> {
    let s = settings;
    check_settings(robot, s)?;
    observer.progress(Stage::Candidates, 0, 1);
    let candidates = offered_candidates(robot, s)?;
    let random = draw(robot, s, s.poses, 2)?;
    let identified = identifiable(robot, s, &candidates)?;
    let k = identified.len();
    check_size(s, candidates.len(), k)?;
    let d = design_inputs(robot, s, &identified, &candidates);
    let ridge = DMatrix::identity(k, k) * 1e-6;
    observer.progress(Stage::Candidates, 1, 1);

    let c = select::choose(
        &d.blocks,
        &(&d.fixed + &ridge),
        s.criterion,
        &d.w,
        s.poses,
        greedy,
        observer,
    );
    let chosen = c.chosen;
    let n_all = s.poses + s.include.len();
    let planned = quality(
        &(&d.fixed + d.blocks.information(&chosen)),
        n_all,
        &d.scale,
        &d.workspace,
        s.noise_mm,
    );
    let random_q = random_quality(robot, s, &d, &random, n_all);
    Ok(Plan {
        poses: chosen.iter().map(|&i| candidates[i].clone()).collect(),
        identified,
        planned,
        random: random_q,
        greedy_value: c.greedy_value,
        final_value: c.final_value,
        exchange_passes: c.passes,
        exchanges: c.exchanges,
    })
}

/// Checks the settings a plan cannot start without: at least one pose, as many candidates as
/// poses, a positive noise, a non-negative noise per metre, and included poses with the robot's
/// joint count.
fn check_settings(robot: &Robot, s: &PlanSettings) -> Result<()> {
    if s.poses == 0 {
        return Err(Error::invalid("poses", "must be at least 1"));
    }
    if s.candidates < s.poses {
        return Err(Error::invalid(
            "candidates",
            format!(
                "{} candidates cannot give {} poses: give at least as many candidates as poses \
                 (ten times as many or more for a good plan)",
                s.candidates, s.poses
            ),
        ));
    }
    if !(s.noise_mm > 0.0 && s.noise_mm.is_finite()) {
        return Err(Error::invalid(
            "noise_mm",
            format!("{} is not a positive length (mm)", s.noise_mm),
        ));
    }
    if !(s.noise_per_m >= 0.0 && s.noise_per_m.is_finite()) {
        return Err(Error::invalid(
            "noise_per_m",
            format!(
                "{} is not a non-negative noise per metre (mm/m)",
                s.noise_per_m
            ),
        ));
    }
    for (i, q) in s.include.iter().enumerate() {
        if q.len() != robot.dof() {
            return Err(Error::invalid(
                "include",
                format!(
                    "pose {} has {} joint values, robot `{}` has {} joints",
                    i + 1,
                    q.len(),
                    robot.name(),
                    robot.dof()
                ),
            ));
        }
    }
    Ok(())
}

/// The candidate poses offered to the selection: `s.candidates` random poses (stream 1) less
/// those already among the included poses.
fn offered_candidates(robot: &Robot, s: &PlanSettings) -> Result<Vec<Vec<f64>>> {
    // Candidates already among the included poses (same seed, same rules) are not offered.
    let mut candidates = draw(robot, s, s.candidates, 1)?;
    let taken: std::collections::HashSet<Vec<u64>> = s
        .include
        .iter()
        .map(|q| q.iter().map(|v| v.to_bits()).collect())
        .collect();
    candidates.retain(|q| !taken.contains(&q.iter().map(|v| v.to_bits()).collect::<Vec<_>>()));
    Ok(candidates)
}

/// The parameters the included poses and (the first [`ANALYSIS_POSES`] of) the candidates
/// identify.
fn identifiable(robot: &Robot, s: &PlanSettings, candidates: &[Vec<f64>]) -> Result<Vec<Param>> {
    // The identifiable parameters: analysis of the candidates at their nominal tool points.
    let mut obs = Observations::new(robot.dof());
    for (line, q) in s
        .include
        .iter()
        .chain(candidates.iter().take(ANALYSIS_POSES))
        .enumerate()
    {
        obs.push(q, robot.tool_position(q), line + 1)?;
    }
    let ident = analyze(robot, &obs, &IdentifiabilityOptions::default())?;
    Ok(ident.identified)
}

/// Checks that the plan can identify `k` parameters (at least `k` poses with the included
/// ones) and that its estimated time is within [`select::MAX_SECONDS`].
fn check_size(s: &PlanSettings, n_candidates: usize, k: usize) -> Result<()> {
    if s.poses + s.include.len() < k {
        return Err(Error::invalid(
            "poses",
            format!(
                "{} poses{} for {k} identifiable parameters: a calibration needs at least {k}",
                s.poses + s.include.len(),
                if s.include.is_empty() {
                    String::new()
                } else {
                    format!(" ({} included)", s.include.len())
                }
            ),
        ));
    }
    let secs = select::estimated_seconds(s.poses, n_candidates, k);
    if secs > select::MAX_SECONDS {
        return Err(Error::invalid(
            "poses",
            format!(
                "{} poses of {} candidates for {k} parameters would take about {} minutes \
                 (estimated; a plan is limited to {} minutes): choose fewer poses or \
                 candidates, or plan in parts, each part's poses included in the next",
                s.poses,
                n_candidates,
                (secs / 60.0).ceil(),
                select::MAX_SECONDS / 60.0
            ),
        ));
    }
    Ok(())
}

/// What the selection and the qualities work on: the candidates' scaled Jacobian blocks and
/// the information they share.
struct DesignInputs {
    /// Positions of the identified parameters among the robot's.
    index: Vec<usize>,
    /// Each column's RMS over the candidates (the columns are divided by it).
    scale: Vec<f64>,
    /// The candidates' scaled blocks, not noise-weighted: the workspace.
    workspace: Blocks,
    /// The workspace's mean `J^T J`.
    w: DMatrix<f64>,
    /// The candidates' scaled, noise-weighted blocks the selection chooses from.
    blocks: Blocks,
    /// The information of the included poses (zero without them).
    fixed: DMatrix<f64>,
}

/// The design's inputs for `identified` over `candidates` and the included poses.
fn design_inputs(
    robot: &Robot,
    s: &PlanSettings,
    identified: &[Param],
    candidates: &[Vec<f64>],
) -> DesignInputs {
    let k = identified.len();
    let index: Vec<usize> = identified
        .iter()
        .map(|p| robot.param_position(*p).expect("a parameter of the robot"))
        .collect();

    let mut jc = jacobians(robot, &index, candidates);
    let scale = column_scale(&jc, k);
    scale_columns(&mut jc, k, &scale);
    // The workspace's mean J^T J: the candidates' model-error blocks, not noise-weighted.
    let workspace = Blocks::new(k, jc.clone());
    let all: Vec<usize> = (0..workspace.len()).collect();
    let w = workspace.information(&all) / workspace.len().max(1) as f64;
    weight_by_noise(&mut jc, k, robot, candidates, s);
    let blocks = Blocks::new(k, jc);
    let fixed = included_information(robot, s, &index, &scale);
    DesignInputs {
        index,
        scale,
        workspace,
        w,
        blocks,
        fixed,
    }
}

/// The RMS of each of the `k` columns of the Jacobian blocks `jc` (at least the smallest
/// positive number).
fn column_scale(jc: &[f64], k: usize) -> Vec<f64> {
    (0..k)
        .map(|a| {
            let ss: f64 = jc.chunks_exact(k).map(|row| row[a] * row[a]).sum();
            (ss * ROWS as f64 / jc.len().max(1) as f64 * k as f64)
                .sqrt()
                .max(f64::MIN_POSITIVE)
        })
        .collect()
}

/// The information matrix of the included poses (scaled, noise-weighted), zero without them.
fn included_information(
    robot: &Robot,
    s: &PlanSettings,
    index: &[usize],
    scale: &[f64],
) -> DMatrix<f64> {
    let k = index.len();
    let mut ji = jacobians(robot, index, &s.include);
    scale_columns(&mut ji, k, scale);
    weight_by_noise(&mut ji, k, robot, &s.include, s);
    let included = Blocks::new(k, ji);
    let all_included: Vec<usize> = (0..s.include.len()).collect();
    if s.include.is_empty() {
        DMatrix::zeros(k, k)
    } else {
        included.information(&all_included)
    }
}

/// The quality of the random poses `random` with the included ones, `n_all` poses in all.
fn random_quality(
    robot: &Robot,
    s: &PlanSettings,
    d: &DesignInputs,
    random: &[Vec<f64>],
    n_all: usize,
) -> Quality {
    let k = d.index.len();
    let mut jr = jacobians(robot, &d.index, random);
    scale_columns(&mut jr, k, &d.scale);
    weight_by_noise(&mut jr, k, robot, random, s);
    let rb = Blocks::new(k, jr);
    let all_random: Vec<usize> = (0..random.len()).collect();
    quality(
        &(&d.fixed + rb.information(&all_random)),
        n_all,
        &d.scale,
        &d.workspace,
        s.noise_mm,
    )
}
