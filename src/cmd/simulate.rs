//! `robocal simulate`: measure a virtual robot with a virtual laser tracker.

use super::common;
use super::io_plan::IoPlan;
use crate::exit;
use anyhow::Context;
use clap::Args;
use robocal_core::io::measurements::{measurements_csv, read_measurements, Positions};
use robocal_core::io::result::FrameVec;
use robocal_core::io::write_all_atomic;
use robocal_core::simulation::{
    simulate, simulate_joints, PerJoint, Simulation, SimulationBuilder, SimulationConfig,
    SimulationSettings, TargetMeasurement, TruthFile, TruthSource, TruthSpec, SET_VALIDATION,
};
use robocal_core::Robot;
use std::path::{Path, PathBuf};

mod constraints;

/// Rows from which a progress bar is shown.
const BAR_FROM: usize = 10_000;

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// The nominal robot, the model the controller believes: a preset, a TOML robot file or a URDF.
    #[arg(long)]
    robot: String,
    /// The robot that really moves: a preset (e.g. kuka-kr480-r3330-table3), a TOML robot file,
    /// the truth file (*.truth.json) of an earlier simulation (its tracker frame too), or
    /// `random`: the nominal robot with seeded random geometric errors.
    #[arg(long)]
    truth: String,
    /// Number of random calibration poses (set `calibration`); with --validation at most
    /// 10000000 in all.
    #[arg(long, required_unless_present_any = ["joints", "constraint", "constraint_plan"])]
    poses: Option<usize>,
    /// Measure the joint values of this CSV (q1..qn in degrees, mm for a prismatic joint, or
    /// axis1..axisN) instead of random poses, e.g.
    /// commanded joints in the verification phase. Rows keep their order and extra columns; any
    /// x,y,z columns are replaced by the new readings.
    #[arg(long, conflicts_with_all = ["poses", "validation", "no_plane", "plane_z_mm"])]
    joints: Option<PathBuf>,
    /// Seed of every random choice: same arguments and seed give byte-identical files.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The measurement CSV to write; the truth goes to FILE.truth.json beside it.
    #[arg(long)]
    out: PathBuf,
    /// Also draw N validation poses (set `validation`), in the same file unless
    /// --validation-out is given.
    #[arg(long, default_value_t = 0)]
    validation: usize,
    /// Write the validation rows to this CSV instead of --out.
    #[arg(long)]
    validation_out: Option<PathBuf>,
    /// Leave out the paper's three points on a plane parallel to the base plane (set `plane`).
    #[arg(long)]
    no_plane: bool,
    /// Height of the plane points' plane (mm, base frame); default: the median tool height of
    /// random poses.
    #[arg(long, allow_hyphen_values = true)]
    plane_z_mm: Option<f64>,
    /// Pose of the tracker in the robot's base frame, x,y,z,A,B,C (mm, deg); default
    /// 3112.8,-2179.6,1200,125,0,0 (about 4 m away, turned 125 degrees, levelled).
    #[arg(long, allow_hyphen_values = true)]
    tracker: Option<String>,
    /// Tracker noise, constant part: standard deviation per axis (mm).
    #[arg(long, default_value_t = robocal_core::simulation::DEFAULT_NOISE_MM, allow_hyphen_values = true)]
    noise_mm: f64,
    /// Tracker noise, distance part: standard deviation per axis per metre from the tracker (mm/m).
    #[arg(long, default_value_t = robocal_core::simulation::DEFAULT_NOISE_PER_M, allow_hyphen_values = true)]
    noise_per_m: f64,
    /// With --truth random: standard deviation of the length errors (d, a, base and tool
    /// x/y/z), mm [default: 0.5].
    #[arg(long, allow_hyphen_values = true)]
    length_error_mm: Option<f64>,
    /// With --truth random: standard deviation of the angle errors (alpha, phi, base and tool
    /// A/B/C), deg [default: 0.03].
    #[arg(long, allow_hyphen_values = true)]
    angle_error_deg: Option<f64>,
    /// With --truth random: also tilt (Hayati beta) every joint axis nominally parallel to the
    /// previous one, an error modified DH cannot represent.
    #[arg(long)]
    tilt_parallel_axes: bool,
    /// Reject random poses whose nominal tool point is below this height (mm, base frame).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    floor_mm: f64,
    /// Reject random poses whose nominal tool point is closer than this to the base axis (mm);
    /// default: 15% of the chain's total length.
    #[arg(long, allow_hyphen_values = true)]
    footprint_mm: Option<f64>,
    /// Gravity deflection: joint compliances in rad per N·m, one value for all joints or one per
    /// joint (e.g. 1e-7). Turns the gravity model on.
    #[arg(long, allow_hyphen_values = true)]
    compliance: Option<String>,
    /// Gravity deflection: link masses in kg, one value for all or one per joint (link j is
    /// moved by joint j, its mass at its midpoint) [default: 0].
    #[arg(long, allow_hyphen_values = true, requires = "compliance")]
    link_masses_kg: Option<String>,
    /// Gravity deflection: payload at the tool point, kg [default: 0].
    #[arg(long, allow_hyphen_values = true, requires = "compliance")]
    payload_kg: Option<f64>,
    /// Gross outliers: fraction of the readings displaced, in [0, 1].
    #[arg(long, allow_hyphen_values = true)]
    outlier_fraction: Option<f64>,
    /// Gross outliers: smallest displacement, mm [default: 2].
    #[arg(long, allow_hyphen_values = true, requires = "outlier_fraction")]
    outlier_min_mm: Option<f64>,
    /// Gross outliers: largest displacement, mm [default: 5].
    #[arg(long, allow_hyphen_values = true, requires = "outlier_fraction")]
    outlier_max_mm: Option<f64>,
    /// Measure every reflector of the robot file's `tools` at each pose: one row per target,
    /// with a `target` column (1..k). The plane points use target 1.
    #[arg(long, conflicts_with = "outlier_fraction")]
    all_targets: bool,
    /// 6-DoF measurements: write each measured frame's orientation (`a,b,c`, deg, in the tracker
    /// frame) beside x,y,z, with this 1-sigma noise per axis (deg, e.g. 0.001).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "outlier_fraction")]
    orientation_sigma_deg: Option<f64>,
    /// The robot's repeatability: a random error per joint and per move, 1-sigma in degrees (mm
    /// for a prismatic joint), one value for all joints or one per joint; `default`: the class
    /// default (each joint's error turns the tool by 0.01 mm at the arm's reach). Repeated poses
    /// (e.g. an ISO 9283 plan given to --joints) then scatter as on a real robot.
    #[arg(long, allow_hyphen_values = true, value_name = "V|V1,..,Vn|default")]
    repeatability_deg: Option<String>,
    /// Backlash: half the gear play of each joint (deg; mm for a prismatic joint), one value for
    /// all joints or one per joint, or `auto` for the robot class's default (about half an arc
    /// minute on a heavy arm). Each joint stops short on the side it came from, the poses
    /// visited in row order from home; writes `dir1..dirN`.
    #[arg(long, allow_hyphen_values = true)]
    backlash_deg: Option<String>,
    /// Thermal growth: `auto` warms the arm up over the session with the robot class's default
    /// (a KR 480: 15 K with a one-hour time constant, 20 s per pose, steel); its links and base
    /// column grow with the temperature; writes `temperature_c` and `time_s`.
    #[arg(long, value_parser = ["auto", "none"])]
    thermal: Option<String>,
    /// Thermal growth: the rise at steady work (K) [default: the class's].
    #[arg(long, allow_hyphen_values = true, requires = "thermal")]
    thermal_rise_c: Option<f64>,
    /// Thermal growth: where on the warm-up curve the session starts (s since the arm started
    /// working; 0 starts cold) [default: 0].
    #[arg(long, allow_hyphen_values = true, requires = "thermal")]
    thermal_start_s: Option<f64>,
    /// Thermal growth: seconds between two measured poses [default: the class's].
    #[arg(long, allow_hyphen_values = true, requires = "thermal")]
    seconds_per_pose: Option<f64>,
    /// Thermal growth: how much each link warms relative to the measured temperature, one
    /// value for all links or one per link (e.g. `0.6,1.5,1.3,0.8,0,1.1`: an arm warming
    /// unevenly, for `calibrate --thermal per-link`) [default: 1, evenly].
    #[arg(
        long,
        value_name = "G|G1,..",
        allow_hyphen_values = true,
        requires = "thermal"
    )]
    thermal_link_gain: Option<String>,
    /// Measure from a fresh tracker set-up: station K (1, 2, ..) is the tracker carried
    /// elsewhere around the robot (turned 15 to 45 degrees about the base axis) and set up
    /// again; evaluate such data with --refit-frame [default: 0, the --tracker pose].
    #[arg(long, default_value_t = 0)]
    station: u32,
    /// Constraint data instead of tracker readings: the tool point brought to fixed points,
    /// onto spheres or onto planes from varied orientations (a `constraint` column, no x,y,z);
    /// --noise-mm is then the contact's noise (probe and repeatability).
    #[arg(long, value_name = "point|sphere|plane", group = "constraint_mode", conflicts_with_all = ["poses", "joints", "validation"])]
    constraint: Option<String>,
    /// With --constraint: how many points, spheres or planes.
    #[arg(long, default_value_t = 4, requires = "constraint")]
    features: usize,
    /// With --constraint: configurations per point, sphere or plane.
    #[arg(long, default_value_t = 20, requires = "constraint")]
    per_feature: usize,
    /// With --constraint sphere: the spheres' radius (mm).
    #[arg(long, default_value_t = 25.0, requires = "constraint")]
    radius_mm: f64,
    /// With --constraint sphere: leave radius_mm empty (the radius is estimated).
    #[arg(long, requires = "constraint")]
    unknown_radius: bool,
    /// With --constraint: largest tilt of the tool from a feature's reference orientation (deg).
    #[arg(long, default_value_t = 60.0, requires = "constraint")]
    tilt_deg: f64,
    /// With --constraint: a plane's touched square's half-size, a sphere's contact region (mm).
    #[arg(long, default_value_t = 300.0, requires = "constraint")]
    span_mm: f64,
    /// With --constraint point|sphere: write the true distances between every pair of points
    /// or centres to this CSV (from,to,distance_mm), for calibrate --distances.
    #[arg(long, requires = "constraint_mode")]
    distances_out: Option<PathBuf>,
    /// Measure a constraint plan (`plan --constraint` or `--features-file`'s file) instead: the
    /// true robot moved from each planned configuration until its tool is where the nominal's
    /// was (the planned contact), with --noise-mm; the features are where the plan put them.
    #[arg(long, value_name = "FILE", group = "constraint_mode", conflicts_with_all = ["poses", "joints", "validation", "constraint"])]
    constraint_plan: Option<PathBuf>,
}

