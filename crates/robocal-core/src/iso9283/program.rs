//! The test plan as a robot program: the N cycles of P1, P5, P4, P3, P2 as joint motions with an
//! exact stop and a dwell (the time the tracker needs to measure) at each pose, in KUKA KRL, ABB
//! RAPID or URScript.
//!
//! The joints are the plan's commanded ones ([`Plan::joints`]: nominal, or compensated on the
//! calibrated model) as controller axis values ([`crate::model::JointSpace::axes_from_joints`]: the KUKA presets'
//! signs; URScript in rad), written as precisely as the controller keeps them
//! ([`crate::programs::digits`]: 32-bit floats for KRL and RAPID, 9 decimals for URScript), so
//! that robocal's own program readers ([`Format::targets`]) give them back to that precision.
//! Each pose is one joint target (KRL: an `AXIS` aggregate in each `PTP`; RAPID: a `CONST
//! jointtarget` per pose moved to with `MoveAbsJ ... fine`; URScript: a joint list per pose given
//! to `movej`), visited in a loop over the cycles. Speeds, accelerations, the tool and the base
//! are the controller's defaults (KRL: the `$VEL_AXIS` in force; RAPID `v100`, `tool0`;
//! URScript `movej`'s defaults): ISO 9283 asks for the test at the rated load and speed the
//! integrator chooses, which only the cell knows.

use super::plan::{Plan, CYCLE_ORDER};
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::programs::{Format, TargetKind};
use std::fmt::Write as _;

/// The default dwell at each pose (s): the robot settles and the tracker measures.
pub const DEFAULT_DWELL_S: f64 = 2.0;

/// Number of axes of the formats' joint targets.
const AXES: usize = 6;

/// A plan's program: the text, and the commanded controller axis values of P1..P5 (display
/// units: deg, or mm for a prismatic axis) as written.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanProgram {
    /// The program text.
    pub text: String,
    /// The format.
    pub format: Format,
    /// P1..P5's controller axis values as the controller keeps the written text.
    pub axes: Vec<Vec<f64>>,
}

/// Writes `plan` for `robot` (the nominal robot, whose controller map turns joints into axis
/// values) as a program of `format`, dwelling `dwell_s` seconds at every pose. Fails, naming the
/// setting, for a robot without six joints (the formats' joint targets have six axes) or a dwell
/// outside 0..=3600 s.
pub fn plan_program(
    plan: &Plan,
    robot: &Robot,
    format: Format,
    dwell_s: f64,
) -> Result<PlanProgram> {
    if robot.dof() != AXES {
        return Err(Error::invalid(
            "program_format",
            format!(
                "{} joint targets have {AXES} axes; the robot has {} joints",
                format.name(),
                robot.dof()
            ),
        ));
    }
    if !(dwell_s.is_finite() && (0.0..=3600.0).contains(&dwell_s)) {
        return Err(Error::invalid(
            "dwell_s",
            format!("{dwell_s} is not a dwell in 0..=3600 s"),
        ));
    }
    let mut axes = Vec::with_capacity(5);
    let mut written = Vec::with_capacity(5);
    for q in &plan.joints {
        let values = format.joint_values(&robot.joint_space().axes_from_joints(q));
        let text: Vec<String> = values
            .iter()
            .enumerate()
            .map(|(i, v)| format.precision(TargetKind::Joints, i).write(*v))
            .collect();
        let kept: Vec<f64> = values
            .iter()
            .enumerate()
            .map(|(i, v)| format.precision(TargetKind::Joints, i).written(*v))
            .collect();
        axes.push(format.axes_of(&kept));
        written.push(text);
    }
    let header = header(plan, robot);
    let text = match format {
        Format::Krl => krl(plan, &header, &written, dwell_s),
        Format::Rapid => rapid(plan, &header, &written, dwell_s),
        Format::UrScript => urscript(plan, &header, &written, dwell_s),
    };
    Ok(PlanProgram { text, format, axes })
}

/// The comment lines that open every program (without the comment marker).
fn header(plan: &Plan, robot: &Robot) -> Vec<String> {
    let c = plan.cube.centre;
    let order: Vec<String> = CYCLE_ORDER.iter().map(|p| format!("P{p}")).collect();
    vec![
        format!(
            "ISO 9283 pose accuracy and repeatability test: {} cycles of {}",
            plan.cycles,
            order.join(", ")
        ),
        format!(
            "written by robocal iso9283 plan for robot {}, {} joints",
            robot.name(),
            if plan.compensated {
                "compensated"
            } else {
                "nominal"
            }
        ),
        format!(
            "cube: edge {:.3} mm, centre ({:.3}, {:.3}, {:.3}) mm in the base frame",
            plan.cube.edge_mm, c.x, c.y, c.z
        ),
        "measure the tool point at every dwell; speeds, tool and base: set them for the test"
            .to_owned(),
    ]
}

fn seconds(s: f64) -> String {
    let t = format!("{s:.3}");
    t.trim_end_matches('0').trim_end_matches('.').to_owned()
}

fn krl(plan: &Plan, header: &[String], joints: &[Vec<String>], dwell_s: f64) -> String {
    let mut out = String::from("&ACCESS RVP\nDEF iso9283( )\n");
    for h in header {
        let _ = writeln!(out, "; {h}");
    }
    out.push_str("DECL INT CYCLE\n");
    let _ = writeln!(out, "FOR CYCLE = 1 TO {}", plan.cycles);
    for p in CYCLE_ORDER {
        let members: Vec<String> = joints[p - 1]
            .iter()
            .enumerate()
            .map(|(i, v)| format!("A{} {v}", i + 1))
            .collect();
        let _ = writeln!(out, "  PTP {{AXIS: {}}} ; P{p}", members.join(", "));
        let _ = writeln!(out, "  WAIT SEC {} ; measure P{p}", seconds(dwell_s));
    }
    out.push_str("ENDFOR\nEND\n");
    out
}

fn rapid(plan: &Plan, header: &[String], joints: &[Vec<String>], dwell_s: f64) -> String {
    let mut out = String::from("MODULE iso9283\n");
    for h in header {
        let _ = writeln!(out, "  ! {h}");
    }
    for (k, j) in joints.iter().enumerate() {
        let _ = writeln!(
            out,
            "  CONST jointtarget p{} := [[{}],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];",
            k + 1,
            j.join(",")
        );
    }
    out.push_str("\n  PROC main()\n");
    let _ = writeln!(out, "    FOR cycle FROM 1 TO {} DO", plan.cycles);
    for p in CYCLE_ORDER {
        let _ = writeln!(out, "      MoveAbsJ p{p}, v100, fine, tool0;");
        let _ = writeln!(out, "      WaitTime {}; ! measure P{p}", seconds(dwell_s));
    }
    out.push_str("    ENDFOR\n  ENDPROC\nENDMODULE\n");
    out
}

fn urscript(plan: &Plan, header: &[String], joints: &[Vec<String>], dwell_s: f64) -> String {
    let mut out = String::from("def iso9283():\n");
    for h in header {
        let _ = writeln!(out, "  # {h}");
    }
    for (k, j) in joints.iter().enumerate() {
        let _ = writeln!(out, "  p{} = [{}]", k + 1, j.join(", "));
    }
    out.push_str("  cycle = 0\n");
    let _ = writeln!(out, "  while cycle < {}:", plan.cycles);
    for p in CYCLE_ORDER {
        let _ = writeln!(out, "    movej(p{p})");
        let _ = writeln!(out, "    sleep({}) # measure P{p}", seconds(dwell_s));
    }
    out.push_str("    cycle = cycle + 1\n  end\nend\n");
    out
}
