//! SIGINT and SIGTERM: the temporary files being written are removed and the program exits with
//! code 130, so that an interrupted run leaves no litter and every earlier output as it was.
//! (SIGKILL cannot be caught: the temporaries it leaves are removed at the next write of the same
//! output, see `robocal_core::io::atomic`.)
//!
//! The handler does this itself, on whichever thread the signal reaches, with async-signal-safe
//! calls only (atomics, `unlink`, `write`, `_exit`): no thread is kept waiting for signals, which
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
        // SAFETY: the action is async-signal-safe: `interrupted` makes only atomic operations
        // and the calls `unlink`, `write` and `_exit`, and allocates nothing.
        let _ = unsafe { signal_hook::low_level::register(signal, move || interrupted(name)) };
    }
}

#[cfg(not(unix))]
pub fn install() {}

/// The handler: removes the temporaries, says so on standard error and exits with 130; returns
/// only when the process is already ending.
#[cfg(unix)]
fn interrupted(signal: &str) {
    if EXITING.swap(true, SeqCst) {
        return;
    }
    let removed = robocal_core::io::remove_temporaries();
    let mut m = Message::default();
    if STDERR_TERMINAL.load(SeqCst) {
        // A progress bar may be on the terminal's last line: cleared before the message.
        m.push(b"\r\x1b[2K");
    }
    m.push(b"error: interrupted by ");
    m.push(signal.as_bytes());
    m.push(b"; ");
    m.number(removed);
    m.push(b" unfinished temporary file(s) removed, no output half-written\n");
    m.write_to_stderr();
    signal_hook::low_level::exit(robocal::exit::INTERRUPTED)
}

/// The handler's message, made without allocating (as a handler must).
#[cfg(unix)]
struct Message {
    bytes: [u8; 160],
    len: usize,
}

#[cfg(unix)]
impl Default for Message {
    fn default() -> Message {
        Message {
            bytes: [0; 160],
            len: 0,
        }
    }
}

#[cfg(unix)]
impl Message {
    fn push(&mut self, b: &[u8]) {
        let n = b.len().min(self.bytes.len() - self.len);
        self.bytes[self.len..self.len + n].copy_from_slice(&b[..n]);
        self.len += n;
    }

    fn number(&mut self, mut v: usize) {
        let mut digits = [0u8; 20];
        let mut k = digits.len();
        loop {
            k -= 1;
            digits[k] = b'0' + (v % 10) as u8;
            v /= 10;
            if v == 0 {
                break;
            }
        }
        self.push(&digits[k..]);
    }

    fn write_to_stderr(&self) {
        let mut from = 0;
        while from < self.len {
            // SAFETY: writes initialized bytes of `self.bytes` to descriptor 2.
            let n = unsafe {
                libc::write(
                    2,
                    self.bytes[from..self.len].as_ptr().cast(),
                    self.len - from,
                )
            };
            if n <= 0 {
                return;
            }
            from += n as usize;
        }
    }
}
