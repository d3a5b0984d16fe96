//! A constraint calibration (issue 31) is a normal result file that every reader takes:
//! `evaluate` of held-out constraint rows (their residuals) and of tracker points (registered to
//! the calibration, which is up to the base pose), `compensate` (in the calibrated base frame,
//! said to be the nominal one), `export` and `report` (the features and what the data cannot
//! see), `fk`. `simulate --constraint` writes the truth file like the other modes.

use crate::util::*;

const KR: &str = "kuka-kr480-r3330";

/// Fixed-point data of a random true robot split into calibration (the first 15 rows of each
/// point) and held-out rows (the other 5), the distances, the calibration result and the
/// truth file.
struct Calibrated {
    dir: Dir,
    held_out: std::path::PathBuf,
    result: std::path::PathBuf,
    truth: std::path::PathBuf,
}

fn calibrated() -> Calibrated {
    let dir = Dir::new();
    let all = dir.join("all.csv");
    let dist = dir.join("d.csv");
    let o = ok(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        "random",
        "--constraint",
        "point",
        "--noise-mm",
        "0.01",
        "--out",
        p(&all),
        "--distances-out",
        p(&dist),
    ]);
    let truth = dir.join("all.truth.json");
    assert!(o.stdout().contains("all.truth.json"), "{}", o.stdout());
    let text = std::fs::read_to_string(&all).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let (mut cal, mut held) = (format!("{header}\n"), format!("{header}\n"));
    let mut seen = std::collections::HashMap::new();
    for l in lines {
        let label = l.rsplit(',').next().unwrap().to_owned();
        let k = seen.entry(label).or_insert(0);
        *k += 1;
        let to = if *k <= 15 { &mut cal } else { &mut held };
        to.push_str(l);
        to.push('\n');
    }
    let data = dir.write("cal.csv", cal);
    let held_out = dir.write("held.csv", held);
    let result = dir.join("cal.json");
    ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--distances",
        p(&dist),
        "--out",
        p(&result),
    ]);
    Calibrated {
        dir,
        held_out,
        result,
        truth,
    }
}

#[test]
fn the_truth_file_holds_the_true_robot_and_features() {
    let c = calibrated();
    let t = read_json(&c.truth);
    assert_eq!(t["nominal"], KR);
    assert!(t["parameters"]["a2"]["calibrated"].is_number(), "{t}");
    let f = t["constraint"]["features"].as_array().unwrap();
    assert_eq!(f.len(), 4);
    assert_eq!(f[0]["kind"], "point");
    assert_eq!(f[0]["position_mm"].as_array().unwrap().len(), 3);
    // The calibration's features match the true ones up to the base pose: their distances
    // agree (the 6 distances were given; the check is that the truth file holds the same
    // features the data were made from).
    let r = read_json(&c.result);
    let pos = |v: &serde_json::Value| -> [f64; 3] {
        let a = v["position_mm"].as_array().unwrap();
        [0, 1, 2].map(|i| a[i].as_f64().unwrap())
    };
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let cf = r["constraint"]["features"].as_array().unwrap();
    for i in 0..4 {
        for j in i + 1..4 {
            let d_true = dist(pos(&f[i]), pos(&f[j]));
            let d_cal = dist(pos(&cf[i]), pos(&cf[j]));
            assert!((d_true - d_cal).abs() < 0.05, "{i}-{j}: {d_true} {d_cal}");
        }
    }
}

