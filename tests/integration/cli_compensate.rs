//! `robocal compensate`: commanded joints from a result file (eq. 12-14), per-row statuses, and
//! clear errors for bad input with nothing written.

use crate::util::library::*;
use crate::util::*;
use robocal_core::frame::TrackerFrame;
use robocal_core::{preset, Robot};
use std::path::Path;

fn setup() -> (Dir, std::path::PathBuf) {
    let dir = Dir::new();
    let res = write_result(dir.path(), &TrackerFrame::identity());
    (dir, res)
}

#[test]
fn joints_mode_writes_converged_commanded_joints() {
    let (dir, res) = setup();
    let desired = poses(75, 1);
    let input = dir.join("desired.csv");
    write_joints(&input, &desired);
    let out = dir.join("commanded.csv");
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--joints",
        p(&input),
        "--out",
        p(&out),
        "--position-only",
    ]);
    o.assert_ok();
    let text = o.stdout();
    assert!(text.contains("converged            75"), "{text}");
    assert!(text.contains("wrote"), "{text}");

    let (h, rows) = read_csv(&out);
    assert_eq!(
        h.join(","),
        "q1,q2,q3,q4,q5,q6,axis1,axis2,axis3,axis4,axis5,axis6,status,residual_mm,iterations,\
         at_limit,x_desired,y_desired,z_desired,\
         q1_desired,q2_desired,q3_desired,q4_desired,q5_desired,q6_desired,id"
    );
    assert_eq!(rows.len(), 75);
    let nom = preset(KUKA).unwrap();
    let cal = preset(TRUTH).unwrap();
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[col(&h, "status")], "converged");
        assert_eq!(r[col(&h, "id")], format!("p{k}"));
        let q: Vec<f64> = (0..6).map(|i| num(&r[i]).to_radians()).collect();
        let qd: Vec<f64> = (0..6)
            .map(|i| num(&r[col(&h, &format!("q{}_desired", i + 1))]).to_radians())
            .collect();
        for i in 0..6 {
            assert!((qd[i] - desired[k][i]).abs() < 1e-10);
        }
        // eq. 13-14: the calibrated model at the commanded joints is at the nominal position of
        // the desired joints (1e-6 mm solve + rounding of the written degrees).
        let pd = nom.tool_position(&qd);
        let pc = cal.tool_position(&q);
        assert!((pc - pd).norm() < 2e-6, "row {k}: {}", (pc - pd).norm());
        let xd = num(&r[col(&h, "x_desired")]);
        assert!((xd - pd.x).abs() < 1e-8);
        assert!(num(&r[col(&h, "residual_mm")]) <= 1e-6);
        // The correction is real: commanded joints differ from the desired ones.
        assert!((0..6).any(|i| (q[i] - qd[i]).abs() > 1e-6));
        // The KUKA controller's axes: A = (-q1, q2, q3, -q4, q5, -q6) (DESIGN.md).
        for (i, sign) in [-1.0, 1.0, 1.0, -1.0, 1.0, -1.0].iter().enumerate() {
            let a = num(&r[col(&h, &format!("axis{}", i + 1))]);
            assert!(
                (a - sign * num(&r[i])).abs() < 1e-12,
                "row {k}: axis{}",
                i + 1
            );
        }
    }
}

#[test]
fn targets_mode_reports_every_row_and_strict_fails_without_writing() {
    let (dir, res) = setup();
    let cal = preset(TRUTH).unwrap();
    let reachable = cal.tool_position(&[0.3, -0.8, 0.6, 0.1, 0.5, -0.2]);
    let input = dir.join("targets.csv");
    std::fs::write(
        &input,
        format!(
            "name,x,y,z\nok,{},{},{}\nfar,9000,0,1000\n",
            reachable.x, reachable.y, reachable.z
        ),
    )
    .unwrap();
    let out = dir.join("commanded.csv");
    let args = |strict: bool| {
        let mut a = vec![
            "compensate",
            "--robot",
            KUKA,
            "--params",
            p(&res),
            "--targets",
            p(&input),
            "--out",
            p(&out),
        ];
        if strict {
            a.push("--strict");
        }
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    // --strict first: exit 5, listed rows, nothing written.
    let o = robocal(&args(true).iter().map(|s| s.as_str()).collect::<Vec<_>>());
    o.assert_code(5);
    assert!(o.stderr().contains("line 3: unreachable"), "{}", o.stderr());
    assert!(!out.exists());
    // Default: exit 0, both rows written with their status, a warning names the line.
    let o = robocal(&args(false).iter().map(|s| s.as_str()).collect::<Vec<_>>());
    o.assert_ok();
    assert!(
        o.stderr().contains("targets.csv: line 3: unreachable"),
        "{}",
        o.stderr()
    );
    let (h, rows) = read_csv(&out);
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0][col(&h, "status")], "converged");
    assert_eq!(rows[1][col(&h, "status")], "unreachable");
    assert_eq!(rows[1][col(&h, "name")], "far");
    assert!(num(&rows[1][col(&h, "residual_mm")]) > 1000.0);
    assert!(!h.contains(&"q1_desired".to_string()));
    let q: Vec<f64> = (0..6).map(|i| num(&rows[0][i]).to_radians()).collect();
    assert!((cal.tool_position(&q) - reachable).norm() < 2e-6);
}