/// A list of numbers `V` or `V1,..,Vn` (the library spreads one value to every joint and
/// checks the count).
fn numbers(name: &str, s: &str) -> anyhow::Result<Vec<f64>> {
    s.split(',')
        .enumerate()
        .map(|(i, part)| {
            let part = part.trim();
            part.parse::<f64>().map_err(|_| {
                exit::usage(format!("{name}: value {} `{part}` is not a number", i + 1))
            })
        })
        .collect()
}

/// `auto` (or `word`): the robot class's default; else numbers.
fn per_joint(name: &str, s: &str, word: &str) -> anyhow::Result<PerJoint> {
    if s == word {
        return Ok(PerJoint::ClassDefault);
    }
    Ok(PerJoint::Values(numbers(name, s)?))
}

pub(crate) fn tracker_arg(s: &str) -> anyhow::Result<FrameVec> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| exit::usage(format!("--tracker: `{s}` is not a list of numbers")))?;
    let [x, y, z, a, b, c] = v[..] else {
        return Err(exit::usage(format!(
            "--tracker: expected 6 values x,y,z,A,B,C (mm, deg), got {}",
            v.len()
        )));
    };
    Ok(FrameVec { x, y, z, a, b, c })
}

/// The flags as the library's settings, parsed but not checked ([`SimulationBuilder::build`]
/// checks them).
fn builder(a: &SimulateArgs) -> anyhow::Result<SimulationBuilder> {
    let list = |name: &str, v: &Option<String>| v.as_deref().map(|s| numbers(name, s)).transpose();
    Ok(SimulationBuilder {
        seed: a.seed,
        poses: a.poses,
        validation_poses: a.validation,
        joints_given: a.joints.is_some(),
        plane_points: !a.no_plane,
        plane_z_mm: a.plane_z_mm,
        tracker_frame: a.tracker.as_deref().map(tracker_arg).transpose()?,
        noise_mm: a.noise_mm,
        noise_per_m: a.noise_per_m,
        length_sigma_mm: a.length_error_mm,
        angle_sigma_deg: a.angle_error_deg,
        tilt_parallel_axes: a.tilt_parallel_axes,
        floor_z_mm: a.floor_mm,
        footprint_radius_mm: a.footprint_mm,
        compliance_rad_per_nm: list("--compliance", &a.compliance)?,
        link_masses_kg: list("--link-masses-kg", &a.link_masses_kg)?,
        payload_kg: a.payload_kg,
        outlier_fraction: a.outlier_fraction,
        outlier_min_mm: a.outlier_min_mm,
        outlier_max_mm: a.outlier_max_mm,
        all_targets: a.all_targets,
        orientation_sigma_deg: a.orientation_sigma_deg,
        repeatability: a
            .repeatability_deg
            .as_deref()
            .map(|s| per_joint("--repeatability-deg", s, "default"))
            .transpose()?,
        backlash: a
            .backlash_deg
            .as_deref()
            .map(|s| per_joint("--backlash-deg", s, "auto"))
            .transpose()?,
        thermal: a.thermal.as_deref() == Some("auto"),
        thermal_rise_c: a.thermal_rise_c,
        thermal_start_s: a.thermal_start_s,
        seconds_per_pose: a.seconds_per_pose,
        thermal_link_gain: a
            .thermal_link_gain
            .as_deref()
            .map(|s| numbers("--thermal-link-gain", s))
            .transpose()?,
        station: a.station,
    })
}

