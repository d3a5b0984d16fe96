//! A result is self-contained: it embeds its nominal robot, so `fk --params`, `evaluate`,
//! `compensate` and `report` work from any directory with the result file alone; a `--robot`
//! given beside it must agree with the embedded one; results without one still need `--robot`.

use crate::util::library::*;
use crate::util::{command, p, read_csv, KUKA};
use robocal_core::io::CalibrationResult;
use robocal_core::{load_robot_file, preset, Robot};
use std::path::{Path, PathBuf};
use std::process::Output;

fn examples(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// Runs robocal in `cwd`.
fn robocal_in(cwd: &Path, args: &[&str]) -> Output {
    command()
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run robocal")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", stderr(o));
    stdout(o)
}

/// A real `calibrate` run of `robot_arg` (a preset or a robot file) on simulated data in `work`,
/// its result copied alone into a fresh directory `alone` (returned with the result's name).
fn calibrated_alone(work: &Path, robot_arg: &str, truth: &str) -> (tempfile::TempDir, PathBuf) {
    let data = work.join("cal.csv");
    ok(&robocal_in(
        work,
        &[
            "simulate", "--robot", robot_arg, "--truth", truth, "--poses", "60", "--seed", "4",
            "--out", "cal.csv",
        ],
    ));
    assert!(data.is_file());
    ok(&robocal_in(
        work,
        &[
            "calibrate",
            "--robot",
            robot_arg,
            "--data",
            "cal.csv",
            "--out",
            "res.json",
        ],
    ));
    let alone = tempfile::tempdir().unwrap();
    std::fs::copy(work.join("res.json"), alone.path().join("res.json")).unwrap();
    (alone, PathBuf::from("res.json"))
}

fn fk_json(cwd: &Path, extra: &[&str], joints: &str) -> serde_json::Value {
    let mut args = vec!["fk", "--joints", joints, "--json"];
    args.extend_from_slice(extra);
    serde_json::from_str(&ok(&robocal_in(cwd, &args))).unwrap()
}

/// The embedded robot is the nominal robot itself, bit for bit, for a preset and for the
/// 7-joint track robot (prismatic joint, controller map).
#[test]
fn the_result_embeds_the_nominal_robot() {
    for (arg, nominal) in [
        (KUKA.to_owned(), preset(KUKA).unwrap()),
        (
            p(&examples("kr480-track.toml")).to_owned(),
            load_robot_file(&examples("kr480-track.toml")).unwrap(),
        ),
    ] {
        let work = tempfile::tempdir().unwrap();
        let (alone, res) = calibrated_alone(work.path(), &arg, &arg);
        let path = alone.path().join(&res);
        let r = CalibrationResult::read(&path).unwrap();
        let embedded: Robot = r.robot.nominal_robot(&path, None).unwrap().unwrap();
        assert_eq!(embedded, nominal, "{arg}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let robot = &json["robot"];
        assert_eq!(robot["joints"].as_array().unwrap().len(), nominal.dof());
        assert_eq!(robot["dof"], nominal.dof());
        assert!(robot["controller"]["sign"].is_array(), "{robot}");
    }
}

/// From a directory that holds only the result: fk, evaluate, compensate and report need no
/// --robot, and give what they give with it.
#[test]
fn commands_work_from_another_directory_with_the_result_alone() {
    let work = tempfile::tempdir().unwrap();
    let track = examples("kr480-track.toml");
    let (alone, res) = calibrated_alone(work.path(), p(&track), p(&track));
    let d = alone.path();
    let res = p(&res);
    let q = "1200,10,-30,20,40,-50,60";
    let without = fk_json(d, &["--params", res], q);
    let with = fk_json(d, &["--params", res, "--robot", p(&track)], q);
    assert_eq!(without, with);
    // The calibrated model differs from the nominal one.
    let nominal = fk_json(d, &["--robot", p(&track)], q);
    assert_ne!(without, nominal);

    // evaluate: the calibration data (copied beside the result) under both models.
    std::fs::copy(work.path().join("cal.csv"), d.join("data.csv")).unwrap();
    let o = robocal_in(
        d,
        &["evaluate", "--params", res, "--data", "data.csv", "--json"],
    );
    let v: serde_json::Value = serde_json::from_str(&ok(&o)).unwrap();
    // 60 calibration poses and the 3 plane points.
    assert_eq!(v["n"], 63);
    assert!(v["calibrated"]["mean_mm"].as_f64().unwrap() < 0.1, "{v}");

    // compensate: joints of the data, commanded joints written.
    let o = robocal_in(
        d,
        &[
            "compensate",
            "--params",
            res,
            "--joints",
            "data.csv",
            "--out",
            "cmd.csv",
        ],
    );
    ok(&o);
    let (h, rows) = read_csv(&d.join("cmd.csv"));
    assert_eq!(rows.len(), 63);
    assert!(h.iter().any(|c| c == "axis7"), "{h:?}");

    // report: the recorded files (cal.csv in the other directory) are not here; the robot is.
    let o = robocal_in(d, &["report", res, "--out", "rep"]);
    ok(&o);
    assert!(d.join("rep/report.html").is_file());
    // fk without --params and without --robot: a usage error.
    let o = robocal_in(d, &["fk", "--joints", q]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("give --robot"), "{}", stderr(&o));
}

/// A --robot given beside a result must be the embedded robot: same joints, nominal values and
/// controller map (another name is fine). A difference is bad input (exit 3) naming both and
/// the difference.
#[test]
fn a_robot_given_beside_the_result_must_agree_with_it() {
    let work = tempfile::tempdir().unwrap();
    let (alone, res) = calibrated_alone(work.path(), KUKA, "kuka-kr480-r3330-table3");
    let d = alone.path();
    let res = p(&res);
    let q = "10,-40,30,20,40,-50";
    // The preset's robot file under another name: the same robot.
    let same = examples("kr480-r3330.toml");
    assert_eq!(
        fk_json(d, &["--params", res], q),
        fk_json(d, &["--params", res, "--robot", p(&same)], q)
    );
    // The same table with another controller map.
    let text = std::fs::read_to_string(&same).unwrap();
    let other_signs = text.replace(
        "sign = [-1, 1, 1, -1, 1, -1]",
        "sign = [1, 1, 1, -1, 1, -1]",
    );
    assert_ne!(text, other_signs);
    std::fs::write(d.join("signs.toml"), other_signs).unwrap();
    // A nominal tool T0 that differs (not a parameter of the result's table).
    let other_tool = text.replace("239.5558", "239.6558");
    assert_ne!(text, other_tool);
    std::fs::write(d.join("tool.toml"), other_tool).unwrap();
    for (file, want) in [
        ("signs.toml", "controller sign of joint 1 is -1 against 1"),
        (
            "tool.toml",
            "nominal tool T0 z = 239.5558 mm against 239.6558 mm",
        ),
    ] {
        for args in [
            vec!["fk", "--params", res, "--robot", file, "--joints", q],
            vec![
                "evaluate", "--params", res, "--robot", file, "--data", "none.csv",
            ],
            vec!["report", res, "--robot", file, "--out", "rep"],
        ] {
            let o = robocal_in(d, &args);
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(3), "{args:?}: {e}");
            assert!(e.contains(want), "{args:?}: {e}");
            assert!(e.contains(res) && e.contains(file), "{args:?}: {e}");
        }
    }
    assert!(!d.join("rep").exists());
}

