//! Writing files so that a failed run never leaves a half-written file or destroys an earlier
//! result: the content goes to a temporary file beside the target, which is renamed over it only
//! once complete.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

fn io_err(path: &Path, e: std::io::Error) -> Error {
    Error::Io {
        path: path.to_owned(),
        source: e,
    }
}

/// A file being written; becomes visible under its final name only on [`AtomicFile::commit`].
/// Dropped without commit, the temporary file is removed.
pub struct AtomicFile {
    target: PathBuf,
    tmp: PathBuf,
    file: Option<std::io::BufWriter<std::fs::File>>,
}

impl AtomicFile {
    /// Starts writing `target`. Fails (naming the path) if its directory does not exist or is not
    /// writable, or if `target` is a directory.
    pub fn create(target: &Path) -> Result<AtomicFile> {
        if target.is_dir() {
            return Err(io_err(
                target,
                std::io::Error::other("is a directory, expected a file path"),
            ));
        }
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            return Err(io_err(
                target,
                std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("directory {} does not exist", dir.display()),
                ),
            ));
        }
        let name = target
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
        let file = std::fs::File::create(&tmp).map_err(|e| io_err(target, e))?;
        Ok(AtomicFile {
            target: target.to_owned(),
            tmp,
            file: Some(std::io::BufWriter::new(file)),
        })
    }

    /// The final path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Flushes, syncs and renames the temporary file over the target. On failure the temporary
    /// file is removed and the target is left as it was.
    pub fn commit(mut self) -> Result<()> {
        let Some(mut w) = self.file.take() else {
            return Ok(());
        };
        let done = w
            .flush()
            .and_then(|()| w.into_inner().map_err(|e| e.into_error()))
            .and_then(|f| f.sync_all())
            .and_then(|()| std::fs::rename(&self.tmp, &self.target));
        if let Err(e) = done {
            let _ = std::fs::remove_file(&self.tmp);
            return Err(io_err(&self.target, e));
        }
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.file.as_mut().expect("not yet committed").write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.file.as_mut().expect("not yet committed").flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes).map_err(|e| io_err(path, e))?;
    f.commit()
}

/// Writes several files so that either all of them or none are replaced: each is written to a
/// temporary file first; only when all are complete are they renamed.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    let mut open = Vec::with_capacity(files.len());
    for (p, bytes) in files {
        let mut f = AtomicFile::create(p)?;
        f.write_all(bytes).map_err(|e| io_err(p, e))?;
        open.push(f);
    }
    for f in open {
        f.commit()?;
    }
    Ok(())
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
}
