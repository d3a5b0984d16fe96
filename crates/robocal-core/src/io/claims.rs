//! Claims on output files: a run that is going to write a set of outputs (a measurement CSV and
//! its truth file, a report directory) claims every one of them first, so that two runs writing
//! the same outputs at the same time cannot interleave their files. The second run is refused,
//! naming the first one's process, before it writes anything.
//!
//! A claim is an advisory lock (`flock`) on a lock file named after the output's absolute path
//! in robocal's private directory (`private_dir`), never beside the outputs:
//! nothing is created in the user's directories, and the operating system releases every lock
//! when the process ends, however it ends. Claims are held until the process exits. Without
//! Unix, claims are not made.

use crate::error::{Error, Result};
use std::path::{Component, Path, PathBuf};

/// Claims the outputs `paths` for this process, all or none: fails (an I/O error naming the
/// output and the process holding it) when another live process has claimed one of them. An
/// output this process claimed already is claimed again without error.
pub fn claim_outputs(paths: &[&Path]) -> Result<()> {
    imp::claim(paths)
}

/// The path an output is known by: absolute, with the symbolic links of its existing part
/// resolved, so that every spelling of one file gives one claim.
fn key(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
    // The longest existing ancestor, canonicalized, and the rest as given (without `.`).
    let mut rest = Vec::new();
    let mut base = abs.as_path();
    loop {
        if let Ok(c) = std::fs::canonicalize(base) {
            let mut k = c;
            for part in rest.iter().rev() {
                k.push(part);
            }
            return k;
        }
        match (base.parent(), base.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_owned());
                base = parent;
            }
            _ => {
                return abs
                    .components()
                    .filter(|c| *c != Component::CurDir)
                    .collect()
            }
        }
    }
}

/// robocal's private directory (`$TMPDIR/robocal-UID`, mode 0700, created if needed): the
/// claims on outputs and the records of temporary files, never anything beside the outputs.
#[cfg(unix)]
pub(crate) fn private_dir() -> std::io::Result<PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt};
    // SAFETY: getuid has no preconditions and cannot fail.
    let uid = unsafe { libc::getuid() };
    let dir = std::env::temp_dir().join(format!("robocal-{uid}"));
    match std::fs::DirBuilder::new().mode(0o700).create(&dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(e),
    }
    let m = std::fs::symlink_metadata(&dir)?;
    if !m.is_dir() || m.uid() != uid {
        return Err(std::io::Error::other(format!(
            "{} is not a directory of this user's",
            dir.display()
        )));
    }
    Ok(dir)
}

/// FNV-1a, 64 bits: the lock file's name from the key (the same in every process).
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[cfg(unix)]
mod imp {
    use super::{fnv1a, key, Error, Result};
    use std::fs::File;
    use std::io::Read;
    use std::os::fd::AsRawFd;
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::FileExt;
    use std::path::{Path, PathBuf};
    use std::sync::Mutex;

    /// The width of the process id in a lock file (a `u32` has at most 10 digits).
    const ID_WIDTH: usize = 10;

    /// The claims this process holds: the output's key and its open, locked lock file.
    static HELD: Mutex<Vec<(PathBuf, File)>> = Mutex::new(Vec::new());

    /// The directory of the lock files.
    fn lock_dir() -> std::io::Result<PathBuf> {
        let d = super::private_dir()?.join("claims");
        match std::fs::create_dir(&d) {
            Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => Err(e),
            _ => Ok(d),
        }
    }

    pub(super) fn claim(paths: &[&Path]) -> Result<()> {
        let mut held = HELD
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let mut new: Vec<(PathBuf, File)> = Vec::new();
        for path in paths {
            let k = key(path);
            if held.iter().chain(new.iter()).any(|(h, _)| *h == k) {
                continue;
            }
            let file = lock(&k).map_err(|e| Error::Io {
                path: path.to_path_buf(),
                source: e,
            })?;
            new.push((k, file));
        }
        held.extend(new);
        Ok(())
    }

