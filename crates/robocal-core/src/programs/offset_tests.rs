//! A target used both directly and with an offset (URScript `pose_trans`/`pose_add`, KRL's
//! geometric operator `:`, RAPID `Offs`/`RelTool`): one value cannot be compensated for two
//! poses, so robocal refuses rather than compensating one use and letting the other move by a
//! correction meant for another pose. Each case leaves the motion with the offset unchanged,
//! its reason naming the target and the lines, so that the run stops (exit 5) unless
//! `--keep-going`.

use super::census::MotionOutcome;
use super::tests::{krl_program, rapid_program, run, ur_program};
use super::*;
use crate::compensation::{Compensator, DampedLeastSquares};
use crate::model::presets::preset;
use crate::model::robot_file::parse_robot_toml;
use crate::model::Robot;

fn robot_file(name: &str) -> Robot {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    parse_robot_toml(&std::fs::read_to_string(&p).unwrap(), &p).unwrap()
}

/// The reasons of the motions left unchanged, by line.
fn unchanged(out: &CompensatedProgram) -> Vec<(usize, String)> {
    out.unchanged_motions()
        .map(|m| match &m.outcome {
            MotionOutcome::Unchanged(w) => (m.motion.line, w.clone()),
            MotionOutcome::Compensated => unreachable!(),
        })
        .collect()
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn a_urscript_target_used_directly_and_with_an_offset_is_refused_with_both_lines() {
    let nom = robot_file("ur5.toml");
    let cal = nom.clone();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings::default();
    // The fixture's `pick` (used directly), now also used with a literal offset.
    let base = ur_program(&nom);
    let text = base.replace(
        "  movel(pick, a=1.2, v=0.25)\n",
        "  movel(pick, a=1.2, v=0.25)\n  movel(pose_trans(pick, p[0, 0, 0.05, 0, 0, 0]))\n",
    );
    assert_ne!(text, base);
    let out = run(Path::new("m.script"), &text, Format::UrScript, &comp, &s);
    let (direct, offset) = (
        line_of(&text, "movel(pick,"),
        line_of(&text, "pose_trans(pick"),
    );
    let pick = out.changes.iter().find(|c| c.name == "pick").unwrap();
    assert!(!pick.applied);
    let why = pick.skipped.as_deref().unwrap();
    assert_eq!(
        why,
        format!(
            "used both directly (line {direct}) and with an offset (line {offset}): one value \
             cannot be compensated for two poses; give the offset motion a target of its own"
        )
    );
    // Both motions are listed, each naming the target and the reason; the text keeps `pick`.
    let lines: Vec<usize> = unchanged(&out).iter().map(|(l, _)| *l).collect();
    assert_eq!(lines, [direct, offset]);
    assert!(unchanged(&out)
        .iter()
        .all(|(_, w)| w.contains("target pick") && w.contains("used both directly")));
    assert!(out.texts[0].contains(&text[text.find("pick = ").unwrap()..][..40]));
    // Two different offsets: refused the same way.
    let two = base.replace(
        "  movel(pick, a=1.2, v=0.25)\n",
        "  movel(pose_add(pick, p[0, 0, 0.05, 0, 0, 0]))\n  \
         movel(pose_trans(pick, p[0, 0, 0.05, 0, 0, 0]))\n",
    );
    let out = run(Path::new("m.script"), &two, Format::UrScript, &comp, &s);
    let pick = out.changes.iter().find(|c| c.name == "pick").unwrap();
    assert!(
        pick.skipped
            .as_deref()
            .unwrap()
            .starts_with("used with two different offsets"),
        "{pick:?}"
    );
}

#[test]
fn a_krl_point_used_with_the_geometric_operator_names_the_point_it_is_built_on() {
    let (nom, cal) = (
        preset("kuka-kr480-r3330").unwrap(),
        preset("kuka-kr480-r3330-table3").unwrap(),
    );
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings::default();
    // A declared point used directly, then with an offset in either order; an inline
    // aggregate as an operand.
    let base = krl_program(&nom);
    let first = base.find("LIN {E6POS:").unwrap();
    let end = first + base[first..].find('}').unwrap() + 1;
    let value = base[first + 4..end].replacen("E6POS: ", "", 1);
    let def = base.find("DEF demo( )\r\n").unwrap() + "DEF demo( )\r\n".len();
    let text = format!(
        "{}DECL E6POS XP1={value}\r\n{}PTP XP1\r\nLIN XP1 : {{X 100}}\r\n\
         LIN {{X 0,Y 0,Z 100,A 0,B 0,C 0}}:XP1 C_DIS\r\n{}",
        &base[..def],
        &base[def..first],
        &base[first..]
    );
    let out = run(Path::new("m.src"), &text, Format::Krl, &comp, &s);
    let xp1 = out.changes.iter().find(|c| c.name == "XP1").unwrap();
    assert!(xp1.applied, "{xp1:?}");
    let left = unchanged(&out);
    let decl = line_of(&text, "DECL E6POS XP1");
    for needle in ["LIN XP1 : {X 100}", "}:XP1 C_DIS"] {
        let l = line_of(&text, needle);
        let (_, why) = left
            .iter()
            .find(|(k, _)| *k == l)
            .unwrap_or_else(|| panic!("line {l} not listed: {left:?}"));
        assert!(
            why.contains(&format!("computed at run time from XP1 (line {decl})"))
                && why.contains("not for this one"),
            "{why}"
        );
    }
    // The operand aggregate is not compensated as if the robot went to it.
    let operand = out
        .changes
        .iter()
        .find(|c| c.line == line_of(&text, "}:XP1 C_DIS"));
    if let Some(c) = operand {
        assert!(!c.applied, "{c:?}");
        assert!(c
            .skipped
            .as_deref()
            .unwrap()
            .starts_with("part of an expression computed at run time"));
    }
    // The direct use stays compensated; only the operator motions are left.
    assert_eq!(left.len(), 2, "{left:?}");
}

#[test]
fn a_rapid_offs_of_a_declared_target_names_it() {
    let nom = robot_file("programs/irb-like.toml");
    let cal = nom.clone();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let s = ProgramSettings::default();
    let base = rapid_program(&nom);
    let text = base.replace(
        "  ENDPROC",
        "    MoveL Offs(p0, 0, 0, 100), v100, fine, tool0;\n    \
         MoveL RelTool(p0, 0, 0, -50), v100, fine, tool0;\n  ENDPROC",
    );
    let out = run(Path::new("m.mod"), &text, Format::Rapid, &comp, &s);
    let decl = line_of(&text, "CONST robtarget p0");
    let left = unchanged(&out);
    assert_eq!(left.len(), 2, "{left:?}");
    for (needle, (l, why)) in ["Offs(p0", "RelTool(p0"].iter().zip(&left) {
        assert_eq!(*l, line_of(&text, needle));
        assert!(
            why.contains(&format!("computed at run time from p0 (line {decl})")),
            "{why}"
        );
    }
}
