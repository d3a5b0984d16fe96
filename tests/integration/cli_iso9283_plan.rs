//! `robocal iso9283 plan`: the cube in the usable workspace (above the floor), the plan as a
//! robot program, and the test after calibration on the poses of the plan before it.

use crate::util::fixtures::cell;
use crate::util::*;

const KUKA: &str = "kuka-kr480-r3330";

/// The plan in the usable workspace and as a robot program: every corner of the cube above the
/// floor (`--floor-mm`), the program beside the CSV with the cycle's five joint motions; a
/// program the robot cannot take, or a format its extension contradicts, is refused with
/// nothing written.
#[test]
fn plan_floor_and_program() {
    let d = Dir::new();
    let plan = d.join("plan.csv");
    let prog = d.join("iso.src");
    let o = ok(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--cycles",
        "3",
        "--floor-mm",
        "1200",
        "--out",
        p(&plan),
        "--program",
        p(&prog),
        "--dwell-s",
        "3",
    ]);
    assert!(o.stdout().contains("KUKA KRL program"), "{}", o.stdout());
    let (h, rows) = read_csv(&plan);
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let (cx, cz) = (col("x_c"), col("z_c"));
    let zs: Vec<f64> = rows.iter().map(|r| r[cz].parse().unwrap()).collect();
    assert!(zs.iter().all(|z| *z >= 1200.0), "{zs:?}");
    // The cube's edge from P2..P5 (at 80 % of the half diagonal): its lowest corner too.
    let x: Vec<f64> = rows[..5].iter().map(|r| r[cx].parse().unwrap()).collect();
    let half_edge = (x[1] - x[0]).abs() / 0.8;
    assert!(zs[0] - half_edge >= 1200.0 - 1e-6, "{zs:?} {half_edge}");
    let text = std::fs::read_to_string(&prog).unwrap();
    assert!(text.contains("FOR CYCLE = 1 TO 3"), "{text}");
    assert_eq!(text.matches("PTP {AXIS:").count(), 5, "{text}");
    assert_eq!(text.matches("WAIT SEC 3").count(), 5, "{text}");

    // RAPID by its extension, URScript by the flag.
    let rapid = d.join("iso.mod");
    ok(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--cycles",
        "2",
        "--out",
        p(&plan),
        "--program",
        p(&rapid),
    ]);
    assert!(std::fs::read_to_string(&rapid)
        .unwrap()
        .contains("MoveAbsJ p1, v100, fine, tool0;"));
    let ur = d.join("iso.txt");
    ok(&[
        "iso9283",
        "plan",
        "--robot",
        &example("ur5.toml"),
        "--cycles",
        "2",
        "--out",
        p(&plan),
        "--program",
        p(&ur),
        "--program-format",
        "urscript",
    ]);
    assert!(std::fs::read_to_string(&ur).unwrap().contains("movej(p1)"));

    // Refused, nothing written: a format the extension contradicts (usage), an extension that
    // names none and no format (usage), a robot without six joints (bad input).
    let (plan2, prog2) = (d.join("p2.csv"), d.join("p2.mod"));
    let o = robocal(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--out",
        p(&plan2),
        "--program",
        p(&prog2),
        "--program-format",
        "krl",
    ]);
    o.assert_code(2);
    assert!(o.stderr().contains("--program-format"), "{}", o.stderr());
    let prog3 = d.join("p2.txt");
    let o = robocal(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--out",
        p(&plan2),
        "--program",
        p(&prog3),
    ]);
    o.assert_code(2);
    let prog4 = d.join("p2.src");
    let o = robocal(&[
        "iso9283",
        "plan",
        "--robot",
        &example("kr480-track.toml"),
        "--cycles",
        "2",
        "--out",
        p(&plan2),
        "--program",
        p(&prog4),
    ]);
    o.assert_code(3);
    assert!(o.stderr().contains("--program-format"), "{}", o.stderr());
    let o = robocal(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--out",
        p(&plan2),
        "--program",
        p(&prog4),
        "--dwell-s",
        "-1",
    ]);
    o.assert_code(3);
    assert!(o.stderr().contains("--dwell-s"), "{}", o.stderr());
    for f in [&plan2, &prog2, &prog3, &prog4] {
        assert!(!f.exists(), "{}", f.display());
    }
}

/// `--poses-from`: the test after calibration commands the poses of the plan before it (the
/// cube, P1..P5, the tool orientation), with the compensated joints.
#[test]
fn plan_poses_from_an_earlier_plan() {
    let d = Dir::new();
    let c = cell();
    let before = d.join("before.csv");
    let after = d.join("after.csv");
    ok(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--cycles",
        "2",
        "--out",
        p(&before),
    ]);
    let o = ok(&[
        "iso9283",
        "plan",
        "--params",
        p(&c.result),
        "--cycles",
        "3",
        "--poses-from",
        p(&before),
        "--out",
        p(&after),
    ]);
    assert!(o.stdout().contains(", as "), "{}", o.stdout());
    let (h, b) = read_csv(&before);
    let (_, a) = read_csv(&after);
    assert_eq!(a.len(), 15);
    let cols: Vec<usize> = ["x_c", "y_c", "z_c", "a_c", "b_c", "c_c"]
        .iter()
        .map(|n| h.iter().position(|c| c == n).unwrap())
        .collect();
    let q1 = h.iter().position(|c| c == "q1").unwrap();
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!(ra[1], rb[1], "the same pose order");
        for k in &cols {
            let (x, y): (f64, f64) = (ra[*k].parse().unwrap(), rb[*k].parse().unwrap());
            assert!((x - y).abs() < 1e-9, "{} {x} vs {y}", h[*k]);
        }
        assert_ne!(ra[q1], rb[q1], "compensated joints");
    }
    // Not with a cube of its own; not a file that is no plan.
    let none = d.join("none.csv");
    let o = robocal(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--poses-from",
        p(&before),
        "--center",
        "1,2,3",
        "--out",
        p(&none),
    ]);
    o.assert_code(2);
    let o = robocal(&[
        "iso9283",
        "plan",
        "--robot",
        KUKA,
        "--poses-from",
        p(&c.truth),
        "--out",
        p(&none),
    ]);
    o.assert_code(3);
    assert!(!none.exists());
}
