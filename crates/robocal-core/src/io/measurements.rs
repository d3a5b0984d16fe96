//! Measurement CSV files (DESIGN.md): a header row, columns `q1..qn` (model joint values:
//! degrees, or mm for a prismatic joint) or `axis1..axisN` (the controller's values, converted
//! through the robot's `[controller]`, and checked against `q1..qn` when a file has both) and
//! `x,y,z` (mm, tracker frame); other columns (`id`, `set`, ...) are carried through.
//!
//! The same reader serves joint-only files (desired or commanded joints) with
//! [`Positions::Ignored`] or [`Positions::Optional`]. CRLF line endings and a UTF-8 byte-order
//! mark are accepted. Every rejection names the file, the line and the column; joint values and
//! positions must be within their plausible ranges ([`crate::ranges`]).

use crate::error::{Error, Result};
use crate::io::columns::{
    csv_reader_header_trimmed, joint_column, next_record, Cells, ColumnLayout, JointColumns,
};
use crate::io::csv_text::CsvText;
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

/// Writes a measurement (or joint) CSV atomically: `q1..qn` (model joint values: degrees, or mm
/// for a prismatic joint), then `x,y,z` in mm if every row has a position, then the extra
/// columns.
pub fn write_measurements(path: &Path, set: &MeasurementSet) -> Result<()> {
    let bytes = measurements_csv(set).map_err(|e| Error::Io {
        path: path.to_owned(),
        source: e,
    })?;
    crate::io::atomic::write_atomic(path, &bytes)
}

