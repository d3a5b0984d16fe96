//! Semicolon `.xyz` lines without a header: `NAME;X;Y;Z;;;;` (trailing empty fields allowed; a
//! decimal point or comma). The file does not say its unit: `--length-unit` is required.

use super::lines::{number, Delimiter, Dialect, LineReader};
use super::points::{resolve_length_unit, PointRow, PointTable};
use super::{ImportConfig, PointsFormat};
use crate::error::{Error, Result};
use std::io::BufRead;

/// Whether a line looks like an xyz line: a name, then three numbers, separated by `;`.
pub fn looks_like(line: &str) -> bool {
    let f: Vec<&str> = line.split(';').map(str::trim).collect();
    f.len() >= 4
        && !f[0].is_empty()
        && f[1..4]
            .iter()
            .all(|v| super::lines::is_number(v) || super::lines::is_comma_number(v))
}

/// Reads an xyz file.
pub fn read<R: BufRead>(lines: &mut LineReader<R>, config: &ImportConfig) -> Result<PointTable> {
    let path = lines.path().to_owned();
    let (unit, unit_source) = resolve_length_unit(&path, None, config.length_unit, None)?;
    let mut rows = Vec::new();
    let mut decimal = None;
    while let Some((line, text)) = lines.next_line()? {
        let mut fields = Vec::with_capacity(8);
        if text.trim().is_empty() {
            continue;
        }
        Delimiter::Semicolon.split(text, &mut fields);
        if fields.len() < 4 {
            return Err(Error::parse(
                &path,
                Some(line),
                None,
                format!(
                    "{} fields separated by `;`; an xyz line is NAME;X;Y;Z (a truncated file?)",
                    fields.len()
                ),
            ));
        }
        if let Some(extra) = fields[4..].iter().find(|f| !f.is_empty()) {
            return Err(Error::parse(
                &path,
                Some(line),
                Some("5"),
                format!("unexpected value `{extra}` after NAME;X;Y;Z"),
            ));
        }
        let dec = *decimal.get_or_insert(if fields[1].contains(',') { ',' } else { '.' });
        let mut p = [0.0; 3];
        for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
            p[k] = number(&path, line, axis, fields[k + 1], dec)?;
        }
        rows.push(PointRow {
            line,
            name: Some(fields[0].to_owned()).filter(|n| !n.is_empty()),
            p,
            abc_deg: None,
            sigma_mm: None,
            temperature_c: None,
            time_s: None,
        });
    }
    super::points::finish(PointTable {
        path,
        format: PointsFormat::Xyz,
        dialect: Dialect {
            delimiter: Delimiter::Semicolon,
            decimal: decimal.unwrap_or('.'),
            header_line: None,
        },
        length_unit: unit,
        unit_source,
        ignored_columns: Vec::new(),
        deleted_lines: Vec::new(),
        rows,
    })
}
