//! `robocal.plan_constraints`: `robocal plan --constraint KIND` / `--features-file FILE`
//! through the same library call (`planning::constraint::plan_constraints`), the configurations
//! as the CLI writes them (`written`), so the file `out` is the CLI's for the same settings.

use crate::errors::{usage, IntoPy};
use crate::robot::PyRobot;
use crate::written::{csv_bytes, read_back};
use pyo3::prelude::*;
use robocal_core::io::write_all_atomic;
use robocal_core::observations::constraint::ConstraintKind;
use robocal_core::planning::constraint::{plan_constraints, ConstraintPlanSettings};
use robocal_core::planning::constraint_features::{read_features, FeaturePlaces};
use robocal_core::planning::{Criterion, Quality};
use robocal_core::simulation::constraint::{constraint_measurements, ConstraintSimulation};
use robocal_core::simulation::PoseSampler;
use std::path::PathBuf;

/// A quality as JSON in interface units (`std` in the parameters' units).
fn quality(q: &Quality, params: &[robocal_core::Param]) -> serde_json::Value {
    serde_json::json!({
        "observability": q.observability,
        "log_det": q.log_det,
        "workspace_rms_mm": q.workspace_rms_mm,
        "std": params.iter().zip(&q.std).map(|(p, s)| p.unit().from_internal(*s)).collect::<Vec<_>>(),
    })
}

/// Plans constraint configurations (see `robocal.plan_constraints`); returns the joint values
/// (n, dof) in degrees as written, the written further columns (`constraint`, `radius_mm`), and
/// the plan's summary as JSON. Writes the CLI's file to `out` when given.
#[pyfunction]
#[pyo3(signature = (robot, constraint, features, features_file, per_feature, candidates_per_feature,
                    radius_mm, unknown_radius, distances, tilt_deg, span_mm, noise_mm, seed,
                    criterion, floor_mm, footprint_mm, out))]
#[allow(clippy::too_many_arguments)]
#[allow(clippy::type_complexity)]
pub fn plan_constraint_configurations<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    constraint: &str,
    features: usize,
    features_file: Option<PathBuf>,
    per_feature: usize,
    candidates_per_feature: usize,
    radius_mm: f64,
    unknown_radius: bool,
    distances: bool,
    tilt_deg: f64,
    span_mm: f64,
    noise_mm: f64,
    seed: u64,
    criterion: &str,
    floor_mm: f64,
    footprint_mm: Option<f64>,
    out: Option<PathBuf>,
) -> PyResult<(Bound<'py, PyAny>, Vec<(String, Vec<String>)>, String)> {
    let nominal = &robot.inner;
    let kind = ConstraintKind::parse(constraint).ok_or_else(|| {
        usage(format!(
            "constraint: `{constraint}` is not point, sphere or plane"
        ))
    })?;
    let criterion = match criterion.replace('_', "-").as_str() {
        "workspace" => Criterion::IOptimal,
        "d-optimal" => Criterion::DOptimal,
        other => {
            return Err(usage(format!(
                "criterion: `{other}` is not `workspace` or `d-optimal`"
            )))
        }
    };
    let places = match &features_file {
        Some(path) => FeaturePlaces::Given {
            path: path.clone(),
            features: read_features(path).py_err()?,
        },
        None => FeaturePlaces::Drawn,
    };
    let count = match &places {
        FeaturePlaces::Given { features, .. } => features.len(),
        FeaturePlaces::Drawn => features,
    };
    let settings = ConstraintPlanSettings {
        spec: ConstraintSimulation {
            kind,
            features: count,
            per_feature,
            noise_mm,
            radius_mm,
            radius_known: !unknown_radius,
            tilt_deg,
            span_mm,
            distances,
            seed,
        },
        places,
        candidates_per_feature,
        sampler: PoseSampler {
            floor_z_mm: floor_mm,
            footprint_radius_mm: footprint_mm.unwrap_or(0.15 * nominal.reach_mm()),
            ..PoseSampler::default()
        },
        criterion,
    };
    let p = py
        .detach(|| plan_constraints(nominal, &settings, &()))
        .py_err()?;
    let set = constraint_measurements(nominal, &p.data);
    let csv = csv_bytes(&set)?;
    if let Some(path) = &out {
        write_all_atomic(&[(path.as_path(), csv.as_slice())]).py_err()?;
    }
    let w = read_back(&csv, nominal.dof(), false)?;
    let q = numpy::ndarray::Array2::from_shape_vec((w.rows, nominal.dof()), w.q.clone())
        .expect("rows x dof values");
    let q = numpy::PyArray2::from_owned_array(py, q).into_any();
    let summary = serde_json::json!({
        "features": p.features.iter().map(|f| serde_json::json!({
            "label": f.label(),
            "position_mm": [f.position.x, f.position.y, f.position.z],
            "normal": f.normal.map(|n| [n.x, n.y, n.z]),
            "radius_mm": f.radius_mm,
            "radius_known": f.radius_known,
        })).collect::<Vec<_>>(),
        "parameters": p.identified.iter().map(|x| x.name()).collect::<Vec<_>>(),
        "unseen": p.unseen,
        "scale_known": p.scale_known,
        "planned": quality(&p.planned, &p.identified),
        "random": quality(&p.random_quality, &p.identified),
        "weakest": p.weakest.iter().map(|d| serde_json::json!({
            "rms_mm": d.rms_mm,
            "parameters": d.params.iter().map(|(q, w)| (q.name(), *w)).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "exchange_passes": p.exchange_passes,
        "exchanges": p.exchanges,
    });
    Ok((q, w.extra, summary.to_string()))
}
