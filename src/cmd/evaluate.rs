//! `robocal evaluate`: error statistics of a measured data set under the nominal and the
//! calibrated model (validation, paper section IV), or of measured commanded poses against their
//! desired positions (verification, section V.B, Table V).

mod conditions;
mod constraints;
mod gap;

use super::common;
use super::io_plan::{self, IoPlan};
use anyhow::Context;
use clap::{Args, ValueEnum};
use robocal_core::evaluation::gap::Repeatability;
use robocal_core::evaluation::{Against, Evaluator, PerPointWriter, Reference};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::measurements::read_measurements;
use robocal_core::io::{
    CalibrationResult, Measurement, MeasurementReader, MeasurementSet, Positions,
};
use robocal_core::simulation::RepeatabilityModel;
use robocal_core::{ErrorStats, Robot};

use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct EvaluateArgs {
    /// The nominal robot: a preset name, a TOML robot file or a URDF [default: the robot embedded in
    /// the result; when given, it must agree with that one].
    #[arg(long)]
    robot: Option<String>,
    /// The calibration result (`robocal calibrate --out`): calibrated model and tracker frame.
    #[arg(long)]
    params: PathBuf,
    /// Measured data: q1..qn (degrees, mm for a prismatic joint) or axis1..axisN, x,y,z (mm,
    /// tracker frame), other columns carried.
    #[arg(long)]
    data: PathBuf,
    /// What the measured points are compared with. `auto`: the desired positions when the data
    /// carry the columns `compensate` writes (x_desired,y_desired,z_desired or q1_desired..),
    /// else the models.
    #[arg(long, value_enum, default_value_t = AgainstArg::Auto)]
    against: AgainstArg,
    /// Write per-point errors (dx, dy, dz, norm per series, mm, base frame) to this CSV. `-`:
    /// standard output (written when complete; the table then goes to standard error).
    #[arg(long, value_name = "OUT.csv")]
    per_point: Option<PathBuf>,
    /// Print the statistics as JSON.
    #[arg(long)]
    json: bool,
    /// The robot's joint limits are only nominal: joint values outside them are a warning
    /// listing the lines instead of an error (exit code 3).
    #[arg(long)]
    nominal_limits: bool,
    /// The payload (kg) the robot carried when these data were measured, for a calibration whose
    /// joint compliances were identified at a known payload (`calibrate --payload-kg`)
    /// [default: the calibration's payload].
    #[arg(long, value_name = "KG")]
    payload_kg: Option<f64>,
    /// The data were measured from another tracker station (the tracker moved after the
    /// calibration): fit a fresh rigid tracker frame to them under the calibrated model (and one
    /// under the nominal model for its series) instead of using the calibration's frame.
    /// Without it, data that clearly come from another station are refused (exit code 3).
    #[arg(long)]
    refit_frame: bool,
    /// The robot's pose repeatability (mm, ISO 9283 RP) for the verification's gap split
    /// [default: the class default of the robot's reach].
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    repeatability_mm: Option<f64>,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum AgainstArg {
    /// Desired positions if the data carry them, else the models.
    Auto,
    /// The nominal and calibrated models at the measured joints (validation).
    Model,
    /// The desired positions of commanded poses (verification).
    Desired,
}

/// The nominal robot, the calibrated one and the result of `--params`, checked to belong
/// together (see [`common::nominal_and_result`]).
pub(super) fn calibrated_model(
    robot: Option<&str>,
    params: &Path,
) -> anyhow::Result<(Robot, Robot, CalibrationResult)> {
    common::nominal_and_result(robot, params, "--params")
}

/// Everything `evaluate` needs, checked completely before any work: flag combinations, the
/// files plan, the models and the result (checked to belong together).
struct Settings {
    nominal: Robot,
    calibrated: Robot,
    result: CalibrationResult,
    against: Against,
    params: PathBuf,
    data: PathBuf,
    per_point: Option<PathBuf>,
    outputs: io_plan::Outputs,
    json: bool,
    nominal_limits: bool,
    refit_frame: bool,
    repeatability_mm: Option<f64>,
}

impl TryFrom<&EvaluateArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &EvaluateArgs) -> anyhow::Result<Settings> {
        let stdout_data = a.per_point.as_deref() == Some(Path::new(io_plan::STDOUT));
        if stdout_data && a.json {
            return Err(crate::exit::usage(
                "--per-point - and --json both want standard output: write the per-point \
                 errors to a file",
            ));
        }
        let mut plan = IoPlan::new();
        plan.robot_opt("--robot", a.robot.as_deref())
            .input("--params", &a.params)
            .recorded_in("--params", &a.params)
            .input("--data", &a.data);
        if let Some(p) = &a.per_point {
            plan.output_or_stdout("--per-point", p);
        }
        if let Some(rp) = a.repeatability_mm {
            robocal_core::evaluation::gap::check_rp(rp)
                .map_err(|e| crate::exit::usage(format!("--repeatability-mm: {e}")))?;
        }
        let outputs = plan.check()?;
        let (nominal, mut calibrated, result) = calibrated_model(a.robot.as_deref(), &a.params)?;
        common::apply_payload(&mut calibrated, a.payload_kg)?;
        common::warn_not_calibrated(&result, &a.params)?;
        let against = match a.against {
            AgainstArg::Auto => Against::Auto,
            AgainstArg::Model => Against::Model,
            AgainstArg::Desired => Against::Desired,
        };
        Ok(Settings {
            nominal,
            calibrated,
            result,
            against,
            params: a.params.clone(),
            data: a.data.clone(),
            per_point: a.per_point.clone(),
            outputs,
            json: a.json,
            nominal_limits: a.nominal_limits,
            refit_frame: a.refit_frame,
            repeatability_mm: a.repeatability_mm,
        })
    }
}

