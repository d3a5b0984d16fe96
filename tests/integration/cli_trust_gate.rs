//! The plausibility gate end to end: data in metres or inches, a mirrored tracker frame, joints
//! in radians, a missing J2/J3 coupling and the wrong robot each exit with code 6, naming the
//! check and the likely cause, writing nothing and leaving the inputs as they were;
//! `--accept-implausible` writes a result marked implausible, which `compensate` refuses and the
//! other commands warn about; nothing to identify and rank tolerances beyond double precision are
//! clear errors; an ill-conditioned identification writes no fake standard deviations.

use crate::util::fixtures::{gate_data, real_fit};
use crate::util::*;
use serde_json::Value;
use std::path::Path;

/// A copy of a measurement CSV with every row's joints (degrees) and position changed.
fn transformed(src: &Path, dst: &Path, q_of: &dyn Fn(&mut [f64]), m_of: &dyn Fn(&mut [f64; 3])) {
    let text = std::fs::read_to_string(src).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let qcols: Vec<usize> = (1..=6).map(|i| col(&format!("q{i}"))).collect();
    let mcols = [col("x"), col("y"), col("z")];
    let mut out = format!("{}\n", header.join(","));
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
        let mut q: Vec<f64> = qcols.iter().map(|&c| cells[c].parse().unwrap()).collect();
        let mut m = mcols.map(|c| cells[c].parse::<f64>().unwrap());
        q_of(&mut q);
        m_of(&mut m);
        for (&c, v) in qcols.iter().zip(&q) {
            cells[c] = v.to_string();
        }
        for (&c, v) in mcols.iter().zip(&m) {
            cells[c] = v.to_string();
        }
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    std::fs::write(dst, out).unwrap();
}

fn same_q(_: &mut [f64]) {}
fn same_m(_: &mut [f64; 3]) {}

/// Runs `calibrate` on a bad data set and checks: exit code 6, the failed check and the cause
/// named, nothing written (an earlier result stays), the input unchanged.
fn expect_implausible(robot: &str, data: &Path, check: &str, cause: &str) {
    let dir = data.parent().unwrap();
    let out = dir.join("result.json");
    std::fs::write(&out, "earlier result").unwrap();
    let before = std::fs::read(data).unwrap();
    let args = [
        "calibrate",
        "--robot",
        robot,
        "--data",
        p(data),
        "--out",
        p(&out),
    ];
    // Data of the wrong robot, or joints that need a coupling, also lie outside the model's joint
    // limits: the reader refuses them first (exit 3). With the limits declared nominal they reach
    // the fit, and the gate must stop them.
    let o = robocal(&args);
    if o.code() == Some(3) {
        assert!(
            o.stderr().contains("outside the joint limits"),
            "{}",
            o.stderr()
        );
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier result");
    }
    let mut args = args.to_vec();
    args.push("--nominal-limits");
    let o = robocal(&args);
    let err = o.stderr();
    o.assert_code(6);
    assert!(
        err.contains("implausible fit") && err.contains("nothing written"),
        "{err}"
    );
    assert!(
        err.contains(&format!("{check}:")),
        "{check} not named: {err}"
    );
    assert!(
        err.contains("likely cause") && err.contains(cause),
        "cause `{cause}`: {err}"
    );
    assert!(err.contains("--accept-implausible"), "{err}");
    assert!(o.stdout().contains("IMPLAUSIBLE"), "{}", o.stdout());
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier result");
    assert_eq!(std::fs::read(data).unwrap(), before, "input changed");
    let others: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".tmp") || n.starts_with('.'))
        .collect();
    assert!(others.is_empty(), "left behind: {others:?}");
}

type QFn = fn(&mut [f64]);
type MFn = fn(&mut [f64; 3]);

#[test]
fn units_mirror_radians_and_coupling_exit_6_with_the_cause() {
    let f = gate_data();
    let cases: [(&str, QFn, MFn, &str, &str); 5] = [
        (
            "metres",
            same_q,
            |m| m.iter_mut().for_each(|v| *v /= 1000.0),
            "units",
            "metres",
        ),
        (
            "inches",
            same_q,
            |m| m.iter_mut().for_each(|v| *v /= 25.4),
            "units",
            "inches",
        ),
        (
            "mirrored",
            same_q,
            |m| m[1] = -m[1],
            "handedness",
            "mirrored",
        ),
        (
            "radians",
            |q| q.iter_mut().for_each(|v| *v = v.to_radians()),
            same_m,
            "nominal_error",
            "radians",
        ),
        (
            // A FANUC-style J3 given where the model needs q3 = -(J2 + J3).
            "coupling",
            |q| q[2] = -q[2] - q[1],
            same_m,
            "nominal_error",
            "joint 3 is given without its coupling to joint 2",
        ),
    ];
    for (name, q_of, m_of, check, cause) in cases {
        let dir = Dir::new();
        let data = dir.join(format!("{name}.csv"));
        transformed(&f.cell, &data, &q_of, &m_of);
        expect_implausible(KUKA, &data, check, cause);
    }
}

