//! Planning constraint configurations (issue 31): which configurations touching fixed points,
//! spheres or planes are worth measuring when there is no tracker.
//!
//! Candidates are configurations of the nominal robot that reach each feature from varied tool
//! orientations ([`constraint_features`](super::constraint_features): inverse kinematics with
//! `simulate --constraint`'s generator). Each candidate contributes the rows the constraint fit
//! ([`crate::identification::constraint`]) would get from it: a fixed point's three, a sphere's
//! or a plane's one, with columns for the robot parameters the data identify AND the features'
//! own parameters, which are estimated with them; known distances add their rows to every
//! design. The selection is the tracker planner's ([`super::select::choose`], greedy then
//! exchange passes) on that information matrix `M`:
//! - I-optimality (default) with the weight `W` zero in the features' columns and, in the robot
//!   block, the mean `J^T J` of the tool point over random workspace poses: `tr(W M^-1)` is then
//!   `tr(W_rr S^-1)` with `S` the Schur complement of the features' block, the robot's
//!   information once the features are eliminated, i.e. the mean squared model error over the
//!   workspace that the parameters' uncertainty leaves (before the rigid alignment a constraint
//!   calibration is judged after, so an upper bound of it);
//! - D-optimality: `det M` of all unknowns (`det` of the features' block times `det S`).
//!
//! Each feature first gets the fewest rows it needs ([`ConstraintKind::min_rows`]), chosen by the
//! same criterion among its own candidates; the rest of the poses go wherever they help most.
//! What the data cannot see is what the calibration says (the base pose always, the scale
//! without a known length, a plane's blind directions): the planned set is analysed by
//! [`calibrate_constraints`] itself on noise-free nominal rows, and the design's columns are
//! the parameters that analysis identifies on the candidates.

use super::constraint_features::{candidates, FeaturePlaces};
use super::design::{Blocks, Criterion, ROWS};
use super::select::{self, choose, Greedy};
use super::{quality, scale_columns, Quality};
use crate::error::{Error, Result};
use crate::identification::constraint::fit::{evaluate, Layout};
use crate::identification::constraint::{
    calibrate_constraints, ConstraintOptions, FeatureEstimate, Fixed,
};
use crate::identification::prediction::point_jacobian;
use crate::model::{Param, Robot};
use crate::observations::constraint::{ConstraintData, ConstraintKind};
use crate::progress::{Observer, Stage};
use crate::simulation::constraint::ConstraintSimulation;
use crate::simulation::{random_poses, PoseSampler};
use nalgebra::{DMatrix, Vector3};
use rand::SeedableRng;

/// Default candidate configurations per feature.
pub const DEFAULT_CANDIDATES_PER_FEATURE: usize = 200;

/// Most candidate configurations per feature.
pub const MAX_CANDIDATES_PER_FEATURE: usize = 5000;

/// Candidate rows per feature the identifiability analysis looks at.
const ANALYSIS_ROWS: usize = 60;

/// Random workspace poses the model error is averaged over.
const WORKSPACE_POSES: usize = 1000;

/// What a constraint plan needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintPlanSettings {
    /// The features and how configurations reach them, as `simulate --constraint` takes them:
    /// kind, count and sphere radius (for drawn places), `per_feature` (the plan chooses
    /// `features x per_feature` configurations in all), tilt and span, whether the distances
    /// between points or sphere centres will be known (measured), the contact's noise and the
    /// seed.
    pub spec: ConstraintSimulation,
    /// Where the features are.
    pub places: FeaturePlaces,
    /// Candidate configurations per feature.
    pub candidates_per_feature: usize,
    /// Joint limits, floor and footprint rules of the drawn configurations.
    pub sampler: PoseSampler,
    /// What the selection optimizes.
    pub criterion: Criterion,
}

impl Default for ConstraintPlanSettings {
    fn default() -> Self {
        ConstraintPlanSettings {
            spec: ConstraintSimulation::default(),
            places: FeaturePlaces::Drawn,
            candidates_per_feature: DEFAULT_CANDIDATES_PER_FEATURE,
            sampler: PoseSampler::default(),
            criterion: Criterion::IOptimal,
        }
    }
}

