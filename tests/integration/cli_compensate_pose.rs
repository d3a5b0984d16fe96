//! `robocal compensate` full pose (the default): commanded joints that put the calibrated tool on
//! the nominal pose, position and orientation, with the configuration statuses; Cartesian
//! targets with `a,b,c`; position-only targets and `--position-only`.

use crate::util::library::*;
use crate::util::*;
use robocal_core::frame::{frame_vector, Frame, TrackerFrame};
use robocal_core::{preset, Robot};

/// Position (mm) and orientation (deg) distance of two frames.
fn distance(a: &Frame, b: &Frame) -> (f64, f64) {
    let r = a.rotation.matrix().transpose() * b.rotation.matrix();
    let s = 0.5
        * ((r[(2, 1)] - r[(1, 2)]).powi(2)
            + (r[(0, 2)] - r[(2, 0)]).powi(2)
            + (r[(1, 0)] - r[(0, 1)]).powi(2))
        .sqrt();
    let c = 0.5 * (r.trace() - 1.0);
    (
        (a.translation.vector - b.translation.vector).norm(),
        s.atan2(c).to_degrees(),
    )
}

fn joints_of(h: &[String], r: &[String], prefix: &str, suffix: &str) -> Vec<f64> {
    (1..=6)
        .map(|i| num(&r[col(h, &format!("{prefix}{i}{suffix}"))]).to_radians())
        .collect()
}

#[test]
fn joints_are_compensated_for_the_whole_pose_by_default() {
    let dir = Dir::new();
    let res = write_result(dir.path(), &TrackerFrame::identity());
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
    ]);
    o.assert_ok();
    assert!(o.stdout().contains("full pose"), "{}", o.stdout());
    let (h, rows) = read_csv(&out);
    let header = h.join(",");
    assert!(
        header.contains(
            "status,residual_mm,residual_deg,iterations,at_limit,x_desired,y_desired,\
                         z_desired,a_desired,b_desired,c_desired,q1_desired"
        ),
        "{header}"
    );
    let (nom, cal): (Robot, Robot) = (preset(KUKA).unwrap(), preset(TRUTH).unwrap());
    let mut converged = 0;
    for r in &rows {
        let q = joints_of(&h, r, "q", "");
        let qd = joints_of(&h, r, "q", "_desired");
        let status = r[col(&h, "status")].as_str();
        let (dp, dw) = distance(&cal.tool_pose(&q), &nom.tool_pose(&qd));
        // The desired orientation written is the nominal tool's A, B, C.
        let v = frame_vector(&nom.tool_pose(&qd));
        for (k, c) in ["a_desired", "b_desired", "c_desired"].iter().enumerate() {
            let w = num(&r[col(&h, c)]);
            assert!((w - v[3 + k].to_degrees()).abs() < 1e-6, "{c}: {w}");
        }
        match status {
            "converged" | "singular" => {
                converged += usize::from(status == "converged");
                // 1e-6 mm / deg solve + rounding of the written degrees (1e-10).
                assert!(dp < 2e-6 && dw < 2e-6, "{status}: {dp} mm {dw} deg");
                assert!(num(&r[col(&h, "residual_deg")]) <= 1e-6);
            }
            "unreachable" => assert!(num(&r[col(&h, "residual_mm")]) > 1e-6),
            other => panic!("unexpected status {other}"),
        }
    }
    assert!(converged >= 70, "{converged} of 75 converged");
    // Non-converged rows are listed as warnings with their pose residuals.
    if converged < 75 {
        assert!(
            o.stderr().contains("deg from the target pose"),
            "{}",
            o.stderr()
        );
    }
}

#[test]
fn cartesian_targets_with_orientation_and_without() {
    let dir = Dir::new();
    let res = write_result(dir.path(), &TrackerFrame::identity());
    let cal = preset(TRUTH).unwrap();
    let qs = [
        [0.3, -0.8, 0.6, 0.1, 0.5, -0.2],
        [-0.4, -1.1, 1.2, 0.8, -0.9, 0.4],
    ];
    let mut text = String::from("name,x,y,z,a,b,c,q1,q2,q3,q4,q5,q6\n");
    for (k, q) in qs.iter().enumerate() {
        let v = frame_vector(&cal.tool_pose(q));
        let seed: Vec<String> = q
            .iter()
            .map(|a| format!("{}", a.to_degrees() + 2.0))
            .collect();
        text += &format!(
            "t{k},{},{},{},{},{},{},{}\n",
            v[0],
            v[1],
            v[2],
            v[3].to_degrees(),
            v[4].to_degrees(),
            v[5].to_degrees(),
            seed.join(",")
        );
    }
    let input = dir.write("poses.csv", &text);
    let out = dir.join("commanded.csv");
    let run = |extra: &[&str]| {
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
        a.extend_from_slice(extra);
        robocal(&a)
    };
    run(&["--strict"]).assert_ok();
    let (h, rows) = read_csv(&out);
    assert!(h.contains(&"a_desired".to_string()) && !h.contains(&"a".to_string()));
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[col(&h, "status")], "converged");
        let q = joints_of(&h, r, "q", "");
        let (dp, dw) = distance(&cal.tool_pose(&q), &cal.tool_pose(&qs[k]));
        assert!(dp < 2e-6 && dw < 2e-6, "{dp} mm {dw} deg");
    }
    // --position-only: the orientation is not used, and said so.
    let o = run(&["--position-only"]);
    o.assert_ok();
    assert!(
        o.stderr()
            .contains("a,b,c columns (orientations) are not used"),
        "{}",
        o.stderr()
    );
    let (h, _) = read_csv(&out);
    assert!(!h.contains(&"residual_deg".to_string()));
    // Without a,b,c: position-only, with a note.
    let pos = dir.write("points.csv", "x,y,z\n2500,300,1500\n");
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--targets",
        p(&pos),
        "--out",
        p(&out),
    ]);
    o.assert_ok();
    assert!(o.stderr().contains("no a,b,c columns"), "{}", o.stderr());
    // Some but not all of a,b,c: exit 3 naming the file, line and column, nothing written.
    let half = dir.write("half.csv", "x,y,z,a,b\n2500,300,1500,0,90\n");
    let never = dir.join("never.csv");
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&res),
        "--targets",
        p(&half),
        "--out",
        p(&never),
    ]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("half.csv:1: field `c`: missing column"),
        "{}",
        o.stderr()
    );
    assert!(!never.exists());
}