#[test]
fn the_kuka_model_on_ur5_data_is_the_wrong_robot() {
    let f = gate_data();
    let dir = Dir::new();
    let data = dir.join("ur5.csv");
    std::fs::copy(&f.ur5, &data).unwrap();
    expect_implausible(
        KUKA,
        &data,
        "nominal_error",
        "robot description does not match",
    );
}

#[test]
fn the_kuka_model_on_real_ur5_data_exits_6() {
    let Some(d) = real_data() else { return };
    let dir = Dir::new();
    let data = dir.join("grid.csv");
    std::fs::copy(d.join("jacobi_ur5_grid.csv"), &data).unwrap();
    expect_implausible(
        KUKA,
        &data,
        "nominal_error",
        "robot description does not match",
    );
}

#[test]
fn real_ur5_and_wam_pass_the_gate() {
    let Some(d) = real_data() else { return };
    // The calibrations cli_calibrate's real-data tests check too, made once.
    for robot in ["ur5", "wam"] {
        let fit = real_fit(&d, robot);
        assert!(fit.stdout.contains("plausibility: all 12 checks passed"));
        let j = &fit.result;
        assert_eq!(j["status"], "calibrated");
        assert_eq!(j["plausibility"]["passed"], true);
        // With margin: Table II under a quarter of its limit.
        let nominal = j["plausibility"]["checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == "nominal_error")
            .unwrap()
            .clone();
        let (m, l) = (
            nominal["measured"].as_f64().unwrap(),
            nominal["limit"].as_f64().unwrap(),
        );
        assert!(m < 0.25 * l, "{robot}: {nominal}");
    }
}

#[test]
fn good_data_pass_and_the_result_records_every_check() {
    let f = gate_data();
    let dir = Dir::new();
    let out = dir.join("r.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&f.cell),
        "--validate",
        p(&f.validation),
        "--out",
        p(&out),
    ]);
    o.assert_ok();
    assert!(
        o.stdout()
            .contains("checks passed (convergence, units, handedness"),
        "{}",
        o.stdout()
    );
    let j = read_json(&out);
    assert_eq!(j["status"], "calibrated");
    let p = &j["plausibility"];
    assert_eq!(p["passed"], true);
    let names: Vec<&str> = p["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "convergence",
            "units",
            "handedness",
            "nominal_error",
            "validation_nominal_error",
            "length_moves",
            "angle_moves",
            "parameter_ranges",
            "improvement",
            "discarded_points",
            "residuals",
            "weight_share"
        ]
    );
    for c in p["checks"].as_array().unwrap() {
        assert_eq!(c["passed"], true, "{c}");
        assert!(c["measured"].is_number() && c["limit"].is_number(), "{c}");
        assert!(c.get("cause").is_none(), "{c}");
    }
    assert!(p.get("likely_causes").is_none());
}

#[test]
fn accept_implausible_writes_a_marked_result_that_compensate_refuses() {
    let f = gate_data();
    let dir = Dir::new();
    let data = dir.join("metres.csv");
    transformed(&f.cell, &data, &same_q, &|m| {
        m.iter_mut().for_each(|v| *v /= 1000.0)
    });
    let out = dir.join("r.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&out),
        "--accept-implausible",
    ]);
    let err = o.stderr();
    o.assert_ok();
    assert!(
        err.contains("WARNING: IMPLAUSIBLE FIT WRITTEN") && err.contains("metres"),
        "{err}"
    );
    let j = read_json(&out);
    assert_eq!(j["status"], "implausible");
    assert!(j["implausible_reason"].as_str().unwrap().contains("units:"));
    assert_eq!(j["plausibility"]["passed"], false);

    // compensate refuses it (exit 6, nothing written) ...
    let commanded = dir.join("commanded.csv");
    let comp = |extra: &[&str]| {
        let mut args = vec![
            "compensate",
            "--robot",
            KUKA,
            "--params",
            p(&out),
            "--joints",
            p(&data),
            "--out",
            p(&commanded),
        ];
        args.extend_from_slice(extra);
        robocal(&args)
    };
    let o = comp(&[]);
    let err = o.stderr();
    o.assert_code(6);
    assert!(
        err.contains("IMPLAUSIBLE")
            && err.contains("units:")
            && err.contains("--accept-implausible"),
        "{err}"
    );
    assert!(!commanded.exists());
    // ... unless accepted there too.
    let o = comp(&["--accept-implausible"]);
    o.assert_ok();
    assert!(
        o.stderr().contains("FAILED the plausibility gate"),
        "{}",
        o.stderr()
    );
    assert!(commanded.exists());

    // evaluate, fk, robot show and report use it with a warning.
    let warned = |o: &Outcome| {
        o.assert_ok();
        assert!(
            o.stderr()
                .contains("is an IMPLAUSIBLE result, not a calibration"),
            "{}",
            o.stderr()
        );
    };
    warned(&robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&out),
        "--data",
        p(&data),
    ]));
    warned(&robocal(&[
        "fk",
        "--robot",
        KUKA,
        "--params",
        p(&out),
        "--joints",
        "0,-90,90,0,0,0",
    ]));
    let o = robocal(&["robot", "show", KUKA, "--params", p(&out)]);
    warned(&o);
    assert!(
        o.stdout().contains("IMPLAUSIBLE parameters"),
        "{}",
        o.stdout()
    );
    warned(&robocal(&[
        "report",
        p(&out),
        "--out",
        p(&dir.join("report")),
    ]));
}