/// A constraint plan.
#[derive(Debug, Clone)]
pub struct ConstraintPlan {
    /// The chosen configurations (grouped by feature, in the order chosen within each) with
    /// their features and, when known, the distances (nominal values: measure them).
    pub data: ConstraintData,
    /// As many configurations drawn at random among the candidates (the first of each
    /// feature's, as `simulate --constraint` draws them), for comparison.
    pub random: ConstraintData,
    /// The features at their nominal places (base frame of the nominal robot).
    pub features: Vec<FeatureEstimate>,
    /// The robot parameters the plan's design covers.
    pub identified: Vec<Param>,
    /// The robot parameters the planned data leave at their nominal values, with why.
    pub fixed: Vec<Fixed>,
    /// What the planned data cannot see, in words, as the calibration will say it.
    pub unseen: Vec<String>,
    /// Whether the data carry a length (known distances or a sphere's radius); without, a
    /// calibration of them must accept a result up to scale.
    pub scale_known: bool,
    /// The quality of the chosen configurations (standard deviations of the robot parameters
    /// only, at the spec's noise).
    pub planned: Quality,
    /// The quality of the random ones.
    pub random_quality: Quality,
    /// The combinations of robot parameters the chosen configurations determine least, as they
    /// matter for the model error (see [`weakest`]), largest share first: at most
    /// [`WEAKEST_SHOWN`].
    pub weakest: Vec<WeakDirection>,
    /// Exchange passes run (after the per-feature minimum), and poses replaced in all.
    pub exchange_passes: usize,
    /// Poses the exchange passes replaced.
    pub exchanges: usize,
}

/// Most weak directions a plan reports.
pub const WEAKEST_SHOWN: usize = 3;

/// A combination of robot parameters the planned data determine least.
#[derive(Debug, Clone, PartialEq)]
pub struct WeakDirection {
    /// Its share of the predicted workspace model error: the square root of its part of the
    /// mean squared error (mm; the parts of every direction add up to the square of
    /// [`Quality::workspace_rms_mm`]).
    pub rms_mm: f64,
    /// The parameters that make it up, largest weight first (column-scaled units, the largest
    /// 1 in size; those under 0.3 of it left out, at most four).
    pub params: Vec<(Param, f64)>,
}

/// The directions of the robot parameters' information once the features are eliminated (the
/// Schur complement `S` of the features' block of `m`, scaled units), each with its part
/// `noise^2 v^T W v / lambda` of the predicted mean squared workspace error (`W` the robot
/// block of the workspace weight `w`), largest first. Empty when the features' block is
/// singular.
pub fn weakest(
    m: &DMatrix<f64>,
    w: &DMatrix<f64>,
    params: &[Param],
    noise_mm: f64,
) -> Vec<WeakDirection> {
    let (n, kr) = (m.nrows(), params.len());
    let mrr = m.view((0, 0), (kr, kr)).into_owned();
    let s = if n > kr {
        let mrf = m.view((0, kr), (kr, n - kr)).into_owned();
        let Some(ch) = m.view((kr, kr), (n - kr, n - kr)).into_owned().cholesky() else {
            return Vec::new();
        };
        &mrr - &mrf * ch.solve(&mrf.transpose())
    } else {
        mrr
    };
    let wrr = w.view((0, 0), (kr, kr)).into_owned();
    let eig = nalgebra::SymmetricEigen::new(s);
    let mut out: Vec<WeakDirection> = (0..kr)
        .filter(|&i| eig.eigenvalues[i] > 0.0)
        .map(|i| {
            let v = eig.eigenvectors.column(i);
            let part =
                noise_mm * noise_mm * (v.transpose() * &wrr * v)[(0, 0)] / eig.eigenvalues[i];
            let big = v.amax().max(f64::MIN_POSITIVE);
            let mut ps: Vec<(Param, f64)> = (0..kr)
                .filter(|&j| v[j].abs() >= 0.3 * big)
                .map(|j| (params[j], v[j] / big))
                .collect();
            ps.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
            ps.truncate(4);
            WeakDirection {
                rms_mm: part.max(0.0).sqrt(),
                params: ps,
            }
        })
        .collect();
    out.sort_by(|a, b| b.rms_mm.total_cmp(&a.rms_mm));
    out
}

