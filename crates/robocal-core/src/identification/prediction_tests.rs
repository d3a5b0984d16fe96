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
