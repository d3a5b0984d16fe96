//! SpatialAnalyzer ASCII point exports: optional `//` header lines (version, frame, units:
//! `// Units: Millimeters`), then `Collection Group Target X Y Z` per line, separated by spaces
//! or commas; one to three name fields (or none) before the coordinates. The point's name is its
//! target name (the last name field). A first line of column names (`Collection Group Target X
//! Y Z`) is skipped.

use super::lines::{is_number, number, Delimiter, Dialect, LineReader};
use super::points::{resolve_length_unit, PointRow, PointTable};
use super::units::LengthUnit;
use super::{ImportConfig, PointsFormat};
use crate::error::{Error, Result};
use std::io::BufRead;

/// The length unit a `//` comment line names after the word "unit(s)", if any.
fn unit_of_comment(c: &str) -> Option<LengthUnit> {
    let lower = c.to_ascii_lowercase();
    let at = lower.find("unit")?;
    lower[at..]
        .split(|ch: char| !ch.is_alphanumeric())
        .skip(1)
        .find_map(LengthUnit::from_word)
}

/// Reads an SA export.
pub fn read<R: BufRead>(lines: &mut LineReader<R>, config: &ImportConfig) -> Result<PointTable> {
    let path = lines.path().to_owned();
    let mut file_unit = None;
    let mut rows = Vec::new();
    let mut delimiter = None;
    let mut header_line = None;
    let mut width = None;
    let mut data: Vec<(usize, Option<String>, [String; 3])> = Vec::new();
    while let Some((line, text)) = lines.next_line()? {
        let mut fields = Vec::with_capacity(8);
        let t = text.trim();
        if t.is_empty() {
            continue;
        }
        if let Some(c) = t.strip_prefix("//") {
            if file_unit.is_none() {
                file_unit = unit_of_comment(c).map(|u| (u, format!("line {line} `{t}`")));
            }
            continue;
        }
        let d = *delimiter.get_or_insert(if t.contains(',') {
            Delimiter::Comma
        } else {
            Delimiter::Whitespace
        });
        d.split(t, &mut fields);
        if data.is_empty() && header_line.is_none() && !fields.iter().any(|f| is_number(f)) {
            header_line = Some(line);
            continue;
        }
        let w = *width.get_or_insert(fields.len());
        if fields.len() != w || !(3..=6).contains(&w) {
            return Err(Error::parse(
                &path,
                Some(line),
                None,
                format!(
                    "{} fields ({d} separated) where the points have {w}: [Collection] [Group] \
                     [Target] X Y Z (a truncated export?)",
                    fields.len()
                ),
            ));
        }
        let name = (w > 3).then(|| fields[w - 4].to_owned());
        data.push((
            line,
            name,
            [
                fields[w - 3].into(),
                fields[w - 2].into(),
                fields[w - 1].into(),
            ],
        ));
    }
    let (unit, unit_source) = resolve_length_unit(&path, file_unit, config.length_unit, None)?;
    for (line, name, xyz) in data {
        let mut p = [0.0; 3];
        for (k, axis) in ["X", "Y", "Z"].iter().enumerate() {
            p[k] = number(&path, line, axis, &xyz[k], '.')?;
        }
        rows.push(PointRow {
            line,
            name,
            p,
            abc_deg: None,
            sigma_mm: None,
            temperature_c: None,
            time_s: None,
        });
    }
    if rows.is_empty() && header_line.is_none() && delimiter.is_none() {
        return Err(Error::parse(&path, None, None, "no points in the file"));
    }
    super::points::finish(PointTable {
        path,
        format: PointsFormat::Sa,
        dialect: Dialect {
            delimiter: delimiter.unwrap_or(Delimiter::Whitespace),
            decimal: '.',
            header_line,
        },
        length_unit: unit,
        unit_source,
        ignored_columns: Vec::new(),
        deleted_lines: Vec::new(),
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_in_comments() {
        assert_eq!(unit_of_comment(" Units: Millimeters"), Some(LengthUnit::Mm));
        assert_eq!(
            unit_of_comment(" Linear Units = Meters"),
            Some(LengthUnit::M)
        );
        assert_eq!(unit_of_comment(" SA version 2023.1"), None);
    }
}
