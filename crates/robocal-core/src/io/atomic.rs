//! Writing files so that a failed or interrupted run never leaves a half-written file, never
//! destroys an earlier result and never replaces anything but a regular file: the content goes to
//! a temporary file `.robocal-PID-RANDOM.tmp` beside the target, which is renamed over it only
//! once complete. A symbolic link to a regular file is written through (see [`resolve_output`]).
//!
//! Temporary files are in a table while open, so that a signal handler can remove them all
//! ([`remove_temporaries`]), and recorded in robocal's private directory; those a killed run left
//! behind are removed by the next run that writes a file (only files a record proves are
//! robocal's: never a user's file, whatever its name).

use crate::error::{Error, Result};
pub use crate::io::open_temporaries::remove_temporaries;
use crate::io::open_temporaries::{add, interrupted, retiring, Open};
pub use crate::io::target::resolve_output;
use crate::io::temporaries::{remove_stale, temporary_name, Record};
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};

fn io_err(path: &Path, e: std::io::Error) -> Error {
    Error::Io {
        path: path.to_owned(),
        source: e,
    }
}

/// Where the content of an [`AtomicFile`] goes on commit.
enum Dest {
    /// The temporary file is renamed over `path` (the target with its symbolic links resolved).
    Rename { path: PathBuf },
    /// The spool file is copied to `sink`.
    Stream { sink: Box<dyn Write + Send> },
}

/// A file being written; becomes visible under its final name only on [`AtomicFile::commit`].
/// Dropped without commit, the temporary file is removed.
pub struct AtomicFile {
    /// The name the caller gave (for messages).
    target: PathBuf,
    dest: Dest,
    file: Option<BufWriter<File>>,
    /// The temporary file (its path and its place in the table of open temporaries), until it
    /// is renamed or removed. None for a spool without a name (on Unix it is removed as soon as
    /// it is open).
    open: Option<Open>,
}

impl AtomicFile {
    /// Starts writing `target`. Fails (naming the path) if its directory does not exist or is not
    /// writable, if `target` is (or links to) a directory, device, FIFO or socket, or if the run
    /// is being interrupted. Temporaries left by runs that no longer exist are removed. An existing target's permissions are kept.
    pub fn create(target: &Path) -> Result<AtomicFile> {
        let path = resolve_output(target)?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
            _ => PathBuf::from("."),
        };
        // Before the step below, which blocks SIGINT and SIGTERM on this thread while it runs.
        remove_stale();
        // Created in the table of open temporaries: a signal handler removing them sees it, or
        // this sees that the run is being interrupted.
        let (file, open) = add(target, || {
            let mut attempt = 0;
            let (tmp, file) = loop {
                let tmp = dir.join(temporary_name());
                match File::options().write(true).create_new(true).open(&tmp) {
                    Ok(file) => break (tmp, file),
                    // A file of that name exists (never opened, never replaced): draw another.
                    Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempt < 8 => {
                        attempt += 1;
                    }
                    Err(e) => return Err(io_err(target, e)),
                }
            };
            let record = Record::write(&tmp, &file);
            Ok((file, Some((tmp, record))))
        })?;
        if let Ok(m) = std::fs::metadata(&path) {
            let _ = file.set_permissions(m.permissions());
        }
        Ok(AtomicFile {
            target: target.to_owned(),
            dest: Dest::Rename { path },
            file: Some(BufWriter::new(file)),
            open,
        })
    }

    /// Starts writing to `sink` (e.g. standard output) under the name `label` (for messages):
    /// the content is spooled to an anonymous temporary file and copied to `sink` only on
    /// [`AtomicFile::commit`], so that a failed run writes nothing there either.
    pub fn stream(label: &Path, sink: Box<dyn Write + Send>) -> Result<AtomicFile> {
        static SPOOLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = SPOOLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp =
            std::env::temp_dir().join(format!(".robocal-spool.{}.{k}.tmp", std::process::id()));
        let (file, open) = add(label, || {
            let file = File::options()
                .read(true)
                .write(true)
                .create_new(true)
                .open(&tmp)
                .map_err(|e| io_err(&tmp, e))?;
            // Unix keeps an open file's content after its name is removed: then nothing can be
            // left behind, whatever ends the process.
            if std::fs::remove_file(&tmp).is_ok() {
                return Ok((file, None));
            }
            let record = Record::write(&tmp, &file);
            Ok((file, Some((tmp, record))))
        })?;
        Ok(AtomicFile {
            target: label.to_owned(),
            dest: Dest::Stream { sink },
            file: Some(BufWriter::new(file)),
            open,
        })
    }

    /// The path (or label) given.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Flushes, syncs and renames the temporary file over the target (or copies the spool to the
    /// stream). On failure the temporary file is removed and the target is left as it was.
    pub fn commit(self) -> Result<()> {
        commit_all(vec![self])
    }

    /// The writer, flushed and taken out (the temporary stays in the table of open temporaries
    /// until renamed).
    fn finish(&mut self) -> Result<File> {
        let Some(w) = self.file.take() else {
            return Err(io_err(
                &self.target,
                std::io::Error::other("already committed"),
            ));
        };
        let file = w
            .into_inner()
            .map_err(|e| io_err(&self.target, e.into_error()))?;
        if matches!(self.dest, Dest::Rename { .. }) {
            file.sync_all().map_err(|e| io_err(&self.target, e))?;
        }
        Ok(file)
    }

    /// Removes the temporary file if it is still this writer's (not renamed, not removed by
    /// [`remove_temporaries`]).
    fn discard(&mut self) {
        let Some(open) = self.open.take() else {
            return;
        };
        // None: the signal handler has it (and removes it).
        if let Some(mut r) = retiring([&open], false) {
            let _ = std::fs::remove_file(open.tmp());
            r.done(0, open);
        }
    }
}

