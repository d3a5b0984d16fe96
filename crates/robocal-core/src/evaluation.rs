//! Validation and verification (paper, sections IV and V.B): the displacement errors (eq. 3) of a
//! measured data set, `E_i = P_act - P_ref`, with `P_act = pose(tracker_frame) * M_i` the
//! measured point moved into the base frame (the result's tracker frame, eq. 9-10), and their
//! statistics (Tables II, IV, V).
//!
//! Two references, [`Reference`]:
//! - [`Reference::Model`] (validation, Table IV): `P_ref` is the tool position of the model at the
//!   measured joints, for the nominal and for the calibrated model.
//! - [`Reference::Desired`] (verification, Table V): the data are measurements of *commanded*
//!   joints (the output of compensation); `P_ref` is the desired position P_des (eq. 13), read from
//!   the `x_desired,y_desired,z_desired` columns the commanded file carries, or computed as the
//!   nominal tool position of the `q1_desired..qn_desired` columns. The second series is the
//!   calibrated model at the commanded joints: the error the calibration predicts for these poses.
//!
//! Both series use the same tracker frame, the result's; so the nominal statistics here can differ
//! a little from the result's `before` figures, for which the frame was fitted to the nominal model.

use crate::compensation::commanded::{desired_joint_column, DESIRED_POSITION_COLUMNS};
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::io::result::CalibrationResult;
use crate::io::{AtomicFile, Measurement, MeasurementSet};
use crate::model::Robot;
use crate::stats::ErrorStats;
use nalgebra::{Point3, Vector3};
use std::io::Write;
use std::path::Path;

/// What the measured points are compared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// The models' tool positions at the measured joints (validation).
    Model,
    /// The desired positions of commanded poses (verification).
    Desired,
}

/// The reference asked for: [`Against::Auto`] picks [`Reference::Desired`] when the data carry
/// desired columns, else [`Reference::Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Against {
    /// Desired when the data have `x_desired,y_desired,z_desired` or `q1_desired..qn_desired`.
    Auto,
    /// Always the models.
    Model,
    /// Always the desired positions (an error if the data lack the columns).
    Desired,
}

/// One series of errors: a reference for every point and the errors against it.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Short name used in files: `nominal`, `calibrated` or `desired`.
    pub name: &'static str,
    /// What the reference is, in words.
    pub description: &'static str,
    /// `P_act - P_ref` per point (mm, base frame).
    pub errors: Vec<Vector3<f64>>,
    /// Statistics of the error norms.
    pub stats: ErrorStats,
}

impl Series {
    fn new(name: &'static str, description: &'static str, errors: Vec<Vector3<f64>>) -> Series {
        let norms: Vec<f64> = errors.iter().map(|e| e.norm()).collect();
        Series {
            name,
            description,
            stats: ErrorStats::from_norms(&norms),
            errors,
        }
    }
}

/// The errors of a data set under two references.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// The reference used.
    pub reference: Reference,
    /// The data rows' 1-based lines.
    pub lines: Vec<usize>,
    /// Model: `[nominal, calibrated]`; desired: `[desired, calibrated]`.
    pub series: [Series; 2],
}

/// Evaluates a measured data set (positions required) under the `nominal` and `calibrated`
/// models, with the measured points moved into the base frame by `tracker_frame`.
pub fn evaluate(
    nominal: &Robot,
    calibrated: &Robot,
    tracker_frame: &Frame,
    data: &MeasurementSet,
    against: Against,
) -> Result<Evaluation> {
    if nominal.dof() != data.dof || calibrated.dof() != data.dof {
        return Err(Error::invalid(
            data.path.display().to_string(),
            format!(
                "read for {} joints, the robot has {}",
                data.dof,
                nominal.dof()
            ),
        ));
    }
    let reference = match against {
        Against::Model => Reference::Model,
        Against::Desired => Reference::Desired,
        Against::Auto => {
            if has_desired_columns(data) {
                Reference::Desired
            } else {
                Reference::Model
            }
        }
    };
    let mut actual = Vec::with_capacity(data.rows.len());
    for r in &data.rows {
        let Some(m) = r.p else {
            return Err(Error::parse(
                &data.path,
                Some(r.line),
                None,
                "no measured position (x,y,z)",
            ));
        };
        actual.push((tracker_frame * Point3::from(m)).coords);
    }
    let errors_of = |reference: &dyn Fn(&Measurement) -> Result<Vector3<f64>>| {
        data.rows
            .iter()
            .zip(&actual)
            .map(|(r, a)| Ok(a - reference(r)?))
            .collect::<Result<Vec<_>>>()
    };
    let cal = Series::new(
        "calibrated",
        match reference {
            Reference::Model => "measured - calibrated model at the measured joints",
            Reference::Desired => "measured - calibrated model at the commanded joints",
        },
        errors_of(&|r| Ok(calibrated.tool_position(&r.q)))?,
    );
    let first = match reference {
        Reference::Model => Series::new(
            "nominal",
            "measured - nominal model at the measured joints",
            errors_of(&|r| Ok(nominal.tool_position(&r.q)))?,
        ),
        Reference::Desired => {
            let source = DesiredSource::find(data, nominal.dof())?;
            Series::new(
                "desired",
                "measured - desired position (eq. 13)",
                errors_of(&|r| source.position(data, r, nominal))?,
            )
        }
    };
    Ok(Evaluation {
        reference,
        lines: data.rows.iter().map(|r| r.line).collect(),
        series: [first, cal],
    })
}

/// Whether a data set carries desired positions or desired joints.
pub fn has_desired_columns(data: &MeasurementSet) -> bool {
    DesiredSource::find(data, data.dof).is_ok()
}

