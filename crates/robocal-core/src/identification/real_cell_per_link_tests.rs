//! The thermal family with one coefficient per link: its columns against central differences,
//! what a session can and cannot separate, and exact recovery of an uneven warm-up.

use super::*;

/// How much each link of the simulated arm warms relative to the measured temperature:
/// the column (link 1) less, the arms next to the joint 2 and 3 motors more. Link 5 has no
/// length in the model (nothing of it can grow), so it is given none in the truth either.
const GAIN: [f64; 6] = [0.6, 1.5, 1.3, 0.8, 0.0, 1.1];

fn per_link_model(reference_c: f64) -> Robot {
    let mut r = preset("kuka-kr480-r3330").unwrap();
    backlash::enable(&mut r, &[0, 1, 2, 3, 4, 5]).unwrap();
    thermal::enable_per_link(&mut r, reference_c).unwrap();
    r
}

#[test]
fn per_link_columns_match_central_differences() {
    let mut r = per_link_model(22.0);
    assert!(thermal::per_link(&r));
    let ks: Vec<Param> = r
        .params()
        .into_iter()
        .filter(|p| p.family_id() == thermal::ID)
        .collect();
    assert_eq!(
        ks.iter().map(|p| p.name()).collect::<Vec<_>>(),
        (1..=6).map(|j| format!("thermal_k{j}")).collect::<Vec<_>>()
    );
    for (j, p) in ks.iter().enumerate() {
        r.set(*p, 1e-5 * (0.5 + 0.3 * j as f64));
        assert_eq!(Param::parse(&p.name()), Some(*p));
    }
    let params = r.params();
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    for _ in 0..20 {
        let q: Vec<f64> = r
            .limits()
            .iter()
            .map(|l| rng.gen_range(l.min..=l.max))
            .collect();
        let c = Conditions {
            temperature_c: rng.gen_range(10.0..40.0),
            ..Conditions::UNKNOWN
        };
        let mut jp = vec![Vector3::zeros(); params.len()];
        let p0 = r.target_screws_in(&q, 0, &c, None, Some(&mut jp), None).0;
        assert!((p0 - r.target_position_in(&q, 0, &c)).norm() < 1e-12);
        // The family's columns and the grown lengths' columns.
        for (k, p) in params.iter().enumerate() {
            if !(p.family_id() == thermal::ID || thermal::grows(*p)) {
                continue;
            }
            let h = if p.family_id() == thermal::ID {
                1e-7
            } else {
                1e-4
            };
            let at = |d: f64| {
                let mut s = r.clone();
                s.set(*p, r.get(*p) + d);
                s.target_position_in(&q, 0, &c)
            };
            let fd = (at(h) - at(-h)) / (2.0 * h);
            let err = (fd - jp[k]).norm();
            assert!(
                err <= 1e-6 * fd.norm().max(1.0),
                "{}: analytic {:?} vs central {:?}",
                p.name(),
                jp[k],
                fd
            );
        }
    }
    // The reference moves, the coefficients stay.
    thermal::set_reference_c(&mut r, 25.0).unwrap();
    assert_eq!(thermal::reference_c(&r), Some(25.0));
    assert!((r.get(ks[2]) - 1.1e-5).abs() < 1e-18);
}

/// A noise-free session of a truth whose links warm unevenly ([`GAIN`]); `wide`: the
/// session spans the whole warm-up of a 30 K rise (300 poses of 30 s, a 30 min time
/// constant), else the class default (75 poses, 20 to 24.5 deg C).
fn uneven_session(reference_c: f64, wide: bool) -> crate::simulation::Simulation {
    let kr = preset("kuka-kr480-r3330").unwrap();
    let mut truth = super::table3_fixed_at(reference_c);
    // d1 and d6 hold their nominal values at the reference under each link's own growth.
    let cell = ThermalModel::for_robot(&kr);
    for (p, j) in [(Param::d(0), 0), (Param::d(5), 5)] {
        let shrink = (-EXPANSION * GAIN[j] * (reference_c - cell.ambient_c)).exp();
        truth.set(p, kr.get(p) * shrink);
    }
    let thermal = if wide {
        ThermalModel {
            rise_c: 30.0,
            time_constant_s: 1800.0,
            seconds_per_pose: 30.0,
            ..cell
        }
    } else {
        cell
    };
    let cfg = SimulationConfig {
        seed: 4,
        poses: if wide { 300 } else { 75 },
        validation_poses: 40,
        noise_mm: 0.0,
        noise_per_m: 0.0,
        backlash: Some(BacklashModel {
            half_play_deg: HALF_PLAY.to_vec(),
        }),
        thermal: Some(ThermalModel {
            link_gain: Some(GAIN.to_vec()),
            ..thermal
        }),
        ..SimulationConfig::default()
    };
    simulate(&kr, &TruthSpec::Robot(truth), &cfg, &()).unwrap()
}

