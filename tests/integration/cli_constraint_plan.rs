//! `plan --constraint` and `plan --features-file` (issue 31): configurations touching fixed
//! points, spheres or planes chosen for observability, written as a constraint measurement file;
//! what such data cannot see named; bad features files exit 3 naming file, line and column,
//! with nothing written.

use crate::util::*;

const KR: &str = "kuka-kr480-r3330";

/// Numbers in the `planned`/`random` columns of the plan's line starting with `label`.
fn planned_random(text: &str, label: &str) -> (f64, f64) {
    let line = text
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no `{label}` line in\n{text}"));
    let v: Vec<f64> = line[label.len()..]
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    (v[0], v[1])
}

#[test]
fn a_fixed_point_plan_is_a_constraint_file_better_than_random() {
    let dir = Dir::new();
    let out = dir.join("plan.csv");
    let o = ok(&[
        "plan",
        "--robot",
        KR,
        "--constraint",
        "point",
        "--features",
        "3",
        "--per-feature",
        "10",
        "--candidates-per-feature",
        "60",
        "--distances",
        "--out",
        p(&out),
    ]);
    let text = o.stdout();
    let (header, rows) = read_csv(&out);
    assert_eq!(header, ["q1", "q2", "q3", "q4", "q5", "q6", "constraint"]);
    assert_eq!(rows.len(), 30);
    for f in ["point:P1", "point:P2", "point:P3"] {
        assert!(rows.iter().filter(|r| r[6] == f).count() >= 2, "{f}");
    }
    let (pl, rd) = planned_random(&text, "predicted workspace model error, RMS (mm)");
    assert!(pl < rd, "planned {pl} vs random {rd}\n{text}");
    assert!(text.contains("up to the base pose"), "{text}");
    assert!(text.contains("measure the distances"), "{text}");
}

#[test]
fn a_plane_plan_names_what_a_plane_cannot_see() {
    let dir = Dir::new();
    let out = dir.join("plane.csv");
    let text = ok(&[
        "plan",
        "--robot",
        KR,
        "--constraint",
        "plane",
        "--features",
        "1",
        "--per-feature",
        "40",
        "--candidates-per-feature",
        "150",
        "--out",
        p(&out),
    ])
    .stdout();
    // A plane has no length: the scale is named with what to add; its weakest directions are
    // listed with their share of the predicted error.
    assert!(
        text.contains("the robot's scale: no known length"),
        "{text}"
    );
    assert!(text.contains("--accept-unknown-scale"), "{text}");
    assert!(
        text.contains("Directions the planned configurations see least"),
        "{text}"
    );
    assert_eq!(read_csv(&out).1.len(), 40);
}

#[test]
fn a_features_file_places_the_features() {
    let dir = Dir::new();
    // Where the robot's tool is at two reference configurations (fk), as a teach pendant shows.
    let at = |q: &str| {
        let j: serde_json::Value =
            serde_json::from_str(&ok(&["fk", "--robot", KR, "--joints", q, "--json"]).stdout())
                .unwrap();
        [
            j["x"].as_f64().unwrap(),
            j["y"].as_f64().unwrap(),
            j["z"].as_f64().unwrap(),
        ]
    };
    let a = at("10,-70,80,5,40,0");
    let b = at("-25,-60,70,0,50,10");
    let feats = dir.write(
        "cell.csv",
        format!(
            "constraint,x,y,z\npoint:nest1,{},{},{}\npoint:nest2,{},{},{}\n",
            a[0], a[1], a[2], b[0], b[1], b[2]
        ),
    );
    let out = dir.join("plan.csv");
    let text = ok(&[
        "plan",
        "--robot",
        KR,
        "--features-file",
        p(&feats),
        "--per-feature",
        "8",
        "--candidates-per-feature",
        "40",
        "--distances",
        "--out",
        p(&out),
    ])
    .stdout();
    let rows = read_csv(&out).1;
    assert_eq!(rows.len(), 16);
    assert!(rows.iter().any(|r| r[6] == "point:nest1"), "{text}");
    assert!(rows.iter().any(|r| r[6] == "point:nest2"), "{text}");
}

