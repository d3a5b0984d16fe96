//! The options of `robocal.calibrate`, turned into the library's `CalibrationSettings` and model
//! families and checked by the library (`CalibrationSettings::check`, as the CLI's flags are)
//! before any work.

use crate::errors::{usage, IntoPy};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::identification::{
    AutoFamilies, CalibrationSettings, IdentifiabilityOptions, ModelChoice, Objective, RobustLoss,
    SolverOptions, DEFAULT_RANK_TOLERANCE,
};
use robocal_core::model::family::{backlash, compliance, thermal, transmission};
use robocal_core::observations::{TrackerSigma, Weighting};
use robocal_core::{Param, Robot};

/// Everything `calibrate` takes beside the data.
#[derive(Debug, Clone)]
pub struct Options {
    /// The library's settings.
    pub settings: CalibrationSettings,
    /// Use rows outside the joint limits (with a warning).
    pub nominal_limits: bool,
    /// Return a result of a solver that did not converge, marked partial.
    pub keep_partial: bool,
    /// Return a converged fit that failed the plausibility gate, marked implausible.
    pub accept_implausible: bool,
    /// Notes for the caller (shown as Python warnings).
    pub notes: Vec<String>,
}

/// The known option names (the keyword arguments of `robocal.calibrate`).
const KNOWN: &[&str] = &[
    "objective",
    "robust_loss",
    "robust_scale",
    "fix",
    "free",
    "beta",
    "compliance",
    "payload_kg",
    "harmonics",
    "backlash",
    "thermal",
    "model",
    "affine",
    "rank_tol",
    "max_iterations",
    "keep_partial",
    "accept_implausible",
    "tracker_sigma",
    "orientation_weight",
    "validate_refit_frame",
    "nominal_limits",
];

/// Reads option `key` of `d`, `None` when absent or None.
fn opt<'py, T: FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    key: &str,
    what: &str,
) -> PyResult<Option<T>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v
            .extract::<T>()
            .map(Some)
            .map_err(|_| usage(format!("{key}: expected {what}, got {}", describe(&v)))),
    }
}

/// A value as Python shows it, shortened.
pub fn describe(v: &Bound<'_, PyAny>) -> String {
    let r = v.repr().map(|s| s.to_string()).unwrap_or_default();
    let t = v
        .get_type()
        .name()
        .map(|s| s.to_string())
        .unwrap_or_default();
    let r: String = r.chars().take(60).collect();
    format!("{r} ({t})")
}

/// A list option: a comma-separated string or a sequence of strings.
fn names(d: &Bound<'_, PyDict>, key: &str) -> PyResult<Vec<String>> {
    let Some(v) = d.get_item(key)? else {
        return Ok(Vec::new());
    };
    if v.is_none() {
        return Ok(Vec::new());
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(s.split(',').map(|p| p.trim().to_owned()).collect());
    }
    v.extract::<Vec<String>>().map_err(|_| {
        usage(format!(
            "{key}: expected parameter names (a list of str, or one comma-separated str), got {}",
            describe(&v)
        ))
    })
}

/// A joint selection: a keyword (`none`, `parallel`/`auto`), a comma-separated string or a
/// sequence of 1-based joint numbers; returned as text the CLI's parser reads.
fn joint_selection(d: &Bound<'_, PyDict>, key: &str) -> PyResult<String> {
    let Some(v) = d.get_item(key)? else {
        return Ok("none".into());
    };
    if v.is_none() {
        return Ok("none".into());
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(s);
    }
    if let Ok(js) = v.extract::<Vec<i64>>() {
        if js.is_empty() {
            return Ok("none".into());
        }
        return Ok(js
            .iter()
            .map(|j| j.to_string())
            .collect::<Vec<_>>()
            .join(","));
    }
    Err(usage(format!(
        "{key}: expected a keyword or a list of joint numbers (from 1), got {}",
        describe(&v)
    )))
}

/// 1-based joint numbers of a list, checked against the robot.
fn joint_numbers(robot: &Robot, list: &str, key: &str, keywords: &str) -> PyResult<Vec<usize>> {
    let mut out = Vec::new();
    for part in list.split(',') {
        let j: usize = part.trim().parse().map_err(|_| {
            usage(format!(
                "{key}: `{part}` is not {keywords} or a joint number"
            ))
        })?;
        if j == 0 || j > robot.dof() {
            return Err(usage(format!(
                "{key}: joint {j} does not exist (robot `{}` has joints 1..{})",
                robot.name(),
                robot.dof()
            )));
        }
        if !out.contains(&(j - 1)) {
            out.push(j - 1);
        }
    }
    Ok(out)
}

