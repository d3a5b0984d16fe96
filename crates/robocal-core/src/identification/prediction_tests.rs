//! Tests of the parent module (`identification::prediction`).

use super::*;

/// The expected norm of an isotropic Gaussian is `sigma sqrt(8/pi)`; of a 1-D one
/// `sigma sqrt(2/pi)`.
#[test]
fn expected_norms_match_closed_forms() {
    let n = NormExpectation::new();
    let s = 0.3;
    let iso = n.mean_norm(&(Matrix3::identity() * s * s));
    let exact = s * (8.0 / std::f64::consts::PI).sqrt();
    assert!((iso / exact - 1.0).abs() < 1e-12, "{iso} vs {exact}");
    let mut one = Matrix3::zeros();
    one[(1, 1)] = s * s;
    let line = n.mean_norm(&one);
    let exact = s * (2.0 / std::f64::consts::PI).sqrt();
    assert!((line / exact - 1.0).abs() < 1e-6, "{line} vs {exact}");
    // A plane: Rayleigh, E = s sqrt(pi / 2).
    let mut plane = Matrix3::identity() * s * s;
    plane[(2, 2)] = 0.0;
    let flat = n.mean_norm(&plane);
    let exact = s * (std::f64::consts::FRAC_PI_2).sqrt();
    assert!((flat / exact - 1.0).abs() < 1e-6, "{flat} vs {exact}");
}

/// Anisotropic covariances, rotated: the quadrature against a fine midpoint rule over the
/// whole sphere (800 x 1600 cells in polar angle and azimuth, no symmetry used).
#[test]
fn expected_norms_match_a_fine_reference() {
    use nalgebra::Rotation3;
    let n = NormExpectation::new();
    let er = 2.0 * (2.0 / std::f64::consts::PI).sqrt();
    for (l, axis) in [
        ([1.0, 0.3, 0.01], Vector3::new(0.3, -0.5, 0.8)),
        ([4.0, 1.0, 1.0], Vector3::new(1.0, 0.0, 0.2)),
        ([1e-4, 2e-4, 9e-4], Vector3::new(-0.2, 0.7, 0.1)),
    ] {
        let r = Rotation3::new(axis).into_inner();
        let s = r * Matrix3::from_diagonal(&Vector3::from(l)) * r.transpose();
        let (nt, np) = (800, 1600);
        let (mut sum, mut area) = (0.0, 0.0);
        for it in 0..nt {
            let theta = std::f64::consts::PI * (it as f64 + 0.5) / nt as f64;
            let (st, ct) = theta.sin_cos();
            for ip in 0..np {
                let phi = std::f64::consts::TAU * (ip as f64 + 0.5) / np as f64;
                let u = Vector3::new(st * phi.cos(), st * phi.sin(), ct);
                sum += st * u.dot(&(s * u)).max(0.0).sqrt();
                area += st;
            }
        }
        let reference = er * sum / area;
        let got = n.mean_norm(&s);
        assert!(
            (got / reference - 1.0).abs() < 1e-5,
            "{l:?}: {got} vs {reference}"
        );
    }
}

/// `J C J^T` through the Cholesky factor equals the direct product.
#[test]
fn model_covariance_by_the_factor_matches_the_direct_product() {
    use rand::Rng;
    let robot = crate::model::presets::preset("kuka-kr480-r3330").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let k = 30;
    let a = DMatrix::from_fn(k, k, |_, _| rng.gen_range(-1.0..1.0));
    let c = &a * a.transpose() + DMatrix::identity(k, k) * 1e-3;
    let cov: Vec<f64> = (0..k * k).map(|i| c[(i / k, i % k)]).collect();
    let l = c.clone().cholesky().unwrap().unpack();
    let direct = Predictor {
        robot: &robot,
        index: (0..k).collect(),
        cov: cov.clone(),
        factor: None,
        sigma: 0.01,
        norms: NormExpectation::new(),
    };
    let factored = Predictor {
        robot: &robot,
        index: (0..k).collect(),
        cov,
        factor: Some((0..k * k).map(|i| l[(i / k, i % k)]).collect()),
        sigma: 0.01,
        norms: NormExpectation::new(),
    };
    let mut x = vec![0.0; 3 * k];
    for _ in 0..20 {
        // Some zero entries, as the Jacobians of parameters that do not move a point have.
        let j: Vec<f64> = (0..3 * k)
            .map(|i| {
                if i % 7 == 0 {
                    0.0
                } else {
                    rng.gen_range(-50.0..50.0)
                }
            })
            .collect();
        let m1 = direct.model_covariance(&j, &mut x);
        let m2 = factored.model_covariance(&j, &mut x);
        assert!((m1 - m2).norm() <= 1e-12 * m1.norm(), "{m1} vs {m2}");
    }
}

