//! `robocal demo`: the paper's whole experiment in simulation, with its tables beside the
//! paper's, a report, and the files of every step.

use super::demo_text::{command_line, para, sh};
use super::io_plan::IoPlan;
use super::paper_tables::{error_table, parameter_table, percent, Column};
use anyhow::Context;
use clap::Args;
use robocal_core::compensation::IkStatus;
use robocal_core::experiment::{
    files, run_experiment, Experiment, ExperimentConfig, PAPER_NOMINAL, PAPER_TRUTH,
};
use robocal_core::io::write_all_atomic;
use robocal_core::registration::InitialFrame;
use robocal_core::ErrorStats;
use robocal_report::{number_list, paper, ReportData, HISTOGRAM_FILE, HTML_FILE};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Seed of the simulation (poses and tracker noise; the verification uses SEED + 1). The same
    /// seed gives the same files.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Directory for the report and the files of every step (created if needed; files of the
    /// same names in it are replaced).
    #[arg(long, default_value = "robocal-report")]
    out: PathBuf,
    /// Today's ideal cell: no backlash, no thermal growth, the verification measured in the
    /// same cell right after the calibration. By default the cell is honest: the KR 480's class
    /// defaults of backlash and thermal growth, the verification measured later, warm, from
    /// another tracker station.
    #[arg(long)]
    ideal: bool,
}

/// Every file the demo writes into its directory.
const OUTPUT_FILES: [&str; 9] = [
    files::CELL,
    files::VALIDATION,
    files::CELL_TRUTH,
    files::DESIRED,
    files::RESULT,
    files::COMMANDED,
    files::VERIFY,
    HTML_FILE,
    HISTOGRAM_FILE,
];

/// Everything `demo` needs, checked before any work: the output directory plan and the
/// experiment's configuration.
struct Settings {
    out: PathBuf,
    experiment: ExperimentConfig,
}

impl TryFrom<&DemoArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &DemoArgs) -> anyhow::Result<Settings> {
        IoPlan::new()
            .output_dir("--out", &a.out, &OUTPUT_FILES)
            .check()?;
        let mut experiment = if a.ideal {
            ExperimentConfig::paper(a.seed)?
        } else {
            ExperimentConfig::honest(a.seed)?
        };
        // Record the files as `robocal calibrate` run by hand on them would.
        let path = |name: &str| a.out.join(name).display().to_string();
        experiment
            .result_settings
            .insert("data".into(), path(files::CELL).into());
        experiment
            .result_settings
            .insert("validate".into(), path(files::VALIDATION).into());
        Ok(Settings {
            out: a.out.clone(),
            experiment,
        })
    }
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    let Settings {
        out,
        experiment: cfg,
    } = Settings::try_from(&a)?;
    let dir = &out;
    let path = |name: &str| dir.join(name);

    let bar = crate::progress::Bar::new("demo");
    let elasto_cfg = elasto_config(&cfg)?;
    let exp = run_experiment(cfg, &bar).context("running the experiment")?;
    let elasto = match elasto_cfg {
        Some(c) => {
            bar.note("the elasto-geometric calibration");
            Some(run_experiment(c, &()).context("running the elasto-geometric calibration")?)
        }
        None => None,
    };
    let families = match (&elasto, exp.config.real_cell) {
        (Some(e), Some(_)) => {
            bar.note("the calibration with the real cell's families");
            let c = e.config.with_real_cell_families()?;
            Some(run_experiment(c, &()).context("running the real cell's calibration")?)
        }
        _ => None,
    };
    bar.note("writing the report");
    let report = ReportData::from_experiment(&exp, &dir.display().to_string())?;
    let rendered = robocal_report::render(&report)?;
    std::fs::create_dir_all(dir).map_err(|e| robocal_core::Error::Io {
        path: dir.clone(),
        source: e,
    })?;
    let mut writes: Vec<(PathBuf, &[u8])> = exp
        .files()
        .iter()
        .map(|(name, bytes)| (path(name), bytes.as_slice()))
        .collect();
    writes.push((path(HTML_FILE), rendered.html.as_bytes()));
    writes.push((path(HISTOGRAM_FILE), rendered.histogram_svg.as_bytes()));
    let refs: Vec<(&Path, &[u8])> = writes.iter().map(|(p, b)| (p.as_path(), *b)).collect();
    write_all_atomic(&refs)?;
    bar.finish();

    print_run(&exp)?;
    print_model_choice(&exp)?;
    if let Some(e) = &elasto {
        print_elasto(&exp, e, families.as_ref(), dir)?;
    }
    print_files(&exp, dir)?;
    outln!()?;
    super::iso9283::demo_table(&exp)?;
    outln!("report: {}", path(HTML_FILE).display())?;
    Ok(())
}

