//! Predicted accuracy of a calibrated model at poses it was not fitted to.
//!
//! At a new pose q the error of the calibrated model against a measurement is
//! `e = J(q) delta + eps`: the estimates' error `delta` (covariance `C`, see [`Covariance`])
//! seen through the tool point's Jacobian `J(q)` of the identified parameters, plus the new
//! measurement's own noise `eps` (per-axis standard deviation `sigma`, estimated from the
//! calibration residuals). So `e` is Gaussian with covariance `Sigma(q) = J C J^T + sigma^2 I`,
//! and the expected error norm at q is `E|e|`, computed from `Sigma`'s eigenvalues (closed form)
//! by a fixed Gauss quadrature over the sphere (deterministic; exact to about 1e-6).
//! Averaged over the calibration poses, that is the expected mean error at new poses spread like
//! them ([`Prediction::mean_mm`]), the figure a validation set measures. Each pose's `J(q)` is
//! taken under its row's conditions (temperature, approach directions), as the fit took it: the
//! thermal and backlash families' columns vanish without them.

use crate::identification::covariance::Covariance;
use crate::identification::simd::with_avx;
use crate::identification::system::add_gram;
use crate::kinematics::Conditions;
use crate::model::{Param, Robot};
use crate::observations::Observations;
use crate::simulation::{random_poses, PoseSampler};
use nalgebra::{DMatrix, Matrix3, Vector3};
use rand::SeedableRng;

/// Gauss-Legendre nodes per coordinate of the sphere's octant ([`NormExpectation`]): 12 x 12
/// = 144 evaluations per pose, against 512 directions of a Fibonacci sphere (0.5%) and 8192
/// random normals (the first version, 12 ms of a 14 ms 75-pose calibration) before.
const QUADRATURE_NODES: usize = 12;

/// Most poses averaged over: larger sets are thinned evenly (the mean changes by far less than
/// the prediction's own uncertainty).
const MAX_POSES: usize = 4000;

/// Poses of the workspace map ([`Prediction::map`]).
pub const MAP_POSES: usize = 300;

/// One point of the map of predicted error over the workspace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapPoint {
    /// The tool position of the calibrated model, base frame (mm).
    pub position: Vector3<f64>,
    /// Expected error norm of a measurement there (mm): noise and parameter uncertainty.
    pub mean_mm: f64,
    /// RMS of the model's own error there, `sqrt(tr(J C J^T))` (mm): parameter uncertainty
    /// alone, what a perfect measurement would see.
    pub model_mm: f64,
}

/// The predicted accuracy of a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Expected mean error norm at new poses spread like the calibration poses (mm).
    pub mean_mm: f64,
    /// Standard deviation of the error norm over such poses (mm).
    pub std_mm: f64,
    /// Expected RMS error norm (mm).
    pub rms_mm: f64,
    /// The per-axis measurement noise used (mm): RMS of the calibration residuals not
    /// down-weighted, corrected for the fitted parameters' degrees of freedom.
    pub noise_sigma_mm: f64,
    /// The mean error the parameters' uncertainty alone leaves at those poses (mm RMS).
    pub model_rms_mm: f64,
    /// Predicted error at random poses within the joint limits, no lower than the lowest
    /// calibration point ([`MAP_POSES`] of them).
    pub map: Vec<MapPoint>,
}

/// The tool point's Jacobian rows (3 x k, row-major into `out`) with respect to the parameters at
/// `index` (positions in `robot.params()`), at joints `q`. `jp` is scratch of
/// `robot.param_count()` screws.
pub fn point_jacobian(
    robot: &Robot,
    index: &[usize],
    q: &[f64],
    jp: &mut [Vector3<f64>],
    out: &mut [f64],
) -> Vector3<f64> {
    target_jacobian(robot, index, q, 0, &Conditions::UNKNOWN, jp, out)
}

#[path = "prediction_norms.rs"]
mod norms;
use norms::NormExpectation;
#[cfg(test)]
use norms::{gauss_legendre, sym3_eigenvalues};

