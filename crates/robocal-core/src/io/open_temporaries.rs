//! The temporary files this process has open, in a table that a signal handler can empty
//! ([`remove_temporaries`]): an interrupted run removes them from the handler itself, with no
//! thread kept waiting for signals (starting one cost every run about a fifth of a millisecond,
//! measured on the 75-pose calibration).
//!
//! The handler may only make async-signal-safe calls, so the table is made of atomics and of
//! paths as C strings, and never locked. Each slot is:
//! - *free*;
//! - *busy*: a writer is creating, renaming or removing its file;
//! - *open*: its file exists and its paths may be read;
//! - *taken*: the handler is removing its file.
//!
//! A writer makes its slot busy, does its step (create the file and its record, or rename or
//! remove it), then makes it open or free. The handler first closes the table (no slot is made
//! busy afterwards for a new file or a rename), then waits for every busy slot to leave that
//! state, and removes the files of the open ones. A writer blocks SIGINT and SIGTERM on its own
//! thread while its slot is busy, so that the handler, which runs on any thread the signal
//! reaches, never waits for the thread it interrupted.
//!
//! So no file is created after the handler has looked, none is renamed into place after it
//! started, and a file being created when the signal arrives is removed with its record.

use crate::error::{Error, Result};
use crate::io::temporaries::Record;
use std::ffi::{c_char, CString};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU8, Ordering::SeqCst};

/// How many temporary files can be open at once with the handler able to remove them. A file
/// beyond them is written all the same; only its record removes it after an interruption (at
/// the next write).
const SLOTS: usize = 256;

const FREE: u8 = 0;
const BUSY: u8 = 1;
const OPEN: u8 = 2;
const TAKEN: u8 = 3;

/// One open temporary file: its state, and its path and its record's path (null when none), as
/// C strings the writer owns until the slot is free.
struct Slot {
    state: AtomicU8,
    tmp: AtomicPtr<c_char>,
    record: AtomicPtr<c_char>,
}

impl Slot {
    const fn new() -> Slot {
        Slot {
            state: AtomicU8::new(FREE),
            tmp: AtomicPtr::new(std::ptr::null_mut()),
            record: AtomicPtr::new(std::ptr::null_mut()),
        }
    }

    /// Frees the paths (the slot is busy: this thread's).
    fn release_paths(&self) {
        for p in [&self.tmp, &self.record] {
            let raw = p.swap(std::ptr::null_mut(), SeqCst);
            if !raw.is_null() {
                // SAFETY: every non-null pointer here came from `CString::into_raw` in
                // `publish`, and a busy slot's pointers are read by no one else.
                drop(unsafe { CString::from_raw(raw) });
            }
        }
    }
}

static TABLE: [Slot; SLOTS] = [const { Slot::new() }; SLOTS];

/// Set by [`remove_temporaries`]: the run is being interrupted.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// The error of a writer that finds the run being interrupted.
pub(crate) fn interrupted(path: &Path) -> Error {
    Error::Io {
        path: path.to_owned(),
        source: std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "interrupted: the file being written was removed",
        ),
    }
}

/// A temporary file in the table, from its creation until [`Retiring::done`].
pub(crate) struct Open {
    /// Its slot; none when the table was full.
    slot: Option<usize>,
    record: Record,
}

impl Open {
    /// Its slot in the table, if it has one.
    pub(crate) fn slot(&self) -> Option<usize> {
        self.slot
    }
}

/// Creates a temporary file with `make` as one step the handler waits for, and puts it in the
/// table. `make` gives what it made, and the file's path and record when there is a file to
/// remove on interruption (`None`: nothing to register, such as a spool whose name is already
/// removed). Fails with [`interrupted`] (for `target`), without calling `make`, when the run
/// is being interrupted.
pub(crate) fn add<T>(
    target: &Path,
    make: impl FnOnce() -> Result<(T, Option<(PathBuf, Record)>)>,
) -> Result<(T, Option<Open>)> {
    let _masked = signals::Masked::new();
    let slot = TABLE
        .iter()
        .position(|s| s.state.compare_exchange(FREE, BUSY, SeqCst, SeqCst).is_ok());
    let free = |slot: Option<usize>| {
        if let Some(k) = slot {
            TABLE[k].state.store(FREE, SeqCst);
        }
    };
    if CLOSED.load(SeqCst) {
        free(slot);
        return Err(interrupted(target));
    }
    let (made, file) = match make() {
        Ok(m) => m,
        Err(e) => {
            free(slot);
            return Err(e);
        }
    };
    let Some((tmp, record)) = file else {
        free(slot);
        return Ok((made, None));
    };
    if let Some(k) = slot {
        publish(&TABLE[k], &tmp, &record);
    }
    Ok((made, Some(Open { slot, record })))
}

