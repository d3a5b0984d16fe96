//! Measurement CSV files (DESIGN.md): a header row, columns `q1..qn` (model joint values:
//! degrees, or mm for a prismatic joint) or `axis1..axisN` (the controller's values, converted
//! through the robot's `[controller]`, and checked against `q1..qn` when a file has both) and
//! `x,y,z` (mm, tracker frame); other columns (`id`, `set`, ...) are carried through.
//!
//! The same reader serves joint-only files (desired or commanded joints) with
//! [`Positions::Ignored`] or [`Positions::Optional`]. CRLF line endings and a UTF-8 byte-order
//! mark are accepted. Every rejection names the file, the line and the column; joint values and
//! positions must be within their plausible ranges ([`crate::ranges`]).
//!
//! [`write_measurements`] and [`measurements_csv`] (re-exported here) write such files.

use crate::error::{Error, Result};
use crate::io::columns::{
    csv_reader_header_trimmed, joint_column, next_record, Cells, ColumnLayout, JointColumns,
};
use crate::io::csv_text::CsvText;
pub use crate::io::measurements_write::{measurements_csv, write_measurements};
use crate::model::JointSpace;
use crate::ranges;
use nalgebra::Vector3;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Whether a file must, may or must not have `x,y,z` columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Positions {
    /// `x,y,z` are required (measurement files).
    Required,
    /// `x,y,z` are read when present.
    Optional,
    /// `x,y,z` are ignored: carried through as extra columns (joint files).
    Ignored,
}

/// One row of a measurement file.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// 1-based line of the row in the file.
    pub line: usize,
    /// Joint values (model values, internal units: radians, or mm for a prismatic joint).
    pub q: Vec<f64>,
    /// Measured tool point (mm, tracker frame), when the file has positions.
    pub p: Option<Vector3<f64>>,
    /// The row's values of the extra columns, in [`MeasurementSet::extra_columns`] order.
    pub extra: Vec<String>,
}

/// A whole measurement (or joint) file.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementSet {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// The robot's joints (types and controller map): how the joint values were read and are
    /// written.
    pub joints: JointSpace,
    /// Names of the columns other than the joint columns and `x,y,z`, in file order.
    pub extra_columns: Vec<String>,
    /// The rows, in file order.
    pub rows: Vec<Measurement>,
    /// Things worth telling the user that do not stop the run (e.g. values that look like radians).
    pub warnings: Vec<String>,
}

impl MeasurementSet {
    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.joints.dof()
    }

    /// Whether every row has a position.
    pub fn has_positions(&self) -> bool {
        !self.rows.is_empty() && self.rows.iter().all(|r| r.p.is_some())
    }

    /// Pairs of lines `(first, repeat)` whose joint values are identical.
    pub fn duplicate_poses(&self) -> Vec<(usize, usize)> {
        let mut idx: Vec<usize> = (0..self.rows.len()).collect();
        let key = |i: usize| -> Vec<u64> { self.rows[i].q.iter().map(|v| v.to_bits()).collect() };
        idx.sort_by_key(|&i| key(i));
        let mut out = Vec::new();
        for w in idx.windows(2) {
            if key(w[0]) == key(w[1]) {
                let (a, b) = (self.rows[w[0]].line, self.rows[w[1]].line);
                out.push((a.min(b), a.max(b)));
            }
        }
        out.sort();
        out
    }

    /// The column value of an extra column for a row, by name.
    pub fn extra_value<'a>(&self, row: &'a Measurement, column: &str) -> Option<&'a str> {
        self.extra_columns
            .iter()
            .position(|c| c == column)
            .map(|k| row.extra[k].as_str())
    }
}

/// Reads a measurement CSV for a robot with the joints `joints` (`Robot::joint_space`).
pub fn read_measurements(
    path: &Path,
    joints: &JointSpace,
    positions: Positions,
) -> Result<MeasurementSet> {
    MeasurementReader::open(path, joints, positions)?.read_all()
}

/// Parses measurement CSV text from any reader; `path` is used in messages.
pub fn parse_measurements<R: Read>(
    reader: R,
    path: &Path,
    joints: &JointSpace,
    positions: Positions,
) -> Result<MeasurementSet> {
    MeasurementReader::new(reader, path, joints, positions)?.read_all()
}

