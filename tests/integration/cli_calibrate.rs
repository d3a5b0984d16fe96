//! `robocal calibrate` end to end: simulated data written as CSV, the result JSON contract, the
//! printed tables, `fk --params` on the result, bad input, and the real UR5/WAM data sets.

use crate::util::*;
use rand::SeedableRng;
use robocal_core::frame::{pose, TrackerFrame};
use robocal_core::io::CalibrationResult;
use robocal_core::simulation::{random_poses, PoseSampler, Tracker};
use robocal_core::{preset, Robot};
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn tracker(noise: bool) -> Tracker {
    let (s, p) = if noise { (0.010, 0.005) } else { (0.0, 0.0) };
    let frame = TrackerFrame::new(pose(&[3900.0, -2200.0, -350.0, 2.65, 0.007, -0.012]));
    Tracker::new(frame, s, p).unwrap()
}

/// Simulated rows `(q rad, measured point)` of the Table III truth.
fn simulate(n: usize, seed: u64, noise: bool) -> Vec<(Vec<f64>, [f64; 3])> {
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let tr = tracker(noise);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let sampler = PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    };
    random_poses(&truth, n, &sampler, &mut rng)
        .unwrap()
        .into_iter()
        .map(|q| {
            let m = tr.measure(&truth.tool_position(&q), &mut rng);
            (q, [m.x, m.y, m.z])
        })
        .collect()
}

/// Writes a measurement CSV with `id` and `set` columns.
fn write_csv(path: &Path, rows: &[(Vec<f64>, [f64; 3])], set: &dyn Fn(usize) -> &'static str) {
    let mut s = String::from("id,q1,q2,q3,q4,q5,q6,x,y,z,set\n");
    for (i, (q, m)) in rows.iter().enumerate() {
        let _ = write!(s, "p{i}");
        for v in q {
            let _ = write!(s, ",{:.10}", v.to_degrees());
        }
        let _ = writeln!(s, ",{:.7},{:.7},{:.7},{}", m[0], m[1], m[2], set(i));
    }
    std::fs::write(path, s).unwrap();
}

fn paper_files(dir: &Path, noise: bool) -> (PathBuf, PathBuf) {
    // Three plane points (joint 1 turning alone keeps the tool at one height), then 75 poses.
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let tr = tracker(noise);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut rows: Vec<(Vec<f64>, [f64; 3])> = [-40.0f64, 10.0, 55.0]
        .iter()
        .map(|a1| {
            let q = vec![a1.to_radians(), -0.9, 0.6, 0.3, 0.8, -0.2];
            let m = tr.measure(&truth.tool_position(&q), &mut rng);
            (q, [m.x, m.y, m.z])
        })
        .collect();
    rows.extend(simulate(75, 1, noise));
    let cal = dir.join("cal.csv");
    write_csv(&cal, &rows, &|i| {
        if i < 3 {
            "plane"
        } else {
            "calibration"
        }
    });
    let val = dir.join("val.csv");
    write_csv(&val, &simulate(73, 2, noise), &|_| "validation");
    (cal, val)
}

#[test]
fn calibrate_prints_the_tables_and_writes_the_contract() {
    let dir = Dir::new();
    let (cal, val) = paper_files(dir.path(), true);
    let out = dir.join("result.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&cal),
        "--validate",
        p(&val),
        "--affine",
        "--out",
        p(&out),
    ]);
    let t = o.text();
    o.assert_ok();
    for want in [
        "3 plane point(s)",
        "initial measurement frame from 3 plane points",
        "Table II",
        "Table III",
        "Table IV",
        "26 parameters identified, 10 fixed",
        "d1       fixed: same effect as base_z",
        "affine Tr (eq. 8-11)",
        "converged",
    ] {
        assert!(t.contains(want), "missing `{want}` in:\n{t}");
    }
    let j = read_json(&out);
    let params = j["parameters"].as_object().unwrap();
    assert_eq!(params.len(), 36);
    let mut identified = 0;
    for (name, e) in params {
        assert!(e["nominal"].is_f64() && e["calibrated"].is_f64(), "{name}");
        let unit = e["unit"].as_str().unwrap();
        assert!(unit == "mm" || unit == "deg");
        if e["fixed"].as_bool().unwrap() {
            assert!(e["reason"].is_string(), "{name}");
            assert_eq!(e["nominal"], e["calibrated"], "{name}");
        } else {
            identified += 1;
            assert!(e["std"].as_f64().unwrap() > 0.0, "{name}");
        }
    }
    assert_eq!(identified, 26);
    for k in ["x", "y", "z", "a", "b", "c"] {
        assert!(j["tracker_frame"][k].is_f64());
    }
    for set in ["calibration", "validation"] {
        for when in ["before", "after"] {
            let st = &j["errors"][set][when];
            for k in ["mean_mm", "std_mm", "max_mm", "rms_mm"] {
                assert!(st[k].is_f64(), "{set}.{when}.{k}");
            }
        }
    }
    assert_eq!(j["errors"]["calibration"]["after"]["n"], 75);
    assert_eq!(j["errors"]["validation"]["after"]["n"], 73);
    let after = j["errors"]["validation"]["after"]["mean_mm"]
        .as_f64()
        .unwrap();
    let before = j["errors"]["validation"]["before"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(before > 0.5 && after < 0.1, "{before} -> {after}");
    assert!(j["identifiability"]["condition_number"].as_f64().unwrap() > 1.0);
    assert_eq!(j["identifiability"]["n_identified"], 26);
    assert_eq!(j["solver"]["converged"], true);
    assert!(
        j["uncertainty"]["most_correlated"]
            .as_array()
            .unwrap()
            .len()
            > 3
    );
    assert!(j["registration"]["affine"]["t"].as_array().unwrap().len() == 12);

    // The contract: pose(tracker_frame) * m against the calibrated model gives the "after" errors.
    let res = CalibrationResult::read(&out).unwrap();
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let robot = res.calibrated_robot(&nominal, &out).unwrap();
    let f = res.tracker_frame();
    let rows = simulate(73, 2, true);
    let mean = rows
        .iter()
        .map(|(q, m)| {
            let p = f.to_base(&nalgebra::Vector3::new(m[0], m[1], m[2]));
            (p - robot.tool_position(q)).norm()
        })
        .sum::<f64>()
        / rows.len() as f64;
    assert!((mean - after).abs() < 1e-6, "{mean} vs {after}");
}

