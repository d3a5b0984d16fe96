//! The temporary files of [`crate::io::AtomicFile`]: a registry of those this process has open,
//! so that an interrupted run can remove them ([`remove_temporaries`]), and the clean-up of
//! temporaries that a killed run left behind (`.NAME.PID.tmp` whose process is gone).

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// The temporary files this process has open. Every creation, rename and removal of one happens
/// under this lock, so that [`remove_temporaries`] (called from a signal-handling thread) sees a
/// consistent set and no new file can appear after it.
pub(crate) struct Registry {
    open: Vec<PathBuf>,
    /// Set by [`remove_temporaries`]: the run is being interrupted, no new temporary file is
    /// started and none is renamed into place.
    closed: bool,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    open: Vec::new(),
    closed: false,
});

/// The registry, locked. A panic while it was held leaves it usable: its content is always
/// consistent (single pushes and removals).
pub(crate) fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Registry {
    /// Whether [`remove_temporaries`] has run.
    pub(crate) fn closed(&self) -> bool {
        self.closed
    }

    /// Whether `tmp` is one of this process's open temporary files.
    pub(crate) fn contains(&self, tmp: &Path) -> bool {
        self.open.iter().any(|p| p == tmp)
    }

    pub(crate) fn add(&mut self, tmp: PathBuf) {
        self.open.push(tmp);
    }

    /// Forgets `tmp` (renamed into place or removed); whether it was registered.
    pub(crate) fn forget(&mut self, tmp: &Path) -> bool {
        match self.open.iter().position(|p| p == tmp) {
            Some(k) => {
                self.open.swap_remove(k);
                true
            }
            None => false,
        }
    }
}

/// Removes every temporary file this process has open (the files being written, not yet renamed
/// into place) and stops any new one from being started or renamed: what a handler of SIGINT or
/// SIGTERM calls before the process exits, so that an interrupted run leaves nothing behind and
/// every earlier output as it was. Returns how many files were removed. Writers still running
/// afterwards fail with an "interrupted" I/O error.
pub fn remove_temporaries() -> usize {
    let mut reg = registry();
    reg.closed = true;
    let mut removed = 0;
    for tmp in reg.open.drain(..) {
        if std::fs::remove_file(&tmp).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The name of the temporary file this process writes `name` through: `.NAME.PID.tmp`.
pub(crate) fn temporary_name(name: &str) -> String {
    format!(".{name}.{}.tmp", std::process::id())
}

/// The process id in a file name of the form `.NAME.PID.tmp`, if it has that form.
fn temporary_pid(file_name: &str, name: &str) -> Option<u32> {
    let pid = file_name
        .strip_prefix('.')?
        .strip_prefix(name)?
        .strip_prefix('.')?
        .strip_suffix(".tmp")?;
    if pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// Removes the temporary files `.NAME.PID.tmp` of `name` in `dir` that a run which no longer
/// exists left behind (killed by SIGKILL or a power cut, which no handler can catch). A file is
/// left alone when its process is alive (another run writing the same output) or when that
/// cannot be told (not Unix); only regular files are removed. Called with the registry held, so
/// that this process's own temporaries are known.
pub(crate) fn remove_stale(reg: &Registry, dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let own = std::process::id();
    for e in entries.flatten() {
        let file_name = e.file_name();
        let Some(pid) = file_name.to_str().and_then(|f| temporary_pid(f, name)) else {
            continue;
        };
        let path = dir.join(&file_name);
        if reg.contains(&path) || (pid != own && process_alive(pid)) {
            continue;
        }
        // Never a directory or a symbolic link, whatever its name.
        if e.file_type().is_ok_and(|t| t.is_file()) {
            let _ = std::fs::remove_file(&path);
        }
    }
}

/// Whether a process with id `pid` exists (`kill(pid, 0)`: it does if the call succeeds or is
/// refused for permission).
#[cfg(unix)]
fn process_alive(pid: u32) -> bool {
    let Ok(pid) = i32::try_from(pid) else {
        return false;
    };
    if pid <= 0 {
        return true;
    }
    // SAFETY: signal 0 sends nothing; kill only checks that the process exists.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

/// Without a portable way to tell, every process is taken as alive: nothing is removed.
#[cfg(not(unix))]
fn process_alive(_pid: u32) -> bool {
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_are_recognized_exactly() {
        assert_eq!(temporary_pid(".out.csv.123.tmp", "out.csv"), Some(123));
        assert_eq!(temporary_pid(".out.csv.123.tmp", "out"), None);
        assert_eq!(temporary_pid(".out.csv..tmp", "out.csv"), None);
        assert_eq!(temporary_pid(".out.csv.12a.tmp", "out.csv"), None);
        assert_eq!(temporary_pid("out.csv.123.tmp", "out.csv"), None);
        assert_eq!(temporary_pid(".out.csv.123", "out.csv"), None);
        assert_eq!(
            temporary_pid(".out.csv.99999999999999.tmp", "out.csv"),
            None
        );
    }

    #[cfg(unix)]
    #[test]
    fn own_process_is_alive_and_an_impossible_pid_is_not() {
        assert!(process_alive(std::process::id()));
        assert!(!process_alive(999_999_999));
        assert!(!process_alive(u32::MAX));
    }
}