pub fn run(a: EvaluateArgs) -> anyhow::Result<()> {
    let Settings {
        nominal,
        calibrated: cal,
        result: res,
        against,
        params,
        data,
        per_point: per_point_path,
        mut outputs,
        json,
        nominal_limits,
        refit_frame,
        repeatability_mm,
    } = Settings::try_from(&a)?;
    if let Some(inputs) = &res.inputs {
        robocal_core::io::inputs::check_unchanged(inputs, &data, &params)?;
    }
    let section = robocal_core::io::result_constraint::ConstraintSection::of(&res, &params)?;
    // A file that cannot be read is the reader's to report, with its context.
    if super::calibrate::is_constraint_file(&data, &nominal).unwrap_or(false) {
        if per_point_path.is_some() || !matches!(against, Against::Auto | Against::Model) {
            return Err(crate::exit::usage(
                "--per-point and --against desired apply to tracker points, not to constraint \
                 rows",
            ));
        }
        return constraints::run(constraints::HeldOut {
            nominal: &nominal,
            calibrated: &cal,
            section: section.as_ref(),
            params: &params,
            data: &data,
            json,
        });
    }
    // A calibration up to the base pose has no tracker frame: tracker points are registered to
    // it, as with --refit-frame.
    let refit_frame = refit_frame || section.as_ref().is_some_and(|s| !s.base_pose_known);
    if let Some(s) = section.as_ref().filter(|s| !s.base_pose_known) {
        errln!(
            "note: {} is a constraint calibration: {}; the tracker frame of {} is registered to \
             its points under each model (as --refit-frame), so the errors are those after the \
             best rigid alignment",
            params.display(),
            s.frame,
            data.display()
        )?;
    }
    // Row by row: only the error norms are kept (16 bytes per row), so files of any length fit.
    let context = || format!("--data {}", data.display());
    let mut reader = MeasurementReader::open(&data, nominal.joint_space(), Positions::Required)
        .with_context(context)?;
    let header = reader.header();
    // A station of their own: both frames fitted to the whole file first.
    let whole = || read_measurements(&data, nominal.joint_space(), Positions::Required);
    let (nominal_frame, frame) = if refit_frame {
        let set = whole().with_context(context)?;
        robocal_core::evaluation::station_frames(&nominal, &cal, &set)?
    } else {
        (res.nominal_frame(), res.tracker_frame())
    };
    let ev =
        Evaluator::new(&nominal, &cal, &frame, &header, against)?.with_nominal_frame(nominal_frame);
    let names = ev.series();
    // The calibrated model without each condition family the data's columns feed.
    let without = conditions::models_without(&cal, &header)?;
    let ev_without = without
        .iter()
        .map(|w| Evaluator::new(&nominal, &w.model, &frame, &header, against))
        .collect::<Result<Vec<_>, _>>()?;
    let mut sums_without = vec![0.0; without.len()];
    let mut per_point = match &per_point_path {
        Some(p) => Some(PerPointWriter::to_output(
            outputs.open(p)?,
            &header,
            [names[0].0, names[1].0],
        )?),
        None => None,
    };
    let mut norms = [Vec::new(), Vec::new()];
    let mut not_converged = Statuses::new(&header);
    let mut outside = OutsideLimits::new(&nominal, &data);
    while let Some(r) = reader.next_row().with_context(context)? {
        outside.check(r.line, &r.q);
        let e = ev.errors(&r)?;
        norms[0].push(e[0].norm());
        norms[1].push(e[1].norm());
        for (sum, ev) in sums_without.iter_mut().zip(&ev_without) {
            *sum += ev.errors(&r)?[1].norm();
        }
        if let Some(w) = &mut per_point {
            w.write(&r, &e)?;
        }
        not_converged.note(&r);
    }
    for w in reader.finish().with_context(context)? {
        errln!("warning: {w}")?;
    }
    let n_outside = outside.count();
    // Refused before anything is written (the per-point writer is dropped).
    super::common::check_limits(outside, nominal_limits, &mut Vec::new())?;
    let mean = norms[1].iter().sum::<f64>() / norms[1].len().max(1) as f64;
    if mean > robocal_core::registration::STATION_MIN_MM {
        // Far off: data of another robot or in another unit (calibrate's gate, exit 6), or
        // from another tracker station.
        let set = whole().with_context(context)?;
        robocal_core::evaluation::check_data_matches(&cal, &set)?;
        if !refit_frame && ev.reference() == Reference::Model {
            robocal_core::evaluation::check_station(&cal, &set, mean)?;
        }
    }
    if let Some(w) = per_point {
        w.commit()?;
    }
    not_converged.report()?;
    let n = norms[0].len();
    let series: Vec<Series> = names
        .iter()
        .zip(&norms)
        .map(|(&(name, description), norms)| Series {
            name,
            description,
            stats: ErrorStats::from_norms(norms),
        })
        .collect();
    let reference = ev.reference();
    let means_without: Vec<f64> = sums_without.iter().map(|s| s / n.max(1) as f64).collect();
    let gap = if reference == Reference::Desired {
        let set = whole().with_context(context)?;
        // The robot's repeatability: the RP given, else its class's default per joint.
        let repeatability = match repeatability_mm {
            Some(rp) => Repeatability::Rp(rp),
            None => Repeatability::PerJoint {
                std_deg: RepeatabilityModel::default_for(&nominal).std_deg,
                source: "the class default".to_owned(),
            },
        };
        robocal_core::evaluation::gap::split(
            &nominal,
            &cal,
            &res,
            &set,
            series[0].stats.rms_mm,
            refit_frame.then_some(&frame),
            repeatability,
        )?
    } else {
        None
    };
    if json {
        let mut o = serde_json::Map::new();
        o.insert("data".into(), data.display().to_string().into());
        o.insert("params".into(), params.display().to_string().into());
        o.insert(
            "reference".into(),
            match reference {
                Reference::Model => "model",
                Reference::Desired => "desired",
            }
            .into(),
        );
        o.insert("n".into(), n.into());
        if refit_frame {
            o.insert(
                "refit_frame".into(),
                serde_json::json!({
                    "calibrated": frame.vector_deg(),
                    "nominal": nominal_frame.vector_deg(),
                }),
            );
        }
        if nominal_limits {
            o.insert("rows_outside_limits".into(), n_outside.into());
        }
        for s in &series {
            o.insert(s.name.into(), serde_json::to_value(s.stats)?);
        }
        if reference == Reference::Desired {
            o.insert(
                "predicted".into(),
                serde_json::json!({
                    "new_poses": res.prediction.as_ref().map(|p| serde_json::json!({
                        "mean_mm": p.mean_mm,
                        "std_mm": p.std_mm,
                        "rms_mm": p.rms_mm,
                    })),
                    "calibration": res.errors.calibration.after,
                    "validation": res.errors.validation.map(|v| v.after),
                }),
            );
        }
        if let Some(g) = &gap {
            o.insert("gap".into(), g.json());
        }
        if !without.is_empty() {
            o.insert(
                "calibrated_without".into(),
                without
                    .iter()
                    .zip(&means_without)
                    .map(|(w, m)| (w.key.to_owned(), serde_json::json!({ "mean_mm": m })))
                    .collect::<serde_json::Map<_, _>>()
                    .into(),
            );
        }
        if let Some(p) = &per_point_path {
            o.insert("per_point".into(), p.display().to_string().into());
        }
        outln!("{}", serde_json::to_string_pretty(&o)?)?;
    } else {
        print_table(
            (&data, &params, per_point_path.as_deref()),
            n,
            reference,
            &series,
            &res,
            refit_frame.then_some(&frame),
        )?;
        if let Some(g) = &gap {
            gap::print(g)?;
        }
        conditions::print(&without, &means_without, series[1].stats.mean_mm)?;
    }
    Ok(())
}

