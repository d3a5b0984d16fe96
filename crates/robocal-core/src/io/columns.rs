//! What every CSV reader of robocal shares: a trimmed reader and blank rows skipped
//! ([`crate::io::csv_reader`], re-exported here), the header split into joint columns (`q1..qn`,
//! model joint values, or `axis1..axisN`, controller values), position columns `x,y,z` and extra
//! columns (with the checks every file gets: empty file, unnamed or repeated columns, joints the
//! robot does not have), numeric cells that must be finite, and joint values turned into model
//! values (internal units) through the robot's [`JointSpace`]. Each file format then decides
//! which columns it requires.
//!
//! Joint columns: a file gives `q1..qn` (degrees, or mm for a prismatic joint) or
//! `axis1..axisN` (the controller's values, same units, converted through the robot's
//! `[controller]` map; the identity without one). A file with both (a commanded file written by
//! `compensate` has both) uses `q1..qn`, and every axis value must be the controller value of
//! that row's joints (to [`AXIS_AGREEMENT`]), else the row is rejected naming the column: the two
//! can never silently disagree.

use crate::error::{Error, Result};
pub(crate) use crate::io::csv_lines::LineCounted;
pub(crate) use crate::io::csv_reader::{
    csv_error, csv_reader, csv_reader_header_trimmed, next_record,
};
use crate::io::plain_decimal::plain_decimal;
use crate::model::{JointSpace, JointType};
use std::io::Read;
use std::path::Path;

/// How closely the `axis` columns of a file that also has `q` columns must agree with the
/// controller values of its joints (degrees or mm): the rounding of values written with 9
/// decimals, with room for the map's arithmetic.
pub const AXIS_AGREEMENT: f64 = 1e-6;

/// The column of model joint `i` (0-based): `q{i+1}`.
pub fn joint_column(i: usize) -> String {
    format!("q{}", i + 1)
}

/// The column of controller axis `i` (0-based): `axis{i+1}`.
pub fn axis_column(i: usize) -> String {
    format!("axis{}", i + 1)
}

/// A row's cells as a [`ColumnLayout`] reads them: a `csv` record, or a line of a small file
/// without quotes split at its delimiter ([`crate::io::csv_text`]).
pub(crate) trait Cells {
    /// Cell `k` as written (the layout's readers trim it).
    fn cell(&self, k: usize) -> &str;
}

impl Cells for csv::StringRecord {
    #[inline]
    fn cell(&self, k: usize) -> &str {
        &self[k]
    }
}

/// The header of a CSV file, split by role.
pub(crate) struct ColumnLayout {
    /// All column names, in file order (a UTF-8 byte-order mark removed).
    pub headers: Vec<String>,
    /// Column of joint `j` (`q{j+1}`), where present.
    pub q: Vec<Option<usize>>,
    /// Column of controller axis `j` (`axis{j+1}`), where present.
    pub axis: Vec<Option<usize>>,
    /// Columns of `x,y,z`, where present (only when positions are read).
    pub xyz: [Option<usize>; 3],
    /// Columns carried through unchanged.
    pub extra: Vec<usize>,
    /// Their names.
    pub extra_columns: Vec<String>,
    /// The delimiter the header was read with (`,`, `;` or tab).
    pub delimiter: u8,
}

/// A header name as robocal knows it: the names of its columns (`q1`, `axis1`, `x`, `set`, `id`,
/// `a`...) in any case become lower case; any other name is kept as written.
fn known_name(h: &str) -> String {
    let lower = h.to_ascii_lowercase();
    if is_known(&lower) {
        lower
    } else {
        h.to_owned()
    }
}

/// Whether a lower-case name is one of robocal's columns.
fn is_known(lower: &str) -> bool {
    joint_column_index(lower).is_some()
        || ["x", "y", "z", "a", "b", "c", "set", "id"].contains(&lower)
}

