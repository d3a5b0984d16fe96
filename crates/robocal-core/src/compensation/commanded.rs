//! The commanded-joints CSV written by `robocal compensate`.
//!
//! Columns, in order:
//! - `q1..qn`: the commanded joint values theta_com (model joint values: degrees, or mm for a
//!   prismatic joint; eq. 14);
//! - `axis1..axisN`, when the robot has a controller map (`[controller]`; the KUKA presets have
//!   one): the same commanded joints as the controller's axis values, what to send to the
//!   controller. Without a map axis values are the joint values, and the columns are left out;
//! - `status` ([`IkStatus::as_str`]), `residual_mm`, `residual_deg` (full pose only: the angle of
//!   the orientation error), `iterations`, `at_limit` (joints that end at a limit, e.g. `q2 q5`,
//!   empty when none);
//! - `x_desired,y_desired,z_desired`: the desired tool position P_des (mm, base frame; eq. 13, or
//!   the given target), and for a full-pose compensation `a_desired,b_desired,c_desired`, its
//!   orientation as A, B, C (deg, frame vector convention);
//! - `q1_desired..qn_desired`: the desired joint values theta_des (degrees or mm; eq. 12), when the
//!   input was a joint file;
//! - the input's other columns, unchanged.
//!
//! As a joint file it reads with [`crate::io::read_measurements`] (`q1..qn` are the commanded
//! joints, checked against `axis1..axisN`; the rest are extra columns), so a simulator or a measurement of the commanded poses
//! carries the desired columns through, and `evaluate` compares the measured points with
//! `x_desired,y_desired,z_desired` (the paper's verification, Table V).

use super::{Compensation, IkStatus};
use crate::error::{Error, Result};
use crate::io::atomic::AtomicFile;
use crate::io::columns::{axis_column, joint_column};
use crate::model::JointSpace;
use std::io::Write;
use std::path::Path;

/// Column with the solve's [`IkStatus`].
pub const STATUS_COLUMN: &str = "status";
/// Column with the solve's residual (mm).
pub const RESIDUAL_COLUMN: &str = "residual_mm";
/// Column with the solve's orientation residual (deg; full pose only).
pub const RESIDUAL_DEG_COLUMN: &str = "residual_deg";
/// Column with the solve's iteration count.
pub const ITERATIONS_COLUMN: &str = "iterations";
/// Column listing the joints that end at a limit.
pub const AT_LIMIT_COLUMN: &str = "at_limit";
/// Columns of the desired tool position P_des (mm, base frame).
pub const DESIRED_POSITION_COLUMNS: [&str; 3] = ["x_desired", "y_desired", "z_desired"];
/// Columns of the desired tool orientation (A, B, C in deg, base frame; full pose only).
pub const DESIRED_ORIENTATION_COLUMNS: [&str; 3] = ["a_desired", "b_desired", "c_desired"];

/// The column of desired joint `i` (0-based): `q{i+1}_desired`.
pub fn desired_joint_column(i: usize) -> String {
    format!("q{}_desired", i + 1)
}

/// The header of a commanded file for a robot with the joints `joints`, with or without desired
/// joints, position-only or full pose, before the input's extra columns.
pub fn commanded_header(
    joints: &JointSpace,
    with_desired_joints: bool,
    full_pose: bool,
) -> Vec<String> {
    let dof = joints.dof();
    let mut h: Vec<String> = (0..dof).map(joint_column).collect();
    if joints.controller().is_some() {
        h.extend((0..dof).map(axis_column));
    }
    h.push(STATUS_COLUMN.into());
    h.push(RESIDUAL_COLUMN.into());
    if full_pose {
        h.push(RESIDUAL_DEG_COLUMN.into());
    }
    h.push(ITERATIONS_COLUMN.into());
    h.push(AT_LIMIT_COLUMN.into());
    h.extend(DESIRED_POSITION_COLUMNS.map(String::from));
    if full_pose {
        h.extend(DESIRED_ORIENTATION_COLUMNS.map(String::from));
    }
    if with_desired_joints {
        h.extend((0..dof).map(desired_joint_column));
    }
    h
}

/// Checks that no extra column of the input (`input` names the file in the message) has the name
/// of a column the commanded file adds (desired joints and orientation included, whichever the
/// mode).
pub fn check_extra_columns(
    input: &Path,
    joints: &JointSpace,
    extra_columns: &[String],
) -> Result<()> {
    let own = commanded_header(joints, true, true);
    for c in extra_columns {
        if own.contains(c) {
            return Err(Error::parse(
                input,
                Some(1),
                Some(c),
                "the output of compensate has a column of this name; rename or remove it \
                 (is this already a commanded file?)",
            ));
        }
    }
    Ok(())
}

