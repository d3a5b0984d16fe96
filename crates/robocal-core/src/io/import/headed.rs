//! Tracker exports with a header row (Leica and generic CSV): the header is classified into the
//! columns robocal uses by the format's own names ([`super::leica`], [`super::csv_points`]),
//! the rest are listed as ignored, and each row becomes a [`PointRow`].

use super::lines::{comma_ambiguity, is_comma_number, number, Delimiter, Dialect, LineReader};
use super::points::{quaternion_abc, resolve_length_unit, PointRow, PointTable, U95_PER_SIGMA};
use super::timestamp;
use super::units::LengthUnit;
use super::{ImportConfig, PointsFormat};
use crate::error::{Error, Result};
use std::io::BufRead;

/// A column robocal reads from a tracker export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Col {
    /// x, y or z (0, 1, 2).
    Pos(usize),
    /// A 6-DoF orientation angle A, B or C in degrees (0, 1, 2).
    Abc(usize),
    /// Quaternion component 0..3 (scalar first).
    Quat(usize),
    /// Expanded uncertainty U(95).
    U95,
    /// 1-sigma uncertainty (mm).
    Sigma,
    /// Temperature.
    Temperature,
    /// Time stamp.
    Time,
    /// The point's name.
    Name,
    /// A mark that the point was deleted in the tracker software (Leica's `Delete`): such rows
    /// are left out and listed.
    Deleted,
}

