//! The paired joint values against the robot's joint limits (when the import is given a robot).
//!
//! A calibration engineer's rules: a joint value outside its limit is a unit or column mix-up
//! until shown otherwise, so it is an error naming the joint log, the line and the column, the
//! value and the limits, with the rows of every other such point listed; when the robot's limits
//! are only nominal (`nominal_limits`), each such point is a listed warning instead and its
//! values are kept. A log in radians read as degrees stays inside any robot's limits, so it is
//! caught by its values: every revolute joint value of the paired rows within ±2π "degrees"
//! while the robot's joints move through more than that is an error (a warning when the angle
//! unit was given as degrees by the `angle_unit` setting). Controller values (`axis` columns) are
//! not checked here: they become model joint values, and meet the limits, in `calibrate`.

use super::joints::{JointKind, JointLayout};
use super::units::AngleUnit;
use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use crate::ranges::{fmt_value, LIMIT_TOLERANCE_DEG};

/// Points described one by one in messages; the rest are counted.
const LISTED: usize = 20;

/// The robot's joint limits for an import, in the CSV's units (deg, or mm for a prismatic joint).
#[derive(Debug, Clone, PartialEq)]
pub struct ImportLimits {
    robot: String,
    /// (min, max) per joint, deg or mm.
    limits: Vec<(f64, f64)>,
    revolute: Vec<bool>,
    /// Whether the limits are only nominal: values outside them are warnings, not errors.
    pub nominal: bool,
}

impl ImportLimits {
    /// The limits of `robot`; `nominal`: values outside them are listed warnings, not an error.
    pub fn new(robot: &Robot, nominal: bool) -> ImportLimits {
        let js = robot.joint_space();
        ImportLimits {
            robot: robot.name().to_owned(),
            limits: robot
                .limits()
                .iter()
                .enumerate()
                // To the 9 decimals files hold (120, not 119.99999999999999).
                .map(|(j, l)| {
                    let shown = |v: f64| (js.to_display(j, v) * 1e9).round() / 1e9;
                    (shown(l.min), shown(l.max))
                })
                .collect(),
            revolute: (0..robot.dof())
                .map(|j| robot.joint_type(j) == JointType::Revolute)
                .collect(),
            nominal,
        }
    }

    /// The robot's joint count.
    pub fn dof(&self) -> usize {
        self.limits.len()
    }
}

/// One paired row: its first line in the joint log, how to name it (`line 12`, or a dwell's
/// lines) and its joint values (deg or mm).
pub(super) struct PairedRow<'a> {
    pub line: usize,
    pub label: String,
    pub q: &'a [f64],
}

/// Checks the paired rows (see the module documentation); returns the warnings.
pub(super) fn check(
    lim: &ImportLimits,
    layout: &JointLayout,
    rows: &[PairedRow<'_>],
) -> Result<Vec<String>> {
    if layout.kind == JointKind::Axis {
        return Ok(Vec::new());
    }
    let mut warnings = radians_as_degrees(lim, layout, rows)?;
    let unit = |j: usize| if lim.revolute[j] { "deg" } else { "mm" };
    let mut outside = Vec::new();
    for r in rows {
        for (j, (&v, &(lo, hi))) in r.q.iter().zip(&lim.limits).enumerate() {
            if v < lo - LIMIT_TOLERANCE_DEG || v > hi + LIMIT_TOLERANCE_DEG {
                outside.push((r, j, v, lo, hi));
            }
        }
    }
    let Some(&(first, j0, v0, lo0, hi0)) = outside.first() else {
        return Ok(warnings);
    };
    let describe = |&(r, j, v, lo, hi): &(&PairedRow, usize, f64, f64, f64)| {
        format!(
            "{}: {} = {} {u} (limits {}..{})",
            r.label,
            layout.joint_names[j],
            fmt_value(v),
            fmt_value(lo),
            fmt_value(hi),
            u = unit(j)
        )
    };
    let listed: Vec<String> = outside.iter().take(LISTED).map(describe).collect();
    let more = outside.len().saturating_sub(LISTED);
    let points = {
        let mut p: Vec<usize> = outside.iter().map(|o| o.0.line).collect();
        p.dedup();
        p.len()
    };
    if lim.nominal {
        let path = layout.path.display();
        warnings.extend(listed.iter().map(|l| {
            format!(
                "{path}: {l}: outside the limits of robot `{}` (kept: the limits are nominal)",
                lim.robot
            )
        }));
        if more > 0 {
            warnings.push(format!(
                "{path}: {more} more joint values outside the limits ({points} of the {} paired \
                 points in all)",
                rows.len()
            ));
        }
        return Ok(warnings);
    }
    let listed = if more > 0 {
        format!("{}; ... ({more} more)", listed.join("; "))
    } else {
        listed.join("; ")
    };
    Err(Error::parse(
        &layout.path,
        Some(first.line),
        Some(&layout.joint_names[j0]),
        format!(
            "{} {u} is outside the joint limits of robot `{}` (q{}: {}..{} {u}); {points} of the \
             {} paired points are outside: {}. Is the angle unit right ({} from {}; see the \
             `angle_unit` setting)? If the robot's limits are only nominal, see the \
             `nominal_limits` setting",
            fmt_value(v0),
            lim.robot,
            j0 + 1,
            fmt_value(lo0),
            fmt_value(hi0),
            rows.len(),
            listed,
            layout.angle_unit,
            layout.unit_source,
            u = unit(j0)
        ),
    ))
}

/// A log in radians read as degrees: every revolute value of at least three paired rows within
/// ±2π while the robot's revolute joints reach beyond ±4π (deg); one joint at least moving.
fn radians_as_degrees(
    lim: &ImportLimits,
    layout: &JointLayout,
    rows: &[PairedRow<'_>],
) -> Result<Vec<String>> {
    let two_pi = 2.0 * std::f64::consts::PI;
    let rev: Vec<usize> = (0..lim.dof()).filter(|&j| lim.revolute[j]).collect();
    let reach = rev
        .iter()
        .map(|&j| lim.limits[j].0.abs().max(lim.limits[j].1.abs()))
        .fold(0.0, f64::max);
    if layout.angle_unit != AngleUnit::Deg
        || rows.len() < 3
        || rev.is_empty()
        || reach < 2.0 * two_pi
    {
        return Ok(Vec::new());
    }
    let mut largest = 0.0f64;
    let mut moved = false;
    for &j in &rev {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for r in rows {
            lo = lo.min(r.q[j]);
            hi = hi.max(r.q[j]);
        }
        largest = largest.max(lo.abs()).max(hi.abs());
        moved |= hi > lo;
    }
    if largest > two_pi + 1e-9 || !moved {
        return Ok(Vec::new());
    }
    let msg = format!(
        "every revolute joint value of the {} paired rows lies within ±{} deg, a range of \
         radians, while robot `{}` reaches ±{} deg: the joint log looks like radians read as \
         degrees (angle unit {} from {})",
        rows.len(),
        fmt_value((largest * 1000.0).ceil() / 1000.0),
        lim.robot,
        fmt_value(reach.round()),
        layout.angle_unit,
        layout.unit_source
    );
    if layout.unit_source.contains("setting") {
        return Ok(vec![format!(
            "{}: {msg}; kept, as the `angle_unit` setting says degrees",
            layout.path.display()
        )]);
    }
    Err(Error::parse(
        &layout.path,
        layout.dialect.header_line,
        Some(&layout.joint_names[rev[0]]),
        format!("{msg}; see the `angle_unit` setting"),
    ))
}
