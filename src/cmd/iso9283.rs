//! `robocal iso9283`: the ISO 9283 pose accuracy and repeatability test: `plan` writes the test
//! (the cube, P1..P5, the cycles, the joints to command), `evaluate` computes AP, RP, AD, RD and
//! drift from the measured test.

use super::common;
use super::io_plan::IoPlan;
use crate::exit;
use clap::{Args, Subcommand};
use robocal_core::frame::TrackerFrame;
use robocal_core::io::{write_all_atomic, write_atomic};
use robocal_core::iso9283::{
    evaluate, make_plan, plan_csv, plan_program, read_plan, read_test_data, Evaluation,
    PlanSettings, Spec, TrackerMpe, CYCLE_ORDER, DEFAULT_CYCLES, DEFAULT_DWELL_S,
};
use robocal_core::programs::Format;
use std::path::PathBuf;

#[derive(Subcommand, Debug)]
// Each command's arguments are built only when it runs (or for help, completions, man).
#[command(defer = true)]
pub enum Iso9283Cmd {
    /// The test plan: the largest cube (edges parallel to the base axes) the robot reaches at
    /// every test pose with the tool orientation, P1..P5 on its diagonal plane, the cycles P1,
    /// P5, P4, P3, P2; with --params, the compensated joints on the calibrated model.
    Plan(PlanArgs),
    /// AP, RP (position and orientation), AD, RD and drift per pose from the measured test, the
    /// tracker's uncertainty beside RP, pass/fail against --spec.
    Evaluate(EvaluateArgs),
}

#[derive(Args, Debug)]
pub struct PlanArgs {
    /// The nominal robot: a preset, a TOML robot file or a URDF [default: the robot embedded in
    /// --params].
    #[arg(long, required_unless_present = "params")]
    robot: Option<String>,
    /// A calibration result: the plan's joints are then the compensated ones on its calibrated
    /// model (the same commanded poses), for the test after calibration.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Number of cycles (ISO 9283: 30).
    #[arg(long, default_value_t = DEFAULT_CYCLES)]
    cycles: usize,
    /// The cube's edge (mm) [default: the largest that fits].
    #[arg(long, value_name = "L")]
    cube_mm: Option<f64>,
    /// The cube's centre X,Y,Z (mm, base frame) [default: searched].
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    center: Option<String>,
    /// The tool orientation A,B,C (deg, base frame) at every pose [default: the tool's
    /// orientation at the middle of the joint ranges, or the first default seed configuration
    /// away from singularities].
    #[arg(long, value_name = "A,B,C", allow_hyphen_values = true)]
    orientation: Option<String>,
    /// The cube, poses and tool orientation of an earlier plan (the test before calibration):
    /// with --params, the same test with the compensated joints.
    #[arg(long, value_name = "PLAN.csv", conflicts_with_all = ["cube_mm", "center", "orientation"])]
    poses_from: Option<PathBuf>,
    /// The floor (mm, base frame): no point of the cube below it [default: 0, the base plane
    /// the robot is mounted on].
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    floor_mm: f64,
    /// The robot's footprint: the cube keeps this far (mm) from the base z axis [default: 15 %
    /// of the robot's chain length, as simulate's poses; 0 allows a cube above the robot].
    #[arg(long, value_name = "MM")]
    footprint_mm: Option<f64>,
    /// The plan CSV to write (cycle,pose,q1..qn,x_c,y_c,z_c,a_c,b_c,c_c).
    #[arg(long)]
    out: PathBuf,
    /// Also write the plan as a robot program: the cycles' joint motions (the plan's joints as
    /// controller axis values), an exact stop and a dwell at each pose.
    #[arg(long, value_name = "FILE")]
    program: Option<PathBuf>,
    /// The program's language [default: from --program's extension: .src KRL, .mod RAPID,
    /// .script URScript].
    #[arg(long, value_parser = ["krl", "rapid", "urscript"], requires = "program")]
    program_format: Option<String>,
    /// The program's dwell at each pose (s): the robot settles and the tracker measures.
    #[arg(
        long,
        value_name = "S",
        default_value_t = DEFAULT_DWELL_S,
        requires = "program",
        allow_hyphen_values = true
    )]
    dwell_s: f64,
}

