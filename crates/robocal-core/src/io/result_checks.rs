//! The checks a result file passes on reading beyond its JSON shape ([`CalibrationResult::parse`]):
//! a `status` robocal writes, and every number within its plausible range ([`crate::ranges`]).

use super::ParamEntry;
use super::{CalibrationResult, FrameVec, StatusValue, KNOWN_STATUSES};
use crate::error::{Error, Result};
use crate::model::Robot;
use indexmap::IndexMap;
use std::path::Path;

/// The checks of [`CalibrationResult::parse`] on a result read from `text` (without a byte
/// order mark): status, ranges and the robot it describes, whose nominal model it returns.
pub(super) fn check_read(
    r: CalibrationResult,
    text: &str,
    path: &Path,
) -> Result<(CalibrationResult, Option<Robot>)> {
    check_status(r.status.as_ref(), text, path)?;
    check_parameters(&r.parameters, text, path)?;
    check_frame(&r.tracker_frame, "tracker_frame", text, path)?;
    let nominal = r.robot.nominal_robot(path, Some(text))?;
    let e = &r.errors;
    let tables = [
        ("calibration", Some(&e.calibration)),
        ("validation", e.validation.as_ref()),
    ];
    for (set, t) in tables {
        let Some(t) = t else { continue };
        for (when, s) in [("before", &t.before), ("after", &t.after)] {
            for (name, v) in [
                ("mean_mm", s.mean_mm),
                ("std_mm", s.std_mm),
                ("max_mm", s.max_mm),
                ("rms_mm", s.rms_mm),
                ("p95_mm", s.p95_mm),
            ] {
                let field = || format!("errors.{set}.{when}.{name}");
                check_value(text, path, &field, v, &crate::ranges::ERROR)?;
            }
        }
    }
    Ok((r, nominal))
}

/// Checks `v` against `range`; the error names the file, the field (its name made only then)
/// and its line in `text`.
fn check_value(
    text: &str,
    path: &Path,
    field: &dyn Fn() -> String,
    v: f64,
    range: &crate::ranges::Range,
) -> Result<()> {
    range.check(v).map(|_| ()).map_err(|msg| {
        let field = field();
        let line = crate::io::json_keys::line_of_key(text, &field);
        Error::parse(path, line, Some(&field), msg)
    })
}

/// Checks the values of a `parameters` object (result or truth file) against the range of their
/// unit: nominal and calibrated values, and standard deviations.
pub(crate) fn check_parameters(
    params: &IndexMap<String, ParamEntry>,
    text: &str,
    path: &Path,
) -> Result<()> {
    use crate::ranges::Range;
    for (name, p) in params {
        let range = Range::for_unit(p.unit);
        let field = |k: &'static str| move || format!("parameters.{name}.{k}");
        check_value(text, path, &field("nominal"), p.nominal, range)?;
        check_value(text, path, &field("calibrated"), p.calibrated, range)?;
        if let Some(sd) = p.std {
            check_value(text, path, &field("std"), sd, Range::size_for_unit(p.unit))?;
        }
    }
    Ok(())
}

/// Checks a frame vector (`field` names it, e.g. `tracker_frame`): x, y, z as lengths, A, B, C
/// as angles.
pub(crate) fn check_frame(f: &FrameVec, field: &str, text: &str, path: &Path) -> Result<()> {
    use crate::ranges::{ANGLE, LENGTH};
    for (k, v, range) in [
        ("x", f.x, &LENGTH),
        ("y", f.y, &LENGTH),
        ("z", f.z, &LENGTH),
        ("a", f.a, &ANGLE),
        ("b", f.b, &ANGLE),
        ("c", f.c, &ANGLE),
    ] {
        check_value(text, path, &|| format!("{field}.{k}"), v, range)?;
    }
    Ok(())
}

/// Checks a result's `status`: present, and one robocal writes.
fn check_status(status: Option<&StatusValue>, text: &str, path: &Path) -> Result<()> {
    let known = KNOWN_STATUSES.join(", ");
    let msg = match status {
        Some(StatusValue::Known(_)) => return Ok(()),
        None => {
            return Err(Error::parse(
                path,
                None,
                Some("status"),
                format!(
                    "missing: every result robocal writes says whether it is a calibration \
                     (one of {known}); without it the file cannot be trusted as one"
                ),
            ))
        }
        Some(StatusValue::Other(serde_json::Value::String(s))) => {
            format!("`{s}` is not a status robocal writes ({known})")
        }
        Some(StatusValue::Other(other)) => {
            format!("{other} is not a status robocal writes ({known})")
        }
    };
    let line = crate::io::json_keys::line_of_key(text, "status");
    Err(Error::parse(path, line, Some("status"), msg))
}
