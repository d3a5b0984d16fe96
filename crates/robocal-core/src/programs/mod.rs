//! Robot programs: every target of a controller program replaced by its compensated value, in the
//! controller's own units and axis conventions, everything else kept byte for byte.
//!
//! A format's reader finds the targets and the byte spans of their numeric fields
//! ([`ProgramTarget`]); [`compensate_program`] compensates each (full pose by default, see
//! [`crate::compensation`]) and splices the new numbers into exactly those spans, so the text
//! outside them is unchanged. Formats ([`Format`]): KUKA KRL ([`krl`]), ABB RAPID ([`rapid`]),
//! URScript ([`urscript`]). The readers are hand-written: no maintained Rust parser exists for
//! these languages, and robocal needs only their targets.
//!
//! - **Joint targets** (KRL AXIS/E6AXIS, RAPID jointtarget, URScript joint lists): the
//!   controller's axis values (deg; URScript rad) go through the robot's controller map
//!   ([`crate::model::JointSpace::joints_from_axes`]; the KUKA presets: q = (-A1, A2, A3, -A4,
//!   A5, -A6); robots without a map: the identity) to the desired model joints; the commanded
//!   joints go back to axis values.
//! - **Cartesian targets** (KRL POS/E6POS/FRAME, RAPID robtarget, URScript `p[...]`): the pose is
//!   taken as the tool frame (target 1, [`crate::Robot::tool_pose`]) in the robot's base frame,
//!   i.e. the program's base/work object and tool are those of the robot description: a `$BASE`
//!   or `$TOOL` set in a KRL program, a RAPID wobj other than `wobj0` or a tool other than the
//!   robot file's, a URScript `set_tcp` are not followed. The desired joints are the nominal
//!   model's inverse kinematics on the branch the target's configuration data give
//!   ([`seed::Branch`]: KRL `S` and `T`, RAPID confdata; a URScript pose, which has none, takes
//!   the solution nearest the previous target's joints, as the controller takes the one nearest
//!   its current joints). The compensated pose written is the nominal model's pose at the
//!   commanded joints, so that the controller, which believes the nominal model, drives the
//!   robot to the commanded joints. The configuration data are kept, and must still hold at the
//!   commanded joints ([`IkStatus::ConfigurationChange`] otherwise), with one exception: a KRL
//!   `T` follows an axis that compensation moves across 0 from within 1 degree of it (a target
//!   at A4 = 0 may need A4 = -0.002).
//!
//! Numbers are written with [`ProgramSettings::decimals`] decimals in mm and deg (3 more in m and
//! rad, 4 more for a quaternion), and every written target is verified after rounding: read back
//! as the controller would (joints, or the nominal inverse kinematics of the written pose from
//! the commanded joints, on the target's branch), the calibrated model's tool must be within
//! [`ProgramSettings::verify_mm`] and [`ProgramSettings::verify_deg`] of the desired pose.

pub mod krl;
mod lex;
pub mod rapid;
pub mod seed;
pub mod urscript;

use crate::compensation::{Compensator, DampedLeastSquares, IkStatus};
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::Robot;
use seed::{branch_joints, matches, Branch, BranchJoints};
use std::ops::Range;
use std::path::Path;

pub use seed::turn_of;

/// One numeric field of a target: its name in the program, its value, its byte span.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The field's name (`A1`, `X`, `q1`, ...).
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
    /// A Cartesian pose (the format's units and orientation representation).
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
    /// The numeric fields compensation replaces, in order (`A1..A6`, `X, Y, Z, A, B, C`, ...).
    pub fields: Vec<Field>,
    /// KRL's turn `T`, when given.
    pub turn: Option<u32>,
    /// The byte range of the turn's value.
    pub turn_span: Option<Range<usize>>,
    /// KRL's status `S`, when given.
    pub status: Option<u32>,
    /// RAPID's confdata `[cf1, cf4, cf6, cfx]`, for a robtarget.
    pub conf: Option<[i64; 4]>,
}

impl ProgramTarget {
    /// The branch a Cartesian target asks for; `previous`: the joints (model values, rad) of the
    /// target before it in the program, for a target without configuration data.
    pub fn branch(&self, previous: Option<&[f64]>) -> Branch {
        if let Some(c) = self.conf {
            Branch::Rapid(c)
        } else if self.turn.is_some() || self.status.is_some() {
            Branch::Krl {
                status: self.status,
                turn: self.turn,
            }
        } else if let Some(p) = previous {
            Branch::Nearest(p.to_vec())
        } else {
            Branch::Any
        }
    }
}