/// One series' name, description and statistics.
struct Series {
    name: &'static str,
    description: &'static str,
    stats: ErrorStats,
}

/// Rows listed one by one in the note about rows that did not converge in compensation.
const LISTED: usize = 20;

/// Rows of a commanded file whose compensation did not converge (`status` column).
struct Statuses {
    column: Option<usize>,
    count: usize,
    listed: Vec<String>,
}

impl Statuses {
    fn new(header: &MeasurementSet) -> Statuses {
        Statuses {
            column: header.extra_columns.iter().position(|c| c == "status"),
            count: 0,
            listed: Vec::new(),
        }
    }

    fn note(&mut self, r: &Measurement) {
        let Some(k) = self.column else { return };
        let s = &r.extra[k];
        if s != "converged" {
            self.count += 1;
            if self.listed.len() < LISTED {
                self.listed.push(format!("line {} ({s})", r.line));
            }
        }
    }

    /// Tells the user about them.
    fn report(&self) -> anyhow::Result<()> {
        if self.count == 0 {
            return Ok(());
        }
        let more = if self.count > self.listed.len() {
            format!(", ... ({} more)", self.count - self.listed.len())
        } else {
            String::new()
        };
        errln!(
            "note: {} row(s) were not converged in compensation; their errors are included: {}{more}",
            self.count,
            self.listed.join(", ")
        )?;
        Ok(())
    }
}