/// What the experiment did, step by step, beside the paper's tables.
fn print_run(exp: &Experiment) -> anyhow::Result<()> {
    print_setup(exp)?;
    print_before(exp)?;
    print_identification(exp)?;
    print_verification(exp)
}

/// The cell: the nominal and the true robot (with its sag), the tracker and the points.
fn print_setup(exp: &Experiment) -> anyhow::Result<()> {
    let cfg = &exp.config;
    let s = &cfg.session;
    outln!(
        "robocal demo: the experiment of Samak et al. (2019) on a simulated KUKA KR 480 R3330, seed {}",
        s.seed
    )?;
    outln!(
        "  nominal model  {} (Table I, tool T0 of eq. 7): what the controller believes",
        cfg.nominal.name()
    )?;
    outln!(
        "  true robot     {} (the paper's Table III){}",
        cfg.truth.name(),
        if s.gravity.is_some() {
            ", sagging under gravity:"
        } else {
            ""
        }
    )?;
    if let Some(g) = &s.gravity {
        outln!(
            "                 joint compliances {} rad/(N m),",
            number_list(&g.compliance_rad_per_nm, ",")
        )?;
        outln!(
            "                 link masses {} kg, payload {} kg{}",
            number_list(&g.link_masses_kg, ","),
            g.payload_kg,
            if exp.session.deflection_mm.is_some() {
                ":"
            } else {
                ""
            }
        )?;
        if let Some(d) = &exp.session.deflection_mm {
            let st = ErrorStats::from_norms(d);
            outln!(
                "                 the tool sags {:.3} mm on average, {:.3} mm at most",
                st.mean_mm,
                st.max_mm
            )?;
        }
    }
    let t = &s.tracker_frame;
    outln!(
        "  laser tracker  at x {} y {} z {} mm, A {} B {} C {} deg;",
        t.x,
        t.y,
        t.z,
        t.a,
        t.b,
        t.c
    )?;
    outln!(
        "                 noise {:.3} mm + {:.3} mm/m per axis (1 sigma)",
        s.noise_mm,
        s.noise_per_m
    )?;
    outln!(
        "  points         {} plane + {} calibration + {} validation",
        if s.plane_points { 3 } else { 0 },
        s.poses,
        s.validation_poses
    )?;
    super::demo_real_cell::print_cell(exp)?;
    Ok(())
}

/// The measurement frame and Table II beside the paper's.
fn print_before(exp: &Experiment) -> anyhow::Result<()> {
    let cal = &exp.calibration;
    outln!()?;
    match cal.registration.initial {
        InitialFrame::Plane { n, tilt_deg, .. } => para(&format!(
            "Measurement frame: initial from the {n} plane points (plane tilt {tilt_deg:.3} deg), \
             then fitted to the {} calibration points (sum of norms, eq. 11).",
            cal.calibration.before.len()
        )),
        InitialFrame::LeastSquares => para(&format!(
            "Measurement frame: least-squares fit to the {} calibration points, refined (eq. 11).",
            cal.calibration.before.len()
        )),
    }?;
    outln!()?;
    let e = &exp.result.errors;
    let mut cols = vec![Column {
        label: "Calibration points",
        ours: e.calibration.before,
        paper: paper::table2_calibration(),
    }];
    if let Some(v) = &e.validation {
        cols.push(Column {
            label: "Validation points",
            ours: v.before,
            paper: paper::table2_validation(),
        });
    }
    out!(
        "{}",
        error_table(
            "Table II. Error before calibration (nominal model, fitted measurement frame)",
            &cols
        )
    )?;
    outln!()?;
    Ok(())
}

