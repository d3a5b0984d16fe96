//! Compensation of a whole program: its targets through the frames in force, its motions
//! accounted for, the new numbers spliced into exactly the spans of the old ones.

use super::census::{Motion, MotionOutcome, MotionReport, TargetRef};
use super::frames::{Frames, KrlConfig};
use super::seed::{self, matches, Branch};
use super::target_solve::{
    desired_and_target, solve_commanded, stored_values, values_to_write, verification,
    written_joints,
};
use super::{
    census_krl, census_rapid, census_ur, pose_distance, Change, CompensatedProgram, Format,
    ProgramSettings, ProgramTarget, Source, TargetKind,
};
use crate::compensation::{Compensator, DampedLeastSquares, IkStatus};
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::Robot;
use std::ops::Range;

/// Compensates every target of a program: `sources[0]` the program, and for KRL its `.dat` as
/// `sources[1]` when there is one; `config` the KUKA controller's numbered frames. Targets that
/// cannot be compensated (a status other than converged, a check after rounding that fails, a
/// frame robocal cannot resolve) are left unchanged and listed with `applied = false`; every
/// motion statement is listed with its outcome. The caller decides whether anything left
/// unchanged stops the run. A malformed target is an error naming its file, line and field.
pub fn compensate_program(
    sources: &[Source],
    format: Format,
    config: Option<&KrlConfig>,
    comp: &Compensator<'_, DampedLeastSquares>,
    settings: &ProgramSettings,
) -> Result<CompensatedProgram> {
    let nominal = comp.nominal();
    let mut targets: Vec<ProgramTarget> = Vec::new();
    for (k, s) in sources.iter().enumerate() {
        format.check_dialect(&s.path, &s.text)?;
        for mut t in format.targets(&s.path, &s.text)? {
            t.file = k;
            targets.push(t);
        }
    }
    if !targets.is_empty() && nominal.dof() != 6 {
        return Err(Error::invalid(
            "program",
            format!(
                "its targets have 6 axes; the robot has {} joints",
                nominal.dof()
            ),
        ));
    }
    let main = sources.first().map_or("", |s| s.text.as_str());
    let motions = match format {
        Format::Krl => census_krl::motions(main, sources.get(1).map(|s| s.text.as_str()), config),
        Format::Rapid => census_rapid::motions(main),
        Format::UrScript => census_ur::motions(main),
    };
    let names = Names::new(format, &targets);
    let links: Vec<Vec<Option<usize>>> = motions
        .iter()
        .map(|m| {
            m.refs
                .iter()
                .map(|r| link(&names, &targets, m, r))
                .collect()
        })
        .collect();
    let frames = target_frames(&targets, &motions, &links);
    let mut changes = Vec::with_capacity(targets.len());
    let mut splices: Vec<Vec<(Range<usize>, String)>> = vec![Vec::new(); sources.len()];
    // The joints of the previous target (desired, model values): where a controller without
    // configuration data starts a Cartesian target's inverse kinematics.
    let mut previous: Option<Vec<f64>> = None;
    for (t, f) in targets.iter().zip(&frames) {
        let (c, desired) = match f {
            Ok(f) => compensate_target(t, format, f, comp, settings, previous.as_deref()),
            Err(why) => (skipped(t, why.clone()), None),
        };
        if desired.is_some() {
            previous = desired;
        }
        if c.applied {
            let text = &sources[t.file].text;
            for (k, (fd, v)) in t.fields.iter().zip(&c.new).enumerate() {
                if *v != fd.value {
                    splices[t.file].push((fd.span.clone(), format.precision(t.kind, k).write(*v)));
                }
            }
            if let (Some(span), Some(old), Some(new)) = (&t.turn_span, t.turn, c.new_turn) {
                if old != new {
                    splices[t.file].push((
                        span.clone(),
                        super::krl::format_turn(new, &text[span.clone()]),
                    ));
                }
            }
        }
        changes.push(c);
    }
    let texts = sources
        .iter()
        .zip(splices.iter_mut())
        .map(|(s, sp)| splice(&s.text, sp))
        .collect();
    let motions = motions
        .into_iter()
        .zip(links)
        .map(|(m, l)| outcome(format, &names, m, &l, &changes))
        .collect();
    Ok(CompensatedProgram {
        texts,
        changes,
        motions,
    })
}

fn splice(text: &str, splices: &mut [(Range<usize>, String)]) -> String {
    splices.sort_by_key(|(r, _)| r.start);
    let mut out = String::with_capacity(text.len() + 16 * splices.len());
    let mut at = 0;
    for (span, s) in splices.iter() {
        out.push_str(&text[at..span.start]);
        out.push_str(s);
        at = span.end;
    }
    out.push_str(&text[at..]);
    out
}

/// The targets by name (upper case for KRL and RAPID, whose names are case-insensitive).
struct Names {
    format: Format,
    by_name: std::collections::HashMap<String, Vec<usize>>,
}