/// Puts the paths in the busy slot `s` and opens it.
fn publish(s: &Slot, tmp: &Path, record: &Record) {
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_encoded_bytes())
            .map_or(std::ptr::null_mut(), CString::into_raw)
    };
    s.tmp.store(c(tmp), SeqCst);
    s.record
        .store(record.path().map_or(std::ptr::null_mut(), c), SeqCst);
    s.state.store(OPEN, SeqCst);
}

/// Open temporaries being renamed or removed, as one step the handler waits for: their slots
/// are busy and SIGINT and SIGTERM are blocked on this thread until it is dropped. Those not
/// [`Retiring::done`] go back to the table as they were.
pub(crate) struct Retiring {
    /// Each file's slot while it is busy (none: no slot, or done).
    slots: Vec<Option<usize>>,
    _masked: signals::Masked,
}

/// Starts retiring the files in `slots` ([`Open::slot`], in the order [`Retiring::done`] counts
/// them): `None` when the handler has taken one of them (it removes them: the writer has nothing
/// left to do) or, when `renaming`, when the run is being interrupted (no file is renamed into
/// place after that; removing one still is).
pub(crate) fn retiring(
    slots: impl IntoIterator<Item = Option<usize>>,
    renaming: bool,
) -> Option<Retiring> {
    let mut r = Retiring {
        slots: Vec::new(),
        _masked: signals::Masked::new(),
    };
    for slot in slots {
        match slot {
            Some(k)
                if TABLE[k]
                    .state
                    .compare_exchange(OPEN, BUSY, SeqCst, SeqCst)
                    .is_err() =>
            {
                return None;
            }
            slot => r.slots.push(slot),
        }
    }
    if renaming && CLOSED.load(SeqCst) {
        return None;
    }
    Some(r)
}

impl Retiring {
    /// The `k`-th file is renamed or removed: its slot is freed and its record removed.
    pub(crate) fn done(&mut self, k: usize, file: Open) {
        if let Some(s) = self.slots.get_mut(k).and_then(Option::take) {
            TABLE[s].release_paths();
            TABLE[s].state.store(FREE, SeqCst);
        }
        file.record.remove();
    }
}

impl Drop for Retiring {
    fn drop(&mut self) {
        for k in self.slots.iter().flatten() {
            TABLE[*k].state.store(OPEN, SeqCst);
        }
    }
}

/// Removes every temporary file this process has open (the files being written, not yet renamed
/// into place) and their records, after those being created, renamed or removed right now are,
/// and stops any new one from being started or renamed: what a handler of SIGINT or SIGTERM
/// calls before the process exits, so that an interrupted run leaves nothing behind and every
/// earlier output as it was. Returns how many files were removed. Writers still running
/// afterwards fail with an "interrupted" I/O error.
///
/// Async-signal-safe (atomics and `unlink` only; it allocates and frees nothing). Once called,
/// the process is expected to end: the taken slots are not freed.
pub fn remove_temporaries() -> usize {
    CLOSED.store(true, SeqCst);
    let mut removed = 0;
    for s in &TABLE {
        loop {
            match s.state.load(SeqCst) {
                BUSY => std::hint::spin_loop(),
                OPEN if s
                    .state
                    .compare_exchange(OPEN, TAKEN, SeqCst, SeqCst)
                    .is_err() => {}
                OPEN => {
                    if signals::unlink(s.tmp.load(SeqCst)) {
                        removed += 1;
                    }
                    signals::unlink(s.record.load(SeqCst));
                    break;
                }
                _ => break,
            }
        }
    }
    removed
}

#[cfg(unix)]
mod signals {
    use std::ffi::c_char;

    /// SIGINT and SIGTERM blocked on this thread (the signals whose handler calls
    /// [`super::remove_temporaries`]), until dropped on the same thread (it is not `Send`).
    pub(super) struct Masked(libc::sigset_t, std::marker::PhantomData<*const ()>);