    #[cfg(test)]
    pub(super) fn lock_for_test(key: &Path) -> std::io::Result<File> {
        lock(key)
    }

    /// Opens and locks the lock file of `key`, then writes this process's id into it.
    fn lock(key: &Path) -> std::io::Result<File> {
        let dir = lock_dir()?;
        let name = format!("{:016x}.lock", fnv1a(key.as_os_str().as_bytes()));
        let mut f = File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(dir.join(name))?;
        // SAFETY: flock on a descriptor this function owns.
        if unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
            let e = std::io::Error::last_os_error();
            if e.raw_os_error() != Some(libc::EWOULDBLOCK) {
                return Err(e);
            }
            let mut holder = String::new();
            let _ = f.read_to_string(&mut holder);
            let holder = holder.trim();
            let who = if holder.is_empty() {
                String::new()
            } else {
                format!(" (process {holder})")
            };
            return Err(std::io::Error::other(format!(
                "another robocal run{who} is writing this output; nothing was written: run \
                     again once it has finished, or give another output"
            )));
        }
        // The id padded to a fixed width, written over the last holder's: the file keeps its
        // length and its block (truncating it first cost a block's release and allocation in
        // every run). Readers trim the padding.
        let id = format!("{:<ID_WIDTH$}", std::process::id());
        if f.metadata()?.len() != ID_WIDTH as u64 {
            f.set_len(0)?;
        }
        f.write_all_at(id.as_bytes(), 0)?;
        Ok(f)
    }
}

#[cfg(not(unix))]
mod imp {
    use super::Result;
    use std::path::Path;

    pub(super) fn claim(_paths: &[&Path]) -> Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_file_has_one_key_however_spelled() {
        let d = std::env::temp_dir().join(format!("robocal-claims-key-{}", std::process::id()));
        std::fs::create_dir_all(d.join("sub")).unwrap();
        assert_eq!(key(&d.join("sub/../a.csv")), key(&d.join("a.csv")));
        assert_eq!(key(&d.join("./new/b.csv")), key(&d.join("new/b.csv")));
        assert_ne!(key(&d.join("a.csv")), key(&d.join("b.csv")));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_claim_is_held_once_per_process_and_refused_to_another_descriptor() {
        let d = std::env::temp_dir().join(format!("robocal-claims-two-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let out = d.join("x.csv");
        claim_outputs(&[&out]).unwrap();
        claim_outputs(&[&out, &out]).unwrap();
        // Another open file description (as another process would have) is refused, and told
        // which process holds the claim.
        let e = imp_other_lock(&key(&out)).unwrap_err().to_string();
        assert!(e.contains("another robocal run"), "{e}");
        assert!(
            e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A lock file keeps this process's id alone, whatever an earlier holder (or an older
    /// robocal, which wrote the id unpadded) left in it.
    #[cfg(unix)]
    #[test]
    fn a_lock_file_holds_the_holders_id_alone() {
        use std::os::unix::ffi::OsStrExt;
        let d = std::env::temp_dir().join(format!("robocal-claims-id-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        for (k, before) in ["", "123", "4294967295 and more"].iter().enumerate() {
            let out = key(&d.join(format!("{k}.csv")));
            let file = private_dir()
                .unwrap()
                .join("claims")
                .join(format!("{:016x}.lock", fnv1a(out.as_os_str().as_bytes())));
            std::fs::create_dir_all(file.parent().unwrap()).unwrap();
            std::fs::write(&file, before).unwrap();
            let held = imp_other_lock(&out).unwrap();
            let text = std::fs::read_to_string(&file).unwrap();
            assert_eq!(text.trim(), std::process::id().to_string(), "{before:?}");
            assert_eq!(text.len(), 10, "{text:?}");
            drop(held);
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Locks `key` through a new open file description, as another process would.
    #[cfg(unix)]
    fn imp_other_lock(k: &Path) -> std::io::Result<std::fs::File> {
        imp::lock_for_test(k)
    }
}
