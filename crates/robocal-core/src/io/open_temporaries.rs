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
//! A writer's *step* (create a file and its record, or rename or remove files) is counted while
//! it runs, with SIGINT and SIGTERM blocked on the writer's thread, and its slots busy. The
//! handler first closes the table (no step creates or renames a file after that), waits for the
//! steps in progress to end, then removes the files of the open slots. Because a step blocks the
//! two signals on its own thread, the handler, which runs on any thread the signal reaches,
//! never waits for a step of the thread it interrupted.
//!
//! So no file is created after the handler has looked, none is renamed into place after it
//! started (a set of renames is one step: all or none), and a file being created when the signal
//! arrives is removed with its record. The wait is bounded ([`STEP_WAIT_NS`]): a step that cannot
//! end (blocked, say, on a lock the interrupted thread holds) leaves its file to its record,
//! which the next write removes.

use crate::error::{Error, Result};
use crate::io::temporaries::Record;
use std::ffi::{c_char, CString};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU8, AtomicUsize, Ordering::SeqCst};

/// How many temporary files can be open at once with the handler able to remove them. A file
/// beyond them is written all the same, its steps waited for like any; only its record removes
/// it after an interruption (at the next write).
const SLOTS: usize = 256;

/// How long the handler waits for the steps in progress (ns).
const STEP_WAIT_NS: i64 = 2_000_000_000;

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

/// The steps in progress.
static STEPS: AtomicUsize = AtomicUsize::new(0);

/// A step in progress: counted, and SIGINT and SIGTERM blocked on this thread, until dropped
/// (the count first, while the signals are still blocked: a signal pending on this thread is
/// delivered once the step no longer counts).
struct Step {
    _counted: Counted,
    _masked: signals::Masked,
}

struct Counted;

impl Drop for Counted {
    fn drop(&mut self) {
        STEPS.fetch_sub(1, SeqCst);
    }
}

impl Step {
    fn begin() -> Step {
        let masked = signals::Masked::new();
        STEPS.fetch_add(1, SeqCst);
        Step {
            _counted: Counted,
            _masked: masked,
        }
    }
}

/// A slot claimed for a file being created: freed when dropped unless published (a failure or
/// a panic of the creation leaves no slot busy).
struct Claimed(Option<usize>);

impl Drop for Claimed {
    fn drop(&mut self) {
        if let Some(k) = self.0 {
            TABLE[k].state.store(FREE, SeqCst);
        }
    }
}

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
    tmp: PathBuf,
    record: Record,
}

