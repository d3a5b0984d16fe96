//! Robot programs: every target of a controller program replaced by its compensated value, in the
//! controller's own units and axis conventions, everything else kept byte for byte.
//!
//! A format's reader finds the targets and the byte spans of their numeric fields
//! ([`ProgramTarget`]); [`compensate_program`] compensates each (full pose by default, see
//! [`crate::compensation`]) and splices the new numbers into exactly those spans, so the text
//! outside them is unchanged. Formats: KUKA KRL ([`krl`]).
//!
//! - **Joint targets** (KRL AXIS/E6AXIS): the controller's axis values (deg) go through the
//!   robot's controller map ([`crate::model::JointSpace::joints_from_axes`]; the KUKA presets:
//!   q = (-A1, A2, A3, -A4, A5, -A6)) to the desired model joints; the commanded joints go back
//!   to axis values.
//! - **Cartesian targets** (KRL POS/E6POS/FRAME): the pose is taken as the tool frame (target 1,
//!   [`crate::Robot::tool_pose`]) in the robot's base frame; a `$BASE` or `$TOOL` set elsewhere
//!   in the program is not followed. The desired joints are the nominal model's inverse
//!   kinematics on the branch the target's turn `T` gives (bit i set: axis i+1 negative; `S` is
//!   kept as written); the compensated pose written is the nominal model's pose at the commanded
//!   joints, so that the controller, which believes the nominal model, drives the robot to the
//!   commanded joints. `S` is kept; `T` is kept where the commanded axes keep their signs, and
//!   follows an axis that compensation moves across 0 from within 1 degree of it (a target at
//!   A4 = 0 may need A4 = -0.002); any other sign change is another branch
//!   ([`IkStatus::ConfigurationChange`]).
//!
//! Numbers are written with [`ProgramSettings::decimals`] decimals, and every written target is
//! verified after rounding: read back as the controller would (joints, or the nominal inverse
//! kinematics of the written pose from the commanded joints), the calibrated model's tool must be
//! within [`ProgramSettings::verify_mm`] and [`ProgramSettings::verify_deg`] of the desired pose.

pub mod krl;

use crate::compensation::{Compensator, DampedLeastSquares, IkStatus, PoseNewton};
use crate::error::{Error, Result};
use crate::frame::{frame_vector, pose, Frame};
use crate::model::Robot;
use std::ops::Range;
use std::path::Path;

/// One numeric field of a target: its name in the program, its value, its byte span.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The field's name (`A1`, `X`, ...).
    pub name: String,
    /// Its value as written (controller units).
    pub value: f64,
    /// Its byte range in the program text.
    pub span: Range<usize>,
}

/// What a target holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetKind {
    /// Controller axis values.
    Joints,
    /// A Cartesian pose `x, y, z, a, b, c` (mm, deg).
    Pose,
}

/// A target found in a program.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramTarget {
    /// Its name (the variable it is declared as, or the motion command).
    pub name: String,
    /// 1-based line.
    pub line: usize,
    /// Joints or pose.
    pub kind: TargetKind,
    /// The numeric fields compensation replaces, in order (`A1..A6` or `X, Y, Z, A, B, C`).
    pub fields: Vec<Field>,
    /// KRL's turn `T`, when given.
    pub turn: Option<u32>,
    /// The byte range of the turn's value.
    pub turn_span: Option<Range<usize>>,
    /// KRL's status `S`, when given.
    pub status: Option<u32>,
}

/// A program format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// KUKA KRL (`.src`, `.dat`).
    Krl,
}

impl Format {
    /// The format of a program file, from its extension.
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("src") | Some("dat") => Ok(Format::Krl),
            _ => Err(Error::invalid(
                "program",
                format!(
                    "{}: unknown program format (KUKA KRL .src/.dat is supported)",
                    path.display()
                ),
            )),
        }
    }

    /// The targets of a program text.
    pub fn targets(self, text: &str) -> Vec<ProgramTarget> {
        match self {
            Format::Krl => krl::targets(text),
        }
    }
}