/// The identification, Table III and Table IV beside the paper's.
fn print_identification(exp: &Experiment) -> anyhow::Result<()> {
    let cal = &exp.calibration;
    let e = &exp.result.errors;
    let id = &cal.identifiability;
    let solver = cal.solver();
    para(&format!(
        "Identification (eq. 4, {}): {} parameters, condition number {:.0}; the solver {} after \
         {} iterations.",
        cal.settings.objective.name(),
        id.identified.len(),
        id.condition_number,
        solver.termination.describe(),
        cal.stages
            .iter()
            .map(|s| s.report.iterations)
            .sum::<usize>()
    ))?;
    outln!()?;
    out!("{}", parameter_table(exp))?;
    outln!()?;
    let mut cols = vec![Column {
        label: "Calibration points",
        ours: e.calibration.after,
        paper: paper::table4_calibration(),
    }];
    if let Some(v) = &e.validation {
        cols.push(Column {
            label: "Validation points",
            ours: v.after,
            paper: paper::table4_validation(),
        });
    }
    out!(
        "{}",
        error_table(
            "Table IV. Error after calibration, predicted (calibrated model, same measurements)",
            &cols
        )
    )?;
    outln!()?;
    Ok(())
}

/// The compensation and Table V: the verification against the prediction, beside the paper's.
fn print_verification(exp: &Experiment) -> anyhow::Result<()> {
    let cfg = &exp.config;
    let n = exp.compensation.len();
    let converged = exp
        .compensation
        .iter()
        .filter(|c| c.report.status == IkStatus::Converged)
        .count();
    let max_change = exp
        .compensation
        .iter()
        .zip(&exp.desired.rows)
        .flat_map(|(c, d)| c.commanded.iter().zip(&d.q).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f64::max)
        .to_degrees();
    para(&format!(
        "Compensation (eq. 12-14): the {n} calibration poses solved on the calibrated model; \
         {converged} of {n} converged, largest joint change {max_change:.4} deg. Verification: \
         the commanded joints measured again in the same cell (new tracker noise, seed {}).",
        cfg.verification_seed
    ))?;
    outln!()?;
    out!(
        "{}",
        error_table(
            "Table V. Error after calibration, measured (compensated calibration poses)",
            &[
                Column {
                    label: "Verification points",
                    ours: exp.verified(),
                    paper: paper::table5_verification(),
                },
                Column {
                    label: "Predicted (Table IV)",
                    ours: exp.predicted(),
                    paper: paper::table4_calibration(),
                },
            ]
        )
    )?;
    let (v, p, b) = (
        exp.verified().mean_mm,
        exp.predicted().mean_mm,
        exp.before().mean_mm,
    );
    para(&format!(
        "Measured {v:.3} mm against {p:.3} mm predicted ({}; the paper: 0.293 against 0.174 mm, \
         {}), {:.1} times below the {b:.3} mm before calibration.",
        percent(v, p),
        percent(0.293, 0.174),
        b / v
    ))?;
    outln!()?;
    Ok(())
}

/// The experiment again on the same measurements (same seeds), calibrated with joint compliance
/// under gravity at the known payload (`calibrate --compliance auto --payload-kg`), when the
/// simulated robot sags.
fn elasto_config(cfg: &ExperimentConfig) -> anyhow::Result<Option<ExperimentConfig>> {
    use robocal_core::model::family::compliance;
    let Some(g) = &cfg.session.gravity else {
        return Ok(None);
    };
    let mut c = cfg.clone();
    let joints = compliance::auto_joints(&c.nominal);
    compliance::enable(&mut c.nominal, &joints, Some(g.payload_kg))?;
    Ok(Some(c))
}