    impl Masked {
        pub(super) fn new() -> Masked {
            // SAFETY: the sets are initialized by sigemptyset before use, and pthread_sigmask
            // only changes this thread's mask.
            unsafe {
                let mut block: libc::sigset_t = std::mem::zeroed();
                libc::sigemptyset(&mut block);
                libc::sigaddset(&mut block, libc::SIGINT);
                libc::sigaddset(&mut block, libc::SIGTERM);
                let mut old: libc::sigset_t = std::mem::zeroed();
                libc::pthread_sigmask(libc::SIG_BLOCK, &block, &mut old);
                Masked(old, std::marker::PhantomData)
            }
        }
    }

    impl Drop for Masked {
        fn drop(&mut self) {
            // SAFETY: restores the mask `new` saved, on the same thread (Masked is not Send).
            unsafe {
                libc::pthread_sigmask(libc::SIG_SETMASK, &self.0, std::ptr::null_mut());
            }
        }
    }

    /// Removes the file named by the C string `p` (null: nothing); whether it was removed.
    pub(super) fn unlink(p: *const c_char) -> bool {
        // SAFETY: a non-null `p` is a C string that stays allocated while its slot is taken.
        !p.is_null() && unsafe { libc::unlink(p) } == 0
    }
}

#[cfg(not(unix))]
mod signals {
    use std::ffi::{c_char, CStr};

    /// Without Unix signals there is nothing to block.
    pub(super) struct Masked(std::marker::PhantomData<*const ()>);

    impl Masked {
        pub(super) fn new() -> Masked {
            Masked(std::marker::PhantomData)
        }
    }

    pub(super) fn unlink(p: *const c_char) -> bool {
        if p.is_null() {
            return false;
        }
        // SAFETY: a non-null `p` is a C string that stays allocated while its slot is taken.
        let s = unsafe { CStr::from_ptr(p) };
        s.to_str()
            .is_ok_and(|s| std::fs::remove_file(std::path::Path::new(s)).is_ok())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(open: &Open) -> u8 {
        TABLE[open.slot().expect("a slot")].state.load(SeqCst)
    }

    /// A slot is open while its file is, busy while it is retired, open again when retiring
    /// stops short, and free once done; its paths are the file's and its record's until then.
    #[test]
    fn a_temporary_holds_its_slot_from_creation_to_retirement() {
        let dir = std::env::temp_dir().join(format!("robocal-open-tmp-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let tmp = dir.join(".robocal-test.tmp");
        let (file, open) = add(&tmp, || {
            let file = std::fs::File::create(&tmp).unwrap();
            let record = Record::write(&tmp, &file);
            Ok((file, Some((tmp.clone(), record))))
        })
        .unwrap();
        let open = open.expect("registered");
        let k = open.slot().unwrap();
        assert_eq!(state(&open), OPEN);
        // SAFETY: the slot is this test's and open: its paths stay allocated.
        let path = unsafe { std::ffi::CStr::from_ptr(TABLE[k].tmp.load(SeqCst)) };
        assert_eq!(path.to_bytes(), tmp.as_os_str().as_encoded_bytes());
        let record = open.record.path().map(Path::to_owned);
        if let Some(r) = &record {
            assert!(r.exists(), "{}", r.display());
        }

        let r = retiring([open.slot()], true).expect("not interrupted");
        assert_eq!(state(&open), BUSY);
        drop(r);
        assert_eq!(
            state(&open),
            OPEN,
            "retiring stopped short gives the slot back"
        );

        let mut r = retiring([open.slot()], false).unwrap();
        drop(file);
        std::fs::remove_file(&tmp).unwrap();
        r.done(0, open);
        // The slot is free now (another test's file may have it already).
        if let Some(r) = record {
            assert!(!r.exists(), "the record is removed with the file");
        }
        drop(r);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// What `add` makes without a file to register (a spool already unnamed) takes no slot, and
    /// a failure of `make` is `add`'s error.
    #[test]
    fn nothing_registered_takes_no_slot() {
        let (v, open) = add(Path::new("x"), || Ok((7, None))).unwrap();
        assert_eq!(v, 7);
        assert!(open.is_none());
        let Err(e) = add::<()>(Path::new("x"), || Err(Error::invalid("x", "refused"))) else {
            panic!("make's error is add's");
        };
        assert!(e.to_string().contains("refused"), "{e}");
    }
}
