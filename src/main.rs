//! `robocal`: calibrate industrial robots from laser-tracker measurements.
//!
//! This binary is the command-line front end: argument parsing, files, progress and printing.
//! The work is done by the `robocal-core` library.

mod cmd;
mod exit;
mod progress;
mod tables;

use clap::Parser;

fn main() {
    let cli = cmd::Cli::parse();
    match cmd::run(cli) {
        Ok(()) => {}
        Err(e) => {
            eprintln!("error: {}", exit::message(&e));
            std::process::exit(exit::code_for(&e));
        }
    }
}
