//! Helpers shared by the subcommands.

use anyhow::Context;
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::CalibrationResult;
use robocal_core::{load_robot_with, ChainSelection, Robot};
use std::path::Path;

/// `--base-link` and `--tip-link`: which chain of a URDF robot file to use. Global flags: they
/// apply to the `--robot` argument of whichever command is given.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ChainArgs {
    /// URDF robots: the link the robot starts at (its frame is the base frame) [default: the
    /// file's root link].
    #[arg(long, global = true, value_name = "LINK")]
    pub base_link: Option<String>,
    /// URDF robots: the link the robot ends at (its frame is the tool frame) [default: the only
    /// end of a chain with movable joints; required when the file holds several].
    #[arg(long, global = true, value_name = "LINK")]
    pub tip_link: Option<String>,
}

static CHAIN: std::sync::OnceLock<ChainSelection> = std::sync::OnceLock::new();

/// Records the command line's `--base-link`/`--tip-link` for [`robot`] (once, before any work).
pub fn set_chain(a: &ChainArgs) {
    let _ = CHAIN.set(ChainSelection {
        base_link: a.base_link.clone(),
        tip_link: a.tip_link.clone(),
    });
}

/// The robot of `--robot NAME|FILE` (for a URDF file, the chain of `--base-link`/`--tip-link`).
pub fn robot(arg: &str) -> anyhow::Result<Robot> {
    let chain = CHAIN.get().cloned().unwrap_or_default();
    if chain.is_given() && !robocal_core::io::robot::is_urdf_arg(arg) {
        let path = Path::new(arg);
        let urdf = path.is_file()
            && std::fs::read_to_string(path)
                .is_ok_and(|t| robocal_core::model::urdf::looks_like_urdf(&t));
        if !urdf {
            return Err(crate::exit::usage(format!(
                "--base-link and --tip-link choose the chain of a URDF robot; --robot {arg} is \
                 not a URDF file"
            )));
        }
    }
    load_robot_with(arg, &chain).with_context(|| format!("--robot {arg}"))
}

/// A nominal robot and, with `--params RESULT.json`, the calibrated one and its result.
pub struct Model {
    /// The nominal robot.
    pub nominal: Robot,
    /// The calibrated robot and the result it came from.
    pub calibrated: Option<(Robot, CalibrationResult)>,
}

impl Model {
    /// The calibrated robot if there is one, else the nominal.
    pub fn active(&self) -> &Robot {
        self.calibrated.as_ref().map_or(&self.nominal, |c| &c.0)
    }
}

/// Loads the nominal robot and, with `--params RESULT.json`, the calibrated one and its result.
/// See [`nominal_and_result`] for where the nominal robot comes from.
pub fn model(robot_arg: Option<&str>, params: Option<&Path>) -> anyhow::Result<Model> {
    let Some(p) = params else {
        let Some(arg) = robot_arg else {
            return Err(crate::exit::usage(
                "give --robot NAME|FILE, or --params RESULT.json with a result that embeds its \
                 robot",
            ));
        };
        return Ok(Model {
            nominal: robot(arg)?,
            calibrated: None,
        });
    };
    let (nominal, cal, res) = nominal_and_result(robot_arg, p, "--params")?;
    Ok(Model {
        nominal,
        calibrated: Some((cal, res)),
    })
}

/// The nominal robot, the calibrated one and the result of `result` (named `flag` in
/// messages), checked to belong together. The nominal robot is `--robot` when given, else the
/// one the result embeds; given both, they must agree (joints, convention, nominal parameters,
/// controller map; exit code 3 naming the first difference). A result without an embedded
/// robot (from an older robocal) needs `--robot` (exit code 2 without it).
pub fn nominal_and_result(
    robot_arg: Option<&str>,
    result: &Path,
    flag: &str,
) -> anyhow::Result<(Robot, Robot, CalibrationResult)> {
    let res = CalibrationResult::read(result)?;
    let embedded = res.robot.nominal_robot(result, None)?;
    let nominal = match (robot_arg, &embedded) {
        (Some(arg), _) => robot(arg)?,
        (None, Some(r)) => r.clone(),
        (None, None) => {
            return Err(crate::exit::usage(format!(
                "{flag} {}: the result does not embed its robot (written by an older robocal): \
                 give --robot NAME|FILE",
                result.display()
            )))
        }
    };
    let cal = res.calibrated_robot(&nominal, result)?;
    robocal_core::evaluation::check_result_nominal(&res, &nominal, result)?;
    if let (Some(arg), Some(emb)) = (robot_arg, &embedded) {
        if let Some(diff) = robocal_core::model::description::nominal_difference(emb, &nominal) {
            return Err(crate::exit::input(format!(
                "the robot embedded in {flag} {} (`{}`) and --robot {arg} (`{}`) disagree: \
                 {diff} (result against --robot); leave out --robot to use the result's own \
                 robot",
                result.display(),
                emb.name(),
                nominal.name()
            )));
        }
    }
    Ok((nominal, cal, res))
}