/// Plans constraint configurations for `robot` (see the module docs).
pub fn plan_constraints(
    robot: &Robot,
    settings: &ConstraintPlanSettings,
    observer: &dyn Observer,
) -> Result<ConstraintPlan> {
    let s = settings;
    check_settings(s)?;
    let g = robot.geometric();
    observer.progress(Stage::Candidates, 0, 1);
    let cand_spec = ConstraintSimulation {
        per_feature: s.candidates_per_feature,
        noise_mm: 0.0,
        ..s.spec.clone()
    };
    let sim = candidates(&g, &s.sampler, &cand_spec, &s.places)?;
    let cand = sim.data;
    let features: Vec<FeatureEstimate> = cand
        .features
        .iter()
        .enumerate()
        .map(|(k, f)| nominal_feature(f, sim.true_positions[k], sim.true_normals[k], &cand_spec))
        .collect();
    let scale_known = cand.has_known_length();
    let opts = ConstraintOptions {
        accept_unknown_scale: !scale_known,
        ..ConstraintOptions::default()
    };
    // The robot parameters such data identify (the calibration's own analysis).
    let analysis = calibrate_constraints(
        &g,
        &subset(&cand, &first_of_each(&cand, ANALYSIS_ROWS)),
        &opts,
    )?;
    let identified = analysis.identified.clone();
    let layout = Layout::new(&g, &identified, &features);
    let poses = cand.features.len() * s.spec.per_feature;
    check_time(poses, &cand, layout.n)?;
    let d = Design::of(&g, &layout, &cand, &features, s)?;
    observer.progress(Stage::Candidates, 1, 1);
    let (chosen, passes, exchanges) = select_rows(&d, &cand, s, poses, observer);
    let random_idx = first_of_each(&cand, s.spec.per_feature);
    let judge = |idx: &[usize]| {
        let mut q = quality(
            &(&d.fixed_info + d.blocks.information(idx)),
            idx.len(),
            &d.scale,
            &d.workspace,
            s.spec.noise_mm,
        );
        q.std.truncate(identified.len());
        q
    };
    let planned = judge(&chosen);
    let mut weak = weakest(
        &(&d.fixed_info + d.blocks.information(&chosen)),
        &d.w,
        &identified,
        s.spec.noise_mm,
    );
    weak.truncate(WEAKEST_SHOWN);
    let random_quality = judge(&random_idx);
    // Grouped by feature, in the order chosen within each.
    let mut grouped = chosen.clone();
    grouped.sort_by_key(|&i| cand.rows[i].feature);
    let data = subset(&cand, &grouped);
    let said = calibrate_constraints(&g, &data, &opts)?;
    Ok(ConstraintPlan {
        random: subset(&cand, &random_idx),
        data,
        features,
        identified,
        fixed: said.fixed,
        unseen: said.unseen,
        scale_known,
        planned,
        random_quality,
        weakest: weak,
        exchange_passes: passes,
        exchanges,
    })
}

/// The settings a plan needs beyond the simulation's: a positive noise (the predicted errors
/// scale with it), and at least as many candidates per feature as poses.
fn check_settings(s: &ConstraintPlanSettings) -> Result<()> {
    s.spec.validate()?;
    if s.spec.noise_mm <= 0.0 || s.spec.noise_mm.is_nan() {
        return Err(Error::invalid(
            "noise_mm",
            "must be positive for a plan (the predicted errors scale with it)",
        ));
    }
    if s.candidates_per_feature < s.spec.per_feature
        || s.candidates_per_feature > MAX_CANDIDATES_PER_FEATURE
    {
        return Err(Error::invalid(
            "candidates_per_feature",
            format!(
                "{} is not within {}..{MAX_CANDIDATES_PER_FEATURE} (at least the poses per \
                 feature; ten times as many or more for a good plan)",
                s.candidates_per_feature, s.spec.per_feature
            ),
        ));
    }
    Ok(())
}

