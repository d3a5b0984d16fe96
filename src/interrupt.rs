//! SIGINT and SIGTERM: the temporary files being written are removed and the program exits with
//! code 130, so that an interrupted run leaves no litter and every earlier output as it was.
//! (SIGKILL cannot be caught: the temporaries it leaves are removed at the next write of the same
//! output, see `robocal_core::io::atomic`.)
//!
//! The handler does this itself, on whichever thread the signal reaches, with async-signal-safe
//! calls only (atomics, `clock_gettime`, `unlink`, `write`, `_exit`): no thread is kept waiting for signals, which
//! cost every run about a fifth of a millisecond to start.

use std::sync::atomic::{AtomicBool, Ordering::SeqCst};

/// Set by whoever ends the process first: the main thread reporting its result, or the handler.
/// The other then leaves it to them: the handler returns, the main thread waits for the
/// handler's exit (130) instead of racing it with, say, the I/O error of a writer whose
/// temporary file was just removed.
static EXITING: AtomicBool = AtomicBool::new(false);

/// Whether standard error is a terminal, asked when the handler is installed (the handler may
/// not ask).
static STDERR_TERMINAL: AtomicBool = AtomicBool::new(false);

/// Ends the process with `code` unless a signal is already doing so; `report` runs first (the
/// error message).
pub fn exit(code: i32, report: impl FnOnce()) -> ! {
    if EXITING.swap(true, SeqCst) {
        loop {
            std::thread::park();
        }
    }
    report();
    std::process::exit(code)
}

/// Installs the handler of SIGINT and SIGTERM. If it cannot be installed, the signals keep
/// their default action (the process ends; temporaries are cleaned up later).
#[cfg(unix)]
pub fn install() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    use std::io::IsTerminal;
    STDERR_TERMINAL.store(std::io::stderr().is_terminal(), SeqCst);
    for (signal, name) in [(SIGINT, "SIGINT"), (SIGTERM, "SIGTERM")] {
        // SAFETY: the action is async-signal-safe: `interrupted` makes only atomic operations,
        // formats on the stack and calls `clock_gettime`, `unlink`, `write` and `_exit`; it
        // allocates nothing and takes no lock.
        let _ = unsafe { signal_hook::low_level::register(signal, move || interrupted(name)) };
    }
}

#[cfg(not(unix))]
pub fn install() {}

/// The handler: removes the temporaries, says so on standard error and exits with 130; returns
/// only when the process is already ending.
#[cfg(unix)]
fn interrupted(signal: &str) {
    use std::io::Write;
    if EXITING.swap(true, SeqCst) {
        return;
    }
    let removed = robocal_core::io::remove_temporaries();
    // A progress bar may be on the terminal's last line: cleared before the message.
    let clear = if STDERR_TERMINAL.load(SeqCst) {
        "\r\x1b[2K"
    } else {
        ""
    };
    // Formatted into a buffer on the stack: `core::fmt` neither allocates nor locks.
    let mut bytes = [0u8; 160];
    let mut w = std::io::Cursor::new(&mut bytes[..]);
    let _ = writeln!(
        w,
        "{clear}error: interrupted by {signal}; {removed} unfinished temporary file(s) removed, \
         no output half-written"
    );
    let len = w.position() as usize;
    write_to_stderr(&bytes[..len]);
    signal_hook::low_level::exit(robocal::exit::INTERRUPTED)
}

/// Writes `bytes` to descriptor 2 with `write(2)` (no lock, as a handler must).
#[cfg(unix)]
fn write_to_stderr(mut bytes: &[u8]) {
    while !bytes.is_empty() {
        // SAFETY: writes initialized bytes of `bytes` to descriptor 2.
        let n = unsafe { libc::write(2, bytes.as_ptr().cast(), bytes.len()) };
        if n <= 0 {
            return;
        }
        bytes = &bytes[n as usize..];
    }
}
