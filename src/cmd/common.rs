//! Helpers shared by the subcommands.

use anyhow::Context;
use robocal_core::io::CalibrationResult;
use robocal_core::{load_robot, Robot};
use std::path::Path;

/// The robot of `--robot NAME|FILE`.
pub fn robot(arg: &str) -> anyhow::Result<Robot> {
    load_robot(arg).with_context(|| format!("--robot {arg}"))
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

/// Loads `--robot` and optional `--params`.
pub fn model(robot_arg: &str, params: Option<&Path>) -> anyhow::Result<Model> {
    let nominal = robot(robot_arg)?;
    let calibrated = match params {
        None => None,
        Some(p) => {
            let res = CalibrationResult::read(p)?;
            let cal = res.calibrated_robot(&nominal, p)?;
            robocal_core::evaluation::check_result_nominal(&res, &nominal, p)?;
            Some((cal, res))
        }
    };
    Ok(Model {
        nominal,
        calibrated,
    })
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

/// Checks an output path before any work: its directory must exist, it must not be a directory,
/// and it must not be one of the `inputs` (a failed or finished run must never destroy its own
/// input). Exit code 4 (I/O) for the first two, 2 (usage) for the last.
pub fn check_output(flag: &str, out: &Path, inputs: &[&Path]) -> anyhow::Result<()> {
    let io = |msg: String| -> anyhow::Error {
        anyhow::Error::from(robocal_core::Error::Io {
            path: out.to_owned(),
            source: std::io::Error::other(msg),
        })
        .context(flag.to_owned())
    };
    if out.is_dir() {
        return Err(io("is a directory, expected a file path".into()));
    }
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(io(format!("directory {} does not exist", dir.display())));
    }
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    };
    if let Some(i) = inputs.iter().find(|i| same(out, i)) {
        return Err(crate::exit::usage(format!(
            "{flag} {}: this is also an input ({}); write the output to another file",
            out.display(),
            i.display()
        )));
    }
    Ok(())
}

/// Warns (stderr) when a result file is a partial result (`calibrate --keep-partial` after the
/// solver did not converge), which is not a calibration.
pub fn warn_partial(res: &CalibrationResult, path: &Path) {
    if let Some(why) = res.partial_reason() {
        eprintln!(
            "warning: {} is a PARTIAL result, not a calibration ({why})",
            path.display()
        );
    }
}
