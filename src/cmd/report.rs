//! `robocal report`: the HTML report of any calibration result, with the per-point errors of its
//! measurement files when they are at hand.

use super::common;
use super::io_plan::IoPlan;
use crate::exit;
use anyhow::Context;
use clap::Args;
use robocal_core::io::result_sections::Settings as RecordedSettings;
use robocal_core::io::{read_measurements, CalibrationResult, MeasurementSet, Positions};
use robocal_core::JointSpace;
use robocal_report::{write_report, ReportData, RunData, HISTOGRAM_FILE, HTML_FILE};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ReportArgs {
    /// The calibration result (`robocal calibrate --out`).
    #[arg(value_name = "RESULT.json")]
    result: PathBuf,
    /// The nominal robot (preset or TOML file) [default: the robot embedded in the result, or
    /// for older results the `--robot` recorded in it; when given, it must agree with the
    /// embedded one].
    #[arg(long)]
    robot: Option<String>,
    /// The calibration measurements, for each point's error against its reach [default: the
    /// `--data` file recorded in the result, if it is still there].
    #[arg(long, value_name = "CAL.csv")]
    data: Option<PathBuf>,
    /// Validation measurements [default: the `--validate` file recorded in the result, if it is
    /// still there]. Gives the validation statistics if the result has none.
    #[arg(long, value_name = "VAL.csv")]
    validate: Option<PathBuf>,
    /// Measurements of compensated poses (`robocal compensate` output measured again): the
    /// verification, the paper's Table V.
    #[arg(long, value_name = "VERIFY.csv")]
    verify: Option<PathBuf>,
    /// Show the paper's figures (Samak et al. 2019) beside the error tables: only for a result
    /// of the paper's robot (the KUKA KR 480 R3330, preset kuka-kr480-r3330).
    #[arg(long)]
    paper: bool,
    /// Add a table of every point's errors (collapsed until opened; long for large sets).
    #[arg(long)]
    point_table: bool,
    /// An ISO 9283 test to show: its plan and measured data (`robocal iso9283`), in the result's
    /// tracker frame; repeat for several (e.g. before and after calibration).
    #[arg(long, value_name = "PLAN.csv,DATA.csv")]
    iso9283: Vec<String>,
    #[command(flatten)]
    meta: super::report_meta::MetaArgs,
    /// Directory for report.html and histogram.svg (created if needed).
    #[arg(long)]
    out: PathBuf,
}

/// The robot whose figures `--paper` shows.
const PAPER_ROBOT: &str = "kuka-kr480-r3330";

/// A file setting recorded in the result by `robocal calibrate` (`robot_arg`, `data`,
/// `validate`).
fn recorded(
    result: &CalibrationResult,
    key: fn(&RecordedSettings) -> &Option<String>,
) -> Option<&str> {
    result.settings.as_ref().and_then(|s| key(s).as_deref())
}

/// The file given, or the one the result recorded if it still exists (with a note if not).
fn file_arg(
    given: &Option<PathBuf>,
    result: &CalibrationResult,
    key: fn(&RecordedSettings) -> &Option<String>,
    flag: &str,
) -> anyhow::Result<Option<PathBuf>> {
    if let Some(p) = given {
        return Ok(Some(p.clone()));
    }
    let Some(p) = recorded(result, key).map(PathBuf::from) else {
        return Ok(None);
    };
    if p.is_file() {
        Ok(Some(p))
    } else {
        errln!(
            "note: the result names {} as its {flag} file, which is not here; give {flag} FILE \
             to show its points",
            p.display()
        )?;
        Ok(None)
    }
}

fn read(
    path: &Option<PathBuf>,
    joints: &JointSpace,
    flag: &str,
) -> anyhow::Result<Option<MeasurementSet>> {
    let Some(p) = path else {
        return Ok(None);
    };
    let set = read_measurements(p, joints, Positions::Required)
        .with_context(|| format!("{flag} {}", p.display()))?;
    for w in &set.warnings {
        errln!("warning: {w}")?;
    }
    Ok(Some(set))
}

/// Everything `report` needs, checked before any work: the files plan, the robot (given or
/// recorded in the result), the models and the measurement files to show.
struct Settings {
    result_path: PathBuf,
    result: CalibrationResult,
    nominal: robocal_core::Robot,
    calibrated: robocal_core::Robot,
    /// The calibration data: given, or recorded in the result and still there.
    data: Option<PathBuf>,
    /// The validation data: given, or recorded in the result and still there.
    validate: Option<PathBuf>,
    verify: Option<PathBuf>,
    paper: bool,
    point_table: bool,
    /// What identifies the calibration (serial, tracker, operator...).
    metadata: Vec<robocal_report::Setting>,
    out: PathBuf,
}

