//! `simulate --constraint point|sphere|plane`: constraint data instead of tracker readings (issue
//! 31). The true robot brings its tool point to fixed points, onto spheres or onto planes from
//! varied orientations (inverse kinematics on the true robot); `--noise-mm` is the contact's
//! noise (probe and repeatability). Writes the measurement CSV (`constraint`, `radius_mm`, no
//! `x,y,z`) and, with `--distances-out`, the true distances between the points or centres.

use super::SimulateArgs;
use crate::exit;
use anyhow::Context;
use robocal_core::io::measurements::measurements_csv;
use robocal_core::io::write_all_atomic;
use robocal_core::observations::constraint::ConstraintKind;
use robocal_core::simulation::constraint::{
    constraint_measurements, distances_csv, simulate_constraints, ConstraintSimulation,
};
use robocal_core::simulation::{
    check_truth_matches, stream_rng, GeometricErrors, PoseSampler, Stream, TruthSource,
};

/// Runs the constraint simulation of `a` (`a.constraint` is set).
pub(super) fn run(a: &SimulateArgs, kind: &str) -> anyhow::Result<()> {
    let Some(kind) = ConstraintKind::parse(kind) else {
        return Err(exit::usage(format!(
            "--constraint {kind}: not point, sphere or plane"
        )));
    };
    if a.distances_out.is_some() && kind == ConstraintKind::Plane {
        return Err(exit::usage(
            "--distances-out: planes have no distances (they are between points or sphere \
             centres)",
        ));
    }
    let nominal = super::common::robot(&a.robot)?;
    let truth = TruthSource::from_arg(&a.truth, &nominal)
        .with_context(|| format!("--truth {}", a.truth))?;
    let random = matches!(truth, TruthSource::Random);
    if !random
        && (a.length_error_mm.is_some() || a.angle_error_deg.is_some() || a.tilt_parallel_axes)
    {
        return Err(exit::usage(
            "--length-error-mm, --angle-error-deg and --tilt-parallel-axes apply only to --truth \
             random",
        ));
    }
    let (truth, errors) = match truth {
        TruthSource::Random => {
            let d = GeometricErrors::default();
            let e = GeometricErrors {
                length_sigma_mm: a.length_error_mm.unwrap_or(d.length_sigma_mm),
                angle_sigma_deg: a.angle_error_deg.unwrap_or(d.angle_sigma_deg),
                tilt_parallel_axes: a.tilt_parallel_axes,
            };
            let t = e.apply(&nominal, &mut stream_rng(a.seed, Stream::Truth))?;
            (t, Some(e))
        }
        TruthSource::Robot(t) | TruthSource::File { robot: t, .. } => {
            check_truth_matches(&nominal, &t)?;
            (t, None)
        }
    };
    let spec = ConstraintSimulation {
        kind,
        features: a.features,
        per_feature: a.per_feature,
        noise_mm: a.noise_mm,
        radius_mm: a.radius_mm,
        radius_known: !a.unknown_radius,
        tilt_deg: a.tilt_deg,
        span_mm: a.span_mm,
        distances: a.distances_out.is_some(),
        seed: a.seed,
    };
    spec.validate()
        .map_err(|e| exit::usage(format!("--constraint {}: {e}", kind.key())))?;
    let sampler = PoseSampler {
        floor_z_mm: a.floor_mm,
        footprint_radius_mm: a.footprint_mm.unwrap_or(0.15 * nominal.reach_mm()),
        ..PoseSampler::default()
    };
    let sim = simulate_constraints(&truth, &sampler, &spec)?;
    let set = constraint_measurements(&nominal, &sim.data);
    let csv = measurements_csv(&set)?;
    let dist = distances_csv(&sim.data).into_bytes();
    let truth_out = super::truth_path(&a.out);
    let truth_json = truth_file(a, (&nominal, &truth, errors), &spec, &sim)?.into_bytes();
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&a.out, &csv), (&truth_out, &truth_json)];
    if let Some(d) = &a.distances_out {
        files.push((d, &dist));
    }
    write_all_atomic(&files)?;
    outln!(
        "{} constraint row(s): {} {}(s) x {} configuration(s), contact noise {} mm; written to \
         {}{}",
        sim.data.rows.len(),
        spec.features,
        kind.key(),
        spec.per_feature,
        spec.noise_mm,
        a.out.display(),
        a.distances_out.as_ref().map_or(String::new(), |d| format!(
            ", {} distance(s) to {}",
            sim.data.distances.len(),
            d.display()
        ))
    )?;
    outln!(
        "truth (the true robot and the true features, base frame of the true robot): {}",
        truth_out.display()
    )?;
    Ok(())
}

/// The truth file: the one the other simulate modes write (the true robot's parameters; the
/// tracker frame the identity, as there is no tracker), with a `constraint` section holding the
/// true features (base frame of the true robot) and the simulation's settings.
fn truth_file(
    a: &SimulateArgs,
    (nominal, truth, errors): (
        &robocal_core::Robot,
        &robocal_core::Robot,
        Option<GeometricErrors>,
    ),
    spec: &ConstraintSimulation,
    sim: &robocal_core::simulation::constraint::SimulatedConstraints,
) -> anyhow::Result<String> {
    use robocal_core::io::result::{FrameVec, RobotInfo};
    use robocal_core::simulation::{SetInfo, SimulationConfig, TruthFile};
    let identity = FrameVec {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        a: 0.0,
        b: 0.0,
        c: 0.0,
    };
    let file_name = a
        .out
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tf = TruthFile {
        generator: format!("robocal-core {}", env!("CARGO_PKG_VERSION")),
        robot: RobotInfo::shape_of(truth),
        nominal: nominal.name().to_owned(),
        truth: a.truth.clone(),
        parameters: TruthFile::parameter_entries(nominal, truth),
        tracker_frame: identity,
        settings: SimulationConfig {
            seed: a.seed,
            poses: sim.data.rows.len(),
            validation_poses: 0,
            plane_points: false,
            plane_z_mm: None,
            tracker_frame: identity,
            noise_mm: spec.noise_mm,
            noise_per_m: 0.0,
            ..SimulationConfig::default()
        },
        geometric_errors: errors,
        joints_file: None,
        sets: [(
            "constraint".to_owned(),
            SetInfo {
                rows: sim.data.rows.len(),
                file: file_name,
            },
        )]
        .into_iter()
        .collect(),
        plane_z_mm: None,
        outliers: Vec::new(),
        gravity_effect: None,
        warnings: Vec::new(),
    };
    let mut v = serde_json::to_value(&tf)?;
    let features: Vec<serde_json::Value> = sim
        .data
        .features
        .iter()
        .zip(sim.true_positions.iter().zip(&sim.true_normals))
        .map(|(f, (p, n))| {
            serde_json::json!({
                "kind": f.kind.key(),
                "name": f.name,
                "position_mm": [p.x, p.y, p.z],
                "radius_mm": (f.kind == ConstraintKind::Sphere).then_some(spec.radius_mm),
                "radius_given": f.radius_mm.is_some(),
                "normal": n.map(|n| [n.x, n.y, n.z]),
            })
        })
        .collect();
    v["constraint"] = serde_json::json!({
        "frame": "base frame of the true robot",
        "kind": spec.kind.key(),
        "features": features,
        "per_feature": spec.per_feature,
        "tilt_deg": spec.tilt_deg,
        "span_mm": spec.span_mm,
        "distances": sim.data.distances.len(),
    });
    let mut s = serde_json::to_string_pretty(&v)?;
    s.push('\n');
    Ok(s)
}