fn all_params(but_tool_orientation: bool) -> String {
    let mut v: Vec<String> = ["alpha", "d", "a", "phi"]
        .iter()
        .flat_map(|p| (1..=6).map(move |i| format!("{p}{i}")))
        .collect();
    v.extend("xyzabc".chars().map(|c| format!("base_{c}")));
    let tool = if but_tool_orientation {
        "xyz"
    } else {
        "xyzabc"
    };
    v.extend(tool.chars().map(|c| format!("tool_{c}")));
    v.join(",")
}

#[test]
fn nothing_to_identify_and_tolerances_beyond_double_precision_are_clear_errors() {
    let f = gate_data();
    let dir = Dir::new();
    let out = dir.join("r.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "calibrate",
            "--robot",
            KUKA,
            "--data",
            p(&f.cell),
            "--out",
            p(&out),
        ];
        args.extend_from_slice(extra);
        robocal(&args)
    };
    let all = all_params(false);
    let o = run(&["--fix", &all]);
    o.assert_code(2);
    assert!(
        o.stderr().contains("--fix: names every parameter"),
        "{}",
        o.stderr()
    );
    let effective = all_params(true);
    let o = run(&["--fix", &effective]);
    o.assert_code(5);
    let err = o.stderr();
    assert!(
        err.contains("nothing to identify") && err.contains("tool_a, tool_b, tool_c"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    for tol in ["1e-15", "1e-17", "0", "1"] {
        let o = run(&["--rank-tol", tol]);
        o.assert_code(2);
        assert!(
            o.stderr().contains("--rank-tol") && o.stderr().contains("double precision"),
            "{}",
            o.stderr()
        );
    }
    assert!(!out.exists());
}

#[test]
fn an_ill_conditioned_fit_writes_null_standard_deviations_with_the_reason() {
    // The KR 480 with axes 2 and 3 tilted by 0.01 degrees: at the smallest rank tolerance, d3 is
    // identified beside d2 with a condition number beyond double precision.
    let dir = Dir::new();
    let text = std::fs::read_to_string(root().join("examples/kr480-r3330.toml")).unwrap();
    let tilted = text.replacen(
        "alpha = 0\nd = 0\na = 1300",
        "alpha = 0.01\nd = 0\na = 1300",
        1,
    );
    assert_ne!(tilted, text);
    let robot = dir.write("tilted.toml", tilted);
    let data = dir.join("exact.csv");
    let o = robocal(&[
        "simulate",
        "--robot",
        p(&robot),
        "--truth",
        p(&robot),
        "--poses",
        "75",
        "--seed",
        "5",
        "--noise-mm",
        "0",
        "--noise-per-m",
        "0",
        "--out",
        p(&data),
    ]);
    o.assert_ok();
    let out = dir.join("r.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        p(&robot),
        "--data",
        p(&data),
        "--out",
        p(&out),
        "--rank-tol",
        "1e-10",
    ]);
    let err = o.stderr();
    o.assert_ok();
    assert!(
        err.contains("standard deviations unavailable") && err.contains("condition number"),
        "{err}"
    );
    assert!(o.stdout().contains("n/a"), "{}", o.stdout());
    let j = read_json(&out);
    let id = &j["identifiability"];
    assert!(id["condition_number"].as_f64().unwrap() > 1e7, "{id}");
    assert_eq!(id["ill_conditioned"], true);
    let d3 = &j["parameters"]["d3"];
    assert_eq!(d3["fixed"], false);
    assert!(d3.get("std").is_none(), "{d3}");
    assert!(d3["reason"]
        .as_str()
        .unwrap()
        .contains("standard deviation unavailable"));
    let u = &j["uncertainty"];
    let stds = u["std"].as_object().unwrap();
    assert!(!stds.is_empty() && stds.values().all(Value::is_null), "{u}");
    assert!(u["std_unavailable"]
        .as_str()
        .unwrap()
        .contains("condition number"));
    // At the default tolerance d3 is fixed and every standard deviation is a number.
    let o = robocal(&[
        "calibrate",
        "--robot",
        p(&robot),
        "--data",
        p(&data),
        "--out",
        p(&out),
    ]);
    o.assert_ok();
    let j = read_json(&out);
    assert_eq!(j["parameters"]["d3"]["fixed"], true);
    assert!(j["uncertainty"]["std"]
        .as_object()
        .unwrap()
        .values()
        .all(Value::is_number));
    assert_eq!(j["identifiability"]["ill_conditioned"], false);
}