/// The robocal column a header name nearly is, for a robot with `dof` joints: the same but for
/// separators (`q_1`, `Q 1`, `axis-1`), a unit (`x_mm`, `x [mm]`, `q1(deg)`) or the word
/// `joint` (`joint1`); `None` for a robocal name or one that is not near any.
fn near_miss(h: &str, dof: usize) -> Option<String> {
    let lower = h.to_ascii_lowercase();
    if is_known(&lower) {
        return None;
    }
    let mut core = lower.clone();
    for unit in [
        "(mm)", "[mm]", "(deg)", "[deg]", "(rad)", "[rad]", "_mm", "_deg", "_rad",
    ] {
        if let Some(c) = core.strip_suffix(unit) {
            core = c.to_owned();
        }
    }
    let mut core: String = core
        .chars()
        .filter(|c| !matches!(c, '_' | '-' | ' ' | '.'))
        .collect();
    for (from, to) in [("joint", "q"), ("j", "q")] {
        if let Some(rest) = core.strip_prefix(from) {
            if !rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit()) {
                core = format!("{to}{rest}");
            }
        }
    }
    let wanted = match joint_column_index(&core) {
        Some((_, j)) => (1..=dof).contains(&j),
        None => ["x", "y", "z"].contains(&core.as_str()),
    };
    (wanted && core != lower).then_some(core)
}

/// `q{k}` or `axis{k}`: whether it is an axis column, and k.
fn joint_column_index(name: &str) -> Option<(bool, usize)> {
    let (axis, num) = match name.strip_prefix("axis") {
        Some(num) => (true, num),
        None => (false, name.strip_prefix('q')?),
    };
    if num.is_empty() || !num.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    num.parse().ok().map(|k| (axis, k))
}

/// Where a file's joint values come from (see the module documentation).
pub(crate) enum JointColumns {
    /// `q1..qn`.
    Model(Vec<usize>),
    /// `axis1..axisN`.
    Axes(Vec<usize>),
    /// Both: `q` is used, `axis` must agree.
    Both(Vec<usize>, Vec<usize>),
}

impl ColumnLayout {
    /// Reads and classifies the header of a file for a robot with `dof` joints. With
    /// `read_xyz` false, `x,y,z` are extra columns. `expected` describes the columns the file
    /// needs, for the empty-file message.
    pub fn read<R: Read>(
        rdr: &mut csv::Reader<LineCounted<R>>,
        path: &Path,
        dof: usize,
        read_xyz: bool,
        expected: &str,
    ) -> Result<ColumnLayout> {
        let delimiter = rdr.get_ref().delimiter();
        let headers = rdr
            .headers()
            .map_err(|e| csv_error(path, e, None::<&LineCounted<R>>))?;
        ColumnLayout::of_header(headers, delimiter, path, dof, read_xyz, expected)
    }

    /// [`ColumnLayout::read`] of a header already read (trimmed), with the file's delimiter.
    pub fn of_header(
        header: &csv::StringRecord,
        delimiter: u8,
        path: &Path,
        dof: usize,
        read_xyz: bool,
        expected: &str,
    ) -> Result<ColumnLayout> {
        let perr = |field: Option<&str>, msg: String| Error::parse(path, Some(1), field, msg);
        let headers: Vec<String> = header
            .iter()
            .map(|h| known_name(h.trim_start_matches('\u{feff}')))
            .collect();
        if headers.iter().all(|h| h.is_empty()) {
            return Err(perr(
                None,
                format!("empty file: expected a header row with {expected}"),
            ));
        }
        let mut layout = ColumnLayout {
            q: vec![None; dof],
            axis: vec![None; dof],
            xyz: [None; 3],
            extra: Vec::new(),
            extra_columns: Vec::new(),
            headers: Vec::new(),
            delimiter,
        };
        for (k, h) in headers.iter().enumerate() {
            if h.is_empty() {
                return Err(perr(None, format!("column {} has an empty name", k + 1)));
            }
            if headers[..k].contains(h) {
                return Err(perr(Some(h), "column appears twice".into()));
            }
            if let Some((axis, j)) = joint_column_index(h) {
                if j == 0 || j > dof {
                    let range = if axis {
                        format!("axis1..axis{dof}")
                    } else {
                        format!("q1..q{dof}")
                    };
                    return Err(perr(
                        Some(h),
                        format!(
                            "the robot has {dof} joints ({range}); this file has a column `{h}`"
                        ),
                    ));
                }
                if axis {
                    layout.axis[j - 1] = Some(k);
                } else {
                    layout.q[j - 1] = Some(k);
                }
                continue;
            }
            match ["x", "y", "z"].iter().position(|a| a == h) {
                Some(a) if read_xyz => layout.xyz[a] = Some(k),
                _ => {
                    layout.extra.push(k);
                    layout.extra_columns.push(h.clone());
                }
            }
        }
        layout.headers = headers;
        Ok(layout)
    }