/// How a format names its columns: `classify(name)` for a header cell's lower-case name
/// (unit removed).
pub struct Naming {
    /// The format.
    pub format: PointsFormat,
    /// The column a header name stands for.
    pub classify: fn(&str) -> Option<Col>,
    /// The unit a file of this format has when its header names none.
    pub default_unit: Option<(LengthUnit, &'static str)>,
}

/// Default names of a point-name column.
pub const NAME_COLUMNS: [&str; 5] = ["name", "id", "point", "point id", "point name"];

struct Layout {
    cols: Vec<(usize, Col, String)>,
    n_header: usize,
}

/// The units a header names for the columns robocal reads.
#[derive(Default)]
struct HeaderUnits {
    /// The positions' unit and where it was named (the first position header with a unit).
    length: Option<(LengthUnit, String)>,
    /// The unit of the U(95) column, if its header names one.
    u95: Option<LengthUnit>,
    /// Whether the temperature column is in degrees Fahrenheit.
    fahrenheit: bool,
}

/// A header row read into the columns robocal uses.
struct Header {
    /// The columns robocal reads, and the header's width.
    layout: Layout,
    /// The header cells of the columns robocal does not use.
    ignored: Vec<String>,
    /// The units the header names.
    units: HeaderUnits,
}

/// The data rows of an export.
struct Body {
    /// The rows kept.
    rows: Vec<PointRow>,
    /// The lines of the rows marked as deleted.
    deleted_lines: Vec<usize>,
    /// The decimal mark, found from the first row (none without rows).
    decimal: Option<char>,
}

/// Reads a headed export: the header row classified into columns and checked, the length unit
/// resolved, then the data rows read into a [`PointTable`].
pub fn read<R: BufRead>(
    lines: &mut LineReader<R>,
    naming: &Naming,
    config: &ImportConfig,
) -> Result<PointTable> {
    let path = lines.path().to_owned();
    let (header_line, header) = header_row(lines, &path)?;
    let delimiter = Delimiter::of_header(&header);
    let mut cells = Vec::new();
    delimiter.split(&header, &mut cells);
    let Header {
        layout,
        ignored,
        units,
    } = classify_header(&path, header_line, &cells, naming, config)?;
    check_columns(&path, header_line, &layout, &cells, delimiter)?;
    let (unit, unit_source) =
        resolve_length_unit(&path, units.length, config.length_unit, naming.default_unit)?;
    let u95_k = units.u95.unwrap_or(unit).to_mm() / unit.to_mm();
    let body = read_rows(
        lines,
        &path,
        header_line,
        delimiter,
        &layout,
        [u95_k, 1.0 / unit.to_mm()],
        units.fahrenheit,
    )?;
    super::points::finish(PointTable {
        path,
        format: naming.format,
        dialect: Dialect {
            delimiter,
            decimal: body.decimal.unwrap_or('.'),
            header_line: Some(header_line),
        },
        length_unit: unit,
        unit_source,
        ignored_columns: ignored,
        rows: body.rows,
        deleted_lines: body.deleted_lines,
    })
}

/// The first non-blank line (the header) and its line number; an error for a file without one.
fn header_row<R: BufRead>(
    lines: &mut LineReader<R>,
    path: &std::path::Path,
) -> Result<(usize, String)> {
    loop {
        match lines.next_line()? {
            None => return Err(Error::parse(path, None, None, "empty file: no header row")),
            Some((_, l)) if l.trim().is_empty() => continue,
            Some((n, l)) => return Ok((n, l.to_owned())),
        }
    }
}

/// Classifies the header cells into the columns robocal reads (the rest listed as ignored),
/// with the units they name; an error for a second column of the same quantity or a unit it
/// does not know.
fn classify_header(
    path: &std::path::Path,
    header_line: usize,
    cells: &[&str],
    naming: &Naming,
    config: &ImportConfig,
) -> Result<Header> {
    let mut layout = Layout {
        cols: Vec::new(),
        n_header: cells.len(),
    };
    let mut ignored = Vec::new();
    let mut units = HeaderUnits::default();
    let wanted_name = config.name_column.as_deref().map(str::to_lowercase);
    for (i, cell) in cells.iter().enumerate() {
        let (name, unit) = super::units::split_header(cell);
        let Some(col) = column_of(&name, wanted_name.as_deref(), naming) else {
            if !cell.is_empty() {
                ignored.push(cell.to_string());
            }
            continue;
        };
        if layout.cols.iter().any(|(_, c, _)| *c == col) {
            return Err(Error::parse(
                path,
                Some(header_line),
                Some(cell),
                "a second column for the same quantity",
            ));
        }
        note_unit(path, header_line, cell, col, &unit, &mut units)?;
        layout.cols.push((i, col, cell.to_string()));
    }
    Ok(Header {
        layout,
        ignored,
        units,
    })
}

/// The column a header name (lower case, unit removed) stands for: the `name_column` setting's
/// name is the point name, and then the default name columns are not; otherwise the format's
/// naming decides.
fn column_of(name: &str, wanted_name: Option<&str>, naming: &Naming) -> Option<Col> {
    match wanted_name {
        Some(w) if w == name => Some(Col::Name),
        Some(_) if NAME_COLUMNS.contains(&name) => None,
        _ => (naming.classify)(name),
    }
}

/// Records the unit a header cell gives its column (positions, U(95), temperature) in `units`;
/// an error for a unit it does not know or positions in two different units.
fn note_unit(
    path: &std::path::Path,
    header_line: usize,
    cell: &str,
    col: Col,
    unit: &Option<String>,
    units: &mut HeaderUnits,
) -> Result<()> {
    let unit_err = |u: &str| {
        Error::parse(
            path,
            Some(header_line),
            Some(cell),
            format!("unknown unit `{u}` (mm, m or in); give the `length_unit` setting instead"),
        )
    };
    match (col, unit) {
        (Col::Pos(_), Some(u)) => {
            let lu = LengthUnit::from_word(u).ok_or_else(|| unit_err(u))?;
            match &units.length {
                Some((other, w)) if *other != lu => {
                    return Err(Error::parse(
                        path,
                        Some(header_line),
                        Some(cell),
                        format!("in {lu}, but {w} is in {other}"),
                    ))
                }
                Some(_) => {}
                None => units.length = Some((lu, format!("header `{}`", cell.trim()))),
            }
        }
        (Col::U95, Some(u)) => {
            units.u95 = Some(LengthUnit::from_word(u).ok_or_else(|| unit_err(u))?);
        }
        (Col::Temperature, Some(u)) => {
            let u = u.trim_start_matches(['°', 'º']).to_ascii_lowercase();
            match u.as_str() {
                "c" => {}
                "f" => units.fahrenheit = true,
                _ => {
                    return Err(Error::parse(
                        path,
                        Some(header_line),
                        Some(cell),
                        format!("unknown temperature unit `{u}` (C or F)"),
                    ))
                }
            }
        }
        _ => {}
    }
    Ok(())
}

/// Checks that the header has the x, y and z columns, all four quaternion columns or none, and
/// all three of a, b, c or none.
fn check_columns(
    path: &std::path::Path,
    header_line: usize,
    layout: &Layout,
    cells: &[&str],
    delimiter: Delimiter,
) -> Result<()> {
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        if !layout.cols.iter().any(|(_, c, _)| *c == Col::Pos(k)) {
            return Err(Error::parse(
                path,
                Some(header_line),
                Some(axis),
                format!(
                    "missing column (the header, read as {} columns separated by {}, has: {})",
                    cells.len(),
                    delimiter,
                    cells.join(" | ")
                ),
            ));
        }
    }
    let quats = layout
        .cols
        .iter()
        .filter(|(_, c, _)| matches!(c, Col::Quat(_)))
        .count();
    if quats != 0 && quats != 4 {
        return Err(Error::parse(
            path,
            Some(header_line),
            Some("Q0..Q3"),
            "a quaternion needs all four columns Q0, Q1, Q2, Q3",
        ));
    }
    let abcs = layout
        .cols
        .iter()
        .filter(|(_, c, _)| matches!(c, Col::Abc(_)))
        .count();
    if abcs != 0 && abcs != 3 {
        return Err(Error::parse(
            path,
            Some(header_line),
            Some("a,b,c"),
            "an orientation needs all three columns a, b, c",
        ));
    }
    Ok(())
}