/// A program format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// KUKA KRL (`.src`, `.dat`).
    Krl,
    /// ABB RAPID (`.mod`, `.modx`, `.prg`).
    Rapid,
    /// Universal Robots URScript (`.script`, `.urscript`).
    UrScript,
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
            Some("mod") | Some("modx") | Some("prg") => Ok(Format::Rapid),
            Some("script") | Some("urscript") => Ok(Format::UrScript),
            _ => Err(Error::invalid(
                "program",
                format!(
                    "{}: unknown program format from its extension (known: KUKA KRL .src/.dat, \
                     ABB RAPID .mod/.modx/.prg, URScript .script/.urscript)",
                    path.display()
                ),
            )),
        }
    }

    /// The targets of a program text, in file order; `path` names the program in errors (a
    /// malformed target: its line and field).
    pub fn targets(self, path: &Path, text: &str) -> Result<Vec<ProgramTarget>> {
        match self {
            Format::Krl => krl::targets(path, text),
            Format::Rapid => rapid::targets(path, text),
            Format::UrScript => urscript::targets(path, text),
        }
    }

    /// The tool frame (mm) of a Cartesian target's values.
    pub fn pose_of(self, values: &[f64]) -> Frame {
        match self {
            Format::Krl => krl::pose_of(values),
            Format::Rapid => rapid::pose_of(values),
            Format::UrScript => urscript::pose_of(values),
        }
    }

    /// The values of a Cartesian target at tool frame `f`, written like `old` (the target's
    /// values in the input: quaternion sign, rotation vector turn).
    pub fn pose_values(self, f: &Frame, old: &[f64]) -> Vec<f64> {
        match self {
            Format::Krl => krl::pose_values(f),
            Format::Rapid => rapid::pose_values(f, old),
            Format::UrScript => urscript::pose_values(f, old),
        }
    }

    /// Controller axis values in the robot's display units (deg, mm) from a joint target's values.
    pub fn axes_of(self, values: &[f64]) -> Vec<f64> {
        match self {
            Format::UrScript => values.iter().map(|v| v.to_degrees()).collect(),
            _ => values.to_vec(),
        }
    }

    /// A joint target's values from controller axis values (display units).
    pub fn joint_values(self, axes: &[f64]) -> Vec<f64> {
        match self {
            Format::UrScript => axes.iter().map(|v| v.to_radians()).collect(),
            _ => axes.to_vec(),
        }
    }

    /// Decimals of field `i` of a target of `kind`, for `base` decimals in mm and deg.
    pub fn decimals(self, kind: TargetKind, i: usize, base: usize) -> usize {
        match (self, kind) {
            (Format::UrScript, _) => base + 3,
            (Format::Rapid, TargetKind::Pose) if i >= 3 => base + 4,
            _ => base,
        }
    }
}

/// How a program is compensated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramSettings {
    /// Whole pose (default) or position only.
    pub full_pose: bool,
    /// Decimals of the numbers written in mm and deg (m and rad: 3 more; quaternions: 4 more).
    /// Default 4.
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

