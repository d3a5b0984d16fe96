//! Prismatic joints and controller axes through the command line: the KR 480 on a linear track
//! (`examples/kr480-track.toml`) simulated, calibrated, compensated and verified; axis columns
//! instead of joint columns; `robot show` and `fk` with a track; bad `[controller]` sections.

use crate::util::*;
use robocal_core::io::CalibrationResult;
use robocal_core::load_robot;
use std::path::PathBuf;

/// The track robot's whole cycle: simulate -> calibrate -> compensate -> measure the commanded
/// poses -> evaluate. The track's values are mm in every file (never converted), the commanded
/// file carries the controller's axes, and the verification matches the prediction.
#[test]
fn simulate_calibrate_compensate_verify_on_the_tracked_robot() {
    let dir = Dir::new();
    let d = |f: &str| -> PathBuf { dir.join(f) };
    let robot = example("kr480-track.toml");
    let nominal = load_robot(&robot).unwrap();
    ok(&[
        "simulate",
        "--robot",
        &robot,
        "--truth",
        "random",
        "--poses",
        "80",
        "--validation",
        "40",
        "--seed",
        "3",
        "--out",
        p(&d("cell.csv")),
    ]);
    let (h, rows) = read_csv(&d("cell.csv"));
    assert_eq!(&h[..8], ["q1", "q2", "q3", "q4", "q5", "q6", "q7", "x"]);
    // The track's column holds mm over its travel (0..4000), not radians or degrees of it.
    let track: Vec<f64> = rows.iter().map(|r| num(&r[0])).collect();
    assert!(track.iter().all(|v| (0.0..=4000.0).contains(v)));
    assert!(track.iter().any(|v| *v > 2000.0), "{track:?}");

    let out = ok(&[
        "calibrate",
        "--robot",
        &robot,
        "--data",
        p(&d("cell.csv")),
        "--out",
        p(&d("res.json")),
    ])
    .stdout();
    assert!(out.contains("prismatic"), "{out}");
    let res = CalibrationResult::read(&d("res.json")).unwrap();
    assert_eq!(res.robot.joint_types[0], robocal_core::JointType::Prismatic);
    let after = res.errors.calibration.after;
    assert!(after.mean_mm < 0.06, "{after:?}");
    assert!(res.errors.calibration.before.mean_mm > 5.0 * after.mean_mm);

    let out = ok(&[
        "compensate",
        "--robot",
        &robot,
        "--params",
        p(&d("res.json")),
        "--joints",
        p(&d("cell.csv")),
        "--position-only",
        "--out",
        p(&d("cmd.csv")),
    ])
    .stdout();
    assert!(out.contains("converged           123"), "{out}");
    assert!(out.contains(" mm (line"), "{out}");
    let (h, rows) = read_csv(&d("cmd.csv"));
    let cal = res.calibrated_robot(&nominal, &d("res.json")).unwrap();
    for r in &rows {
        assert_eq!(r[col(&h, "status")], "converged");
        let q: Vec<f64> = (0..7)
            .map(|i| num(&r[col(&h, &format!("q{}", i + 1))]))
            .collect();
        let qd: Vec<f64> = (0..7)
            .map(|i| num(&r[col(&h, &format!("q{}_desired", i + 1))]))
            .collect();
        // The desired track value is the input's, in mm; the commanded one moved a little.
        assert!((q[0] - qd[0]).abs() < 20.0, "{q:?} vs {qd:?}");
        // eq. 13-14 through the written values (mm and degrees).
        let pc = cal.tool_position(&nominal.joints_from_display(&q));
        let pd = nominal.tool_position(&nominal.joints_from_display(&qd));
        assert!((pc - pd).norm() < 2e-6, "{}", (pc - pd).norm());
        // The controller's axes: E1 = q1, A1 = -q2, ..., A6 = -q7.
        let a: Vec<f64> = (0..7)
            .map(|i| num(&r[col(&h, &format!("axis{}", i + 1))]))
            .collect();
        let sign = [1.0, -1.0, 1.0, 1.0, -1.0, 1.0, -1.0];
        for i in 0..7 {
            assert!((a[i] - sign[i] * q[i]).abs() < 1e-9, "{a:?} vs {q:?}");
        }
    }

    ok(&[
        "simulate",
        "--robot",
        &robot,
        "--truth",
        p(&d("cell.truth.json")),
        "--joints",
        p(&d("cmd.csv")),
        "--out",
        p(&d("verify.csv")),
    ]);
    let out = ok(&[
        "evaluate",
        "--robot",
        &robot,
        "--params",
        p(&d("res.json")),
        "--data",
        p(&d("verify.csv")),
    ])
    .stdout();
    assert!(out.contains("verification"), "{out}");
    let line = out
        .lines()
        .find(|l| l.starts_with("Mean (mm)"))
        .unwrap_or_else(|| panic!("{out}"));
    let verified = num(line.split_whitespace().nth(2).unwrap());
    assert!(verified < 1.5 * after.mean_mm, "{out}");
}

