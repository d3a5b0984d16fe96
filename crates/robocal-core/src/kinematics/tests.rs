use super::poe::Poe;
use crate::model::{presets::preset, Convention, JointLimit, Link, Param, Robot};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_robot(rng: &mut ChaCha8Rng, conv: Convention, n: usize, betas: bool) -> Robot {
    let links = (0..n)
        .map(|_| Link {
            alpha: rng.gen_range(-3.0..3.0),
            d: rng.gen_range(-500.0..500.0),
            a: rng.gen_range(-500.0..500.0),
            phi: rng.gen_range(-3.0..3.0),
            beta: if betas { rng.gen_range(-0.1..0.1) } else { 0.0 },
        })
        .collect();
    let limits = vec![
        JointLimit {
            min: -3.0,
            max: 3.0
        };
        n
    ];
    let base = [
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    ];
    let tool0 = [
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-100.0..100.0),
        rng.gen_range(0.0..300.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    ];
    let mut r = Robot::new("random", conv, links, limits, base, tool0).unwrap();
    if betas {
        for i in 0..n {
            r.enable_beta(i).unwrap();
        }
    }
    for k in 0..6 {
        r.set(
            Param::Tool(k),
            rng.gen_range(-2.0..2.0) * if k < 3 { 1.0 } else { 0.01 },
        );
    }
    r
}

fn random_q(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.gen_range(-3.1..3.1)).collect()
}

#[test]
fn table1_zero_pose() {
    let r = preset("kuka-kr480-r3330").unwrap();
    let q = [0.0; 6];
    let f = r.flange_pose(&q).translation.vector;
    assert!(
        (f - Vector3::new(3615.0, 0.0, 990.0)).norm() < 1e-9,
        "flange {f}"
    );
    let t = r.tool_position(&q);
    let want = Vector3::new(3854.5558, -70.9065, 947.5837);
    assert!((t - want).norm() < 1e-4, "tool {t}");
    assert!((r.tool_pose(&q).translation.vector - t).norm() < 1e-12);
}

#[test]
fn kuka_has_36_parameters_with_paper_names() {
    let r = preset("kuka-kr480-r3330").unwrap();
    let names: Vec<String> = r.params().iter().map(|p| p.name()).collect();
    assert_eq!(names.len(), 36);
    assert_eq!(names[0], "alpha1");
    assert_eq!(names[6], "d1");
    assert_eq!(names[12], "a1");
    assert_eq!(names[18], "phi1");
    assert_eq!(names[24], "base_x");
    assert_eq!(names[35], "tool_c");
    let t3 = preset("kuka-kr480-r3330-table3").unwrap();
    assert!((t3.get_display(Param::D(0)) - 1044.237).abs() < 1e-12);
    assert!((t3.get_display(Param::Base(3)) + 0.0497).abs() < 1e-12);
    assert!((t3.get_display(Param::Tool(1)) + 0.4149).abs() < 1e-12);
}

#[test]
fn poe_equals_dh_product() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let cases = [
        (Convention::Mdh, 6, false),
        (Convention::Dh, 6, false),
        (Convention::Mdh, 7, true),
        (Convention::Dh, 7, true),
    ];
    for (conv, n, betas) in cases {
        let r = random_robot(&mut rng, conv, n, betas);
        let poe = Poe::from_robot(&r);
        for _ in 0..250 {
            let q = random_q(&mut rng, n);
            let a = r.tool_pose(&q);
            let b = poe.tool_pose(&q);
            let dp = (a.translation.vector - b.translation.vector).norm();
            let dr = (a.rotation.matrix() - b.rotation.matrix()).norm();
            assert!(dp < 1e-9, "{conv:?} n={n}: position differs by {dp} mm");
            assert!(dr < 1e-12, "{conv:?} n={n}: rotation differs by {dr}");
        }
    }
    // And the paper's robot, 1000 poses.
    for name in ["kuka-kr480-r3330", "kuka-kr480-r3330-table3"] {
        let r = preset(name).unwrap();
        let poe = Poe::from_robot(&r);
        for _ in 0..1000 {
            let q = random_q(&mut rng, 6);
            let dp = (r.tool_position(&q) - poe.tool_pose(&q).translation.vector).norm();
            assert!(dp < 1e-9, "{name}: {dp}");
        }
    }
}

fn check_close(an: &Vector3<f64>, fd: &Vector3<f64>, scale: f64, what: &str) {
    let err = (an - fd).norm();
    assert!(
        err <= 1e-6 * fd.norm().max(scale),
        "{what}: analytic {an} vs finite difference {fd} (err {err})"
    );
}

#[test]
fn jacobians_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut robots = vec![
        preset("kuka-kr480-r3330").unwrap(),
        preset("kuka-kr480-r3330-table3").unwrap(),
    ];
    for (conv, n, betas) in [
        (Convention::Mdh, 6, true),
        (Convention::Dh, 6, true),
        (Convention::Mdh, 7, true),
        (Convention::Dh, 7, false),
        (Convention::Dh, 7, true),
    ] {
        robots.push(random_robot(&mut rng, conv, n, betas));
    }
    for r in robots {
        let n = r.dof();
        let params = r.params();
        let mut jq = vec![Vector3::zeros(); n];
        let mut jp = vec![Vector3::zeros(); params.len()];
        for _ in 0..20 {
            let q = random_q(&mut rng, n);
            let p = r.tool_position_jacobians(&q, Some(&mut jq), Some(&mut jp));
            assert!((p - r.tool_position(&q)).norm() < 1e-9);
            // Typical magnitude of a column: the reach (mm per rad).
            let scale = p.norm().max(1.0) * 1e-3;
            for i in 0..n {
                let h = 1e-6;
                let mut qp = q.clone();
                qp[i] += h;
                let mut qm = q.clone();
                qm[i] -= h;
                let fd = (r.tool_position(&qp) - r.tool_position(&qm)) / (2.0 * h);
                check_close(&jq[i], &fd, scale, &format!("{} dp/dq{}", r.name(), i + 1));
            }
            for (k, &prm) in params.iter().enumerate() {
                let h = if prm.unit() == crate::Unit::Mm {
                    1e-4
                } else {
                    1e-7
                };
                let v = r.get(prm);
                let mut rp = r.clone();
                rp.set(prm, v + h);
                let mut rm = r.clone();
                rm.set(prm, v - h);
                let fd = (rp.tool_position(&q) - rm.tool_position(&q)) / (2.0 * h);
                check_close(
                    &jp[k],
                    &fd,
                    scale,
                    &format!("{} {:?} dp/d{}", r.name(), r.convention(), prm),
                );
            }
        }
    }
}

#[test]
fn parameter_get_set_by_name() {
    let mut r = preset("kuka-kr480-r3330").unwrap();
    let p = r.param_by_name("a2").unwrap();
    r.set_display(p, 501.0);
    assert_eq!(r.get_display(p), 501.0);
    let q = [0.0; 6];
    assert!((r.flange_pose(&q).translation.vector.x - 3616.0).abs() < 1e-9);
    assert!(r.param_by_name("beta2").is_err());
    r.enable_beta(1).unwrap();
    assert!(r.param_by_name("beta2").is_ok());
    assert_eq!(r.param_count(), 37);
    let e = r.param_by_name("d9").unwrap_err().to_string();
    assert!(e.contains("unknown parameter `d9`"), "{e}");
}

#[test]
fn parallel_axes_detection() {
    let mut r = preset("kuka-kr480-r3330").unwrap();
    // Axes 2 and 3 are parallel (alpha3 = 0).
    assert_eq!(r.enable_beta_for_parallel_axes(), vec![2]);
}
