//! `robocal plan --constraint point|sphere|plane` (or `--features-file`): the configurations
//! touching fixed points, spheres or planes worth measuring without a tracker
//! ([`robocal_core::planning::constraint`]). Writes a measurement CSV with the `constraint`
//! column (and `radius_mm` for spheres) and no x,y,z: the file to measure, the joints as the
//! robot reaches each feature.

use super::super::io_plan::IoPlan;
use super::{CriterionArg, PlanArgs};
use crate::exit;
use clap::Args;
use robocal_core::io::write_measurements;
use robocal_core::observations::constraint::ConstraintKind;
use robocal_core::planning::constraint::{
    plan_constraints, ConstraintPlan, ConstraintPlanSettings, DEFAULT_CANDIDATES_PER_FEATURE,
};
use robocal_core::planning::constraint_features::{read_features, FeaturePlaces};
use robocal_core::planning::Criterion;
use robocal_core::simulation::constraint::{constraint_measurements, ConstraintSimulation};
use robocal_core::simulation::PoseSampler;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub(super) struct ConstraintPlanArgs {
    /// Plan configurations that bring the tool point to fixed points, onto spheres or onto
    /// planes (no tracker), the features placed as `simulate --constraint` places them; --noise-mm
    /// is then the contact's noise (probe and repeatability).
    #[arg(long, value_name = "point|sphere|plane", group = "constraint_mode", conflicts_with_all = ["poses", "candidates", "include", "tracker", "range_mm", "features_file"])]
    constraint: Option<String>,
    /// The cell's features instead: a CSV with the columns constraint (point:NAME, sphere:NAME,
    /// plane:NAME), x,y,z (mm, base frame: a point, a sphere's centre, a point of a plane) and as
    /// needed nx,ny,nz (a plane's normal toward the probe; a sphere's touched side, default up)
    /// and radius_mm (a sphere's).
    #[arg(long, value_name = "FILE", group = "constraint_mode", conflicts_with_all = ["poses", "candidates", "include", "tracker", "range_mm", "features"])]
    features_file: Option<PathBuf>,
    /// With --constraint: how many points, spheres or planes.
    #[arg(long, default_value_t = 4, requires = "constraint_mode")]
    features: usize,
    /// Configurations per feature (the plan chooses features x this many in all; each feature
    /// gets at least what it needs: 2 for a point, 4 for a sphere, 3 for a plane).
    #[arg(long, default_value_t = 20, requires = "constraint_mode")]
    per_feature: usize,
    /// Candidate configurations per feature to choose from.
    #[arg(long, default_value_t = DEFAULT_CANDIDATES_PER_FEATURE, requires = "constraint_mode")]
    candidates_per_feature: usize,
    /// With --constraint sphere: the spheres' radius (mm).
    #[arg(long, default_value_t = 25.0, requires = "constraint_mode")]
    radius_mm: f64,
    /// Spheres of unknown radius (estimated with the robot).
    #[arg(long, requires = "constraint_mode")]
    unknown_radius: bool,
    /// The distances between every pair of points or sphere centres will be measured (a
    /// distances file for `calibrate --distances`): the design counts them, and they give the
    /// robot's scale.
    #[arg(long, requires = "constraint_mode")]
    distances: bool,
    /// Largest tilt of the tool from a feature's reference orientation (deg).
    #[arg(long, default_value_t = 60.0, requires = "constraint_mode")]
    tilt_deg: f64,
    /// A plane's touched square's half-size, a sphere's contact region (mm).
    #[arg(long, default_value_t = 300.0, requires = "constraint_mode")]
    span_mm: f64,
}

impl ConstraintPlanArgs {
    /// Whether a constraint plan is asked for.
    pub(super) fn active(&self) -> bool {
        self.constraint.is_some() || self.features_file.is_some()
    }
}

