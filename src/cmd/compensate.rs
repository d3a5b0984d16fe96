//! `robocal compensate`: commanded joint values from the calibrated model (paper, section V.A,
//! eq. 12-14), for desired joint vectors or for Cartesian targets: the whole tool pose by default
//! (position and orientation, on the desired configuration), the tool position with
//! `--position-only`; or for the targets of a robot program (`--program`, see [`program`]).

mod conditions;
mod program;

use super::evaluate::calibrated_model;
use super::io_plan::IoPlan;
use super::limits;
use crate::exit;
use anyhow::Context;
use clap::Args;
use robocal_core::compensation::commanded::{check_extra_columns, CommandedWriter};
use robocal_core::compensation::PoseNewton;
use robocal_core::compensation::{read_targets, Compensation, IkStatus};
use robocal_core::io::{MeasurementReader, Positions};
use robocal_core::{Compensator, DampedLeastSquares, Robot, Unit};
use std::path::PathBuf;

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

/// Rows listed one by one in warnings before the rest are summarized.
const LISTED: usize = 20;

/// Everything `compensate` needs, checked completely before any work: the solver's settings
/// (ranges), the files plan, the models and the result (partial or implausible results refused).
struct Settings {
    nominal: Robot,
    calibrated: Robot,
    solver: DampedLeastSquares,
    pose_solver: PoseNewton,
    position_only: bool,
    joints: Option<PathBuf>,
    targets: Option<PathBuf>,
    out: PathBuf,
    outputs: super::io_plan::Outputs,
    strict: bool,
    params: PathBuf,
    program: Option<(PathBuf, robocal_core::programs::Format)>,
    changes: Option<PathBuf>,
    keep_going: bool,
    config: Option<PathBuf>,
    /// The calibration models backlash: every pose approached from below (written as dir1..dirN).
    from_below: bool,
}

