//! Constraint plans on the KR 480: planned configurations against as many random ones (the
//! planner's prediction and simulated calibrations over seeds), a plane's blind directions
//! named, and bad features files.

use super::*;
use crate::model::presets::preset;
use crate::planning::constraint_features::{parse_features, FeaturePlaces};
use crate::simulation::constraint::{aligned_model_error, touch};
use crate::simulation::GeometricErrors;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn nominal() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

fn sampler() -> PoseSampler {
    PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    }
}

fn settings(kind: ConstraintKind) -> ConstraintPlanSettings {
    ConstraintPlanSettings {
        spec: ConstraintSimulation {
            kind,
            ..ConstraintSimulation::default()
        },
        sampler: sampler(),
        ..ConstraintPlanSettings::default()
    }
}

/// The mean model error (mm, after the best rigid alignment, over 300 random poses) of the
/// calibration of `planned` as the true robot of `seed` measures it.
fn calibrated_error(planned: &ConstraintData, seed: u64) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
    let truth = GeometricErrors::default()
        .apply(&nominal(), &mut rng)
        .unwrap();
    let (data, missed) = touch(&truth, &nominal(), planned, 0.01, 5000 + seed).unwrap();
    assert!(missed.len() <= 2, "{missed:?}");
    let cal = calibrate_constraints(&nominal(), &data, &ConstraintOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7000 + seed);
    let poses = random_poses(&nominal(), 300, &sampler(), &mut rng).unwrap();
    aligned_model_error(&cal.robot, &truth, &poses).unwrap().0
}

#[test]
fn planned_fixed_points_beat_random_configurations() {
    let s = settings(ConstraintKind::Point);
    let p = plan_constraints(&nominal(), &s, &()).unwrap();
    assert_eq!(p.data.rows.len(), 80);
    assert_eq!(p.random.rows.len(), 80);
    assert_eq!(p.data.distances.len(), 6);
    for k in 0..4 {
        assert!(
            p.data.rows_of(k).count() >= 2,
            "feature {k} has its minimum"
        );
    }
    assert!(p.scale_known);
    assert!(p.unseen[0].contains("base pose"), "{:?}", p.unseen);
    // The planner's own prediction.
    let (pl, rd) = (
        p.planned.workspace_rms_mm,
        p.random_quality.workspace_rms_mm,
    );
    eprintln!("predicted workspace RMS: planned {pl:.5} mm, random {rd:.5} mm");
    assert!(
        pl.is_finite() && pl < 0.8 * rd,
        "planned {pl} vs random {rd}"
    );
    // The directions' shares add up to the predicted mean squared error.
    let s = settings(ConstraintKind::Point);
    let g = nominal().geometric();
    let data = &p.data;
    let features: Vec<FeatureEstimate> = p.features.clone();
    let layout = Layout::new(&g, &p.identified, &features);
    let (j, dist) = blocks_of(&g, &layout, data, &features);
    let n = layout.n;
    let mut rows = j;
    rows.extend(dist);
    let jm = DMatrix::from_row_slice(rows.len() / n, n, &rows);
    // Scaled by the columns' own sizes here (the shares add up whatever the scaling).
    let scale: Vec<f64> = (0..n).map(|c| jm.column(c).norm()).collect();
    let jm = DMatrix::from_fn(jm.nrows(), n, |r, c| jm[(r, c)] / scale[c]);
    let m = jm.transpose() * &jm;
    let ws = workspace_blocks(&g, &layout, &s.sampler, s.spec.seed, &scale).unwrap();
    let all: Vec<usize> = (0..ws.len()).collect();
    let w = ws.information(&all) / ws.len() as f64;
    let parts = weakest(&m, &w, &p.identified, s.spec.noise_mm);
    let total: f64 = parts.iter().map(|d| d.rms_mm * d.rms_mm).sum();
    assert_eq!(parts.len(), p.identified.len());
    assert!(
        (total.sqrt() / pl - 1.0).abs() < 1e-6,
        "the parts {} against the prediction {pl}",
        total.sqrt()
    );

    // Simulated calibrations of both sets by the true robots of several seeds.
    let seeds = 1..=5;
    let planned: Vec<f64> = seeds
        .clone()
        .map(|s| calibrated_error(&p.data, s))
        .collect();
    let random: Vec<f64> = seeds.map(|s| calibrated_error(&p.random, s)).collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!("model error per seed (mm): planned {planned:.4?}, random {random:.4?}");
    eprintln!(
        "mean model error over 5 seeds: planned {:.4} mm, random {:.4} mm",
        mean(&planned),
        mean(&random)
    );
    assert!(mean(&planned) < mean(&random));
}

