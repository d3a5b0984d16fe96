//! `robocal compensate --program`: KUKA KRL, ABB RAPID and URScript programs with joint and
//! Cartesian targets, compensated end to end. Every written target is checked here by forward
//! kinematics on the calibrated model (as the controller reads it back), and the rest of each
//! file is byte-identical; the exit codes, `--keep-going` and `--changes`.

use crate::util::library::*;
use crate::util::*;
use rand::SeedableRng;
use robocal_core::compensation::PoseNewton;
use robocal_core::frame::TrackerFrame;
use robocal_core::programs::seed::{branch_joints, BranchJoints};
use robocal_core::programs::{pose_distance, Format, ProgramTarget, TargetKind};
use robocal_core::simulation::GeometricErrors;
use robocal_core::{load_robot_file, preset, Robot};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The nominal robot of a shipped program, its calibrated model (KUKA: Table III; the others:
/// random geometric errors of 0.5 mm and 0.05 deg) and a result file for them in `dir`.
fn models(dir: &Dir, program: &str) -> (Robot, Robot, PathBuf) {
    let (nom, cal) = match program {
        "kr480.src" => (preset(KUKA).unwrap(), preset(TRUTH).unwrap()),
        _ => {
            let file = if program.ends_with(".mod") {
                "examples/programs/irb-like.toml"
            } else {
                "examples/ur5.toml"
            };
            let nom = load_robot_file(&root().join(file)).unwrap();
            let e = GeometricErrors {
                length_sigma_mm: 0.5,
                angle_sigma_deg: 0.05,
                tilt_parallel_axes: false,
            };
            let cal = e
                .apply(&nom, &mut rand_chacha::ChaCha8Rng::seed_from_u64(5))
                .unwrap();
            (nom, cal)
        }
    };
    let res = dir.join("result.json");
    result_for(&nom, &cal, &TrackerFrame::identity())
        .write(&res)
        .unwrap();
    (nom, cal, res)
}

fn shipped(name: &str) -> PathBuf {
    root().join("examples/programs").join(name)
}

/// The text outside the targets' replaced spans (numbers and KRL turns), in order.
fn outside(text: &str, targets: &[ProgramTarget]) -> Vec<String> {
    let mut spans: Vec<Range<usize>> = targets
        .iter()
        .flat_map(|t| t.fields.iter().map(|f| f.span.clone()))
        .chain(targets.iter().filter_map(|t| t.turn_span.clone()))
        .collect();
    spans.sort_by_key(|r| r.start);
    let mut out = Vec::new();
    let mut at = 0;
    for r in spans {
        out.push(text[at..r.start].to_owned());
        at = r.end;
    }
    out.push(text[at..].to_owned());
    out
}

/// Compensates a shipped program through the CLI and checks every target of the output by
/// forward kinematics on the calibrated model, and the bytes outside the replaced spans.
fn program_round_trip(name: &str) {
    let dir = Dir::new();
    let (nom, cal, res) = models(&dir, name);
    let input = shipped(name);
    let out = dir.join(format!("out-{name}"));
    let changes = dir.join("changes.csv");
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&input),
        "--out",
        p(&out),
        "--changes",
        p(&changes),
    ]);
    o.assert_ok();
    let format = Format::from_path(&input).unwrap();
    let text_in = std::fs::read_to_string(&input).unwrap();
    let text_out = std::fs::read_to_string(&out).unwrap();
    let tin = format.targets(&input, &text_in).unwrap();
    let tout = format.targets(&out, &text_out).unwrap();
    assert_eq!(tin.len(), 6, "{name}");
    assert_eq!(tout.len(), tin.len());
    assert_eq!(outside(&text_in, &tin), outside(&text_out, &tout), "{name}");
    let js = nom.joint_space();
    let mut previous: Option<Vec<f64>> = None;
    for (a, b) in tin.iter().zip(&tout) {
        let old: Vec<f64> = a.fields.iter().map(|f| f.value).collect();
        let new: Vec<f64> = b.fields.iter().map(|f| f.value).collect();
        assert_ne!(old, new, "{name}: {} line {} unchanged", a.name, a.line);
        let (desired, reached) = match a.kind {
            TargetKind::Joints => (
                nom.tool_pose(&js.joints_from_axes(&format.axes_of(&old))),
                js.joints_from_axes(&format.axes_of(&new)),
            ),
            TargetKind::Pose => {
                // The controller's nominal inverse kinematics of the written pose, on the branch
                // its configuration data (or the previous joints) give.
                let branch = b.branch(previous.as_deref());
                let found =
                    branch_joints(&nom, &PoseNewton::default(), &format.pose_of(&new), &branch);
                let BranchJoints::Found(q) = found else {
                    panic!("{name}: {} line {}: {found:?}", b.name, b.line)
                };
                (format.pose_of(&old), q)
            }
        };
        let (dp, dw) = pose_distance(&cal.tool_pose(&reached), &desired);
        assert!(
            dp < 0.01 && dw < 0.001,
            "{name}: {} line {}: {dp} mm {dw} deg",
            a.name,
            a.line
        );
        // Listed with its line.
        assert!(
            o.stdout()
                .contains(&format!("{:<16} {:>6}", a.name, a.line)),
            "{}",
            o.stdout()
        );
        previous = Some(reached);
    }
    assert!(
        o.stdout().contains("6 compensated, 0 left unchanged"),
        "{}",
        o.stdout()
    );
    let csv = std::fs::read_to_string(&changes).unwrap();
    assert_eq!(csv.lines().count(), 7, "{csv}");
}

