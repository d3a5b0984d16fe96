//! `robocal.calibrate_files` on constraint data (issue 31): a measurement file with a
//! `constraint` column (fixed points, spheres, planes; no x,y,z), with known distances from a
//! distances file, through the CLI's library calls (`calibrate_constraints`,
//! `ConstraintCalibration::to_result`) and with the CLI's refusals: an undetermined scale
//! (`NumericalError`, unless `accept_unknown_scale`), a fit that did not converge
//! (`NumericalError`), a fit that failed the gate (`ImplausibleError`, unless
//! `accept_implausible`), rows outside the joint limits (`InputError`, unless `nominal_limits`).

use crate::errors::{input, raise, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use robocal_core::identification::constraint::{calibrate_constraints, ConstraintOptions};
use robocal_core::io::inputs::{InputFile, Inputs};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::{read_measurements, Measurement, MeasurementSet, Positions};
use robocal_core::observations::constraint::{
    parse_distances, read_distances, ConstraintData, CONSTRAINT_COLUMN, RADIUS_COLUMN,
};
use std::path::PathBuf;

/// Whether the measurement file at `path` has a `constraint` column.
#[pyfunction]
pub fn is_constraint_file(robot: &PyRobot, path: PathBuf) -> PyResult<bool> {
    let r = robocal_core::io::measurements::MeasurementReader::open(
        &path,
        robot.inner.joint_space(),
        Positions::Ignored,
    )
    .py_err()?;
    Ok(r.extra_columns()
        .iter()
        .any(|c| c.eq_ignore_ascii_case(CONSTRAINT_COLUMN)))
}

/// Calibrates `robot` from the constraint file `data` (see the module docs); returns the result
/// JSON, its status, the warnings and the library's seconds, as `calibrate_files`.
#[pyfunction]
#[pyo3(signature = (robot, data, distances = None, accept_unknown_scale = false,
                    accept_implausible = false, nominal_limits = false, rank_tol = None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_constraint_file(
    py: Python<'_>,
    robot: &PyRobot,
    data: PathBuf,
    distances: Option<PathBuf>,
    accept_unknown_scale: bool,
    accept_implausible: bool,
    nominal_limits: bool,
    rank_tol: Option<f64>,
) -> PyResult<(String, String, Vec<String>, f64)> {
    let nominal = &robot.inner;
    let mut warnings = Vec::new();
    let set = read_measurements(&data, nominal.joint_space(), Positions::Ignored).py_err()?;
    warnings.extend(set.warnings.iter().map(|w| w.to_string()));
    limits(nominal, &set, nominal_limits, &mut warnings)?;
    let mut cdata = ConstraintData::from_measurements(&set).py_err()?;
    if let Some(d) = &distances {
        cdata.distances = read_distances(d, &cdata).py_err()?;
    }
    let mut inputs = Inputs::new();
    inputs.insert("data".into(), InputFile::of(&data).py_err()?);
    if let Some(d) = &distances {
        inputs.insert("distances".into(), InputFile::of(d).py_err()?);
    }
    let opts = options(accept_unknown_scale, rank_tol);
    let what = data.display().to_string();
    calibrate_data(
        py,
        nominal,
        &cdata,
        &opts,
        None,
        accept_implausible,
        &what,
        Some(inputs),
        warnings,
    )
}

/// Calibrates `robot` from arrays of constraint rows (see `robocal.calibrate_constraints`):
/// `q` (n, dof) in degrees (mm for a prismatic joint), one `constraint` label per row
/// (`point:NAME`, `sphere:NAME`, `plane:NAME`), `radius_mm` per row (NaN: unknown; None: no
/// radius column), `distances` as `(from, to, mm)`. The rows go through the file form's reader
/// (`ConstraintData::from_measurements`, `parse_distances`), so the refusals are the file's, the
/// arrays' rows numbered from 1 and the distances' entries from 2 (their line in a file).
#[pyfunction]
#[pyo3(signature = (robot, q, constraint, radius_mm = None, distances = None,
                    accept_unknown_scale = false, accept_implausible = false,
                    nominal_limits = false, rank_tol = None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_constraint_arrays(
    py: Python<'_>,
    robot: &PyRobot,
    q: &Bound<'_, PyAny>,
    constraint: Vec<String>,
    radius_mm: Option<Vec<f64>>,
    distances: Option<Vec<(String, String, f64)>>,
    accept_unknown_scale: bool,
    accept_implausible: bool,
    nominal_limits: bool,
    rank_tol: Option<f64>,
) -> PyResult<(String, String, Vec<String>, f64)> {
    let nominal = &robot.inner;
    let qm = robot.joints(q, "q")?;
    if constraint.len() != qm.rows {
        return Err(input(format!(
            "constraint: {} label(s) for {} row(s) of q: one label per row",
            constraint.len(),
            qm.rows
        )));
    }
    if let Some(r) = &radius_mm {
        if r.len() != qm.rows {
            return Err(input(format!(
                "radius_mm: {} value(s) for {} row(s) of q: one per row (NaN where unknown or \
                 not a sphere)",
                r.len(),
                qm.rows
            )));
        }
        if let Some(i) = r.iter().position(|v| v.is_infinite()) {
            return Err(input(format!(
                "radius_mm: row {}: {} is not a length (NaN for an unknown radius)",
                i + 1,
                r[i]
            )));
        }
    }
    let mut extra_columns = vec![CONSTRAINT_COLUMN.to_string()];
    if radius_mm.is_some() {
        extra_columns.push(RADIUS_COLUMN.to_string());
    }
    let set = MeasurementSet {
        path: PathBuf::from("constraint arrays"),
        joints: nominal.joint_space().clone(),
        extra_columns,
        rows: (0..qm.rows)
            .map(|i| {
                let mut extra = vec![constraint[i].clone()];
                if let Some(r) = &radius_mm {
                    extra.push(if r[i].is_nan() {
                        String::new()
                    } else {
                        format!("{}", r[i])
                    });
                }
                Measurement {
                    line: i + 1,
                    q: qm.row(i).to_vec(),
                    p: None,
                    extra,
                }
            })
            .collect(),
        warnings: Vec::new(),
    };
    let mut warnings = Vec::new();
    limits(nominal, &set, nominal_limits, &mut warnings)?;
    let mut cdata = ConstraintData::from_measurements(&set).py_err()?;
    if let Some(d) = distances.filter(|d| !d.is_empty()) {
        let mut w = csv::Writer::from_writer(Vec::new());
        let csv_err = |e: csv::Error| raise(1, format!("distances: {e}"));
        w.write_record(["from", "to", "distance_mm"])
            .map_err(csv_err)?;
        for (a, b, mm) in &d {
            w.write_record([a.as_str(), b.as_str(), &format!("{mm}")])
                .map_err(csv_err)?;
        }
        let text = w
            .into_inner()
            .map_err(|e| raise(1, format!("distances: {e}")))?;
        cdata.distances = parse_distances(
            &text[..],
            std::path::Path::new("distances (entry 1 on line 2)"),
            &cdata,
        )
        .py_err()?;
    }
    let opts = options(accept_unknown_scale, rank_tol);
    calibrate_data(
        py,
        nominal,
        &cdata,
        &opts,
        None,
        accept_implausible,
        "constraint arrays",
        None,
        warnings,
    )
}

/// Refuses rows of `set` outside `nominal`'s joint limits, unless `nominal_limits` (then a
/// warning), as the CLI does.
fn limits(
    nominal: &robocal_core::Robot,
    set: &MeasurementSet,
    nominal_limits: bool,
    warnings: &mut Vec<String>,
) -> PyResult<()> {
    let mut o = OutsideLimits::new(nominal, &set.path);
    for r in &set.rows {
        o.check(r.line, &r.q);
    }
    if nominal_limits {
        if let Some(w) = o.to_warning() {
            warnings.push(format!("{w} (used anyway: nominal_limits=True)"));
        }
    } else if let Some(e) = o.to_error() {
        return Err(input(format!(
            "{}; if the robot's limits are only nominal, pass nominal_limits=True to use these \
             rows",
            crate::errors::message(&e)
        )));
    }
    Ok(())
}

/// The calibration's settings from the keyword arguments.
fn options(accept_unknown_scale: bool, rank_tol: Option<f64>) -> ConstraintOptions {
    let mut opts = ConstraintOptions {
        accept_unknown_scale,
        ..ConstraintOptions::default()
    };
    if let Some(t) = rank_tol {
        opts.rank_tolerance = t;
    }
    opts
}

/// Calibrates from `cdata` (read from a file or from arrays, `what` in messages) with the CLI's
/// refusals, the model chosen as `model` says (`None`: as `calibrate_files` chooses it by default
/// on constraint data, and the CLI: the families the data support, by cross-validation by
/// configuration); returns what `calibrate_constraint_file` returns.
#[allow(clippy::too_many_arguments)]
pub(crate) fn calibrate_data(
    py: Python<'_>,
    nominal: &robocal_core::Robot,
    cdata: &ConstraintData,
    opts: &ConstraintOptions,
    model: Option<robocal_core::identification::ModelChoice>,
    accept_implausible: bool,
    what: &str,
    inputs: Option<Inputs>,
    mut warnings: Vec<String>,
) -> PyResult<(String, String, Vec<String>, f64)> {
    let started = std::time::Instant::now();
    let model =
        model.unwrap_or_else(|| robocal_core::identification::CalibrationSettings::default().model);
    let cal = py
        .detach(|| match model {
            robocal_core::identification::ModelChoice::Auto(auto) => {
                robocal_core::identification::constraint::calibrate_constraints_auto(
                    nominal, cdata, opts, auto,
                )
            }
            robocal_core::identification::ModelChoice::Given => {
                calibrate_constraints(nominal, cdata, opts)
            }
        })
        .map_err(|e| {
            let hint = if cdata.has_known_length() {
                ""
            } else {
                " (distances=FILE with from,to,distance_mm; or radius_mm on a sphere's rows; or \
                 accept_unknown_scale=True)"
            };
            raise(
                crate::errors::exit_code(&e),
                format!(
                    "calibrating from {what}: {}{hint}",
                    crate::errors::message(&e)
                ),
            )
        })?;
    let seconds = started.elapsed().as_secs_f64();
    if !cal.fit.converged {
        return Err(raise(
            5,
            format!(
                "the constraint fit did not converge in {} iterations: not a calibration",
                cal.fit.iterations
            ),
        ));
    }
    if !cal.implausible.is_empty() {
        let summary = cal.implausible.join("\n");
        if !accept_implausible {
            return Err(raise(
                6,
                format!(
                    "implausible fit: the constraint fit converged, but the result cannot be a \
                     calibration. Failed checks:\n{summary}\n(fix the data or the robot; \
                     accept_implausible=True returns it anyway, marked \"status\": \
                     \"implausible\")"
                ),
            ));
        }
        warnings.push(format!(
            "IMPLAUSIBLE FIT (accept_implausible=True): the fit failed the plausibility gate and \
             is NOT a calibration:\n{summary}"
        ));
    }
    if let robocal_core::identification::constraint::Scale::Assumed { held } = &cal.scale {
        warnings.push(format!(
            "the robot's scale is not determined by these data; {} is held at its nominal value \
             (accept_unknown_scale=True): lengths may be off in proportion",
            held.name()
        ));
    }
    if let Some(remark) = cal.model_selection.as_ref().and_then(|s| s.remark.as_ref()) {
        warnings.push(remark.clone());
    }
    let mut res = cal.to_result(nominal, cdata).py_err()?;
    res.inputs = inputs;
    let status = res.status().map_or("calibrated", |s| s.as_str()).to_owned();
    let text = res
        .to_text()
        .map_err(|e| raise(1, format!("cannot serialize the result: {e}")))?;
    Ok((text, status, warnings, seconds))
}

/// `robocal simulate --constraint KIND`: constraint data of the truth (`"random"`, a preset, a
/// robot file, a truth file or a Robot) written to `out` (and the true distances to
/// `distances_out`), the truth file beside `out` (`FILE.truth.json`), through the CLI's library
/// calls, so the files are the CLI's for the same settings. Returns the truth file's path.
#[pyfunction]
#[pyo3(signature = (robot, out, truth, kind, features = 4, per_feature = 20, noise_mm = 0.01,
                    radius_mm = 25.0, unknown_radius = false, tilt_deg = 60.0, span_mm = 300.0,
                    seed = 1, distances_out = None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_constraints(
    robot: &PyRobot,
    out: PathBuf,
    truth: &Bound<'_, PyAny>,
    kind: &str,
    features: usize,
    per_feature: usize,
    noise_mm: f64,
    radius_mm: f64,
    unknown_radius: bool,
    tilt_deg: f64,
    span_mm: f64,
    seed: u64,
    distances_out: Option<PathBuf>,
) -> PyResult<PathBuf> {
    use robocal_core::io::measurements::measurements_csv;
    use robocal_core::observations::constraint::ConstraintKind;
    use robocal_core::simulation::constraint::{
        constraint_measurements, distances_csv, simulate_constraints as simulate, truth_json,
        ConstraintSimulation,
    };
    use robocal_core::simulation::{
        check_truth_matches, stream_rng, GeometricErrors, PoseSampler, Stream, TruthSource,
    };
    let nominal = &robot.inner;
    let Some(kind) = ConstraintKind::parse(kind) else {
        return Err(crate::errors::usage(format!(
            "constraint: `{kind}` is not point, sphere or plane"
        )));
    };
    if distances_out.is_some() && kind == ConstraintKind::Plane {
        return Err(crate::errors::usage(
            "distances_out: planes have no distances (they are between points or sphere centres)",
        ));
    }
    let label = match truth.extract::<String>() {
        Ok(s) => s,
        Err(_) => "robot".to_owned(),
    };
    let (true_robot, errors) = match crate::simulate::truth_arg(truth, nominal)? {
        TruthSource::Random => {
            let e = GeometricErrors::default();
            let t = e
                .apply(nominal, &mut stream_rng(seed, Stream::Truth))
                .py_err()?;
            (t, Some(e))
        }
        TruthSource::Robot(t) | TruthSource::File { robot: t, .. } => {
            check_truth_matches(nominal, &t).py_err()?;
            (t, None)
        }
    };
    let spec = ConstraintSimulation {
        kind,
        features,
        per_feature,
        noise_mm,
        radius_mm,
        radius_known: !unknown_radius,
        tilt_deg,
        span_mm,
        distances: distances_out.is_some(),
        seed,
    };
    spec.validate()
        .map_err(|e| crate::errors::usage(format!("constraint {}: {e}", kind.key())))?;
    let sampler = PoseSampler {
        footprint_radius_mm: 0.15 * nominal.reach_mm(),
        ..PoseSampler::default()
    };
    let sim = simulate(&true_robot, &sampler, &spec).py_err()?;
    let csv = measurements_csv(&constraint_measurements(nominal, &sim.data))
        .map_err(|e| raise(1, format!("cannot write the measurement CSV: {e}")))?;
    let dist = distances_csv(&sim.data).into_bytes();
    let truth_out = out.with_extension("truth.json");
    let name = out
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tj = truth_json((nominal, &true_robot), (&label, errors), &spec, &sim, &name)
        .py_err()?
        .into_bytes();
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&out, &csv), (&truth_out, &tj)];
    if let Some(d) = &distances_out {
        files.push((d, &dist));
    }
    robocal_core::io::write_all_atomic(&files).py_err()?;
    Ok(truth_out)
}
