//! Predicted accuracy of a calibrated model at poses it was not fitted to.
//!
//! At a new pose q the error of the calibrated model against a measurement is
//! `e = J(q) delta + eps`: the estimates' error `delta` (covariance `C`, see [`Covariance`])
//! seen through the tool point's Jacobian `J(q)` of the identified parameters, plus the new
//! measurement's own noise `eps` (per-axis standard deviation `sigma`, estimated from the
//! calibration residuals). So `e` is Gaussian with covariance `Sigma(q) = J C J^T + sigma^2 I`,
//! and the expected error norm at q is `E|e|`, computed from `Sigma`'s eigenvalues with a fixed
//! set of standard normal samples (deterministic; the error of the expectation is below 0.5%).
//! Averaged over the calibration poses, that is the expected mean error at new poses spread like
//! them ([`Prediction::mean_mm`]), the figure a validation set measures.

use crate::identification::covariance::Covariance;
use crate::model::{Param, Robot};
use crate::observations::Observations;
use crate::simulation::{random_poses, PoseSampler};
use nalgebra::{DMatrix, Matrix3, SymmetricEigen, Vector3};
use rand::SeedableRng;

/// Directions behind every expected norm (a Fibonacci sphere; see [`NormExpectation`]). 512
/// average a smooth function of the direction to well under 0.5%; 8192 random normal samples
/// (the first version) took about 12 ms of a 14 ms 75-pose calibration.
const SAMPLES: usize = 512;

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
    let k = index.len();
    let p = robot.tool_screw_jacobians(q, None, Some(jp), None);
    for (c, &i) in index.iter().enumerate() {
        for r in 0..3 {
            out[r * k + c] = jp[i][r];
        }
    }
    p
}

/// Expected norms of zero-mean Gaussian vectors of given covariances: one fixed sample set.
struct NormExpectation {
    z: Vec<[f64; 3]>,
}

impl NormExpectation {
    /// `e = r u` with `r ~ chi(3)` and `u` uniform on the sphere, independent: `E|e|` for
    /// `e ~ N(0, diag(l))` is `E[r] E_u sqrt(u^T diag(l) u)`, `E[r] = 2 sqrt(2/pi)`. The
    /// directions are a Fibonacci sphere (deterministic, evenly spread), each scaled by `E[r]`.
    fn new() -> Self {
        let er = 2.0 * (2.0 / std::f64::consts::PI).sqrt();
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let z = (0..SAMPLES)
            .map(|i| {
                let y = 1.0 - (2.0 * i as f64 + 1.0) / SAMPLES as f64;
                let r = (1.0 - y * y).max(0.0).sqrt();
                let t = golden * i as f64;
                [er * r * t.cos(), er * y, er * r * t.sin()]
            })
            .collect();
        NormExpectation { z }
    }

    /// `E|e|` for `e ~ N(0, s)`.
    fn mean_norm(&self, s: &Matrix3<f64>) -> f64 {
        let ev = SymmetricEigen::new(*s).eigenvalues;
        let l = [ev[0].max(0.0), ev[1].max(0.0), ev[2].max(0.0)];
        let sum: f64 = self
            .z
            .iter()
            .map(|z| (l[0] * z[0] * z[0] + l[1] * z[1] * z[1] + l[2] * z[2] * z[2]).sqrt())
            .sum();
        sum / self.z.len() as f64
    }
}

/// The predictor of a calibration: calibrated model, covariance of its identified parameters and
/// the measurement noise.
pub struct Predictor<'a> {
    robot: &'a Robot,
    index: Vec<usize>,
    cov: &'a DMatrix<f64>,
    sigma: f64,
    norms: NormExpectation,
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
        Some(Predictor {
            robot,
            index,
            cov: &cov.matrix,
            sigma: noise_sigma_mm,
            norms: NormExpectation::new(),
        })
    }

    /// At joints `q`: the tool point, the covariance of the model's error `J C J^T` (mm^2) and
    /// the expected error norm of a measurement.
    pub fn at(&self, q: &[f64]) -> (Vector3<f64>, Matrix3<f64>, f64) {
        let k = self.index.len();
        let mut jp = vec![Vector3::zeros(); self.robot.param_count()];
        let mut j = vec![0.0; 3 * k];
        let p = point_jacobian(self.robot, &self.index, q, &mut jp, &mut j);
        let jm = DMatrix::from_row_slice(3, k, &j);
        let m = &jm * self.cov * jm.transpose();
        let model = Matrix3::from_fn(|r, c| 0.5 * (m[(r, c)] + m[(c, r)]));
        let total = model + Matrix3::identity() * (self.sigma * self.sigma);
        (p, model, self.norms.mean_norm(&total))
    }

    /// The prediction over poses `qs` (the calibration poses) and the workspace map.
    pub fn predict(&self, qs: &[&[f64]], floor_z_mm: f64) -> Prediction {
        let stride = qs.len().div_ceil(MAX_POSES).max(1);
        let (mut sum, mut sum_sq, mut model_sq, mut n) = (0.0, 0.0, 0.0, 0usize);
        for q in qs.iter().step_by(stride) {
            let (_, model, mean) = self.at(q);
            let tr = model.trace();
            sum += mean;
            sum_sq += tr + 3.0 * self.sigma * self.sigma;
            model_sq += tr;
            n += 1;
        }
        let nf = n.max(1) as f64;
        let mean_mm = sum / nf;
        let ms = sum_sq / nf;
        Prediction {
            mean_mm,
            std_mm: (ms - mean_mm * mean_mm).max(0.0).sqrt(),
            rms_mm: ms.sqrt(),
            noise_sigma_mm: self.sigma,
            model_rms_mm: (model_sq / nf).sqrt(),
            map: self.map(floor_z_mm),
        }
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
        qs.iter()
            .map(|q| {
                let (position, model, mean_mm) = self.at(q);
                MapPoint {
                    position,
                    mean_mm,
                    model_mm: model.trace().max(0.0).sqrt(),
                }
            })
            .collect()
    }
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
    let kept: Vec<usize> = (0..norms.len())
        .filter(|&i| threshold_mm.map_or(true, |t| norms[i] <= t))
        .collect();
    let Some(h) = leverage(&kept) else {
        return f64::NAN;
    };
    let rows = rows as f64;
    let mut sum = 0.0;
    for (&i, hi) in kept.iter().zip(&h) {
        let dof = rows - hi;
        if dof.is_nan() || dof <= 1e-6 {
            return f64::NAN;
        }
        sum += norms[i] * norms[i] / dof;
    }
    (sum / kept.len() as f64).sqrt()
}

