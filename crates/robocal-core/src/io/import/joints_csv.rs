//! Joint logs as CSV with a header (`,` `;` or tab; a decimal comma only with `;` or tab; any
//! case): the joint columns are `q1..qn` (model values, written as `q1..qn`), `axis1..axisN`
//! (controller values, written as `axis1..axisN`), or the names `--joint-columns` gives (e.g.
//! `A1..A6`, `J1..J6`, `rax_1..rax_6`: controller values, written as `axis1..axisN`). Degrees
//! unless `--angle-unit rad`. Optional: a time column (`time_s`, `time`, `timestamp`, `t`) and
//! a point-name column (`--name-column`, else `id`, `name`, `point`).

use super::headed::NAME_COLUMNS;
use super::joints::{JointKind, JointLayout};
use super::lines::{Delimiter, Dialect};
use super::units::{split_header, AngleUnit};
use super::{ImportConfig, JointsFormat};
use crate::error::{Error, Result};
use std::path::Path;

/// Names of a time column.
pub const TIME_COLUMNS: [&str; 5] = ["time_s", "time", "timestamp", "t", "time stamp"];

/// The layout of a CSV joint log from its header.
pub fn layout(
    path: &Path,
    line: usize,
    header: &str,
    config: &ImportConfig,
) -> Result<JointLayout> {
    let delimiter = Delimiter::of_header(header);
    let mut cells = Vec::new();
    delimiter.split(header, &mut cells);
    let names: Vec<String> = cells.iter().map(|c| split_header(c).0).collect();
    let find = |n: &str| names.iter().position(|h| h == n);
    let listing = || {
        format!(
            "the header, read as {} columns separated by {}, has: {}",
            cells.len(),
            delimiter,
            cells.join(" | ")
        )
    };
    let (kind, joint_fields, joint_names) = if let Some(given) = &config.joint_columns {
        let mut fields = Vec::new();
        for g in given {
            let f = find(&g.to_lowercase()).ok_or_else(|| {
                Error::parse(
                    path,
                    Some(line),
                    Some(g),
                    format!(
                        "missing column (given by the `joint_columns` setting; {})",
                        listing()
                    ),
                )
            })?;
            fields.push(f);
        }
        (JointKind::Axis, fields, given.clone())
    } else {
        let run = |prefix: &str| -> (Vec<usize>, Vec<String>) {
            let mut f = Vec::new();
            let mut n = Vec::new();
            for k in 1.. {
                match find(&format!("{prefix}{k}")) {
                    Some(i) => {
                        f.push(i);
                        n.push(cells[i].to_string());
                    }
                    None => break,
                }
            }
            (f, n)
        };
        let (qf, qn) = run("q");
        let (af, an) = run("axis");
        if !qf.is_empty() {
            (JointKind::Model, qf, qn)
        } else if !af.is_empty() {
            (JointKind::Axis, af, an)
        } else {
            return Err(Error::parse(
                path,
                Some(line),
                Some("q1"),
                format!(
                    "no joint columns q1..qn or axis1..axisN; name them with the `joint_columns` setting \
                     (e.g. A1,A2,A3,A4,A5,A6); {}",
                    listing()
                ),
            ));
        }
    };
    let time = TIME_COLUMNS
        .iter()
        .find_map(|t| find(t))
        .map(|f| (cells[f].to_string(), f));
    let name = match &config.name_column {
        Some(n) => Some(
            find(&n.to_lowercase())
                .map(|f| (cells[f].to_string(), f))
                .ok_or_else(|| {
                    Error::parse(
                        path,
                        Some(line),
                        Some(n),
                        format!(
                            "missing column (given by the `name_column` setting; {})",
                            listing()
                        ),
                    )
                })?,
        ),
        None => NAME_COLUMNS
            .iter()
            .find_map(|t| find(t))
            .map(|f| (cells[f].to_string(), f)),
    };
    let (angle_unit, unit_source) = match config.angle_unit {
        Some(u) => (u, "the `angle_unit` setting".to_owned()),
        None => (AngleUnit::Deg, "robocal's convention for csv".to_owned()),
    };
    Ok(JointLayout {
        path: path.to_owned(),
        format: JointsFormat::Csv,
        dialect: Dialect {
            delimiter,
            decimal: if delimiter == Delimiter::Comma {
                '.'
            } else {
                ','
            },
            header_line: Some(line),
        },
        joint_names,
        joint_fields,
        kind,
        angle_unit,
        unit_source,
        time,
        name,
        n_fields: cells.len(),
    })
}

/// Whether a first line is data (every field a number), not a header.
pub fn is_headerless(first: &str) -> bool {
    let d = Delimiter::of_header(first);
    let mut f = Vec::new();
    d.split(first, &mut f);
    !f.is_empty()
        && f.iter().all(|v| {
            super::lines::is_number(v)
                || (d != Delimiter::Comma && super::lines::is_comma_number(v))
        })
}

/// The layout of a headerless joint file: every field is a joint value, `q1..qn` in order.
pub fn headerless(path: &Path, first: &str, config: &ImportConfig) -> Result<JointLayout> {
    if config.joint_columns.is_some() || config.name_column.is_some() {
        return Err(Error::parse(
            path,
            None,
            None,
            "the file has no header, so it has no named columns (neither the `joint_columns` \
             setting nor the `name_column` setting applies)",
        ));
    }
    let delimiter = Delimiter::of_header(first);
    let mut f = Vec::new();
    delimiter.split(first, &mut f);
    let n = f.len();
    let (angle_unit, unit_source) = match config.angle_unit {
        Some(u) => (u, "the `angle_unit` setting".to_owned()),
        None => (AngleUnit::Deg, "robocal's convention for csv".to_owned()),
    };
    Ok(JointLayout {
        path: path.to_owned(),
        format: JointsFormat::Csv,
        dialect: Dialect {
            delimiter,
            decimal: if delimiter == Delimiter::Comma {
                '.'
            } else {
                ','
            },
            header_line: None,
        },
        joint_names: (1..=n).map(|k| format!("column {k}")).collect(),
        joint_fields: (0..n).collect(),
        kind: JointKind::Model,
        angle_unit,
        unit_source,
        time: None,
        name: None,
        n_fields: n,
    })
}
