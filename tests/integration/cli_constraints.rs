//! Calibration without a laser tracker (issue 31) through the CLI: `simulate --constraint`
//! writes fixed-point, sphere and plane data; `calibrate` recognizes the `constraint` column,
//! fits the robot and the features, names what the data cannot see, refuses an unknown scale,
//! and rejects bad constraint files (exit 3, file, line and column named; nothing written).

use crate::util::*;

const KR: &str = "kuka-kr480-r3330";

#[test]
fn fixed_points_with_distances_calibrate_up_to_the_base_pose() {
    let dir = Dir::new();
    let (data, dist) = simulate_constraints(&dir, "point", &[]);
    let (header, rows) = read_csv(&data);
    assert_eq!(header, ["q1", "q2", "q3", "q4", "q5", "q6", "constraint"]);
    assert_eq!(rows.len(), 80);
    assert_eq!(rows[0][6], "point:P1");
    assert_eq!(read_csv(&dist).1.len(), 6);
    let out = dir.join("cal.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--distances",
        p(&dist),
        "--out",
        p(&out),
    ]);
    let text = o.stdout();
    assert!(
        text.contains("4 fixed point(s)") && text.contains("6 known distance(s)"),
        "{text}"
    );
    assert!(text.contains("the base pose"), "{text}");
    assert!(text.contains("base_x") && text.contains("held"), "{text}");
    let r = read_json(&out);
    // A normal result file (status, robot, parameters, inputs) with a `constraint` section.
    assert_eq!(r["status"], "calibrated");
    assert_eq!(r["robot"]["name"], KR);
    assert!(
        r["inputs"]["data"]["sha256"].as_str().unwrap().len() == 64,
        "{r}"
    );
    assert!(r["inputs"]["distances"]["sha256"].is_string(), "{r}");
    let c = &r["constraint"];
    assert!(c["residual_rms_mm"].as_f64().unwrap() < 0.03, "{c}");
    assert_eq!(c["features"].as_array().unwrap().len(), 4);
    assert_eq!(c["base_pose_known"], false);
    assert!(c["frame"].as_str().unwrap().contains("up to the base pose"));
    let params = r["parameters"].as_object().unwrap();
    let identified = params.values().filter(|e| e["fixed"] == false).count();
    assert!(identified >= 15, "{r}");
    assert_eq!(params["base_x"]["fixed"], true);
    let after = r["errors"]["calibration"]["after"]["mean_mm"]
        .as_f64()
        .unwrap();
    let before = r["errors"]["calibration"]["before"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(after < 0.03 && before > 10.0 * after, "{before} {after}");
}

#[test]
fn without_distances_the_scale_is_refused_unless_accepted() {
    let dir = Dir::new();
    let (data, _) = simulate_constraints(&dir, "point", &["--features", "2"]);
    let out = dir.join("cal.json");
    let args = [
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--out",
        p(&out),
    ];
    let o = robocal(&args);
    o.assert_code(5);
    let e = o.stderr();
    assert!(
        e.contains("scale is not determined") && e.contains("--distances"),
        "{e}"
    );
    assert!(!out.exists());
    let mut accepted = args.to_vec();
    accepted.push("--accept-unknown-scale");
    let o = ok(&accepted);
    assert!(
        o.stderr().contains("scale is not determined"),
        "{}",
        o.stderr()
    );
    let c = &read_json(&out)["constraint"];
    assert_eq!(c["scale"]["known"], false, "{c}");
    assert!(c["scale"]["held"].is_string(), "{c}");
}

#[test]
fn spheres_of_known_radius_and_planes_calibrate() {
    let dir = Dir::new();
    let (data, _) = simulate_constraints(&dir, "sphere", &[]);
    let (header, rows) = read_csv(&data);
    assert_eq!(header[7], "radius_mm");
    assert_eq!(rows[0][7], "25");
    let out = dir.join("s.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--out",
        p(&out),
    ]);
    assert!(
        o.stdout().contains("sphere S1's radius 25 mm"),
        "{}",
        o.stdout()
    );
    let (plane, _) =
        simulate_constraints(&dir, "plane", &["--features", "3", "--per-feature", "30"]);
    let out = dir.join("p.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&plane),
        "--accept-unknown-scale",
        "--out",
        p(&out),
    ]);
    assert!(o.stdout().contains("plane:P1"), "{}", o.stdout());
}