/// The program format of `--program-format`, or of the program's extension; a format that
/// contradicts a known extension is refused (the controller reads a file by its extension).
fn program_format(given: Option<&str>, path: &std::path::Path) -> anyhow::Result<Format> {
    let by_ext = Format::from_path(path).ok();
    let format = match given {
        Some("krl") => Format::Krl,
        Some("rapid") => Format::Rapid,
        Some(_) => Format::UrScript,
        None => by_ext.ok_or_else(|| {
            exit::usage(format!(
                "--program {}: give --program-format krl|rapid|urscript (the extension is \
                 none of .src, .mod, .script)",
                path.display()
            ))
        })?,
    };
    match by_ext {
        Some(e) if e != format => Err(exit::usage(format!(
            "--program {}: the extension says {}, --program-format says {}",
            path.display(),
            e.name(),
            format.name()
        ))),
        _ => Ok(format),
    }
}

#[derive(Args, Debug)]
pub struct EvaluateArgs {
    /// The plan CSV (`robocal iso9283 plan --out`).
    #[arg(long)]
    plan: PathBuf,
    /// The measured test: the plan's rows with the attained x,y,z (and a,b,c for 6-DoF data,
    /// time_s for drift), in the tracker frame of --params or in the base frame with --frame base.
    #[arg(long)]
    data: PathBuf,
    /// The calibration result: its tracker frame maps the data to the base frame; its robot
    /// (and calibrated model, for a compensated plan) checks the plan.
    #[arg(long, required_unless_present = "frame", conflicts_with = "frame")]
    params: Option<PathBuf>,
    /// `base`: the data are in the robot's base frame (no tracker frame to apply).
    #[arg(long, value_parser = ["base"])]
    frame: Option<String>,
    /// The nominal robot [default: the robot embedded in --params; required with --frame base].
    #[arg(long)]
    robot: Option<String>,
    /// Acceptance limits, e.g. ap=0.5,rp=0.1 (mm): pass/fail per pose and overall.
    #[arg(long, value_name = "ap=MM,rp=MM")]
    spec: Option<String>,
    /// The tracker's maximum permissible error, MM or MM,MM_PER_M (e.g. 0.015,0.006)
    /// [default: 0.015 mm + 0.006 mm/m].
    #[arg(long, value_name = "MM[,MM_PER_M]")]
    tracker_mpe: Option<String>,
    /// Print the evaluation as JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(c: Iso9283Cmd) -> anyhow::Result<()> {
    match c {
        Iso9283Cmd::Plan(a) => plan(a),
        Iso9283Cmd::Evaluate(a) => evaluate_cmd(a),
    }
}

fn triple(flag: &str, s: &str) -> anyhow::Result<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| exit::usage(format!("{flag}: `{s}` is not a list of numbers")))?;
    match v[..] {
        [a, b, c] if v.iter().all(|x| x.is_finite()) => Ok([a, b, c]),
        _ => Err(exit::usage(format!(
            "{flag}: expected 3 finite values, got `{s}`"
        ))),
    }
}

fn plan(a: PlanArgs) -> anyhow::Result<()> {
    let mut io = IoPlan::new();
    io.robot_opt("--robot", a.robot.as_deref())
        .input_opt("--params", a.params.as_deref())
        .input_opt("--poses-from", a.poses_from.as_deref())
        .output("--out", &a.out, "the plan is a file");
    if let Some(p) = &a.program {
        io.output("--program", p, "the program is a file");
    }
    let format = a
        .program
        .as_deref()
        .map(|p| program_format(a.program_format.as_deref(), p))
        .transpose()?;
    io.check()?;
    let mut settings = plan_settings(&a)?;
    let model = common::model(a.robot.as_deref(), a.params.as_deref())?;
    if let (Some((_, res)), Some(p)) = (&model.calibrated, &a.params) {
        common::warn_not_calibrated(res, p)?;
    }
    let calibrated = model.calibrated.as_ref().map(|c| &c.0);
    if let Some(path) = &a.poses_from {
        let (cube, abc) = read_plan(path, &model.nominal, calibrated)?.cube()?;
        settings.centre_mm = Some(cube.centre.into());
        settings.edge_mm = Some(cube.edge_mm);
        settings.orientation_deg = Some(abc);
    }
    let plan = make_plan(&model.nominal, calibrated, &settings)?;
    let csv = plan_csv(&plan, &model.nominal);
    match (&a.program, format) {
        (Some(path), Some(format)) => {
            let prog = plan_program(&plan, &model.nominal, format, a.dwell_s)?;
            write_all_atomic(&[
                (a.out.as_path(), &csv),
                (path.as_path(), prog.text.as_bytes()),
            ])?;
        }
        _ => write_atomic(&a.out, &csv)?,
    }
    print_plan(&a, &plan, &model.nominal, format)
}