fn fk_json(robot: &str, params: &Path, q: &[f64]) -> [f64; 3] {
    let joints = q
        .iter()
        .map(|v| format!("{v}"))
        .collect::<Vec<_>>()
        .join(",");
    let o = robocal(&[
        "fk",
        "--robot",
        robot,
        "--params",
        p(params),
        "--joints",
        &joints,
        "--json",
    ]);
    o.assert_ok();
    let v: Value = serde_json::from_str(&o.stdout()).unwrap();
    [
        v["x"].as_f64().unwrap(),
        v["y"].as_f64().unwrap(),
        v["z"].as_f64().unwrap(),
    ]
}

#[test]
fn fk_with_the_result_uses_the_calibrated_model() {
    let dir = Dir::new();
    let (cal, _) = paper_files(dir.path(), false);
    let out = dir.join("r.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&cal),
        "--beta",
        "parallel",
        "--objective",
        "least-squares",
        "--out",
        p(&out),
    ]);
    o.assert_ok();
    let res = CalibrationResult::read(&out).unwrap();
    assert!(res.parameters.contains_key("beta3"));
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let robot: Robot = res.calibrated_robot(&nominal, &out).unwrap();
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let f = res.tracker_frame();
    let tr = tracker(false);
    for q in [
        [10.0, -60.0, 30.0, 45.0, -20.0, 90.0],
        [-120.0, -20.0, 80.0, -150.0, 60.0, -30.0],
    ] {
        let p = fk_json("kuka-kr480-r3330", &out, &q);
        let qr: Vec<f64> = q.iter().map(|v| v.to_radians()).collect();
        let lib = robot.tool_position(&qr);
        for k in 0..3 {
            assert!((p[k] - lib[k]).abs() < 1e-8, "{p:?} vs {lib}");
        }
        // And the calibrated model predicts what the (noise-free) tracker would measure.
        let m = tr.exact(&truth.tool_position(&qr));
        let pm = f.to_base(&m);
        assert!((pm - lib).norm() < 1e-5, "{pm} vs {lib}");
    }
}

