//! Row-by-row evaluation, for data sets too large to hold: [`Evaluator`] computes one row's
//! errors (eq. 3) under both references, [`PerPointWriter`] writes them as they come. A caller
//! keeps only the error norms (8 bytes per row and series) for the statistics.
//! [`super::evaluate`] and [`super::Evaluation::write_per_point`] are these two over a whole set.

use super::{has_desired_columns, Against, DesiredSource, Reference};
use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::io::{AtomicFile, Measurement, MeasurementSet};
use crate::model::Robot;
use nalgebra::Vector3;
use std::io::Write;
use std::path::Path;

fn types(t: &[crate::model::JointType]) -> String {
    t.iter().map(|x| x.as_str()).collect::<Vec<_>>().join(", ")
}

/// Computes the errors of measured rows of one file (see the module docs of
/// [`crate::evaluation`]).
pub struct Evaluator<'a> {
    nominal: &'a Robot,
    calibrated: &'a Robot,
    tracker_frame: &'a TrackerFrame,
    header: &'a MeasurementSet,
    reference: Reference,
    desired: Option<DesiredSource>,
    /// The frame of the nominal series (Table II's registration frame; by default the
    /// calibrated model's).
    nominal_frame: TrackerFrame,
    extras: crate::io::row_extras::ExtrasLayout,
}

impl<'a> Evaluator<'a> {
    /// An evaluator for the rows of a file described by `header` (path, joint count and extra
    /// columns; its rows are not used): checks the joint count and, for [`Against::Desired`],
    /// that the file has desired columns.
    pub fn new(
        nominal: &'a Robot,
        calibrated: &'a Robot,
        tracker_frame: &'a TrackerFrame,
        header: &'a MeasurementSet,
        against: Against,
    ) -> Result<Evaluator<'a>> {
        if nominal.dof() != header.dof()
            || calibrated.dof() != header.dof()
            || nominal.joint_types() != header.joints.types()
        {
            return Err(Error::invalid(
                header.path.display().to_string(),
                format!(
                    "read for {} joints ({}), the robot has {} ({})",
                    header.dof(),
                    types(header.joints.types()),
                    nominal.dof(),
                    types(nominal.joint_types())
                ),
            ));
        }
        let reference = match against {
            Against::Model => Reference::Model,
            Against::Desired => Reference::Desired,
            Against::Auto if has_desired_columns(header) => Reference::Desired,
            Against::Auto => Reference::Model,
        };
        let desired = match reference {
            Reference::Desired => Some(DesiredSource::find(header, nominal.dof())?),
            Reference::Model => None,
        };
        Ok(Evaluator {
            nominal,
            calibrated,
            tracker_frame,
            header,
            reference,
            desired,
            nominal_frame: *tracker_frame,
            extras: crate::io::row_extras::ExtrasLayout::of(header)?,
        })
    }

    /// Evaluates the nominal series in `frame` (a result's registration frame: the nominal
    /// model's Table II frame) instead of the calibrated model's tracker frame.
    pub fn with_nominal_frame(mut self, frame: TrackerFrame) -> Self {
        self.nominal_frame = frame;
        self
    }

    /// The reference chosen.
    pub fn reference(&self) -> Reference {
        self.reference
    }

    /// The two series' names and descriptions: `nominal` or `desired`, then `calibrated`.
    pub fn series(&self) -> [(&'static str, &'static str); 2] {
        match self.reference {
            Reference::Model => [
                ("nominal", "measured - nominal model at the measured joints"),
                (
                    "calibrated",
                    "measured - calibrated model at the measured joints",
                ),
            ],
            Reference::Desired => [
                ("desired", "measured - desired position (eq. 13)"),
                (
                    "calibrated",
                    "measured - calibrated model at the commanded joints",
                ),
            ],
        }
    }

    /// The errors `P_act - P_ref` (mm, base frame) of one row under both series.
    pub fn errors(&self, r: &Measurement) -> Result<[Vector3<f64>; 2]> {
        let Some(m) = r.p else {
            return Err(Error::parse(
                &self.header.path,
                Some(r.line),
                None,
                "no measured position (x,y,z)",
            ));
        };
        let extras = self.extras.read(self.header, r)?;
        let t = extras.target;
        // The row's temperature and approach directions, for models that read them.
        let c = extras.conditions.unwrap_or_default();
        let targets = self
            .nominal
            .target_count()
            .min(self.calibrated.target_count());
        if t >= targets {
            return Err(Error::parse(
                &self.header.path,
                Some(r.line),
                Some(crate::io::row_extras::TARGET_COLUMN),
                format!("target {} of a robot with {targets} tool vector(s)", t + 1),
            ));
        }
        let actual = self.tracker_frame.to_base(&m);
        let first = match &self.desired {
            None => self.nominal_frame.to_base(&m) - self.nominal.target_position_in(&r.q, t, &c),
            Some(source) => actual - source.position(self.header, r, self.nominal)?,
        };
        Ok([
            first,
            actual - self.calibrated.target_position_in(&r.q, t, &c),
        ])
    }
}