/// The plan's settings from the flags, checked by the library.
fn plan_settings(a: &PlanArgs) -> anyhow::Result<PlanSettings> {
    let settings = PlanSettings {
        cycles: a.cycles,
        edge_mm: a.cube_mm,
        centre_mm: a
            .center
            .as_deref()
            .map(|s| triple("--center", s))
            .transpose()?,
        orientation_deg: a
            .orientation
            .as_deref()
            .map(|s| triple("--orientation", s))
            .transpose()?,
        floor_z_mm: a.floor_mm,
        footprint_radius_mm: a.footprint_mm,
        ..PlanSettings::default()
    };
    settings.validate()?;
    Ok(settings)
}

/// The cube, the tool orientation, the five poses with their joints, and the files written.
fn print_plan(
    a: &PlanArgs,
    plan: &robocal_core::iso9283::Plan,
    robot: &robocal_core::Robot,
    format: Option<Format>,
) -> anyhow::Result<()> {
    let c = plan.cube.centre;
    outln!(
        "cube: edge {:.1} mm, centre ({:.1}, {:.1}, {:.1}) mm (base frame){}",
        plan.cube.edge_mm,
        c.x,
        c.y,
        c.z,
        if let Some(p) = &a.poses_from {
            format!(", as {}", p.display())
        } else if a.cube_mm.is_none() {
            ", the largest that fits".to_owned()
        } else {
            String::new()
        }
    )?;
    let o = plan.pose_vector_deg(1);
    outln!(
        "tool orientation A={:.3} B={:.3} C={:.3} deg; measuring plane through the cube's \
         corners (-,-,-), (+,-,-), (+,+,+), (-,+,+)",
        o[3],
        o[4],
        o[5]
    )?;
    let names: Vec<String> = (1..=robot.dof()).map(|i| format!("q{i}")).collect();
    outln!(
        "{:<5}{:>11}{:>11}{:>11}  joints{} (deg)",
        "pose",
        "x (mm)",
        "y (mm)",
        "z (mm)",
        if plan.compensated { " compensated" } else { "" }
    )?;
    for k in 1..=5 {
        let v = plan.pose_vector_deg(k);
        let q: Vec<String> = robot
            .joints_to_display(&plan.joints[k - 1])
            .iter()
            .zip(&names)
            .map(|(v, n)| format!("{n}={v:.4}"))
            .collect();
        outln!(
            "P{k:<4}{:>11.3}{:>11.3}{:>11.3}  {}",
            v[0],
            v[1],
            v[2],
            q.join(" ")
        )?;
    }
    let order: Vec<String> = CYCLE_ORDER.iter().map(|p| format!("P{p}")).collect();
    outln!(
        "wrote {} ({} rows: {} cycles of {})",
        a.out.display(),
        5 * plan.cycles,
        plan.cycles,
        order.join(", ")
    )?;
    if let (Some(path), Some(format)) = (&a.program, format) {
        outln!(
            "wrote {} ({} program: the same cycles as joint motions, {} s dwell at each pose)",
            path.display(),
            format.name(),
            a.dwell_s
        )?;
    }
    Ok(())
}

fn evaluate_cmd(a: EvaluateArgs) -> anyhow::Result<()> {
    let mut io = IoPlan::new();
    io.robot_opt("--robot", a.robot.as_deref())
        .input_opt("--params", a.params.as_deref())
        .input("--plan", &a.plan)
        .input("--data", &a.data);
    io.check()?;
    let spec = a.spec.as_deref().map(Spec::parse).transpose()?;
    let tracker = match a.tracker_mpe.as_deref() {
        Some(s) => TrackerMpe::parse(s)?,
        None => TrackerMpe::default(),
    };
    if a.params.is_none() && a.robot.is_none() {
        return Err(exit::usage("--frame base needs --robot NAME|FILE"));
    }
    let model = common::model(a.robot.as_deref(), a.params.as_deref())?;
    let frame = match &model.calibrated {
        Some((_, res)) => res.tracker_frame.to_tracker_frame(),
        None => TrackerFrame::identity(),
    };
    let calibrated = model.calibrated.as_ref().map(|c| &c.0);
    let plan = read_plan(&a.plan, &model.nominal, calibrated)?;
    let poses = read_test_data(&a.data, &plan, &model.nominal, &frame)?;
    let ev = evaluate(&poses, &tracker, &frame.origin(), spec.as_ref())?;
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&ev)?)?;
    } else {
        print_table(&ev, a.params.is_some())?;
    }
    if ev.pass == Some(false) {
        let failed: Vec<String> = ev
            .poses
            .iter()
            .filter(|p| p.pass == Some(false))
            .map(|p| format!("P{}", p.pose))
            .collect();
        return Err(exit::rejected(format!(
            "the test fails the spec {} at {}",
            a.spec.as_deref().unwrap_or_default(),
            failed.join(", ")
        )));
    }
    Ok(())
}