/// From this many poses, the per-pose work of a prediction runs on several threads (each pose's
/// figures are computed on their own and summed in order: the same bits on any thread count).
/// Below it one thread does it: for the workspace map's [`MAP_POSES`] (4.1 M instructions in
/// callgrind, its text in the result included: the run with no map takes that many fewer)
/// starting the thread pool and handing the work over cost more CPU time than they save
/// (measured on the paper's 75 poses with `--model geometric`, whose map was then the run's
/// only parallel work: 4.7-5.3 ms of CPU on one thread against 5.3-5.5 ms, 8 context switches
/// against 13-17).
const PARALLEL_MIN_POSES: usize = 512;

/// `f(i)` for `i` in `0..n`, in order; on several threads for large `n`. `scratch` makes each
/// thread's (or the single loop's) reusable buffers.
fn map_poses<T: Send, S>(
    n: usize,
    scratch: impl Fn() -> S + Sync + Send,
    f: impl Fn(&mut S, usize) -> T + Sync + Send,
) -> Vec<T> {
    use rayon::prelude::*;
    if n >= PARALLEL_MIN_POSES {
        (0..n)
            .into_par_iter()
            .map_init(&scratch, |s, i| f(s, i))
            .collect()
    } else {
        let mut s = scratch();
        (0..n).map(|i| f(&mut s, i)).collect()
    }
}

/// The predictor of a calibration: calibrated model, covariance of its identified parameters and
/// the measurement noise.
pub struct Predictor<'a> {
    robot: &'a Robot,
    index: Vec<usize>,
    /// The covariance, row-major (k x k).
    cov: Vec<f64>,
    /// Its Cholesky factor `L` (`C = L L^T`, lower, row-major), when `C` is positive definite:
    /// then `J C J^T = (J L)(J L)^T` at half the cost.
    factor: Option<Vec<f64>>,
    sigma: f64,
    norms: NormExpectation,
}

/// Reusable buffers of one thread's predictions.
struct Scratch {
    jp: Vec<Vector3<f64>>,
    j: Vec<f64>,
    x: Vec<f64>,
}

impl<'a> Predictor<'a> {
    /// A predictor, or `None` when the covariance is unavailable.
    pub fn new(robot: &'a Robot, cov: &'a Covariance, noise_sigma_mm: f64) -> Option<Self> {
        if cov.unavailable.is_some() || !noise_sigma_mm.is_finite() {
            return None;
        }
        let index = cov
            .params
            .iter()
            .map(|p: &Param| robot.param_position(*p))
            .collect::<Option<Vec<_>>>()?;
        let k = index.len();
        let factor = cov
            .matrix
            .clone()
            .cholesky()
            .map(|c| c.unpack())
            .map(|l| (0..k * k).map(|i| l[(i / k, i % k)]).collect());
        let cov = (0..k * k).map(|i| cov.matrix[(i / k, i % k)]).collect();
        Some(Predictor {
            robot,
            index,
            cov,
            factor,
            sigma: noise_sigma_mm,
            norms: NormExpectation::new(),
        })
    }

    fn scratch(&self) -> Scratch {
        let k = self.index.len();
        Scratch {
            jp: vec![Vector3::zeros(); self.robot.param_count()],
            j: vec![0.0; 3 * k],
            x: vec![0.0; 3 * k],
        }
    }