/// The leverages `h_i = tr(J_i S^-1 J_i^T)` of points `kept` (Jacobian blocks `jac`, `rows x k`
/// row-major each), `S = sum J^T J` over them; `None` when `S` is singular.
fn leverages(jac: &[Vec<f64>], k: usize, rows: usize, kept: &[usize]) -> Option<Vec<f64>> {
    let mut s = DMatrix::zeros(k, k);
    for &i in kept {
        let j = DMatrix::from_row_slice(rows, k, &jac[i]);
        s += j.transpose() * &j;
    }
    let ch = s.cholesky()?;
    Some(
        kept.iter()
            .map(|&i| {
                let j = DMatrix::from_row_slice(rows, k, &jac[i]);
                let x = ch.solve(&j.transpose());
                (&j * x).trace()
            })
            .collect(),
    )
}

/// The prediction of a calibrated model from its calibration points (see the module docs);
/// `None` when the covariance is unavailable or too few points leave no noise estimate.
pub fn predict(
    calibrated: &Robot,
    covariance: &Covariance,
    calibration: &Observations,
    residual_norms: &[f64],
    threshold_mm: Option<f64>,
) -> Option<Prediction> {
    let rows = calibration.kind().rows();
    let index = covariance
        .params
        .iter()
        .map(|p| calibrated.param_position(*p))
        .collect::<Option<Vec<_>>>()?;
    let k = index.len();
    let mut jp = vec![Vector3::zeros(); calibrated.param_count()];
    let jac: Vec<Vec<f64>> = (0..calibration.len())
        .map(|i| {
            let mut j = vec![0.0; 3 * k];
            point_jacobian(calibrated, &index, calibration.q(i), &mut jp, &mut j);
            j
        })
        .collect();
    // (The leverages come from the tool point's rows: exact for point measurements.)
    let sigma = noise_sigma(residual_norms, rows, threshold_mm, &|kept| {
        leverages(&jac, k, 3, kept)
    });
    let pred = Predictor::new(calibrated, covariance, sigma)?;
    let qs: Vec<&[f64]> = (0..calibration.len()).map(|i| calibration.q(i)).collect();
    let floor = (0..calibration.len())
        .map(|i| calibrated.tool_position(calibration.q(i)).z)
        .fold(f64::INFINITY, f64::min);
    Some(pred.predict(&qs, floor))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The expected norm of an isotropic Gaussian is `sigma sqrt(8/pi)`; of a 1-D one
    /// `sigma sqrt(2/pi)`.
    #[test]
    fn expected_norms_match_closed_forms() {
        let n = NormExpectation::new();
        let s = 0.3;
        let iso = n.mean_norm(&(Matrix3::identity() * s * s));
        let exact = s * (8.0 / std::f64::consts::PI).sqrt();
        assert!((iso / exact - 1.0).abs() < 0.005, "{iso} vs {exact}");
        let mut one = Matrix3::zeros();
        one[(1, 1)] = s * s;
        let line = n.mean_norm(&one);
        let exact = s * (2.0 / std::f64::consts::PI).sqrt();
        assert!((line / exact - 1.0).abs() < 0.01, "{line} vs {exact}");
    }

    #[test]
    fn noise_sigma_counts_degrees_of_freedom_and_skips_outliers() {
        let norms = [1.0, 1.0, 1.0, 1.0, 50.0];
        // 4 kept points, 3 rows each, leverage 0.5 each (2 parameters): r^2 / 2.5 per point.
        let half = |kept: &[usize]| Some(vec![0.5; kept.len()]);
        let s = noise_sigma(&norms, 3, Some(10.0), &half);
        assert!((s - (1.0f64 / 2.5).sqrt()).abs() < 1e-12);
        let full = |kept: &[usize]| Some(vec![3.0; kept.len()]);
        assert!(noise_sigma(&norms, 3, Some(10.0), &full).is_nan());
        assert!(noise_sigma(&norms, 3, Some(10.0), &|_| None).is_nan());
    }
}
