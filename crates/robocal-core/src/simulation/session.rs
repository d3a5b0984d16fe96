//! A whole simulated measurement session, as `robocal simulate` runs it: the paper's plane,
//! calibration and validation points measured in one virtual cell, or given joint values
//! measured (the verification phase), with the truth file that goes beside the data.

use super::cell::{Readings, VirtualCell};
use super::conditions::write_conditions;
use super::config::SimulationConfig;
use super::truth::{GeometricErrors, TruthSpec};
use super::truth_file::{OutlierRecord, SetInfo, TruthFile};
use crate::error::{Error, Result};
use crate::io::measurements::{Measurement, MeasurementSet};
use crate::io::result::RobotInfo;
use crate::io::SetLabel;
use crate::model::Robot;
use crate::progress::{Observer, Stage};
use crate::stats::ErrorStats;
use indexmap::IndexMap;
use std::path::{Path, PathBuf};

/// The `set` of the three plane points.
pub const SET_PLANE: &str = SetLabel::Plane.as_str();
/// The `set` of the calibration points.
pub const SET_CALIBRATION: &str = SetLabel::Calibration.as_str();
/// The `set` of the validation points.
pub const SET_VALIDATION: &str = SetLabel::Validation.as_str();

/// Poses drawn per progress step.
const CHUNK: usize = 1000;

/// A simulated session: the cell, the measurement rows and what was injected.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// The cell (truth robot, tracker, models) after the session.
    pub cell: VirtualCell,
    /// The rows in file order. Random sessions have the extra columns `id` (`P1..`, `C1..`,
    /// `V1..`) and `set` (`plane`, `calibration`, `validation`); joint sessions keep the joint
    /// file's extra columns.
    pub measurements: MeasurementSet,
    /// The exact readings (no noise, no outliers; mm, tracker frame), one per row.
    pub exact: Vec<nalgebra::Vector3<f64>>,
    /// The outliers: row index (0-based, in `measurements`) and displacement (mm).
    pub outliers: Vec<(usize, [f64; 3])>,
    /// How far gravity moved each tool point (mm), one per row, when gravity is on.
    pub deflection_mm: Option<Vec<f64>>,
    /// Height of the plane points' plane (mm, base frame).
    pub plane_z_mm: Option<f64>,
    /// Things worth telling the user (joint values outside the limits, ...).
    pub warnings: Vec<String>,
    config: SimulationConfig,
    truth_label: String,
    geometric_errors: Option<GeometricErrors>,
    joints_file: Option<String>,
}

fn rows_of(
    qs: Vec<Vec<f64>>,
    points: &[nalgebra::Vector3<f64>],
    prefix: &str,
    set: &str,
    first_line: usize,
) -> Vec<Measurement> {
    qs.into_iter()
        .zip(points)
        .enumerate()
        .map(|(i, (q, p))| Measurement {
            line: first_line + i,
            q,
            p: Some(*p),
            extra: vec![format!("{prefix}{}", i + 1), set.to_owned()],
        })
        .collect()
}

/// Draws `n` poses from `draw` in chunks, reporting progress.
fn chunked(
    n: usize,
    done: &mut usize,
    total: usize,
    observer: &dyn Observer,
    mut draw: impl FnMut(usize) -> Result<Vec<Vec<f64>>>,
) -> Result<Vec<Vec<f64>>> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let k = CHUNK.min(n - out.len());
        out.extend(draw(k)?);
        *done += k;
        observer.progress(Stage::Measurement, *done, total);
    }
    Ok(out)
}