/// Picks one figure out of a statistics record.
type Figure = fn(&ErrorStats) -> f64;

/// The rows of the statistics tables.
const STAT_ROWS: [(&str, Figure); 5] = [
    ("Mean (mm)", |s| s.mean_mm),
    ("St. dev. (mm)", |s| s.std_mm),
    ("Max. (mm)", |s| s.max_mm),
    ("RMS (mm)", |s| s.rms_mm),
    ("P95 (mm)", |s| s.p95_mm),
];

fn cell(v: f64) -> String {
    if v.is_finite() {
        format!(" {v:>12.4}")
    } else {
        format!(" {:>12}", "-")
    }
}

/// Prints the statistics of `files` (`--data`, `--params`, `--per-point`).
fn print_table(
    (data, params, per_point_path): (&Path, &Path, Option<&Path>),
    n: usize,
    reference: Reference,
    series: &[Series],
    res: &CalibrationResult,
    refit: Option<&robocal_core::frame::TrackerFrame>,
) -> anyhow::Result<()> {
    let what = match reference {
        Reference::Model => "validation: measured points against the models at the measured joints",
        Reference::Desired => {
            "verification: measured commanded poses against their desired positions (Table V)"
        }
    };
    let frame = match refit {
        Some(f) => {
            let v = f.vector_deg();
            format!(
                "tracker frame fitted to these data (another station): x={:.3} y={:.3} z={:.3} mm, \
                 A={:.4} B={:.4} C={:.4} deg",
                v[0], v[1], v[2], v[3], v[4], v[5]
            )
        }
        None => format!("tracker frame of {}", params.display()),
    };
    outln!("{}: {} points; {what}; {frame}", data.display(), n)?;
    match reference {
        Reference::Model => {
            for s in series {
                outln!("  {:<11} {}", s.name, s.description)?;
            }
            outln!()?;
            outln!("{:<14} {:>12} {:>12}", "", series[0].name, series[1].name)?;
            for (label, f) in STAT_ROWS {
                outln!(
                    "{label:<14}{}{}",
                    cell(f(&series[0].stats)),
                    cell(f(&series[1].stats))
                )?;
            }
            let (b, c) = (series[0].stats.mean_mm, series[1].stats.mean_mm);
            if b > 0.0 {
                outln!(
                    "mean error {} by {:.1}% with the calibrated model",
                    if c <= b { "reduced" } else { "increased" },
                    100.0 * (b - c).abs() / b
                )?;
            }
        }
        Reference::Desired => {
            // Verification beside what the calibration predicted (the result's Table IV).
            let cal = res.errors.calibration.after;
            let val = res.errors.validation.map(|v| v.after);
            outln!(
                "  predicted: the calibrated model's errors in {} (Table IV)",
                params.display()
            )?;
            outln!()?;
            out!("{:<14} {:>12} {:>12}", "", "verification", "pred. cal.")?;
            if val.is_some() {
                out!(" {:>12}", "pred. val.")?;
            }
            outln!()?;
            for (label, f) in STAT_ROWS {
                // A result file without p95 reads it as 0: show it as unknown.
                let pred = |s: &ErrorStats| {
                    if label.starts_with("P95") && s.p95_mm == 0.0 {
                        f64::NAN
                    } else {
                        f(s)
                    }
                };
                out!(
                    "{label:<14}{}{}",
                    cell(f(&series[0].stats)),
                    cell(pred(&cal))
                )?;
                if let Some(v) = &val {
                    out!("{}", cell(pred(v)))?;
                }
                outln!()?;
            }
            // One prediction everywhere: the expected mean error at new poses spread like the
            // calibration poses (calibrate's `prediction`); Table IV's calibration points only
            // for a result without one, and then named as such.
            let m = series[0].stats.mean_mm;
            let (p, basis) = match res.prediction.as_ref().map(|p| p.mean_mm) {
                Some(p) if p.is_finite() => (
                    p,
                    "predicted at new poses spread like the calibration poses (calibrate's \
                     prediction)",
                ),
                _ => (
                    cal.mean_mm,
                    "on the calibration points (Table IV; the result has no prediction)",
                ),
            };
            if p > 0.0 {
                outln!(
                    "verification mean {m:.4} mm vs {p:.4} mm {basis} ({:+.0}%)",
                    100.0 * (m - p) / p
                )?;
            }
        }
    }
    if let Some(p) = per_point_path {
        outln!("wrote {} ({n} rows)", io_plan::shown(p))?;
    }
    Ok(())
}
