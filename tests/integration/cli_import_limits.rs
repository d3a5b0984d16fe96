//! `robocal import --robot` checks each paired point's joint values against the robot's limits
//! (issue 28): a value outside them is exit 3 naming the joint log's line and column, listing
//! every point outside, nothing written; `--nominal-limits` keeps them with a warning per point; a
//! joint log in radians read as degrees is caught (it stays inside any limits); the same log
//! with `--angle-unit rad` imports as the degrees file does; the same checks when pairing by time
//! (a dwell's lines).

use crate::util::*;
use std::path::Path;

const POINTS: &str = "import/kr480-points.csv";
const JOINTS: &str = "import/kr480-joints.csv";

fn import(dir: &Dir, joints: &Path, extra: &[&str]) -> (Outcome, std::path::PathBuf) {
    let out = dir.join("imported.csv");
    let _ = std::fs::remove_file(&out);
    let points = example(POINTS);
    let mut a = vec![
        "import",
        "--points",
        &points,
        "--joints",
        p(joints),
        "--match",
        "name",
        "--robot",
        KUKA,
        "--out",
        p(&out),
    ];
    a.extend_from_slice(extra);
    (robocal(&a), out)
}

/// The shipped joint CSV with each joint value mapped by `f(row, joint, value)`.
fn joints_with(f: impl Fn(usize, usize, f64) -> String) -> String {
    let text = std::fs::read_to_string(example(JOINTS)).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for (r, l) in lines.enumerate() {
        let cells: Vec<&str> = l.split(',').collect();
        let q: Vec<String> = cells[1..]
            .iter()
            .enumerate()
            .map(|(j, v)| f(r, j, num(v)))
            .collect();
        out.push_str(&format!("{},{}\n", cells[0], q.join(",")));
    }
    out
}

#[test]
fn joint_values_outside_the_limits_are_refused_or_listed() {
    let dir = Dir::new();
    // The shipped files are within the KR 480's limits.
    let (o, out) = import(&dir, Path::new(&example(JOINTS)), &[]);
    o.assert_code(0);
    assert!(
        out.is_file() && !o.stdout().contains("warning"),
        "{}",
        o.stdout()
    );

    // q2 of the points on lines 3 and 7 beyond its upper limit (20 deg), q5 of line 7 too.
    let bad = dir.write(
        "bad.csv",
        joints_with(|r, j, v| match (r, j) {
            (1, 1) => "25".into(),
            (5, 1) => "21.5".into(),
            (5, 4) => "-121".into(),
            _ => format!("{v}"),
        }),
    );
    let (o, out) = import(&dir, &bad, &[]);
    o.assert_code(3);
    let e = o.stderr();
    for s in [
        "bad.csv:3: field `q2`",
        "25 deg is outside the joint limits of robot `kuka-kr480-r3330` (q2: -130..20 deg)",
        "2 of the 30 paired points are outside",
        "line 7: q2 = 21.5 deg",
        "line 7: q5 = -121 deg (limits -120..120)",
        "--nominal-limits",
        "--angle-unit",
    ] {
        assert!(e.contains(s), "expected `{s}` in: {e}");
    }
    assert!(!out.exists(), "written despite the error");

    // Nominal limits: kept, one warning per value outside.
    let (o, out) = import(&dir, &bad, &["--nominal-limits"]);
    o.assert_code(0);
    let stdout = o.stdout();
    let warned: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("warning: "))
        .collect();
    assert_eq!(warned.len(), 3, "{stdout}");
    assert!(warned[0].contains("bad.csv: line 3: q2 = 25 deg (limits -130..20)"));
    assert!(warned[2].contains("line 7: q5 = -121 deg") && warned[2].contains("nominal"));
    let written = std::fs::read_to_string(&out).unwrap();
    assert!(
        written.lines().any(|l| l.contains(",25.000000000,")),
        "{written}"
    );
}

#[test]
fn a_log_in_radians_read_as_degrees_is_caught() {
    let dir = Dir::new();
    let rad = dir.write(
        "rad.csv",
        joints_with(|_, _, v| format!("{}", v.to_radians())),
    );
    let (o, out) = import(&dir, &rad, &[]);
    o.assert_code(3);
    let e = o.stderr();
    for s in [
        "rad.csv:1: field `q1`",
        "every revolute joint value of the 30 paired rows lies within ±",
        "radians read as degrees",
        "--angle-unit",
    ] {
        assert!(e.contains(s), "expected `{s}` in: {e}");
    }
    assert!(!out.exists());
    // Read as radians, it is the degrees file (to the 9 decimals written).
    let (o, out) = import(&dir, &rad, &["--angle-unit", "rad"]);
    o.assert_code(0);
    let from_rad = std::fs::read_to_string(&out).unwrap();
    let (o2, out2) = import(&dir, Path::new(&example(JOINTS)), &[]);
    o2.assert_code(0);
    let from_deg = std::fs::read_to_string(&out2).unwrap();
    for (a, b) in from_rad.lines().zip(from_deg.lines()).skip(1) {
        let (a, b): (Vec<&str>, Vec<&str>) = (a.split(',').collect(), b.split(',').collect());
        for k in 0..6 {
            assert!((num(a[k]) - num(b[k])).abs() < 1e-8, "{a:?} vs {b:?}");
        }
    }
    // Said to be degrees: kept, with a warning.
    let (o, _) = import(&dir, &rad, &["--angle-unit", "deg"]);
    o.assert_code(0);
    assert!(
        o.stdout().contains("warning: ") && o.stdout().contains("radians read as degrees"),
        "{}",
        o.stdout()
    );
    // Degrees read as radians: far outside the limits.
    let (o, _) = import(&dir, Path::new(&example(JOINTS)), &["--angle-unit", "rad"]);
    o.assert_code(3);
    assert!(o.stderr().contains("kr480-joints.csv:2:"), "{}", o.stderr());
}

#[test]
fn pairing_by_time_checks_each_dwell() {
    let dir = Dir::new();
    // The shipped RTDE log with its first dwell's joint 2 (actual_q_1) past -130 deg.
    let log = std::fs::read_to_string(example("import/kr480-rtde.txt")).unwrap();
    let mut lines: Vec<String> = log.lines().map(String::from).collect();
    let first: Vec<String> = lines[1].split(' ').map(String::from).collect();
    let mut changed = Vec::new();
    for (i, l) in lines.iter_mut().enumerate().skip(1) {
        let mut cells: Vec<String> = l.split(' ').map(String::from).collect();
        if cells[2..8] != first[2..8] {
            break;
        }
        cells[3] = format!("{}", (-131.0f64).to_radians());
        *l = cells.join(" ");
        changed.push(i + 1);
    }
    assert!(changed.len() > 10, "the log starts with a dwell");
    let f = dir.write("rtde.txt", lines.join("\n") + "\n");
    let out = dir.join("timed.csv");
    let o = robocal(&[
        "import",
        "--points",
        &example("import/kr480-timed-leica.csv"),
        "--joints",
        p(&f),
        "--match",
        "time",
        "--robot",
        KUKA,
        "--out",
        p(&out),
    ]);
    o.assert_code(3);
    let e = o.stderr();
    assert!(
        e.contains(&format!("rtde.txt:{}: field `actual_q_1`", changed[0]))
            && e.contains("-131 deg is outside")
            && e.contains(&format!("dwell of lines {}-", changed[0])),
        "{e}"
    );
    assert!(!out.exists());
}
