//! SIGINT and SIGTERM: the temporary files being written are removed and the program exits with
//! code 130, so that an interrupted run leaves no litter and every earlier output as it was.
//! (SIGKILL cannot be caught: the temporaries it leaves are removed at the next write of the same
//! output, see `robocal_core::io::atomic`.)

use std::io::Write;
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Held by whoever ends the process: the main thread reporting its result, or the signal
/// thread. A writer that fails because its temporary file was just removed then waits for the
/// signal thread's exit (130) instead of racing it with an I/O error.
static EXIT: Mutex<()> = Mutex::new(());

/// Ends the process with `code` unless a signal is already doing so; `report` runs first (the
/// error message), under the same guard.
pub fn exit(code: i32, report: impl FnOnce()) -> ! {
    let _guard: MutexGuard<()> = EXIT.lock().unwrap_or_else(PoisonError::into_inner);
    report();
    std::process::exit(code)
}

/// Starts the thread that handles SIGINT and SIGTERM. If the handler cannot be installed, the
/// signals keep their default action (the process ends; temporaries are cleaned up later).
#[cfg(unix)]
pub fn install() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return;
    };
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(sig) = signals.forever().next() {
                let name = if sig == SIGINT { "SIGINT" } else { "SIGTERM" };
                exit(robocal::exit::INTERRUPTED, || {
                    let removed = robocal_core::io::remove_temporaries();
                    clear_progress_line();
                    let _ = writeln!(
                        std::io::stderr(),
                        "error: interrupted by {name}; {removed} unfinished temporary file(s) \
                         removed, no output half-written"
                    );
                });
            }
        });
    drop(spawned);
}

#[cfg(not(unix))]
pub fn install() {}

/// A progress bar may be on the terminal's last line: clear it before the message.
fn clear_progress_line() {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() {
        let _ = write!(std::io::stderr(), "\r\x1b[2K");
    }
}