/// Reads the data rows after the header: blank lines skipped, rows marked as deleted listed,
/// the decimal mark taken from the first row's x.
fn read_rows<R: BufRead>(
    lines: &mut LineReader<R>,
    path: &std::path::Path,
    header_line: usize,
    delimiter: Delimiter,
    layout: &Layout,
    // U(95) and sigma_mm values into the file's length unit (`finish` converts to mm).
    k: [f64; 2],
    fahrenheit: bool,
) -> Result<Body> {
    let mut decimal = None;
    let mut rows = Vec::new();
    let mut deleted_lines = Vec::new();
    while let Some((line, text)) = lines.next_line()? {
        let mut fields = Vec::with_capacity(layout.n_header);
        if text.trim().is_empty() {
            continue;
        }
        delimiter.split(text, &mut fields);
        check_field_count(
            path,
            line,
            header_line,
            delimiter,
            layout.n_header,
            fields.len(),
        )?;
        let dec = *decimal.get_or_insert_with(|| decimal_mark(&fields, layout, delimiter));
        if is_deleted(path, line, &fields, layout)? {
            deleted_lines.push(line);
            continue;
        }
        rows.push(row(path, line, &fields, layout, dec, k, fahrenheit)?);
    }
    Ok(Body {
        rows,
        deleted_lines,
        decimal,
    })
}

/// Checks that a row has as many fields as the header: more with comma separators is the
/// decimal-comma ambiguity, otherwise a truncated export.
fn check_field_count(
    path: &std::path::Path,
    line: usize,
    header_line: usize,
    delimiter: Delimiter,
    n_header: usize,
    n_fields: usize,
) -> Result<()> {
    if n_fields != n_header {
        if delimiter == Delimiter::Comma && n_fields > n_header {
            return Err(comma_ambiguity(path, line, n_header, n_fields));
        }
        return Err(Error::parse(
            path,
            Some(line),
            None,
            format!(
                "{n_fields} fields where the header (line {header_line}) has {n_header} (a \
                 truncated export?)"
            ),
        ));
    }
    Ok(())
}

