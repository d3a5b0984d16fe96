use super::seed::{branch_joints, BranchJoints};
use super::seed::{krl_status, rapid_conf};
use super::*;
use crate::compensation::{Compensator, DampedLeastSquares, PoseNewton};
use crate::model::presets::preset;
use crate::model::robot_file::parse_robot_toml;
use crate::model::Robot;
use crate::simulation::{random_poses, GeometricErrors, PoseSampler};
use rand::SeedableRng;

fn kuka() -> (Robot, Robot) {
    (
        preset("kuka-kr480-r3330").unwrap(),
        preset("kuka-kr480-r3330-table3").unwrap(),
    )
}

fn example(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

fn robot_file(name: &str) -> Robot {
    let p = example(name);
    parse_robot_toml(&std::fs::read_to_string(&p).unwrap(), &p).unwrap()
}

/// A calibrated model of `nominal`: random geometric errors (0.5 mm, 0.05 deg).
fn perturbed(nominal: &Robot, seed: u64) -> Robot {
    let e = GeometricErrors {
        length_sigma_mm: 0.5,
        angle_sigma_deg: 0.05,
        tilt_parallel_axes: false,
    };
    e.apply(nominal, &mut rand_chacha::ChaCha8Rng::seed_from_u64(seed))
        .unwrap()
}

/// Axis values (deg) of the KUKA fixture's targets.
const AXES: [[f64; 6]; 3] = [
    [0.0, -90.0, 90.0, 0.0, 45.0, 0.0],
    [20.0, -60.0, 70.0, 30.0, 50.0, -40.0],
    [-35.0, -75.0, 100.0, -20.0, -60.0, 80.0],
];

/// A KRL program with joint and Cartesian targets at `AXES` (the Cartesian ones from the
/// nominal model, with their S and T), comments, blank lines, odd spacing, a `$BASE` frame and a
/// relative motion that must stay untouched.
pub(crate) fn krl_program(nominal: &Robot) -> String {
    let js = nominal.joint_space();
    let mut s = String::from(
        "&ACCESS RVP\r\nDEF demo( )\r\n; robocal example: joint and Cartesian targets\r\n\
         $BASE = {X 0.0, Y 0.0, Z 0.0, A 0.0, B 0.0, C 0.0}\r\n\r\n",
    );
    for (k, a) in AXES.iter().enumerate() {
        s += &format!(
            "PTP {{A1 {}, A2 {},A3 {}, A4  {}, A5 {}, A6 {}}} C_PTP ; joint target {k}\r\n",
            a[0], a[1], a[2], a[3], a[4], a[5]
        );
        let q = js.joints_from_axes(a);
        let v = krl::pose_values(&nominal.tool_pose(&q));
        s += &format!(
            "LIN {{E6POS: X {:.3}, Y {:.3}, Z {:.3}, A {:.3}, B {:.3}, C {:.3}, S 'B{:03b}', \
             T {}, E1 0.0}}\r\n",
            v[0],
            v[1],
            v[2],
            v[3],
            v[4],
            v[5],
            krl_status(nominal, &q).unwrap(),
            turn_of(nominal, &q)
        );
    }
    s += "END\r\n";
    s
}

/// Axis values (deg) of the ABB-like fixture's targets.
const ABB_AXES: [[f64; 6]; 3] = [
    [0.0, 0.0, 0.0, 0.0, 30.0, 0.0],
    [-25.0, 20.0, -10.0, 100.0, -50.0, -200.0],
    [150.0, -30.0, 20.0, -45.0, 60.0, 95.0],
];

/// A RAPID module with declared and inline joint and Cartesian targets (the Cartesian ones from
/// the nominal model, with their confdata), a tooldata and comments.
pub(crate) fn rapid_program(nominal: &Robot) -> String {
    let js = nominal.joint_space();
    let ext = "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]";
    let mut s = String::from(
        "MODULE demo\n  ! robocal example: joint and Cartesian targets\n  \
         PERS tooldata gun := [TRUE,[[0,0,250],[1,0,0,0]],[5,[0,0,100],[1,0,0,0],0,0,0]];\n",
    );
    let mut moves = String::new();
    for (k, a) in ABB_AXES.iter().enumerate() {
        let q = js.joints_from_axes(a);
        let v = rapid::pose_values(&nominal.tool_pose(&q), &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        let c = rapid_conf(nominal, &q);
        let rob = format!(
            "[[{:.3},{:.3}, {:.3}],[{:.8},{:.8},{:.8},{:.8}],[{},{},{},{}],{ext}]",
            v[0], v[1], v[2], v[3], v[4], v[5], v[6], c[0], c[1], c[2], c[3]
        );
        let joints = format!(
            "[[{},{},{},{},{},{}],{ext}]",
            a[0], a[1], a[2], a[3], a[4], a[5]
        );
        if k == 1 {
            moves += &format!("    MoveAbsJ {joints}\\NoEOffs, v100, fine, tool0;\n");
            moves += &format!("    MoveL {rob}, v100, z10, gun\\WObj:=wobj0; ! inline\n\n");
        } else {
            s += &format!("  CONST jointtarget j{k} := {joints};\n");
            s += &format!("  CONST robtarget p{k}:={rob};\n");
            moves += &format!(
                "    MoveAbsJ j{k}, v100, fine, tool0;\n    MoveJ p{k}, v100, z10, gun;\n"
            );
        }
    }
    s + "\n  PROC main()\n" + &moves + "  ENDPROC\nENDMODULE\n"
}

/// Joint values (rad) of the UR5 fixture's joint targets.
const UR_JOINTS: [[f64; 6]; 3] = [
    [0.0, -1.6, 1.55, -1.5, -1.55, 0.0],
    [0.5, -1.2, 1.4, -1.7, -1.4, 0.3],
    [-0.8, -1.9, 2.0, -1.2, -1.7, -0.4],
];

/// A URScript program with joint and Cartesian targets: variables, literals, an offset pose
/// that must stay untouched, comments.
pub(crate) fn ur_program(nominal: &Robot) -> String {
    let js = nominal.joint_space();
    let mut s = String::from(
        "def demo():\n  # robocal example: joint and Cartesian targets\n  \
         offset = p[0, 0, 0.05, 0, 0, 0]\n",
    );
    for (k, j) in UR_JOINTS.iter().enumerate() {
        let list = format!(
            "[{}, {},{}, {}, {}, {}]",
            j[0], j[1], j[2], j[3], j[4], j[5]
        );
        let q = js.joints_from_axes(&j.map(f64::to_degrees));
        let v = urscript::pose_values(&nominal.tool_pose(&q), &[0.0; 6]);
        // No `-0.000000` for a component within rounding of zero.
        let v: Vec<f64> = v
            .iter()
            .map(|x| if x.abs() < 5e-7 { 0.0 } else { *x })
            .collect();
        let p = format!(
            "p[{:.6}, {:.6}, {:.6}, {:.6}, {:.6}, {:.6}]",
            v[0], v[1], v[2], v[3], v[4], v[5]
        );
        if k == 0 {
            s += &format!("  home = {list}\n  pick = {p}\n\n  movej(home, a=1.4, v=1.05)\n");
            s += "  movel(pick, a=1.2, v=0.25)\n";
        } else {
            s += &format!("  movej({list}, a=1.4, v=1.05)\n  movel({p}, a=1.2, v=0.25, r=0)\n");
        }
    }
    s + "end\n"
}

/// Compensates one program file.
pub(crate) fn run(
    path: &Path,
    text: &str,
    format: Format,
    comp: &Compensator<'_, DampedLeastSquares>,
    s: &ProgramSettings,
) -> CompensatedProgram {
    let src = [Source {
        path: path.to_owned(),
        text: text.to_owned(),
    }];
    compensate_program(&src, format, None, comp, s).unwrap()
}

/// The text outside the targets' numeric fields, in order.
pub(crate) fn outside_fields(text: &str, targets: &[ProgramTarget]) -> Vec<String> {
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

/// Random byte edits of `fixture`: the reader never panics, and every field it reads spans
/// exactly the number it reports.
pub(crate) fn edits_never_panic(format: Format, fixture: &str) {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let alphabet = b"{}[]():;,!#=\"' \n\r\t-+.eEp0123456789AXYZBCST$_";
    for _ in 0..3000 {
        let mut b = fixture.as_bytes().to_vec();
        for _ in 0..1 + next() % 6 {
            let at = (next() as usize) % (b.len() + 1);
            let c = alphabet[(next() as usize) % alphabet.len()];
            match next() % 3 {
                0 if at < b.len() => b[at] = c,
                1 if at < b.len() => {
                    b.remove(at);
                }
                _ => b.insert(at, c),
            }
        }
        let text = String::from_utf8_lossy(&b);
        // The motion census reads any text.
        match format {
            Format::Krl => drop(census_krl::motions(&text, Some(&text), None)),
            Format::Rapid => drop(census_rapid::motions(&text)),
            Format::UrScript => drop(census_ur::motions(&text)),
        }
        if let Ok(ts) = format.targets(Path::new("f"), &text) {
            for t in ts {
                for f in &t.fields {
                    assert_eq!(text[f.span.clone()].parse::<f64>().ok(), Some(f.value));
                }
            }
        }
    }
}

/// Compensates `text` and checks the Must-show properties: every target applied; (a) every
/// written target, read back from the output as the controller reads it, puts the calibrated
/// tool on the desired pose within the documented tolerance (FK on the calibrated model);
/// (b) the output equals the input outside the replaced spans.
fn check_program(format: Format, nom: &Robot, cal: &Robot, text: &str) -> CompensatedProgram {
    let comp = Compensator::new(nom, cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings::default();
    let path = Path::new("fixture");
    let out = run(path, text, format, &comp, &s);
    let (tin, tout) = (
        format.targets(path, text).unwrap(),
        format.targets(path, &out.texts[0]).unwrap(),
    );
    assert_eq!(tin.len(), tout.len());
    assert_eq!(out.changes.len(), tin.len());
    assert_eq!(
        outside_fields(text, &tin),
        outside_fields(&out.texts[0], &tout)
    );
    assert!(
        out.unchanged_motions().next().is_none(),
        "{:?}",
        out.motions
    );
    let js = nom.joint_space();
    let mut previous: Option<Vec<f64>> = None;
    for ((c, t), t0) in out.changes.iter().zip(&tout).zip(&tin) {
        assert!(c.applied, "{c:?}");
        assert_eq!(c.status, IkStatus::Converged);
        let written: Vec<f64> = t.fields.iter().map(|f| f.value).collect();
        assert_eq!(written, c.new);
        let written: Vec<f64> = written
            .iter()
            .enumerate()
            .map(|(k, v)| format.precision(t.kind, k).stored(*v))
            .collect();
        let old: Vec<f64> = t0.fields.iter().map(|f| f.value).collect();
        let (desired, reached) = match t.kind {
            TargetKind::Joints => {
                let qd = js.joints_from_axes(&format.axes_of(&old));
                let qw = js.joints_from_axes(&format.axes_of(&written));
                (nom.tool_pose(&qd), qw)
            }
            TargetKind::Pose => {
                // What the controller does with the written pose: its nominal inverse
                // kinematics on the branch the written configuration data give.
                let b = t.branch(previous.as_deref());
                let BranchJoints::Found(q) =
                    branch_joints(nom, &PoseNewton::default(), &format.pose_of(&written), &b)
                else {
                    panic!("{}: the written pose is not on its branch", c.name)
                };
                (format.pose_of(&old), q)
            }
        };
        // RAPID: the tool `gun` (the robot description's tool) as given, on the calibrated flange.
        let actual = match (format, t.kind) {
            (Format::Rapid, TargetKind::Pose) => {
                cal.tool_pose(&reached) * cal.tool_frame().inverse() * nom.tool_frame()
            }
            _ => cal.tool_pose(&reached),
        };
        let (dp, dw) = pose_distance(&actual, &desired);
        assert!(
            dp < s.verify_mm && dw < s.verify_deg,
            "{} line {}: {dp} mm {dw} deg",
            c.name,
            c.line
        );
        assert!(c.correction_mm > 0.05, "{c:?}");
        previous = Some(reached);
    }
    out
}

#[test]
fn a_krl_program_is_compensated_target_by_target_and_kept_byte_for_byte() {
    let (nom, cal) = kuka();
    let out = check_program(Format::Krl, &nom, &cal, &krl_program(&nom));
    assert_eq!(out.changes.len(), 6);
}

#[test]
fn a_rapid_program_is_compensated_target_by_target_and_kept_byte_for_byte() {
    let nom = robot_file("programs/irb-like.toml");
    let cal = perturbed(&nom, 7);
    let text = rapid_program(&nom);
    let out = check_program(Format::Rapid, &nom, &cal, &text);
    assert_eq!(out.changes.len(), 6);
    // The confdata are kept.
    let (a, b) = (
        Format::Rapid.targets(Path::new("a"), &text).unwrap(),
        Format::Rapid
            .targets(Path::new("b"), &out.texts[0])
            .unwrap(),
    );
    assert!(a.iter().zip(&b).all(|(x, y)| x.conf == y.conf));
}

#[test]
fn a_urscript_program_is_compensated_target_by_target_and_kept_byte_for_byte() {
    let nom = robot_file("ur5.toml");
    let cal = perturbed(&nom, 3);
    let out = check_program(Format::UrScript, &nom, &cal, &ur_program(&nom));
    assert_eq!(out.changes.len(), 6);
}

/// Against its own nominal model nothing needs a change: every target is still solved and
/// verified, and the text stays byte for byte (numbers that do not change keep their text).
#[test]
fn targets_that_need_no_change_are_verified_and_keep_their_text() {
    let (nom, _) = kuka();
    let irb = robot_file("programs/irb-like.toml");
    let ur5 = robot_file("ur5.toml");
    for (format, robot, text) in [
        (Format::Krl, &nom, krl_program(&nom)),
        (Format::Rapid, &irb, rapid_program(&irb)),
        (Format::UrScript, &ur5, ur_program(&ur5)),
    ] {
        let comp = Compensator::new(robot, robot, DampedLeastSquares::default()).unwrap();
        let s = ProgramSettings::default();
        let out = run(Path::new("same"), &text, format, &comp, &s);
        assert_eq!(out.texts[0], text, "{format:?}");
        for c in &out.changes {
            assert!(c.applied && c.status == IkStatus::Converged, "{c:?}");
            assert!(
                c.verified_mm < s.verify_mm && c.verified_deg < s.verify_deg,
                "{c:?}"
            );
            assert!(c.correction_mm < 1e-3 && c.correction_deg < 1e-4, "{c:?}");
        }
    }
}

#[test]
fn position_only_compensation_puts_the_tool_point_on_target() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings {
        full_pose: false,
        ..ProgramSettings::default()
    };
    let out = run(Path::new("k"), &krl_program(&nom), Format::Krl, &comp, &s);
    assert!(out
        .changes
        .iter()
        .all(|c| c.applied && c.verified_mm < 0.01));
}

/// Cartesian targets written from random joints with their configuration data are read back
/// to the same joints: KRL S and T, RAPID confdata.
#[test]
fn cartesian_targets_come_back_on_their_branch() {
    let solver = PoseNewton::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for (robot, krl) in [
        (kuka().0, true),
        (robot_file("programs/irb-like.toml"), false),
    ] {
        let js = robot.joint_space();
        let mut checked = 0;
        let mut worst = 0.0f64;
        for q in random_poses(&robot, 300, &PoseSampler::default(), &mut rng).unwrap() {
            let axes = js.axes_from_joints(&q);
            let c = crate::compensation::configuration::configuration(&robot, &q).unwrap();
            if c.margin() < 0.05
                || axes
                    .iter()
                    .any(|a| a.abs() < 0.01 || (a / 90.0).fract().abs() < 1e-4)
            {
                continue;
            }
            let f = robot.tool_pose(&q);
            let branch = if krl {
                Branch::Krl {
                    status: krl_status(&robot, &q),
                    turn: Some(turn_of(&robot, &q)),
                }
            } else {
                Branch::Rapid(rapid_conf(&robot, &q))
            };
            let BranchJoints::Found(back) = branch_joints(&robot, &solver, &f, &branch) else {
                panic!("{axes:?}: not found on {branch:?}")
            };
            let err = q
                .iter()
                .zip(&back)
                .map(|(a, b)| (a - b).abs().to_degrees())
                .fold(0.0, f64::max);
            assert!(err < 1e-9, "{axes:?} ({branch:?}): {err} deg");
            worst = worst.max(err);
            checked += 1;
        }
        eprintln!(
            "{}: {checked} poses back on their branch, largest joint error {worst:.1e} deg",
            if krl { "KRL" } else { "RAPID" }
        );
        assert!(checked > 150, "{checked}");
    }
}

#[test]
fn the_kuka_home_position_has_status_b010() {
    let (nom, _) = kuka();
    let js = nom.joint_space();
    let home = js.joints_from_axes(&[0.0, -90.0, 90.0, 0.0, 45.0, 0.0]);
    assert_eq!(krl_status(&nom, &home), Some(0b010));
    // Overhead area, A5 negative.
    let q = js.joints_from_axes(&[0.0, -130.0, -20.0, 0.0, -45.0, 0.0]);
    assert_eq!(krl_status(&nom, &q), Some(0b101));
    let abb = robot_file("programs/irb-like.toml");
    let zero = abb
        .joint_space()
        .joints_from_axes(&[0.0, 0.0, 0.0, 0.0, 30.0, 0.0]);
    assert_eq!(rapid_conf(&abb, &zero), [0, 0, 0, 0]);
    let q = abb
        .joint_space()
        .joints_from_axes(&[-100.0, 0.0, 0.0, 185.0, -30.0, -1.0]);
    assert_eq!(rapid_conf(&abb, &q), [-2, 2, -1, 1]);
}

#[test]
fn a_target_that_cannot_be_compensated_is_left_unchanged_and_listed() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let text = "DEF far()\nLIN {X 9000, Y 0, Z 1000, A 0, B 90, C 0}\nEND\n";
    let s = ProgramSettings::default();
    let out = run(Path::new("far.src"), text, Format::Krl, &comp, &s);
    assert_eq!(out.texts[0], text);
    assert_eq!(out.changes.len(), 1);
    assert!(!out.changes[0].applied);
    assert_eq!(out.changes[0].status, IkStatus::Unreachable);
}

#[test]
fn shipped_example_programs_are_the_fixtures() {
    let (nom, _) = kuka();
    let irb = robot_file("programs/irb-like.toml");
    let ur5 = robot_file("ur5.toml");
    for (name, text) in [
        ("programs/kr480.src", krl_program(&nom)),
        ("programs/irb-like.mod", rapid_program(&irb)),
        ("programs/ur5.script", ur_program(&ur5)),
    ] {
        let path = example(name);
        if std::env::var_os("ROBOCAL_WRITE_EXAMPLE").is_some() {
            std::fs::write(&path, &text).unwrap();
            continue;
        }
        let shipped = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            shipped, text,
            "{name}: regenerate with ROBOCAL_WRITE_EXAMPLE=1"
        );
    }
}

/// A RAPID target in a declared work object for a declared tool: compensated through both
/// (FK on the calibrated model, the tool as given, after 32-bit rounding); the same target in
/// a work object declared elsewhere is left unchanged, "frame unknown".
#[test]
fn rapid_targets_are_mapped_through_their_tool_and_work_object() {
    use crate::frame::pose;
    let nom = robot_file("programs/irb-like.toml");
    let cal = perturbed(&nom, 9);
    let grip = pose(&[20.0, 0.0, 300.0, 0.0, 0.4, 0.0]);
    let w = pose(&[800.0, -300.0, 200.0, 0.5, 0.0, 0.0]) * pose(&[0.0, 0.0, 50.0, 0.0, 0.0, 0.0]);
    let q = nom
        .joint_space()
        .joints_from_axes(&[-25.0, 20.0, -10.0, 100.0, -50.0, -100.0]);
    let flange = nom.tool_pose(&q) * nom.tool_frame().inverse();
    let p = w.inverse() * flange * grip;
    let v = rapid::pose_values(&p, &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    let c = rapid_conf(&nom, &q);
    let q5 = nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, 0.5);
    let text = format!(
        "MODULE m\n  PERS tooldata grip := [TRUE,[[20,0,300],[{},0,{},0]],[5,[0,0,100],[1,0,0,0],0,0,0]];\n  \
         PERS wobjdata table := [FALSE,TRUE,\"\",[[800,-300,200],[{},{},{},{}]],[[0,0,50],[1,0,0,0]]];\n  \
         CONST robtarget pt := [[{},{},{}],[{},{},{},{}],[{},{},{},{}],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\n  \
         PROC main()\n    MoveL pt, v100, z10, grip\\WObj:=table;\n  ENDPROC\nENDMODULE\n",
        (0.2f64).cos(), (0.2f64).sin(), q5.w, q5.i, q5.j, q5.k,
        v[0], v[1], v[2], v[3], v[4], v[5], v[6], c[0], c[1], c[2], c[3]
    );
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings::default();
    let out = run(Path::new("m.mod"), &text, Format::Rapid, &comp, &s);
    assert!(out.changes[0].applied, "{:?}", out.changes);
    assert!(
        out.unchanged_motions().next().is_none(),
        "{:?}",
        out.motions
    );
    let t = &Format::Rapid
        .targets(Path::new("m.mod"), &out.texts[0])
        .unwrap()[0];
    let new: Vec<f64> = t.fields.iter().map(|f| f64::from(f.value as f32)).collect();
    let x = w * rapid::pose_of(&new) * grip.inverse() * nom.tool_frame();
    let BranchJoints::Found(qc) = branch_joints(&nom, &PoseNewton::default(), &x, &t.branch(None))
    else {
        panic!("not on its branch")
    };
    let real = cal.tool_pose(&qc) * cal.tool_frame().inverse() * grip;
    let (dp, dw) = pose_distance(&real, &(w * p));
    assert!(dp < 3e-4 && dw < 3e-5, "{dp} mm {dw} deg");
    assert!(out.changes[0].correction_mm > 0.05);
    // A work object this module does not declare.
    let other = text.replace("\\WObj:=table", "\\WObj:=fixture");
    let out = run(Path::new("m.mod"), &other, Format::Rapid, &comp, &s);
    assert_eq!(out.texts[0], other);
    let why = out.changes[0].skipped.as_deref().unwrap();
    assert!(
        why.contains("frame unknown") && why.contains("fixture"),
        "{why}"
    );
    assert_eq!(out.unchanged_motions().count(), 1);
}

/// `pose_trans(T, p[...])`, `pose_trans(p[...], T)` and `pose_add(T, p[...])` with literal
/// offsets: T is compensated so that the combination the controller computes lands on the
/// nominal combination on the calibrated robot; a variable offset stays computed at run time.
#[test]
fn urscript_targets_combined_with_literal_poses_are_compensated_through_the_offset() {
    use super::frames::Offset;
    let nom = robot_file("ur5.toml");
    let cal = perturbed(&nom, 5);
    let q = nom
        .joint_space()
        .joints_from_axes(&[20.0, -100.0, 80.0, -70.0, -90.0, 10.0]);
    let goal = nom.tool_pose(&q);
    let lit = |f: &crate::frame::Frame| {
        let v = urscript::pose_values(f, &[0.0; 6]);
        format!(
            "p[{:.9}, {:.9}, {:.9}, {:.9}, {:.9}, {:.9}]",
            v[0], v[1], v[2], v[3], v[4], v[5]
        )
    };
    let off = urscript::pose_of(&[0.01, -0.02, 0.05, 0.1, 0.0, -0.2]);
    let frame = urscript::pose_of(&[0.3, -0.2, 0.1, 0.0, 0.0, 0.4]);
    let offsets = [Offset::After(off), Offset::Before(frame), Offset::Add(off)];
    // Each target chosen so that its combination is `goal`.
    let t: Vec<String> = offsets.iter().map(|o| lit(&o.unapply(&goal))).collect();
    let text = format!(
        "def m():\n  a = {t0}\n  b = {t1}\n  movel(pose_trans(a, {o}), a=1.2, v=0.25)\n  \
         movel(pose_trans({f}, b), a=1.2)\n  \
         movej(get_inverse_kin(pose_add({t2}, {o}), qnear=[0,0,0,0,0,0]))\n  \
         o = {o}\n  movel(pose_trans(a, o))\nend\n",
        t0 = t[0],
        t1 = t[1],
        t2 = t[2],
        o = lit(&off),
        f = lit(&frame),
    );
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings::default();
    let path = Path::new("m.script");
    let out = run(path, &text, Format::UrScript, &comp, &s);
    let targets = Format::UrScript.targets(path, &out.texts[0]).unwrap();
    let names: Vec<&str> = targets.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["a", "b", "movej"], "{text}");
    // The last motion (a variable offset) is the only one left, named with its expression.
    let left: Vec<_> = out.unchanged_motions().collect();
    assert_eq!(left.len(), 1, "{:?}", out.motions);
    assert_eq!(left[0].motion.line, text.lines().count() - 1);
    // The offsets themselves keep their text.
    assert_eq!(out.texts[0].matches(&lit(&off)).count(), 3);
    assert!(out.texts[0].contains(&lit(&frame)));
    for (k, o) in offsets.iter().enumerate() {
        let c = &out.changes[k];
        assert!(c.applied && c.correction_mm > 0.05, "{c:?}");
        let v: Vec<f64> = targets[k].fields.iter().map(|f| f.value).collect();
        // What the controller does: the combination, solved on the nominal model.
        let x = o.apply(&urscript::pose_of(&v));
        let BranchJoints::Found(qw) = branch_joints(
            &nom,
            &PoseNewton::default(),
            &x,
            &Branch::Nearest(q.clone()),
        ) else {
            panic!("{o:?}: the written pose is not reached")
        };
        let (dp, dw) = pose_distance(&cal.tool_pose(&qw), &goal);
        assert!(dp < 1e-4 && dw < 1e-5, "{o:?}: {dp} mm {dw} deg");
    }
}
