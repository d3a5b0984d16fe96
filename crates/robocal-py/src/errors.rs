//! The library's errors as Python exceptions.
//!
//! One base class, `robocal.RobocalError`, and one subclass per family of the CLI's exit codes
//! (README, "Exit codes"), so a script can catch what it can handle: `UsageError` (2, a bad
//! argument), `InputError` (3, bad data: a wrong shape, dtype or value), `FileError` (4, a file could
//! not be read or written), `NumericalError` (5), `ImplausibleError` (6). Each carries the
//! library's message, with the settings it names shown as this module's keyword arguments (the
//! CLI shows its flags there).

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use robocal_core::Error as E;

create_exception!(
    robocal,
    RobocalError,
    PyException,
    "Every error robocal raises: its `exit_code` attribute is the CLI's exit code for it."
);
create_exception!(
    robocal,
    UsageError,
    RobocalError,
    "A bad argument (the CLI's exit code 2)."
);
create_exception!(
    robocal,
    InputError,
    RobocalError,
    "Bad input data: a malformed or inconsistent array, file or value (exit code 3)."
);
create_exception!(
    robocal,
    FileError,
    RobocalError,
    "A file could not be read or written (exit code 4)."
);
create_exception!(
    robocal,
    NumericalError,
    RobocalError,
    "A numerical failure: no convergence, too few points, an unidentifiable model (exit code 5)."
);
create_exception!(
    robocal,
    ImplausibleError,
    RobocalError,
    "A fit that converged but cannot be a calibration: the plausibility gate (exit code 6)."
);

/// Library setting -> the keyword argument of this module that sets it.
const KEYWORDS: &[(&str, &str)] = &[
    ("identifiability.fix", "fix"),
    ("identifiability.free", "free"),
    ("identifiability.rank_tolerance", "rank_tol"),
    ("robust_scale_mm", "robust_scale"),
    ("weighting.tracker", "tracker_sigma"),
    ("weighting.mm_per_deg", "orientation_weight"),
    ("solver.max_iterations", "max_iterations"),
    ("validation_refit_frame", "validate_refit_frame"),
    ("orientation_mm_per_deg", "orientation_weight"),
    ("payload_kg", "payload_kg"),
    ("compliance", "compliance"),
    ("harmonics", "harmonics"),
    ("max_iterations", "max_iterations"),
    // simulation::SimulationConfig (robocal.simulate)
    ("tracker_frame", "tracker"),
    ("floor_z_mm", "floor_mm"),
    ("footprint_radius_mm", "footprint_mm"),
    ("plane_points", "plane"),
    ("validation_poses", "validation"),
    ("truth.tilt_parallel_axes", "tilt_parallel_axes"),
    ("truth.length_sigma_mm", "length_error_mm"),
    ("truth.angle_sigma_deg", "angle_error_deg"),
    ("gravity.compliance_rad_per_nm", "compliance"),
    ("gravity.link_masses_kg", "link_masses_kg"),
    ("gravity.payload_kg", "payload_kg"),
    ("outliers.fraction", "outlier_fraction"),
    ("outliers.min_mm", "outlier_min_mm"),
    ("outliers.max_mm", "outlier_max_mm"),
    ("targets", "all_targets"),
    // planning::PlanSettings (robocal.plan)
    ("tracker_range", "range_mm"),
    // io::import::ImportConfig (robocal.import_measurements)
    ("time_offset_s", "time_offset"),
    ("time_tolerance_s", "time_tolerance"),
    ("dwell.still_deg", "still_deg"),
    ("dwell.min_s", "dwell_min_s"),
    // iso9283::PlanSettings, plan_program (robocal.iso9283_plan)
    ("edge_mm", "cube_mm"),
    ("centre_mm", "center"),
    ("orientation_deg", "orientation"),
];

/// Phrases the library uses for a setting that is no field of its settings structs.
const PHRASES: &[(&str, &str)] = &[("rank tolerance", "rank tolerance (`rank_tol`)")];

/// `text` with every setting named in backticks replaced by its keyword argument.
pub fn with_keywords(text: &str) -> String {
    let mut out = text.to_owned();
    for (setting, kw) in KEYWORDS {
        let quoted = format!("`{setting}`");
        if out.contains(&quoted) {
            out = out.replace(&quoted, &format!("`{kw}`"));
        }
    }
    out
}

/// The message of a library error as a Python user should read it (see the module docs).
pub fn message(e: &E) -> String {
    let text = match e {
        E::Invalid { field, message } | E::Usage { field, message } => {
            let f = KEYWORDS
                .iter()
                .find(|(s, _)| s == field)
                .map_or(field.as_str(), |(_, k)| k);
            format!("{f}: {}", with_keywords(message))
        }
        E::Numerical(m) | E::Implausible(m) => PHRASES
            .iter()
            .fold(with_keywords(m), |t, (p, r)| t.replace(p, r)),
        other => other.to_string(),
    };
    text
}

/// The CLI's exit code for a library error (the same table as `src/exit.rs`).
pub fn exit_code(e: &E) -> i32 {
    match e {
        E::Io { .. } => 4,
        E::Parse { .. } | E::Invalid { .. } | E::UnknownParameter { .. } | E::JointCount { .. } => {
            3
        }
        E::UnknownPreset { .. } | E::Usage { .. } => 2,
        E::Numerical(_) => 5,
        E::Implausible(_) => 6,
    }
}

/// A Python exception of the family of exit code `code` with `message`.
pub fn raise(code: i32, message: impl Into<String>) -> PyErr {
    let m = message.into();
    let err = match code {
        2 => UsageError::new_err(m),
        3 => InputError::new_err(m),
        4 => FileError::new_err(m),
        5 => NumericalError::new_err(m),
        6 => ImplausibleError::new_err(m),
        _ => RobocalError::new_err(m),
    };
    Python::attach(|py| {
        // The exit code as an attribute; setting it cannot fail on a fresh exception.
        let _ = err.value(py).setattr("exit_code", code);
    });
    err
}

/// A bad argument (exit code 2).
pub fn usage(message: impl Into<String>) -> PyErr {
    raise(2, message)
}

/// Bad input data (exit code 3).
pub fn input(message: impl Into<String>) -> PyErr {
    raise(3, message)
}

/// A library error as its Python exception.
pub fn to_py(e: E) -> PyErr {
    raise(exit_code(&e), message(&e))
}

/// `Result<T, robocal_core::Error>` -> `PyResult<T>`.
pub trait IntoPy<T> {
    /// The error as its Python exception.
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for robocal_core::Result<T> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("RobocalError", py.get_type::<RobocalError>())?;
    m.add("UsageError", py.get_type::<UsageError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("FileError", py.get_type::<FileError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("ImplausibleError", py.get_type::<ImplausibleError>())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_named_as_keywords() {
        let e = E::invalid(
            "identifiability.fix",
            "`d2` is given both to `identifiability.fix` and to `identifiability.free`",
        );
        assert_eq!(
            message(&e),
            "fix: `d2` is given both to `fix` and to `free`"
        );
        let e = E::Numerical("raise the rank tolerance".into());
        assert_eq!(message(&e), "raise the rank tolerance (`rank_tol`)");
        assert_eq!(exit_code(&e), 5);
        // Fields that are not settings stay as they are.
        let e = E::invalid("calibration data", "no calibration points");
        assert_eq!(message(&e), "calibration data: no calibration points");
    }
}