/// A measurement (or joint) file read one row at a time, so that files of millions of rows need
/// no more memory than one row: the header is checked by [`MeasurementReader::new`], each
/// [`MeasurementReader::next_row`] parses and checks one row, and [`MeasurementReader::finish`]
/// rejects a file without rows and returns the warnings. [`read_measurements`] is this reader
/// collecting every row.
pub struct MeasurementReader<R: Read> {
    source: Rows<R>,
    path: PathBuf,
    joints: JointSpace,
    layout: ColumnLayout,
    q_col: JointColumns,
    xyz_col: Option<[usize; 3]>,
    record: csv::StringRecord,
    rows: usize,
    max_abs_deg: f64,
}

/// Where a reader's rows come from: the `csv` reader, or a small file without quotes read from
/// memory ([`CsvText`]: the same rows, lines and errors).
enum Rows<R: Read> {
    Csv(csv::Reader<crate::io::columns::LineCounted<R>>),
    Text(CsvText),
}

/// The columns a measurement file must have, for the empty-file message.
fn expected_columns(dof: usize) -> String {
    format!("q1..q{dof} (or axis1..axis{dof}) and x,y,z")
}

impl MeasurementReader<std::io::BufReader<std::fs::File>> {
    /// Opens a measurement file for a robot with the joints `joints` and checks its header.
    pub fn open(path: &Path, joints: &JointSpace, positions: Positions) -> Result<Self> {
        let mut file = crate::io::input::open_input(path)?;
        if let Some(mut text) = CsvText::of_file(&mut file, path)? {
            let mut header = csv::StringRecord::new();
            text.header(&mut header);
            let dof = joints.dof();
            let layout = ColumnLayout::of_header(
                &header,
                text.delimiter(),
                path,
                dof,
                positions != Positions::Ignored,
                &expected_columns(dof),
            )?;
            return Self::with_layout(Rows::Text(text), layout, path, joints, positions);
        }
        MeasurementReader::new(std::io::BufReader::new(file), path, joints, positions)
    }
}

impl<R: Read> MeasurementReader<R> {
    /// Reads and checks the header of measurement CSV text; `path` is used in messages.
    pub fn new(reader: R, path: &Path, joints: &JointSpace, positions: Positions) -> Result<Self> {
        let dof = joints.dof();
        let mut rdr = csv_reader_header_trimmed(reader);
        let layout = ColumnLayout::read(
            &mut rdr,
            path,
            dof,
            positions != Positions::Ignored,
            &expected_columns(dof),
        )?;
        Self::with_layout(Rows::Csv(rdr), layout, path, joints, positions)
    }

    /// The reader of `source` whose header is `layout`, checked for the columns it must have.
    fn with_layout(
        source: Rows<R>,
        layout: ColumnLayout,
        path: &Path,
        joints: &JointSpace,
        positions: Positions,
    ) -> Result<Self> {
        let perr = |line: Option<usize>, field: Option<&str>, msg: String| {
            Error::parse(path, line, field, msg)
        };
        let dof = joints.dof();
        let Some(q) = layout.joint_columns(path)? else {
            return Err(perr(
                Some(1),
                Some(&joint_column(0)),
                format!(
                    "missing column (the robot has {dof} joints: q1..q{dof}, or the controller's \
                     axis1..axis{dof}; {})",
                    layout.header_seen()
                ),
            ));
        };
        let xyz_col = layout.xyz;
        let n_xyz = xyz_col.iter().filter(|c| c.is_some()).count();
        let xyz_col = match xyz_col {
            [Some(x), Some(y), Some(z)] => Some([x, y, z]),
            _ if positions == Positions::Required || n_xyz > 0 => {
                let a = xyz_col.iter().position(Option::is_none).unwrap_or(0);
                return Err(perr(
                    Some(1),
                    Some(["x", "y", "z"][a]),
                    format!(
                        "missing column (measured positions need x,y,z in mm; {})",
                        layout.header_seen()
                    ),
                ));
            }
            _ => None,
        };
        Ok(MeasurementReader {
            source,
            path: path.to_owned(),
            joints: joints.clone(),
            q_col: q,
            xyz_col,
            layout,
            record: csv::StringRecord::new(),
            rows: 0,
            max_abs_deg: 0.0,
        })
    }

    /// Names of the columns other than the joint columns and `x,y,z`, in file order.
    pub fn extra_columns(&self) -> &[String] {
        &self.layout.extra_columns
    }

    /// Whether the file has `x,y,z` columns (and reads them).
    pub fn has_positions(&self) -> bool {
        self.xyz_col.is_some()
    }