#[test]
fn bad_features_exit_3_naming_them() {
    let dir = Dir::new();
    let out = dir.join("plan.csv");
    let run = |file: &std::path::Path| {
        robocal(&[
            "plan",
            "--robot",
            KR,
            "--features-file",
            p(file),
            "--per-feature",
            "5",
            "--candidates-per-feature",
            "20",
            "--out",
            p(&out),
        ])
    };
    let far = dir.write(
        "far.csv",
        "constraint,x,y,z\npoint:near,1800,0,1200\npoint:moon,20000,0,0\n",
    );
    let o = run(&far);
    o.assert_code(3);
    let e = o.stderr();
    assert!(e.contains("far.csv:3") && e.contains("point:moon"), "{e}");
    assert!(e.contains("out of the robot's reach"), "{e}");
    let none = dir.write("none.csv", "constraint,x,y,z\n");
    let o = run(&none);
    o.assert_code(3);
    assert!(o.stderr().contains("no feature"), "{}", o.stderr());
    let plane = dir.write("plane.csv", "constraint,x,y,z\nplane:table,1500,0,300\n");
    let o = run(&plane);
    o.assert_code(3);
    assert!(o.stderr().contains("needs its normal"), "{}", o.stderr());
    assert!(!out.exists(), "nothing written");
    // No feature drawn either.
    robocal(&[
        "plan",
        "--robot",
        KR,
        "--constraint",
        "point",
        "--features",
        "0",
        "--out",
        p(&out),
    ])
    .assert_code(3);
    // Refused settings, each named as the flag the user typed (fewer candidates than
    // configurations per feature among them).
    for (args, want) in [
        (&["--features", "0"][..], "--features: must be at least 1"),
        (
            &["--per-feature", "1"],
            "--per-feature: 1 is fewer than a point needs (2)",
        ),
        (
            &["--tilt-deg", "95"],
            "--tilt-deg: 95 is not within 0..90 degrees",
        ),
        (
            &["--span-mm", "0"],
            "--span-mm: 0 is not within (0, 5000] mm",
        ),
        (
            &["--per-feature", "30", "--candidates-per-feature", "20"],
            "--candidates-per-feature: 20 is not within 30..5000",
        ),
    ] {
        let mut a = vec!["plan", "--robot", KR, "--constraint", "point"];
        a.extend_from_slice(args);
        a.extend(["--out", p(&out)]);
        let o = robocal(&a);
        o.assert_code(3);
        assert!(o.stderr().contains(want), "{args:?}: {}", o.stderr());
    }
    // Constraint flags without a constraint plan are a usage error.
    robocal(&[
        "plan",
        "--robot",
        KR,
        "--poses",
        "30",
        "--per-feature",
        "5",
        "--out",
        p(&out),
    ])
    .assert_code(2);
    assert!(!out.exists(), "nothing written");
}

#[test]
fn a_plan_measured_by_the_true_robot_calibrates() {
    // plan -> measure (simulated: the true robot touches each planned contact) -> calibrate ->
    // evaluate on tracker points of the same true robot.
    let dir = Dir::new();
    let plan = dir.join("plan.csv");
    ok(&[
        "plan",
        "--robot",
        KR,
        "--constraint",
        "point",
        "--features",
        "3",
        "--per-feature",
        "12",
        "--candidates-per-feature",
        "60",
        "--distances",
        "--out",
        p(&plan),
    ]);
    let data = dir.join("measured.csv");
    let dist = dir.join("measured.distances.csv");
    let o = ok(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        "random",
        "--constraint-plan",
        p(&plan),
        "--noise-mm",
        "0.01",
        "--out",
        p(&data),
        "--distances-out",
        p(&dist),
    ]);
    let (planned, measured) = (read_csv(&plan).1, read_csv(&data).1);
    // A contact the truth cannot reach within its limits is left out, with a warning.
    let left_out = planned.len() - measured.len();
    assert!(left_out <= 2, "{}", o.stderr());
    assert_eq!(
        left_out > 0,
        o.stderr().contains("left out"),
        "{}",
        o.stderr()
    );
    assert!(
        o.stdout()
            .contains(&format!("{} constraint row(s)", measured.len())),
        "{}",
        o.stdout()
    );
    // Each measured row is a planned row (in order, the same feature) with the truth's
    // configuration near the planned one (a few mm of model error: a few degrees at most, at
    // the wrist near its singularity), never the same.
    let dq = |a: &[String], b: &[String]| -> f64 {
        (0..6)
            .map(|j| (a[j].parse::<f64>().unwrap() - b[j].parse::<f64>().unwrap()).abs())
            .fold(0.0, f64::max)
    };
    let mut planned = planned.iter();
    for b in &measured {
        let a = planned
            .find(|a| a[6] == b[6] && dq(a, b) < 10.0)
            .unwrap_or_else(|| panic!("no planned row near {b:?}"));
        assert!(dq(a, b) > 0.0);
    }
    assert_eq!(read_csv(&dist).1.len(), 3);
    let truth = dir.join("measured.truth.json");
    let t = read_json(&truth);
    assert_eq!(t["constraint"]["features"].as_array().unwrap().len(), 3);
    let res = dir.join("result.json");
    ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--distances",
        p(&dist),
        "--out",
        p(&res),
    ]);
    let check = dir.join("check.csv");
    ok(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        p(&truth),
        "--poses",
        "40",
        "--no-plane",
        "--noise-mm",
        "0.01",
        "--out",
        p(&check),
    ]);
    let j: serde_json::Value = serde_json::from_str(
        &ok(&[
            "evaluate",
            "--params",
            p(&res),
            "--data",
            p(&check),
            "--json",
        ])
        .stdout(),
    )
    .unwrap();
    let (cal, nom) = (
        j["calibrated"]["mean_mm"].as_f64().unwrap(),
        j["nominal"]["mean_mm"].as_f64().unwrap(),
    );
    assert!(
        cal < 0.1 && cal < 0.1 * nom,
        "calibrated {cal} mm, nominal {nom} mm"
    );
    // The plan file is an input: not an output.
    robocal(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        "random",
        "--constraint-plan",
        p(&plan),
        "--out",
        p(&plan),
    ])
    .assert_code(2);
}
