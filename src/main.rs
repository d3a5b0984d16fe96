//! `robocal`: calibrate industrial robots from laser-tracker measurements.
//!
//! This binary is a thin wrapper over the `robocal` library (the command-line front end); the work
//! is done by the `robocal-core` library. It adds what only a process has: the SIGPIPE action and
//! the SIGINT/SIGTERM handler that removes unfinished temporary files.

mod interrupt;

use robocal::exit;
use std::io::Write;

fn main() {
    reset_sigpipe();
    ignore_sigxfsz();
    interrupt::install();
    match robocal::run_from(std::env::args_os()) {
        Ok(()) => interrupt::exit(exit::OK, || {}),
        Err(e) => {
            if let Some(clap_err) = e.downcast_ref::<clap::Error>() {
                // clap prints usage errors, --help and --version itself, with its own exit codes;
                // a stream that cannot take them is exit 4 like any other failed write.
                let code = clap_err.exit_code();
                match clap_err.print().and_then(|()| flush_stdout()) {
                    // A usage error keeps its code when standard error cannot take its message.
                    Err(e) if !clap_err.use_stderr() => interrupt::exit(exit::IO, || {
                        let _ =
                            writeln!(std::io::stderr(), "error: writing to standard output: {e}");
                    }),
                    _ => interrupt::exit(code, || {}),
                }
            }
            // Where standard error cannot take the message either, the exit code says it all.
            interrupt::exit(exit::code_for(&e), || {
                let _ = writeln!(std::io::stderr(), "error: {}", exit::message(&e));
            })
        }
    }
}

fn flush_stdout() -> std::io::Result<()> {
    std::io::stdout().flush()
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

/// A file-size limit (`ulimit -f`) would kill the process with SIGXFSZ, leaving its temporary
/// file; ignored, the write fails with "File too large" instead, which ends the run like any
/// failed write (exit 4, temporaries removed, earlier outputs as they were).
#[cfg(unix)]
fn ignore_sigxfsz() {
    // SAFETY: called first thing in main, before any other thread exists; SIG_IGN is a valid
    // disposition for SIGXFSZ.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

#[cfg(not(unix))]
fn ignore_sigxfsz() {}