#[test]
fn closed_form_eigenvalues_match_nalgebra() {
    use rand::Rng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for _ in 0..200 {
        let a = Matrix3::from_fn(|_, _| rng.gen_range(-1.0..1.0));
        let s = a * a.transpose() + Matrix3::identity() * rng.gen_range(0.0..0.1);
        let mut want: Vec<f64> = nalgebra::SymmetricEigen::new(s)
            .eigenvalues
            .iter()
            .copied()
            .collect();
        want.sort_by(|x, y| y.total_cmp(x));
        let got = sym3_eigenvalues(&s);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-12 * s.norm(), "{got:?} vs {want:?}");
        }
    }
    let d = Matrix3::from_diagonal(&Vector3::new(2.0, 2.0, 2.0));
    assert_eq!(sym3_eigenvalues(&d), [2.0, 2.0, 2.0]);
}

#[test]
fn gauss_legendre_integrates_polynomials_exactly() {
    let (x, w) = gauss_legendre(QUADRATURE_NODES);
    for p in 0..2 * QUADRATURE_NODES {
        let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
        let want = if p % 2 == 1 {
            0.0
        } else {
            2.0 / (p as f64 + 1.0)
        };
        assert!((got - want).abs() < 1e-14, "x^{p}: {got} vs {want}");
    }
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

/// The prediction's two passes (the Gram matrix and floor, then the leverages and the model
/// parts) give the noise and the mean of a direct computation: `S = sum J^T J` over the kept
/// points, `h_i = tr(J_i S^-1 J_i^T)`, `sigma = sqrt(mean r_i^2 / (3 - h_i))`, and the mean of
/// `E|e|` with `e ~ N(0, J C J^T + sigma^2 I)` over every pose (fewer than the thinning's
/// bound). One residual above the threshold is left out of the noise, not of the mean.
#[test]
fn prediction_matches_a_direct_computation() {
    use rand::Rng;
    let robot = crate::model::presets::preset("kuka-kr480-r3330").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let sampler = PoseSampler {
        floor_z_mm: f64::NEG_INFINITY,
        footprint_radius_mm: 0.0,
        max_tries_per_pose: 1000,
    };
    // More poses than the parallel bound, so the passes' threads are exercised too.
    let qs = random_poses(&robot, 300, &sampler, &mut rng).unwrap();
    let mut obs = Observations::new(robot.dof());
    for (i, q) in qs.iter().enumerate() {
        obs.push(q, robot.tool_position(q), i + 2).unwrap();
    }
    // The parameters whose columns are independent over these poses (the first of each
    // dependent group), as an identification would keep.
    let all: Vec<usize> = (0..robot.param_count()).collect();
    let mut jp = vec![Vector3::zeros(); robot.param_count()];
    let mut jall = vec![0.0; 3 * all.len()];
    let mut full = DMatrix::zeros(all.len(), all.len());
    for q in &qs {
        point_jacobian(&robot, &all, q, &mut jp, &mut jall);
        let ji = DMatrix::from_row_slice(3, all.len(), &jall);
        full += ji.transpose() * ji;
    }
    let mut index: Vec<usize> = Vec::new();
    for a in all {
        let mut trial = index.clone();
        trial.push(a);
        let g = DMatrix::from_fn(trial.len(), trial.len(), |r, c| {
            full[(trial[r], trial[c])]
                / (full[(trial[r], trial[r])] * full[(trial[c], trial[c])]).sqrt()
        });
        if full[(a, a)] > 0.0 && g.symmetric_eigenvalues().min() > 1e-9 {
            index = trial;
        }
    }
    let params: Vec<Param> = index.iter().map(|&i| robot.params()[i]).collect();
    let k = params.len();
    assert!(k >= 20, "{k} independent parameters");
    let a = DMatrix::from_fn(k, k, |_, _| rng.gen_range(-1e-3..1e-3));
    let c = &a * a.transpose() + DMatrix::identity(k, k) * 1e-8;
    let cov = Covariance {
        params: params.clone(),
        matrix: c.clone(),
        sigma_mm: 0.02,
        unavailable: None,
    };
    let mut norms: Vec<f64> = (0..qs.len()).map(|_| rng.gen_range(0.005..0.05)).collect();
    norms[17] = 5.0;
    let threshold = Some(0.5);
    let p = predict(&robot, &cov, &obs, &norms, threshold).expect("a prediction");

    let mut j = vec![0.0; 3 * k];
    let jac = |q: &[f64], jp: &mut [Vector3<f64>], j: &mut [f64]| {
        point_jacobian(&robot, &index, q, jp, j);
        DMatrix::from_row_slice(3, k, j)
    };
    let kept: Vec<usize> = (0..qs.len()).filter(|&i| norms[i] <= 0.5).collect();
    let mut s = DMatrix::zeros(k, k);
    for &i in &kept {
        let ji = jac(&qs[i], &mut jp, &mut j);
        s += ji.transpose() * &ji;
    }
    let s_inv = s.try_inverse().unwrap();
    let mut sum = 0.0;
    for &i in &kept {
        let ji = jac(&qs[i], &mut jp, &mut j);
        let h = (&ji * &s_inv * ji.transpose()).trace();
        sum += norms[i] * norms[i] / (3.0 - h);
    }
    let sigma = (sum / kept.len() as f64).sqrt();
    assert!(
        (p.noise_sigma_mm / sigma - 1.0).abs() < 1e-9,
        "{} vs {sigma}",
        p.noise_sigma_mm
    );
    let ne = NormExpectation::new();
    let mean = qs
        .iter()
        .map(|q| {
            let ji = jac(q, &mut jp, &mut j);
            let m = &ji * &c * ji.transpose();
            let m = Matrix3::from_fn(|r, cc| m[(r, cc)]);
            ne.mean_norm(&(m + Matrix3::identity() * sigma * sigma))
        })
        .sum::<f64>()
        / qs.len() as f64;
    assert!(
        (p.mean_mm / mean - 1.0).abs() < 1e-9,
        "{} vs {mean}",
        p.mean_mm
    );
    assert_eq!(p.map.len(), MAP_POSES);
}

/// A candidate's lighter prediction (the noise by one degrees-of-freedom correction, the mean
/// over at most [`CANDIDATE_POSES`] poses) is within 1% of the full one on calibrations of
/// noisy simulated data, small and large, with noise growing with the distance as a tracker's.
#[test]
fn a_candidates_prediction_is_close_to_the_full_one() {
    use crate::identification::pipeline::{calibrate_model, CalibrationData};
    use rand_distr::{Distribution, Normal};
    let truth = crate::model::presets::preset("kuka-kr480-r3330-table3").unwrap();
    let nominal = crate::model::presets::preset("kuka-kr480-r3330").unwrap();
    for (n, seed) in [(75, 1), (1500, 2)] {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let qs = random_poses(&truth, n, &PoseSampler::default(), &mut rng).unwrap();
        let unit = Normal::new(0.0, 1.0).unwrap();
        let mut obs = Observations::new(6);
        for (i, q) in qs.iter().enumerate() {
            let p = truth.tool_position(q);
            let sigma = 0.01 + 0.01 * p.norm() / 1000.0;
            let m = p.map(|v| v + sigma * unit.sample(&mut rng));
            obs.push(q, m, i + 2).unwrap();
        }
        let data = CalibrationData {
            calibration: &obs,
            plane: None,
            validation: None,
        };
        let cal = calibrate_model(&nominal, data, &Default::default(), &()).unwrap();
        let full = cal.prediction.as_ref().expect("a prediction");
        let threshold = cal.robust_scale_mm;
        let light = predict_for_candidate(
            &cal.calibrated,
            &cal.covariance,
            &obs,
            &cal.calibration.after,
            threshold,
        )
        .expect("a candidate's prediction");
        for (what, a, b) in [
            ("mean", light.mean_mm, full.mean_mm),
            ("noise", light.noise_sigma_mm, full.noise_sigma_mm),
        ] {
            assert!((a / b - 1.0).abs() < 0.01, "{n} poses, {what}: {a} vs {b}");
        }
        assert!(light.map.is_empty());
    }
}
