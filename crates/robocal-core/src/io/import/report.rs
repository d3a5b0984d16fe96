//! What an import did, for the user: the formats, dialects and units read, the clock offset, the
//! counts paired, and every point and joint row (or dwell) left unpaired with its line or time.

use super::joints::JointKind;
use super::lines::Dialect;
use super::points::PointTable;
use super::units::AngleUnit;
use super::{ImportConfig, JointsFormat, JointsRead, LengthUnit, MatchBy, PointsFormat};
use std::path::{Path, PathBuf};

/// What an import read, paired and left out.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportReport {
    /// The tracker export.
    pub points_path: PathBuf,
    /// Its format (detected or given).
    pub points_format: PointsFormat,
    /// Whether the format was detected.
    pub points_detected: bool,
    /// How it was read.
    pub points_dialect: Dialect,
    /// Its length unit.
    pub length_unit: LengthUnit,
    /// Where the unit came from.
    pub length_unit_source: String,
    /// Columns of the export not used.
    pub ignored_columns: Vec<String>,
    /// Lines of rows the export marks deleted (left out).
    pub deleted_lines: Vec<usize>,
    /// Points in the export.
    pub points: usize,
    /// The joint log.
    pub joints_path: PathBuf,
    /// Its format.
    pub joints_format: JointsFormat,
    /// Whether the format was detected.
    pub joints_detected: bool,
    /// How it was read.
    pub joints_dialect: Dialect,
    /// Its joint columns, in joint order.
    pub joint_columns: Vec<String>,
    /// Whether they were written as model values (`q`) or controller values (`axis`).
    pub joint_kind: JointKind,
    /// Their unit.
    pub angle_unit: AngleUnit,
    /// Where the unit came from.
    pub angle_unit_source: String,
    /// Rows of the joint log.
    pub joint_rows: usize,
    /// How points were paired.
    pub match_by: MatchBy,
    /// Dwells found (matching by time).
    pub dwells: Option<usize>,
    /// Tracker clock minus joint-log clock (s) and whether it was found (else given).
    pub time_offset: Option<(f64, bool)>,
    /// Points paired.
    pub matched: usize,
    /// Points left unpaired (line, name or time).
    pub unmatched_points: Vec<String>,
    /// Joint rows or dwells left unpaired (line or time).
    pub unmatched_joints: Vec<String>,
    /// The columns written.
    pub columns: Vec<String>,
    /// Optional columns not written, and why.
    pub left_out: Vec<String>,
    /// Warnings (joint values outside nominal limits, listed per point).
    pub warnings: Vec<String>,
}

pub(super) struct Parts<'a> {
    pub table: &'a PointTable,
    pub log: &'a JointsRead,
    pub config: &'a ImportConfig,
    pub pairs: &'a [Option<usize>],
    pub left: &'a [usize],
    pub offset: Option<(f64, bool)>,
    pub columns: Vec<String>,
    pub left_out: Vec<String>,
    pub joints_path: &'a Path,
    pub warnings: Vec<String>,
}