/// Runs compensate expecting failure with `code`; checks that the message contains every needle
/// and that nothing was written.
fn fails(dir: &Path, args: &[&str], code: i32, needles: &[&str]) {
    let out = dir.join("never.csv");
    let mut a = vec!["compensate", "--robot", KUKA];
    a.extend_from_slice(args);
    a.extend_from_slice(&["--out", p(&out)]);
    let o = robocal(&a);
    let e = o.stderr();
    o.assert_code(code);
    for n in needles {
        assert!(e.contains(n), "`{e}` lacks `{n}`");
    }
    assert!(!out.exists(), "{a:?} wrote output");
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left");
}

#[test]
fn bad_results_and_inputs_are_clear_errors_and_write_nothing() {
    let (dir, res) = setup();
    let d = dir.path();
    let input = d.join("desired.csv");
    write_joints(&input, &poses(5, 2));
    let inp = p(&input);
    fn with<'a>(extra: &[&'a str], input: &'a str) -> Vec<&'a str> {
        let mut v: Vec<&str> = extra.to_vec();
        v.extend_from_slice(&["--joints", input]);
        v
    }

    // A result made for the UR5 (6 joints, standard DH).
    let ur5 = robocal_core::load_robot(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/ur5.toml"))
        .unwrap();
    let r = d.join("ur5.json");
    result_for(&ur5, &ur5, &TrackerFrame::identity())
        .write(&r)
        .unwrap();
    fails(
        d,
        &with(&["--params", p(&r)], inp),
        3,
        &["ur5.json", "robot.convention"],
    );
    // A result made for the 7-joint WAM.
    let wam = robocal_core::load_robot(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/wam.toml"))
        .unwrap();
    let r = d.join("wam.json");
    result_for(&wam, &wam, &TrackerFrame::identity())
        .write(&r)
        .unwrap();
    fails(
        d,
        &with(&["--params", p(&r)], inp),
        3,
        &["wam.json", "robot.dof", "7-joint"],
    );
    // Same shape, another nominal model (Table III as nominal).
    let t3: Robot = preset(TRUTH).unwrap();
    let r = d.join("t3.json");
    result_for(&t3, &t3, &TrackerFrame::identity())
        .write(&r)
        .unwrap();
    fails(
        d,
        &with(&["--params", p(&r)], inp),
        3,
        &["t3.json", "nominal", "wrong --robot"],
    );

    // Missing fields.
    let full: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&res).unwrap()).unwrap();
    let mut v = full.clone();
    v.as_object_mut().unwrap().remove("tracker_frame");
    let r = d.join("no_frame.json");
    std::fs::write(&r, v.to_string()).unwrap();
    fails(
        d,
        &with(&["--params", p(&r)], inp),
        3,
        &["no_frame.json", "tracker_frame"],
    );
    let mut v = full.clone();
    v["parameters"].as_object_mut().unwrap().remove("d3");
    let r = d.join("no_d3.json");
    std::fs::write(&r, v.to_string()).unwrap();
    fails(
        d,
        &with(&["--params", p(&r)], inp),
        3,
        &["no_d3.json", "`d3` is missing"],
    );
    let r = d.join("broken.json");
    std::fs::write(&r, "{\"parameters\": {").unwrap();
    fails(d, &with(&["--params", p(&r)], inp), 3, &["broken.json"]);
    fails(
        d,
        &with(&["--params", p(&d.join("absent.json"))], inp),
        4,
        &["absent.json"],
    );

    // Bad joint files.
    let bad = d.join("bad.csv");
    std::fs::write(&bad, "q1,q2,q3,q4,q5\n1,2,3,4,5\n").unwrap();
    fails(
        d,
        &["--params", p(&res), "--joints", p(&bad)],
        3,
        &["bad.csv:1", "`q6`"],
    );
    std::fs::write(&bad, "q1,q2,q3,q4,q5,q6\n1,2,3,4,5,6\n1,2,x,4,5,6\n").unwrap();
    fails(
        d,
        &["--params", p(&res), "--joints", p(&bad)],
        3,
        &["bad.csv:3", "`q3`"],
    );
    std::fs::write(&bad, "q1,q2,q3,q4,q5,q6,status\n1,2,3,4,5,6,ok\n").unwrap();
    fails(
        d,
        &["--params", p(&res), "--joints", p(&bad)],
        3,
        &["bad.csv:1", "`status`"],
    );
    std::fs::write(&bad, "x,y\n1,2\n").unwrap();
    fails(
        d,
        &["--params", p(&res), "--targets", p(&bad)],
        3,
        &["bad.csv:1", "`z`"],
    );

    // Bad flags.
    fails(
        d,
        &with(&["--params", p(&res), "--tolerance-mm", "0"], inp),
        2,
        &["--tolerance-mm"],
    );
    fails(
        d,
        &with(&["--params", p(&res), "--max-iterations", "0"], inp),
        2,
        &["--max-iterations"],
    );
    fails(d, &["--params", p(&res)], 2, &["--joints"]);
    let mut both = with(&["--params", p(&res)], inp);
    both.extend_from_slice(&["--targets", p(&input)]);
    fails(d, &both, 2, &["--targets"]);
}

#[test]
fn output_into_a_missing_directory_is_an_io_error() {
    let (dir, res) = setup();
    let input = dir.join("desired.csv");
    write_joints(&input, &poses(3, 3));
    let out = dir.join("no/such/dir/c.csv");
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--joints",
        p(&input),
        "--out",
        p(&out),
    ]);
    o.assert_code(4);
    assert!(o.stderr().contains("does not exist"), "{}", o.stderr());
}
