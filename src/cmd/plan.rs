//! `robocal plan`: the poses worth measuring (I- or D-optimal selection from random candidates);
//! with `--constraint` or `--features-file`, the configurations touching fixed points, spheres
//! or planes worth measuring ([`constraint`]).

mod constraint;

use super::common;
use super::io_plan::IoPlan;
use crate::exit;
use clap::Args;
use robocal_core::io::{
    read_measurements, write_measurements, Measurement, MeasurementSet, Positions,
};
use robocal_core::planning::{
    plan_observed, Criterion, Plan, PlanBuilder, PlanSettings, Quality, DEFAULT_CANDIDATES,
};
use robocal_core::simulation::{DEFAULT_NOISE_MM, DEFAULT_NOISE_PER_M};
use robocal_core::{Param, Robot};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct PlanArgs {
    /// The nominal robot: a preset name, a TOML robot file or a URDF.
    #[arg(long)]
    robot: String,
    /// Number of poses to choose (besides those of --include).
    #[arg(long, required_unless_present_any = ["constraint", "features_file"])]
    poses: Option<usize>,
    /// Where to write the chosen poses (CSV: q1..qn in degrees, mm for a prismatic joint), a
    /// joints file for `simulate --joints` or for measuring.
    #[arg(long)]
    out: PathBuf,
    /// Number of random candidates to choose from.
    #[arg(long, default_value_t = DEFAULT_CANDIDATES)]
    candidates: usize,
    /// Seed of the candidates: same arguments and seed give the same poses.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The tracker's pose in the base frame x,y,z,A,B,C (mm, deg), for --range-mm; default: the
    /// simulation's.
    #[arg(long, value_name = "x,y,z,A,B,C", allow_hyphen_values = true)]
    tracker: Option<String>,
    /// The tracker's working range MIN,MAX (mm): only poses whose tool point is at a distance
    /// from the tracker within it.
    #[arg(long, value_name = "MIN,MAX")]
    range_mm: Option<String>,
    /// Poses measured anyway (a joints or measurement CSV): part of the design, not written.
    #[arg(long, value_name = "FILE")]
    include: Option<PathBuf>,
    /// Reject poses whose nominal tool point is below this height (mm, base frame), as
    /// `simulate` does.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    floor_mm: f64,
    /// Reject poses whose nominal tool point is closer than this to the base axis (mm); default:
    /// 15% of the chain's total length, as `simulate`.
    #[arg(long, allow_hyphen_values = true)]
    footprint_mm: Option<f64>,
    /// Tracker noise, constant part: standard deviation per axis (mm), for the predicted
    /// standard deviations.
    #[arg(long, default_value_t = DEFAULT_NOISE_MM)]
    noise_mm: f64,
    /// Tracker noise per metre of distance (mm/m); with --tracker, poses far from the tracker
    /// count less in the design.
    #[arg(long, default_value_t = DEFAULT_NOISE_PER_M)]
    noise_per_m: f64,
    /// What the plan optimizes: `workspace` (the mean model error over the workspace,
    /// I-optimality) or `d-optimal` (the parameters' joint confidence region).
    #[arg(long, value_enum, default_value_t = CriterionArg::Workspace)]
    criterion: CriterionArg,
    #[command(flatten)]
    constraint: constraint::ConstraintPlanArgs,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
enum CriterionArg {
    /// I-optimality: minimize the mean squared model error over the workspace.
    Workspace,
    /// D-optimality: maximize det(J^T J).
    DOptimal,
}

/// Two numbers `MIN,MAX` (the library checks them as a range).
fn range_arg(s: &str) -> anyhow::Result<(f64, f64)> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| exit::usage(format!("--range-mm: `{s}` is not two numbers MIN,MAX")))?;
    let [a, b] = v[..] else {
        return Err(exit::usage(format!(
            "--range-mm: expected MIN,MAX (mm), got {} value(s)",
            v.len()
        )));
    };
    Ok((a, b))
}

struct Settings {
    robot: Robot,
    plan: PlanSettings,
    include: Option<PathBuf>,
    out: PathBuf,
}

impl TryFrom<&PlanArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &PlanArgs) -> anyhow::Result<Settings> {
        let builder = PlanBuilder {
            poses: a.poses.unwrap_or_default(),
            candidates: a.candidates,
            seed: a.seed,
            criterion: match a.criterion {
                CriterionArg::Workspace => Criterion::IOptimal,
                CriterionArg::DOptimal => Criterion::DOptimal,
            },
            tracker_frame: a
                .tracker
                .as_deref()
                .map(super::simulate::tracker_arg)
                .transpose()?,
            tracker_range: a.range_mm.as_deref().map(range_arg).transpose()?,
            include: Vec::new(),
            floor_z_mm: a.floor_mm,
            footprint_radius_mm: a.footprint_mm,
            noise_mm: a.noise_mm,
            noise_per_m: a.noise_per_m,
        };
        let robot = common::robot(&a.robot)?;
        let plan = builder.build(&robot)?;
        IoPlan::new()
            .robot("--robot", &a.robot)
            .input_opt("--include", a.include.as_deref())
            .output(
                "--out",
                &a.out,
                "the poses are a file that later commands read",
            )
            .check()?;
        Ok(Settings {
            plan,
            robot,
            include: a.include.clone(),
            out: a.out.clone(),
        })
    }
}

