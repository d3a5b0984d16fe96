//! Printing that cannot panic: the command's messages to standard output and standard error go
//! through [`outln!`]/[`out!`] and [`errln!`], which return an error (exit code 4, "a file could
//! not be written") instead of panicking as `println!` does when the stream is full
//! (`> /dev/full`) or otherwise fails. A closed pipe (`robocal demo | head`) still ends the
//! program quietly: SIGPIPE has its default action (see `main.rs`).

use std::io::Write;

/// Which stream failed, for the message.
#[derive(Clone, Copy)]
pub(crate) enum Stream {
    Stdout,
    Stderr,
}

impl Stream {
    fn name(self) -> &'static str {
        match self {
            Stream::Stdout => "standard output",
            Stream::Stderr => "standard error",
        }
    }
}

/// The error of a failed write to `stream`: exit code 4.
pub(crate) fn stream_error(stream: Stream, e: &std::io::Error) -> anyhow::Error {
    crate::exit::CliError {
        code: crate::exit::IO,
        message: format!("writing to {}: {e}", stream.name()),
    }
    .into()
}

/// Writes `args` to standard output (line-buffered: a line reaches the stream at its newline).
pub(crate) fn write_out(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    std::io::stdout()
        .lock()
        .write_fmt(args)
        .map_err(|e| stream_error(Stream::Stdout, &e))
}

/// Writes `args` to standard error (unbuffered).
pub(crate) fn write_err(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    std::io::stderr()
        .lock()
        .write_fmt(args)
        .map_err(|e| stream_error(Stream::Stderr, &e))
}

/// Flushes standard output: what is left of a line without its newline. Called once the
/// command is done, so that a failure there is reported like any other.
pub(crate) fn flush_out() -> anyhow::Result<()> {
    std::io::stdout()
        .lock()
        .flush()
        .map_err(|e| stream_error(Stream::Stdout, &e))
}

/// `println!` that returns `anyhow::Result<()>` instead of panicking.
macro_rules! outln {
    () => {
        $crate::output::write_out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that returns `anyhow::Result<()>` instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write_out(format_args!($($arg)*))
    };
}

/// `eprintln!` that returns `anyhow::Result<()>` instead of panicking.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::output::write_err(format_args!("{}\n", format_args!($($arg)*)))
    };
}
