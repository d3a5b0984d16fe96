//! The temporary files of [`crate::io::AtomicFile`]: their names (`.robocal-PID-RANDOM.tmp`) and
//! the records that prove which files are robocal's temporaries, so that those a killed run left
//! behind are removed later ([`remove_stale`]) and nothing else is. Those this process has open
//! are in `io::open_temporaries`, which an interrupted run empties.

use std::path::{Path, PathBuf};

/// The longest name a temporary file gets (`.robocal-PID-RANDOM.tmp`): short whatever the
/// output's name, so that any legal output name can be written.
pub(crate) const MAX_NAME: usize = 48;

/// A fresh name for a temporary file: `.robocal-PID-RANDOM.tmp`, independent of the output's
/// name (so never too long) and unlikely to exist; the file is created with `create_new`, which
/// never opens an existing file, and a new name is drawn if one does.
pub(crate) fn temporary_name() -> String {
    let name = format!(
        ".robocal-{}-{:016x}.tmp",
        std::process::id(),
        rand::random::<u64>()
    );
    debug_assert!(name.len() <= MAX_NAME);
    name
}

/// The record (in robocal's private directory, never beside the outputs) that proves a
/// temporary file is robocal's: the file's absolute path, device and inode. Only a file a
/// record names, with the same device and inode, whose process no longer exists, is ever removed
/// as stale: a user's file is never taken for a temporary, whatever its name.
pub(crate) struct Record {
    path: Option<PathBuf>,
}

impl Record {
    /// Records the temporary `tmp` (just created, open as `file`). Without a private directory
    /// (or without Unix) nothing is recorded and the file is only removed by this process.
    pub(crate) fn write(tmp: &Path, file: &std::fs::File) -> Record {
        Record {
            path: imp::write_record(tmp, file),
        }
    }

    /// The record's path; none when nothing was recorded.
    pub(crate) fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Removes the record (the temporary was renamed into place or removed).
    pub(crate) fn remove(&self) {
        if let Some(p) = &self.path {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Removes the temporary files that runs which no longer exist left behind (killed by SIGKILL
/// or a power cut, which no handler can catch), as their records name them: only a regular file
/// with the recorded device and inode. Records of live processes (or when that cannot be told)
/// are left alone, this process's own among them.
pub(crate) fn remove_stale() {
    imp::remove_stale();
}

#[cfg(unix)]
mod imp {
    use super::process_alive;
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::MetadataExt;
    use std::path::{Path, PathBuf};

    fn records_dir() -> Option<PathBuf> {
        let d = crate::io::claims::private_dir().ok()?.join("temporaries");
        match std::fs::create_dir(&d) {
            Ok(()) => Some(d),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Some(d),
            Err(_) => None,
        }
    }

    pub(super) fn write_record(tmp: &Path, file: &std::fs::File) -> Option<PathBuf> {
        let m = file.metadata().ok()?;
        let abs = std::path::absolute(tmp).ok()?;
        let rec = records_dir()?.join(format!(
            "{}-{:016x}",
            std::process::id(),
            rand::random::<u64>()
        ));
        let mut text = format!("{} {}\n", m.dev(), m.ino()).into_bytes();
        text.extend_from_slice(abs.as_os_str().as_bytes());
        std::fs::File::options()
            .write(true)
            .create_new(true)
            .open(&rec)
            .and_then(|mut f| std::io::Write::write_all(&mut f, &text))
            .ok()?;
        Some(rec)
    }

    pub(super) fn remove_stale() {
        let Some(dir) = records_dir() else {
            return;
        };
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return;
        };
        for e in entries.flatten() {
            let name = e.file_name();
            let Some(pid) = name
                .to_str()
                .and_then(|n| n.split_once('-'))
                .and_then(|(pid, _)| pid.parse::<u32>().ok())
            else {
                continue;
            };
            if pid == std::process::id() || process_alive(pid) {
                continue;
            }
            let Ok(text) = std::fs::read(e.path()) else {
                continue;
            };
            let Some(k) = text.iter().position(|b| *b == b'\n') else {
                let _ = std::fs::remove_file(e.path());
                continue;
            };
            let (head, path) = (
                &text[..k],
                Path::new(std::ffi::OsStr::from_bytes(&text[k + 1..])),
            );
            let mut ids = std::str::from_utf8(head)
                .unwrap_or("")
                .split(' ')
                .map(|v| v.parse::<u64>().ok());
            if let (Some(Some(dev)), Some(Some(ino))) = (ids.next(), ids.next()) {
                let same = std::fs::symlink_metadata(path)
                    .is_ok_and(|m| m.is_file() && m.dev() == dev && m.ino() == ino);
                if same {
                    let _ = std::fs::remove_file(path);
                }
            }
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(not(unix))]
mod imp {
    use std::path::{Path, PathBuf};

    pub(super) fn write_record(_tmp: &Path, _file: &std::fs::File) -> Option<PathBuf> {
        None
    }

    pub(super) fn remove_stale() {}
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
    fn temporary_names_are_short_and_fresh() {
        let a = temporary_name();
        let b = temporary_name();
        assert_ne!(a, b);
        assert!(a.len() <= MAX_NAME, "{a}");
        assert!(
            a.starts_with(&format!(".robocal-{}-", std::process::id())),
            "{a}"
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