/// `FILE.truth.json` beside `FILE.csv`.
fn truth_path(out: &Path) -> PathBuf {
    out.with_extension("truth.json")
}

/// Everything `simulate` needs, checked completely before any work: counts, flag combinations,
/// the files plan, the robots and every setting of the simulation (ranges, per-joint lists). The
/// command body only reads it.
struct Settings {
    nominal: Robot,
    truth: TruthSpec,
    cfg: SimulationConfig,
    joints: Option<PathBuf>,
    out: PathBuf,
    truth_out: PathBuf,
    validation_out: Option<PathBuf>,
    targets: TargetMeasurement,
}

impl TryFrom<&SimulateArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &SimulateArgs) -> anyhow::Result<Settings> {
        if a.validation_out.is_some() && a.validation == 0 {
            return Err(exit::usage(
                "--validation-out needs --validation N (N >= 1)",
            ));
        }
        let truth_out = truth_path(&a.out);
        let builder = builder(a)?;
        let mut plan = IoPlan::new();
        plan.robot("--robot", &a.robot);
        if a.truth != "random" {
            plan.robot("--truth", &a.truth);
        }
        plan.input_opt("--joints", a.joints.as_deref())
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
        if let Some(v) = &a.validation_out {
            plan.output(
                "--validation-out",
                v,
                "the truth file records which file holds each set",
            );
        }
        plan.check()?;
        let nominal = common::robot(&a.robot)?;
        let truth = TruthSource::from_arg(&a.truth, &nominal)
            .with_context(|| format!("--truth {}", a.truth))?;
        let SimulationSettings {
            truth,
            config: cfg,
            targets,
        } = builder.build(&nominal, truth)?;
        Ok(Settings {
            nominal,
            truth,
            cfg,
            joints: a.joints.clone(),
            out: a.out.clone(),
            truth_out,
            validation_out: a.validation_out.clone(),
            targets,
        })
    }
}