    /// The file's description without rows (path, joint count, extra columns): what row-wise
    /// consumers need to interpret a row.
    pub fn header(&self) -> MeasurementSet {
        MeasurementSet {
            path: self.path.clone(),
            joints: self.joints.clone(),
            extra_columns: self.layout.extra_columns.clone(),
            rows: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// The next data row (blank rows are skipped), `None` at the end of the file. Fails naming
    /// the line and the column of a malformed cell.
    pub fn next_row(&mut self) -> Result<Option<Measurement>> {
        let mut row = Measurement {
            line: 0,
            q: Vec::with_capacity(self.joints.dof()),
            p: None,
            extra: Vec::new(),
        };
        Ok(self.next_row_into(&mut row)?.then_some(row))
    }

    /// [`MeasurementReader::next_row`] written to `row` (every field replaced), reusing its
    /// buffers: a file of any length is read without an allocation per row. `false` at the end
    /// of the file (`row` then unchanged).
    pub fn next_row_into(&mut self, row: &mut Measurement) -> Result<bool> {
        let at = Columns {
            layout: &self.layout,
            q_col: &self.q_col,
            xyz_col: self.xyz_col,
            joints: &self.joints,
            path: &self.path,
        };
        let largest_angle = match &mut self.source {
            Rows::Csv(rdr) => match next_record(rdr, &mut self.record, &self.path)? {
                Some(line) => at.row_into(&self.record, line, row)?,
                None => return Ok(false),
            },
            Rows::Text(text) => match text.next_record(&self.path)? {
                Some((line, cells)) => at.row_into(&cells, line, row)?,
                None => return Ok(false),
            },
        };
        self.max_abs_deg = self.max_abs_deg.max(largest_angle);
        self.rows += 1;
        Ok(true)
    }

    /// Ends the reading: fails if the file had no data rows; returns the warnings (e.g. joint
    /// values that look like radians).
    pub fn finish(self) -> Result<Vec<String>> {
        if self.rows == 0 {
            return Err(Error::parse(
                &self.path,
                None,
                None,
                "no data rows after the header".to_string(),
            ));
        }
        let mut warnings = Vec::new();
        // Radians of any joint range (up to a full turn each way) are within ±2π; a real session
        // in degrees moves some revolute joint further than 6.3 degrees.
        if self.rows >= 3
            && self.max_abs_deg > 0.0
            && self.max_abs_deg <= std::f64::consts::TAU + 1e-9
        {
            warnings.push(format!(
                "{}: every {}joint value is within ±{:.3} (±2π); they look like radians, but \
                 files hold degrees",
                self.path.display(),
                if self.joints.any_prismatic() {
                    "revolute "
                } else {
                    ""
                },
                self.max_abs_deg
            ));
        }
        Ok(warnings)
    }

    /// Reads every remaining row into a [`MeasurementSet`].
    pub fn read_all(mut self) -> Result<MeasurementSet> {
        let mut set = self.header();
        while let Some(r) = self.next_row()? {
            set.rows.push(r);
        }
        set.warnings = self.finish()?;
        Ok(set)
    }
}

/// What a reader needs to read one row: its header's layout and the robot's joints.
struct Columns<'a> {
    layout: &'a ColumnLayout,
    q_col: &'a JointColumns,
    xyz_col: Option<[usize; 3]>,
    joints: &'a JointSpace,
    path: &'a Path,
}

impl Columns<'_> {
    /// The row at `line` of cells `record` into `row` (every field replaced); the largest
    /// magnitude of a revolute joint's cell, for the radians warning.
    fn row_into(&self, record: &impl Cells, line: usize, row: &mut Measurement) -> Result<f64> {
        let (layout, path) = (self.layout, self.path);
        let largest_angle =
            layout.joint_values_into(record, self.q_col, self.joints, path, line, &mut row.q)?;
        let pos = |k| {
            layout.number_in(
                record,
                k,
                path,
                line,
                &ranges::LENGTH,
                "not a plausible tracker reading",
            )
        };
        let p = match self.xyz_col {
            Some([x, y, z]) => Some(Vector3::new(pos(x)?, pos(y)?, pos(z)?)),
            None => None,
        };
        row.line = line;
        row.p = p;
        layout.extra_values_into(record, &mut row.extra);
        Ok(largest_angle)
    }
}

#[cfg(test)]
#[path = "measurements_tests.rs"]
mod tests;