    /// `J C J^T` for the 3 x k rows `j` (row-major); `x` is scratch of 3 k.
    #[inline(always)]
    fn model_covariance(&self, j: &[f64], x: &mut [f64]) -> Matrix3<f64> {
        let k = self.index.len();
        // x = J L (L lower: row a reaches columns 0..=a), then (J L)(J L)^T; or x = J C (C
        // symmetric, read by rows), then (J C) J^T.
        let (m, width) = match &self.factor {
            Some(l) => (l, 0),
            None => (&self.cov, k),
        };
        // The three rows together: each row of `m` is read once for the three (the same sums,
        // term by term in the same order, as row by row).
        x.fill(0.0);
        let (x0, rest) = x.split_at_mut(k);
        let (x1, x2) = rest.split_at_mut(k);
        for a in 0..k {
            let (j0, j1, j2) = (j[a], j[k + a], j[2 * k + a]);
            if j0 == 0.0 && j1 == 0.0 && j2 == 0.0 {
                continue;
            }
            let n = (a + 1).max(width);
            let row = &m[a * k..a * k + n];
            for (((v0, v1), v2), mv) in x0[..n]
                .iter_mut()
                .zip(&mut x1[..n])
                .zip(&mut x2[..n])
                .zip(row)
            {
                *v0 += j0 * mv;
                *v1 += j1 * mv;
                *v2 += j2 * mv;
            }
        }
        let y = if self.factor.is_some() { &*x } else { j };
        let mut out = Matrix3::zeros();
        for r in 0..3 {
            for c in r..3 {
                let v: f64 = x[r * k..(r + 1) * k]
                    .iter()
                    .zip(&y[c * k..(c + 1) * k])
                    .map(|(a, b)| a * b)
                    .sum();
                out[(r, c)] = v;
                out[(c, r)] = v;
            }
        }
        out
    }

    /// The expected error norm of a measurement whose model error has covariance `model`.
    fn mean_norm(&self, model: &Matrix3<f64>) -> f64 {
        self.norms
            .mean_norm(&(model + Matrix3::identity() * (self.sigma * self.sigma)))
    }

    /// Tool point of target `t` and `J C J^T` at joints `q` under conditions `c` (the row's
    /// temperature and approach directions, which the thermal and backlash columns need).
    #[inline(always)]
    fn model_at(
        &self,
        s: &mut Scratch,
        q: &[f64],
        t: usize,
        c: &Conditions,
    ) -> (Vector3<f64>, Matrix3<f64>) {
        let p = target_jacobian(self.robot, &self.index, q, t, c, &mut s.jp, &mut s.j);
        (p, self.model_covariance(&s.j, &mut s.x))
    }

    /// At joints `q`: the tool point, the covariance of the model's error `J C J^T` (mm^2) and
    /// the expected error norm of a measurement.
    pub fn at(&self, q: &[f64]) -> (Vector3<f64>, Matrix3<f64>, f64) {
        let (p, model) = self.model_at(&mut self.scratch(), q, 0, &Conditions::UNKNOWN);
        (p, model, self.mean_norm(&model))
    }

    /// The prediction from the model-error covariances `J C J^T` of the poses averaged over (the
    /// calibration poses), and the workspace map.
    /// `models` are those of [`averaged_poses`].
    fn predict_from(&self, models: &[Matrix3<f64>], floor_z_mm: f64, map: bool) -> Prediction {
        let picked: Vec<&Matrix3<f64>> = models.iter().collect();
        let means = map_poses(picked.len(), || (), |_, i| self.mean_norm(picked[i]));
        let (mut sum, mut sum_sq, mut model_sq) = (0.0, 0.0, 0.0);
        for (model, mean) in picked.iter().zip(&means) {
            let tr = model.trace();
            sum += mean;
            sum_sq += tr + 3.0 * self.sigma * self.sigma;
            model_sq += tr;
        }
        let nf = picked.len().max(1) as f64;
        let mean_mm = sum / nf;
        let ms = sum_sq / nf;
        Prediction {
            mean_mm,
            std_mm: (ms - mean_mm * mean_mm).max(0.0).sqrt(),
            rms_mm: ms.sqrt(),
            noise_sigma_mm: self.sigma,
            model_rms_mm: (model_sq / nf).sqrt(),
            map: if map {
                self.map(floor_z_mm)
            } else {
                Vec::new()
            },
        }
    }

