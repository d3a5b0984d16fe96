//! `robocal plan`: planned poses feed `simulate --joints` and `calibrate`, beat random ones on
//! the printed indices, respect the flags' rules, and bad input writes nothing.

use crate::util::*;

#[test]
fn planned_poses_simulate_and_calibrate_with_a_prediction() {
    let d = Dir::new();
    let poses = d.join("poses.csv");
    let o = ok(&[
        "plan",
        "--robot",
        "kuka-kr480-r3330",
        "--poses",
        "40",
        "--candidates",
        "1500",
        "--seed",
        "3",
        "--out",
        p(&poses),
    ]);
    let out = o.stdout();
    assert!(out.contains("observability index O1"), "{out}");
    assert!(out.contains("alpha2"), "{out}");
    let (h, rows) = read_csv(&poses);
    assert_eq!(h, ["q1", "q2", "q3", "q4", "q5", "q6"]);
    assert_eq!(rows.len(), 40);
    // The same seed gives the same file.
    let again = d.join("again.csv");
    ok(&[
        "plan",
        "--robot",
        "kuka-kr480-r3330",
        "--poses",
        "40",
        "--candidates",
        "1500",
        "--seed",
        "3",
        "--out",
        p(&again),
    ]);
    assert_eq!(
        std::fs::read(&poses).unwrap(),
        std::fs::read(&again).unwrap()
    );
    // Measure them, calibrate with validation: the result predicts its accuracy (for poses
    // spread like the calibration poses; the validation poses are random, hence the margin).
    let meas = d.join("meas.csv");
    ok(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        "random",
        "--joints",
        p(&poses),
        "--out",
        p(&meas),
    ]);
    let val = d.join("val.csv");
    ok(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        p(&meas.with_extension("truth.json")),
        "--poses",
        "60",
        "--no-plane",
        "--seed",
        "9",
        "--out",
        p(&val),
    ]);
    let res = d.join("r.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&meas),
        "--validate",
        p(&val),
        "--out",
        p(&res),
    ]);
    assert!(
        o.stdout().contains("Predicted at new poses"),
        "{}",
        o.stdout()
    );
    let j = read_json(&res);
    assert_eq!(j["settings"]["objective"], "adaptive");
    let pred = j["prediction"]["mean_mm"].as_f64().unwrap();
    let meas_mean = j["errors"]["validation"]["after"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(
        (meas_mean / pred - 1.0).abs() < 0.3,
        "predicted {pred}, measured {meas_mean}"
    );
    assert_eq!(j["prediction"]["map"].as_array().unwrap().len(), 300);
}

#[test]
fn bad_plan_flags_are_refused_and_write_nothing() {
    let d = Dir::new();
    let out = d.join("poses.csv");
    let run = |extra: &[&str]| {
        let mut a = vec!["plan", "--robot", "kuka-kr480-r3330", "--out", p(&out)];
        a.extend_from_slice(extra);
        robocal(&a)
    };
    run(&["--poses", "0"]).assert_code(2);
    run(&["--poses", "50", "--candidates", "10"]).assert_code(2);
    // A range that is none: a setting outside its plausible range, checked by the library.
    run(&["--poses", "30", "--range-mm", "5,1"]).assert_code(3);
    run(&["--poses", "30", "--range-mm", "abc"]).assert_code(2);
    run(&["--poses", "30", "--tracker", "1,2,3"]).assert_code(2);
    // Fewer poses than identifiable parameters: a setting the library rejects.
    let o = run(&["--poses", "5", "--candidates", "200"]);
    assert!(!o.success());
    assert!(o.text().contains("--poses"), "{}", o.text());
    // A missing --include file is an I/O error.
    run(&["--poses", "30", "--include", p(&d.join("none.csv"))]).assert_code(4);
    assert!(!out.exists());
}

#[test]
fn the_tracker_range_limits_the_poses() {
    let d = Dir::new();
    let poses = d.join("poses.csv");
    ok(&[
        "plan",
        "--robot",
        "kuka-kr480-r3330",
        "--poses",
        "30",
        "--candidates",
        "600",
        "--tracker",
        "3112.8,-2179.6,1200,125,0,0",
        "--range-mm",
        "2000,4000",
        "--out",
        p(&poses),
    ]);
    let robot = robocal_core::preset("kuka-kr480-r3330").unwrap();
    let origin = nalgebra::Vector3::new(3112.8, -2179.6, 1200.0);
    let (_, rows) = read_csv(&poses);
    for r in rows {
        let q: Vec<f64> = r.iter().map(|v| num(v).to_radians()).collect();
        let dist = (robot.tool_position(&q) - origin).norm();
        assert!((2000.0 - 1e-3..=4000.0 + 1e-3).contains(&dist), "{dist}");
    }
}

/// On a terminal `plan` shows its progress: the stages (candidates, choosing poses, exchanging
/// poses) with their counts, drawn on stderr. Run under a pseudo-terminal by util-linux's
/// `script`; a tenth of `--poses 2000 --candidates 200000` (whose time the README gives), so
/// that each stage lasts long enough to be drawn. Skipped, saying so, without `script`.
#[test]
fn plan_shows_its_progress_on_a_terminal() {
    let has_script = std::process::Command::new("script")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_script {
        eprintln!("skipped: util-linux `script` (a pseudo-terminal) is not installed");
        return;
    }
    let d = Dir::new();
    let out = d.join("poses.csv");
    let cmd = format!(
        "{} plan --robot {KUKA} --poses 200 --candidates 20000 --seed 3 --out {}",
        env!("CARGO_BIN_EXE_robocal"),
        p(&out)
    );
    let start = std::time::Instant::now();
    let o = std::process::Command::new("script")
        .args(["-qefc", &cmd, "/dev/null"])
        .env("TERM", "xterm")
        .env_remove("NO_COLOR")
        .output()
        .unwrap();
    let took = start.elapsed();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    eprintln!("plan --poses 200 --candidates 20000 on a terminal: {took:.1?}");
    for stage in ["choosing poses", "exchanging poses"] {
        assert!(text.contains(stage), "no `{stage}` drawn:\n{text}");
    }
    // Counts of the 200 poses chosen, below and at the total.
    assert!(text.contains("/200"), "{text}");
    assert!(text.contains("200 poses written"), "{text}");
    assert!(out.is_file());
}