/// The model `robocal calibrate` would choose on the same calibration points by default
/// (`--model auto`, with its default objective), beside the paper's geometric model.
fn print_model_choice(exp: &Experiment) -> anyhow::Result<()> {
    use robocal_core::identification::{
        selection, split_measurements, AutoFamilies, CalibrationData, CalibrationSettings,
    };
    let split = split_measurements(&exp.data)?;
    let sel = selection::select(
        &exp.config.nominal,
        CalibrationData {
            calibration: &split.calibration,
            plane: Some(&split.plane),
            validation: None,
        },
        &CalibrationSettings::default(),
        AutoFamilies::default(),
    )?;
    para(
        "The paper's model is geometric. The model `robocal calibrate` chooses by default on the \
         same calibration points (--model auto, default objective):",
    )?;
    super::calibrate::print_selection(&sel)?;
    outln!()?;
    Ok(())
}

/// The geometric calibration beside the elasto-geometric one, and the verification of both.
fn print_elasto(
    geo: &Experiment,
    el: &Experiment,
    families: Option<&Experiment>,
    dir: &Path,
) -> anyhow::Result<()> {
    if let Some(f) = families {
        return super::demo_real_cell::print_families(geo, el, f, dir);
    }
    let payload = geo
        .config
        .session
        .gravity
        .as_ref()
        .map_or(0.0, |g| g.payload_kg);
    para(&format!(
        "Beyond the paper: the same measurements calibrated with joint compliance under gravity          (the elasto-geometric model: each joint turns by its compliance times the gravity torque          about its axis; coefficients from the chain's geometry, the {payload} kg payload known),          then compensated and verified the same way:"
    ))?;
    let val = |e: &Experiment| {
        e.result
            .errors
            .validation
            .map_or(f64::NAN, |v| v.after.mean_mm)
    };
    outln!("{:<34} {:>12} {:>18}", "", "Geometric", "Elasto-geometric")?;
    for (label, a, b) in [
        ("Validation mean (mm)", val(geo), val(el)),
        (
            "Verification mean (mm)",
            geo.verified().mean_mm,
            el.verified().mean_mm,
        ),
        (
            "Verification max (mm)",
            geo.verified().max_mm,
            el.verified().max_mm,
        ),
    ] {
        outln!("{label:<34} {a:>12.3} {b:>18.3}")?;
    }
    outln!(
        "{:<34} {:>12} {:>18}",
        "Identified parameters",
        geo.calibration.identifiability.identified.len(),
        el.calibration.identifiability.identified.len()
    )?;
    para("By hand, on the files below:")?;
    command_line(&[
        "robocal calibrate".to_owned(),
        format!("--robot {PAPER_NOMINAL}"),
        format!("--data {}", sh(&dir.join(files::CELL))),
        format!("--validate {}", sh(&dir.join(files::VALIDATION))),
        "--compliance auto".to_owned(),
        format!("--payload-kg {payload}"),
        "--model geometric".to_owned(),
        format!("--out {}", sh(&dir.join("result-elasto.json"))),
    ])?;
    outln!()?;
    Ok(())
}

/// The files written, and the commands that write them again by hand.
fn print_files(exp: &Experiment, dir: &Path) -> anyhow::Result<()> {
    print_file_list(exp, dir)?;
    print_commands(exp, dir)
}

/// The files the experiment wrote in `dir`, and what each holds.
fn print_file_list(exp: &Experiment, dir: &Path) -> anyhow::Result<()> {
    outln!("Files in {}:", dir.display())?;
    let n_cal = exp.desired.rows.len();
    for (names, what) in [
        (
            format!("{}, {}", files::CELL, files::VALIDATION),
            "simulated tracker readings (plane + calibration; validation)".to_owned(),
        ),
        (
            files::CELL_TRUTH.to_owned(),
            "the truth: true parameters, tracker pose, settings".to_owned(),
        ),
        (
            files::DESIRED.to_owned(),
            format!("the {n_cal} calibration poses, desired poses of the verification"),
        ),
        (
            files::RESULT.to_owned(),
            "the calibration result".to_owned(),
        ),
        (
            files::COMMANDED.to_owned(),
            "compensated joints (eq. 14), desired positions".to_owned(),
        ),
        (
            files::VERIFY.to_owned(),
            "readings at the compensated joints".to_owned(),
        ),
        (
            format!("{HTML_FILE}, {HISTOGRAM_FILE}"),
            "the report, the histogram (Fig. 2)".to_owned(),
        ),
    ] {
        outln!("  {names:<28} {what}")?;
    }
    Ok(())
}

