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
use crate::frame::TrackerFrame;
use crate::io::result::CalibrationResult;
use crate::io::{Measurement, MeasurementSet};
use crate::model::Robot;
use crate::stats::ErrorStats;
use nalgebra::Vector3;
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
    tracker_frame: &TrackerFrame,
    data: &MeasurementSet,
    against: Against,
) -> Result<Evaluation> {
    evaluate_framed(
        nominal,
        calibrated,
        [tracker_frame, tracker_frame],
        data,
        against,
    )
}

/// [`evaluate`] with the nominal series in a frame of its own: `frames` are the nominal model's
/// (a result's registration frame, that of Table II) and the calibrated model's (the result's
/// `tracker_frame`).
pub fn evaluate_framed(
    nominal: &Robot,
    calibrated: &Robot,
    frames: [&TrackerFrame; 2],
    data: &MeasurementSet,
    against: Against,
) -> Result<Evaluation> {
    let tracker_frame = frames[1];
    if nominal.dof() != data.dof() || calibrated.dof() != data.dof() {
        return Err(Error::invalid(
            data.path.display().to_string(),
            format!(
                "read for {} joints, the robot has {}",
                data.dof(),
                nominal.dof()
            ),
        ));
    }
    let ev = Evaluator::new(nominal, calibrated, tracker_frame, data, against)?
        .with_nominal_frame(*frames[0]);
    let mut errors = [
        Vec::with_capacity(data.rows.len()),
        Vec::with_capacity(data.rows.len()),
    ];
    for r in &data.rows {
        let [a, b] = ev.errors(r)?;
        errors[0].push(a);
        errors[1].push(b);
    }
    let [e0, e1] = errors;
    let [(n0, d0), (n1, d1)] = ev.series();
    let (first, cal) = (Series::new(n0, d0, e0), Series::new(n1, d1, e1));
    let reference = ev.reference();
    Ok(Evaluation {
        reference,
        lines: data.rows.iter().map(|r| r.line).collect(),
        series: [first, cal],
    })
}

/// Whether a data set carries desired positions or desired joints.
pub(crate) fn has_desired_columns(data: &MeasurementSet) -> bool {
    DesiredSource::find(data, data.dof()).is_ok()
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
                 q1_desired..q{dof}_desired (degrees, mm for a prismatic joint), as `robocal \
                 compensate` writes them",
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
        let num = |k: usize, range: &crate::ranges::Range| -> Result<f64> {
            let s = r.extra[k].trim();
            let err = |msg: String| {
                Error::parse(&data.path, Some(r.line), Some(&data.extra_columns[k]), msg)
            };
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => range.check(v).map_err(err),
                _ => Err(err(format!("`{s}` is not a finite number"))),
            }
        };
        let pos = |k| num(k, &crate::ranges::LENGTH);
        match self {
            DesiredSource::Position(c) => Ok(Vector3::new(pos(c[0])?, pos(c[1])?, pos(c[2])?)),
            DesiredSource::Joints(c) => {
                let s = nominal.joint_space();
                let q = c
                    .iter()
                    .enumerate()
                    .map(|(i, &k)| {
                        let range = match nominal.joint_type(i) {
                            crate::model::JointType::Prismatic => &crate::ranges::LENGTH,
                            crate::model::JointType::Revolute => &crate::ranges::JOINT,
                        };
                        num(k, range).map(|v| s.to_internal(i, v))
                    })
                    .collect::<Result<Vec<_>>>()?;
                Ok(nominal.tool_position(&q))
            }
        }
    }
}

impl Evaluation {
    /// Writes the per-point errors atomically: `line`, `q1..qn` (degrees or mm), the input's extra
    /// columns, then for each series `dx_<name>,dy_<name>,dz_<name>,norm_<name>` (mm, base frame).
    pub fn write_per_point(&self, path: &Path, data: &MeasurementSet) -> Result<()> {
        let mut w = PerPointWriter::create(path, data, [self.series[0].name, self.series[1].name])?;
        for (k, r) in data.rows.iter().enumerate() {
            w.write(r, &[self.series[0].errors[k], self.series[1].errors[k]])?;
        }
        w.commit()
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
                     has {mine} {}: wrong nominal robot or wrong result file (result robot: `{}`)",
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

pub mod gap;
mod station;
mod stream;
pub use station::{check_data_matches, check_station, observations_of, station_frames};
pub use stream::{Evaluator, PerPointWriter};

#[cfg(test)]
mod tests;