impl Open {
    /// The temporary file's path.
    pub(crate) fn tmp(&self) -> &Path {
        &self.tmp
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
    // Dropped in reverse: the claim (if not published) before the step.
    let _step = Step::begin();
    let mut claimed = Claimed(
        TABLE
            .iter()
            .position(|s| s.state.compare_exchange(FREE, BUSY, SeqCst, SeqCst).is_ok()),
    );
    if CLOSED.load(SeqCst) {
        return Err(interrupted(target));
    }
    let (made, file) = make()?;
    let Some((tmp, record)) = file else {
        return Ok((made, None));
    };
    let slot = claimed.0.take();
    if let Some(k) = slot {
        publish(&TABLE[k], &tmp, &record);
    }
    Ok((made, Some(Open { slot, tmp, record })))
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
/// are busy until it is dropped. Those not [`Retiring::done`] go back to the table as they were.
pub(crate) struct Retiring {
    /// Each file's slot while it is busy (none: no slot, or done).
    slots: Vec<Option<usize>>,
    _step: Step,
}

/// Starts retiring `files` (in the order [`Retiring::done`] counts them): `None` when the
/// handler has taken one of them (it removes them: the writer has nothing left to do) or, when
/// `renaming`, when the run is being interrupted (no file is renamed into place after that;
/// removing one still is).
pub(crate) fn retiring<'a>(
    files: impl IntoIterator<Item = &'a Open>,
    renaming: bool,
) -> Option<Retiring> {
    let mut r = Retiring {
        slots: Vec::new(),
        _step: Step::begin(),
    };
    for f in files {
        match f.slot {
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
    /// The `k`-th file is renamed or removed: its record is removed, then its slot freed.
    pub(crate) fn done(&mut self, k: usize, file: Open) {
        // Within the step: a handler waiting for it finds the record gone.
        file.record.remove();
        if let Some(s) = self.slots.get_mut(k).and_then(Option::take) {
            TABLE[s].release_paths();
            TABLE[s].state.store(FREE, SeqCst);
        }
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
    let start = signals::now_ns();
    let waiting = || signals::now_ns().saturating_sub(start) < STEP_WAIT_NS;
    while STEPS.load(SeqCst) > 0 && waiting() {
        std::hint::spin_loop();
    }
    let mut removed = 0;
    for s in &TABLE {
        loop {
            match s.state.load(SeqCst) {
                // Removal (not renaming) may still start after the wait; a step does not stop
                // for long.
                BUSY if waiting() => std::hint::spin_loop(),
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

    /// The monotonic clock (ns; `clock_gettime` is async-signal-safe).
    pub(super) fn now_ns() -> i64 {
        let mut t = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: writes the time into `t`, which this function owns.
        unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut t) };
        // `time_t` and `c_long` are narrower than i64 on some targets.
        #[allow(clippy::useless_conversion)]
        i64::from(t.tv_sec)
            .saturating_mul(1_000_000_000)
            .saturating_add(i64::from(t.tv_nsec))
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

    /// Without Unix signals nothing waits: no bound is needed.
    pub(super) fn now_ns() -> i64 {
        0
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
        TABLE[open.slot.expect("a slot")].state.load(SeqCst)
    }

    /// A temporary file `path` made through [`add`], with its record.
    fn temporary(path: &Path) -> (std::fs::File, Open) {
        let (file, open) = add(path, || {
            let file = std::fs::File::create(path).unwrap();
            let record = Record::write(path, &file);
            Ok((file, Some((path.to_owned(), record))))
        })
        .unwrap();
        (file, open.expect("registered"))
    }

    fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("robocal-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A slot is open while its file is, busy while it is retired, open again when retiring
    /// stops short, and free once done; its paths are the file's and its record's until then.
    #[test]
    fn a_temporary_holds_its_slot_from_creation_to_retirement() {
        let dir = scratch_dir("open-tmp");
        let tmp = dir.join(".robocal-test.tmp");
        let (file, open) = temporary(&tmp);
        let k = open.slot.unwrap();
        assert_eq!(state(&open), OPEN);
        // SAFETY: the slot is this test's and open: its paths stay allocated.
        let path = unsafe { std::ffi::CStr::from_ptr(TABLE[k].tmp.load(SeqCst)) };
        assert_eq!(path.to_bytes(), tmp.as_os_str().as_encoded_bytes());
        let record = open.record.path().map(Path::to_owned);
        if let Some(r) = &record {
            assert!(r.exists(), "{}", r.display());
        }

        let r = retiring([&open], true).expect("not interrupted");
        assert_eq!(state(&open), BUSY);
        drop(r);
        assert_eq!(
            state(&open),
            OPEN,
            "retiring stopped short gives the slot back"
        );

        let mut r = retiring([&open], false).unwrap();
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

    /// Set in the child process that [`the_handler_waits_for_steps_and_takes_open_files`]
    /// starts: [`remove_temporaries`] closes the table for the whole process, so it runs alone.
    const CHILD: &str = "ROBOCAL_OPEN_TEMPORARIES_CHILD";

    #[test]
    fn the_handler_waits_for_steps_and_takes_open_files() {
        let name = "io::open_temporaries::tests::handler_in_a_child_process";
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args([name, "--exact", "--ignored", "--test-threads=1"])
            .env(CHILD, "1")
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(out.status.success(), "{text}");
        assert!(text.contains("1 passed"), "the child ran nothing: {text}");
    }

    /// In a child process alone (see [`CHILD`]):
    /// - a creation that panics leaves no slot busy and no step counted;
    /// - the handler waits for a step in progress (a rename), then removes the open file and
    ///   the records of both, and keeps the renamed file;
    /// - once closed, no temporary is created and none renamed; removing one still is.
    #[test]
    #[ignore = "run alone in a child process by the_handler_waits_for_steps_and_takes_open_files"]
    fn handler_in_a_child_process() {
        if std::env::var_os(CHILD).is_none() {
            return;
        }
        let busy = || {
            TABLE
                .iter()
                .filter(|s| s.state.load(SeqCst) == BUSY)
                .count()
        };
        let panicked = std::panic::catch_unwind(|| {
            add::<()>(Path::new("x"), || panic!("a creation that panics"))
        });
        assert!(panicked.is_err());
        assert_eq!((busy(), STEPS.load(SeqCst)), (0, 0));

        let dir = scratch_dir("open-tmp-child");
        let (a, b, out) = (dir.join("a.tmp"), dir.join("b.tmp"), dir.join("a.out"));
        let (fa, open_a) = temporary(&a);
        let (fb, open_b) = temporary(&b);
        let records: Vec<PathBuf> = [&open_a, &open_b]
            .iter()
            .filter_map(|o| o.record.path().map(Path::to_owned))
            .collect();
        let mut r = retiring([&open_a], true).unwrap();
        let handler = std::thread::spawn(remove_temporaries);
        std::thread::sleep(std::time::Duration::from_millis(200));
        assert!(
            !handler.is_finished(),
            "the handler waits for the rename in progress"
        );
        drop(fa);
        std::fs::rename(&a, &out).unwrap();
        r.done(0, open_a);
        drop(r);
        assert_eq!(handler.join().unwrap(), 1, "b removed");
        assert!(out.exists() && !b.exists());
        for r in &records {
            assert!(!r.exists(), "{} left", r.display());
        }

        let Err(e) = add(&dir.join("c.tmp"), || Ok(((), None))) else {
            panic!("a temporary created after the handler");
        };
        assert!(e.to_string().contains("interrupted"), "{e}");
        assert!(retiring([], true).is_none(), "a rename after the handler");
        assert!(retiring([], false).is_some(), "a removal after the handler");
        drop((fb, open_b));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