    /// The prediction over poses `qs` (the calibration poses) and the workspace map.
    pub fn predict(&self, qs: &[&[f64]], floor_z_mm: f64) -> Prediction {
        let picked = averaged_poses(qs.len());
        let models = map_poses(
            picked.len(),
            || self.scratch(),
            |s, i| self.model_at(s, qs[picked[i]], 0, &Conditions::UNKNOWN).1,
        );
        self.predict_from(&models, floor_z_mm, true)
    }

    /// [`MAP_POSES`] random poses within the joint limits, tool no lower than `floor_z_mm`
    /// (fixed seed: the same calibration gives the same map). Empty if the limits leave no
    /// such pose.
    fn map(&self, floor_z_mm: f64) -> Vec<MapPoint> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x3A9);
        let sampler = PoseSampler {
            floor_z_mm,
            footprint_radius_mm: 0.0,
            max_tries_per_pose: 1000,
        };
        let Ok(qs) = random_poses(self.robot, MAP_POSES, &sampler, &mut rng) else {
            return Vec::new();
        };
        map_poses(
            qs.len(),
            || self.scratch(),
            |s, i| {
                let (position, model) = self.model_at(s, &qs[i], 0, &Conditions::UNKNOWN);
                MapPoint {
                    position,
                    mean_mm: self.mean_norm(&model),
                    model_mm: model.trace().max(0.0).sqrt(),
                }
            },
        )
    }
}

/// The Jacobian rows of target `t` (0-based) of the robot's targets under conditions `c`, as
/// [`point_jacobian`] gives them for the tool point.
#[inline(always)]
fn target_jacobian(
    robot: &Robot,
    index: &[usize],
    q: &[f64],
    t: usize,
    c: &Conditions,
    jp: &mut [Vector3<f64>],
    out: &mut [f64],
) -> Vector3<f64> {
    let k = index.len();
    let (p, _) = if c.is_unknown() {
        robot.target_screws(q, t, None, Some(jp), None)
    } else {
        robot.target_screws_in(q, t, c, None, Some(jp), None)
    };
    let (o0, rest) = out[..3 * k].split_at_mut(k);
    let (o1, o2) = rest.split_at_mut(k);
    for (((v0, v1), v2), &i) in o0.iter_mut().zip(o1).zip(o2).zip(index) {
        let col = &jp[i];
        (*v0, *v1, *v2) = (col.x, col.y, col.z);
    }
    p
}

/// The per-axis noise of the calibration residuals `norms` (mm) over `rows` rows each: the
/// points at or below `threshold_mm` (all when `None`), each squared residual divided by its
/// degrees of freedom `rows - h_i` (`h_i` its leverage, `tr(J_i S^-1 J_i^T)` with `S` the kept
/// points' `sum J^T J`), averaged: `sqrt(mean r_i^2 / (rows - h_i))`. Unlike one global correction `sum r^2 / (rows n - k)`, it stays unbiased when the noise
/// differs between poses (a tracker's grows with distance) and the high-leverage poses are the
/// noisier ones (Horn, Horn and Duncan's HC2 idea). `leverage` gives `h_i`; NaN when too few
/// points remain.
pub fn noise_sigma(
    norms: &[f64],
    rows: usize,
    threshold_mm: Option<f64>,
    leverage: &dyn Fn(&[usize]) -> Option<Vec<f64>>,
) -> f64 {
    let kept = kept_points(norms, threshold_mm);
    let Some(h) = leverage(&kept) else {
        return f64::NAN;
    };
    noise_from_leverages(norms, rows, &kept, &h)
}

/// The points [`noise_sigma`] keeps: those at or below `threshold_mm` (all when `None`).
fn kept_points(norms: &[f64], threshold_mm: Option<f64>) -> Vec<usize> {
    (0..norms.len())
        .filter(|&i| threshold_mm.map_or(true, |t| norms[i] <= t))
        .collect()
}

/// [`noise_sigma`] from the kept points' leverages `h` (in `kept` order).
fn noise_from_leverages(norms: &[f64], rows: usize, kept: &[usize], h: &[f64]) -> f64 {
    let rows = rows as f64;
    let mut sum = 0.0;
    for (&i, hi) in kept.iter().zip(h) {
        let dof = rows - hi;
        if dof.is_nan() || dof <= 1e-6 {
            return f64::NAN;
        }
        sum += norms[i] * norms[i] / dof;
    }
    (sum / kept.len() as f64).sqrt()
}