/// The per-point error file, written row by row and made visible only by
/// [`PerPointWriter::commit`]: `line`, `q1..qn` (degrees, or mm for a prismatic joint), the
/// input's extra columns, then for
/// each series `dx_<name>,dy_<name>,dz_<name>,norm_<name>` (mm, base frame).
pub struct PerPointWriter {
    joints: crate::model::JointSpace,
    path: std::path::PathBuf,
    w: csv::Writer<AtomicFile>,
    fields: Vec<String>,
}

impl PerPointWriter {
    /// Starts the file at `path` for the rows of the file `header` describes and the series
    /// named `names`. Fails if an extra column of the input has the name of an output column.
    pub fn create(path: &Path, header: &MeasurementSet, names: [&str; 2]) -> Result<Self> {
        Self::to_output(AtomicFile::create(path)?, header, names)
    }

    /// As [`PerPointWriter::create`], into an output already open (a file or a stream such as
    /// standard output, see [`AtomicFile::stream`]).
    pub fn to_output(out: AtomicFile, header: &MeasurementSet, names: [&str; 2]) -> Result<Self> {
        let path = out.target().to_owned();
        let path = path.as_path();
        let mut head = vec!["line".to_owned()];
        head.extend((0..header.dof()).map(crate::io::columns::joint_column));
        let own_start = head.len();
        for name in names {
            for c in ["dx", "dy", "dz", "norm"] {
                head.push(format!("{c}_{name}"));
            }
        }
        if let Some(c) = header.extra_columns.iter().find(|c| head.contains(c)) {
            return Err(Error::parse(
                &header.path,
                Some(1),
                Some(c),
                "the per-point output has a column of this name; rename or remove it",
            ));
        }
        let own: Vec<String> = head.drain(own_start..).collect();
        head.extend(header.extra_columns.iter().cloned());
        head.extend(own);
        let mut w = csv::Writer::from_writer(out);
        w.write_record(&head).map_err(|e| csv_io(path, e))?;
        Ok(PerPointWriter {
            joints: header.joints.clone(),
            path: path.to_owned(),
            w,
            fields: Vec::with_capacity(head.len()),
        })
    }

    /// Writes one row and its errors (in the series order of [`PerPointWriter::create`]).
    pub fn write(&mut self, r: &Measurement, errors: &[Vector3<f64>; 2]) -> Result<()> {
        let f = &mut self.fields;
        f.clear();
        f.push(r.line.to_string());
        f.extend(
            r.q.iter()
                .enumerate()
                .map(|(i, v)| format!("{:.9}", self.joints.to_display(i, *v))),
        );
        f.extend(r.extra.iter().cloned());
        for e in errors {
            f.extend([e.x, e.y, e.z, e.norm()].iter().map(|v| format!("{v:.6}")));
        }
        self.w.write_record(&*f).map_err(|e| csv_io(&self.path, e))
    }

    /// Completes the file: renames it into place.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        let mut out = self
            .w
            .into_inner()
            .map_err(|e| io_err(&path, std::io::Error::other(e.to_string())))?;
        out.flush().map_err(|e| io_err(&path, e))?;
        out.commit()
    }
}

fn io_err(path: &Path, e: std::io::Error) -> Error {
    Error::Io {
        path: path.to_owned(),
        source: e,
    }
}

fn csv_io(path: &Path, e: csv::Error) -> Error {
    io_err(path, std::io::Error::other(e))
}