/// Parses `--joints q1,...,qn` (model joint values: degrees, or mm for a prismatic joint) into
/// internal units (radians or mm), checking count and finiteness.
pub fn joints_arg(s: &str, robot: &Robot) -> anyhow::Result<Vec<f64>> {
    let mut q = Vec::new();
    for (i, part) in s.split(',').enumerate() {
        let part = part.trim();
        let v: f64 = part.parse().map_err(|_| {
            crate::exit::usage(format!(
                "--joints: value {} `{part}` is not a number",
                i + 1
            ))
        })?;
        if !v.is_finite() {
            return Err(crate::exit::usage(format!(
                "--joints: value {} `{part}` is not a finite number",
                i + 1
            )));
        }
        // An angle (deg) or, for a prismatic joint, a length (mm), within its plausible range.
        let range = match robot.joint_types().get(i) {
            Some(robocal_core::JointType::Prismatic) => &robocal_core::ranges::LENGTH,
            _ => &robocal_core::ranges::JOINT,
        };
        if let Err(msg) = range.check(v) {
            return Err(crate::exit::usage(format!(
                "--joints: value {}: {msg}",
                i + 1
            )));
        }
        q.push(v);
    }
    if q.len() != robot.dof() {
        return Err(crate::exit::usage(format!(
            "--joints: robot `{}` has {} joints, got {} values",
            robot.name(),
            robot.dof(),
            q.len()
        )));
    }
    Ok(robot.joints_from_display(&q))
}

/// Warns (stderr) when a result file is not a calibration: a partial result (`calibrate
/// --keep-partial` after the solver did not converge) or an implausible one (`calibrate
/// --accept-implausible` after the fit failed the plausibility gate).
pub fn warn_not_calibrated(res: &CalibrationResult, path: &Path) -> anyhow::Result<()> {
    use robocal_core::io::result::NotCalibrated;
    match res.not_calibrated() {
        Some(NotCalibrated::Partial(why)) => errln!(
            "warning: {} is a PARTIAL result, not a calibration ({why})",
            path.display()
        )?,
        Some(NotCalibrated::Implausible(why)) => errln!(
            "warning: {} is an IMPLAUSIBLE result, not a calibration: it failed the \
             plausibility gate and was kept with --accept-implausible:\n{}",
            path.display(),
            indent(&why)
        )?,
        None => {}
    }
    Ok(())
}

/// Indents every line of `text` by four spaces.
pub fn indent(text: &str) -> String {
    text.lines()
        .map(|l| format!("    {l}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Refuses rows outside the joint limits (exit code 3), or with `--nominal-limits` warns about
/// them and keeps them in `outside` for the result.
pub fn check_limits(
    o: OutsideLimits,
    nominal_limits: bool,
    outside: &mut Vec<OutsideLimits>,
) -> anyhow::Result<()> {
    if nominal_limits {
        if let Some(w) = o.to_warning() {
            errln!("warning: {w} (used anyway: --nominal-limits)")?;
            outside.push(o);
        }
        return Ok(());
    }
    match o.to_error() {
        None => Ok(()),
        Some(e) => Err(crate::exit::input(format!(
            "{e}; if the robot's limits are only nominal, give --nominal-limits to use these rows"
        ))),
    }
}

/// Applies `--payload-kg` of `evaluate` and `compensate` to the calibrated model: the payload
/// now carried, for a calibration whose joint compliances were identified at a known payload
/// (`calibrate --payload-kg`). Without the flag the model keeps the calibration's payload.
pub fn apply_payload(calibrated: &mut Robot, payload_kg: Option<f64>) -> anyhow::Result<()> {
    let Some(m) = payload_kg else {
        return Ok(());
    };
    robocal_core::model::family::compliance::set_payload_kg(calibrated, m)
        .map_err(|e| crate::exit::usage(crate::cmd::flags::cli_text(&e)))
}
