//! `robocal`: calibrate industrial robots from laser-tracker measurements.
//!
//! This binary is the command-line front end: argument parsing, files, progress and printing.
//! The work is done by the `robocal-core` library.

mod cmd;
mod exit;
mod interrupt;
mod progress;
mod tables;

use clap::Parser;

fn main() {
    reset_sigpipe();
    interrupt::install();
    let cli = cmd::Cli::parse();
    match cmd::run(cli) {
        Ok(()) => interrupt::exit(exit::OK, || {}),
        Err(e) => interrupt::exit(exit::code_for(&e), || {
            eprintln!("error: {}", exit::message(&e))
        }),
    }
}

/// Rust ignores SIGPIPE, so printing to a closed pipe (`robocal demo | head`) would panic; restore
/// the default action so the program ends quietly, as Unix tools do.
#[cfg(unix)]
fn reset_sigpipe() {
    // SAFETY: called first thing in main, before any other thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn reset_sigpipe() {}