/// Commits several files so that they are replaced together: all are claimed for this process
/// ([`crate::io::claim_outputs`]: refused while another run is writing one of them), completed
/// and synced first, then renamed one after the other with no interruption between them (a signal handler
/// calling [`remove_temporaries`] waits for the renames). Streams are copied last. On a failure
/// before the renames nothing is replaced and every temporary file is removed.
pub fn commit_all(mut files: Vec<AtomicFile>) -> Result<()> {
    if files.is_empty() {
        return Ok(());
    }
    // Another process writing one of these outputs now would interleave its set with this one.
    let targets: Vec<&Path> = files
        .iter()
        .filter_map(|f| match &f.dest {
            Dest::Rename { path } => Some(path.as_path()),
            Dest::Stream { .. } => None,
        })
        .collect();
    crate::io::claims::claim_outputs(&targets)?;
    let mut spooled = Vec::new();
    for f in &mut files {
        spooled.push(f.finish()?);
    }
    {
        // Renamed as one step a signal handler waits for; none once the run is being
        // interrupted.
        let renamed = files.iter().filter_map(|f| match (&f.dest, &f.open) {
            (Dest::Rename { .. }, Some(open)) => Some(open),
            _ => None,
        });
        let Some(mut r) = retiring(renamed, true) else {
            return Err(interrupted(&files[0].target));
        };
        let mut k = 0;
        for f in &mut files {
            let Dest::Rename { path } = &f.dest else {
                continue;
            };
            let Some(open) = f.open.take() else {
                continue;
            };
            if let Err(e) = std::fs::rename(open.tmp(), path) {
                // Still this writer's: removed when it is dropped.
                f.open = Some(open);
                return Err(io_err(&f.target, e));
            }
            r.done(k, open);
            k += 1;
        }
    }
    for (f, mut spool) in files.iter_mut().zip(spooled) {
        let target = f.target.clone();
        if let Dest::Stream { sink, .. } = &mut f.dest {
            spool
                .rewind()
                .and_then(|()| std::io::copy(&mut spool, sink))
                .and_then(|_| sink.flush())
                .map_err(|e| io_err(&target, e))?;
        }
    }
    Ok(())
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self.file.as_mut() {
            Some(f) => f.write(buf),
            None => Err(std::io::Error::other("already committed")),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match self.file.as_mut() {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        self.discard();
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_parts(path, &[bytes])
}

/// Writes the concatenation of `parts` to `path` atomically (without joining them in memory
/// first).
pub fn write_atomic_parts(path: &Path, parts: &[&[u8]]) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    for bytes in parts {
        f.write_all(bytes).map_err(|e| io_err(path, e))?;
    }
    f.commit()
}

/// Writes several files so that either all of them or none are replaced: each is written to a
/// temporary file first; only when all are complete are they renamed ([`commit_all`]).
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    let mut open = Vec::with_capacity(files.len());
    for (p, bytes) in files {
        let mut f = AtomicFile::create(p)?;
        f.write_all(bytes).map_err(|e| io_err(p, e))?;
        open.push(f);
    }
    commit_all(open)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_directory_is_an_error_and_writes_nothing() {
        let e = write_atomic(Path::new("/nonexistent-dir-robocal/x.csv"), b"a")
            .unwrap_err()
            .to_string();
        assert!(e.contains("/nonexistent-dir-robocal/x.csv"), "{e}");
        assert!(e.contains("does not exist"), "{e}");
    }

    #[test]
    fn failed_rename_leaves_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("robocal-atomic-mv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("r.json");
        let mut f = AtomicFile::create(&p).unwrap();
        f.write_all(b"new").unwrap();
        // The target turns into a non-empty directory before the commit: rename fails.
        std::fs::create_dir_all(p.join("x")).unwrap();
        let e = f.commit().unwrap_err().to_string();
        assert!(e.contains("r.json"), "{e}");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("r.json")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn dropped_without_commit_leaves_old_file() {
        let dir = std::env::temp_dir().join(format!("robocal-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("r.json");
        write_atomic(&p, b"old").unwrap();
        {
            let mut f = AtomicFile::create(&p).unwrap();
            f.write_all(b"new, half").unwrap();
        }
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "temporary file left behind"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("robocal-atomic-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// Only a file that a record of a dead run names, with the recorded device and inode, is
    /// removed as stale; files named like temporaries without such a record are the user's.
    #[cfg(unix)]
    #[test]
    fn only_recorded_temporaries_of_dead_runs_are_removed() {
        use std::os::unix::fs::MetadataExt;
        let d = scratch("stale");
        let records = crate::io::claims::private_dir()
            .unwrap()
            .join("temporaries");
        std::fs::create_dir_all(&records).unwrap();
        let record = |name: &str, file: &Path, ino_offset: u64| {
            let m = std::fs::metadata(file).unwrap();
            let text = format!(
                "{} {}\n{}",
                m.dev(),
                m.ino() + ino_offset,
                std::path::absolute(file).unwrap().display()
            );
            std::fs::write(records.join(name), text).unwrap();
        };
        // A dead run's temporary (pid 999999999 cannot exist), recorded.
        let stale = d.join(".robocal-999999999-00000000000000aa.tmp");
        std::fs::write(&stale, "left by a killed run").unwrap();
        record("999999999-00000000000000aa", &stale, 0);
        // A user's file under such a name, no record; one whose record names another inode
        // (the temporary was removed and the name reused); a live process's (pid 1).
        std::fs::write(d.join(".robocal-999999999-00000000000000bb.tmp"), "user").unwrap();
        let reused = d.join(".robocal-999999999-00000000000000cc.tmp");
        std::fs::write(&reused, "user").unwrap();
        record("999999999-00000000000000cc", &reused, 1);
        let live = d.join(".robocal-1-00000000000000dd.tmp");
        std::fs::write(&live, "live").unwrap();
        record("1-00000000000000dd", &live, 0);
        write_atomic(&d.join("r.json"), b"new").unwrap();
        assert_eq!(
            names(&d),
            [
                ".robocal-1-00000000000000dd.tmp",
                ".robocal-999999999-00000000000000bb.tmp",
                ".robocal-999999999-00000000000000cc.tmp",
                "r.json"
            ]
        );
        // The dead runs' records are gone, the live one's stays.
        assert!(!records.join("999999999-00000000000000aa").exists());
        assert!(!records.join("999999999-00000000000000cc").exists());
        assert!(records.join("1-00000000000000dd").exists());
        std::fs::remove_file(records.join("1-00000000000000dd")).unwrap();
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_name_of_255_bytes_can_be_written() {
        let d = scratch("long");
        let p = d.join(format!("{}.csv", "n".repeat(251)));
        write_atomic(&p, b"x").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"x");
        assert_eq!(names(&d).len(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_to_a_regular_file_is_written_through_and_kept() {
        let d = scratch("link");
        std::fs::write(d.join("real.json"), "old").unwrap();
        std::os::unix::fs::symlink("real.json", d.join("link.json")).unwrap();
        write_atomic(&d.join("link.json"), b"new").unwrap();
        assert!(std::fs::symlink_metadata(d.join("link.json"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(d.join("real.json")).unwrap(), b"new");
        assert_eq!(names(&d), ["link.json", "real.json"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_never_replaced() {
        let d = scratch("special");
        std::os::unix::fs::symlink("/dev/null", d.join("null.csv")).unwrap();
        let e = write_atomic(&d.join("null.csv"), b"x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("character device"), "{e}");
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device());
        assert_eq!(names(&d), ["null.csv"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn permissions_of_the_old_file_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("mode");
        let p = d.join("r.json");
        std::fs::write(&p, "old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&p, b"new").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_stream_gets_the_content_only_on_commit() {
        #[derive(Clone, Default)]
        struct Sink(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);
        impl Write for Sink {
            fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
                self.0.lock().unwrap().extend_from_slice(b);
                Ok(b.len())
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let sink = Sink::default();
        let mut f =
            AtomicFile::stream(Path::new("standard output"), Box::new(sink.clone())).unwrap();
        f.write_all(b"a,b\n1,2\n").unwrap();
        assert!(sink.0.lock().unwrap().is_empty());
        f.commit().unwrap();
        assert_eq!(*sink.0.lock().unwrap(), b"a,b\n1,2\n");
        let dropped = Sink::default();
        {
            let mut f = AtomicFile::stream(Path::new("standard output"), Box::new(dropped.clone()))
                .unwrap();
            f.write_all(b"half").unwrap();
        }
        assert!(dropped.0.lock().unwrap().is_empty());
    }
}