impl TryFrom<&ReportArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &ReportArgs) -> anyhow::Result<Settings> {
        let mut plan = IoPlan::new();
        plan.input("RESULT", &a.result)
            .recorded_in("RESULT", &a.result)
            .input_opt("--data", a.data.as_deref())
            .input_opt("--validate", a.validate.as_deref())
            .input_opt("--verify", a.verify.as_deref())
            .input_opt("--meta", a.meta.meta.as_deref())
            .output_dir("--out", &a.out, &[HTML_FILE, HISTOGRAM_FILE]);
        if let Some(r) = &a.robot {
            plan.robot("--robot", r);
        }
        plan.check()?;
        let metadata = super::report_meta::metadata(&a.meta)?;
        let result = CalibrationResult::read(&a.result)?;
        // The robot: --robot, else the one the result embeds, else (older results) the --robot
        // recorded in the result's settings.
        let recorded_robot = if a.robot.is_some() || !result.robot.joints.is_empty() {
            None
        } else {
            match recorded(&result, |s| &s.robot_arg) {
                Some(r) => Some(r.to_owned()),
                None => {
                    return Err(exit::usage(format!(
                        "{} neither embeds nor records its robot: give --robot NAME|FILE",
                        a.result.display()
                    )))
                }
            }
        };
        let robot = a.robot.as_deref().or(recorded_robot.as_deref());
        let (nominal, calibrated, result) = common::nominal_and_result(robot, &a.result, "RESULT")
            .with_context(|| match (&a.robot, &recorded_robot) {
                (None, Some(r)) => {
                    format!(
                        "the robot `{r}` recorded in the result (give --robot to choose another)"
                    )
                }
                (Some(r), _) => format!("--robot {r}"),
                (None, None) => format!("the robot embedded in {}", a.result.display()),
            })?;
        super::common::warn_not_calibrated(&result, &a.result)?;
        if a.paper {
            let paper_robot = common::robot(PAPER_ROBOT)?;
            if let Some(diff) =
                robocal_core::model::description::nominal_difference(&paper_robot, &nominal)
            {
                return Err(exit::usage(format!(
                    "--paper shows the figures of Samak et al. (2019) for their robot (preset \
                     {PAPER_ROBOT}), but {} is a calibration of `{}`, another robot ({diff}): \
                     leave out --paper",
                    a.result.display(),
                    nominal.name()
                )));
            }
        }
        let data_path = file_arg(&a.data, &result, |s| &s.data, "--data")?;
        let val_path = file_arg(&a.validate, &result, |s| &s.validate, "--validate")?;
        Ok(Settings {
            result_path: a.result.clone(),
            result,
            nominal,
            calibrated,
            data: data_path,
            validate: val_path,
            verify: a.verify.clone(),
            paper: a.paper,
            point_table: a.point_table,
            metadata,
            out: a.out.clone(),
        })
    }
}

pub fn run(a: ReportArgs) -> anyhow::Result<()> {
    let Settings {
        result_path,
        result,
        nominal,
        calibrated,
        data: data_path,
        validate: val_path,
        verify,
        paper,
        point_table,
        metadata,
        out,
    } = Settings::try_from(&a)?;
    let joints = nominal.joint_space();
    // The files the calibration recorded must be the ones it read; every set must be of this
    // robot (calibrate's gate: another robot's points, another unit, a mirrored frame).
    for p in [&data_path, &val_path, &verify].into_iter().flatten() {
        if let Some(inputs) = &result.inputs {
            robocal_core::io::inputs::check_unchanged(inputs, p, &result_path)?;
        }
    }
    let section =
        robocal_core::io::result_constraint::ConstraintSection::of(&result, &result_path)?;
    let mut data_path = data_path;
    if let Some(p) = data_path.as_ref() {
        if super::calibrate::is_constraint_file(p, &nominal).unwrap_or(false) {
            errln!(
                "note: {} holds constraint rows, which have no tracker points to plot; the \
                 report shows their residuals from the result (robocal evaluate gives those of \
                 held-out rows)",
                p.display()
            )?;
            data_path = None;
        }
    }
    let data = read(&data_path, joints, "--data")?;
    let validation = read(&val_path, joints, "--validate")?;
    let verification = read(&verify, joints, "--verify")?;
    for set in [&data, &validation, &verification].into_iter().flatten() {
        robocal_core::evaluation::check_data_matches(&calibrated, set)?;
    }
    let mut report = ReportData::from_run(&RunData {
        result: &result,
        nominal: &nominal,
        calibrated: &calibrated,
        calibration: data.as_ref(),
        validation: validation.as_ref(),
        verification: verification.as_ref(),
        with_paper: paper,
    })?;
    // File names only: the report is handed on, the directories of this machine mean nothing
    // to its reader.
    let name = robocal_report::file_name;
    report.subtitle = Some(format!(
        "Result {}{}{}",
        name(&result_path),
        data_path
            .as_ref()
            .map_or(String::new(), |p| format!("; calibration data {}", name(p))),
        verify
            .as_ref()
            .map_or(String::new(), |p| format!("; verification {}", name(p)))
    ));
    report.metadata = metadata;
    report.metadata.push(robocal_report::Setting::new(
        "Report made",
        super::report_meta::now_utc(),
    ));
    report.point_table = point_table;
    report.iso9283 = super::iso9283::report_tests(&a.iso9283, &nominal, &calibrated, &result)?;
    report.settings.insert(
        0,
        robocal_report::Setting::new("Result file", name(&result_path)),
    );
    if let Some(v) = &verify {
        report
            .settings
            .push(robocal_report::Setting::new("Verification data", name(v)));
    }
    if let Some(c) = &section {
        constraint_report(&mut report, c);
    }
    let files = write_report(&out, &report)?;
    print_summary(&report)?;
    outln!(
        "report: {} (histogram: {})",
        files.html.display(),
        files.histogram_svg.display()
    )?;
    Ok(())
}