/// How a program is compensated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramSettings {
    /// Whole pose (default) or position only.
    pub full_pose: bool,
    /// Decimals of the numbers written (mm and deg). Default 4.
    pub decimals: usize,
    /// Largest position error (mm) of a written target after rounding. Default 0.01: a joint
    /// rounded to 5e-5 deg moves the tool of a 3.6 m arm by up to 3e-3 mm.
    pub verify_mm: f64,
    /// Largest orientation error (deg) of a written target after rounding. Default 0.001.
    pub verify_deg: f64,
}

impl Default for ProgramSettings {
    fn default() -> Self {
        ProgramSettings {
            full_pose: true,
            decimals: 4,
            verify_mm: 0.01,
            verify_deg: 0.001,
        }
    }
}

/// What happened to one target.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// The target's name.
    pub name: String,
    /// 1-based line.
    pub line: usize,
    /// Joints or pose.
    pub kind: TargetKind,
    /// The values as written in the input (controller units).
    pub old: Vec<f64>,
    /// The values written to the output (after rounding; the old ones when not applied).
    pub new: Vec<f64>,
    /// The correction: position (mm) and angle (deg) between the nominal tool poses of the old
    /// and the new values.
    pub correction_mm: f64,
    /// See [`Change::correction_mm`].
    pub correction_deg: f64,
    /// How the compensation ended.
    pub status: IkStatus,
    /// The verified error of the written target on the calibrated model (mm, deg): see the
    /// module documentation. Infinite when the target was not compensated.
    pub verified_mm: f64,
    /// See [`Change::verified_mm`].
    pub verified_deg: f64,
    /// The turn written (KRL `T` of the commanded joints), when the target has one.
    pub new_turn: Option<u32>,
    /// Whether the output holds the new values (false for a target that could not be
    /// compensated: left unchanged).
    pub applied: bool,
}

/// A compensated program.
#[derive(Debug, Clone, PartialEq)]
pub struct CompensatedProgram {
    /// The output text: the input with the applied targets' fields replaced.
    pub text: String,
    /// Every target, in file order.
    pub changes: Vec<Change>,
}

/// Compensates every target of `text` (a program in `format`) with `comp` (nominal = what the
/// controller believes, calibrated = the real robot). Targets that cannot be compensated (status
/// other than converged, or failing the check after rounding) are left unchanged and listed with
/// `applied = false`; the caller decides whether that stops the run.
pub fn compensate_program(
    text: &str,
    format: Format,
    comp: &Compensator<'_, DampedLeastSquares>,
    settings: &ProgramSettings,
) -> Result<CompensatedProgram> {
    let nominal = comp.nominal();
    let targets = format.targets(text);
    if !targets.is_empty() && nominal.dof() != 6 {
        return Err(Error::invalid(
            "program",
            format!(
                "its targets have 6 axes; the robot has {} joints",
                nominal.dof()
            ),
        ));
    }
    let mut changes = Vec::with_capacity(targets.len());
    let mut splices: Vec<(Range<usize>, String)> = Vec::new();
    for t in &targets {
        let c = compensate_target(t, comp, settings);
        if c.applied {
            for (f, v) in t.fields.iter().zip(&c.new) {
                splices.push((f.span.clone(), krl::format_number(*v, settings.decimals)));
            }
            if let (Some(span), Some(old), Some(new)) = (&t.turn_span, t.turn, c.new_turn) {
                if old != new {
                    splices.push((span.clone(), krl::format_turn(new, &text[span.clone()])));
                }
            }
        }
        changes.push(c);
    }
    splices.sort_by_key(|(r, _)| r.start);
    let mut out = String::with_capacity(text.len() + 16 * splices.len());
    let mut at = 0;
    for (span, s) in &splices {
        out.push_str(&text[at..span.start]);
        out.push_str(s);
        at = span.end;
    }
    out.push_str(&text[at..]);
    Ok(CompensatedProgram { text: out, changes })
}

/// Position (mm) and angle (deg) between two frames.
pub fn pose_distance(a: &Frame, b: &Frame) -> (f64, f64) {
    let r = a.rotation.matrix().transpose() * b.rotation.matrix();
    let w = crate::compensation::rotation_angle(&r);
    (
        (a.translation.vector - b.translation.vector).norm(),
        w.to_degrees(),
    )
}