pub fn run(a: SimulateArgs) -> anyhow::Result<()> {
    if let Some(plan) = &a.constraint_plan {
        return constraints::run_plan(&a, plan);
    }
    if let Some(kind) = &a.constraint {
        return constraints::run(&a, kind);
    }
    let s = Settings::try_from(&a)?;
    let sim = measure(&s)?;
    let truth_file = write_files(&s, &sim)?;
    for w in &sim.warnings {
        errln!("warning: {w}")?;
    }
    print_summary(&s, &truth_file)
}

/// The session: the joints of `--joints` measured, or poses drawn, on the true robot, with a
/// progress bar for large sessions.
fn measure(s: &Settings) -> anyhow::Result<Simulation> {
    let (nominal, truth, cfg) = (&s.nominal, &s.truth, &s.cfg);
    let joints = match &s.joints {
        Some(p) => Some(read_measurements(
            p,
            nominal.joint_space(),
            Positions::Optional,
        )?),
        None => None,
    };
    let rows = match &joints {
        Some(j) => j.rows.len(),
        None => cfg.poses + cfg.validation_poses + if cfg.plane_points { 3 } else { 0 },
    };
    let bar = (rows >= BAR_FROM).then(|| crate::progress::Bar::new("simulating"));
    let observer: &dyn robocal_core::Observer = match &bar {
        Some(b) => b,
        None => &(),
    };
    let mut sim = match joints {
        // The joint file is dropped as soon as it is measured (large files: memory).
        Some(j) => simulate_joints(nominal, truth, cfg, &j, observer)?,
        None => simulate(nominal, truth, cfg, observer)?,
    };
    sim.measure_targets(&s.targets)?;
    if let Some(b) = &bar {
        b.finish();
    }
    Ok(sim)
}