/// Compensates every target of `text` (a program in `format`, named `path` in errors) with
/// `comp` (nominal = what the controller believes, calibrated = the real robot). Targets that
/// cannot be compensated (status other than converged, or failing the check after rounding) are
/// left unchanged and listed with `applied = false`; the caller decides whether that stops the
/// run. A malformed target is an error naming its line.
pub fn compensate_program(
    path: &Path,
    text: &str,
    format: Format,
    comp: &Compensator<'_, DampedLeastSquares>,
    settings: &ProgramSettings,
) -> Result<CompensatedProgram> {
    let nominal = comp.nominal();
    let targets = format.targets(path, text)?;
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
    // The joints of the previous target (desired, model values): where a controller without
    // configuration data starts a Cartesian target's inverse kinematics.
    let mut previous: Option<Vec<f64>> = None;
    for t in &targets {
        let (c, desired) = compensate_target(t, format, comp, settings, previous.as_deref());
        if desired.is_some() {
            previous = desired;
        }
        if c.applied {
            // A number the compensation leaves as it was (after rounding) keeps its text.
            for (k, (f, v)) in t.fields.iter().zip(&c.new).enumerate() {
                if *v != f.value {
                    let d = format.decimals(t.kind, k, settings.decimals);
                    splices.push((f.span.clone(), krl::format_number(*v, d)));
                }
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

/// Axes of the desired joints within this of 0 (deg) may change sign by compensation: the KRL
/// turn written follows the commanded joints there.
const TURN_ADJUST_DEG: f64 = 1.0;

/// Compensates one target; also returns its desired joints (model values), when known.
fn compensate_target(
    t: &ProgramTarget,
    format: Format,
    comp: &Compensator<'_, DampedLeastSquares>,
    s: &ProgramSettings,
    previous: Option<&[f64]>,
) -> (Change, Option<Vec<f64>>) {
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
    let branch = t.branch(previous);
    // Desired joints (model values) and the desired tool pose.
    let (desired, mut branch_ok) = match t.kind {
        TargetKind::Joints => (js.joints_from_axes(&format.axes_of(&old)), true),
        TargetKind::Pose => {
            match branch_joints(nominal, &comp.pose_solver, &format.pose_of(&old), &branch) {
                BranchJoints::Found(d) => (d, true),
                BranchJoints::Other(d) => (d, false),
                BranchJoints::Unreachable => {
                    change.status = IkStatus::Unreachable;
                    return (change, None);
                }
            }
        }
    };
    let desired_pose = match t.kind {
        TargetKind::Joints => nominal.tool_pose(&desired),
        TargetKind::Pose => format.pose_of(&old),
    };
    let rep = if s.full_pose {
        comp.compensate_pose(&desired, &mut q).1
    } else {
        comp.compensate(&desired, &mut q).1
    };
    change.status = rep.status;
    if rep.status.is_converged() && t.kind == TargetKind::Pose {
        branch_ok &= commanded_branch_ok(t, nominal, &desired, &q, &branch, &mut change);
    }
    if rep.status.is_converged() && !branch_ok {
        change.status = IkStatus::ConfigurationChange;
    }
    if !change.status.is_converged() {
        return (change, Some(desired));
    }
    // The values to write, rounded as written, and their check on the calibrated model.
    let new: Vec<f64> = match t.kind {
        TargetKind::Joints => format.joint_values(&js.axes_from_joints(&q)),
        TargetKind::Pose => format.pose_values(&nominal.tool_pose(&q), &old),
    }
    .iter()
    .enumerate()
    .map(|(k, v)| round(*v, format.decimals(t.kind, k, s.decimals)))
    .collect();
    let reached = match t.kind {
        TargetKind::Joints => Some(js.joints_from_axes(&format.axes_of(&new))),
        TargetKind::Pose => {
            // The controller's inverse kinematics of the written pose, on the commanded branch.
            let mut qw = vec![0.0; nominal.dof()];
            let r = comp
                .pose_solver
                .solve(nominal, &format.pose_of(&new), 0, &q, &mut qw);
            r.status.is_converged().then_some(qw)
        }
    };
    let Some(qw) = reached else {
        change.status = IkStatus::NotConverged;
        return (change, Some(desired));
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
        return (change, Some(desired));
    }
    let after = match t.kind {
        TargetKind::Joints => nominal.tool_pose(&qw),
        TargetKind::Pose => format.pose_of(&new),
    };
    let (cm, cd) = pose_distance(&desired_pose, &after);
    change.correction_mm = cm;
    change.correction_deg = cd;
    change.new = new;
    change.applied = true;
    (change, Some(desired))
}

/// Whether the commanded joints `q` of a Cartesian target keep its configuration data (see the
/// module documentation); sets the KRL turn to write.
fn commanded_branch_ok(
    t: &ProgramTarget,
    nominal: &Robot,
    desired: &[f64],
    q: &[f64],
    branch: &Branch,
    change: &mut Change,
) -> bool {
    let js = nominal.joint_space();
    match (branch, t.turn) {
        (Branch::Krl { status, .. }, Some(tt)) => {
            // The turn follows the commanded joints where an axis of the desired joints lies
            // within TURN_ADJUST_DEG of 0 (compensation may move it across); elsewhere a
            // different sign is another branch.
            // A bit changes only where the commanded axis has the other sign beyond
            // seed::ZERO_DEG (a target written at 0 comes back as +-1e-4).
            let axes = js.axes_from_joints(desired);
            let mut new_turn = tt;
            for (i, a) in js.axes_from_joints(q).iter().enumerate() {
                if a.abs() >= seed::ZERO_DEG {
                    new_turn = (new_turn & !(1 << i)) | (u32::from(*a < 0.0) << i);
                }
            }
            let fixed = axes
                .iter()
                .enumerate()
                .filter(|(_, a)| a.abs() >= TURN_ADJUST_DEG)
                .all(|(i, _)| (new_turn ^ tt) & (1 << i) == 0);
            change.new_turn = Some(new_turn);
            let s_branch = Branch::Krl {
                status: *status,
                turn: None,
            };
            fixed && matches(nominal, q, &s_branch)
        }
        _ => matches(nominal, q, branch),
    }
}

#[cfg(test)]
mod tests;