fn round(v: f64, decimals: usize) -> f64 {
    krl::format_number(v, decimals).parse().unwrap_or(v)
}

fn pose_of(values: &[f64]) -> Frame {
    pose(&[
        values[0],
        values[1],
        values[2],
        values[3].to_radians(),
        values[4].to_radians(),
        values[5].to_radians(),
    ])
}

fn values_of(f: &Frame) -> Vec<f64> {
    let v = frame_vector(f);
    vec![
        v[0],
        v[1],
        v[2],
        v[3].to_degrees(),
        v[4].to_degrees(),
        v[5].to_degrees(),
    ]
}

/// The turn of joints `q`: bit i set when controller axis i+1 is negative.
pub fn turn_of(robot: &Robot, q: &[f64]) -> u32 {
    let axes = robot.joint_space().axes_from_joints(q);
    axes.iter()
        .enumerate()
        .filter(|(_, a)| **a < 0.0)
        .map(|(i, _)| 1u32 << i)
        .sum()
}

/// Axes within this of zero (deg) match either sign of a turn: a target written at exactly 0
/// comes back from inverse kinematics as +-1e-12.
const TURN_ZERO_DEG: f64 = 1e-6;

/// Whether the controller axes of `q` have the signs turn `t` gives (bit i: axis i+1 < 0); an
/// axis within `zero_deg` of 0 matches either sign.
fn matches_turn(robot: &Robot, q: &[f64], t: u32, zero_deg: f64) -> bool {
    let axes = robot.joint_space().axes_from_joints(q);
    axes.iter()
        .enumerate()
        .all(|(i, a)| a.abs() < zero_deg || (t & (1 << i) != 0) == (*a < 0.0))
}

/// Axes of the desired joints within this of 0 (deg) may change sign by compensation: the turn
/// written follows the commanded joints there.
const TURN_ADJUST_DEG: f64 = 1.0;

/// The nominal model's joints at a Cartesian target on the branch of its turn: start
/// configurations with the turn's axis signs, the first solution matching the turn.
fn desired_joints(
    nominal: &Robot,
    solver: &PoseNewton,
    target: &Frame,
    turn: Option<u32>,
) -> Option<Vec<f64>> {
    let n = nominal.dof();
    let js = nominal.joint_space();
    let mut q = vec![0.0; n];
    let mut fallback = None;
    for k in 0..32 {
        let mut start = crate::compensation::default_seeds(nominal, k + 1).pop()?;
        crate::compensation::turn_towards(nominal, &target.translation.vector, &mut start);
        if let Some(t) = turn {
            let mut axes = js.axes_from_joints(&start);
            for (i, a) in axes.iter_mut().enumerate() {
                let neg = t & (1 << i) != 0;
                if neg != (*a < 0.0) {
                    *a = -*a;
                }
            }
            start = js.joints_from_axes(&axes);
        }
        let rep = solver.solve(nominal, target, 0, &start, &mut q);
        if !rep.status.is_converged() {
            continue;
        }
        match turn {
            Some(t) if !matches_turn(nominal, &q, t, TURN_ZERO_DEG) => {
                fallback.get_or_insert_with(|| q.clone());
            }
            _ => return Some(q),
        }
    }
    // No solution on the turn's branch: the nearest other one (the status then says so).
    fallback
}