pub(super) fn build(p: Parts<'_>) -> ImportReport {
    let t = p.table;
    let t0 = t.rows.iter().find_map(|r| r.time_s);
    let unmatched_points = p
        .pairs
        .iter()
        .enumerate()
        .filter(|(_, j)| j.is_none())
        .map(|(i, _)| {
            let r = &t.rows[i];
            let mut s = format!("line {}", r.line);
            if let Some(n) = &r.name {
                s.push_str(&format!(" `{n}`"));
            }
            if let (Some(ts), Some(t0)) = (r.time_s, t0) {
                s.push_str(&format!(" at {:.3} s", ts - t0));
            }
            s
        })
        .collect();
    let unmatched_joints = p
        .left
        .iter()
        .map(|&j| {
            if p.config.match_by == MatchBy::Time {
                let d = &p.log.dwells[j];
                format!(
                    "dwell {:.3}..{:.3} s (lines {}-{})",
                    d.start_s, d.end_s, d.first_line, d.last_line
                )
            } else {
                let r = &p.log.kept[j];
                match &r.name {
                    Some(n) => format!("line {} `{n}`", r.line),
                    None => format!("line {}", r.line),
                }
            }
        })
        .collect();
    let l = &p.log.layout;
    ImportReport {
        points_path: t.path.clone(),
        points_format: t.format,
        points_detected: p.config.points_format == PointsFormat::Auto,
        points_dialect: t.dialect.clone(),
        length_unit: t.length_unit,
        length_unit_source: t.unit_source.clone(),
        ignored_columns: t.ignored_columns.clone(),
        deleted_lines: t.deleted_lines.clone(),
        points: t.rows.len(),
        joints_path: p.joints_path.to_owned(),
        joints_format: l.format,
        joints_detected: p.config.joints_format == JointsFormat::Auto,
        joints_dialect: l.dialect.clone(),
        joint_columns: l.joint_names.clone(),
        joint_kind: l.kind,
        angle_unit: l.angle_unit,
        angle_unit_source: l.unit_source.clone(),
        joint_rows: p.log.rows,
        match_by: p.config.match_by,
        dwells: (p.config.match_by == MatchBy::Time).then_some(p.log.dwells.len()),
        time_offset: p.offset,
        matched: p.pairs.iter().filter(|j| j.is_some()).count(),
        unmatched_points,
        unmatched_joints,
        columns: p.columns,
        left_out: p.left_out,
        warnings: p.warnings,
    }
}

impl ImportReport {
    /// The report as lines of text.
    pub fn lines(&self) -> Vec<String> {
        let how = |d: bool| if d { "detected" } else { "given" };
        let mut v = vec![
            format!(
                "points: {} read as {} ({}; {}), {} points, length unit {} ({})",
                self.points_path.display(),
                self.points_format,
                how(self.points_detected),
                self.points_dialect,
                self.points,
                self.length_unit,
                self.length_unit_source
            ),
            format!(
                "joints: {} read as {} ({}; {}), {} rows, joint columns {} ({}, written as {}), \
                 angle unit {} ({})",
                self.joints_path.display(),
                self.joints_format,
                how(self.joints_detected),
                self.joints_dialect,
                self.joint_rows,
                self.joint_columns.join(","),
                match self.joint_kind {
                    JointKind::Model => "model joint values",
                    JointKind::Axis => "controller values",
                },
                match self.joint_kind {
                    JointKind::Model => format!("q1..q{}", self.joint_columns.len()),
                    JointKind::Axis => format!("axis1..axis{}", self.joint_columns.len()),
                },
                self.angle_unit,
                self.angle_unit_source
            ),
        ];
        if !self.ignored_columns.is_empty() {
            v.push(format!(
                "points columns not used: {}",
                self.ignored_columns.join(", ")
            ));
        }
        if !self.deleted_lines.is_empty() {
            v.push(format!(
                "points marked deleted in the export, left out: {} (line{} {})",
                self.deleted_lines.len(),
                if self.deleted_lines.len() == 1 {
                    ""
                } else {
                    "s"
                },
                self.deleted_lines
                    .iter()
                    .map(|l| l.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if let Some(n) = self.dwells {
            v.push(format!("dwells found in the joint log: {n}"));
        }
        if let Some((o, found)) = self.time_offset {
            v.push(format!(
                "clock offset (tracker minus joint log): {o:.3} s ({})",
                if found {
                    "found from the dwells"
                } else {
                    "given"
                }
            ));
        }
        v.push(format!(
            "paired by {}: {} of {} points; {} points and {} {} left unpaired",
            self.match_by,
            self.matched,
            self.points,
            self.unmatched_points.len(),
            self.unmatched_joints.len(),
            if self.match_by == MatchBy::Time {
                "dwells"
            } else {
                "joint rows"
            }
        ));
        for u in &self.unmatched_points {
            v.push(format!("  point without joints: {u}"));
        }
        for u in &self.unmatched_joints {
            v.push(format!("  joints without a point: {u}"));
        }
        v.push(format!("columns written: {}", self.columns.join(",")));
        for l in &self.left_out {
            v.push(format!("  not written: {l}"));
        }
        v.extend(self.warnings.iter().map(|w| format!("warning: {w}")));
        v
    }
}