impl TryFrom<&CompensateArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &CompensateArgs) -> anyhow::Result<Settings> {
        let solver = DampedLeastSquares {
            tolerance_mm: a.tolerance_mm,
            max_iterations: a.max_iterations,
            ..DampedLeastSquares::default()
        };
        solver
            .validate()
            .map_err(|e| exit::usage(super::flags::cli_text(&e)))?;
        let pose_solver = PoseNewton {
            tolerance_mm: a.tolerance_mm,
            tolerance_deg: a.tolerance_deg,
            max_iterations: a.max_iterations,
            ..PoseNewton::default()
        };
        pose_solver
            .validate()
            .map_err(|e| exit::usage(super::flags::cli_text(&e)))?;
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
        if a.program.is_none() {
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
        }
        let program = match &a.program {
            Some(p) => Some((
                p.clone(),
                robocal_core::programs::Format::from_path(p)
                    .map_err(|e| exit::usage(super::flags::cli_text(&e)))?,
            )),
            None => None,
        };
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
        let outputs = plan.check()?;
        let (nominal, mut calibrated, res) = calibrated_model(a.robot.as_deref(), &a.params)?;
        super::common::apply_payload(&mut calibrated, a.payload_kg)?;
        let from_below = conditions::approached_from_below(&calibrated);
        let calibrated = conditions::fold(&calibrated, a.temperature_c)?;
        if let Some(why) = res.partial_reason() {
            return Err(exit::input(format!(
                "--params {}: a partial result, not a calibration ({why}); compensation refuses \
                 it: re-run calibrate with a higher --max-iterations",
                a.params.display()
            )));
        }
        if let Some(why) = res.implausible_reason() {
            if !a.accept_implausible {
                return Err(exit::implausible(format!(
                    "--params {}: an IMPLAUSIBLE result, not a calibration: it failed the \
                     plausibility gate:\n{}\ncompensation refuses it (fix the data or the robot \
                     and calibrate again, or give --accept-implausible to use it anyway)",
                    a.params.display(),
                    super::common::indent(&why)
                )));
            }
            errln!(
                "WARNING: --accept-implausible: compensating with {}, a result that FAILED the \
                 plausibility gate; the commanded joints may be far from right:\n{}",
                a.params.display(),
                super::common::indent(&why)
            )?;
        }
        if robocal_core::io::result_constraint::ConstraintSection::of(&res, &a.params)?
            .is_some_and(|s| !s.base_pose_known)
        {
            errln!(
                "note: {} is a constraint calibration, up to the base pose: targets are taken in \
                 the calibrated base frame, whose pose is the nominal one; positions are right \
                 relative to each other and to the constrained features, not absolutely",
                a.params.display()
            )?;
        }
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
    let dof = nominal.dof();
    let joints = nominal.joint_space();
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
    let mut full_pose = !position_only;
    let pb = crate::progress::spinner("compensating");
    let mut tally = Tally::default();
    let mut q = vec![0.0; dof];
    // Rows are solved and written one at a time: only the summary is kept, so files of any
    // length fit in memory.
    let (input, writer) = if let Some(path) = &joints_path {
        let context = || format!("--joints {}", path.display());
        let mut reader =
            MeasurementReader::open(path, joints, Positions::Optional).with_context(context)?;
        check_extra_columns(path, joints, reader.extra_columns())?;
        if reader.has_positions() {
            errln!(
                "note: {}: the x,y,z columns (measured positions) are not used or carried",
                path.display()
            )?;
        }
        let (columns, added) =
            conditions::direction_columns(reader.extra_columns(), dof, from_below);
        let mut w =
            CommandedWriter::to_output(outputs.open(&out)?, joints, true, full_pose, &columns)?;
        let mut outside = Listing::default();
        while let Some(r) = reader.next_row().with_context(context)? {
            nominal.check_joints(&r.q, &format!("{}:{}", path.display(), r.line))?;
            let o = nominal.joints_outside_limits(&r.q);
            if !o.is_empty() {
                let js: Vec<String> = o.iter().map(|i| format!("q{}", i + 1)).collect();
                outside.push(format!("line {} ({})", r.line, js.join(" ")));
            }
            let c = if full_pose {
                let (f, report) = comp.compensate_pose(&r.q, &mut q);
                Compensation {
                    desired_position: f.translation.vector,
                    desired_orientation: Some(f.rotation),
                    commanded: q.clone(),
                    report,
                }
            } else {
                let (p, report) = comp.compensate(&r.q, &mut q);
                Compensation {
                    desired_position: p,
                    desired_orientation: None,
                    commanded: q.clone(),
                    report,
                }
            };
            tally.add(&nominal, r.line, &c, Some(&r.q));
            w.write(
                &c,
                Some(&r.q),
                &conditions::with_directions(&r.extra, added),
            )?;
            tally.tick(&pb);
        }
        for warning in reader.finish().with_context(context)? {
            errln!("warning: {warning}")?;
        }
        if outside.count > 0 {
            errln!(
                "warning: {}: {} desired pose(s) outside the joint limits; solved from the \
                 nearest pose within them: {}",
                path.display(),
                outside.count,
                outside.text()
            )?;
        }
        (path, w)
    } else {
        let path = targets
            .as_ref()
            .expect("clap requires --joints or --targets");
        let set =
            read_targets(path, joints).with_context(|| format!("--targets {}", path.display()))?;
        check_extra_columns(path, joints, &set.extra_columns)?;
        if full_pose && !set.has_orientation {
            errln!(
                "note: {}: no a,b,c columns: the targets are positions, compensated position-only \
                 (orientation free, configuration not checked)",
                path.display()
            )?;
            full_pose = false;
        } else if position_only && set.has_orientation {
            errln!(
                "note: {}: --position-only: the a,b,c columns (orientations) are not used",
                path.display()
            )?;
        }
        let (columns, added) = conditions::direction_columns(&set.extra_columns, dof, from_below);
        let mut w =
            CommandedWriter::to_output(outputs.open(&out)?, joints, false, full_pose, &columns)?;
        for t in &set.rows {
            if let Some(s) = &t.seed {
                cal.check_joints(s, &format!("{}:{}", path.display(), t.line))?;
            }
            let c = match t.frame().filter(|_| full_pose) {
                Some(f) => Compensation {
                    desired_position: t.p,
                    desired_orientation: Some(f.rotation),
                    report: comp.reach_pose(&f, t.seed.as_deref(), &mut q),
                    commanded: q.clone(),
                },
                None => Compensation {
                    desired_position: t.p,
                    desired_orientation: None,
                    report: comp.reach(&t.p, t.seed.as_deref(), &mut q),
                    commanded: q.clone(),
                },
            };
            tally.add(&nominal, t.line, &c, None);
            w.write(&c, None, &conditions::with_directions(&t.extra, added))?;
            tally.tick(&pb);
        }
        (path, w)
    };
    pb.finish_and_clear();