fn expect_failure(args: &[&str], out: &Path, code: i32, wants: &[&str]) {
    let o = robocal(args);
    let t = o.text();
    o.assert_code(code);
    for w in wants {
        assert!(t.contains(w), "{args:?}: missing `{w}` in {t}");
    }
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn bad_input_is_rejected_and_nothing_is_written() {
    let dir = Dir::new();
    let out = dir.join("never.json");
    let o = p(&out).to_owned();
    let run = |data: &Path, extra: &[&str], code: i32, wants: &[&str]| {
        let mut args = vec![
            "calibrate",
            "--robot",
            "kuka-kr480-r3330",
            "--data",
            p(data),
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", &o]);
        expect_failure(&args, &out, code, wants);
    };
    // Fewer points than identifiable parameters.
    let few = dir.join("few.csv");
    write_csv(&few, &simulate(20, 3, true), &|_| "");
    run(
        &few,
        &[],
        5,
        &["20 calibration points for 26 identifiable parameters"],
    );
    // A duplicated pose.
    let mut rows = simulate(40, 4, true);
    rows.push(rows[5].clone());
    let dup = dir.join("dup.csv");
    write_csv(&dup, &rows, &|_| "");
    run(&dup, &[], 3, &["dup.csv:42", "duplicated pose", "line 7"]);
    // NaN.
    let nan = dir.join("nan.csv");
    let text = std::fs::read_to_string(&dup).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let mut cells: Vec<String> = lines[3].split(',').map(str::to_owned).collect();
    cells[8] = "NaN".into();
    lines[3] = cells.join(",");
    std::fs::write(&nan, lines.join("\n")).unwrap();
    run(
        &nan,
        &[],
        3,
        &["nan.csv:4", "field `y`", "not a finite number"],
    );
    // An absurd reading (a unit mistake or a corrupt file).
    cells[8] = "1e300".into();
    lines[3] = cells.join(",");
    let huge = dir.write("huge.csv", lines.join("\n"));
    run(
        &huge,
        &[],
        3,
        &["huge.csv:4", "not a plausible tracker reading"],
    );
    // A joint count that differs from the robot's.
    let seven = dir.join("seven.csv");
    std::fs::write(
        &seven,
        "q1,q2,q3,q4,q5,q6,q7,x,y,z\n1,2,3,4,5,6,7,100,200,300\n",
    )
    .unwrap();
    run(&seven, &[], 3, &["seven.csv:1", "q7", "6 joints"]);
    // Unknown --fix / --free names, all named at once.
    let ok = dir.join("ok.csv");
    write_csv(&ok, &simulate(40, 6, true), &|_| "");
    run(
        &ok,
        &["--fix", "d1,d9,tool_q"],
        2,
        &["--fix", "`d9`", "`tool_q`"],
    );
    run(&ok, &["--free", "beta3"], 2, &["--free", "`beta3`"]);
    // Freeing what cannot be identified.
    run(
        &ok,
        &["--free", "tool_a"],
        5,
        &["--free", "tool_a: no effect"],
    );
    run(&ok, &["--beta", "9"], 2, &["--beta", "joint 9"]);
    // Two plane points: the initial frame needs three.
    let two = dir.join("two-plane.csv");
    write_csv(&two, &simulate(40, 7, true), &|i| {
        if i < 2 {
            "plane"
        } else {
            ""
        }
    });
    run(&two, &[], 3, &["plane points", "2 row(s) with set = plane"]);
    // An output directory that does not exist.
    let missing = dir.join("nope").join("r.json");
    expect_failure(
        &[
            "calibrate",
            "--robot",
            "kuka-kr480-r3330",
            "--data",
            p(&ok),
            "--out",
            p(&missing),
        ],
        &missing,
        4,
        &["does not exist"],
    );
}

#[test]
fn robust_objective_names_the_downweighted_lines() {
    let dir = Dir::new();
    let mut rows = simulate(75, 8, true);
    for i in [9usize, 30, 61] {
        rows[i].1[0] += 4.0;
        rows[i].1[2] -= 3.0;
    }
    let cal = dir.join("cal.csv");
    write_csv(&cal, &rows, &|_| "");
    let out = dir.join("r.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&cal),
        "--objective",
        "robust",
        "--out",
        p(&out),
    ]);
    let t = o.text();
    o.assert_ok();
    assert!(t.contains("3 point(s) down-weighted"), "{t}");
    let j = read_json(&out);
    let mut lines: Vec<u64> = j["downweighted_points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["line"].as_u64().unwrap())
        .collect();
    lines.sort();
    // Data rows start on line 2.
    assert_eq!(lines, vec![11, 32, 63]);
}

#[test]
fn real_ur5_grid_calibration_predicts_the_random_poses() {
    let Some(d) = real_data() else { return };
    let j = &fixtures::real_fit(&d, "ur5").result;
    let v = &j["errors"]["validation"];
    let after = v["after"]["mean_mm"].as_f64().unwrap();
    let before = v["before"]["mean_mm"].as_f64().unwrap();
    assert_eq!(v["after"]["n"], 20);
    // Target of issue 4: at most 0.12 mm (the authors' hybrid model with a neural network:
    // 0.155 mm).
    assert!(after <= 0.12, "UR5 random poses: {before} -> {after} mm");
    // The data are already roughly in the base frame: the fitted frame is close to identity.
    let tf = &j["tracker_frame"];
    assert!(tf["x"].as_f64().unwrap().abs() < 10.0);
}

#[test]
fn real_wam_grid_calibration_improves_the_random_poses() {
    let Some(d) = real_data() else { return };
    let j = &fixtures::real_fit(&d, "wam").result;
    // The WAM sags under gravity: a geometric model removes about a third of its error on
    // unseen poses (figures in README.md).
    let v = &j["errors"]["validation"];
    let after = v["after"]["mean_mm"].as_f64().unwrap();
    let before = v["before"]["mean_mm"].as_f64().unwrap();
    assert!(
        after < 0.75 * before,
        "WAM random poses: {before} -> {after} mm"
    );
    let c = &j["errors"]["calibration"];
    assert!(
        c["after"]["mean_mm"].as_f64().unwrap() < 0.5 * c["before"]["mean_mm"].as_f64().unwrap()
    );
}