impl Names {
    fn new(format: Format, targets: &[ProgramTarget]) -> Names {
        let mut by_name: std::collections::HashMap<String, Vec<usize>> = Default::default();
        let mut n = Names {
            format,
            by_name: Default::default(),
        };
        for (k, t) in targets.iter().enumerate() {
            by_name.entry(n.key(&t.name)).or_default().push(k);
        }
        n.by_name = by_name;
        n
    }

    fn key(&self, name: &str) -> String {
        match self.format {
            Format::UrScript => name.to_owned(),
            _ => name.to_ascii_uppercase(),
        }
    }
}

/// The target a motion's reference names: inline, the target written in its statement; named,
/// the target of that name (KRL, RAPID: any case; URScript: the last assignment before it).
fn link(names: &Names, targets: &[ProgramTarget], m: &Motion, r: &TargetRef) -> Option<usize> {
    match r {
        TargetRef::Inline => {
            let k = targets.partition_point(|t| {
                t.file < m.file
                    || (t.file == m.file
                        && t.fields.first().map_or(0, |f| f.span.start) < m.span.start)
            });
            let first = |t: &ProgramTarget| t.fields.first().map_or(0, |f| f.span.start);
            targets[k..]
                .iter()
                .take_while(|t| t.file == m.file && first(t) < m.span.end)
                .position(|t| m.span.contains(&first(t)) && !t.fields.is_empty())
                .map(|i| i + k)
        }
        TargetRef::Named(n) => {
            let all = names.by_name.get(&names.key(n))?;
            let before = all.iter().rev().find(|k| {
                let t = &targets[**k];
                t.file != m.file
                    || t.fields
                        .first()
                        .is_some_and(|f| f.span.start < m.span.start)
            });
            before.or(all.first()).copied()
        }
        TargetRef::Computed(_) => None,
    }
}

/// The frames of each Cartesian target: those of the motions that use it (all the same), the
/// robot description's for a target no motion uses in a program that sets no frame.
fn target_frames(
    targets: &[ProgramTarget],
    motions: &[Motion],
    links: &[Vec<Option<usize>>],
) -> Vec<std::result::Result<Frames, String>> {
    let mut out: Vec<Option<std::result::Result<(Frames, usize), String>>> =
        vec![None; targets.len()];
    for (m, l) in motions.iter().zip(links) {
        for k in l.iter().flatten() {
            if targets[*k].kind == TargetKind::Joints {
                continue;
            }
            out[*k] = match out[*k].take() {
                None => Some(Ok((m.frames.clone(), m.line))),
                Some(Ok((f, line))) if f != m.frames => Some(Err(two_uses(&f, line, m))),
                other => other,
            };
        }
    }
    let sets_frames = motions.iter().any(|m| m.frames != Frames::default());
    // An aggregate written inside an expression the controller computes (`{X 1, ..}:XP1`) is an
    // operand, not where the robot goes.
    let operand_of = |t: &ProgramTarget| {
        let at = t.fields.first().map_or(0, |f| f.span.start);
        motions.iter().find(|m| {
            m.file == t.file
                && m.span.contains(&at)
                && m.refs.iter().any(|r| matches!(r, TargetRef::Computed(_)))
        })
    };
    out.into_iter()
        .zip(targets)
        .map(|(f, t)| match f {
            None if operand_of(t).is_some() => Err(format!(
                "part of an expression computed at run time (motion on line {})",
                operand_of(t).map_or(0, |m| m.line)
            )),
            Some(Ok((f, _))) => match f.unknown() {
                Some(why) => Err(format!("frame unknown: {why}")),
                None => Ok(f),
            },
            Some(Err(e)) => Err(e),
            None if t.kind == TargetKind::Joints || !sets_frames => Ok(Frames::default()),
            None => Err("frame unknown: no motion of the program uses it".to_owned()),
        })
        .collect()
}

/// Why a target used by two motions with different frames (`first` at line `line`, then `m`)
/// cannot be compensated for both.
fn two_uses(first: &Frames, line: usize, m: &Motion) -> String {
    let same_frames = first.tool == m.frames.tool && first.base == m.frames.base;
    match (first.offset.is_some(), m.frames.offset.is_some()) {
        (a, b) if same_frames && a != b => {
            let (direct, offset) = if a { (m.line, line) } else { (line, m.line) };
            format!(
                "used both directly (line {direct}) and with an offset (line {offset}): one value \
                 cannot be compensated for two poses; give the offset motion a target of its own"
            )
        }
        _ if same_frames => format!(
            "used with two different offsets (lines {line} and {}): one value cannot be \
             compensated for two poses; give each motion a target of its own",
            m.line
        ),
        _ => format!(
            "frame unknown: used with different tools or bases (lines {line} and {})",
            m.line
        ),
    }
}

/// The program target a computed expression is built on (`Offs(p10, 0, 0, 100)`: `p10`), if it
/// names one.
fn based_on(names: &Names, e: &str) -> Option<usize> {
    e.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty() && !w.as_bytes()[0].is_ascii_digit())
        .find_map(|w| names.by_name.get(&names.key(w)).and_then(|v| v.first()))
        .copied()
}

