//! Tests of the real cell's effects: backlash, thermal growth, a fresh tracker station.

use super::*;
use crate::model::presets::preset;
use nalgebra::Vector3;

fn kr480() -> crate::Robot {
    preset("kuka-kr480-r3330").unwrap()
}

fn table3() -> crate::Robot {
    preset("kuka-kr480-r3330-table3").unwrap()
}

fn quiet(poses: usize) -> SimulationConfig {
    SimulationConfig {
        poses,
        validation_poses: 5,
        noise_mm: 0.0,
        noise_per_m: 0.0,
        ..SimulationConfig::default()
    }
}

fn column<'a>(s: &'a Simulation, name: &str) -> Vec<&'a str> {
    let m = &s.measurements;
    let k = m.extra_columns.iter().position(|c| c == name).unwrap();
    m.rows.iter().map(|r| r.extra[k].as_str()).collect()
}

#[test]
fn backlash_moves_each_pose_against_its_approach_and_writes_the_directions() {
    let truth = TruthSpec::Robot(table3());
    let b = BacklashModel::for_robot(&kr480());
    let cfg = SimulationConfig {
        backlash: Some(b.clone()),
        ..quiet(20)
    };
    let s = simulate(&kr480(), &truth, &cfg, &()).unwrap();
    let plain = simulate(&kr480(), &truth, &quiet(20), &()).unwrap();
    let qs: Vec<Vec<f64>> = s.measurements.rows.iter().map(|r| r.q.clone()).collect();
    let dirs = approach_directions(&home(&table3()), &qs);
    let frame = s.cell.tracker().frame;
    let mut moved = 0.0_f64;
    for (i, r) in s.measurements.rows.iter().enumerate() {
        for (j, d) in dirs[i].iter().enumerate() {
            assert_eq!(column(&s, &direction_column(j))[i], d.to_string());
        }
        let reached = b.reached(&table3(), &r.q, &dirs[i]);
        let p = frame.to_tracker(&table3().tool_position(&reached));
        assert!((p - r.p.unwrap()).norm() < 1e-9);
        moved = moved.max((r.p.unwrap() - plain.measurements.rows[i].p.unwrap()).norm());
    }
    // Half a minute of arc on a 3 m arm is tenths of a millimetre.
    assert!(moved > 0.05 && moved < 2.0, "{moved}");
    // No play, no change.
    let zero = SimulationConfig {
        backlash: Some(BacklashModel {
            half_play_deg: vec![0.0; 6],
        }),
        ..quiet(20)
    };
    let z = simulate(&kr480(), &truth, &zero, &()).unwrap();
    for (a, b) in z.measurements.rows.iter().zip(&plain.measurements.rows) {
        assert_eq!(a.p, b.p);
    }
}

#[test]
fn thermal_growth_follows_the_warm_up_and_writes_temperature_and_time() {
    let truth = TruthSpec::Robot(table3());
    let t = ThermalModel::for_robot(&kr480());
    let cfg = SimulationConfig {
        thermal: Some(t.clone()),
        ..quiet(200)
    };
    let s = simulate(&kr480(), &truth, &cfg, &()).unwrap();
    let temps: Vec<f64> = column(&s, TEMPERATURE_COLUMN)
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    let times: Vec<f64> = column(&s, TIME_COLUMN)
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(times[0], 0.0);
    assert_eq!(temps[0], 20.0);
    assert!(temps.windows(2).all(|w| w[1] >= w[0]));
    // 208 poses of 20 s: more than an hour, most of the rise (1 - exp(-4160 / 3600) = 0.69).
    let last = *temps.last().unwrap();
    let rise = t.rise_c;
    assert!(
        last > 20.0 + 0.6 * rise && last < 20.0 + 0.75 * rise,
        "{last}"
    );
    let frame = s.cell.tracker().frame;
    for (i, r) in s.measurements.rows.iter().enumerate() {
        assert_eq!(times[i], 20.0 * i as f64);
        let grown = t.grown(&table3(), temps[i]);
        let p = frame.to_tracker(&grown.tool_position(&r.q));
        assert!((p - r.p.unwrap()).norm() < 1e-9);
    }
    // Starting warm, the session is near the plateau.
    let warm = SimulationConfig {
        thermal: Some(ThermalModel {
            start_s: 4.0 * 3600.0,
            ..t
        }),
        ..quiet(5)
    };
    let w = simulate(&kr480(), &truth, &warm, &()).unwrap();
    let first: f64 = column(&w, TEMPERATURE_COLUMN)[0].parse().unwrap();
    assert!(first > 27.8, "{first}");
}

#[test]
fn a_fresh_station_measures_from_elsewhere_and_the_truth_file_says_where() {
    let truth = TruthSpec::Robot(table3());
    let s0 = simulate(&kr480(), &truth, &quiet(10), &()).unwrap();
    let cfg = SimulationConfig {
        station: 1,
        ..quiet(10)
    };
    let s1 = simulate(&kr480(), &truth, &cfg, &()).unwrap();
    let tf = s1.truth_file(&[]);
    assert_eq!(tf.tracker_frame, cfg.station_tracker_frame());
    assert_ne!(tf.tracker_frame, cfg.tracker_frame);
    // The same true points, seen from another place: same distances between them.
    let p0: Vec<Vector3<f64>> = s0.measurements.rows.iter().map(|r| r.p.unwrap()).collect();
    let p1: Vec<Vector3<f64>> = s1.measurements.rows.iter().map(|r| r.p.unwrap()).collect();
    assert!((p0[0] - p1[0]).norm() > 100.0);
    for i in 1..p0.len() {
        let (d0, d1) = ((p0[i] - p0[0]).norm(), (p1[i] - p1[0]).norm());
        assert!((d0 - d1).abs() < 1e-8);
    }
}

#[test]
fn bad_settings_are_refused_naming_the_setting() {
    let truth = TruthSpec::Robot(table3());
    let cfg = SimulationConfig {
        backlash: Some(BacklashModel {
            half_play_deg: vec![0.01; 5],
        }),
        ..quiet(5)
    };
    let e = simulate(&kr480(), &truth, &cfg, &())
        .unwrap_err()
        .to_string();
    assert!(e.contains("backlash.half_play_deg"), "{e}");
    let cfg = SimulationConfig {
        thermal: Some(ThermalModel {
            expansion_per_k: -1e-5,
            ..ThermalModel::for_robot(&kr480())
        }),
        ..quiet(5)
    };
    let e = simulate(&kr480(), &truth, &cfg, &())
        .unwrap_err()
        .to_string();
    assert!(e.contains("thermal.expansion_per_k"), "{e}");
}