/// A measurement file with the controller's `axis1..axisN` gives the same calibration as the same
/// data with the model's `q1..qn` (FANUC-style J2/J3 coupling: q3 = -(J2 + J3)).
#[test]
fn axis_columns_calibrate_like_joint_columns() {
    let dir = Dir::new();
    let d = |f: &str| -> PathBuf { dir.join(f) };
    let robot = example("fanuc-like.toml");
    let r = load_robot(&robot).unwrap();
    ok(&[
        "simulate",
        "--robot",
        &robot,
        "--truth",
        "random",
        "--poses",
        "60",
        "--seed",
        "4",
        "--out",
        p(&d("q.csv")),
    ]);
    // The same rows with the controller's values: axis = M^-1 (q - offset).
    let (h, rows) = read_csv(&d("q.csv"));
    let mut head: Vec<String> = (1..=6).map(|i| format!("axis{i}")).collect();
    head.extend(h[6..].iter().cloned());
    let mut text = head.join(",") + "\n";
    for row in &rows {
        let q: Vec<f64> = row[..6].iter().map(|v| num(v)).collect();
        let a = r.joint_space().axes_from_joints(&r.joints_from_display(&q));
        assert!((q[2] + a[1] + a[2]).abs() < 1e-9, "q3 = -(J2 + J3)");
        let mut rec: Vec<String> = a.iter().map(|v| format!("{v:.12}")).collect();
        rec.extend(row[6..].iter().cloned());
        text += &(rec.join(",") + "\n");
    }
    std::fs::write(d("axis.csv"), text).unwrap();
    for (data, out) in [("q.csv", "q.json"), ("axis.csv", "axis.json")] {
        ok(&[
            "calibrate",
            "--robot",
            &robot,
            "--data",
            p(&d(data)),
            "--out",
            p(&d(out)),
        ]);
    }
    let a = CalibrationResult::read(&d("q.json")).unwrap();
    let b = CalibrationResult::read(&d("axis.json")).unwrap();
    for (name, e) in &a.parameters {
        let f = &b.parameters[name];
        assert!(
            (e.calibrated - f.calibrated).abs() < 1e-6,
            "{name}: {} vs {}",
            e.calibrated,
            f.calibrated
        );
        assert_eq!(e.fixed, f.fixed, "{name}");
    }
    let (x, y) = (a.errors.calibration.after, b.errors.calibration.after);
    assert!((x.mean_mm - y.mean_mm).abs() < 1e-9, "{x:?} vs {y:?}");
    // A file with both kinds that disagree is refused, naming line and column.
    let text = std::fs::read_to_string(d("q.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[0].push_str(",axis1,axis2,axis3,axis4,axis5,axis6");
    for (k, l) in lines.iter_mut().enumerate().skip(1) {
        let q: Vec<f64> = l.split(',').take(6).map(num).collect();
        let mut a = r.joint_space().axes_from_joints(&r.joints_from_display(&q));
        if k == 5 {
            a[2] += 0.01;
        }
        for v in a {
            l.push_str(&format!(",{v:.12}"));
        }
    }
    std::fs::write(d("both.csv"), lines.join("\n") + "\n").unwrap();
    let o = robocal(&[
        "calibrate",
        "--robot",
        &robot,
        "--data",
        p(&d("both.csv")),
        "--out",
        p(&d("both.json")),
    ]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("both.csv:6: field `axis3`") && o.stderr().contains("disagrees"),
        "{}",
        o.stderr()
    );
    assert!(!d("both.json").exists());
}

#[test]
fn robot_show_and_fk_with_a_track() {
    let robot = example("kr480-track.toml");
    let s = ok(&["robot", "show", &robot]).stdout();
    for n in [
        "1 prismatic",
        "2  revolute",
        "q1: 0 .. 4000 mm (prismatic)",
        "q2: -185 .. 185 deg (revolute)",
        "q2 = -axis2",
    ] {
        assert!(s.contains(n), "`{s}` lacks `{n}`");
    }
    let s = ok(&["robot", "show", &example("fanuc-like.toml")]).stdout();
    assert!(s.contains("q3 = -axis3 - axis2"), "{s}");
    // fk: the track's value is mm (1000 mm along x), the arm's degrees.
    let at = |j: &str| -> [f64; 3] {
        let v: serde_json::Value =
            serde_json::from_str(&ok(&["fk", "--robot", &robot, "--joints", j, "--json"]).stdout())
                .unwrap();
        [
            v["x"].as_f64().unwrap(),
            v["y"].as_f64().unwrap(),
            v["z"].as_f64().unwrap(),
        ]
    };
    let a = at("0,10,-30,20,40,-50,60");
    let b = at("1000,10,-30,20,40,-50,60");
    assert!(
        (b[0] - a[0] - 1000.0).abs() < 1e-9 && (b[1] - a[1]).abs() < 1e-9,
        "{a:?} {b:?}"
    );
}

#[test]
fn bad_controller_section_names_file_line_and_field() {
    let dir = Dir::new();
    let text = std::fs::read_to_string(example("fanuc-like.toml")).unwrap();
    for (from, to, needles) in [
        (
            "sign = [1, 1, -1, 1, 1, 1]",
            "sign = [1, 1, -1, 1, 1]",
            &["field `controller.sign`", "expected 6 values"][..],
        ),
        (
            "coupling = [[3, 2, -1.0]]",
            "coupling = [[3, 7, -1.0]]",
            &[
                "field `controller.coupling[1]`",
                "j 7 is not a joint number 1..6",
            ][..],
        ),
        (
            "coupling = [[3, 2, -1.0]]",
            "coupling = [[2, 3, 1.0], [3, 2, -1.0]]",
            &["field `controller.coupling`", "singular"][..],
        ),
    ] {
        let bad = text.replace(from, to);
        assert_ne!(bad, text);
        let path = dir.write("bad.toml", &bad);
        let line = bad.lines().position(|l| l == to).unwrap() + 1;
        let o = robocal(&["fk", "--robot", p(&path), "--joints", "0,0,0,0,0,0"]);
        o.assert_code(3);
        let e = o.stderr();
        let at = format!("{}:{line}: ", path.display());
        assert!(e.contains(&at), "`{e}` lacks `{at}`");
        for n in needles {
            assert!(e.contains(n), "`{e}` lacks `{n}`");
        }
    }
}
