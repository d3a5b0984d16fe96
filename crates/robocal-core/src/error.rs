//! The library's error type: one enum whose variants carry the context a user needs to fix the
//! input (file, line, field, value).

use std::path::PathBuf;

/// Everything that can go wrong in robocal-core.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A file's content is malformed. `line` is 1-based where known.
    #[error("{}", fmt_parse(.path, *.line, .field, .message))]
    Parse {
        /// The file (or a description such as `<robot preset>`).
        path: PathBuf,
        /// The 1-based line, where known.
        line: Option<usize>,
        /// The field or column, where known.
        field: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// An argument or a value of the model is invalid.
    #[error("{field}: {message}")]
    Invalid {
        /// The offending field or argument.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A setting given where it does not apply (a random truth's error sizes with a truth
    /// robot), or a count outside what one run may ask: the call itself is wrong, as a
    /// command line's usage error.
    #[error("{field}: {message}")]
    Usage {
        /// The offending setting.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A preset name that does not exist.
    #[error("unknown robot preset `{name}` (known presets: {known}); or give a path to a TOML robot file")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The known presets, comma-separated.
        known: String,
    },
    /// A parameter name that does not exist for this robot.
    #[error("unknown parameter `{name}` (this robot has: {known})")]
    UnknownParameter {
        /// The name asked for.
        name: String,
        /// The robot's parameter names.
        known: String,
    },
    /// A joint vector whose length does not match the robot.
    #[error("{context}: expected {expected} joint values, got {got}")]
    JointCount {
        /// Where the joint vector came from.
        context: String,
        /// The robot's joint count.
        expected: usize,
        /// What was given.
        got: usize,
    },
    /// A numerical procedure failed.
    #[error("{0}")]
    Numerical(String),
    /// A fit converged but failed the plausibility gate
    /// ([`crate::identification::plausibility`]): it cannot be a calibration.
    #[error("{0}")]
    Implausible(String),
}

fn fmt_parse(
    path: &std::path::Path,
    line: Option<usize>,
    field: &Option<String>,
    message: &str,
) -> String {
    let mut s = path.display().to_string();
    if let Some(l) = line {
        s.push_str(&format!(":{l}"));
    }
    if let Some(f) = field {
        s.push_str(&format!(": field `{f}`"));
    }
    s.push_str(": ");
    s.push_str(message);
    s
}

impl Error {
    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Usage`].
    pub fn usage(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Usage {
            field: field.into(),
            message: message.into(),
        }
    }

    /// A count `value` of setting `field` outside `min..=max` as an [`Error::Usage`] (`why` says
    /// what the upper limit protects); `Ok` within.
    pub fn check_count(field: &str, value: u64, min: u64, max: u64, why: &str) -> Result<()> {
        if value < min {
            return Err(Error::usage(field, format!("at least {min}, got {value}")));
        }
        if value > max {
            return Err(Error::usage(
                field,
                format!("at most {max} ({why}), got {value}"),
            ));
        }
        Ok(())
    }

    /// Shorthand for [`Error::Parse`].
    pub fn parse(
        path: impl Into<PathBuf>,
        line: Option<usize>,
        field: Option<&str>,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse {
            path: path.into(),
            line,
            field: field.map(str::to_owned),
            message: message.into(),
        }
    }

    /// This error without its line, for an [`Error::Parse`] whose field names the place better
    /// than a line of text the reader never saw (a robot built from a description, not a
    /// file); other errors as they are.
    pub fn without_line(self) -> Self {
        match self {
            Error::Parse {
                path,
                field,
                message,
                ..
            } => Error::Parse {
                path,
                line: None,
                field,
                message,
            },
            other => other,
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
