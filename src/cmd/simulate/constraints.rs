//! `simulate --constraint point|sphere|plane`: constraint data instead of tracker readings (issue
//! 31). The true robot brings its tool point to fixed points, onto spheres or onto planes from
//! varied orientations (inverse kinematics on the true robot); `--noise-mm` is the contact's
//! noise (probe and repeatability); `--compliance` (with `--link-masses-kg`, `--payload-kg`)
//! makes the true robot sag under gravity, as in the tracker mode. Writes the measurement CSV
//! (`constraint`, `radius_mm`, no `x,y,z`) and, with `--distances-out`, the true distances
//! between the points or centres.

use super::SimulateArgs;
use crate::exit;
use anyhow::Context;
use robocal_core::io::measurements::measurements_csv;
use robocal_core::io::write_all_atomic;
use robocal_core::observations::constraint::ConstraintKind;
use robocal_core::simulation::constraint::{
    constraint_measurements, distances_csv, simulate_constraints, truth_json, ConstraintSimulation,
};
use robocal_core::simulation::{
    check_truth_matches, stream_rng, GeometricErrors, GravityModel, PoseSampler, Stream,
    TruthSource,
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
    let (truth, errors) = truth_of(a, &nominal)?;
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
    // The robot that moves: the truth, sagging under gravity when asked (the compliance family
    // set to the gravity model's physics).
    let gravity = gravity(a, nominal.dof())?;
    let moving = match &gravity {
        Some(g) => g
            .equivalent(&truth, false)
            .map_err(|e| exit::usage(format!("--compliance: {e}")))?,
        None => truth.clone(),
    };
    let sim = simulate_constraints(&moving, &sampler, &spec)?;
    let set = constraint_measurements(&nominal, &sim.data);
    let csv = measurements_csv(&set)?;
    let dist = distances_csv(&sim.data).into_bytes();
    let truth_out = super::truth_path(&a.out);
    let file_name = a
        .out
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut truth_json = truth_json(
        (&nominal, &truth),
        (&a.truth, errors),
        &spec,
        &sim,
        &file_name,
    )?;
    if let Some(g) = &gravity {
        // The gravity model in the settings, as the tracker mode's truth file has it.
        let mut v: serde_json::Value = serde_json::from_str(&truth_json)?;
        v["settings"]["gravity"] = serde_json::to_value(g)?;
        truth_json = serde_json::to_string_pretty(&v)? + "\n";
    }
    let truth_json = truth_json.into_bytes();
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

/// The gravity model of `--compliance`, `--link-masses-kg` and `--payload-kg` (one value for all
/// joints or one per joint), checked; `None` without `--compliance`.
fn gravity(a: &SimulateArgs, dof: usize) -> anyhow::Result<Option<GravityModel>> {
    let per_joint = |name: &str, s: &str| -> anyhow::Result<Vec<f64>> {
        let v = super::numbers(name, s)?;
        match v.len() {
            1 => Ok(vec![v[0]; dof]),
            n if n == dof => Ok(v),
            n => Err(exit::usage(format!(
                "{name}: {n} values: give one for every joint or one per joint ({dof})"
            ))),
        }
    };
    let Some(c) = &a.compliance else {
        return Ok(None);
    };
    let g = GravityModel::new(
        per_joint("--compliance", c)?,
        match &a.link_masses_kg {
            Some(m) => per_joint("--link-masses-kg", m)?,
            None => vec![0.0; dof],
        },
        a.payload_kg.unwrap_or(0.0),
    );
    g.validate(dof)
        .map_err(|e| exit::usage(format!("--compliance: {e}")))?;
    Ok(Some(g))
}

/// The true robot of `a.truth` (and the random errors' sizes, for a random truth).
fn truth_of(
    a: &SimulateArgs,
    nominal: &robocal_core::Robot,
) -> anyhow::Result<(robocal_core::Robot, Option<GeometricErrors>)> {
    let truth =
        TruthSource::from_arg(&a.truth, nominal).with_context(|| format!("--truth {}", a.truth))?;
    let random = matches!(truth, TruthSource::Random);
    if !random
        && (a.length_error_mm.is_some() || a.angle_error_deg.is_some() || a.tilt_parallel_axes)
    {
        return Err(exit::usage(
            "--length-error-mm, --angle-error-deg and --tilt-parallel-axes apply only to --truth \
             random",
        ));
    }
    Ok(match truth {
        TruthSource::Random => {
            let d = GeometricErrors::default();
            let e = GeometricErrors {
                length_sigma_mm: a.length_error_mm.unwrap_or(d.length_sigma_mm),
                angle_sigma_deg: a.angle_error_deg.unwrap_or(d.angle_sigma_deg),
                tilt_parallel_axes: a.tilt_parallel_axes,
            };
            let t = e.apply(nominal, &mut stream_rng(a.seed, Stream::Truth))?;
            (t, Some(e))
        }
        TruthSource::Robot(t) | TruthSource::File { robot: t, .. } => {
            check_truth_matches(nominal, &t)?;
            (t, None)
        }
    })
}

/// Measures the constraint plan at `plan` (`--constraint-plan`): the true robot of `a.truth`
/// touches every planned contact (`simulation::constraint::measure_plan`); writes the
/// measurement CSV, the truth file and, with `--distances-out`, the true distances.
pub(super) fn run_plan(a: &SimulateArgs, plan: &std::path::Path) -> anyhow::Result<()> {
    use robocal_core::io::{read_measurements, Positions};
    use robocal_core::observations::constraint::ConstraintData;
    use robocal_core::simulation::constraint::measure_plan;
    let nominal = super::common::robot(&a.robot)?;
    let truth_out = super::truth_path(&a.out);
    let mut io = super::super::io_plan::IoPlan::new();
    io.robot("--robot", &a.robot);
    if a.truth != "random" {
        io.robot("--truth", &a.truth);
    }
    io.input("--constraint-plan", plan)
        .output(
            "--out",
            &a.out,
            "the truth file is written beside it (FILE.truth.json)",
        )
        .derived_output(
            "--out",
            &a.out,
            &truth_out,
            "the truth file written beside it",
        );
    if let Some(d) = &a.distances_out {
        io.output("--distances-out", d, "calibrate reads it");
    }
    io.check()?;
    let set = read_measurements(plan, nominal.joint_space(), Positions::Ignored)?;
    let planned = ConstraintData::from_measurements(&set)?;
    if a.distances_out.is_some()
        && planned
            .features
            .iter()
            .filter(|f| f.kind != ConstraintKind::Plane)
            .count()
            < 2
    {
        return Err(exit::usage(
            "--distances-out: the plan has fewer than two points or spheres (distances are \
             between points or sphere centres)",
        ));
    }
    let (truth, errors) = truth_of(a, &nominal)?;
    let (sim, missed) = measure_plan(
        &truth,
        &nominal,
        &planned,
        a.noise_mm,
        a.seed,
        a.distances_out.is_some(),
    )?;
    let csv = measurements_csv(&constraint_measurements(&nominal, &sim.data))?;
    let dist = distances_csv(&sim.data).into_bytes();
    let file_name = a
        .out
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let kind = planned.features[0].kind;
    let spec = ConstraintSimulation {
        kind,
        features: planned.features.len(),
        per_feature: 0,
        noise_mm: a.noise_mm,
        seed: a.seed,
        distances: a.distances_out.is_some(),
        ..ConstraintSimulation::default()
    };
    let truth_json = truth_json(
        (&nominal, &truth),
        (&a.truth, errors),
        &spec,
        &sim,
        &file_name,
    )?
    .into_bytes();
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&a.out, &csv), (&truth_out, &truth_json)];
    if let Some(d) = &a.distances_out {
        files.push((d, &dist));
    }
    write_all_atomic(&files)?;
    if !missed.is_empty() {
        let lines: Vec<String> = missed
            .iter()
            .map(|&i| planned.rows[i].line.to_string())
            .collect();
        errln!(
            "warning: the true robot does not reach {} planned contact(s) from the planned \
             configuration within its joint limits (at a limit or a singularity); left out, as an \
             operator would skip them: {} line(s) {}",
            missed.len(),
            plan.display(),
            lines.join(", ")
        )?;
    }
    outln!(
        "{} constraint row(s) of the plan {} measured by the true robot, contact noise {} mm; \
         written to {}{}",
        sim.data.rows.len(),
        plan.display(),
        a.noise_mm,
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