/// Prints the evaluation as tables.
fn print_table(ev: &Evaluation, tracker_frame: bool) -> anyhow::Result<()> {
    let orient = ev.poses.iter().any(|p| p.orientation.is_some());
    let drift = ev.poses.iter().any(|p| p.drift.is_some());
    out!(
        "{:<5}{:>4}{:>10}{:>10}{:>10}{:>10}{:>10}{:>11}",
        "pose",
        "n",
        "AP (mm)",
        "AP_x",
        "AP_y",
        "AP_z",
        "RP (mm)",
        "MPE (mm)"
    )?;
    if orient {
        out!("{:>10}{:>10}", "AP_ang(°)", "RP_max(°)")?;
    }
    if drift {
        out!("{:>10}{:>10}", "dAP (mm)", "dRP (mm)")?;
    }
    outln!("{}", if ev.spec.is_some() { "  result" } else { "" })?;
    for p in &ev.poses {
        out!(
            "P{:<4}{:>4}{:>10.4}{:>10.4}{:>10.4}{:>10.4}{:>10.4}{:>11.4}",
            p.pose,
            p.n,
            p.ap_mm,
            p.ap_x_mm,
            p.ap_y_mm,
            p.ap_z_mm,
            p.rp_mm,
            p.tracker_mpe_mm
        )?;
        if orient {
            match &p.orientation {
                Some(o) => out!(
                    "{:>10.5}{:>10.5}",
                    o.ap_angle_deg,
                    o.rp_a_deg.max(o.rp_b_deg).max(o.rp_c_deg)
                )?,
                None => out!("{:>20}", "")?,
            }
        }
        if drift {
            match &p.drift {
                Some(d) => out!("{:>10.4}{:>10.4}", d.dap_mm, d.drp_mm)?,
                None => out!("{:>20}", "")?,
            }
        }
        let mark = if p.rp_below_tracker { " *" } else { "" };
        match p.pass {
            Some(true) => outln!("  pass{mark}")?,
            Some(false) => outln!("  FAIL{mark}")?,
            None => outln!("{mark}")?,
        }
    }
    let d = &ev.distance;
    outln!(
        "distance P{}-P{}: commanded {:.3} mm, AD {:.4} mm, RD {:.4} mm",
        d.from,
        d.to,
        d.commanded_mm,
        d.ad_mm,
        d.rd_mm
    )?;
    let t = &ev.tracker;
    outln!(
        "tracker MPE {} mm + {} mm/m at the {}; RP below it is marked * (not resolved by the \
         instrument)",
        t.mpe_mm,
        t.per_m_mm,
        if tracker_frame {
            "tracker's distance from each pose"
        } else {
            "distance from the base origin (--frame base)"
        }
    )?;
    if ev.poses.iter().any(|p| p.rp_below_tracker) {
        outln!("* RP below the tracker's MPE: an upper bound set by the instrument")?;
    }
    if let (Some(s), Some(pass)) = (&ev.spec, ev.pass) {
        let lim = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v} mm"));
        outln!(
            "spec AP <= {}, RP <= {}: {}",
            lim(s.ap_mm),
            lim(s.rp_mm),
            if pass { "PASS" } else { "FAIL" }
        )?;
    }
    Ok(())
}

