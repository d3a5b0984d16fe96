//! Real cells through the CLI: `simulate --all-targets` (several reflectors per pose) and
//! `--orientation-sigma-deg` (6-DoF rows) calibrate like any other data, and `evaluate` knows a
//! set measured from another tracker station (refused, or fitted with `--refit-frame`).

use crate::util::fixtures::three_reflectors;
use crate::util::*;
use std::path::Path;

/// 75 poses of a random KR 480 truth (seed `seed`), written to `cell.csv` in `dir` with its
/// truth file.
fn kr480_cell(dir: &Path, seed: &str) -> std::path::PathBuf {
    let data = dir.join("cell.csv");
    ok(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        "random",
        "--poses",
        "75",
        "--seed",
        seed,
        "--out",
        p(&data),
    ]);
    data
}

fn stats(result: &Path, set: &str) -> serde_json::Value {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(result).unwrap()).unwrap();
    v["errors"][set]["after"].clone()
}

#[test]
fn several_reflectors_and_six_dof_rows_simulate_and_calibrate() {
    let dir = Dir::new();
    let d = dir.path();
    let robot = three_reflectors(d);
    let data = d.join("cell.csv");
    ok(&[
        "simulate",
        "--robot",
        p(&robot),
        "--truth",
        "random",
        "--poses",
        "200",
        "--validation",
        "20",
        "--seed",
        "4",
        "--out",
        p(&data),
        "--all-targets",
    ]);
    let text = std::fs::read_to_string(&data).unwrap();
    let header = text.lines().next().unwrap();
    assert!(header.ends_with(",target"), "{header}");
    // 3 plane rows through target 1, then every pose through its three targets.
    assert_eq!(text.lines().count(), 1 + 3 + 3 * 220);
    for t in ["1", "2", "3"] {
        assert!(text.lines().skip(4).any(|l| l.ends_with(&format!(",{t}"))));
    }
    let result = d.join("cell.json");
    ok(&[
        "calibrate",
        "--robot",
        p(&robot),
        "--data",
        p(&data),
        "--out",
        p(&result),
    ]);
    let v = stats(&result, "validation");
    assert_eq!(v["n"], 60);
    // The default tracker noise is about 0.03 mm per axis at these distances.
    assert!(v["mean_mm"].as_f64().unwrap() < 0.08, "{v}");
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("cell.truth.json")).unwrap()).unwrap();
    let res: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&result).unwrap()).unwrap();
    // Every reflector's offset identified. The flange's own roll about its axis is a
    // combination of the offsets (it is fixed, and the offsets are expressed in a flange frame
    // that may turn by the truth's error): compare what no such turn changes, the distances
    // between the reflectors, each within 0.01 mm of the truth (200 poses: the offsets' stds are
    // about 0.002 mm).
    let value =
        |v: &serde_json::Value, name: &str| v["parameters"][name]["calibrated"].as_f64().unwrap();
    let point = |v: &serde_json::Value, t: usize| -> [f64; 3] {
        let offset = [[0.0, 0.0, 0.0], [180.0, 0.0, 0.0], [0.0, 160.0, 0.0]][t - 1];
        let prefix = if t == 1 {
            "tool".to_string()
        } else {
            format!("tool{t}")
        };
        ["x", "y", "z"]
            .iter()
            .enumerate()
            .map(|(i, a)| offset[i] + value(v, &format!("{prefix}_{a}")))
            .collect::<Vec<_>>()
            .try_into()
            .unwrap()
    };
    let dist = |v: &serde_json::Value, a: usize, b: usize| {
        let (pa, pb) = (point(v, a), point(v, b));
        ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2) + (pa[2] - pb[2]).powi(2)).sqrt()
    };
    for (a, b) in [(1, 2), (1, 3), (2, 3)] {
        let (got, want) = (dist(&res, a, b), dist(&truth, a, b));
        assert!(
            (got - want).abs() < 0.01,
            "targets {a}-{b}: {got} vs truth {want}"
        );
    }

    let six = d.join("six.csv");
    ok(&[
        "simulate",
        "--robot",
        p(&robot),
        "--truth",
        "random",
        "--poses",
        "60",
        "--validation",
        "20",
        "--seed",
        "4",
        "--out",
        p(&six),
        "--orientation-sigma-deg",
        "0.001",
    ]);
    let header = std::fs::read_to_string(&six).unwrap();
    assert!(header.lines().next().unwrap().ends_with(",a,b,c"));
    let result6 = d.join("six.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        p(&robot),
        "--data",
        p(&six),
        "--out",
        p(&result6),
    ]);
    assert!(o.stdout().contains("deg"), "{}", o.stdout());
    let res6: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&result6).unwrap()).unwrap();
    let after = &res6["orientation_errors"]["validation"]["after"];
    // 0.001 deg per axis of probe noise: the calibrated frames within a few thousandths.
    assert!(after["mean_deg"].as_f64().unwrap() < 0.01, "{after}");
    assert!(
        res6["prediction"]["mean_mm"].as_f64().is_some(),
        "{}",
        res6["prediction"]
    );
    // The report shows the orientation errors of 6-DoF data, and no such panel for points.
    ok(&["report", p(&result6), "--out", p(&d.join("six-report"))]);
    let html = std::fs::read_to_string(d.join("six-report/report.html")).unwrap();
    assert!(html.contains("<h2>Orientation errors</h2>"));
    assert!(html.contains("<td>Validation, calibrated model</td><td class=\"num\">20</td>"));
    ok(&["report", p(&result), "--out", p(&d.join("points-report"))]);
    let html = std::fs::read_to_string(d.join("points-report/report.html")).unwrap();
    assert!(!html.contains("Orientation errors"));

    // Misuse is a usage error naming the flag.
    let one = robocal(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        "random",
        "--poses",
        "10",
        "--seed",
        "1",
        "--out",
        p(&d.join("x.csv")),
        "--all-targets",
    ]);
    assert_eq!(one.code(), Some(2), "{}", one.text());
    assert!(one.stderr().contains("--all-targets"), "{}", one.stderr());
    assert!(!d.join("x.csv").exists());
}