/// Runs the constraint plan of `a` (`a.constraint.active()`).
pub(super) fn run(a: &PlanArgs) -> anyhow::Result<()> {
    let c = &a.constraint;
    let kind = match &c.constraint {
        Some(k) => ConstraintKind::parse(k)
            .ok_or_else(|| exit::usage(format!("--constraint {k}: not point, sphere or plane")))?,
        None => ConstraintKind::Point,
    };
    let robot = super::common::robot(&a.robot)?;
    IoPlan::new()
        .robot("--robot", &a.robot)
        .input_opt("--features-file", c.features_file.as_deref())
        .output(
            "--out",
            &a.out,
            "the configurations are a file that later commands read",
        )
        .check()?;
    let places = match &c.features_file {
        Some(path) => FeaturePlaces::Given {
            path: path.clone(),
            features: read_features(path)?,
        },
        None => FeaturePlaces::Drawn,
    };
    let features = match &places {
        FeaturePlaces::Given { features, .. } => features.len(),
        FeaturePlaces::Drawn => c.features,
    };
    let settings = ConstraintPlanSettings {
        spec: ConstraintSimulation {
            kind,
            features,
            per_feature: c.per_feature,
            noise_mm: a.noise_mm,
            radius_mm: c.radius_mm,
            radius_known: !c.unknown_radius,
            tilt_deg: c.tilt_deg,
            span_mm: c.span_mm,
            distances: c.distances,
            seed: a.seed,
        },
        places,
        candidates_per_feature: c.candidates_per_feature,
        sampler: PoseSampler {
            floor_z_mm: a.floor_mm,
            footprint_radius_mm: a.footprint_mm.unwrap_or(0.15 * robot.reach_mm()),
            ..PoseSampler::default()
        },
        criterion: match a.criterion {
            CriterionArg::Workspace => Criterion::IOptimal,
            CriterionArg::DOptimal => Criterion::DOptimal,
        },
    };
    let bar = crate::progress::Bar::new("planning");
    let p = plan_constraints(&robot, &settings, &bar);
    bar.finish();
    let p = p?;
    print_plan(&robot, &settings, &p)?;
    let mut set = constraint_measurements(&robot, &p.data);
    set.path = a.out.clone();
    write_measurements(&a.out, &set)?;
    outln!(
        "{} configurations written to {} (measure them: bring the tool to each row's feature \
         from about these joint values and record the joints{})",
        p.data.rows.len(),
        a.out.display(),
        if p.data.distances.is_empty() {
            ""
        } else {
            "; measure the distances between the points or centres for calibrate --distances"
        }
    )?;
    Ok(())
}

fn print_plan(
    robot: &robocal_core::Robot,
    s: &ConstraintPlanSettings,
    p: &ConstraintPlan,
) -> anyhow::Result<()> {
    outln!(
        "robot {} ({} joints): {} configurations on {} feature(s) chosen from {} candidates \
         each (seed {}); {} identifiable robot parameters",
        robot.name(),
        robot.dof(),
        p.data.rows.len(),
        p.features.len(),
        s.candidates_per_feature,
        s.spec.seed,
        p.identified.len()
    )?;
    outln!(
        "{} design on the robot's parameters and the features' own (estimated with them), \
         greedy, then {} exchange pass(es) replacing {} configuration(s)",
        match s.criterion {
            Criterion::IOptimal => "I-optimal (workspace error)",
            Criterion::DOptimal => "D-optimal",
        },
        p.exchange_passes,
        p.exchanges
    )?;
    outln!()?;
    outln!("Features (nominal places, base frame, mm):")?;
    for (k, f) in p.features.iter().enumerate() {
        let at = f.position;
        outln!(
            "  {:<16} ({:.1}, {:.1}, {:.1}){}{}: {} configurations",
            f.label(),
            at.x,
            at.y,
            at.z,
            f.normal.map_or(String::new(), |n| format!(
                " normal ({:.3}, {:.3}, {:.3})",
                n.x, n.y, n.z
            )),
            f.radius_mm.map_or(String::new(), |r| format!(
                " radius {r} mm{}",
                if f.radius_known { "" } else { " (unknown)" }
            )),
            p.data.rows_of(k).count()
        )?;
    }
    outln!()?;
    super::print_figures(&p.planned, &p.random_quality)?;
    outln!(
        "(random: as many configurations drawn as `simulate --constraint` draws them; the \
         error before the rigid alignment, at {} mm contact noise per axis)",
        s.spec.noise_mm
    )?;
    outln!()?;
    super::print_stds(&p.identified, &p.planned, &p.random_quality)?;
    if !p.weakest.is_empty() {
        outln!(
            "Directions the planned configurations see least (share of the predicted model \
             error, RMS mm; the parameters that make each up, relative weights):"
        )?;
        for d in &p.weakest {
            let parts: Vec<String> = d
                .params
                .iter()
                .map(|(q, w)| format!("{:+.2} {}", w, q.name()))
                .collect();
            outln!("  {:>10.5}  {}", d.rms_mm, parts.join(" "))?;
        }
        outln!()?;
    }
    outln!("What these data cannot see:")?;
    for u in &p.unseen {
        outln!("  - {u}")?;
    }
    if !p.scale_known {
        outln!(
            "no known length in the plan: calibrate refuses such data unless \
             --accept-unknown-scale (measure a distance with --distances, or use a sphere of \
             known radius)"
        )?;
    }
    outln!()?;
    Ok(())
}