    if tally.failed.count > 0 {
        if strict {
            // The writer is dropped: nothing is written.
            return Err(exit::numerical(format!(
                "--strict: {} of {} row(s) of {} did not converge; nothing written:\n  {}",
                tally.failed.count,
                tally.rows,
                input.display(),
                tally.failed.lines().join("\n  ")
            )));
        }
        for f in &tally.failed.items {
            errln!("warning: {}: {f}", input.display())?;
        }
        if tally.failed.count > LISTED {
            errln!(
                "warning: ... and {} more (see the status column of {})",
                tally.failed.count - LISTED,
                super::io_plan::shown(&out)
            )?;
        }
    }
    writer.commit()?;
    print_summary(
        joints_path.is_some(),
        full_pose,
        &params,
        (tolerance_mm, tolerance_deg),
        &out,
        input,
        &tally,
    )?;
    Ok(())
}

/// The first [`LISTED`] of a kind of row, and how many there are.
#[derive(Default)]
struct Listing {
    count: usize,
    items: Vec<String>,
}

impl Listing {
    fn push(&mut self, item: String) {
        self.count += 1;
        if self.items.len() < LISTED {
            self.items.push(item);
        }
    }

    /// The listed items, and a last line for the rest.
    fn lines(&self) -> Vec<String> {
        let mut v = self.items.clone();
        if self.count > v.len() {
            v.push(format!("... and {} more", self.count - v.len()));
        }
        v
    }

    fn text(&self) -> String {
        let mut s = self.items.join(", ");
        if self.count > self.items.len() {
            s.push_str(&format!(", ... ({} more)", self.count - self.items.len()));
        }
        s
    }
}

/// What the summary needs, gathered row by row.
#[derive(Default)]
struct Tally {
    rows: usize,
    counts: [usize; IkStatus::ALL.len()],
    failed: Listing,
    max_residual_converged: f64,
    max_residual: f64,
    max_residual_deg_converged: f64,
    max_residual_deg: f64,
    iterations: usize,
    max_iterations: usize,
    /// The largest joint change among converged rows, of revolute joints (degrees) and of
    /// prismatic ones (mm): (change, line, joint).
    max_change: [Option<(f64, usize, usize)>; 2],
}

impl Tally {
    fn add(&mut self, robot: &Robot, line: usize, c: &Compensation, desired: Option<&[f64]>) {
        let r = &c.report;
        self.rows += 1;
        if let Some(k) = IkStatus::ALL.iter().position(|s| *s == r.status) {
            self.counts[k] += 1;
        }
        self.max_residual = self.max_residual.max(r.residual_mm);
        self.max_residual_deg = self.max_residual_deg.max(r.residual_deg);
        self.iterations += r.iterations;
        self.max_iterations = self.max_iterations.max(r.iterations);
        if !r.status.is_converged() {
            self.failed.push(describe_failure(line, c));
            return;
        }
        self.max_residual_converged = self.max_residual_converged.max(r.residual_mm);
        self.max_residual_deg_converged = self.max_residual_deg_converged.max(r.residual_deg);
        if let Some(d) = desired {
            for (i, (qc, qd)) in c.commanded.iter().zip(d).enumerate() {
                let unit = robot.joint_unit(i);
                let ch = unit.from_internal((qc - qd).abs());
                let slot = &mut self.max_change[usize::from(unit == Unit::Mm)];
                if !matches!(slot, Some(b) if b.0 >= ch) {
                    *slot = Some((ch, line, i));
                }
            }
        }
    }