/// Where the desired positions come from: columns of the extra columns.
enum DesiredSource {
    Position([usize; 3]),
    Joints(Vec<usize>),
}

impl DesiredSource {
    fn find(data: &MeasurementSet, dof: usize) -> Result<DesiredSource> {
        let col = |name: &str| data.extra_columns.iter().position(|c| c == name);
        let pos: Vec<Option<usize>> = DESIRED_POSITION_COLUMNS.iter().map(|c| col(c)).collect();
        if pos.iter().all(Option::is_some) {
            return Ok(DesiredSource::Position([
                pos[0].expect("checked"),
                pos[1].expect("checked"),
                pos[2].expect("checked"),
            ]));
        }
        let joints: Vec<Option<usize>> = (0..dof).map(|i| col(&desired_joint_column(i))).collect();
        if joints.iter().all(Option::is_some) {
            return Ok(DesiredSource::Joints(
                joints.into_iter().map(|j| j.expect("checked")).collect(),
            ));
        }
        let missing = if pos.iter().any(Option::is_some) {
            DESIRED_POSITION_COLUMNS[pos.iter().position(Option::is_none).expect("some")].to_owned()
        } else if joints.iter().any(Option::is_some) {
            desired_joint_column(joints.iter().position(Option::is_none).expect("some"))
        } else {
            DESIRED_POSITION_COLUMNS[0].to_owned()
        };
        Err(Error::parse(
            &data.path,
            Some(1),
            Some(&missing),
            format!(
                "missing column: comparing with desired positions needs {} (mm, base frame) or \
                 q1_desired..q{dof}_desired (degrees), as `robocal compensate` writes them",
                DESIRED_POSITION_COLUMNS.join(",")
            ),
        ))
    }

    fn position(
        &self,
        data: &MeasurementSet,
        r: &Measurement,
        nominal: &Robot,
    ) -> Result<Vector3<f64>> {
        let num = |k: usize| -> Result<f64> {
            let s = r.extra[k].trim();
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(Error::parse(
                    &data.path,
                    Some(r.line),
                    Some(&data.extra_columns[k]),
                    format!("`{s}` is not a finite number"),
                )),
            }
        };
        match self {
            DesiredSource::Position(c) => Ok(Vector3::new(num(c[0])?, num(c[1])?, num(c[2])?)),
            DesiredSource::Joints(c) => {
                let q = c
                    .iter()
                    .map(|&k| num(k).map(f64::to_radians))
                    .collect::<Result<Vec<_>>>()?;
                Ok(nominal.tool_position(&q))
            }
        }
    }
}

impl Evaluation {
    /// Writes the per-point errors atomically: `line`, `q1..qn` (degrees), the input's extra
    /// columns, then for each series `dx_<name>,dy_<name>,dz_<name>,norm_<name>` (mm, base frame).
    pub fn write_per_point(&self, path: &Path, data: &MeasurementSet) -> Result<()> {
        let mut header = vec!["line".to_owned()];
        header.extend((1..=data.dof).map(|i| format!("q{i}")));
        let own_start = header.len();
        for s in &self.series {
            for c in ["dx", "dy", "dz", "norm"] {
                header.push(format!("{c}_{}", s.name));
            }
        }
        if let Some(c) = data.extra_columns.iter().find(|c| header.contains(c)) {
            return Err(Error::parse(
                &data.path,
                Some(1),
                Some(c),
                "the per-point output has a column of this name; rename or remove it",
            ));
        }
        let own: Vec<String> = header.drain(own_start..).collect();
        header.extend(data.extra_columns.iter().cloned());
        header.extend(own);
        let io = |e: std::io::Error| Error::Io {
            path: path.to_owned(),
            source: e,
        };
        let mut out = AtomicFile::create(path)?;
        {
            let mut w = csv::Writer::from_writer(&mut out);
            w.write_record(&header)
                .map_err(|e| io(std::io::Error::other(e)))?;
            let mut f: Vec<String> = Vec::with_capacity(header.len());
            for (k, r) in data.rows.iter().enumerate() {
                f.clear();
                f.push(r.line.to_string());
                f.extend(r.q.iter().map(|v| format!("{:.9}", v.to_degrees())));
                f.extend(r.extra.iter().cloned());
                for s in &self.series {
                    let e = s.errors[k];
                    f.extend([e.x, e.y, e.z, e.norm()].iter().map(|v| format!("{v:.6}")));
                }
                w.write_record(&f)
                    .map_err(|e| io(std::io::Error::other(e)))?;
            }
            w.flush().map_err(io)?;
        }
        out.flush().map_err(io)?;
        out.commit()
    }
}

/// Checks that a result was made for `nominal`: every parameter the robot has must carry the same
/// nominal value in the result (to 1e-6 mm or degrees, relative 1e-9). Catches a result of another
/// robot with the same joint count and convention, which [`CalibrationResult::calibrated_robot`]
/// cannot tell apart. `path` names the result file in errors.
pub fn check_result_nominal(
    result: &CalibrationResult,
    nominal: &Robot,
    path: &Path,
) -> Result<()> {
    for p in nominal.params() {
        let name = p.name();
        let Some(e) = result.parameters.get(&name) else {
            continue;
        };
        let mine = nominal.get_display(p);
        if (e.nominal - mine).abs() > 1e-6 + 1e-9 * mine.abs() {
            return Err(Error::parse(
                path,
                None,
                Some(&format!("parameters.{name}.nominal")),
                format!(
                    "the result was made for a robot with nominal {name} = {} {}, but robot `{}` \
                     has {mine} {}: wrong --robot or wrong result file (result robot: `{}`)",
                    e.nominal,
                    e.unit.as_str(),
                    nominal.name(),
                    p.unit().as_str(),
                    result.robot.name
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