fn fit_model(
    model: &Robot,
    sim: &crate::simulation::Simulation,
) -> super::super::pipeline::Calibration {
    let split = split_measurements(&sim.measurements).unwrap();
    let settings = CalibrationSettings {
        objective: Objective::LeastSquares,
        model: super::super::ModelChoice::Given,
        solver: super::super::SolverOptions {
            step_tolerance_mm: 1e-13,
            gradient_tolerance: 1e-14,
            objective_tolerance: 1e-20,
            ..Default::default()
        },
        ..Default::default()
    };
    let data = CalibrationData {
        calibration: &split.calibration,
        plane: Some(&split.plane),
        validation: Some(&split.validation),
    };
    calibrate(model, data, &settings, &()).unwrap()
}

#[test]
fn noise_free_uneven_warm_up_is_recovered_per_link_and_not_by_the_lumped_coefficient() {
    let reference_c = 22.0;
    // One session of the class default (8.5 K of warm-up): the identifiability analysis says
    // which links' coefficients these data do not separate, each with its reason; link 5 has
    // no length at all, and the wrist's 290 mm moves the tool point too little.
    let short = uneven_session(reference_c, false);
    let c = fit_model(&per_link_model(reference_c), &short);
    let mut undetermined = 0;
    for j in 1..=6 {
        let p = Param::parse(&format!("thermal_k{j}")).unwrap();
        let why = c.identifiability.fixed_reason(p).map(|f| f.describe());
        eprintln!("class default session, thermal_k{j}: {why:?}");
        if j == 5 {
            assert!(
                why.as_deref().is_some_and(|w| w.starts_with("no effect")),
                "{why:?}"
            );
        } else if why.is_some() {
            assert!(
                why.as_deref()
                    .is_some_and(|w| w.starts_with("not determined by these data")),
                "thermal_k{j}: {why:?}"
            );
            undetermined += 1;
        }
    }
    assert!(undetermined >= 1);
    assert!(c
        .identifiability
        .fixed_reason(Param::parse("thermal_k6").unwrap())
        .is_some());
    // A session across the whole warm-up: every link with a length is recovered exactly.
    let sim = uneven_session(reference_c, true);
    let c = fit_model(&per_link_model(reference_c), &sim);
    let v = c.validation.as_ref().unwrap().after_stats();
    let fixed: Vec<String> = c
        .identifiability
        .fixed
        .iter()
        .map(|f| format!("{} ({})", f.param.name(), f.describe()))
        .collect();
    assert!(
        v.max_mm < 1e-8,
        "validation max {} mm; fixed {fixed:?}",
        v.max_mm
    );
    let k5 = Param::parse("thermal_k5").unwrap();
    assert!(c.identifiability.fixed_reason(k5).is_some());
    for (j, g) in GAIN.iter().enumerate() {
        if j == 4 {
            continue;
        }
        let p = Param::parse(&format!("thermal_k{}", j + 1)).unwrap();
        assert!(c.identifiability.identified.contains(&p), "{}", p.name());
        let (got, want) = (c.calibrated.get(p), EXPANSION * g);
        assert!(
            (got - want).abs() <= 1e-6 * want,
            "{}: {got} vs {want}",
            p.name()
        );
    }
    // The lumped coefficient cannot follow an uneven warm-up.
    let lumped = fit_model(&with_families(reference_c), &sim);
    let lv = lumped.validation.as_ref().unwrap().after_stats();
    eprintln!(
        "uneven warm-up: lumped validation mean {:.2e} mm",
        lv.mean_mm
    );
    assert!(lv.mean_mm > 1e-3, "{}", lv.mean_mm);
}