/// Writes `--out` (and `--validation-out`, the validation rows split off) and the truth file
/// beside it, all or none; returns the truth file.
fn write_files(s: &Settings, sim: &Simulation) -> anyhow::Result<TruthFile> {
    let (out, truth_out, validation_out) = (&s.out, &s.truth_out, &s.validation_out);
    // Split the validation rows off if asked; every row's file, in row order, for the truth file.
    let split = validation_out.as_ref().map(|_| {
        (
            sim.select(SET_VALIDATION, false),
            sim.select(SET_VALIDATION, true),
        )
    });
    let (main, val) = match &split {
        Some((m, v)) => (m, Some(v)),
        None => (&sim.measurements, None),
    };
    let m = &sim.measurements;
    let set_col = m.extra_columns.iter().position(|c| c == "set");
    let files: Vec<&Path> = m
        .rows
        .iter()
        .map(|r| {
            let is_val = set_col.is_some_and(|k| r.extra[k] == SET_VALIDATION);
            match (&validation_out, is_val) {
                (Some(v), true) => v.as_path(),
                _ => out.as_path(),
            }
        })
        .collect();
    let truth_file = sim.truth_file(&files);
    let io = |p: &Path, e: std::io::Error| robocal_core::Error::Io {
        path: p.to_owned(),
        source: e,
    };
    let main_csv = measurements_csv(main).map_err(|e| io(out, e))?;
    let json = truth_file.to_json()?;
    let mut writes: Vec<(&Path, Vec<u8>)> = vec![(out.as_path(), main_csv)];
    if let (Some(p), Some(v)) = (&validation_out, val) {
        writes.push((p.as_path(), measurements_csv(v).map_err(|e| io(p, e))?));
    }
    writes.push((truth_out.as_path(), json.into_bytes()));
    let refs: Vec<(&Path, &[u8])> = writes.iter().map(|(p, b)| (*p, b.as_slice())).collect();
    write_all_atomic(&refs)?;

    Ok(truth_file)
}

/// What was written, the truth robot, the tracker and the effects the session simulated.
fn print_summary(s: &Settings, truth_file: &TruthFile) -> anyhow::Result<()> {
    let (cfg, truth_out) = (&s.cfg, &s.truth_out);
    // "wrote cell.csv (3 plane, 75 calibration rows), ..."
    let mut per_file: Vec<(String, Vec<String>)> = Vec::new();
    for (set, info) in &truth_file.sets {
        let item = format!("{} {set}", info.rows);
        match per_file.iter_mut().find(|(f, _)| *f == info.file) {
            Some((_, v)) => v.push(item),
            None => per_file.push((info.file.clone(), vec![item])),
        }
    }
    let listing = per_file
        .iter()
        .map(|(f, v)| format!("{f} ({} rows)", v.join(", ")))
        .collect::<Vec<_>>()
        .join(", ");
    outln!("wrote {listing} and {}", truth_out.display())?;
    let origin = match &truth_file.geometric_errors {
        Some(e) => format!(
            " (random errors: {} mm, {} deg, seed {})",
            e.length_sigma_mm, e.angle_sigma_deg, cfg.seed
        ),
        None => String::new(),
    };
    let t = &cfg.tracker_frame;
    outln!("truth robot: {}{origin}", truth_file.robot.name)?;
    outln!(
        "tracker at x={} y={} z={} mm, A={} B={} C={} deg; noise {} mm + {} mm/m per axis",
        t.x,
        t.y,
        t.z,
        t.a,
        t.b,
        t.c,
        cfg.noise_mm,
        cfg.noise_per_m
    )?;
    if let Some(r) = &cfg.repeatability {
        let v: Vec<String> = r.std_deg.iter().map(|v| format!("{v:.6}")).collect();
        outln!(
            "repeatability: {} deg (mm for a prismatic joint), 1 sigma per joint and move",
            v.join(",")
        )?;
    }
    if let Some(g) = &truth_file.gravity_effect {
        outln!(
            "gravity deflection moved the tool by {:.3} mm on average (max {:.3} mm)",
            g.mean_mm,
            g.max_mm
        )?;
    }
    if !truth_file.outliers.is_empty() {
        outln!(
            "{} outliers injected (lines listed in the truth file)",
            truth_file.outliers.len()
        )?;
    }
    Ok(())
}
