//! Points in a CSV with a header: `x,y,z` in any case (a unit in brackets allowed, e.g.
//! `X [m]`; without one, millimetres, robocal's convention), optional `a,b,c` (deg),
//! `sigma_mm`, `temperature_c`, `time_s` (or `time`, `timestamp`) and a point name (`id`,
//! `name`, `point`, or `--name-column`). Separators `,` `;` or tab; a decimal comma only with
//! `;` or tab.

use super::headed::{Col, Naming, NAME_COLUMNS};
use super::lines::LineReader;
use super::points::PointTable;
use super::units::LengthUnit;
use super::{ImportConfig, PointsFormat};
use crate::error::Result;
use std::io::BufRead;

/// The column a CSV header name stands for.
pub fn classify(name: &str) -> Option<Col> {
    Some(match name {
        "x" => Col::Pos(0),
        "y" => Col::Pos(1),
        "z" => Col::Pos(2),
        "a" => Col::Abc(0),
        "b" => Col::Abc(1),
        "c" => Col::Abc(2),
        "sigma_mm" | "sigma" => Col::Sigma,
        "temperature_c" | "temperature" => Col::Temperature,
        "time_s" | "time" | "timestamp" | "time stamp" => Col::Time,
        n if NAME_COLUMNS.contains(&n) => Col::Name,
        _ => return None,
    })
}

/// Reads a points CSV.
pub fn read<R: BufRead>(lines: &mut LineReader<R>, config: &ImportConfig) -> Result<PointTable> {
    super::headed::read(
        lines,
        &Naming {
            format: PointsFormat::Csv,
            classify,
            default_unit: Some((LengthUnit::Mm, "robocal's convention for csv")),
        },
        config,
    )
}