/// What became of a motion, from what became of its targets.
fn outcome(
    format: Format,
    names: &Names,
    m: Motion,
    links: &[Option<usize>],
    changes: &[Change],
) -> MotionReport {
    let mut why = None;
    if m.relative {
        why = Some("a relative motion: its target is an offset from where the robot is".to_owned());
    } else if let Some(n) = &m.no_target {
        why = Some(n.clone());
    }
    for (r, l) in m.refs.iter().zip(links) {
        if why.is_some() {
            break;
        }
        why = match (r, l) {
            (_, Some(k)) if changes[*k].applied => None,
            (_, Some(k)) => {
                let c = &changes[*k];
                let s = c.skipped.clone().unwrap_or_else(|| c.status.to_string());
                Some(format!(
                    "target {} (line {}) not compensated: {s}",
                    c.name, c.line
                ))
            }
            (TargetRef::Computed(e), None) => Some(match based_on(names, e) {
                // An offset of a program target: that target's correction is for its own pose.
                Some(k) => format!(
                    "target `{e}` computed at run time from {} (line {}): its correction is for \
                     {}'s own pose, not for this one",
                    changes[k].name, changes[k].line, changes[k].name
                ),
                None => format!("target `{e}` computed at run time"),
            }),
            (TargetRef::Named(n), None) => Some(format!(
                "`{n}`: no target of that name in the program{}",
                if format == Format::Krl {
                    " or its .dat"
                } else {
                    ""
                }
            )),
            (TargetRef::Inline, None) => Some(
                "not a complete target (a partial aggregate takes the other values at run time)"
                    .to_owned(),
            ),
        };
    }
    if m.refs.is_empty() && why.is_none() {
        why = Some("no target found in the statement".to_owned());
    }
    let targets = links.iter().flatten().copied().collect();
    MotionReport {
        motion: m,
        outcome: why.map_or(MotionOutcome::Compensated, MotionOutcome::Unchanged),
        targets,
    }
}

fn base_change(t: &ProgramTarget) -> Change {
    let old: Vec<f64> = t.fields.iter().map(|f| f.value).collect();
    Change {
        name: t.name.clone(),
        line: t.line,
        file: t.file,
        kind: t.kind,
        old: old.clone(),
        new: old,
        correction_mm: 0.0,
        correction_deg: 0.0,
        status: IkStatus::NotConverged,
        verified_mm: f64::INFINITY,
        verified_deg: f64::INFINITY,
        new_turn: t.turn,
        applied: false,
        skipped: None,
    }
}

fn skipped(t: &ProgramTarget, why: String) -> Change {
    Change {
        skipped: Some(why),
        ..base_change(t)
    }
}

/// Axes of the desired joints within this of 0 (deg) may change sign by compensation: the KRL
/// turn written follows the commanded joints there.
const TURN_ADJUST_DEG: f64 = 1.0;

/// Compensates one target in frames `fr`; also returns its desired joints (model values).
fn compensate_target(
    t: &ProgramTarget,
    format: Format,
    fr: &Frames,
    comp: &Compensator<'_, DampedLeastSquares>,
    s: &ProgramSettings,
    previous: Option<&[f64]>,
) -> (Change, Option<Vec<f64>>) {
    let nominal = comp.nominal();
    let mut change = base_change(t);
    let old = change.old.clone();
    let old_stored = stored_values(format, t.kind, &old);
    let mut q = vec![0.0; nominal.dof()];
    let branch = t.branch(previous);
    let program = match t.kind {
        TargetKind::Pose => format.pose_of(&old_stored),
        TargetKind::Joints => Frame::identity(),
    };
    let Some((desired, target, mut branch_ok)) =
        desired_and_target(t.kind, format, fr, comp, &old_stored, &program, &branch)
    else {
        change.status = IkStatus::Unreachable;
        return (change, None);
    };
    let rep = solve_commanded(t.kind, s.full_pose, comp, &desired, &target, &mut q);
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
    let new = values_to_write(t.kind, format, fr, nominal, &q, &old, &old_stored);
    let new_stored = stored_values(format, t.kind, &new);
    let Some(qw) = written_joints(t.kind, format, fr, comp, &q, &new_stored) else {
        change.status = IkStatus::NotConverged;
        return (change, Some(desired));
    };
    let (vm, vd) = verification(&comp.calibrated().tool_pose(&qw), &target, s.full_pose);
    change.verified_mm = vm;
    change.verified_deg = vd;
    if vm > s.verify_mm || vd > s.verify_deg {
        change.status = IkStatus::NotConverged;
        return (change, Some(desired));
    }
    let (before, after) = match t.kind {
        TargetKind::Joints => (target, nominal.tool_pose(&qw)),
        TargetKind::Pose => (program, format.pose_of(&new_stored)),
    };
    let (cm, cd) = pose_distance(&before, &after);
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
            // different sign is another branch. A bit changes only where the commanded axis has
            // the other sign beyond seed::ZERO_DEG (a target written at 0 comes back as +-1e-4).
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
