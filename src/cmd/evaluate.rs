//! `robocal evaluate`: error statistics of a measured data set under the nominal and the
//! calibrated model (validation, paper section IV), or of measured commanded poses against their
//! desired positions (verification, section V.B, Table V).

mod conditions;
mod constraints;
mod gap;
mod output;

use super::common;
use super::io_plan::{self, IoPlan};
use anyhow::Context;
use clap::{Args, ValueEnum};
use robocal_core::evaluation::gap::{Gap, Repeatability};
use robocal_core::evaluation::{Against, Evaluator, PerPointWriter, Reference};
use robocal_core::frame::TrackerFrame;
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
    let mut s = Settings::try_from(&a)?;
    if let Some(inputs) = &s.result.inputs {
        robocal_core::io::inputs::check_unchanged(inputs, &s.data, &s.params)?;
    }
    let section = robocal_core::io::result_constraint::ConstraintSection::of(&s.result, &s.params)?;
    // A file that cannot be read is the reader's to report, with its context.
    if super::calibrate::is_constraint_file(&s.data, &s.nominal).unwrap_or(false) {
        if s.per_point.is_some() || !matches!(s.against, Against::Auto | Against::Model) {
            return Err(crate::exit::usage(
                "--per-point and --against desired apply to tracker points, not to constraint \
                 rows",
            ));
        }
        return constraints::run(constraints::HeldOut {
            nominal: &s.nominal,
            calibrated: &s.calibrated,
            section: section.as_ref(),
            params: &s.params,
            data: &s.data,
            json: s.json,
        });
    }
    // A calibration up to the base pose has no tracker frame: tracker points are registered to
    // it, as with --refit-frame.
    if let Some(c) = section.as_ref().filter(|c| !c.base_pose_known) {
        s.refit_frame = true;
        errln!(
            "note: {} is a constraint calibration: {}; the tracker frame of {} is registered to \
             its points under each model (as --refit-frame), so the errors are those after the \
             best rigid alignment",
            s.params.display(),
            c.frame,
            s.data.display()
        )?;
    }
    let e = evaluate_rows(&mut s)?;
    if s.json {
        outln!("{}", serde_json::to_string_pretty(&output::json(&s, &e)?)?)?;
    } else {
        output::print(&s, &e)?;
    }
    Ok(())
}

/// What the rows of `--data` gave.
struct Evaluated {
    /// The tracker frames of the nominal and the calibrated model (fitted to the data with
    /// `--refit-frame`).
    nominal_frame: TrackerFrame,
    frame: TrackerFrame,
    reference: Reference,
    /// Rows evaluated, and of them outside the joint limits.
    n: usize,
    n_outside: usize,
    /// The nominal and the calibrated model's error statistics.
    series: Vec<Series>,
    /// The calibrated model without each condition family the data's columns feed, and its
    /// mean error.
    without: Vec<conditions::Without>,
    means_without: Vec<f64>,
    /// A verification's gap to the prediction.
    gap: Option<Gap>,
}

/// Evaluates the rows of `--data` one by one (only the error norms are kept, 16 bytes per row,
/// so files of any length fit), writing `--per-point` once the rows are all checked.
fn evaluate_rows(s: &mut Settings) -> anyhow::Result<Evaluated> {
    let (nominal, cal) = (&s.nominal, &s.calibrated);
    let context = || format!("--data {}", s.data.display());
    let mut reader = MeasurementReader::open(&s.data, nominal.joint_space(), Positions::Required)
        .with_context(context)?;
    let header = reader.header();
    // A station of their own: both frames fitted to the whole file first.
    let whole = || read_measurements(&s.data, nominal.joint_space(), Positions::Required);
    let (nominal_frame, frame) = if s.refit_frame {
        let set = whole().with_context(context)?;
        robocal_core::evaluation::station_frames(nominal, cal, &set)?
    } else {
        (s.result.nominal_frame(), s.result.tracker_frame())
    };
    let ev =
        Evaluator::new(nominal, cal, &frame, &header, s.against)?.with_nominal_frame(nominal_frame);
    let names = ev.series();
    // The calibrated model without each condition family the data's columns feed.
    let without = conditions::models_without(cal, &header)?;
    let ev_without = without
        .iter()
        .map(|w| Evaluator::new(nominal, &w.model, &frame, &header, s.against))
        .collect::<Result<Vec<_>, _>>()?;
    let mut sums_without = vec![0.0; without.len()];
    let mut per_point = match &s.per_point {
        Some(p) => Some(PerPointWriter::to_output(
            s.outputs.open(p)?,
            &header,
            [names[0].0, names[1].0],
        )?),
        None => None,
    };
    let mut norms = [Vec::new(), Vec::new()];
    let mut not_converged = Statuses::new(&header);
    let mut outside = OutsideLimits::new(nominal, &s.data);
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
    super::common::check_limits(outside, s.nominal_limits, &mut Vec::new())?;
    let mean = norms[1].iter().sum::<f64>() / norms[1].len().max(1) as f64;
    if mean > robocal_core::registration::STATION_MIN_MM {
        // Far off: data of another robot or in another unit (calibrate's gate, exit 6), or
        // from another tracker station.
        let set = whole().with_context(context)?;
        robocal_core::evaluation::check_data_matches(cal, &set)?;
        if !s.refit_frame && ev.reference() == Reference::Model {
            robocal_core::evaluation::check_station(cal, &set, mean)?;
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
    let gap = if reference == Reference::Desired {
        let set = whole().with_context(context)?;
        gap_split(s, &set, series[0].stats.rms_mm, &frame)?
    } else {
        None
    };
    Ok(Evaluated {
        nominal_frame,
        frame,
        reference,
        n,
        n_outside,
        series,
        means_without: sums_without.iter().map(|s| s / n.max(1) as f64).collect(),
        without,
        gap,
    })
}

/// A verification's gap to the calibration's prediction (see [`gap`]), with the robot's
/// repeatability: the RP given, else its class's default per joint.
fn gap_split(
    s: &Settings,
    set: &MeasurementSet,
    verified_rms_mm: f64,
    frame: &TrackerFrame,
) -> anyhow::Result<Option<Gap>> {
    let repeatability = match s.repeatability_mm {
        Some(rp) => Repeatability::Rp(rp),
        None => Repeatability::PerJoint {
            std_deg: RepeatabilityModel::default_for(&s.nominal).std_deg,
            source: "the class default".to_owned(),
        },
    };
    Ok(robocal_core::evaluation::gap::split(
        &s.nominal,
        &s.calibrated,
        &s.result,
        set,
        verified_rms_mm,
        s.refit_frame.then_some(frame),
        repeatability,
    )?)
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
