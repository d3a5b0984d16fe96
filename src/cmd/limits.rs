//! Limits of the count and size arguments. A count is a `usize` to clap, so
//! `--poses 18446744073709551615` parses; unchecked it would overflow a capacity computation (a
//! panic) or ask for an allocation the machine cannot give (an abort). These limits keep every run
//! within a machine of 2 cores and 24 GiB, the size robocal is built and tested on, with a clear
//! usage error beyond them. Lengths of the CLI's own settings are held to the library's plausible
//! length (`robocal_core::ranges::LENGTH`); the library checks the settings it is given itself.

use crate::exit;

/// Most poses one `simulate` run draws (calibration + validation). Measured: 1,000,000 poses take
/// 0.5 GB of memory and 9 s and write a 139 MB CSV, so 10,000,000 need about 5 GB, 1.5 minutes
/// and 1.4 GB of disk: still a fraction of the machine, and far beyond any real calibration
/// (the paper uses 75 + 73). Larger sets: several runs with different seeds.
pub const MAX_POSES: usize = 10_000_000;

/// Most solver iterations of `calibrate`. It converges in 5 to 350 iterations (README,
/// "Calibrating"); a million iterations of a 75-point problem already run for tens of minutes,
/// and a solver that has not converged by then will not.
pub const MAX_CALIBRATION_ITERATIONS: usize = 1_000_000;

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
        assert!(count("--poses", 10_000_000, 0, MAX_POSES, "memory").is_ok());
        let e = count("--poses", usize::MAX, 0, MAX_POSES, "memory").unwrap_err();
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