#[test]
fn evaluate_reports_held_out_constraint_residuals() {
    let c = calibrated();
    let o = ok(&[
        "evaluate",
        "--params",
        p(&c.result),
        "--data",
        p(&c.held_out),
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    assert_eq!(j["reference"], "constraint");
    assert_eq!(j["n"], 20);
    let cal = j["calibrated"]["mean_mm"].as_f64().unwrap();
    let nom = j["nominal"]["mean_mm"].as_f64().unwrap();
    assert!(
        cal < 0.05 && nom > 10.0 * cal,
        "nominal {nom}, calibrated {cal}"
    );
    let o = ok(&[
        "evaluate",
        "--params",
        p(&c.result),
        "--data",
        p(&c.held_out),
    ]);
    assert!(o.stdout().contains("held-out"), "{}", o.stdout());
    assert!(o.stdout().contains("up to the base pose"), "{}", o.stdout());
}

#[test]
fn evaluate_registers_tracker_points_to_a_constraint_calibration() {
    let c = calibrated();
    let trk = c.dir.join("trk.csv");
    ok(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        p(&c.truth),
        "--poses",
        "40",
        "--noise-mm",
        "0.01",
        "--seed",
        "7",
        "--out",
        p(&trk),
    ]);
    let o = ok(&[
        "evaluate",
        "--params",
        p(&c.result),
        "--data",
        p(&trk),
        "--json",
    ]);
    assert!(
        o.stderr().contains("up to the base pose") && o.stderr().contains("registered"),
        "{}",
        o.stderr()
    );
    let j: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    assert!(j["refit_frame"].is_object(), "{j}");
    let cal = j["calibrated"]["mean_mm"].as_f64().unwrap();
    let nom = j["nominal"]["mean_mm"].as_f64().unwrap();
    assert!(
        cal < 0.1 && nom > 10.0 * cal,
        "nominal {nom}, calibrated {cal}"
    );
}

#[test]
fn every_reader_takes_a_constraint_result() {
    let c = calibrated();
    // compensate: in the calibrated base frame, said to be the nominal one.
    let comp = c.dir.join("comp.csv");
    let o = ok(&[
        "compensate",
        "--params",
        p(&c.result),
        "--joints",
        p(&c.held_out),
        "--position-only",
        "--out",
        p(&comp),
    ]);
    assert!(
        o.stderr().contains("up to the base pose") && o.stderr().contains("nominal"),
        "{}",
        o.stderr()
    );
    assert_eq!(read_csv(&comp).1.len(), 20);
    // export: the features and what the data cannot see, as notes.
    for format in ["toml", "urdf"] {
        let out = c.dir.join(format!("robot.{format}"));
        ok(&["export", p(&c.result), "--format", format, "--out", p(&out)]);
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(
            text.contains("Feature point:P1")
                && text.contains("Not identifiable")
                && text.contains("Scale from 6 known distances"),
            "{text}"
        );
    }
    // The exported robot file is a robot robocal reads.
    let toml = c.dir.join("robot.toml");
    ok(&["fk", "--robot", p(&toml), "--joints", "0,-90,90,0,30,0"]);
    ok(&[
        "fk",
        "--params",
        p(&c.result),
        "--joints",
        "0,-90,90,0,30,0",
    ]);
    // report: constraint residuals, the features, the scale, what is unseen.
    let rep = c.dir.join("rep");
    let o = ok(&["report", p(&c.result), "--out", p(&rep)]);
    assert!(
        o.stdout().contains("constraint residuals"),
        "{}",
        o.stdout()
    );
    let html = std::fs::read_to_string(rep.join("report.html")).unwrap();
    for want in [
        "Feature point:P1",
        "Not identifiable",
        "up to the base pose",
        "6 known distances",
    ] {
        assert!(html.contains(want), "report lacks {want}");
    }
}

#[test]
fn constraint_rows_against_a_tracker_calibration_are_refused() {
    let c = calibrated();
    let trk = c.dir.join("trk.csv");
    ok(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        p(&c.truth),
        "--poses",
        "30",
        "--noise-mm",
        "0.01",
        "--out",
        p(&trk),
    ]);
    let tcal = c.dir.join("tcal.json");
    ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&trk),
        "--model",
        "geometric",
        "--out",
        p(&tcal),
    ]);
    let o = robocal(&["evaluate", "--params", p(&tcal), "--data", p(&c.held_out)]);
    o.assert_code(3);
    assert!(o.stderr().contains("without any"), "{}", o.stderr());
}