    /// The header as read, for messages: "header is `a,b`, read as 2 columns separated by
    /// commas".
    pub fn header_seen(&self) -> String {
        let near: Vec<String> = self
            .headers
            .iter()
            .filter_map(|h| near_miss(h, self.q.len()).map(|w| format!("`{h}` is not `{w}`")))
            .collect();
        format!(
            "header is `{}`, read as {} column{} separated by {}{}",
            self.headers.join(","),
            self.headers.len(),
            if self.headers.len() == 1 { "" } else { "s" },
            crate::io::csv_lines::delimiter_name(self.delimiter),
            if near.is_empty() {
                String::new()
            } else {
                format!("; {}", near.join(", "))
            }
        )
    }

    /// The number in column `k` of `record` (at `line`; the cell trimmed): rejects empty cells,
    /// text and non-finite values, naming the file, line and column.
    #[inline]
    pub fn number(&self, record: &impl Cells, k: usize, path: &Path, line: usize) -> Result<f64> {
        let s = record.cell(k).trim();
        let perr = |msg: String| Error::parse(path, Some(line), Some(&self.headers[k]), msg);
        if s.is_empty() {
            return Err(perr("empty cell".into()));
        }
        // A decimal comma, where commas do not separate the columns (`;` or tab): `12,5`.
        let v: f64 = match plain_decimal(s).map_or_else(|| s.parse(), Ok) {
            Ok(v) => v,
            Err(_) if self.delimiter != b',' && s.matches(',').count() == 1 && !s.contains('.') => {
                s.replace(',', ".")
                    .parse()
                    .map_err(|_| perr(format!("`{s}` is not a number")))?
            }
            Err(_) => return Err(perr(format!("`{s}` is not a number"))),
        };
        if !v.is_finite() {
            return Err(perr(format!("`{s}` is not a finite number")));
        }
        Ok(v)
    }

    /// [`ColumnLayout::number`] within `range` ([`crate::ranges`]); a value outside is an error
    /// naming the file, line and column, its message starting with `what` (e.g. `not a plausible
    /// tracker reading`).
    #[inline]
    pub fn number_in(
        &self,
        record: &impl Cells,
        k: usize,
        path: &Path,
        line: usize,
        range: &crate::ranges::Range,
        what: &str,
    ) -> Result<f64> {
        let v = self.number(record, k, path, line)?;
        range.check(v).map_err(|msg| {
            Error::parse(
                path,
                Some(line),
                Some(&self.headers[k]),
                format!("{what}: {msg}"),
            )
        })
    }

    /// The file's joint columns: all of `q1..qn`, all of `axis1..axisN`, or both; `None` when
    /// it has neither. A file with some but not all of one kind is rejected naming the first
    /// missing column.
    pub fn joint_columns(&self, path: &Path) -> Result<Option<JointColumns>> {
        let dof = self.q.len();
        let complete = |cols: &[Option<usize>], name: fn(usize) -> String| -> Result<Vec<usize>> {
            match cols.iter().position(Option::is_none) {
                None => Ok(cols.iter().flatten().copied().collect()),
                Some(j) => Err(Error::parse(
                    path,
                    Some(1),
                    Some(&name(j)),
                    format!(
                        "missing column (the robot has {dof} joints: {}..{}; {})",
                        name(0),
                        name(dof - 1),
                        self.header_seen()
                    ),
                )),
            }
        };
        let has = |cols: &[Option<usize>]| cols.iter().any(Option::is_some);
        Ok(match (has(&self.q), has(&self.axis)) {
            (false, false) => None,
            (true, false) => Some(JointColumns::Model(complete(&self.q, joint_column)?)),
            (false, true) => Some(JointColumns::Axes(complete(&self.axis, axis_column)?)),
            (true, true) => Some(JointColumns::Both(
                complete(&self.q, joint_column)?,
                complete(&self.axis, axis_column)?,
            )),
        })
    }