/// The CSV text [`write_measurements`] writes (`q` with 9 decimals of a degree or mm, `x,y,z`
/// with 6 decimals of a millimetre), for callers that write several files together
/// ([`crate::io::write_all_atomic`]).
pub fn measurements_csv(set: &MeasurementSet) -> std::io::Result<Vec<u8>> {
    let with_p = set.has_positions();
    let mut header: Vec<String> = (0..set.dof()).map(joint_column).collect();
    if with_p {
        header.extend(["x", "y", "z"].map(String::from));
    }
    header.extend(set.extra_columns.iter().cloned());
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&header).map_err(std::io::Error::other)?;
    let mut fields = Vec::with_capacity(header.len());
    for r in &set.rows {
        fields.clear();
        fields.extend(
            r.q.iter()
                .enumerate()
                .map(|(i, v)| format!("{:.9}", set.joints.to_display(i, *v))),
        );
        if let (true, Some(p)) = (with_p, r.p) {
            fields.extend([p.x, p.y, p.z].iter().map(|v| format!("{v:.6}")));
        }
        fields.extend(r.extra.iter().cloned());
        w.write_record(&fields).map_err(std::io::Error::other)?;
    }
    w.into_inner()
        .map_err(|e| std::io::Error::other(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str, pos: Positions) -> Result<MeasurementSet> {
        parse_measurements(
            s.as_bytes(),
            Path::new("m.csv"),
            &JointSpace::revolute(2),
            pos,
        )
    }

    #[test]
    fn reads_and_carries_extra_columns() {
        let s = parse(
            "id,q1,q2,x,y,z\na,10,20,1,2,3\nb,30,-40,4,5,6\n",
            Positions::Required,
        )
        .unwrap();
        assert_eq!(s.rows.len(), 2);
        assert_eq!(s.extra_columns, vec!["id"]);
        assert_eq!(s.rows[1].extra, vec!["b"]);
        assert_eq!(s.rows[1].line, 3);
        assert!((s.rows[1].q[1] + 40f64.to_radians()).abs() < 1e-15);
        assert_eq!(s.rows[0].p, Some(Vector3::new(1.0, 2.0, 3.0)));
    }

    #[test]
    fn dialects_are_read_and_lines_are_true() {
        let lf = "q1,q2,x,y,z\n\n1,2,7,8,9\n1,5,7,8,9\n";
        for text in [
            lf.to_owned(),
            lf.replace('\n', "\r\n"),
            lf.replace('\n', "\r"),
            lf.replace(',', ";"),
            lf.replace(',', "\t"),
            format!("\u{feff}{}", lf.replace("q", "Q").replace("x,y,z", "X,Y,Z")),
        ] {
            let s = parse(&text, Positions::Required).unwrap();
            assert_eq!(s.rows.iter().map(|r| r.line).collect::<Vec<_>>(), [3, 4]);
            assert_eq!(s.rows[1].q[1], 5f64.to_radians());
        }
        // Errors name the true line, whatever the line endings.
        let bad = "q1,q2,x,y,z\r\n\r\n1,2,7,8,9\r\n1,oops,7,8,9\r\n";
        assert!(err(bad, Positions::Required).contains(":4: field `q2`"));
        assert!(err(&bad.replace("\r\n", "\r"), Positions::Required).contains(":4: field `q2`"));
    }

    #[test]
    fn a_header_that_does_not_match_says_how_it_was_read() {
        let e = err("q1|q2|x|y|z\n1|2|7|8|9\n", Positions::Required);
        assert!(e.contains("read as 1 column separated by commas"), "{e}");
        let e = err("q_1,q_2,x,y,z\n1,2,3,4,5\n", Positions::Required);
        assert!(e.contains("read as 5 columns separated by commas"), "{e}");
        // Names that are robocal's but for separators, units or `joint` are named.
        assert!(e.contains("`q_1` is not `q1`, `q_2` is not `q2`"), "{e}");
        let e = err(
            "Joint1;Joint2;X [mm];y_mm;z\n1;2;3;4;5\n",
            Positions::Required,
        );
        assert!(e.contains("separated by semicolons"), "{e}");
        assert!(
            e.contains("`Joint1` is not `q1`, `Joint2` is not `q2`"),
            "{e}"
        );
        assert!(e.contains("`X [mm]` is not `x`, `y_mm` is not `y`"), "{e}");
        // A joint the robot lacks is no near miss.
        let e = err("q1;q2;j3;x;y;zz\n1;2;3;4;5;6\n", Positions::Required);
        assert!(!e.contains("`j3` is not"), "{e}");
    }

    /// A decimal comma is read where commas do not separate the columns (`;` or tab), and
    /// only there.
    #[test]
    fn decimal_commas_with_semicolons_or_tabs() {
        for sep in [";", "\t"] {
            let text = "q1;q2;x;y;z\n1,5;2;7,25;8;9\n".replace(';', sep);
            let s = parse(&text, Positions::Required).unwrap();
            assert_eq!(s.rows[0].q[0], 1.5f64.to_radians());
            assert_eq!(s.rows[0].p.unwrap().x, 7.25);
            let bad = "q1;q2;x;y;z\n1,5,1;2;7;8;9\n".replace(';', sep);
            assert!(err(&bad, Positions::Required).contains("`1,5,1` is not a number"));
        }
        // With commas as separators `1,5` is two cells: the row is too long.
        assert!(parse("q1,q2,x,y,z\n1,5,2,7,8,9\n", Positions::Required).is_err());
    }

    #[test]
    fn crlf_and_bom_accepted() {
        let s = parse(
            "\u{feff}q1,q2,x,y,z\r\n10,20,1,2,3\r\n",
            Positions::Required,
        )
        .unwrap();
        assert_eq!(s.rows.len(), 1);
        assert_eq!(s.rows[0].p.unwrap().z, 3.0);
    }

    fn err(s: &str, pos: Positions) -> String {
        parse(s, pos).unwrap_err().to_string()
    }

    #[test]
    fn rejections_name_line_and_column() {
        let e = err("q1,q2,x,y,z\n1,2,3,4,abc\n", Positions::Required);
        assert!(
            e.contains("m.csv:2: field `z`: `abc` is not a number"),
            "{e}"
        );
        let e = err("q1,q2,x,y,z\n1,2,3,4,5\n1,NaN,3,4,5\n", Positions::Required);
        assert!(e.contains("m.csv:3: field `q2`"), "{e}");
        let e = err("q1,x,y,z\n1,3,4,5\n", Positions::Required);
        assert!(e.contains("field `q2`: missing column"), "{e}");
        let e = err("q1,q2,q3,x,y,z\n1,2,3,3,4,5\n", Positions::Required);
        assert!(e.contains("field `q3`") && e.contains("2 joints"), "{e}");
        let e = err("q1,q2,x,y\n1,2,3,4\n", Positions::Required);
        assert!(e.contains("field `z`: missing column"), "{e}");
        let e = err("q1,q2,x,y,z\n", Positions::Required);
        assert!(e.contains("no data rows"), "{e}");
        let e = err("", Positions::Required);
        assert!(e.contains("empty file"), "{e}");
        let e = err("q1,q2,x,y,z\n1,2,3,4\n", Positions::Required);
        assert!(e.contains("m.csv:2") && e.contains("4 fields"), "{e}");
    }

    #[test]
    fn absurd_magnitudes_name_line_and_column() {
        let e = err(
            "q1,q2,x,y,z\n1,2,3,4,5\n1,1000080,3,4,5\n",
            Positions::Required,
        );
        assert!(
            e.contains(
                "m.csv:3: field `q2`: not a plausible joint value: 1000080 deg is out of range"
            ),
            "{e}"
        );
        let e = err("q1,q2,x,y,z\n1,2,3,4,1e30\n", Positions::Required);
        assert!(
            e.contains(
                "m.csv:2: field `z`: not a plausible tracker reading: 1e30 mm is out of range"
            ),
            "{e}"
        );
        let e = err("q1,q2\n1,-2e5\n", Positions::Ignored);
        assert!(
            e.contains("m.csv:2: field `q2`: not a plausible joint value"),
            "{e}"
        );
        // Multi-turn joints and a tracker 999 m away are fine.
        parse(
            "q1,q2,x,y,z\n36000,-99999,999000,0,-5\n",
            Positions::Required,
        )
        .unwrap();
    }

    #[test]
    fn joint_files_and_warnings() {
        let s = parse("q1,q2\n0.1,0.2\n0.3,-1\n1.2,0.5\n", Positions::Ignored).unwrap();
        assert!(!s.has_positions());
        assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
        let s = parse("q1,q2\n10,20\n10,20\n", Positions::Optional).unwrap();
        assert_eq!(s.duplicate_poses(), vec![(2, 3)]);
    }

    #[test]
    fn write_then_read_roundtrip() {
        let s = parse("id,q1,q2,x,y,z\na,10,20,1,2,3\n", Positions::Required).unwrap();
        let p = std::env::temp_dir().join(format!("robocal-m-{}.csv", std::process::id()));
        write_measurements(&p, &s).unwrap();
        let t = read_measurements(&p, &JointSpace::revolute(2), Positions::Required).unwrap();
        std::fs::remove_file(&p).unwrap();
        assert_eq!(t.rows[0].extra, s.rows[0].extra);
        assert!((t.rows[0].q[0] - s.rows[0].q[0]).abs() < 1e-12);
        assert_eq!(t.rows[0].p, s.rows[0].p);
    }

    fn tracked() -> JointSpace {
        use crate::model::{Controller, JointType};
        let c = Controller::new(vec![1.0, -1.0], vec![100.0, 0.0], vec![]).unwrap();
        JointSpace::new(vec![JointType::Prismatic, JointType::Revolute], Some(c)).unwrap()
    }

    fn parse_with(s: &str, j: &JointSpace) -> Result<MeasurementSet> {
        parse_measurements(s.as_bytes(), Path::new("m.csv"), j, Positions::Optional)
    }

    /// A prismatic joint's column is mm, never converted; axis columns go through the controller.
    #[test]
    fn prismatic_values_and_axis_columns() {
        let j = tracked();
        let s = parse_with("q1,q2\n1500,90\n", &j).unwrap();
        assert_eq!(s.rows[0].q[0], 1500.0);
        assert!((s.rows[0].q[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        // axis1 = 1400 -> q1 = 1500 mm; axis2 = -90 -> q2 = 90 deg.
        let a = parse_with("id,axis2,axis1\nx,-90,1400\n", &j).unwrap();
        assert_eq!(a.rows[0].q, s.rows[0].q);
        assert_eq!(a.extra_columns, vec!["id"]);
        // Written back as model values in display units: mm and degrees.
        let text = String::from_utf8(measurements_csv(&a).unwrap()).unwrap();
        assert_eq!(text, "q1,q2,id\n1500.000000000,90.000000000,x\n");
        // Without a controller map axis values are the joint values.
        let plain = JointSpace::revolute(2);
        let p = parse_with("axis1,axis2\n10,20\n", &plain).unwrap();
        assert!((p.rows[0].q[1] - 20f64.to_radians()).abs() < 1e-15);
        // Small prismatic values do not look like radians; small angles do.
        let w = parse_with("q1,q2\n1,1\n2,2\n3,3\n", &j).unwrap();
        assert_eq!(w.warnings.len(), 1);
        let w = parse_with("q1,q2\n1,10\n2,20\n3,30\n", &j).unwrap();
        assert!(w.warnings.is_empty(), "{:?}", w.warnings);
    }

    /// Both kinds of joint columns: q is used, and axis must agree with it on every row.
    #[test]
    fn q_and_axis_columns_must_agree() {
        let j = tracked();
        let s = parse_with("q1,q2,axis1,axis2\n1500,90,1400,-90\n", &j).unwrap();
        assert_eq!(s.rows[0].q[0], 1500.0);
        let e = parse_with("q1,q2,axis1,axis2\n1500,90,1400,-90\n1500,90,1400,90\n", &j)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.csv:3: field `axis2`") && e.contains("disagrees"),
            "{e}"
        );
        let e = parse_with("q1,q2,axis1\n1,2,3\n", &j)
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.csv:1: field `axis2`: missing column"), "{e}");
        let e = parse_with("axis1,axis3\n1,2\n", &j)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("field `axis3`") && e.contains("axis1..axis2"),
            "{e}"
        );
        let e = parse_with("id\n1\n", &j).unwrap_err().to_string();
        assert!(
            e.contains("field `q1`: missing column") && e.contains("axis1..axis2"),
            "{e}"
        );
    }
}
