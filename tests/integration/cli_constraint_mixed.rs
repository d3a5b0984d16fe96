//! Constraint calibration (issue 31) through the CLI, continued: mixed data (constraint rows
//! and tracker rows in one file: the tracker rows give the scale and register the base, so no
//! distance is needed and the result's tracker frame is used by `evaluate` as for tracker data),
//! and the gate (known distances in the wrong unit scale the whole robot: exit 6, nothing
//! written).

use crate::util::*;

const KR: &str = "kuka-kr480-r3330";

/// Fixed points (no distances file) of a random true robot and its truth file.
fn points(dir: &Dir, extra: &[&str]) -> (std::path::PathBuf, std::path::PathBuf) {
    let data = dir.join("p.csv");
    let mut args = vec![
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
        p(&data),
    ];
    args.extend(extra);
    ok(&args);
    (data, dir.join("p.truth.json"))
}

/// Tracker data of the truth in `truth` (its station).
fn tracker(
    dir: &Dir,
    truth: &std::path::Path,
    name: &str,
    poses: &str,
    seed: &str,
) -> std::path::PathBuf {
    let out = dir.join(name);
    ok(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        p(truth),
        "--poses",
        poses,
        "--noise-mm",
        "0.01",
        "--no-plane",
        "--seed",
        seed,
        "--out",
        p(&out),
    ]);
    out
}

#[test]
fn mixed_data_calibrate_without_distances_and_register_the_base() {
    let dir = Dir::new();
    let (data, truth) = points(&dir, &[]);
    let trk = tracker(&dir, &truth, "t.csv", "20", "3");
    // One file: the constraint rows with empty x,y,z, the tracker rows with an empty constraint.
    let (ch, crows) = read_csv(&data);
    let (th, trows) = read_csv(&trk);
    let qs: Vec<usize> = (1..=6).map(|i| col(&th, &format!("q{i}"))).collect();
    let xyz = [col(&th, "x"), col(&th, "y"), col(&th, "z")];
    let mut text = format!("{},x,y,z\n", ch.join(","));
    for r in &crows {
        text.push_str(&format!("{},,,\n", r.join(",")));
    }
    for r in &trows {
        let q: Vec<&str> = qs.iter().map(|&k| r[k].as_str()).collect();
        let m: Vec<&str> = xyz.iter().map(|&k| r[k].as_str()).collect();
        text.push_str(&format!("{},,{}\n", q.join(","), m.join(",")));
    }
    let mixed = dir.write("mixed.csv", text);
    let out = dir.join("cal.json");
    // Without the tracker rows the scale is refused; with them it is not.
    robocal(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--out",
        p(&out),
    ])
    .assert_code(5);
    let o = ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&mixed),
        "--out",
        p(&out),
    ]);
    let s = o.stdout();
    assert!(
        s.contains("20 tracker row(s)") && s.contains("tracker frame registered"),
        "{s}"
    );
    assert!(
        !o.stderr().contains("scale is not determined"),
        "{}",
        o.stderr()
    );
    let r = read_json(&out);
    let c = &r["constraint"];
    assert_eq!(c["base_pose_known"], true, "{c}");
    assert_eq!(c["tracker_rows"], 20);
    assert!(
        c["scale"]["from"]
            .as_str()
            .unwrap()
            .contains("20 tracker row"),
        "{c}"
    );
    assert!(c["tracker_residual_rms_mm"].as_f64().unwrap() < 0.05, "{c}");
    // Tracker points from the same station: the result's tracker frame is used as it is.
    let val = tracker(&dir, &truth, "v.csv", "40", "9");
    let o = ok(&["evaluate", "--params", p(&out), "--data", p(&val), "--json"]);
    assert!(!o.stderr().contains("registered"), "{}", o.stderr());
    let j: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    assert!(j.get("refit_frame").is_none(), "{j}");
    let cal = j["calibrated"]["mean_mm"].as_f64().unwrap();
    let nom = j["nominal"]["mean_mm"].as_f64().unwrap();
    assert!(
        cal < 0.1 && nom > 10.0 * cal,
        "nominal {nom}, calibrated {cal}"
    );
}

#[test]
fn distances_in_the_wrong_unit_fail_the_gate() {
    let dir = Dir::new();
    let dist = dir.join("d.csv");
    let (data, _) = points(&dir, &["--distances-out", p(&dist)]);
    let (h, rows) = read_csv(&dist);
    let k = col(&h, "distance_mm");
    let mut inches = format!("{}\n", h.join(","));
    for r in &rows {
        let mut r = r.clone();
        r[k] = format!("{}", num(&r[k]) / 25.4);
        inches.push_str(&format!("{}\n", r.join(",")));
    }
    let bad = dir.write("inches.csv", inches);
    let out = dir.join("cal.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--distances",
        p(&bad),
        "--out",
        p(&out),
    ]);
    o.assert_code(6);
    let e = o.stderr();
    assert!(e.contains("implausible") && e.contains("scaled"), "{e}");
    assert!(!out.exists());
}