/// Parses a list of parameter names, naming every unknown one at once.
fn param_list(robot: &Robot, names: &[String], key: &str) -> PyResult<Vec<Param>> {
    let mut out = Vec::new();
    let mut unknown = Vec::new();
    for n in names.iter().map(|n| n.trim()).filter(|n| !n.is_empty()) {
        match robot.param_by_name(n) {
            Ok(p) if !out.contains(&p) => out.push(p),
            Ok(_) => {}
            Err(_) => unknown.push(format!("`{n}`")),
        }
    }
    if !unknown.is_empty() {
        let known: Vec<String> = robot.params().iter().map(|p| p.name()).collect();
        return Err(usage(format!(
            "{key}: unknown parameter{} {} (robot `{}` has: {})",
            if unknown.len() > 1 { "s" } else { "" },
            unknown.join(", "),
            robot.name(),
            known.join(", ")
        )));
    }
    Ok(out)
}

/// Checks the options of `d` and applies the model families they enable (`beta`,
/// `compliance`, `payload_kg`, `harmonics`) to `robot`.
pub fn parse(robot: &mut Robot, d: &Bound<'_, PyDict>) -> PyResult<Options> {
    check_known(d)?;
    let mut notes = Vec::new();
    let objective = objective(d)?;
    let robust_scale: Option<f64> = opt(d, "robust_scale", "a number (mm)")?;
    let max_iterations: i64 = opt(d, "max_iterations", "an int")?.unwrap_or(1000);
    // The library checks the range (`CalibrationSettings::check`); a negative int is no count.
    let max_iterations = usize::try_from(max_iterations)
        .map_err(|_| usage(format!("max_iterations: at least 1, got {max_iterations}")))?;
    enable_families(robot, d, &mut notes)?;
    let fix = param_list(robot, &names(d, "fix")?, "fix")?;
    let free = param_list(robot, &names(d, "free")?, "free")?;
    let rank_tol: Option<f64> = opt(d, "rank_tol", "a number")?;
    let rank_tolerance = rank_tol.unwrap_or(DEFAULT_RANK_TOLERANCE);
    let weighting = weighting(d)?;
    let flag = |k: &str| -> PyResult<bool> { Ok(opt::<bool>(d, k, "a bool")?.unwrap_or(false)) };
    let model = model_choice(d)?;
    let settings = CalibrationSettings {
        objective,
        robust_scale_mm: robust_scale,
        affine_registration: flag("affine")?,
        identifiability: IdentifiabilityOptions {
            rank_tolerance,
            fix,
            free,
            allow_ill_conditioned: rank_tol.is_some(),
        },
        solver: SolverOptions {
            max_iterations,
            ..Default::default()
        },
        weighting,
        validation_refit_frame: flag("validate_refit_frame")?,
        model,
    };
    // The one check of the settings, as the CLI's (the library names the setting; the error
    // shows it as this module's keyword).
    settings.check(robot).py_err()?;
    Ok(Options {
        settings,
        nominal_limits: flag("nominal_limits")?,
        keep_partial: flag("keep_partial")?,
        accept_implausible: flag("accept_implausible")?,
        notes,
    })
}

/// Refuses a keyword that is no option of `robocal.calibrate`.
fn check_known(d: &Bound<'_, PyDict>) -> PyResult<()> {
    for k in d.keys() {
        let k: String = k.extract()?;
        if !KNOWN.contains(&k.as_str()) {
            return Err(usage(format!(
                "unknown option `{k}` (known: {})",
                KNOWN.join(", ")
            )));
        }
    }
    Ok(())
}

/// `objective` and `robust_loss`.
fn objective(d: &Bound<'_, PyDict>) -> PyResult<Objective> {
    let objective: String = opt(d, "objective", "a str")?.unwrap_or_else(|| "adaptive".into());
    let robust_loss: String = opt(d, "robust_loss", "a str")?.unwrap_or_else(|| "cauchy".into());
    let robust = match robust_loss.replace('_', "-").as_str() {
        "cauchy" => RobustLoss::Cauchy,
        "huber" => RobustLoss::Huber,
        other => {
            return Err(usage(format!(
                "robust_loss: `{other}` is not `cauchy` or `huber`"
            )))
        }
    };
    Ok(match objective.replace('_', "-").as_str() {
        "adaptive" => Objective::Adaptive,
        "sum-of-norms" => Objective::SumOfNorms,
        "least-squares" => Objective::LeastSquares,
        "robust" => Objective::Robust(robust),
        other => {
            return Err(usage(format!(
                "objective: `{other}` is not `adaptive`, `sum-of-norms`, `least-squares` or \
                 `robust`"
            )))
        }
    })
}