/// The decimal mark of the export, from a row's x: a comma when the separator is not one and
/// x reads as a decimal-comma number, otherwise a point.
fn decimal_mark(fields: &[&str], layout: &Layout, delimiter: Delimiter) -> char {
    let x = layout
        .cols
        .iter()
        .find(|(_, c, _)| *c == Col::Pos(0))
        .unwrap()
        .0;
    if delimiter != Delimiter::Comma && is_comma_number(fields[x]) {
        ','
    } else {
        '.'
    }
}

/// Whether the row's deletion mark (if the export has the column) says the point was deleted:
/// `1`, `true`, `yes`, `x` (any case) yes; empty, `0`, `false`, `no` no; anything else is an
/// error naming the line.
fn is_deleted(
    path: &std::path::Path,
    line: usize,
    fields: &[&str],
    layout: &Layout,
) -> Result<bool> {
    let Some((i, _, h)) = layout.cols.iter().find(|(_, c, _)| *c == Col::Deleted) else {
        return Ok(false);
    };
    match fields[*i].trim().to_ascii_lowercase().as_str() {
        "1" | "true" | "yes" | "x" => Ok(true),
        "" | "0" | "false" | "no" => Ok(false),
        v => Err(Error::parse(
            path,
            Some(line),
            Some(h),
            format!("`{v}` is not a deletion mark (1/0, true/false, yes/no)"),
        )),
    }
}

fn row(
    path: &std::path::Path,
    line: usize,
    fields: &[&str],
    layout: &Layout,
    dec: char,
    // U(95) and sigma_mm values into the file's length unit (`finish` converts to mm).
    k: [f64; 2],
    fahrenheit: bool,
) -> Result<PointRow> {
    let mut r = PointRow {
        line,
        name: None,
        p: [0.0; 3],
        abc_deg: None,
        sigma_mm: None,
        temperature_c: None,
        time_s: None,
    };
    let mut quat = [None; 4];
    let mut abc = [0.0; 3];
    let num = |i: usize, h: &str| number(path, line, h, fields[i], dec);
    for (i, col, h) in &layout.cols {
        let v = fields[*i];
        let optional = !matches!(col, Col::Pos(_));
        if v.is_empty() && optional {
            continue;
        }
        match *col {
            Col::Pos(k) => r.p[k] = num(*i, h)?,
            Col::Abc(k) => {
                abc[k] = num(*i, h)?;
                r.abc_deg = Some(abc);
            }
            Col::Quat(k) => quat[k] = Some(num(*i, h)?),
            Col::U95 => r.sigma_mm = Some(num(*i, h)? * k[0] / U95_PER_SIGMA),
            Col::Sigma => r.sigma_mm = Some(num(*i, h)? * k[1]),
            Col::Temperature => {
                let t = num(*i, h)?;
                r.temperature_c = Some(if fahrenheit {
                    (t - 32.0) * 5.0 / 9.0
                } else {
                    t
                });
            }
            Col::Time => {
                r.time_s = Some(
                    timestamp::seconds(v)
                        .map_err(|m| Error::parse(path, Some(line), Some(h), m))?,
                )
            }
            Col::Name => r.name = Some(v.to_owned()),
            Col::Deleted => {}
        }
    }
    match quat {
        [Some(a), Some(b), Some(c), Some(d)] => {
            r.abc_deg = Some(quaternion_abc(path, line, [a, b, c, d])?)
        }
        [None, None, None, None] => {}
        _ => {
            return Err(Error::parse(
                path,
                Some(line),
                Some("Q0..Q3"),
                "some quaternion components are empty",
            ))
        }
    }
    if r.abc_deg.is_some()
        && layout
            .cols
            .iter()
            .any(|(i, c, _)| matches!(c, Col::Abc(_)) && fields[*i].is_empty())
    {
        return Err(Error::parse(
            path,
            Some(line),
            Some("a,b,c"),
            "some of a, b, c are empty",
        ));
    }
    Ok(r)
}
