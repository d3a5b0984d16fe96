//! A report of one calibration run: the result file plus, when available, the measured data the
//! per-point figures need (what `robocal report` and `robocal demo` show).

use crate::build::{before_after_histogram, paper_tables};
use crate::data::{
    HistogramSeries, Note, PointDetail, PointError, PointSet, ReachKind, ReportData,
};
use robocal_core::evaluation::{evaluate_framed, Against, Evaluation};
use robocal_core::io::result::BeforeAfter;
use robocal_core::io::{CalibrationResult, MeasurementSet, SetLabel};
use robocal_core::{ErrorStats, Result, Robot};

/// Name of the calibration point set.
pub const CALIBRATION: &str = "Calibration";
/// Name of the validation point set.
pub const VALIDATION: &str = "Validation";
/// Name of the verification point set.
pub const VERIFICATION: &str = "Verification";

/// A calibration run: the result and, each optional, the measured data.
#[derive(Debug, Clone, Copy)]
pub struct RunData<'a> {
    /// The result file's content.
    pub result: &'a CalibrationResult,
    /// The nominal robot the result belongs to.
    pub nominal: &'a Robot,
    /// Its calibrated model (from the result).
    pub calibrated: &'a Robot,
    /// The calibration data file: rows with `set` = `plane` are skipped, rows with `set` =
    /// `validation` are validation points, the others calibration points.
    pub calibration: Option<&'a MeasurementSet>,
    /// Validation measurements (every row except plane points).
    pub validation: Option<&'a MeasurementSet>,
    /// Measurements of compensated poses carrying their desired positions (the columns
    /// `robocal compensate` writes): the verification (Table V).
    pub verification: Option<&'a MeasurementSet>,
    /// Show the paper's figures beside the error tables (for the paper's experiment).
    pub with_paper: bool,
}

/// What the per-point errors of a data set are.
struct Evaluated {
    points: Vec<PointError>,
    details: Vec<PointDetail>,
    stats: [ErrorStats; 2],
}

/// The rows of `set` whose `set` label is (or is not) one of `labels`; an unknown label is an
/// error naming the file and line.
fn rows_where(set: &MeasurementSet, labels: &[SetLabel], keep: bool) -> Result<MeasurementSet> {
    let of_row = set.set_labels()?;
    Ok(MeasurementSet {
        rows: set
            .rows
            .iter()
            .zip(of_row)
            .filter(|(_, l)| labels.contains(l) == keep)
            .map(|(r, _)| r.clone())
            .collect(),
        ..set.clone()
    })
}

fn reach_of(v: nalgebra::Vector3<f64>) -> f64 {
    ReachKind::Radial.of([v.x, v.y, v.z])
}

/// Per-point errors of `set` against the models (validation) or the desired positions
/// (verification: `before` is not available and left NaN).
fn evaluated(run: &RunData, set: &MeasurementSet, against: Against) -> Result<Evaluated> {
    let mut frame = run.result.tracker_frame();
    let mut nominal_frame = run.result.nominal_frame();
    let mut ev: Evaluation = evaluate_framed(
        run.nominal,
        run.calibrated,
        [&nominal_frame, &frame],
        set,
        against,
    )?;
    // A verification measured from another tracker station (set up anew): registered again,
    // under the calibrated model, as `evaluate --refit-frame` does.
    let mean = ev.series[1].stats.mean_mm;
    if against == Against::Desired && mean > robocal_core::registration::STATION_MIN_MM {
        let obs = robocal_core::evaluation::observations_of(set)?;
        if robocal_core::registration::another_station(run.calibrated, &obs, mean).is_some() {
            (nominal_frame, frame) =
                robocal_core::evaluation::station_frames(run.nominal, run.calibrated, set)?;
            ev = evaluate_framed(
                run.nominal,
                run.calibrated,
                [&nominal_frame, &frame],
                set,
                against,
            )?;
        }
    }
    let desired = against == Against::Desired;
    let joints = run.nominal.joint_space();
    let arr = |v: nalgebra::Vector3<f64>| [v.x, v.y, v.z];
    let mut points = Vec::with_capacity(set.rows.len());
    let mut details = Vec::with_capacity(set.rows.len());
    for (k, r) in set.rows.iter().enumerate() {
        let measured = frame.to_base(&r.p.unwrap_or_default());
        let (position, before, after) = if desired {
            // The desired position is the measured point minus its error.
            let e = ev.series[0].errors[k];
            (measured - e, [f64::NAN; 3], arr(e))
        } else {
            (
                run.nominal.tool_position(&r.q),
                arr(ev.series[0].errors[k]),
                arr(ev.series[1].errors[k]),
            )
        };
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        points.push(PointError {
            reach_mm: reach_of(position),
            before_mm: norm(before),
            after_mm: norm(after),
        });
        details.push(PointDetail {
            joints: joints.joints_to_display(&r.q),
            position_mm: arr(position),
            before_mm: before,
            after_mm: after,
        });
    }
    Ok(Evaluated {
        points,
        details,
        stats: [ev.series[0].stats, ev.series[1].stats],
    })
}