/// A Gram matrix `S = sum J^T J` ready for leverages `tr(J S^-1 J^T)`: over the columns that move
/// the points, scaled to a unit diagonal (the leverage does not change, the factor's condition
/// does), `S = D L L^T D`, with `L^-1` explicit so that each point's leverage is the squared norm
/// of `L^-1 D^-1 J^T`, a product of contiguous rows (vectorized) rather than a forward
/// substitution (a chain of dependent divisions).
struct GramFactor {
    /// The columns kept: parameters that do not move the points (a tool orientation identified
    /// from 6-DoF data) have no leverage on them, and their rows and columns are left out of S.
    cols: Vec<usize>,
    /// `1 / sqrt(S_aa)` of the kept columns.
    scale: Vec<f64>,
    /// `L^-1` (lower, row-major, `m x m`).
    linv: Vec<f64>,
    /// `cols.len()`.
    m: usize,
}

impl GramFactor {
    /// The factor of `S` given by its upper triangle (`k x k`, row-major); `None` when singular.
    fn new(upper: &[f64], k: usize) -> Option<GramFactor> {
        let max_diag = (0..k).map(|a| upper[a * k + a]).fold(0.0, f64::max);
        let cols: Vec<usize> = (0..k)
            .filter(|&a| upper[a * k + a] > 1e-12 * max_diag)
            .collect();
        let m = cols.len();
        let scale: Vec<f64> = cols
            .iter()
            .map(|&a| 1.0 / upper[a * k + a].sqrt())
            .collect();
        let s = DMatrix::from_fn(m, m, |r, c| {
            let (a, b) = (cols[r.min(c)], cols[r.max(c)]);
            upper[a * k + b] * scale[r] * scale[c]
        });
        let l = s.cholesky()?.unpack();
        let linv = l.solve_lower_triangular(&DMatrix::identity(m, m))?;
        let linv: Vec<f64> = (0..m * m).map(|i| linv[(i / m, i % m)]).collect();
        Some(GramFactor {
            cols,
            scale,
            linv,
            m,
        })
    }

    /// The leverage `tr(J S^-1 J^T)` of the block `j` (`rows x k`, row-major); `y` is scratch of
    /// `rows x m`.
    #[inline(always)]
    fn leverage(&self, j: &[f64], rows: usize, k: usize, y: &mut [f64]) -> f64 {
        let m = self.m;
        for r in 0..rows {
            for (a, (&c, &d)) in self.cols.iter().zip(&self.scale).enumerate() {
                y[r * m + a] = j[r * k + c] * d;
            }
        }
        let mut h = 0.0;
        for a in 0..m {
            let la = &self.linv[a * m..a * m + a + 1];
            for r in 0..rows {
                let v = dot(la, &y[r * m..r * m + a + 1]);
                h += v * v;
            }
        }
        h
    }
}

