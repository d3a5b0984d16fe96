//! What every CSV reader of robocal shares: a trimmed reader, the header split into joint
//! columns `q1..qn`, position columns `x,y,z` and extra columns (with the checks every file gets:
//! empty file, unnamed or repeated columns, joints the robot does not have), blank rows skipped,
//! and numeric cells that must be finite. Each file format then decides which columns it requires.

use crate::error::{Error, Result};
use std::io::Read;
use std::path::Path;

/// The header of a CSV file, split by role.
pub(crate) struct ColumnLayout {
    /// All column names, in file order (a UTF-8 byte-order mark removed).
    pub headers: Vec<String>,
    /// Column of joint `j` (`q{j+1}`), where present.
    pub q: Vec<Option<usize>>,
    /// Columns of `x,y,z`, where present (only when positions are read).
    pub xyz: [Option<usize>; 3],
    /// Columns carried through unchanged.
    pub extra: Vec<usize>,
    /// Their names.
    pub extra_columns: Vec<String>,
}

/// A CSV reader with robocal's settings: a header row, fields trimmed, equal row lengths.
pub(crate) fn csv_reader<R: Read>(reader: R) -> csv::Reader<R> {
    csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .flexible(false)
        .from_reader(reader)
}

fn joint_column(name: &str) -> Option<usize> {
    let num = name.strip_prefix('q')?;
    if num.is_empty() || !num.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    num.parse().ok()
}

impl ColumnLayout {
    /// Reads and classifies the header of a file for a robot with `dof` joints. With
    /// `read_xyz` false, `x,y,z` are extra columns. `expected` describes the columns the file
    /// needs, for the empty-file message.
    pub fn read<R: Read>(
        rdr: &mut csv::Reader<R>,
        path: &Path,
        dof: usize,
        read_xyz: bool,
        expected: &str,
    ) -> Result<ColumnLayout> {
        let perr = |field: Option<&str>, msg: String| Error::parse(path, Some(1), field, msg);
        let headers: Vec<String> = rdr
            .headers()
            .map_err(|e| csv_error(path, e))?
            .iter()
            .map(|h| h.trim_start_matches('\u{feff}').to_owned())
            .collect();
        if headers.iter().all(|h| h.is_empty()) {
            return Err(perr(
                None,
                format!("empty file: expected a header row with {expected}"),
            ));
        }
        let mut layout = ColumnLayout {
            q: vec![None; dof],
            xyz: [None; 3],
            extra: Vec::new(),
            extra_columns: Vec::new(),
            headers: Vec::new(),
        };
        for (k, h) in headers.iter().enumerate() {
            if h.is_empty() {
                return Err(perr(None, format!("column {} has an empty name", k + 1)));
            }
            if headers[..k].contains(h) {
                return Err(perr(Some(h), "column appears twice".into()));
            }
            if let Some(j) = joint_column(h) {
                if j == 0 || j > dof {
                    return Err(perr(
                        Some(h),
                        format!(
                            "the robot has {dof} joints (q1..q{dof}); this file has a column `{h}`"
                        ),
                    ));
                }
                layout.q[j - 1] = Some(k);
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

    /// The number in column `k` of `record` (at `line`): rejects empty cells, text and
    /// non-finite values, naming the file, line and column.
    pub fn number(
        &self,
        record: &csv::StringRecord,
        k: usize,
        path: &Path,
        line: usize,
    ) -> Result<f64> {
        let s = &record[k];
        let perr = |msg: String| Error::parse(path, Some(line), Some(&self.headers[k]), msg);
        if s.is_empty() {
            return Err(perr("empty cell".into()));
        }
        let v: f64 = s
            .parse()
            .map_err(|_| perr(format!("`{s}` is not a number")))?;
        if !v.is_finite() {
            return Err(perr(format!("`{s}` is not a finite number")));
        }
        Ok(v)
    }

    /// [`ColumnLayout::number`] within `range` ([`crate::ranges`]); a value outside is an error
    /// naming the file, line and column, its message starting with `what` (e.g. `not a plausible
    /// tracker reading`).
    pub fn number_in(
        &self,
        record: &csv::StringRecord,
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

    /// The values of the extra columns of `record`.
    pub fn extra_values(&self, record: &csv::StringRecord) -> Vec<String> {
        self.extra.iter().map(|&k| record[k].to_owned()).collect()
    }
}

/// Reads the next row that is not blank into `record`; its 1-based line, or `None` at the end.
pub(crate) fn next_record<R: Read>(
    rdr: &mut csv::Reader<R>,
    record: &mut csv::StringRecord,
    path: &Path,
) -> Result<Option<usize>> {
    loop {
        if !rdr.read_record(record).map_err(|e| csv_error(path, e))? {
            return Ok(None);
        }
        if !record.iter().all(|f| f.is_empty()) {
            return Ok(Some(
                record.position().map(|p| p.line() as usize).unwrap_or(0),
            ));
        }
    }
}

/// A CSV reader's error as a robocal error: an I/O failure (e.g. the path is a directory) as
/// [`Error::Io`], anything else as [`Error::Parse`] with the line.
pub(crate) fn csv_error(path: &Path, e: csv::Error) -> Error {
    let line = e.position().map(|p| p.line() as usize);
    let msg = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} fields, but the header has {expected_len}"),
        csv::ErrorKind::Utf8 { .. } => "not valid UTF-8 text".to_owned(),
        csv::ErrorKind::Io(_) => {
            return match e.into_kind() {
                csv::ErrorKind::Io(source) => Error::Io {
                    path: path.to_owned(),
                    source,
                },
                other => Error::parse(path, line, None, format!("{other:?}")),
            }
        }
        _ => e.to_string(),
    };
    Error::parse(path, line, None, msg)
}