/// The per-point errors the result file itself lists (`points.<set>`, written by `robocal
/// calibrate`), without reach.
fn result_points(result: &CalibrationResult, validation: bool) -> Option<Vec<PointError>> {
    let points = result.points.as_ref()?;
    let list = if validation {
        points.validation.as_ref()?
    } else {
        &points.calibration
    };
    Some(
        list.iter()
            .map(|p| PointError {
                reach_mm: f64::NAN,
                before_mm: p.before_mm,
                after_mm: p.after_mm,
            })
            .collect(),
    )
}

impl ReportData {
    /// The report of a calibration run: [`ReportData::from_result`], plus per-point errors of
    /// the measured data (error against reach, histogram), the validation statistics when the
    /// result has none and validation data are given, and the verification (Table V). Without
    /// data, the per-point errors the result lists are used for the histogram (the reach plot
    /// needs the joint values).
    pub fn from_run(run: &RunData) -> Result<ReportData> {
        let result = run.result;
        let mut data = ReportData::from_result(result);
        let mut sets = Vec::new();
        let calibration_validation = add_calibration_set(run, &mut sets)?;
        let validation_rows = validation_rows(run, calibration_validation)?;
        let validation_stats =
            add_validation_set(run, validation_rows.as_ref(), &mut data, &mut sets)?;
        let verification = add_verification_set(run, &mut sets)?;

        data.error_tables = paper_tables(
            result.errors.calibration,
            validation_stats,
            verification,
            run.with_paper,
        );
        data.histogram = run_histogram(&sets);
        if sets
            .iter()
            .any(|s| s.points.iter().any(|p| p.reach_mm.is_nan()))
        {
            data.notes.push(Note::info(
                "Without the measurement files the error-against-reach plot cannot place the \
                 points: give the calibration data (and --validate) to see it.",
            ));
        }
        data.point_sets = sets;
        data.joint_units = run.nominal.joint_types().iter().map(|t| t.unit()).collect();
        data.reach = ReachKind::Radial;
        Ok(data)
    }
}

/// Adds the calibration point set to `sets`: the calibration file's rows evaluated against the
/// models, or without it the per-point errors the result lists (if any). Returns the validation
/// rows of the calibration file, if it has some.
fn add_calibration_set(run: &RunData, sets: &mut Vec<PointSet>) -> Result<Option<MeasurementSet>> {
    // Calibration (and validation rows of the calibration file).
    let mut validation_rows: Option<MeasurementSet> = None;
    match run.calibration {
        Some(set) => {
            let cal = rows_where(set, &[SetLabel::Plane, SetLabel::Validation], false)?;
            let e = evaluated(run, &cal, Against::Model)?;
            sets.push(PointSet {
                name: CALIBRATION.into(),
                points: e.points,
                details: e.details,
            });
            let val = rows_where(set, &[SetLabel::Validation], true)?;
            if !val.rows.is_empty() {
                validation_rows = Some(val);
            }
        }
        None => {
            if let Some(points) = result_points(run.result, false) {
                sets.push(PointSet {
                    name: CALIBRATION.into(),
                    points,
                    details: Vec::new(),
                });
            }
        }
    }
    Ok(validation_rows)
}

