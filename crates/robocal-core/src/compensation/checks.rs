//! The checks the inverse-kinematics solvers' settings share (one place for their wording).

use crate::error::{Error, Result};

/// `v` is a positive finite number, or an error naming setting `name`.
pub(crate) fn positive(name: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            format!("{v} must be a positive number"),
        ))
    }
}

/// At least one iteration and a stationary cosine in (0, 1).
pub(crate) fn iterations_and_stationary(
    max_iterations: usize,
    stationary_cosine: f64,
) -> Result<()> {
    if max_iterations == 0 {
        return Err(Error::invalid("max_iterations", "must be at least 1"));
    }
    if !(stationary_cosine > 0.0 && stationary_cosine < 1.0) {
        return Err(Error::invalid(
            "stationary_cosine",
            format!("{stationary_cosine} must lie in (0, 1)"),
        ));
    }
    Ok(())
}
