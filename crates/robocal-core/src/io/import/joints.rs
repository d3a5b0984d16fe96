//! Joint logs, read row by row: the columns of the joint values (in degrees after conversion),
//! the time and the point name, from a header ([`super::joints_csv`], [`super::rtde`]); the
//! rows go to a callback so that a log of millions of rows is never held in memory.

use super::lines::{number, Delimiter, Dialect, LineReader};
use super::units::AngleUnit;
use super::JointsFormat;
use crate::error::{Error, Result};
use crate::ranges;
use std::io::BufRead;
use std::path::Path;

/// Which joint columns robocal writes: the model's joint values or the controller's axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// `q1..qn`: model joint values.
    Model,
    /// `axis1..axisN`: controller values, converted through the robot's `[controller]`.
    Axis,
}

/// How a joint log is read: found from its header.
#[derive(Debug, Clone)]
pub struct JointLayout {
    /// The file.
    pub path: std::path::PathBuf,
    /// The format.
    pub format: JointsFormat,
    /// Delimiter, decimal mark, header line.
    pub dialect: Dialect,
    /// The joint columns' names in the file, in joint order.
    pub joint_names: Vec<String>,
    /// Their field indices.
    pub joint_fields: Vec<usize>,
    /// What the joint values are.
    pub kind: JointKind,
    /// Their unit in the file.
    pub angle_unit: AngleUnit,
    /// Where the unit came from.
    pub unit_source: String,
    /// The time column (name, field), if any.
    pub time: Option<(String, usize)>,
    /// The point-name column (name, field), if any.
    pub name: Option<(String, usize)>,
    /// The number of fields of the header.
    pub n_fields: usize,
}

/// One row of a joint log.
#[derive(Debug, Clone, Copy)]
pub struct JointRow<'a> {
    /// 1-based line.
    pub line: usize,
    /// Time (s, the log's clock), if the log has a time column.
    pub time_s: Option<f64>,
    /// The point name, if the log has a name column.
    pub name: Option<&'a str>,
    /// Joint values in degrees (or mm for a prismatic joint).
    pub q_deg: &'a [f64],
}

/// Reads the rows after the header, calling `sink` for each. Times must increase.
pub fn for_each_row<R: BufRead>(
    lines: &mut LineReader<R>,
    layout: &JointLayout,
    mut sink: impl FnMut(JointRow<'_>) -> Result<()>,
) -> Result<RowsRead> {
    let path = lines.path().to_owned();
    let mut q = vec![0.0; layout.joint_fields.len()];
    let mut last_time: Option<(f64, usize)> = None;
    let mut n = 0;
    let mut decimal_comma = false;
    let dec = layout.dialect.decimal;
    while let Some((line, text)) = lines.next_line()? {
        let mut fields = Vec::with_capacity(layout.n_fields);
        if text.trim().is_empty() {
            continue;
        }
        layout.dialect.delimiter.split(text, &mut fields);
        if fields.len() != layout.n_fields {
            if layout.dialect.delimiter == Delimiter::Comma && fields.len() > layout.n_fields {
                return Err(super::lines::comma_ambiguity(
                    &path,
                    line,
                    layout.n_fields,
                    fields.len(),
                ));
            }
            return Err(Error::parse(
                &path,
                Some(line),
                None,
                format!(
                    "{} fields where the header has {} (a truncated log?)",
                    fields.len(),
                    layout.n_fields
                ),
            ));
        }
        for (k, (&f, name)) in layout
            .joint_fields
            .iter()
            .zip(&layout.joint_names)
            .enumerate()
        {
            decimal_comma |= dec == ',' && fields[f].contains(',');
            let v = layout
                .angle_unit
                .deg(number(&path, line, name, fields[f], dec)?);
            if !ranges::JOINT.contains(v) {
                return Err(Error::parse(
                    &path,
                    Some(line),
                    Some(name),
                    format!(
                        "{v} deg is beyond {} ({}): is the angle unit right ({} from {})? see the \
                         `angle_unit` setting",
                        ranges::JOINT.why,
                        ranges::JOINT.bounds(),
                        layout.angle_unit,
                        layout.unit_source
                    ),
                ));
            }
            q[k] = v;
        }
        let time_s = match &layout.time {
            Some((name, f)) => {
                let t = super::timestamp::seconds(fields[*f])
                    .map_err(|m| Error::parse(&path, Some(line), Some(name), m))?;
                if let Some((prev, prev_line)) = last_time {
                    if t <= prev {
                        return Err(Error::parse(
                            &path,
                            Some(line),
                            Some(name),
                            format!("time {t} s is not after line {prev_line}'s {prev} s"),
                        ));
                    }
                }
                last_time = Some((t, line));
                Some(t)
            }
            None => None,
        };
        let name = layout.name.as_ref().map(|(_, f)| fields[*f]);
        sink(JointRow {
            line,
            time_s,
            name,
            q_deg: &q,
        })?;
        n += 1;
    }
    if n == 0 {
        return Err(Error::parse(&path, None, None, "no rows after the header"));
    }
    Ok(RowsRead {
        rows: n,
        decimal_comma,
    })
}

/// What [`for_each_row`] read.
#[derive(Debug, Clone, Copy)]
pub struct RowsRead {
    /// Data rows.
    pub rows: usize,
    /// Whether joint values had a decimal comma.
    pub decimal_comma: bool,
}

/// The first non-empty line: the header.
pub fn header_line<R: BufRead>(lines: &mut LineReader<R>) -> Result<(usize, String)> {
    loop {
        match lines.next_line()? {
            None => {
                return Err(Error::parse(
                    lines.path(),
                    None,
                    None,
                    "empty file: no header row",
                ))
            }
            Some((_, l)) if l.trim().is_empty() => continue,
            Some((n, l)) => return Ok((n, l.to_owned())),
        }
    }
}

/// The error for a joint log whose joint count differs from the robot's.
pub fn dof_mismatch(path: &Path, line: usize, got: usize, want: usize) -> Error {
    Error::parse(
        path,
        Some(line),
        None,
        format!("{got} joint columns, but the robot has {want} joints"),
    )
}