/// The validation rows: those of the calibration file (`from_calibration`), then those of the
/// validation file (without plane points); `None` without either.
fn validation_rows(
    run: &RunData,
    from_calibration: Option<MeasurementSet>,
) -> Result<Option<MeasurementSet>> {
    // Validation: the rows of the calibration file, then the validation file.
    let mut validation_rows = from_calibration;
    if let Some(v) = run.validation {
        let v = rows_where(v, &[SetLabel::Plane], false)?;
        validation_rows = Some(match validation_rows {
            Some(mut a) => {
                a.rows.extend(v.rows);
                a
            }
            None => v,
        });
    }
    Ok(validation_rows)
}

/// Adds the validation point set to `sets`: `rows` evaluated against the models, or without them
/// the per-point errors the result lists (if any). Returns the validation statistics: the
/// result's, or when it has none those of `rows` (noted in `data`).
fn add_validation_set(
    run: &RunData,
    rows: Option<&MeasurementSet>,
    data: &mut ReportData,
    sets: &mut Vec<PointSet>,
) -> Result<Option<BeforeAfter>> {
    let mut validation_stats = run.result.errors.validation;
    match rows {
        Some(v) => {
            let e = evaluated(run, v, Against::Model)?;
            if validation_stats.is_none() {
                validation_stats = Some(BeforeAfter {
                    before: e.stats[0],
                    after: e.stats[1],
                });
                data.notes
                    .retain(|n| !n.text.starts_with("No validation set"));
                data.notes.push(Note::info(format!(
                    "The validation statistics are computed here from {} ({} points) with \
                     the result's tracker frame; the result file has none.",
                    v.path.display(),
                    v.rows.len()
                )));
            }
            sets.push(PointSet {
                name: VALIDATION.into(),
                points: e.points,
                details: e.details,
            });
        }
        None => {
            if let Some(points) = result_points(run.result, true) {
                sets.push(PointSet {
                    name: VALIDATION.into(),
                    points,
                    details: Vec::new(),
                });
            }
        }
    }
    Ok(validation_stats)
}

/// Adds the verification point set (Table V) to `sets` when the run has verification data, and
/// returns its statistics against the desired positions.
fn add_verification_set(run: &RunData, sets: &mut Vec<PointSet>) -> Result<Option<ErrorStats>> {
    // Verification (Table V).
    let mut verification = None;
    if let Some(v) = run.verification {
        let e = evaluated(run, v, Against::Desired)?;
        verification = Some(e.stats[0]);
        sets.push(PointSet {
            name: VERIFICATION.into(),
            points: e.points,
            details: e.details,
        });
    }
    Ok(verification)
}

/// The histogram's series: the calibration points before and after calibration, the validation
/// and verification points after; empty when no set has per-point errors.
fn run_histogram(sets: &[PointSet]) -> Vec<HistogramSeries> {
    let mut histogram = before_after_histogram(sets, &[CALIBRATION], &[CALIBRATION]);
    // The validation points after calibration beside the calibration points.
    if let Some(v) = sets.iter().find(|s| s.name == VALIDATION) {
        histogram.push(HistogramSeries::new(
            "After calibration – validation points",
            v.points.iter().map(|p| p.after_mm).collect(),
        ));
    }
    if let Some(v) = sets.iter().find(|s| s.name == VERIFICATION) {
        histogram[1].label = "After calibration, predicted – calibration points".into();
        histogram.push(HistogramSeries::new(
            "After calibration, measured – verification points",
            v.points.iter().map(|p| p.after_mm).collect(),
        ));
    }
    if histogram.iter().all(|h| h.values_mm.is_empty()) {
        // No per-point errors at all: leave the figure empty rather than invent values.
        histogram.clear();
    }
    histogram
}