/// The ISO 9283 tests of `report --iso9283 PLAN.csv,DATA.csv` (repeatable): each evaluated with
/// the result's tracker frame, its plan checked against the result's robot (a compensated plan
/// against the calibrated model).
pub(super) fn report_tests(
    args: &[String],
    nominal: &robocal_core::Robot,
    calibrated: &robocal_core::Robot,
    result: &robocal_core::io::CalibrationResult,
) -> anyhow::Result<Vec<robocal_report::IsoTest>> {
    let frame = result.tracker_frame.to_tracker_frame();
    let mut out = Vec::new();
    for arg in args {
        let Some((plan, data)) = arg.split_once(',') else {
            return Err(exit::usage(format!(
                "--iso9283 {arg}: expected PLAN.csv,DATA.csv"
            )));
        };
        let (plan, data) = (PathBuf::from(plan), PathBuf::from(data));
        let mut io = IoPlan::new();
        io.input("--iso9283", &plan).input("--iso9283", &data);
        io.check()?;
        let p = read_plan(&plan, nominal, Some(calibrated))?;
        let compensated = p.rows.first().is_some_and(|r| {
            let c = p.poses[r.pose - 1].translation.vector;
            (nominal.tool_position(&r.q) - c).norm() > robocal_core::iso9283::PLAN_TOLERANCE_MM
        });
        let poses = read_test_data(&data, &p, nominal, &frame)?;
        let ev = evaluate(&poses, &TrackerMpe::default(), &frame.origin(), None)?;
        let label = format!(
            "{} ({} joints, plan {})",
            robocal_report::file_name(&data),
            if compensated {
                "compensated"
            } else {
                "nominal"
            },
            robocal_report::file_name(&plan)
        );
        out.push(robocal_report::IsoTest::from_evaluation(label, &ev));
    }
    Ok(out)
}

/// The demo's last table: the ISO 9283 test (30 cycles, the largest cube) of the experiment's
/// robot before calibration (nominal joints) and after (compensated joints), run in the
/// experiment's cell with the class-default repeatability and evaluated in the calibration's
/// tracker frame.
pub(super) fn demo_table(exp: &robocal_core::experiment::Experiment) -> anyhow::Result<()> {
    use robocal_core::iso9283::simulate_test;
    use robocal_core::simulation::{RepeatabilityModel, TruthSpec};
    let nominal = exp.session.cell.nominal();
    let truth = TruthSpec::Robot(exp.session.cell.truth().clone());
    let mut cfg = exp.config.verification_session();
    // Measured from the calibration's tracker set-up: its fitted frame maps the points to the
    // base frame (a verification from another station would need registering again).
    cfg.station = 0;
    let repeat = RepeatabilityModel::default_for(nominal);
    cfg.repeatability = Some(repeat.clone());
    let frame = exp.result.tracker_frame.to_tracker_frame();
    let before = make_plan(nominal, None, &PlanSettings::default())?;
    // After calibration the same cube and poses (as `plan --poses-from`), compensated.
    let v = before.pose_vector_deg(1);
    let same = PlanSettings {
        centre_mm: Some(before.cube.centre.into()),
        edge_mm: Some(before.cube.edge_mm),
        orientation_deg: Some([v[3], v[4], v[5]]),
        ..PlanSettings::default()
    };
    let after = make_plan(nominal, Some(&exp.calibrated), &same)?;
    let mut figures = Vec::new();
    for (label, plan) in [
        ("before calibration (nominal joints)", before),
        ("after calibration (compensated joints)", after),
    ] {
        let ev = simulate_test(
            nominal,
            &truth,
            &cfg,
            &plan,
            &frame,
            &TrackerMpe::default(),
            &(),
        )?;
        if figures.is_empty() {
            let c = plan.cube.centre;
            outln!(
                "ISO 9283 pose accuracy and repeatability ({} cycles, cube of {:.0} mm centred \
                 at {:.0}, {:.0}, {:.0} mm; repeatability {:.5} deg per joint and move):",
                plan.cycles,
                plan.cube.edge_mm,
                c.x,
                c.y,
                c.z,
                repeat.std_deg[0]
            )?;
        }
        outln!("{label}:")?;
        print_table(&ev, true)?;
        let worst = |f: fn(&robocal_core::iso9283::PoseResult) -> f64| {
            ev.poses.iter().map(f).fold(0.0, f64::max)
        };
        figures.push((worst(|p| p.ap_mm), worst(|p| p.rp_mm)));
    }
    outln!(
        "AP (worst pose) {:.3} mm before, {:.3} mm after calibration; RP {:.3} mm before, {:.3} \
         mm after",
        figures[0].0,
        figures[1].0,
        figures[0].1,
        figures[1].1
    )?;
    outln!()?;
    Ok(())
}