    fn tick(&self, pb: &indicatif::ProgressBar) {
        if self.rows % 4096 == 0 {
            pb.set_message(format!("compensating: {} rows", self.rows));
        }
    }
}

fn describe_failure(line: usize, c: &Compensation) -> String {
    let r = &c.report;
    let why = match r.status {
        IkStatus::JointLimit => {
            let js: Vec<String> = r.limited_joints().map(|i| format!("q{}", i + 1)).collect();
            format!(
                "reachable only beyond the joint limits (held at the limit: {})",
                js.join(" ")
            )
        }
        IkStatus::Unreachable => "outside the workspace of the calibrated model".to_owned(),
        IkStatus::NotConverged => format!("no convergence in {} iterations", r.iterations),
        IkStatus::ConfigurationChange => {
            "the pose is reached only on another configuration (shoulder, elbow or wrist) than \
             the desired one"
                .to_owned()
        }
        IkStatus::Singular => {
            "near a singularity (configuration undecided, large joint motions)".to_owned()
        }
        IkStatus::Converged => "converged".to_owned(),
    };
    if c.desired_orientation.is_some() {
        format!(
            "line {line}: {}: {why}; {:.4} mm and {:.4} deg from the target pose",
            r.status, r.residual_mm, r.residual_deg
        )
    } else {
        format!(
            "line {line}: {}: {why}; closest {:.4} mm from the target",
            r.status, r.residual_mm
        )
    }
}

/// Prints the summary of a run on `input` (desired joints if `joints`, else targets), solved on
/// the calibrated model of `params`, written to `out`.
fn print_summary(
    joints: bool,
    full_pose: bool,
    params: &std::path::Path,
    (tolerance_mm, tolerance_deg): (f64, f64),
    out: &std::path::Path,
    input: &std::path::Path,
    t: &Tally,
) -> anyhow::Result<()> {
    let mode = match (joints, full_pose) {
        (true, true) => "desired poses; target = nominal tool pose (eq. 13, full pose)",
        (true, false) => "desired poses; target = nominal tool position (eq. 13, position only)",
        (false, true) => "Cartesian targets (base frame, full pose)",
        (false, false) => "Cartesian targets (base frame, position only)",
    };
    outln!(
        "{}: {} {mode}; solved on the calibrated model of {}",
        input.display(),
        t.rows,
        params.display()
    )?;
    for (s, n) in IkStatus::ALL.iter().zip(t.counts) {
        outln!("  {:<14} {n:>8}", s.as_str())?;
    }
    outln!(
        "  residual       max {:.3e} mm over converged rows, {:.3e} mm over all (tolerance {:e} mm)",
        t.max_residual_converged, t.max_residual, tolerance_mm
    )?;
    if full_pose {
        outln!(
            "  orientation    max {:.3e} deg over converged rows, {:.3e} deg over all \
             (tolerance {:e} deg)",
            t.max_residual_deg_converged,
            t.max_residual_deg,
            tolerance_deg
        )?;
    }
    let it_mean = t.iterations as f64 / t.rows.max(1) as f64;
    outln!(
        "  iterations     mean {it_mean:.1}, max {}",
        t.max_iterations
    )?;
    for (m, unit) in t.max_change.iter().zip(["deg", "mm"]) {
        if let Some((ch, line, i)) = m {
            outln!(
                "  joint change   max {ch:.4} {unit} (line {line}, q{})",
                i + 1
            )?;
        }
    }
    outln!("wrote {} ({} rows)", super::io_plan::shown(out), t.rows)?;
    Ok(())
}
