//! `compensate`'s flags turned into checked settings before any work: the solvers' settings
//! (ranges), the flags that need a program, the files plan, the models at the cell's conditions,
//! and the result (partial or implausible results refused).

use super::super::evaluate::calibrated_model;
use super::super::io_plan::{IoPlan, Outputs};
use super::super::{common, flags, limits};
use super::{conditions, program, CompensateArgs};
use crate::exit;
use robocal_core::compensation::PoseNewton;
use robocal_core::io::result_constraint::ConstraintSection;
use robocal_core::io::CalibrationResult;
use robocal_core::programs::Format;
use robocal_core::{DampedLeastSquares, Robot};
use std::path::{Path, PathBuf};

/// Everything `compensate` needs, checked completely before any work: the solver's settings
/// (ranges), the files plan, the models and the result (partial or implausible results refused).
pub(super) struct Settings {
    pub(super) nominal: Robot,
    pub(super) calibrated: Robot,
    pub(super) solver: DampedLeastSquares,
    pub(super) pose_solver: PoseNewton,
    pub(super) position_only: bool,
    pub(super) joints: Option<PathBuf>,
    pub(super) targets: Option<PathBuf>,
    pub(super) out: PathBuf,
    pub(super) outputs: Outputs,
    pub(super) strict: bool,
    pub(super) params: PathBuf,
    pub(super) program: Option<(PathBuf, Format)>,
    pub(super) changes: Option<PathBuf>,
    pub(super) keep_going: bool,
    pub(super) config: Option<PathBuf>,
    /// The calibration models backlash: every pose approached from below (written as dir1..dirN).
    pub(super) from_below: bool,
}

impl TryFrom<&CompensateArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &CompensateArgs) -> anyhow::Result<Settings> {
        let (solver, pose_solver) = solvers(a)?;
        let program = program_file(a)?;
        let outputs = plan(a)?;
        let (nominal, mut calibrated, res) = calibrated_model(a.robot.as_deref(), &a.params)?;
        common::apply_payload(&mut calibrated, a.payload_kg)?;
        let from_below = conditions::approached_from_below(&calibrated);
        let calibrated = conditions::fold(&calibrated, a.temperature_c)?;
        check_result(&res, &a.params, a.accept_implausible)?;
        Ok(Settings {
            nominal,
            calibrated,
            solver,
            pose_solver,
            position_only: a.position_only,
            joints: a.joints.clone(),
            targets: a.targets.clone(),
            out: a.out.clone(),
            outputs,
            strict: a.strict,
            params: a.params.clone(),
            program,
            changes: a.changes.clone(),
            keep_going: a.keep_going,
            config: a.config.clone(),
            from_below,
        })
    }
}

/// The position and the full-pose solvers of `--tolerance-mm`, `--tolerance-deg` and
/// `--max-iterations`, each checked against its range.
fn solvers(a: &CompensateArgs) -> anyhow::Result<(DampedLeastSquares, PoseNewton)> {
    let solver = DampedLeastSquares {
        tolerance_mm: a.tolerance_mm,
        max_iterations: a.max_iterations,
        ..DampedLeastSquares::default()
    };
    let pose_solver = PoseNewton {
        tolerance_mm: a.tolerance_mm,
        tolerance_deg: a.tolerance_deg,
        max_iterations: a.max_iterations,
        ..PoseNewton::default()
    };
    solver
        .validate()
        .and_then(|()| pose_solver.validate())
        .map_err(|e| exit::usage(flags::cli_text(&e)))?;
    limits::magnitude("--tolerance-deg", a.tolerance_deg, 3600.0, "deg")?;
    limits::count(
        "--max-iterations",
        a.max_iterations,
        1,
        limits::MAX_IK_ITERATIONS,
        "per row; a solve converges in a handful",
    )?;
    limits::magnitude(
        "--tolerance-mm",
        a.tolerance_mm,
        limits::MAX_LENGTH_MM,
        "mm",
    )?;
    Ok((solver, pose_solver))
}

/// The `--program` and its format (from its extension); without one, `--keep-going` and
/// `--changes` are usage errors.
fn program_file(a: &CompensateArgs) -> anyhow::Result<Option<(PathBuf, Format)>> {
    let Some(p) = &a.program else {
        for (given, flag) in [
            (a.keep_going, "--keep-going"),
            (a.changes.is_some(), "--changes"),
        ] {
            if given {
                return Err(exit::usage(format!(
                    "{flag} applies to a robot program: give --program FILE"
                )));
            }
        }
        return Ok(None);
    };
    let format = Format::from_path(p).map_err(|e| exit::usage(flags::cli_text(&e)))?;
    Ok(Some((p.clone(), format)))
}

/// The files plan, checked: the inputs, and the outputs (with a KRL program that has a `.dat`,
/// the `.dat` written beside `--out`).
fn plan(a: &CompensateArgs) -> anyhow::Result<Outputs> {
    let mut plan = IoPlan::new();
    plan.robot_opt("--robot", a.robot.as_deref())
        .input("--params", &a.params)
        .recorded_in("--params", &a.params)
        .input_opt("--joints", a.joints.as_deref())
        .input_opt("--targets", a.targets.as_deref())
        .input_opt("--program", a.program.as_deref())
        .output_or_stdout("--out", &a.out);
    if let Some(c) = &a.changes {
        plan.output_or_stdout("--changes", c);
    }
    plan.input_opt("--config", a.config.as_deref());
    if let Some(dat) = a.program.as_deref().and_then(program::dat_beside) {
        plan.input("--program", &dat);
        plan.output(
            "--out",
            &program::dat_path(&a.out),
            "a KRL program with a .dat",
        );
    }
    plan.check()
}

/// Refuses a partial result, and an implausible one unless `accept_implausible` (then a loud
/// warning); notes a constraint calibration's unknown base pose.
fn check_result(
    res: &CalibrationResult,
    params: &Path,
    accept_implausible: bool,
) -> anyhow::Result<()> {
    if let Some(why) = res.partial_reason() {
        return Err(exit::input(format!(
            "--params {}: a partial result, not a calibration ({why}); compensation refuses \
             it: re-run calibrate with a higher --max-iterations",
            params.display()
        )));
    }
    if let Some(why) = res.implausible_reason() {
        if !accept_implausible {
            return Err(exit::implausible(format!(
                "--params {}: an IMPLAUSIBLE result, not a calibration: it failed the \
                 plausibility gate:\n{}\ncompensation refuses it (fix the data or the robot \
                 and calibrate again, or give --accept-implausible to use it anyway)",
                params.display(),
                common::indent(&why)
            )));
        }
        errln!(
            "WARNING: --accept-implausible: compensating with {}, a result that FAILED the \
             plausibility gate; the commanded joints may be far from right:\n{}",
            params.display(),
            common::indent(&why)
        )?;
    }
    if ConstraintSection::of(res, params)?.is_some_and(|s| !s.base_pose_known) {
        errln!(
            "note: {} is a constraint calibration, up to the base pose: targets are taken in \
             the calibrated base frame, whose pose is the nominal one; positions are right \
             relative to each other and to the constrained features, not absolutely",
            params.display()
        )?;
    }
    Ok(())
}
