//! Monte Carlo over seeds: the ISO 9283 test of a simulated robot with a known bias (the true
//! robot of the paper's Table III against the nominal) and a known repeatability (per-joint
//! error per move) gives AP and RP within their expected values. The expectations come from the
//! model itself: the bias from the two robots' forward kinematics, the scatter from the
//! linearized covariance `J S_q J^T + sigma_t^2 I` (joint errors and tracker noise), sampled.

use super::*;
use crate::model::presets::preset;
use crate::simulation::{simulate_joints, RepeatabilityModel, SimulationConfig, TruthSpec};
use crate::Robot;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const CYCLES: usize = 30;
const SEEDS: u64 = 20;
const STD_DEG: f64 = 0.001;

/// Tool-point covariance (mm^2) of the joint errors at `q` on `robot`, plus the tracker noise.
fn covariance(robot: &Robot, q: &[f64], std_rad: f64, tracker_sigma: f64) -> Matrix3<f64> {
    let h = 1e-6;
    let mut s = Matrix3::identity() * tracker_sigma * tracker_sigma;
    for i in 0..q.len() {
        let (mut a, mut b) = (q.to_vec(), q.to_vec());
        a[i] += h;
        b[i] -= h;
        let col = (robot.tool_position(&a) - robot.tool_position(&b)) / (2.0 * h) * std_rad;
        s += col * col.transpose();
    }
    s
}

/// Mean and standard deviation of AP and RP of `CYCLES` samples `b + N(0, cov)`, sampled.
fn expected(bias: &Vector3<f64>, cov: &Matrix3<f64>, rng: &mut ChaCha8Rng) -> [(f64, f64); 2] {
    let l = cov.cholesky().expect("positive definite").l();
    let trials = 4000;
    let (mut ap, mut rp) = (Vec::new(), Vec::new());
    for _ in 0..trials {
        let pts: Vec<Vector3<f64>> = (0..CYCLES)
            .map(|_| {
                let z = Vector3::from_fn(|_, _| StandardNormal.sample(&mut *rng));
                bias + l * z
            })
            .collect();
        let g = pts.iter().sum::<Vector3<f64>>() / CYCLES as f64;
        let d: Vec<f64> = pts.iter().map(|p| (p - g).norm()).collect();
        let (m, s) = metrics::mean_std(&d);
        ap.push(g.norm());
        rp.push(m + 3.0 * s);
    }
    [metrics::mean_std(&ap), metrics::mean_std(&rp)]
}

#[test]
fn ap_and_rp_of_a_simulated_robot_over_seeds() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let plan = make_plan(
        &nominal,
        None,
        &PlanSettings {
            cycles: CYCLES,
            ..PlanSettings::default()
        },
    )
    .unwrap();
    let base = SimulationConfig {
        repeatability: Some(RepeatabilityModel::uniform(STD_DEG, &nominal)),
        ..SimulationConfig::default()
    };
    let frame = base.tracker_frame.to_tracker_frame();
    let mut ap = vec![Vec::new(); 5];
    let mut rp = vec![Vec::new(); 5];
    for seed in 1..=SEEDS {
        let cfg = SimulationConfig {
            seed,
            ..base.clone()
        };
        let ev = simulate_test(
            &nominal,
            &TruthSpec::Robot(truth.clone()),
            &cfg,
            &plan,
            &frame,
            &TrackerMpe::default(),
            &(),
        )
        .unwrap();
        for (k, p) in ev.poses.iter().enumerate() {
            ap[k].push(p.ap_mm);
            rp[k].push(p.rp_mm);
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for k in 0..5 {
        let q = &plan.joints[k];
        let bias = truth.tool_position(q) - plan.poses[k].translation.vector;
        let dist_m = (truth.tool_position(q) - frame.origin()).norm() / 1000.0;
        let sigma_t = base.noise_mm + base.noise_per_m * dist_m;
        let cov = covariance(&truth, q, STD_DEG.to_radians(), sigma_t);
        let [(e_ap, s_ap), (e_rp, s_rp)] = expected(&bias, &cov, &mut rng);
        let (m_ap, _) = metrics::mean_std(&ap[k]);
        let (m_rp, _) = metrics::mean_std(&rp[k]);
        let n = SEEDS as f64;
        // The bias is what a calibration removes: large against the scatter.
        assert!(bias.norm() > 0.3, "P{}: bias {} mm", k + 1, bias.norm());
        assert!(
            (m_ap - e_ap).abs() < 4.0 * s_ap / n.sqrt() + 1e-9,
            "P{}: AP {m_ap} mm over seeds, expected {e_ap} +- {s_ap}",
            k + 1
        );
        assert!(
            (m_rp - e_rp).abs() < 4.0 * s_rp / n.sqrt(),
            "P{}: RP {m_rp} mm over seeds, expected {e_rp} +- {s_rp}",
            k + 1
        );
        assert!(
            e_rp > 0.05,
            "P{}: the repeatability shows ({e_rp} mm)",
            k + 1
        );
    }
}

#[test]
fn repeatability_off_gives_the_tracker_noise_only() {
    // Without the model the scatter is the tracker's alone: RP is a few hundredths of a mm.
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let plan = make_plan(
        &nominal,
        None,
        &PlanSettings {
            cycles: 10,
            ..PlanSettings::default()
        },
    )
    .unwrap();
    let set = plan_rows(&nominal, &plan);
    let with = |r: Option<RepeatabilityModel>| {
        let cfg = SimulationConfig {
            repeatability: r,
            ..SimulationConfig::default()
        };
        let sim = simulate_joints(
            &nominal,
            &TruthSpec::Robot(nominal.clone()),
            &cfg,
            &set,
            &(),
        )
        .unwrap();
        let p: Vec<Vector3<f64>> = sim.measurements.rows.iter().map(|m| m.p.unwrap()).collect();
        let spread = |pose: usize| {
            let pts: Vec<&Vector3<f64>> = plan
                .rows()
                .zip(&p)
                .filter(|(r, _)| r.pose == pose)
                .map(|(_, x)| x)
                .collect();
            let g = pts.iter().copied().sum::<Vector3<f64>>() / pts.len() as f64;
            pts.iter().map(|x| (*x - g).norm()).fold(0.0, f64::max)
        };
        spread(1)
    };
    let off = with(None);
    let on = with(Some(RepeatabilityModel::uniform(0.01, &nominal)));
    assert!(off < 0.2, "{off}");
    assert!(on > 3.0 * off, "{on} vs {off}");
    // Validation names the setting.
    let bad = RepeatabilityModel {
        std_deg: vec![0.001; 5],
    };
    let e = bad.validate(6).unwrap_err().to_string();
    assert!(e.starts_with("repeatability.std_deg"), "{e}");
    let d = RepeatabilityModel::default_for(&nominal);
    d.validate(6).unwrap();
    assert!(
        d.std_deg.iter().all(|v| *v > 0.0 && *v < 0.001),
        "{:?}",
        d.std_deg
    );
}