pub fn run(a: PlanArgs) -> anyhow::Result<()> {
    if a.constraint.active() {
        return constraint::run(&a);
    }
    let mut s = Settings::try_from(&a)?;
    if let Some(path) = &s.include {
        let set = read_measurements(path, s.robot.joint_space(), Positions::Optional)?;
        for w in &set.warnings {
            errln!("warning: {w}")?;
        }
        s.plan.include = set.rows.into_iter().map(|r| r.q).collect();
    }
    let bar = crate::progress::Bar::new("planning");
    let p = plan_observed(&s.robot, &s.plan, &bar);
    bar.finish();
    let p = p?;
    print_plan(&s, &p)?;
    let set = MeasurementSet {
        path: s.out.clone(),
        joints: s.robot.joint_space().clone(),
        extra_columns: Vec::new(),
        warnings: Vec::new(),
        rows: p
            .poses
            .iter()
            .enumerate()
            .map(|(i, q)| Measurement {
                line: i + 2,
                q: q.clone(),
                p: None,
                extra: Vec::new(),
            })
            .collect(),
    };
    write_measurements(&s.out, &set)?;
    outln!("{} poses written to {}", p.poses.len(), s.out.display())?;
    Ok(())
}

fn print_plan(s: &Settings, p: &Plan) -> anyhow::Result<()> {
    let n = s.plan.poses + s.plan.include.len();
    outln!(
        "robot {} ({} joints): {} poses chosen from {} candidates (seed {}){}; {} identifiable \
         parameters",
        s.robot.name(),
        s.robot.dof(),
        s.plan.poses,
        s.plan.candidates,
        s.plan.seed,
        if s.plan.include.is_empty() {
            String::new()
        } else {
            format!(", {} included", s.plan.include.len())
        },
        p.identified.len()
    )?;
    outln!(
        "{} design: greedy, then {} exchange pass(es) replacing {} pose(s){}",
        match s.plan.criterion {
            Criterion::IOptimal => "I-optimal (workspace error)",
            Criterion::DOptimal => "D-optimal",
        },
        p.exchange_passes,
        p.exchanges,
        if s.plan.tracker_origin.is_some() {
            "; poses weighted by the tracker's distance-dependent noise"
        } else {
            ""
        }
    )?;
    if s.plan.tracker_origin.is_some() {
        // The design is optimal for the fit that weighs each point as this tracker model does.
        outln!(
            "the figures assume a fit that weighs each point by this tracker model: calibrate \
             does so by default for measurements in the tracker's own frame with the typical \
             model (0.010 mm + 0.005 mm/m); for another give `--tracker-sigma {},{}`",
            s.plan.noise_mm,
            s.plan.noise_per_m
        )?;
    }
    outln!()?;
    print_figures(&p.planned, &p.random)?;
    outln!()?;
    outln!(
        "Predicted standard deviations at {} mm noise per axis{}, {n} poses each",
        s.plan.noise_mm,
        if s.plan.tracker_origin.is_some() {
            format!(" + {} mm/m", s.plan.noise_per_m)
        } else {
            String::new()
        }
    )?;
    print_stds(&p.identified, &p.planned, &p.random)
}

/// The planned and random poses' observability and predicted workspace error, side by side
/// (`plan` and `plan --constraint`).
pub(super) fn print_figures(planned: &Quality, random: &Quality) -> anyhow::Result<()> {
    outln!("{:<44}{:>14}{:>14}", "", "planned", "random")?;
    outln!(
        "{:<44}{:>14.4}{:>14.4}",
        "observability index O1 (scaled Jacobian)",
        planned.observability,
        random.observability
    )?;
    outln!(
        "{:<44}{:>14.4}{:>14.4}",
        "predicted workspace model error, RMS (mm)",
        planned.workspace_rms_mm,
        random.workspace_rms_mm
    )?;
    Ok(())
}

/// Each identified parameter's predicted standard deviation from the planned and the random
/// poses, in its display unit, then a blank line.
pub(super) fn print_stds(
    identified: &[Param],
    planned: &Quality,
    random: &Quality,
) -> anyhow::Result<()> {
    outln!(
        "{:<12}{:>14}{:>14}{:>8}",
        "parameter",
        "planned",
        "random",
        "unit"
    )?;
    for (i, param) in identified.iter().enumerate() {
        let u = param.unit();
        outln!(
            "{:<12}{:>14.5}{:>14.5}{:>8}",
            param.name(),
            u.from_internal(planned.std[i]),
            u.from_internal(random.std[i]),
            u.as_str()
        )?;
    }
    outln!()?;
    Ok(())
}