#[test]
fn a_krl_program_is_compensated_and_checked_by_fk() {
    program_round_trip("kr480.src");
}

#[test]
fn a_rapid_program_is_compensated_and_checked_by_fk() {
    program_round_trip("irb-like.mod");
}

#[test]
fn a_urscript_program_is_compensated_and_checked_by_fk() {
    program_round_trip("ur5.script");
}

/// The KRL example with a target out of reach on line 14.
fn with_unreachable(dir: &Dir) -> PathBuf {
    let mut text = std::fs::read_to_string(shipped("kr480.src")).unwrap();
    let end = text.rfind("END").unwrap();
    text.insert_str(
        end,
        "LIN {X 9000, Y 0, Z 1000, A 0, B 90, C 0} ; too far\r\n",
    );
    dir.write("far.src", text)
}

#[test]
fn a_target_that_cannot_be_compensated_stops_the_run_unless_keep_going() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "kr480.src");
    let input = with_unreachable(&dir);
    let line = std::fs::read_to_string(&input)
        .unwrap()
        .lines()
        .position(|l| l.contains("9000"))
        .unwrap()
        + 1;
    let out = dir.join("out.src");
    let changes = dir.join("changes.csv");
    let args = |extra: &[&str]| {
        let mut v = vec![
            "compensate",
            "--params",
            p(&res),
            "--program",
            p(&input),
            "--out",
            p(&out),
            "--changes",
            p(&changes),
        ];
        v.extend_from_slice(extra);
        v.iter().map(|s| s.to_string()).collect::<Vec<String>>()
    };
    let o = robocal(&args(&[]));
    o.assert_code(5);
    assert!(
        o.stderr()
            .contains(&format!("LIN (line {line}): unreachable")),
        "{}",
        o.stderr()
    );
    assert!(!out.exists() && !changes.exists(), "nothing written");

    let o = robocal(&args(&["--keep-going"]));
    o.assert_ok();
    assert!(o.stdout().contains("left unchanged"), "{}", o.stdout());
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("LIN {X 9000, Y 0, Z 1000, A 0, B 90, C 0} ; too far"));
    let csv = std::fs::read_to_string(&changes).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0],
        [
            "name",
            "line",
            "kind",
            "status",
            "applied",
            "correction_mm",
            "correction_deg",
            "verified_mm",
            "verified_deg",
            "old",
            "new"
        ]
    );
    assert_eq!(rows.len(), 8);
    let far = &rows[7];
    assert_eq!(
        far[..5],
        ["LIN", &line.to_string(), "pose", "unreachable", "false"]
    );
    assert_eq!(far[5], "");
    assert_eq!(far[9], "9000 0 1000 0 90 0");
    assert_eq!(far[9], far[10]);
    for r in &rows[1..7] {
        assert_eq!(r[4], "true", "{r:?}");
        let corr: f64 = r[5].parse().unwrap();
        let verified: f64 = r[7].parse().unwrap();
        assert!(corr > 0.1 && verified < 0.01, "{r:?}");
        assert_eq!(r[9].split(' ').count(), 6);
        assert_ne!(r[9], r[10]);
    }
    // The joint targets: the new values as written in the program.
    let t = Format::Krl.targets(&out, &text).unwrap();
    let written: Vec<String> = t[0].fields.iter().map(|f| f.value.to_string()).collect();
    assert_eq!(rows[1][10], written.join(" "));
}

#[test]
fn bad_program_arguments_are_refused() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "kr480.src");
    let input = dir.write("prog.src", std::fs::read(shipped("kr480.src")).unwrap());
    // The output over the input.
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&input),
        "--out",
        p(&input),
    ]);
    o.assert_code(2);
    assert!(o.stderr().contains("--out"), "{}", o.stderr());
    // An unknown extension.
    let txt = dir.write("prog.txt", "PTP {A1 0}\n");
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&txt),
        "--out",
        p(&dir.join("o.txt")),
    ]);
    o.assert_code(2);
    assert!(o.stderr().contains("--program"), "{}", o.stderr());
    assert!(!dir.join("o.txt").exists());
    // Exclusive with the other inputs.
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&input),
        "--joints",
        p(&input),
        "--out",
        p(&dir.join("o.src")),
    ]);
    o.assert_code(2);
    // `--changes` and `--keep-going` need a program.
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--joints",
        p(&input),
        "--out",
        p(&dir.join("o.csv")),
        "--keep-going",
    ]);
    o.assert_code(2);
    // A malformed target: exit 3 naming the file and line.
    let bad = dir.write(
        "bad.src",
        "DEF m()\r\nPTP {A1 0, A2 -90, A3 x, A4 0, A5 30, A6 0}\r\nEND\r\n",
    );
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&bad),
        "--out",
        p(&dir.join("o.src")),
    ]);
    o.assert_code(3);
    assert!(o.stderr().contains("bad.src:2"), "{}", o.stderr());
    assert!(!dir.join("o.src").exists());
}

#[test]
fn position_only_applies_to_programs() {
    let dir = Dir::new();
    let (_, _, res) = models(&dir, "ur5.script");
    let out = dir.join("o.script");
    let o = robocal(&[
        "compensate",
        "--params",
        p(&res),
        "--program",
        p(&shipped("ur5.script")),
        "--out",
        p(&out),
        "--position-only",
    ]);
    o.assert_ok();
    assert!(o.stdout().contains("position only"), "{}", o.stdout());
    assert!(Path::new(&out).exists());
}