/// Simulates a measurement session with random poses: the three plane points (if
/// `config.plane_points`), `config.poses` calibration points and `config.validation_poses`
/// validation points, measured in that order in the cell of `nominal`, `truth` and `config`.
/// `observer` hears [`Stage::Measurement`] as poses are drawn and measured (readings of all).
pub fn simulate(
    nominal: &Robot,
    truth: &TruthSpec,
    config: &SimulationConfig,
    observer: &dyn Observer,
) -> Result<Simulation> {
    if config.poses == 0 {
        return Err(Error::invalid("poses", "must be at least 1"));
    }
    let mut cell = VirtualCell::from_config(nominal, truth, config)?;
    let n_plane = if config.plane_points { 3 } else { 0 };
    let total = 2 * (n_plane + config.poses + config.validation_poses);
    let mut done = 0;
    let (plane, plane_z) = if config.plane_points {
        let (q, z) = cell.plane_poses()?;
        done += 3;
        observer.progress(Stage::Measurement, done, total);
        (q, Some(z))
    } else {
        (Vec::new(), None)
    };
    let cal = chunked(config.poses, &mut done, total, observer, |k| {
        cell.random_poses(k)
    })?;
    let val = if config.validation_poses > 0 {
        chunked(config.validation_poses, &mut done, total, observer, |k| {
            cell.validation_poses(k)
        })?
    } else {
        Vec::new()
    };
    let mut all: Vec<Vec<f64>> = Vec::with_capacity(total / 2);
    all.extend(plane.iter().cloned());
    all.extend(cal.iter().cloned());
    all.extend(val.iter().cloned());
    let readings = measure(&mut cell, &all, None, config, &mut done, total, observer)?;
    let pts = &readings.points;
    let (a, b) = (plane.len(), plane.len() + cal.len());
    let mut rows = Vec::with_capacity(all.len());
    rows.extend(rows_of(plane, &pts[..a], "P", SET_PLANE, 2));
    rows.extend(rows_of(cal, &pts[a..b], "C", SET_CALIBRATION, 2 + a));
    rows.extend(rows_of(val, &pts[b..], "V", SET_VALIDATION, 2 + b));
    let mut measurements = MeasurementSet {
        path: PathBuf::from("<simulated>"),
        joints: nominal.joint_space().clone(),
        extra_columns: vec!["id".into(), "set".into()],
        rows,
        warnings: Vec::new(),
    };
    write_conditions(&mut measurements, &readings);
    Ok(finish(
        cell,
        measurements,
        readings,
        plane_z,
        Vec::new(),
        config,
        truth,
        None,
    ))
}

