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

/// Bytes of the log parsed as one block on one thread.
const BLOCK_BYTES: usize = 1 << 22;

/// Reads the rows after the header, calling `sink` for each in file order. Times must increase.
///
/// The log is read in blocks of whole lines, a batch of blocks (two per thread) parsed in
/// parallel, then handed to `sink` in order with the time order checked: the first error of the
/// file is the one reported, as if it were read line by line.
pub fn for_each_row<R: BufRead>(
    lines: &mut LineReader<R>,
    layout: &JointLayout,
    sink: impl FnMut(JointRow<'_>) -> Result<()>,
) -> Result<RowsRead> {
    rows_in_blocks(lines, layout, BLOCK_BYTES, sink)
}

/// [`for_each_row`] in blocks of about `block_bytes`.
fn rows_in_blocks<R: BufRead>(
    lines: &mut LineReader<R>,
    layout: &JointLayout,
    block_bytes: usize,
    mut sink: impl FnMut(JointRow<'_>) -> Result<()>,
) -> Result<RowsRead> {
    use rayon::prelude::*;
    let path = lines.path().to_owned();
    let dof = layout.joint_fields.len();
    let batch = 2 * rayon::current_num_threads().max(1);
    let mut last_time: Option<(f64, usize)> = None;
    let mut n = 0;
    let mut decimal_comma = false;
    // The blocks' and their rows' memory, reused batch after batch.
    let mut blocks: Vec<Vec<u8>> = (0..batch).map(|_| Vec::new()).collect();
    let mut parsed: Vec<ParsedBlock> = (0..batch).map(|_| ParsedBlock::default()).collect();
    loop {
        let mut filled = 0;
        while filled < batch && lines.read_block_into(block_bytes, &mut blocks[filled])? {
            filled += 1;
        }
        if filled == 0 {
            break;
        }
        // Each block's first line number: its lines counted in parallel.
        let counts: Vec<usize> = blocks[..filled]
            .par_iter()
            .map(|b| {
                b.iter().filter(|&&c| c == b'\n').count() + usize::from(b.last() != Some(&b'\n'))
            })
            .collect();
        let mut firsts = Vec::with_capacity(filled);
        for c in &counts {
            firsts.push(lines.line() + 1);
            lines.skip_lines(*c);
        }
        blocks[..filled]
            .par_iter()
            .zip(parsed[..filled].par_iter_mut())
            .zip(&firsts)
            .for_each(|((b, out), &first)| parse_block(&path, layout, first, b, out));
        for b in &mut parsed[..filled] {
            decimal_comma |= b.decimal_comma;
            for (r, &line) in b.lines.iter().enumerate() {
                let time_s = match &layout.time {
                    Some((name, _)) => {
                        let t = b.times[r];
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
                sink(JointRow {
                    line,
                    time_s,
                    name: b.names.get(r).map(String::as_str),
                    q_deg: &b.q[r * dof..(r + 1) * dof],
                })?;
                n += 1;
            }
            if let Some(e) = b.error.take() {
                return Err(e);
            }
        }
    }
    if n == 0 {
        return Err(Error::parse(&path, None, None, "no rows after the header"));
    }
    Ok(RowsRead {
        rows: n,
        decimal_comma,
    })
}

/// One block's rows, parsed (joint values `dof` a row, in degrees), up to its first error.
#[derive(Default)]
struct ParsedBlock {
    lines: Vec<usize>,
    q: Vec<f64>,
    /// Times (when the log has a time column).
    times: Vec<f64>,
    /// Point names (when the log has a name column).
    names: Vec<String>,
    decimal_comma: bool,
    error: Option<Error>,
}

/// Parses the lines of `bytes` (whole lines, the first numbered `first_line`) into `out`.
fn parse_block(
    path: &Path,
    layout: &JointLayout,
    first_line: usize,
    bytes: &[u8],
    out: &mut ParsedBlock,
) {
    out.lines.clear();
    out.q.clear();
    out.times.clear();
    out.names.clear();
    out.decimal_comma = false;
    out.error = None;
    let body = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    let mut fields = Vec::with_capacity(layout.n_fields);
    for (i, raw) in body.split(|&c| c == b'\n').enumerate() {
        let line = first_line + i;
        let mut raw = raw;
        while let Some(r) = raw.strip_suffix(b"\r") {
            raw = r;
        }
        if let Err(e) = parse_row(path, layout, line, raw, &mut fields, out) {
            out.error = Some(e);
            break;
        }
    }
}

/// Parses one line into `out` (nothing for a blank line).
fn parse_row<'a>(
    path: &Path,
    layout: &JointLayout,
    line: usize,
    raw: &'a [u8],
    fields: &mut Vec<&'a str>,
    out: &mut ParsedBlock,
) -> Result<()> {
    let mut text = std::str::from_utf8(raw)
        .map_err(|_| Error::parse(path, Some(line), None, "not UTF-8 text"))?;
    if line == 1 {
        text = text.strip_prefix('\u{feff}').unwrap_or(text);
    }
    if text.trim().is_empty() {
        return Ok(());
    }
    layout.dialect.delimiter.split(text, fields);
    if fields.len() != layout.n_fields {
        if layout.dialect.delimiter == Delimiter::Comma && fields.len() > layout.n_fields {
            return Err(super::lines::comma_ambiguity(
                path,
                line,
                layout.n_fields,
                fields.len(),
            ));
        }
        return Err(Error::parse(
            path,
            Some(line),
            None,
            format!(
                "{} fields where the header has {} (a truncated log?)",
                fields.len(),
                layout.n_fields
            ),
        ));
    }
    // A row that fails leaves values in `q` past `lines`: the block ends there, unread.
    let dec = layout.dialect.decimal;
    for (&f, name) in layout.joint_fields.iter().zip(&layout.joint_names) {
        out.decimal_comma |= dec == ',' && fields[f].contains(',');
        let v = layout
            .angle_unit
            .deg(number(path, line, name, fields[f], dec)?);
        if !ranges::JOINT.contains(v) {
            return Err(Error::parse(
                path,
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
        out.q.push(v);
    }
    if let Some((name, f)) = &layout.time {
        match super::timestamp::seconds(fields[*f]) {
            Ok(t) => out.times.push(t),
            Err(m) => return Err(Error::parse(path, Some(line), Some(name), m)),
        }
    }
    if let Some((_, f)) = &layout.name {
        out.names.push(fields[*f].to_owned());
    }
    out.lines.push(line);
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::import::{ImportConfig, MatchBy};

    type Rows = Vec<(usize, Option<f64>, Vec<f64>)>;

    /// The rows (line, time, q) of `text` read in blocks of `block` bytes, or the error.
    fn rows(text: &str, block: usize) -> std::result::Result<Rows, String> {
        let path = Path::new("log.txt");
        let config = ImportConfig::new(MatchBy::Time);
        let mut lines = LineReader::new(text.as_bytes(), path);
        let (hline, header) = header_line(&mut lines).unwrap();
        let layout = super::super::rtde::layout(path, hline, &header, &config).unwrap();
        let mut out = Vec::new();
        rows_in_blocks(&mut lines, &layout, block, |r| {
            out.push((r.line, r.time_s, r.q_deg.to_vec()));
            Ok(())
        })
        .map_err(|e| e.to_string())?;
        Ok(out)
    }

    /// Blocks of any size (one byte to the whole file) read the same rows with the same line
    /// numbers through CRLF, blank lines and a last line without its ending, and stop at the
    /// same first error.
    #[test]
    fn blocks_of_any_size_read_as_lines_do() {
        let mut text = String::from("timestamp actual_q_0 actual_q_1\r\n");
        for k in 0..200 {
            let end = if k % 3 == 0 { "\r\n" } else { "\n" };
            text.push_str(&format!(
                "{} {} {}{end}",
                k as f64 * 0.008,
                k as f64 * 1e-3,
                -0.5
            ));
            if k % 17 == 0 {
                text.push_str("\n  \r\n");
            }
        }
        text.push_str("1.6 0.2 0.3");
        let whole = rows(&text, 1 << 22).unwrap();
        assert_eq!(whole.len(), 201);
        assert_eq!(whole[0].0, 2);
        assert_eq!(whole[1].0, 5, "two blank lines after the first row");
        assert_eq!(whole[200].0, text.lines().count());
        assert!((whole[7].2[0] - (7e-3f64).to_degrees()).abs() < 1e-12);
        for block in [1, 7, 64, 1000] {
            assert_eq!(rows(&text, block).unwrap(), whole, "block of {block} bytes");
        }
        // Errors: a bad number at line 40, then times out of order at line 30 before it; the
        // first in the file is reported whatever the blocks.
        let mut bad: Vec<String> = text.lines().map(String::from).collect();
        bad[39] = "0.3 x 0.1".into();
        let bad1 = bad.join("\n");
        bad[29] = "0.0 0.1 0.1".into();
        let bad2 = bad.join("\n");
        for block in [1, 7, 64, 1000, 1 << 22] {
            let e = rows(&bad1, block).unwrap_err();
            assert!(e.contains("log.txt:40: field `actual_q_0`"), "{block}: {e}");
            let e = rows(&bad2, block).unwrap_err();
            assert!(
                e.contains("log.txt:30:") && e.contains("is not after"),
                "{block}: {e}"
            );
        }
    }
}