fn compensate_target(
    t: &ProgramTarget,
    comp: &Compensator<'_, DampedLeastSquares>,
    s: &ProgramSettings,
) -> Change {
    let nominal = comp.nominal();
    let cal = comp.calibrated();
    let js = nominal.joint_space();
    let old: Vec<f64> = t.fields.iter().map(|f| f.value).collect();
    let mut change = Change {
        name: t.name.clone(),
        line: t.line,
        kind: t.kind,
        old: old.clone(),
        new: old.clone(),
        correction_mm: 0.0,
        correction_deg: 0.0,
        status: IkStatus::NotConverged,
        verified_mm: f64::INFINITY,
        verified_deg: f64::INFINITY,
        new_turn: t.turn,
        applied: false,
    };
    let mut q = vec![0.0; nominal.dof()];
    // Desired joints (model values) and the desired tool pose.
    let (desired, mut branch_ok) = match t.kind {
        TargetKind::Joints => (js.joints_from_axes(&old), true),
        TargetKind::Pose => {
            match desired_joints(nominal, &comp.pose_solver, &pose_of(&old), t.turn) {
                Some(d) => {
                    let ok = match t.turn {
                        Some(tt) => matches_turn(nominal, &d, tt, TURN_ZERO_DEG),
                        None => true,
                    };
                    (d, ok)
                }
                None => {
                    change.status = IkStatus::Unreachable;
                    return change;
                }
            }
        }
    };
    let desired_pose = match t.kind {
        TargetKind::Joints => nominal.tool_pose(&desired),
        TargetKind::Pose => pose_of(&old),
    };
    let rep = if s.full_pose {
        comp.compensate_pose(&desired, &mut q).1
    } else {
        comp.compensate(&desired, &mut q).1
    };
    change.status = rep.status;
    if rep.status.is_converged() {
        if let (TargetKind::Pose, Some(tt)) = (t.kind, t.turn) {
            // The turn follows the commanded joints where an axis of the desired joints lies
            // within TURN_ADJUST_DEG of 0 (compensation may move it across); elsewhere a
            // different sign is another branch.
            let axes = js.axes_from_joints(&desired);
            let mut mask = tt;
            for (i, a) in axes.iter().enumerate() {
                if a.abs() < TURN_ADJUST_DEG {
                    mask &= !(1 << i);
                }
            }
            let new_turn = turn_of(nominal, &q);
            let fixed = axes
                .iter()
                .enumerate()
                .filter(|(_, a)| a.abs() >= TURN_ADJUST_DEG)
                .all(|(i, _)| (new_turn ^ mask) & (1 << i) == 0);
            branch_ok &= fixed;
            change.new_turn = Some(new_turn);
        }
        if !branch_ok {
            change.status = IkStatus::ConfigurationChange;
        }
    }
    if !change.status.is_converged() {
        return change;
    }
    // The values to write, rounded as written, and their check on the calibrated model.
    let new: Vec<f64> = match t.kind {
        TargetKind::Joints => js.axes_from_joints(&q),
        TargetKind::Pose => values_of(&nominal.tool_pose(&q)),
    }
    .iter()
    .map(|v| round(*v, s.decimals))
    .collect();
    let reached = match t.kind {
        TargetKind::Joints => Some(js.joints_from_axes(&new)),
        TargetKind::Pose => {
            // The controller's inverse kinematics of the written pose, on the commanded branch.
            let mut qw = vec![0.0; nominal.dof()];
            let r = comp
                .pose_solver
                .solve(nominal, &pose_of(&new), 0, &q, &mut qw);
            r.status.is_converged().then_some(qw)
        }
    };
    let Some(qw) = reached else {
        change.status = IkStatus::NotConverged;
        return change;
    };
    let actual = cal.tool_pose(&qw);
    let (vm, vd) = if s.full_pose {
        pose_distance(&actual, &desired_pose)
    } else {
        (
            (actual.translation.vector - desired_pose.translation.vector).norm(),
            0.0,
        )
    };
    change.verified_mm = vm;
    change.verified_deg = vd;
    if vm > s.verify_mm || vd > s.verify_deg {
        change.status = IkStatus::NotConverged;
        return change;
    }
    let before = match t.kind {
        TargetKind::Joints => nominal.tool_pose(&desired),
        TargetKind::Pose => pose_of(&old),
    };
    let after = match t.kind {
        TargetKind::Joints => nominal.tool_pose(&qw),
        TargetKind::Pose => pose_of(&new),
    };
    let (cm, cd) = pose_distance(&before, &after);
    change.correction_mm = cm;
    change.correction_deg = cd;
    change.new = new;
    change.applied = true;
    change
}

#[cfg(test)]
mod tests;