#[test]
fn another_station_is_refused_or_fitted_with_refit_frame() {
    let dir = Dir::new();
    let d = dir.path();
    let data = kr480_cell(d, "5");
    let result = d.join("cell.json");
    ok(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&data),
        "--out",
        p(&result),
    ]);
    // The same truth measured after the tracker moved to another station.
    let moved = d.join("moved.csv");
    ok(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        p(&d.join("cell.truth.json")),
        "--poses",
        "40",
        "--seed",
        "9",
        "--no-plane",
        "--tracker",
        "1500,-3000,800,60,0,0",
        "--out",
        p(&moved),
    ]);
    let pp = d.join("per_point.csv");
    let refused = robocal(&[
        "evaluate",
        "--params",
        p(&result),
        "--data",
        p(&moved),
        "--per-point",
        p(&pp),
    ]);
    assert_eq!(refused.code(), Some(3), "{}", refused.text());
    assert!(
        refused.stderr().contains("another tracker station"),
        "{}",
        refused.stderr()
    );
    assert!(
        refused.stderr().contains("--refit-frame"),
        "{}",
        refused.stderr()
    );
    assert!(!pp.exists(), "nothing written on refusal");

    let o = ok(&[
        "evaluate",
        "--params",
        p(&result),
        "--data",
        p(&moved),
        "--refit-frame",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    let fitted = v["calibrated"]["mean_mm"].as_f64().unwrap();
    let calibration = stats(&result, "calibration")["mean_mm"].as_f64().unwrap();
    // In a frame of their own the points show the calibration's accuracy again.
    assert!(
        fitted < 2.0 * calibration + 0.02,
        "{fitted} vs {calibration}"
    );
    let f = v["refit_frame"]["calibrated"].as_array().unwrap();
    assert!((f[0].as_f64().unwrap() - 1500.0).abs() < 20.0, "{f:?}");
    assert!((f[3].as_f64().unwrap() - 60.0).abs() < 0.5, "{f:?}");

    // The calibration's own station still evaluates without a refit.
    ok(&["evaluate", "--params", p(&result), "--data", p(&data)]);

    // The same set as calibrate's validation: refused, or fitted with --validate-refit-frame.
    let again = d.join("again.json");
    let calibrate = |extra: &[&str]| {
        let mut args = vec![
            "calibrate",
            "--robot",
            "kuka-kr480-r3330",
            "--data",
            p(&data),
            "--validate",
            p(&moved),
            "--out",
            p(&again),
        ];
        args.extend_from_slice(extra);
        robocal(&args)
    };
    let refused = calibrate(&[]);
    assert_eq!(refused.code(), Some(3), "{}", refused.text());
    assert!(
        refused.stderr().contains("another tracker station"),
        "{}",
        refused.stderr()
    );
    assert!(
        refused.stderr().contains("--validate-refit-frame"),
        "{}",
        refused.stderr()
    );
    assert!(!again.exists(), "nothing written on refusal");
    calibrate(&["--validate-refit-frame"]).assert_ok();
    let validation = stats(&again, "validation")["mean_mm"].as_f64().unwrap();
    assert!(
        validation < 2.0 * calibration + 0.02,
        "{validation} vs {calibration}"
    );
}

/// `--tracker-sigma F,P` as the README writes it: weighted fitting whose standard deviations are
/// in physical units; `off` weighs every point the same; without the flag, these data (in the
/// tracker's frame, about 4 m from the base) are weighted by the typical tracker, here the same
/// model as given; a malformed value is a usage error.
#[test]
fn tracker_sigma_weights_the_fit() {
    let dir = Dir::new();
    let d = dir.path();
    let data = kr480_cell(d, "8");
    let plain = d.join("plain.json");
    let weighted = d.join("weighted.json");
    let default = d.join("default.json");
    ok(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&data),
        "--out",
        p(&plain),
        "--tracker-sigma",
        "off",
    ]);
    let o = ok(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&data),
        "--out",
        p(&default),
    ]);
    assert!(
        o.stdout().contains("points weighted by a typical tracker"),
        "{}",
        o.stdout()
    );
    ok(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&data),
        "--out",
        p(&weighted),
        "--tracker-sigma",
        "0.01,0.005",
    ]);
    let read = |f: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap()
    };
    let (a, b) = (read(&plain), read(&weighted));
    let (xa, xb) = (
        a["parameters"]["a2"]["calibrated"].as_f64().unwrap(),
        b["parameters"]["a2"]["calibrated"].as_f64().unwrap(),
    );
    assert!(xa != xb, "the weights change the estimate");
    assert!((xa - xb).abs() < 0.05, "{xa} vs {xb}");
    assert_eq!(a["settings"]["weighting"]["source"], "none");
    assert_eq!(b["settings"]["weighting"]["source"], "given");
    let c = read(&default);
    assert_eq!(c["settings"]["weighting"]["source"], "automatic");
    assert_eq!(c["settings"]["weighting"]["tracker"]["per_m_mm"], 0.005);
    let dist = c["settings"]["weighting"]["tracker_distance_mm"]
        .as_f64()
        .unwrap();
    assert!(dist > 3000.0 && dist < 5000.0, "{dist}");
    assert_eq!(
        c["parameters"]["a2"]["calibrated"], b["parameters"]["a2"]["calibrated"],
        "the automatic model is the given one"
    );
    for bad in ["1", "0.01,0.005,1", "-1,0", "x,1"] {
        let o = robocal(&[
            "calibrate",
            "--robot",
            "kuka-kr480-r3330",
            "--data",
            p(&data),
            "--out",
            p(&d.join("bad.json")),
            "--tracker-sigma",
            bad,
        ]);
        assert_eq!(o.code(), Some(2), "{bad}: {}", o.text());
        assert!(
            o.stderr().contains("--tracker-sigma"),
            "{bad}: {}",
            o.stderr()
        );
    }
    assert!(!d.join("bad.json").exists());
}