/// Measures the joint values of a joint (or measurement) file in the cell of `nominal`, `truth`
/// and `config` (the poses settings of `config` are not used): how the verification phase
/// measures commanded joints. The rows keep the file's order and extra columns; any `x,y,z` in
/// the file are replaced by the new readings. Joint values outside the limits are measured and
/// reported in [`Simulation::warnings`]. With backlash, a file with `dir1..dirN` (every cell
/// given) is approached from those sides; otherwise the directions follow the row order.
pub fn simulate_joints(
    nominal: &Robot,
    truth: &TruthSpec,
    config: &SimulationConfig,
    joints: &MeasurementSet,
    observer: &dyn Observer,
) -> Result<Simulation> {
    if joints.dof() != nominal.dof() {
        return Err(Error::JointCount {
            context: joints.path.display().to_string(),
            expected: nominal.dof(),
            got: joints.dof(),
        });
    }
    if joints.rows.is_empty() {
        return Err(Error::parse(&joints.path, None, None, "no data rows"));
    }
    let mut cell = VirtualCell::from_config(nominal, truth, config)?;
    let mut warnings = joints.warnings.clone();
    for r in &joints.rows {
        let out = nominal.joints_outside_limits(&r.q);
        if !out.is_empty() {
            warnings.push(format!(
                "{}:{}: {} outside the joint limits (measured anyway)",
                joints.path.display(),
                r.line,
                out.iter()
                    .map(|i| format!("q{}", i + 1))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    let qs: Vec<Vec<f64>> = joints.rows.iter().map(|r| r.q.clone()).collect();
    let total = 2 * qs.len();
    let given = super::conditions::given_directions(joints)?;
    let mut done = qs.len();
    let readings = measure(
        &mut cell,
        &qs,
        given.as_deref(),
        config,
        &mut done,
        total,
        observer,
    )?;
    let rows = joints
        .rows
        .iter()
        .zip(&readings.points)
        .enumerate()
        .map(|(i, (r, p))| Measurement {
            line: i + 2,
            q: r.q.clone(),
            p: Some(*p),
            extra: r.extra.clone(),
        })
        .collect();
    let mut measurements = MeasurementSet {
        path: PathBuf::from("<simulated>"),
        joints: nominal.joint_space().clone(),
        extra_columns: joints.extra_columns.clone(),
        rows,
        warnings: Vec::new(),
    };
    write_conditions(&mut measurements, &readings);
    Ok(finish(
        cell,
        measurements,
        readings,
        None,
        warnings,
        config,
        truth,
        Some(joints.path.display().to_string()),
    ))
}

/// Measures all poses in one batch (outliers are drawn per batch) and reports progress. With a
/// repeatability model the robot stops at the commanded joints plus its random error per move
/// (the rows keep the commanded joints).
/// Measures the commanded joints `qs` (approached from the sides `given`, else from where the
/// previous pose left the joints): the robot attains them within its repeatability, if the
/// settings give one.
fn measure(
    cell: &mut VirtualCell,
    qs: &[Vec<f64>],
    given: Option<&[Vec<i8>]>,
    config: &SimulationConfig,
    done: &mut usize,
    total: usize,
    observer: &dyn Observer,
) -> Result<Readings> {
    let attained = config
        .repeatability
        .as_ref()
        .map(|m| m.attained(cell.truth(), qs, config.seed));
    // The approach directions are the commanded path's: a joint the program does not move
    // stays on its side of the gear play, whatever scatter the repeatability adds.
    let commanded = match (given, &attained, &config.backlash) {
        (None, Some(_), Some(_)) => Some(super::backlash::approach_directions(
            &super::backlash::home(cell.truth()),
            qs,
        )),
        _ => None,
    };
    let given = given.or(commanded.as_deref());
    let r = cell.measure_approached(attained.as_deref().unwrap_or(qs), given)?;
    *done += qs.len();
    observer.progress(Stage::Measurement, *done, total);
    Ok(r)
}

#[allow(clippy::too_many_arguments)]
fn finish(
    cell: VirtualCell,
    measurements: MeasurementSet,
    readings: Readings,
    plane_z_mm: Option<f64>,
    warnings: Vec<String>,
    config: &SimulationConfig,
    truth: &TruthSpec,
    joints_file: Option<String>,
) -> Simulation {
    let deflection_mm = cell.gravity().map(|_| readings.deflection_mm.clone());
    Simulation {
        outliers: readings
            .outliers
            .iter()
            .map(|o| (o.index, o.displacement_mm))
            .collect(),
        exact: readings.exact,
        cell,
        measurements,
        deflection_mm,
        plane_z_mm,
        warnings,
        config: config.clone(),
        truth_label: truth.label(),
        geometric_errors: match truth {
            TruthSpec::Random(e) => Some(*e),
            TruthSpec::Robot(_) => None,
        },
        joints_file,
    }
}

impl Simulation {
    /// The settings the session ran with.
    pub fn config(&self) -> &SimulationConfig {
        &self.config
    }

    /// The rows whose `set` column is (or, with `keep = false`, is not) `set`, renumbered as the
    /// lines of a file of their own.
    pub fn select(&self, set: &str, keep: bool) -> MeasurementSet {
        let col = self
            .measurements
            .extra_columns
            .iter()
            .position(|c| c == "set");
        let rows = self
            .measurements
            .rows
            .iter()
            .filter(|r| col.map(|k| r.extra[k] == set).unwrap_or(false) == keep)
            .enumerate()
            .map(|(i, r)| Measurement {
                line: i + 2,
                ..r.clone()
            })
            .collect();
        MeasurementSet {
            rows,
            ..self.measurements.clone()
        }
    }

    /// The truth file for this session. `files` names the file every row was written to, in
    /// row order (e.g. all `cell.csv`, or the validation rows `cell-validation.csv`); line
    /// numbers of outliers count within each file.
    pub fn truth_file(&self, files: &[&Path]) -> TruthFile {
        let nominal = self.cell.nominal();
        let truth = self.cell.truth();
        let m = &self.measurements;
        let name_of = |p: &Path| {
            p.file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        let col = |c: &str| m.extra_columns.iter().position(|x| x == c);
        let (id_col, set_col) = (col("id"), col("set"));
        // Line of each row within its own file.
        let mut next_line: IndexMap<String, usize> = IndexMap::new();
        let mut lines = Vec::with_capacity(m.rows.len());
        let mut sets: IndexMap<String, SetInfo> = IndexMap::new();
        for (i, r) in m.rows.iter().enumerate() {
            let file = files.get(i).map(|p| name_of(p)).unwrap_or_default();
            let l = next_line.entry(file.clone()).or_insert(2);
            lines.push(*l);
            *l += 1;
            let set = set_col.map_or("measured", |k| r.extra[k].as_str());
            sets.entry(set.to_owned())
                .or_insert(SetInfo { rows: 0, file })
                .rows += 1;
        }
        let outliers = self
            .outliers
            .iter()
            .map(|(i, d)| OutlierRecord {
                line: lines[*i],
                id: id_col.map(|k| m.rows[*i].extra[k].clone()),
                set: set_col.map(|k| m.rows[*i].extra[k].clone()),
                displacement_mm: *d,
            })
            .collect();
        TruthFile {
            generator: format!("robocal-core {}", env!("CARGO_PKG_VERSION")),
            robot: RobotInfo::shape_of(truth),
            nominal: nominal.name().to_owned(),
            truth: self.truth_label.clone(),
            parameters: TruthFile::parameter_entries(nominal, truth),
            tracker_frame: self.config.station_tracker_frame(),
            settings: self.config.clone(),
            geometric_errors: self.geometric_errors,
            joints_file: self.joints_file.clone(),
            sets,
            plane_z_mm: self.plane_z_mm,
            outliers,
            gravity_effect: self
                .deflection_mm
                .as_ref()
                .map(|d| ErrorStats::from_norms(d)),
            warnings: self.warnings.clone(),
        }
    }
}