#[test]
fn bad_constraint_files_are_errors_naming_the_line_and_column() {
    let dir = Dir::new();
    let (data, dist) =
        simulate_constraints(&dir, "point", &["--features", "2", "--per-feature", "4"]);
    let text = std::fs::read_to_string(&data).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let out = dir.join("cal.json");
    let run = |name: &str, body: String, extra: &[&str], want: &[&str]| {
        let f = dir.write(name, body);
        let mut args = vec![
            "calibrate",
            "--robot",
            KR,
            "--data",
            p(&f),
            "--out",
            p(&out),
        ];
        args.extend(extra);
        let o = robocal(&args);
        o.assert_code(3);
        for w in want {
            assert!(o.stderr().contains(w), "{name}: {w}: {}", o.stderr());
        }
        assert!(!out.exists());
    };
    // A label used once (a typo).
    let typo = text.replacen("point:P2", "point:P3", 1);
    let line = typo.lines().position(|l| l.contains("point:P3")).unwrap() + 1;
    run(
        "typo.csv",
        typo,
        &["--accept-unknown-scale"],
        &[&format!("typo.csv:{line}"), "used on 1 row"],
    );
    // x,y,z on a constraint row.
    let mut xyz = String::from(lines[0]);
    xyz.push_str(",x,y,z\n");
    for (i, l) in lines[1..].iter().enumerate() {
        xyz.push_str(l);
        xyz.push_str(if i == 2 { ",1,2,3\n" } else { ",,,\n" });
    }
    run(
        "xyz.csv",
        xyz,
        &["--accept-unknown-scale"],
        &["xyz.csv:4", "field `x`", "no measured position"],
    );
    // A sphere with two radii.
    let mut sph = format!("{},radius_mm\n", lines[0]);
    for (i, l) in lines[1..].iter().enumerate() {
        let l = l.replace("point:", "sphere:");
        sph.push_str(&format!("{l},{}\n", if i == 1 { 26 } else { 25 }));
    }
    run(
        "sph.csv",
        sph,
        &[],
        &[
            "sph.csv:3",
            "radius_mm",
            "radius 26 mm here but 25 mm on line 2",
        ],
    );
    // An unknown kind.
    run(
        "kind.csv",
        text.replace("point:", "circle:"),
        &[],
        &["kind.csv:2", "unknown constraint kind `circle`"],
    );
    // Distances: an unknown name, a negative distance.
    let d = dir.write("d.csv", "from,to,distance_mm\nP1,P9,100\n");
    run(
        "ok1.csv",
        text.clone(),
        &["--distances", p(&d)],
        &["d.csv:2", "field `to`", "`P9`"],
    );
    let d = dir.write("d2.csv", "from,to,distance_mm\nP1,P2,-100\n");
    run(
        "ok2.csv",
        text.clone(),
        &["--distances", p(&d)],
        &["d2.csv:2", "not a positive length"],
    );
    assert!(dist.exists());
}

#[test]
fn a_plane_with_collinear_points_is_an_error() {
    // Tool points 100 mm apart on one line, reached by the nominal robot's inverse kinematics.
    use robocal_core::{Compensator, DampedLeastSquares};
    let robot = robocal_core::preset(KR).unwrap();
    let ik = Compensator::new(&robot, &robot, DampedLeastSquares::default()).unwrap();
    let start: Vec<f64> = [0.0, -90.0, 90.0, 0.0, 30.0, 0.0]
        .iter()
        .map(|d: &f64| d.to_radians())
        .collect();
    let p0 = robot.tool_position(&start);
    let mut csv = String::from("q1,q2,q3,q4,q5,q6,constraint\n");
    for k in 0..4 {
        let mut q = vec![0.0; 6];
        let target = p0 + nalgebra::Vector3::new(100.0 * k as f64, 0.0, 0.0);
        assert!(ik
            .reach(&target, Some(&start), &mut q)
            .status
            .is_converged());
        let deg: Vec<String> = q.iter().map(|v| format!("{:.9}", v.to_degrees())).collect();
        csv.push_str(&format!("{},plane:F\n", deg.join(",")));
    }
    let dir = Dir::new();
    let f = dir.write("line.csv", csv);
    let out = dir.join("cal.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&f),
        "--accept-unknown-scale",
        "--out",
        p(&out),
    ]);
    o.assert_code(3);
    let e = o.stderr();
    assert!(
        e.contains("line.csv:2") && e.contains("plane `F`") && e.contains("collinear"),
        "{e}"
    );
    assert!(!out.exists());
}
