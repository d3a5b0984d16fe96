//! Headerless text points: `x y z` per line, separated by whitespace or commas (`NAME x y z`
//! when the first of four fields is not a number). The file does not say its unit:
//! `--length-unit` is required.

use super::lines::{is_number, number, Delimiter, Dialect, LineReader};
use super::points::{resolve_length_unit, PointRow, PointTable};
use super::{ImportConfig, PointsFormat};
use crate::error::{Error, Result};
use std::io::BufRead;

/// Whether a line looks like headerless points: three numbers, or a name and three numbers.
pub fn looks_like(line: &str) -> bool {
    let mut f = Vec::new();
    delimiter_of(line).split(line, &mut f);
    match f.len() {
        3 => f.iter().all(|v| is_number(v)),
        4 => f[1..].iter().all(|v| is_number(v)),
        _ => false,
    }
}

fn delimiter_of(line: &str) -> Delimiter {
    if line.contains(',') {
        Delimiter::Comma
    } else {
        Delimiter::Whitespace
    }
}

/// Reads a headerless points file.
pub fn read<R: BufRead>(lines: &mut LineReader<R>, config: &ImportConfig) -> Result<PointTable> {
    let path = lines.path().to_owned();
    let (unit, unit_source) = resolve_length_unit(&path, None, config.length_unit, None)?;
    let mut rows = Vec::new();
    let mut delimiter = None;
    let mut width = None;
    while let Some((line, text)) = lines.next_line()? {
        let mut fields = Vec::with_capacity(4);
        if text.trim().is_empty() {
            continue;
        }
        let d = *delimiter.get_or_insert_with(|| delimiter_of(text));
        d.split(text, &mut fields);
        let w = *width.get_or_insert(fields.len());
        if fields.len() != w || !(3..=4).contains(&w) {
            return Err(Error::parse(
                &path,
                Some(line),
                None,
                format!(
                    "{} fields ({} separated) where the file's lines have x y z{} (a truncated \
                     file?)",
                    fields.len(),
                    d,
                    if w == 4 { " after a name" } else { "" }
                ),
            ));
        }
        let off = w - 3;
        let mut p = [0.0; 3];
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            p[k] = number(&path, line, axis, fields[k + off], '.')?;
        }
        rows.push(PointRow {
            line,
            name: (off == 1).then(|| fields[0].to_owned()),
            p,
            abc_deg: None,
            sigma_mm: None,
            temperature_c: None,
            time_s: None,
        });
    }
    super::points::finish(PointTable {
        path,
        format: PointsFormat::Text,
        dialect: Dialect {
            delimiter: delimiter.unwrap_or(Delimiter::Whitespace),
            decimal: '.',
            header_line: None,
        },
        length_unit: unit,
        unit_source,
        ignored_columns: Vec::new(),
        deleted_lines: Vec::new(),
        rows,
    })
}