/// `a . b` with four sums in flight (the compiler keeps a plain sum's order, so one chain).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (a4.remainder(), b4.remainder());
    for (x, y) in a4.zip(b4) {
        for t in 0..4 {
            acc[t] += x[t] * y[t];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The prediction of a calibrated model from its calibration points (see the module docs);
/// `None` when the covariance is unavailable or too few points leave no noise estimate. Each
/// point's Jacobian is that of the target it measures.
pub fn predict(
    calibrated: &Robot,
    covariance: &Covariance,
    calibration: &Observations,
    residual_norms: &[f64],
    threshold_mm: Option<f64>,
) -> Option<Prediction> {
    // The residual norms are of the points (3 rows), whatever else the kind measures.
    let rows = 3;
    // The noise is not known yet: a predictor of zero noise gives the Jacobians' model parts.
    let pred = Predictor::new(calibrated, covariance, 0.0)?;
    let k = pred.index.len();
    let n = calibration.len();
    // Each point's Jacobian, recomputed where needed rather than stored for a million points.
    // With AVX where the processor has it (the same bits, see `simd`).
    let jacobian = |s: &mut Scratch, i: usize, out: &mut [f64]| {
        with_avx(
            #[inline(always)]
            || {
                target_jacobian(
                    pred.robot,
                    &pred.index,
                    calibration.q(i),
                    calibration.target(i),
                    &calibration.conditions(i),
                    &mut s.jp,
                    out,
                )
            },
        )
    };
    // Two passes over the points, each computing every Jacobian it needs once (a Jacobian is
    // most of a prediction's cost): the first sums `S = sum J^T J` over the points kept for the
    // noise estimate and finds the lowest tool point (the map's floor); the second gives the
    // kept points' leverages and the model parts `J C J^T` at the poses averaged over.
    // (The leverages come from the tool point's rows: exact for point measurements.)
    let kept = kept_points(residual_norms, threshold_mm);
    let mut is_kept = vec![false; n];
    kept.iter().for_each(|&i| is_kept[i] = true);
    let (_, _, upper, floor) = crate::identification::system::chunked(
        n,
        || {
            (
                pred.scratch(),
                vec![0.0; rows * k],
                vec![0.0; k * k],
                f64::INFINITY,
            )
        },
        // Inlined into the chunk's loop, which runs with AVX where the processor has it (see
        // `simd`): the Gram update then takes the wider instructions too.
        #[inline(always)]
        |(s, j, m, lowest), i| {
            let p = jacobian(s, i, j);
            *lowest = lowest.min(p.z);
            if is_kept[i] {
                add_gram(m, j, rows, k, 1.0);
            }
        },
        |mut a, b| {
            a.2.iter_mut().zip(&b.2).for_each(|(x, y)| *x += y);
            a.3 = a.3.min(b.3);
            a
        },
    );
    let g = GramFactor::new(&upper, k)?;
    let picked = averaged_poses(n);
    let mut is_picked = vec![false; n];
    picked.iter().for_each(|&i| is_picked[i] = true);
    // In chunks (the same bits on any number of threads), each chunk's leverages and model parts
    // appended in order: nothing is held per point but the leverage.
    let (_, _, h, models) = crate::identification::system::chunked(
        n,
        || {
            (
                pred.scratch(),
                vec![0.0; rows * g.m],
                Vec::new(),
                Vec::new(),
            )
        },
        #[inline(always)]
        |(s, y, h, models), i| {
            if !(is_kept[i] || is_picked[i]) {
                return;
            }
            let mut j = std::mem::take(&mut s.j);
            jacobian(s, i, &mut j);
            if is_kept[i] {
                h.push(g.leverage(&j, rows, k, y));
            }
            if is_picked[i] {
                models.push(pred.model_covariance(&j, &mut s.x));
            }
            s.j = j;
        },
        |mut a, b| {
            a.2.extend(b.2);
            a.3.extend(b.3);
            a
        },
    );
    let sigma = noise_from_leverages(residual_norms, rows, &kept, &h);
    if !sigma.is_finite() {
        return None;
    }
    let pred = Predictor { sigma, ..pred };
    Some(pred.predict_from(&models, floor, true))
}

/// The poses of `n` a prediction averages over: every one, or an even spread of at most
/// [`MAX_POSES`].
fn averaged_poses(n: usize) -> Vec<usize> {
    averaged_poses_up_to(n, MAX_POSES)
}

/// Every pose of `n`, or an even spread of at most `max`.
fn averaged_poses_up_to(n: usize, max: usize) -> Vec<usize> {
    (0..n).step_by(n.div_ceil(max).max(1)).collect()
}

#[path = "prediction_candidate.rs"]
mod candidate;
pub(crate) use candidate::predict_for_candidate;
pub use candidate::CANDIDATE_POSES;

#[cfg(test)]
#[path = "prediction_tests.rs"]
mod tests;