#[test]
fn a_plane_plan_names_what_a_plane_cannot_see() {
    // One plane: it sees the tool point along its normal only (three planes whose normals span
    // space see every direction but the base pose and the scale).
    let mut s = settings(ConstraintKind::Plane);
    s.spec.features = 1;
    s.spec.per_feature = 40;
    s.candidates_per_feature = 150;
    let p = plan_constraints(&nominal(), &s, &()).unwrap();
    eprintln!("unseen by one plane: {:#?}", p.unseen);
    assert_eq!(p.data.rows.len(), 40);
    assert!(!p.scale_known);
    assert!(
        p.unseen.iter().any(|u| u.contains("scale")),
        "{:?}",
        p.unseen
    );
    assert!(p.unseen[0].contains("base pose"), "{:?}", p.unseen);
    // The directions it sees least, with their shares of the predicted model error.
    eprintln!("weakest directions of one plane: {:#?}", p.weakest);
    assert_eq!(p.weakest.len(), WEAKEST_SHOWN);
    assert!(p.weakest[0].rms_mm >= p.weakest[1].rms_mm && !p.weakest[0].params.is_empty());
    assert!(p.planned.workspace_rms_mm.is_finite());
    assert!(p.planned.workspace_rms_mm < p.random_quality.workspace_rms_mm);
}

#[test]
fn given_features_are_planned_and_bad_ones_named() {
    let path = Path::new("features.csv");
    // Where a reference configuration puts the tool: reachable.
    let q = vec![0.3, -1.2, 1.4, 0.2, 0.8, 0.1];
    let p0 = nominal().tool_position(&q);
    let text = format!(
        "constraint,x,y,z\npoint:A,{},{},{}\npoint:B,{},{},{}\n",
        p0.x,
        p0.y,
        p0.z,
        p0.x - 300.0,
        p0.y + 200.0,
        p0.z
    );
    let given = parse_features(path, &text).unwrap();
    let mut s = settings(ConstraintKind::Point);
    s.spec.features = 2;
    s.spec.per_feature = 15;
    s.candidates_per_feature = 100;
    s.places = FeaturePlaces::Given {
        path: path.into(),
        features: given,
    };
    let p = plan_constraints(&nominal(), &s, &()).unwrap();
    assert_eq!(p.data.rows.len(), 30);
    assert_eq!(p.data.distances.len(), 1);
    assert!((p.features[0].position - p0).norm() < 1e-9);

    // Out of reach: named with its line.
    let far = "constraint,x,y,z\npoint:A,1500,0,1000\npoint:Far,20000,0,0\n";
    s.places = FeaturePlaces::Given {
        path: path.into(),
        features: parse_features(path, far).unwrap(),
    };
    let e = plan_constraints(&nominal(), &s, &())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("features.csv:3") && e.contains("point:Far"),
        "{e}"
    );
    assert!(e.contains("out of the robot's reach"), "{e}");

    for (text, want) in [
        ("constraint,x,y,z\n", "no feature"),
        ("constraint,x,y\npoint:A,1,2\n", "no `z` column"),
        ("constraint,x,y,z\nline:A,1,2,3\n", "is not point:NAME"),
        ("constraint,x,y,z\nplane:P,1,2,3\n", "needs its normal"),
        ("constraint,x,y,z\nsphere:S,1,2,3\n", "needs its radius"),
        ("constraint,x,y,z\npoint:A,1,2,x\n", "not a finite number"),
        (
            "constraint,x,y,z\npoint:A,1,2,3\npoint:A,1,2,4\n",
            "already given on line 2",
        ),
    ] {
        let e = parse_features(path, text).unwrap_err();
        assert!(matches!(e, Error::Parse { .. }), "{e}");
        assert!(e.to_string().contains(want), "{text:?}: {e}");
    }
}