/// Refuses a selection of `poses` among the candidates for `n` unknowns estimated to take longer
/// than a plan may.
fn check_time(poses: usize, cand: &ConstraintData, n: usize) -> Result<()> {
    let secs = select::estimated_seconds(poses, cand.rows.len(), n);
    if secs > select::MAX_SECONDS {
        return Err(Error::invalid(
            "candidates_per_feature",
            format!(
                "{poses} configurations of {} candidates for {n} unknowns would take about {} \
                 minutes (estimated; a plan is limited to {} minutes): choose fewer candidates",
                cand.rows.len(),
                (secs / 60.0).ceil(),
                select::MAX_SECONDS / 60.0
            ),
        ));
    }
    Ok(())
}

/// What the selection works with: the candidates' scaled rows, the known distances'
/// information, the workspace's rows and their mean information.
struct Design {
    /// RMS of each unknown's column over the candidates (the columns are divided by it).
    scale: Vec<f64>,
    blocks: Blocks,
    /// The known distances' information.
    fixed_info: DMatrix<f64>,
    workspace: Blocks,
    /// The workspace's mean information (the criterion's weight).
    w: DMatrix<f64>,
}

impl Design {
    /// The design of the candidates `cand` for the unknowns of `layout`.
    fn of(
        g: &Robot,
        layout: &Layout,
        cand: &ConstraintData,
        features: &[FeatureEstimate],
        s: &ConstraintPlanSettings,
    ) -> Result<Design> {
        let n = layout.n;
        let (mut jc, dist) = blocks_of(g, layout, cand, features);
        let scale: Vec<f64> = (0..n)
            .map(|a| {
                let ss: f64 = jc.chunks_exact(n).map(|row| row[a] * row[a]).sum();
                (ss / cand.rows.len().max(1) as f64)
                    .sqrt()
                    .max(f64::MIN_POSITIVE)
            })
            .collect();
        scale_columns(&mut jc, n, &scale);
        let blocks = Blocks::new(n, jc);
        let mut dj = dist;
        scale_columns(&mut dj, n, &scale);
        let known = DMatrix::from_row_slice(dj.len() / n, n, &dj);
        let fixed_info = known.transpose() * &known;
        let workspace = workspace_blocks(g, layout, &s.sampler, s.spec.seed, &scale)?;
        let all: Vec<usize> = (0..workspace.len()).collect();
        let w = workspace.information(&all) / workspace.len().max(1) as f64;
        Ok(Design {
            scale,
            blocks,
            fixed_info,
            workspace,
            w,
        })
    }
}

/// The rows chosen: each feature's minimum by the criterion, then the rest among all; with the
/// last selection's exchange passes and exchanges.
fn select_rows(
    d: &Design,
    cand: &ConstraintData,
    s: &ConstraintPlanSettings,
    poses: usize,
    observer: &dyn Observer,
) -> (Vec<usize>, usize, usize) {
    let n = d.w.nrows();
    let ridge = DMatrix::identity(n, n) * 1e-6;
    let mut base = &d.fixed_info + &ridge;
    let mut chosen: Vec<usize> = Vec::with_capacity(poses);
    for k in 0..cand.features.len() {
        let own: Vec<usize> = (0..cand.rows.len())
            .filter(|&i| cand.rows[i].feature == k)
            .collect();
        let m = cand.features[k].kind.min_rows();
        let c = choose(
            &d.blocks.subset(&own),
            &base,
            s.criterion,
            &d.w,
            m,
            Greedy::Pooled,
            observer,
        );
        let picked: Vec<usize> = c.chosen.iter().map(|&i| own[i]).collect();
        base += d.blocks.information(&picked);
        chosen.extend(picked);
    }
    let (mut passes, mut exchanges) = (0, 0);
    if poses > chosen.len() {
        let rest: Vec<usize> = (0..cand.rows.len())
            .filter(|i| !chosen.contains(i))
            .collect();
        let c = choose(
            &d.blocks.subset(&rest),
            &base,
            s.criterion,
            &d.w,
            poses - chosen.len(),
            Greedy::Pooled,
            observer,
        );
        passes = c.passes;
        exchanges = c.exchanges;
        chosen.extend(c.chosen.iter().map(|&i| rest[i]));
    }
    (chosen, passes, exchanges)
}