/// Writes a commanded file atomically (nothing is written if anything fails). `desired_joints`
/// (internal units) are the eq. 12 vectors in joint mode; `extra_rows[k]` are row k's values of
/// `extra_columns`.
pub fn write_commanded(
    path: &Path,
    joints: &JointSpace,
    rows: &[Compensation],
    desired_joints: Option<&[Vec<f64>]>,
    extra_columns: &[String],
    extra_rows: &[&[String]],
) -> Result<()> {
    if extra_rows.len() != rows.len() || desired_joints.is_some_and(|d| d.len() != rows.len()) {
        return Err(Error::invalid(
            "commanded file",
            "row counts of results, desired joints and extra columns differ",
        ));
    }
    let mut w = CommandedWriter::create(
        path,
        joints,
        desired_joints.is_some(),
        is_full_pose(rows),
        extra_columns,
    )?;
    for (k, c) in rows.iter().enumerate() {
        w.write(c, desired_joints.map(|d| d[k].as_slice()), extra_rows[k])?;
    }
    w.commit()
}

/// Whether rows are full-pose compensations (the first has a desired orientation).
fn is_full_pose(rows: &[Compensation]) -> bool {
    rows.first()
        .is_some_and(|c| c.desired_orientation.is_some())
}

/// The text [`write_commanded`] writes, for callers that write several files together
/// ([`crate::io::write_all_atomic`]) or read it back as a joint file
/// ([`crate::io::parse_measurements`]).
pub fn commanded_csv(
    joints: &JointSpace,
    rows: &[Compensation],
    desired_joints: Option<&[Vec<f64>]>,
    extra_columns: &[String],
    extra_rows: &[&[String]],
) -> Result<Vec<u8>> {
    if extra_rows.len() != rows.len() || desired_joints.is_some_and(|d| d.len() != rows.len()) {
        return Err(Error::invalid(
            "commanded file",
            "row counts of results, desired joints and extra columns differ",
        ));
    }
    let mut w = CommandedWriter::in_memory(
        Path::new("commanded file"),
        joints,
        desired_joints.is_some(),
        is_full_pose(rows),
        extra_columns,
    )?;
    for (k, c) in rows.iter().enumerate() {
        w.write(c, desired_joints.map(|d| d[k].as_slice()), extra_rows[k])?;
    }
    w.into_bytes()
}

/// A commanded file written row by row (for inputs too large to hold). Into a file
/// ([`CommandedWriter::create`]) it becomes visible only by [`CommandedWriter::commit`]; dropped
/// without it, nothing is written. Into memory ([`CommandedWriter::in_memory`]) it gives the text
/// for callers that write several files together.
pub struct CommandedWriter<W: Write = AtomicFile> {
    path: std::path::PathBuf,
    w: csv::Writer<W>,
    joints: JointSpace,
    with_desired_joints: bool,
    full_pose: bool,
    extra: usize,
    fields: Vec<String>,
}

impl CommandedWriter<AtomicFile> {
    /// Starts the file: the header for a robot with the joints `joints`, with or without the
    /// desired joints, position-only or `full_pose`, and the input's `extra_columns`.
    pub fn create(
        path: &Path,
        joints: &JointSpace,
        with_desired_joints: bool,
        full_pose: bool,
        extra_columns: &[String],
    ) -> Result<Self> {
        Self::to_output(
            AtomicFile::create(path)?,
            joints,
            with_desired_joints,
            full_pose,
            extra_columns,
        )
    }

    /// As [`CommandedWriter::create`], into an output already open (a file or a stream such as
    /// standard output, see [`AtomicFile::stream`]).
    pub fn to_output(
        out: AtomicFile,
        joints: &JointSpace,
        with_desired_joints: bool,
        full_pose: bool,
        extra_columns: &[String],
    ) -> Result<Self> {
        let path = out.target().to_owned();
        Self::start(
            out,
            &path,
            joints,
            with_desired_joints,
            full_pose,
            extra_columns,
        )
    }

    /// Completes the file: renames it into place.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        let io = |e: std::io::Error| Error::Io {
            path: path.clone(),
            source: e,
        };
        let mut out = self
            .w
            .into_inner()
            .map_err(|e| io(std::io::Error::other(e.to_string())))?;
        out.flush().map_err(io)?;
        out.commit()
    }
}

