//! The `robocal` command-line program as a library: argument parsing, files, progress and
//! printing around the `robocal-core` library, which does the work.
//!
//! `src/main.rs` is a thin wrapper over [`run_from`]; the fuzz target `cli_args` drives the same
//! function with generated argument vectors. This is the program's front end, not a stable API:
//! use `robocal-core` from other code.

#[macro_use]
mod output;
mod cmd;
pub mod exit;
mod progress;
mod tables;

use clap::Parser;
use std::ffi::OsString;

/// Parses `args` (the program name first, as in `std::env::args_os()`) and runs the command.
///
/// A command-line that does not parse (or asks for `--help`/`--version`) comes back as a
/// [`clap::Error`] inside the error; [`exit::code_for`] maps every error to its exit code.
pub fn run_from<I, T>(args: I) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = cmd::Cli::try_parse_from(args)?;
    cmd::run(cli)?;
    output::flush_out()
}