/// `simulate`'s flags of the session's gravity model (none without one).
fn gravity_flags(s: &robocal_core::simulation::SimulationConfig) -> Vec<String> {
    let mut gravity = Vec::new();
    if let Some(g) = &s.gravity {
        gravity.push(format!(
            "--compliance {}",
            number_list(&g.compliance_rad_per_nm, ",")
        ));
        gravity.push(format!(
            "--link-masses-kg {}",
            number_list(&g.link_masses_kg, ",")
        ));
        gravity.push(format!("--payload-kg {}", g.payload_kg));
    }
    gravity
}

/// The commands that give the same files again, step by step.
fn print_commands(exp: &Experiment, dir: &Path) -> anyhow::Result<()> {
    let cfg = &exp.config;
    let s = &cfg.session;
    let p = |name: &str| sh(&dir.join(name));
    let gravity = gravity_flags(s);
    let robot = format!("--robot {PAPER_NOMINAL}");
    para(
        "Each step by hand, giving the same files again (in the source tree, `cargo run --release \
         --` stands for `robocal`):",
    )?;
    let mut simulate = vec![
        "robocal simulate".to_owned(),
        robot.clone(),
        format!("--truth {PAPER_TRUTH}"),
        format!("--poses {}", s.poses),
        format!("--validation {}", s.validation_poses),
        format!("--seed {}", s.seed),
    ];
    simulate.extend(gravity.iter().cloned());
    simulate.extend(super::demo_real_cell::simulate_flags(exp, false));
    simulate.push(format!("--out {}", p(files::CELL)));
    simulate.push(format!("--validation-out {}", p(files::VALIDATION)));
    command_line(&simulate)?;
    command_line(&[
        "robocal calibrate".to_owned(),
        robot.clone(),
        // The paper's model and objective (eq. 4); calibrate's defaults are the model the
        // data support and the adaptive objective.
        "--model geometric".to_owned(),
        "--objective sum-of-norms".to_owned(),
        format!("--data {}", p(files::CELL)),
        format!("--validate {}", p(files::VALIDATION)),
        format!("--out {}", p(files::RESULT)),
    ])?;
    command_line(&[
        "robocal compensate".to_owned(),
        robot.clone(),
        format!("--params {}", p(files::RESULT)),
        format!("--joints {}", p(files::DESIRED)),
        format!("--out {}", p(files::COMMANDED)),
        "--position-only".to_owned(),
    ])?;
    let mut verify = vec![
        "robocal simulate".to_owned(),
        robot.clone(),
        format!("--truth {}", p(files::CELL_TRUTH)),
        format!("--joints {}", p(files::COMMANDED)),
        format!("--seed {}", cfg.verification_seed),
    ];
    verify.extend(gravity.iter().cloned());
    verify.extend(super::demo_real_cell::simulate_flags(exp, true));
    verify.push(format!("--out {}", p(files::VERIFY)));
    command_line(&verify)?;
    let mut evaluate = vec![
        "robocal evaluate".to_owned(),
        robot,
        format!("--params {}", p(files::RESULT)),
        format!("--data {}", p(files::VERIFY)),
    ];
    if cfg.real_cell.is_some_and(|r| r.verification_station != 0) {
        evaluate.push("--refit-frame".to_owned());
    }
    command_line(&evaluate)?;
    command_line(&[
        "robocal report".to_owned(),
        p(files::RESULT),
        format!("--verify {}", p(files::VERIFY)),
        "--paper".to_owned(),
        format!("--out {}", p("by-hand")),
    ])?;
    Ok(())
}