/// The model families given (`beta`, `compliance` with `payload_kg`, `harmonics`, `backlash`,
/// `thermal`), enabled on `robot`, in the CLI's order; `notes` tells of a family that adds
/// nothing to this robot.
fn enable_families(
    robot: &mut Robot,
    d: &Bound<'_, PyDict>,
    notes: &mut Vec<String>,
) -> PyResult<()> {
    let beta = joint_selection(d, "beta")?;
    match beta.trim() {
        "none" | "" => {}
        "parallel" => {
            if robot.enable_beta_for_parallel_axes().is_empty() {
                notes.push(format!(
                    "beta=\"parallel\": robot `{}` has no pair of consecutive parallel axes; no \
                     tilt parameter added",
                    robot.name()
                ));
            }
        }
        list => {
            let js = joint_numbers(robot, list, "beta", "`parallel`, `none`")?;
            for &j in &js {
                robot.enable_beta(j).py_err()?;
            }
        }
    }
    let comp = joint_selection(d, "compliance")?;
    let mut joints = match comp.trim() {
        "none" | "" => Vec::new(),
        "auto" => {
            let j = compliance::auto_joints(robot);
            if j.is_empty() {
                notes.push(format!(
                    "compliance=\"auto\": no joint of robot `{}` turns under gravity (every axis \
                     is parallel to its `gravity`); no compliance added",
                    robot.name()
                ));
            }
            j
        }
        list => joint_numbers(robot, list, "compliance", "`auto`, `none`")?,
    };
    joints.sort_unstable();
    let payload_kg: Option<f64> = opt(d, "payload_kg", "a number (kg)")?;
    if payload_kg.is_some() && joints.is_empty() {
        return Err(usage(
            "payload_kg: the payload makes the joint compliances physical; give compliance=\"auto\" \
             or a list of joints too",
        ));
    }
    if !joints.is_empty() {
        compliance::enable(robot, &joints, payload_kg)
            .map_err(|e| usage(crate::errors::message(&e)))?;
    }
    let harmonics: i64 = opt(d, "harmonics", "an int")?.unwrap_or(0);
    if !(0..=transmission::MAX_HARMONICS as i64).contains(&harmonics) {
        return Err(usage(format!(
            "harmonics: {harmonics}: from 0 to {} harmonics per joint",
            transmission::MAX_HARMONICS
        )));
    }
    let all: Vec<usize> = (0..robot.dof()).collect();
    transmission::enable(robot, &all, harmonics as usize)
        .map_err(|e| usage(crate::errors::message(&e)))?;
    // The real cell's families (the CLI's --backlash and --thermal); the thermal reference is
    // set from the data when the calibration runs.
    let backlash_joints = match joint_selection(d, "backlash")?.trim() {
        "none" | "" => Vec::new(),
        "auto" => all.clone(),
        list => joint_numbers(robot, list, "backlash", "`auto`, `none`")?,
    };
    backlash::enable(robot, &backlash_joints).map_err(|e| usage(crate::errors::message(&e)))?;
    match opt::<String>(d, "thermal", "a str")?.as_deref() {
        None | Some("none") => {}
        Some("auto") => thermal::enable(robot, thermal::DEFAULT_REFERENCE_C)
            .map_err(|e| usage(crate::errors::message(&e)))?,
        Some("per-link") => thermal::enable_per_link(robot, thermal::DEFAULT_REFERENCE_C)
            .map_err(|e| usage(crate::errors::message(&e)))?,
        Some(other) => {
            return Err(usage(format!(
                "thermal: {other:?}: expected \"auto\", \"per-link\" or \"none\""
            )))
        }
    }

    Ok(())
}

/// `tracker_sigma` (or "off") and `orientation_weight`.
fn weighting(d: &Bound<'_, PyDict>) -> PyResult<Weighting> {
    let mut weighting = Weighting::default();
    // "off": every point weighs the same, even data in a tracker's frame.
    let off = match d.get_item("tracker_sigma")? {
        Some(v) => v.extract::<String>().is_ok_and(|s| s == "off"),
        None => false,
    };
    if off {
        weighting.automatic = false;
    }
    let tracker_sigma: Option<Vec<f64>> = if off {
        None
    } else {
        opt(d, "tracker_sigma", "(fixed_mm, per_m_mm) or \"off\"")?
    };
    if let Some(ts) = tracker_sigma {
        let [fixed, per_m] = ts[..] else {
            return Err(usage(format!(
                "tracker_sigma: expected two numbers (fixed_mm, per_m_mm), got {}",
                ts.len()
            )));
        };
        weighting.tracker = Some(TrackerSigma::new(fixed, per_m).map_err(|_| {
            usage(format!(
                "tracker_sigma: ({fixed}, {per_m}): expected (fixed_mm, per_m_mm), both \
                 non-negative and at most 1000, not both zero (e.g. (0.0075, 0.003))"
            ))
        })?);
    }
    if let Some(m) = opt::<f64>(d, "orientation_weight", "a number (mm per degree)")? {
        weighting.mm_per_deg = m;
    }
    Ok(weighting)
}

/// `model`: "auto" (default, as the CLI) chooses the families not given explicitly.
fn model_choice(d: &Bound<'_, PyDict>) -> PyResult<ModelChoice> {
    let given = |k: &str| -> PyResult<bool> { Ok(d.get_item(k)?.is_some_and(|v| !v.is_none())) };
    Ok(
        match opt::<String>(d, "model", "a str")?
            .as_deref()
            .unwrap_or("auto")
        {
            "auto" => ModelChoice::Auto(AutoFamilies {
                harmonics: !given("harmonics")?,
                compliance: !given("compliance")?,
                backlash: !given("backlash")?,
                thermal: !given("thermal")?,
            }),
            "geometric" => ModelChoice::Given,
            other => {
                return Err(usage(format!(
                    "model: {other:?}: expected \"auto\" or \"geometric\""
                )))
            }
        },
    )
}
