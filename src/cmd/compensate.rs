//! `robocal compensate`: commanded joint values from the calibrated model (paper, section V.A,
//! eq. 12-14), for desired joint vectors or for Cartesian targets: the whole tool pose by default
//! (position and orientation, on the desired configuration), the tool position with
//! `--position-only`; or for the targets of a robot program (`--program`, see [`program`]).

mod conditions;
mod program;
mod rows;
mod settings;
mod summary;

use clap::Args;
use robocal_core::Compensator;
use settings::Settings;
use std::path::PathBuf;
use summary::Tally;

#[derive(Args, Debug)]
pub struct CompensateArgs {
    /// The nominal robot (what the controller believes): a preset name, a TOML robot file or a URDF
    /// [default: the robot embedded in the result; when given, it must agree with that one].
    #[arg(long)]
    robot: Option<String>,
    /// The calibration result (`robocal calibrate --out`).
    #[arg(long)]
    params: PathBuf,
    /// The payload (kg) the robot will carry at the commanded poses, for a calibration whose
    /// joint compliances were identified at a known payload (`calibrate --payload-kg`): the
    /// commanded joints then account for the deflection at this payload [default: the
    /// calibration's payload].
    #[arg(long, value_name = "KG")]
    payload_kg: Option<f64>,
    /// The arm's temperature (deg C) when the commanded poses will run, for a calibration with
    /// thermal expansion (`calibrate --thermal auto`) [default: the calibration's reference
    /// temperature].
    #[arg(long, value_name = "DEG_C", allow_hyphen_values = true)]
    temperature_c: Option<f64>,
    /// Desired joint values: CSV with q1..qn (model joint values: degrees, mm for a prismatic
    /// joint) or axis1..axisN (controller values, through the robot's [controller]). Each row's
    /// target is its nominal tool position (eq. 13); the solve starts from the row's joints.
    /// Other columns are carried; x,y,z (old measurements), if present, are not.
    #[arg(
        long,
        value_name = "DESIRED.csv",
        required_unless_present_any = ["targets", "program"]
    )]
    joints: Option<PathBuf>,
    /// Cartesian targets instead: CSV with x,y,z (mm, robot base frame), optionally a,b,c (deg,
    /// the tool orientation as A, B, C; without them the targets are position-only) and
    /// optionally q1..qn (or axis1..axisN) to start from; without them, several start
    /// configurations are tried.
    #[arg(long, value_name = "XYZ.csv", conflicts_with = "joints")]
    targets: Option<PathBuf>,
    /// A robot program instead: KUKA KRL (.src, .dat), ABB RAPID (.mod, .modx, .prg) or
    /// URScript (.script, .urscript), by its extension. Every joint and Cartesian target is
    /// replaced by its compensated value in the controller's units and axis conventions; the
    /// rest of the file is kept byte for byte. `--out` is then the compensated program.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["joints", "targets", "strict"])]
    program: Option<PathBuf>,
    /// With `--program`: also write the list of targets as CSV (name, line, kind, status,
    /// applied, correction_mm, correction_deg, verified_mm, verified_deg, old, new).
    #[arg(long, value_name = "CHANGES.csv", requires = "program")]
    changes: Option<PathBuf>,
    /// With `--program`: a target that cannot be compensated is left unchanged and listed with
    /// its status, and the rest is written (exit 0). Without it such a target stops the run
    /// (exit 5, nothing written).
    #[arg(long, requires = "program")]
    keep_going: bool,
    /// With a KRL `--program`: the controller's `$config.dat`, whose `TOOL_DATA[n]` and
    /// `BASE_DATA[n]` resolve the program's tools and bases (without it, Cartesian targets in a
    /// numbered tool or base other than 0 are left unchanged, "frame unknown").
    #[arg(long, value_name = "$config.dat", requires = "program")]
    config: Option<PathBuf>,
    /// Output: with `--program`, the compensated program. Otherwise: commanded joints q1..qn (degrees, mm for a prismatic joint) and, when the robot
    /// has a controller map, the controller's axis1..axisN, with status, residual and the
    /// desired values. `-`: standard output (written when complete; the summary then goes to
    /// standard error).
    #[arg(long, value_name = "COMMANDED.csv")]
    out: PathBuf,
    /// A solve has converged when the tool is this close to its target (mm).
    #[arg(long, default_value_t = 1e-6)]
    tolerance_mm: f64,
    /// Full pose: a solve has converged when the tool's orientation is this close to the target
    /// orientation (deg, the angle of the rotation between them).
    #[arg(long, default_value_t = 1e-6)]
    tolerance_deg: f64,
    /// Compensate the tool position only (the paper's eq. 13-14 as written): the orientation is
    /// free, and the configuration is not checked. Default: the whole pose.
    #[arg(long)]
    position_only: bool,
    /// Most iterations (Jacobian evaluations) per solve (1 to 100000).
    #[arg(long, default_value_t = 500)]
    max_iterations: usize,
    /// Fail (exit code 5, nothing written) if any row does not converge. Without it, such rows
    /// are written with their status and the closest joints found, and listed as warnings.
    #[arg(long)]
    strict: bool,
    /// Use a result that failed the plausibility gate (`"status": "implausible"`, written by
    /// `calibrate --accept-implausible`). Without it such a result is refused (exit code 6).
    #[arg(long)]
    accept_implausible: bool,
}

/// Runs `compensate`: the settings checked, then a robot program ([`program`]) or the rows of
/// `--joints` or `--targets` ([`rows`]) solved and written, the failures told and the summary
/// printed ([`summary`]).
pub fn run(a: CompensateArgs) -> anyhow::Result<()> {
    let Settings {
        nominal,
        calibrated: cal,
        solver,
        pose_solver,
        position_only,
        joints: joints_path,
        targets,
        out,
        mut outputs,
        strict,
        params,
        program: program_file,
        changes,
        keep_going,
        config,
        from_below,
    } = Settings::try_from(&a)?;
    let tolerance_mm = solver.tolerance_mm;
    let tolerance_deg = pose_solver.tolerance_deg;
    let mut comp = Compensator::new(&nominal, &cal, solver)?;
    comp.pose_solver = pose_solver;
    if let Some((path, format)) = &program_file {
        let run = program::ProgramRun {
            program: path,
            format: *format,
            out: &out,
            changes: changes.as_deref(),
            keep_going,
            full_pose: !position_only,
            params: &params,
            config: config.as_deref(),
        };
        return program::run(&run, &comp, &mut outputs);
    }
    let pb = crate::progress::spinner("compensating");
    let mut tally = Tally::default();
    let mut rows = rows::Rows {
        nominal: &nominal,
        calibrated: &cal,
        comp: &comp,
        from_below,
        outputs: &mut outputs,
        out: &out,
        tally: &mut tally,
        pb: &pb,
    };
    let (input, compensated) = if let Some(path) = &joints_path {
        (path, rows.compensate_desired_joints(path, !position_only)?)
    } else {
        let path = targets
            .as_ref()
            .expect("clap requires --joints or --targets");
        (path, rows.compensate_targets(path, position_only)?)
    };
    pb.finish_and_clear();
    // With --strict the writer is dropped on a failure: nothing is written.
    summary::failures(&tally, strict, input, &out)?;
    compensated.writer.commit()?;
    summary::print_summary(
        joints_path.is_some(),
        compensated.full_pose,
        &params,
        (tolerance_mm, tolerance_deg),
        &out,
        input,
        &tally,
    )
}
