//! The UR RTDE recorder's output: space separated, a header with `timestamp` (s) and
//! `actual_q_0..actual_q_5` (radians), any other columns (ignored). The joint values are the
//! UR model's joint values (written as `q1..q6` in degrees).

use super::joints::{JointKind, JointLayout};
use super::lines::{Delimiter, Dialect};
use super::units::AngleUnit;
use super::{ImportConfig, JointsFormat};
use crate::error::{Error, Result};
use std::path::Path;

/// Whether a header is an RTDE recorder's.
pub fn looks_like(header: &str) -> bool {
    let mut f = header.split_whitespace();
    f.any(|c| c == "timestamp") && header.split_whitespace().any(|c| c == "actual_q_0")
}

/// The layout of an RTDE log from its header.
pub fn layout(
    path: &Path,
    line: usize,
    header: &str,
    config: &ImportConfig,
) -> Result<JointLayout> {
    if config.angle_unit == Some(AngleUnit::Deg) {
        return Err(Error::parse(
            path,
            Some(line),
            None,
            "RTDE logs hold radians; drop the `angle_unit` setting (deg)",
        ));
    }
    let cells: Vec<&str> = header.split_whitespace().collect();
    let time = cells
        .iter()
        .position(|c| *c == "timestamp")
        .ok_or_else(|| Error::parse(path, Some(line), Some("timestamp"), "missing column"))?;
    let mut joint_fields = Vec::new();
    let mut joint_names = Vec::new();
    for k in 0.. {
        let name = format!("actual_q_{k}");
        match cells.iter().position(|c| *c == name) {
            Some(f) => {
                joint_fields.push(f);
                joint_names.push(name);
            }
            None => break,
        }
    }
    if joint_fields.is_empty() {
        return Err(Error::parse(
            path,
            Some(line),
            Some("actual_q_0"),
            "missing column",
        ));
    }
    Ok(JointLayout {
        path: path.to_owned(),
        format: JointsFormat::Rtde,
        dialect: Dialect {
            delimiter: Delimiter::Whitespace,
            decimal: '.',
            header_line: Some(line),
        },
        joint_names,
        joint_fields,
        kind: JointKind::Model,
        angle_unit: AngleUnit::Rad,
        unit_source: "RTDE's unit".into(),
        time: Some(("timestamp".into(), time)),
        name: None,
        n_fields: cells.len(),
    })
}