/// A constraint calibration's report: its error tables are the constraint residuals, and its
/// settings show the frame, the features, the scale and what the data cannot see.
fn constraint_report(
    report: &mut ReportData,
    c: &robocal_core::io::result_constraint::ConstraintSection,
) {
    use robocal_report::Setting;
    for t in &mut report.error_tables {
        if t.title.starts_with("Before") {
            t.title = "Before calibration: constraint residuals, nominal model with the features \
                       fitted to it"
                .into();
        } else if t.title.starts_with("After") {
            t.title =
                "After calibration: constraint residuals, calibrated model and features".into();
        }
        t.caption = Some(
            "Distance of each row's tool point from its fixed point, or from its sphere's or \
             plane's surface (mm)."
                .into(),
        );
        for r in &mut t.rows {
            r.label = r.label.replace("points", "rows");
        }
    }
    let s = &mut report.settings;
    s.push(Setting::new(
        "Data",
        format!(
            "constraint rows (no tracker): {} row(s) on {} feature(s), {} known distance(s){}",
            c.rows,
            c.features.len(),
            c.known_distances.len(),
            if c.tracker_rows > 0 {
                format!(", with {} tracker row(s)", c.tracker_rows)
            } else {
                String::new()
            }
        ),
    ));
    s.push(Setting::new("Frame", &c.frame));
    s.push(Setting::new(
        "Scale",
        match (&c.scale.from, &c.scale.held) {
            (Some(from), _) => format!("from {from}"),
            (None, Some(held)) => format!(
                "NOT determined by the data: {held} held at its nominal value (accepted \
                 explicitly)"
            ),
            (None, None) => "not recorded".into(),
        },
    ));
    for f in &c.features {
        let [x, y, z] = f.position_mm;
        s.push(Setting::new(
            format!("Feature {}", f.label()),
            format!(
                "({x:.3}, {y:.3}, {z:.3}) mm{}{}; {} row(s), residual RMS {:.4} mm",
                f.radius_mm.map_or(String::new(), |r| format!(
                    ", radius {r:.3} mm{}",
                    if f.radius_given { " (given)" } else { "" }
                )),
                f.normal.map_or(String::new(), |[a, b, c]| format!(
                    ", normal ({a:.5}, {b:.5}, {c:.5})"
                )),
                f.rows,
                f.residual_rms_mm
            ),
        ));
    }
    for d in &c.known_distances {
        s.push(Setting::new(
            format!("Distance {}-{}", d.from, d.to),
            format!(
                "{:.4} mm given, fitted {:+.4} mm",
                d.distance_mm, d.residual_mm
            ),
        ));
    }
    for u in &c.unseen {
        s.push(Setting::new("Not identifiable", u));
    }
}

fn print_summary(report: &ReportData) -> anyhow::Result<()> {
    for t in &report.error_tables {
        let rows: Vec<String> = t
            .rows
            .iter()
            .map(|r| {
                format!(
                    "{} mean {:.3} mm (n = {})",
                    r.label.to_lowercase(),
                    r.stats.mean_mm,
                    r.stats.n
                )
            })
            .collect();
        outln!("{}: {}", t.title, rows.join(", "))?;
    }
    let shown: usize = report
        .point_sets
        .iter()
        .map(|s| s.points.iter().filter(|p| p.reach_mm.is_finite()).count())
        .sum();
    if shown == 0 {
        outln!("no measurement file: the report has no error-against-reach plot")?;
    }
    Ok(())
}