impl CommandedWriter<Vec<u8>> {
    /// Starts the text in memory (`path` only names it in messages).
    pub fn in_memory(
        path: &Path,
        joints: &JointSpace,
        with_desired_joints: bool,
        full_pose: bool,
        extra_columns: &[String],
    ) -> Result<Self> {
        Self::start(
            Vec::new(),
            path,
            joints,
            with_desired_joints,
            full_pose,
            extra_columns,
        )
    }

    /// The complete text.
    pub fn into_bytes(self) -> Result<Vec<u8>> {
        let path = self.path;
        self.w.into_inner().map_err(|e| Error::Io {
            path,
            source: std::io::Error::other(e.to_string()),
        })
    }
}

impl<W: Write> CommandedWriter<W> {
    fn start(
        sink: W,
        path: &Path,
        joints: &JointSpace,
        with_desired_joints: bool,
        full_pose: bool,
        extra_columns: &[String],
    ) -> Result<Self> {
        let mut header = commanded_header(joints, with_desired_joints, full_pose);
        header.extend(extra_columns.iter().cloned());
        let mut w = csv::Writer::from_writer(sink);
        w.write_record(&header).map_err(|e| csv_io(path, e))?;
        Ok(CommandedWriter {
            path: path.to_owned(),
            w,
            joints: joints.clone(),
            with_desired_joints,
            full_pose,
            extra: extra_columns.len(),
            fields: Vec::with_capacity(header.len()),
        })
    }

    /// Writes one row: the compensation, the desired joints (internal units; exactly when the
    /// file was created with them) and the input's extra values.
    pub fn write(
        &mut self,
        c: &Compensation,
        desired_joints: Option<&[f64]>,
        extra: &[String],
    ) -> Result<()> {
        let dof = self.joints.dof();
        let lengths_ok = c.commanded.len() == dof
            && c.desired_orientation.is_some() == self.full_pose
            && extra.len() == self.extra
            && match desired_joints {
                Some(d) => self.with_desired_joints && d.len() == dof,
                None => !self.with_desired_joints,
            };
        if !lengths_ok {
            return Err(Error::invalid(
                "commanded file",
                "a row does not match the header (joints, desired joints, desired orientation or \
                 extra columns)",
            ));
        }
        let f = &mut self.fields;
        let joints = &self.joints;
        let display = |q: &[f64]| -> Vec<String> {
            q.iter()
                .enumerate()
                .map(|(i, v)| format!("{:.10}", joints.to_display(i, *v)))
                .collect()
        };
        f.clear();
        f.extend(display(&c.commanded));
        if joints.controller().is_some() {
            f.extend(
                joints
                    .axes_from_joints(&c.commanded)
                    .iter()
                    .map(|v| format!("{v:.10}")),
            );
        }
        f.push(c.report.status.as_str().to_owned());
        f.push(format!("{:.3e}", c.report.residual_mm));
        if self.full_pose {
            f.push(format!("{:.3e}", c.report.residual_deg));
        }
        f.push(c.report.iterations.to_string());
        f.push(
            c.report
                .limited_joints()
                .map(|i| format!("q{}", i + 1))
                .collect::<Vec<_>>()
                .join(" "),
        );
        f.extend(c.desired_position.iter().map(|v| format!("{v:.9}")));
        if let Some(r) = &c.desired_orientation {
            let v = crate::frame::frame_vector(&crate::frame::Frame::from_parts(
                nalgebra::Translation3::identity(),
                *r,
            ));
            f.extend(v[3..].iter().map(|a| format!("{:.9}", a.to_degrees())));
        }
        if let Some(d) = desired_joints {
            f.extend(display(d));
        }
        f.extend(extra.iter().cloned());
        self.w.write_record(&*f).map_err(|e| csv_io(&self.path, e))
    }
}

fn csv_io(path: &Path, e: csv::Error) -> Error {
    Error::Io {
        path: path.to_owned(),
        source: std::io::Error::other(e),
    }
}

/// Counts of each status in `rows`, in [`IkStatus::ALL`] order.
pub fn status_counts(rows: &[Compensation]) -> [(IkStatus, usize); IkStatus::ALL.len()] {
    IkStatus::ALL.map(|s| (s, rows.iter().filter(|c| c.report.status == s).count()))
}
