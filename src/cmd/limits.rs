//! Limits of the count and size arguments. A count is a `usize` to clap, so
//! `--poses 18446744073709551615` parses; unchecked it would overflow a capacity computation (a
//! panic) or ask for an allocation the machine cannot give (an abort). These limits keep every run
//! within a machine of 2 cores and 24 GiB, the size robocal is built and tested on, with a clear
//! usage error beyond them (`simulate`'s and `plan`'s counts are checked by the library's
//! settings builders). Lengths of the CLI's own settings are held to the library's plausible
//! length (`robocal_core::ranges::LENGTH`); the library checks the settings it is given itself.

use crate::exit;

/// Most iterations of one inverse-kinematics solve in `compensate` (default 500; a solve
/// converges in a handful). The limit applies per row, and a file may have millions of rows.
pub const MAX_IK_ITERATIONS: usize = 100_000;

/// Largest length of a CLI setting (mm): the library's plausible length, 1 km.
pub const MAX_LENGTH_MM: f64 = robocal_core::ranges::LENGTH.max;

/// Checks that a finite `value` of `flag` is at most `max` in magnitude (`unit` for the
/// message). Non-finite and negative values are left to the checks of the setting itself.
pub fn magnitude(flag: &str, value: f64, max: f64, unit: &str) -> anyhow::Result<()> {
    if value.is_finite() && value.abs() > max {
        // 1e300 in full would be 301 digits.
        let shown = if value.abs() >= 1e15 {
            format!("{value:e}")
        } else {
            format!("{value}")
        };
        return Err(exit::usage(format!(
            "{flag} {shown}: at most {max} {unit} in magnitude"
        )));
    }
    Ok(())
}

/// Checks that `value` of `flag` is within `min..=max` (`what` says what the limit protects, for
/// the message).
pub fn count(flag: &str, value: usize, min: usize, max: usize, what: &str) -> anyhow::Result<()> {
    if value < min {
        return Err(exit::usage(format!(
            "{flag} {value}: must be at least {min}"
        )));
    }
    if value > max {
        return Err(exit::usage(format!(
            "{flag} {value}: at most {max} ({what})"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_outside_their_limits_are_usage_errors_naming_flag_and_limit() {
        assert!(count("--poses", 10_000_000, 0, 10_000_000, "memory").is_ok());
        let e = count("--poses", usize::MAX, 0, 10_000_000, "memory").unwrap_err();
        assert_eq!(crate::exit::code_for(&e), crate::exit::USAGE);
        let m = e.to_string();
        assert!(
            m.contains("--poses 18446744073709551615: at most 10000000"),
            "{m}"
        );
        let e = count("--max-iterations", 0, 1, 10, "time").unwrap_err();
        assert!(e.to_string().contains("at least 1"));
        let e = magnitude("--noise-mm", 1e300, MAX_LENGTH_MM, "mm").unwrap_err();
        assert_eq!(
            e.to_string(),
            "--noise-mm 1e300: at most 1000000 mm in magnitude"
        );
        assert!(magnitude("--noise-mm", -1e6, MAX_LENGTH_MM, "mm").is_ok());
        assert!(magnitude("--noise-mm", f64::INFINITY, MAX_LENGTH_MM, "mm").is_ok());
    }
}
