//! The plan as a robot program: read back with robocal's own program readers, every format gives
//! the plan's commanded joints to the precision written, and the joints reach the commanded
//! poses on the plan's model; the motion census finds the five motions of a cycle.

use super::*;
use crate::model::presets::preset;
use crate::model::robot_file::parse_robot_toml;
use crate::programs::{census_krl, census_rapid, census_ur, Format, TargetKind};
use crate::Robot;
use std::path::Path;

fn ur5() -> Robot {
    parse_robot_toml(
        include_str!("../../../../examples/ur5.toml"),
        Path::new("examples/ur5.toml"),
    )
    .unwrap()
}

/// Largest difference (in units of the written precision) between the joints read back and the
/// plan's; and the largest position error (mm) of the read-back joints on `model`.
fn check_program(robot: &Robot, model: &Robot, plan: &Plan, format: Format) {
    let name = match format {
        Format::Krl => "iso.src",
        Format::Rapid => "iso.mod",
        Format::UrScript => "iso.script",
    };
    let prog = plan_program(plan, robot, format, DEFAULT_DWELL_S).unwrap();
    let path = Path::new(name);
    format.check_dialect(path, &prog.text).unwrap();
    let targets = format.targets(path, &prog.text).unwrap();
    assert_eq!(targets.len(), 5, "{}", prog.text);
    // KRL writes the targets inline in the cycle's order; RAPID and URScript declare P1..P5.
    let order: Vec<usize> = match format {
        Format::Krl => CYCLE_ORDER.to_vec(),
        _ => (1..=5).collect(),
    };
    for (t, pose) in targets.iter().zip(order) {
        assert_eq!(t.kind, TargetKind::Joints);
        let values: Vec<f64> = t.fields.iter().map(|f| f.value).collect();
        // The controller keeps the text as its number type: what the program reports.
        let kept: Vec<f64> = values
            .iter()
            .enumerate()
            .map(|(i, v)| format.precision(TargetKind::Joints, i).stored(*v))
            .collect();
        let axes = format.axes_of(&kept);
        assert_eq!(axes, prog.axes[pose - 1], "{format:?} P{pose}");
        let back = robot.joint_space().joints_from_axes(&axes);
        let want = &plan.joints[pose - 1];
        for (i, (b, w)) in robot
            .joints_to_display(&back)
            .iter()
            .zip(robot.joints_to_display(want))
            .enumerate()
        {
            // 32-bit floats keep 24 bits (half an ulp: 2^-24 relative); URScript 9 decimals
            // of a radian.
            let tol = match format {
                Format::UrScript => (0.5e-9f64).to_degrees() * 1.001,
                _ => w.abs().max(1e-30) * 2f64.powi(-24) * 1.001,
            };
            assert!(
                (b - w).abs() <= tol,
                "{format:?} P{pose} q{}: {b} read back, {w} planned (tol {tol})",
                i + 1
            );
        }
        let e = (model.tool_position(&back) - plan.poses[pose - 1].translation.vector).norm();
        assert!(
            e < 0.01,
            "{format:?} P{pose}: {e} mm from the commanded pose"
        );
    }
    let motions = match format {
        Format::Krl => census_krl::motions(&prog.text, None, None),
        Format::Rapid => census_rapid::motions(&prog.text),
        Format::UrScript => census_ur::motions(&prog.text),
    };
    assert_eq!(motions.len(), 5, "{format:?}");
    assert!(
        prog.text.contains(&format!("{}", plan.cycles)),
        "{}",
        prog.text
    );
}

#[test]
fn programs_read_back_give_the_plan_joints() {
    let s = PlanSettings {
        cycles: 7,
        ..PlanSettings::default()
    };
    let kr = preset("kuka-kr480-r3330").unwrap();
    let cal = preset("kuka-kr480-r3330-table3").unwrap();
    let ur = ur5();
    let before = make_plan(&kr, None, &s).unwrap();
    let after = make_plan(&kr, Some(&cal), &s).unwrap();
    let ur_plan = make_plan(&ur, None, &s).unwrap();
    for format in [Format::Krl, Format::Rapid, Format::UrScript] {
        check_program(&kr, &kr, &before, format);
        check_program(&kr, &cal, &after, format);
        check_program(&ur, &ur, &ur_plan, format);
    }
    // The KUKA controller map: A1 = -q1, so the written axis values are not the model joints.
    let p = plan_program(&before, &kr, Format::Krl, 1.5).unwrap();
    let q1 = kr.joints_to_display(&before.joints[0])[0];
    assert!((p.axes[0][0] + q1).abs() < 1e-3, "{} vs {q1}", p.axes[0][0]);
    assert!(p.text.contains("WAIT SEC 1.5 ; measure P1"), "{}", p.text);
    assert!(p.text.contains("FOR CYCLE = 1 TO 7"), "{}", p.text);
}

#[test]
fn program_settings_refused() {
    let kr = preset("kuka-kr480-r3330").unwrap();
    let plan = make_plan(
        &kr,
        None,
        &PlanSettings {
            cycles: 2,
            ..PlanSettings::default()
        },
    )
    .unwrap();
    for d in [-1.0, f64::NAN, 1e5] {
        let e = plan_program(&plan, &kr, Format::Rapid, d).unwrap_err();
        assert!(e.to_string().starts_with("dwell_s"), "{e}");
    }
    let track = parse_robot_toml(
        include_str!("../../../../examples/kr480-track.toml"),
        Path::new("examples/kr480-track.toml"),
    )
    .unwrap();
    assert_ne!(track.dof(), 6);
    let mut seven = plan.clone();
    seven.joints = vec![vec![0.0; track.dof()]; 5];
    let e = plan_program(&seven, &track, Format::Krl, 2.0).unwrap_err();
    assert!(e.to_string().starts_with("program_format"), "{e}");
}