    /// The model joint values (internal units: rad, or mm for a prismatic joint) of `record`
    /// from the joint columns `cols`, converted through `joints`; with the largest magnitude of a
    /// revolute joint's cell (degrees as written), for the radians warning.
    pub fn joint_values(
        &self,
        record: &impl Cells,
        cols: &JointColumns,
        joints: &JointSpace,
        path: &Path,
        line: usize,
    ) -> Result<(Vec<f64>, f64)> {
        let mut q = Vec::with_capacity(joints.dof());
        let largest = self.joint_values_into(record, cols, joints, path, line, &mut q)?;
        Ok((q, largest))
    }

    /// [`ColumnLayout::joint_values`] written to `q` (its old values replaced; no allocation
    /// once `q` has room for the joints, for files of `q1..qn` columns); returns the largest
    /// magnitude of a revolute joint's cell.
    pub fn joint_values_into(
        &self,
        record: &impl Cells,
        cols: &JointColumns,
        joints: &JointSpace,
        path: &Path,
        line: usize,
        q: &mut Vec<f64>,
    ) -> Result<f64> {
        // Joint j's cell within its plausible range: an angle (deg, multi-turn axes allowed) or,
        // for a prismatic joint, a length (mm).
        let read_into = |c: &[usize], v: &mut [f64]| -> Result<()> {
            for ((&k, t), v) in c.iter().zip(joints.types()).zip(v.iter_mut()) {
                let range = match t {
                    JointType::Revolute => &crate::ranges::JOINT,
                    JointType::Prismatic => &crate::ranges::LENGTH,
                };
                *v = self.number_in(record, k, path, line, range, "not a plausible joint value")?;
            }
            Ok(())
        };
        let read = |c: &[usize]| -> Result<Vec<f64>> {
            let mut v = vec![0.0; c.len()];
            read_into(c, &mut v)?;
            Ok(v)
        };
        let largest_angle = |v: &[f64]| {
            v.iter()
                .zip(joints.types())
                .filter(|(_, t)| **t == JointType::Revolute)
                .fold(0.0f64, |m, (x, _)| m.max(x.abs()))
        };
        q.clear();
        match cols {
            JointColumns::Model(c) => {
                let mut buf = [0.0; crate::model::MAX_JOINTS];
                let v = &mut buf[..c.len()];
                read_into(c, v)?;
                q.extend(v.iter().enumerate().map(|(i, x)| joints.to_internal(i, *x)));
                Ok(largest_angle(v))
            }
            JointColumns::Axes(c) => {
                let v = read(c)?;
                q.extend(joints.joints_from_axes(&v));
                Ok(largest_angle(&v))
            }
            JointColumns::Both(qc, ac) => {
                let v = read(qc)?;
                let a = read(ac)?;
                q.extend(joints.joints_from_display(&v));
                let expected = joints.axes_from_joints(q);
                for (j, (x, e)) in a.iter().zip(&expected).enumerate() {
                    if (x - e).abs() > AXIS_AGREEMENT {
                        return Err(Error::parse(
                            path,
                            Some(line),
                            Some(&self.headers[ac[j]]),
                            format!(
                                "{x} disagrees with {e:.9}, the controller value of this row's \
                                 q1..q{n} (a file with both q and axis columns must give the \
                                 same joints twice; remove one kind)",
                                n = q.len()
                            ),
                        ));
                    }
                }
                Ok(largest_angle(&v))
            }
        }
    }

    /// The values of the extra columns of `record` (trimmed).
    pub fn extra_values(&self, record: &impl Cells) -> Vec<String> {
        self.extra
            .iter()
            .map(|&k| record.cell(k).trim().to_owned())
            .collect()
    }

    /// [`ColumnLayout::extra_values`] written to `out`, reusing its strings.
    pub fn extra_values_into(&self, record: &impl Cells, out: &mut Vec<String>) {
        out.resize_with(self.extra.len(), String::new);
        for (o, &k) in out.iter_mut().zip(&self.extra) {
            o.clear();
            o.push_str(record.cell(k).trim());
        }
    }
}