/// A result written before results embedded their robot still works with --robot, and without
/// it is a usage error (exit 2) that says to give one.
#[test]
fn old_results_without_a_robot_need_robot() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let t = tracker(false);
    let res = write_result(d, &t.frame);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&res).unwrap()).unwrap();
    let robot = v["robot"].as_object_mut().unwrap();
    for k in ["base", "tool", "tool_correction", "joints", "controller"] {
        robot.remove(k);
    }
    std::fs::write(
        d.join("old.json"),
        serde_json::to_string_pretty(&v).unwrap(),
    )
    .unwrap();
    let q = "10,-40,30,20,40,-50";
    let with = fk_json(d, &["--params", "old.json", "--robot", KUKA], q);
    assert_eq!(with, fk_json(d, &["--params", p(&res)], q));
    for args in [
        vec!["fk", "--params", "old.json", "--joints", q],
        vec!["evaluate", "--params", "old.json", "--data", "x.csv"],
        vec![
            "compensate",
            "--params",
            "old.json",
            "--joints",
            "x.csv",
            "--out",
            "c.csv",
        ],
        vec!["report", "old.json", "--out", "rep"],
    ] {
        let o = robocal_in(d, &args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains("give --robot"), "{args:?}: {e}");
    }
}

/// A damaged embedded robot is bad input naming the file, the line and the field.
#[test]
fn a_damaged_embedded_robot_is_refused_with_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let res = write_result(d, &tracker(false).frame);
    let text = std::fs::read_to_string(&res).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["robot"]["joints"][1]["alpha"] = serde_json::json!(1e300);
    let bad = serde_json::to_string_pretty(&v).unwrap();
    std::fs::write(d.join("bad.json"), &bad).unwrap();
    let o = robocal_in(
        d,
        &["fk", "--params", "bad.json", "--joints", "0,0,0,0,0,0"],
    );
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{e}");
    let line = 1 + bad
        .lines()
        .position(|l| l.contains("1e300") || l.contains("1e+300"))
        .unwrap();
    assert!(
        e.contains(&format!(
            "bad.json:{line}: field `robot.joints[2].alpha`: 1e300 deg is out of range"
        )),
        "{e}"
    );
}
