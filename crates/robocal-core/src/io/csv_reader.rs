//! The CSV reader every robocal file reader builds: robocal's settings (a header row, fields
//! trimmed, equal row lengths, the header line's delimiter, true line numbers), blank rows
//! skipped, and the `csv` crate's errors as robocal errors naming the file and line.

use crate::error::{Error, Result};
use crate::io::csv_lines::LineCounted;
use std::io::Read;
use std::path::Path;

/// A CSV reader with robocal's settings: a header row, fields trimmed, equal row lengths, the
/// delimiter of the header line (`,`, `;` or tab), true line numbers ([`LineCounted`]).
pub(crate) fn csv_reader<R: Read>(reader: R) -> csv::Reader<LineCounted<R>> {
    reader_trimming(reader, csv::Trim::All)
}

/// [`csv_reader`] that trims only the header: the cells of each row are left as written, for a
/// reader that reads them through [`ColumnLayout::number`], [`ColumnLayout::extra_values_into`]
/// and [`next_record`], which trim each cell they read (`csv` trims a row by building a new
/// record, an allocation per row).
///
/// [`ColumnLayout::number`]: crate::io::columns::ColumnLayout::number
/// [`ColumnLayout::extra_values_into`]: crate::io::columns::ColumnLayout::extra_values_into
pub(crate) fn csv_reader_header_trimmed<R: Read>(reader: R) -> csv::Reader<LineCounted<R>> {
    reader_trimming(reader, csv::Trim::Headers)
}

fn reader_trimming<R: Read>(reader: R, trim: csv::Trim) -> csv::Reader<LineCounted<R>> {
    let counted = LineCounted::new(reader);
    csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(trim)
        .flexible(false)
        .delimiter(counted.delimiter())
        .from_reader(counted)
}

/// Reads the next row that is not blank into `record`; its 1-based line, or `None` at the end.
pub(crate) fn next_record<R: Read>(
    rdr: &mut csv::Reader<LineCounted<R>>,
    record: &mut csv::StringRecord,
    path: &Path,
) -> Result<Option<usize>> {
    loop {
        let read = rdr.read_record(record);
        if !read.map_err(|e| csv_error(path, e, Some(rdr.get_ref())))? {
            return Ok(None);
        }
        if !record.iter().all(|f| f.trim().is_empty()) {
            let byte = record.position().map_or(0, csv::Position::byte);
            return Ok(Some(rdr.get_ref().line_at(byte)));
        }
    }
}

/// A CSV reader's error as a robocal error: an I/O failure (e.g. the path is a directory) as
/// [`Error::Io`], anything else as [`Error::Parse`] with the line (counted by `lines` where
/// given: the header's errors are on line 1).
pub(crate) fn csv_error<R: Read>(
    path: &Path,
    e: csv::Error,
    lines: Option<&LineCounted<R>>,
) -> Error {
    let line = e.position().map(|p| match lines {
        Some(l) => l.line_at(p.byte()),
        None => p.line() as usize,
    });
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