/// A feature's estimate at its nominal place.
fn nominal_feature(
    f: &crate::observations::constraint::Feature,
    position: Vector3<f64>,
    normal: Option<Vector3<f64>>,
    spec: &ConstraintSimulation,
) -> FeatureEstimate {
    let mut e = FeatureEstimate {
        kind: f.kind,
        name: f.name.clone(),
        position,
        radius_mm: (f.kind == ConstraintKind::Sphere)
            .then_some(f.radius_mm.unwrap_or(spec.radius_mm)),
        radius_known: f.radius_mm.is_some(),
        normal: None,
        offset_mm: None,
    };
    if let Some(n) = normal {
        e.normal = Some(n);
        e.offset_mm = Some(n.dot(&position));
        e.position = n * n.dot(&position);
    }
    e
}

/// The first `per` rows of each feature (indices into `data.rows`).
fn first_of_each(data: &ConstraintData, per: usize) -> Vec<usize> {
    let mut count = vec![0usize; data.features.len()];
    (0..data.rows.len())
        .filter(|&i| {
            let c = &mut count[data.rows[i].feature];
            *c += 1;
            *c <= per
        })
        .collect()
}

/// The data of rows `idx` of `data` (features and distances kept).
fn subset(data: &ConstraintData, idx: &[usize]) -> ConstraintData {
    ConstraintData {
        rows: idx.iter().map(|&i| data.rows[i].clone()).collect(),
        ..data.clone()
    }
}

/// Every candidate row's block (`ROWS x n`, rows past a feature's own zero) and the known
/// distances' rows (`n` each), unscaled.
fn blocks_of(
    robot: &Robot,
    layout: &Layout,
    data: &ConstraintData,
    features: &[FeatureEstimate],
) -> (Vec<f64>, Vec<f64>) {
    let n = layout.n;
    let (_, j) = evaluate(robot, layout, data, features, None, true);
    let j = j.expect("asked for");
    let mut out = vec![0.0; data.rows.len() * ROWS * n];
    let mut row = 0;
    for (i, r) in data.rows.iter().enumerate() {
        for a in 0..features[r.feature].rows() {
            for c in 0..n {
                out[(i * ROWS + a) * n + c] = j[(row, c)];
            }
            row += 1;
        }
    }
    let dist = (row..j.nrows())
        .flat_map(|r| (0..n).map(move |c| (r, c)))
        .map(|(r, c)| j[(r, c)])
        .collect();
    (out, dist)
}

/// The tool point's Jacobian blocks at random workspace poses, in the design's columns (the
/// features' zero), scaled.
fn workspace_blocks(
    robot: &Robot,
    layout: &Layout,
    sampler: &PoseSampler,
    seed: u64,
    scale: &[f64],
) -> Result<Blocks> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(3);
    let qs = random_poses(robot, WORKSPACE_POSES, sampler, &mut rng)?;
    let (n, kr) = (layout.n, layout.index.len());
    let mut jp = vec![Vector3::zeros(); robot.param_count()];
    let mut point = vec![0.0; ROWS * kr];
    let mut out = vec![0.0; qs.len() * ROWS * n];
    for (b, q) in out.chunks_exact_mut(ROWS * n).zip(&qs) {
        point_jacobian(robot, &layout.index, q, &mut jp, &mut point);
        for a in 0..ROWS {
            b[a * n..a * n + kr].copy_from_slice(&point[a * kr..(a + 1) * kr]);
        }
    }
    scale_columns(&mut out, n, scale);
    Ok(Blocks::new(n, out))
}

#[cfg(test)]
#[path = "constraint_tests.rs"]
mod tests;
