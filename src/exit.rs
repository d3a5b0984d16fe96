//! Exit codes (documented in README.md).

/// Success.
pub const OK: i32 = 0;
/// An unexpected internal failure.
pub const INTERNAL: i32 = 1;
/// Bad command-line usage (clap uses this code too).
pub const USAGE: i32 = 2;
/// Bad input data: a malformed or inconsistent file or value.
pub const INPUT: i32 = 3;
/// A file could not be read or written.
pub const IO: i32 = 4;
/// A numerical failure: no convergence, too few points, unidentifiable model.
pub const NUMERICAL: i32 = 5;
/// A fit that converged but cannot be right (the plausibility gate: units, handedness, wrong
/// robot, parameter moves beyond calibration): nothing written unless explicitly accepted.
pub const IMPLAUSIBLE: i32 = 6;
/// A measurement that is valid but fails the acceptance limits it was given (`iso9283 evaluate
/// --spec`): its figures are printed as on a pass, and the code says it failed.
pub const REJECTED: i32 = 7;
/// Interrupted by SIGINT/SIGTERM (128 + signal number for SIGINT, as shells report it).
#[cfg_attr(not(unix), allow(dead_code))]
pub const INTERRUPTED: i32 = 130;

/// An error raised by the CLI itself with an explicit exit code.
#[derive(Debug)]
pub struct CliError {
    /// The exit code.
    pub code: i32,
    /// The message.
    pub message: String,
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

/// A usage error (exit code 2).
pub fn usage(message: impl Into<String>) -> anyhow::Error {
    CliError {
        code: USAGE,
        message: message.into(),
    }
    .into()
}

/// A bad-input error (exit code 3).
#[allow(dead_code)]
pub fn input(message: impl Into<String>) -> anyhow::Error {
    CliError {
        code: INPUT,
        message: message.into(),
    }
    .into()
}

/// A numerical failure (exit code 5).
#[allow(dead_code)]
pub fn numerical(message: impl Into<String>) -> anyhow::Error {
    CliError {
        code: NUMERICAL,
        message: message.into(),
    }
    .into()
}

/// An implausible fit (exit code 6).
pub fn implausible(message: impl Into<String>) -> anyhow::Error {
    CliError {
        code: IMPLAUSIBLE,
        message: message.into(),
    }
    .into()
}

/// A test that failed its acceptance limits (exit code 7).
pub fn rejected(message: impl Into<String>) -> anyhow::Error {
    CliError {
        code: REJECTED,
        message: message.into(),
    }
    .into()
}

/// The message of an error and its causes, outermost first, joined by `: `, with the library's
/// setting names shown as this program's flags (`cmd::flags`). A cause whose text
/// the message already ends with is left out (an I/O error is part of its wrapper's text:
/// `FILE: No such file or directory`, not `FILE: No such file...: No such file...`).
pub fn message(e: &anyhow::Error) -> String {
    let mut s = String::new();
    for cause in e.chain() {
        let c = crate::cmd::flags::cli_text(cause);
        if s.ends_with(&c) {
            continue;
        }
        if !s.is_empty() {
            s.push_str(": ");
        }
        s.push_str(&c);
    }
    s
}

/// The exit code for an error: the first robocal error in its chain decides.
pub fn code_for(e: &anyhow::Error) -> i32 {
    use robocal_core::Error as E;
    for cause in e.chain() {
        if let Some(c) = cause.downcast_ref::<CliError>() {
            return c.code;
        }
        if let Some(c) = cause.downcast_ref::<E>() {
            return match c {
                E::Io { .. } => IO,
                E::Parse { .. }
                | E::Invalid { .. }
                | E::UnknownParameter { .. }
                | E::JointCount { .. } => INPUT,
                E::UnknownPreset { .. } | E::Usage { .. } => USAGE,
                E::Numerical(_) => NUMERICAL,
                E::Implausible(_) => IMPLAUSIBLE,
            };
        }
        if cause.downcast_ref::<std::io::Error>().is_some() {
            return IO;
        }
    }
    INTERNAL
}
