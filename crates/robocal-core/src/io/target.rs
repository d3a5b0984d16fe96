//! Where an output file really goes: robocal replaces only regular files. A symbolic link to a
//! regular file is written through (its target is replaced, the link kept); a directory, device,
//! FIFO or socket, or a link to one, is refused before anything is written.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Most symbolic links followed for a path that does not exist yet (as Linux's MAXSYMLINKS).
const MAX_LINKS: usize = 40;

fn io_err(path: &Path, msg: String) -> Error {
    Error::Io {
        path: path.to_owned(),
        source: std::io::Error::other(msg),
    }
}

/// What a file that is not a regular file is, in words.
fn kind(m: &std::fs::Metadata) -> &'static str {
    let t = m.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// The path an output named `target` is written to: `target` itself, or for a symbolic link the
/// file it finally points to (which may not exist yet). Fails, naming `target`, when it is or
/// points to anything but a regular file (directory, character or block device, FIFO, socket),
/// when its directory does not exist, or when it has no file name.
pub fn resolve_output(target: &Path) -> Result<PathBuf> {
    let is_link = std::fs::symlink_metadata(target).is_ok_and(|m| m.file_type().is_symlink());
    match std::fs::metadata(target) {
        Ok(m) if m.is_file() && !is_link => Ok(target.to_owned()),
        Ok(m) if m.is_file() => std::fs::canonicalize(target).map_err(|e| Error::Io {
            path: target.to_owned(),
            source: e,
        }),
        Ok(m) if m.is_dir() && !is_link => Err(io_err(
            target,
            "is a directory, expected a file path".into(),
        )),
        Ok(m) => {
            let what = kind(&m);
            let through = if is_link {
                match std::fs::canonicalize(target) {
                    Ok(p) => format!("is a symbolic link to {}, {what}", p.display()),
                    Err(_) => format!("is a symbolic link to {what}"),
                }
            } else {
                format!("is {what}")
            };
            Err(io_err(
                target,
                format!(
                    "{through}, not a regular file: robocal replaces only regular files; give \
                     the path of a file"
                ),
            ))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => new_file(target),
        Err(e) => Err(Error::Io {
            path: target.to_owned(),
            source: e,
        }),
    }
}

/// A path that does not exist, or a chain of symbolic links ending at one: where the new file
/// goes, if its directory exists.
fn new_file(target: &Path) -> Result<PathBuf> {
    let mut p = target.to_owned();
    for _ in 0..MAX_LINKS {
        match std::fs::read_link(&p) {
            Ok(to) => {
                p = match p.parent() {
                    Some(d) if to.is_relative() => d.join(to),
                    _ => to,
                }
            }
            Err(_) => {
                if p.file_name().is_none() {
                    return Err(io_err(target, "is not a file path".into()));
                }
                let dir = match p.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d,
                    _ => Path::new("."),
                };
                if !dir.is_dir() {
                    return Err(Error::Io {
                        path: target.to_owned(),
                        source: std::io::Error::new(
                            std::io::ErrorKind::NotFound,
                            format!("directory {} does not exist", dir.display()),
                        ),
                    });
                }
                return Ok(p);
            }
        }
    }
    Err(io_err(
        target,
        format!("more than {MAX_LINKS} symbolic links in a chain"),
    ))
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    fn dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("robocal-target-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn regular_files_and_new_paths_are_written_where_named() {
        let d = dir("plain");
        let f = d.join("a.csv");
        assert_eq!(resolve_output(&f).unwrap(), f);
        std::fs::write(&f, "x").unwrap();
        assert_eq!(resolve_output(&f).unwrap(), f);
        let e = resolve_output(&d.join("no/b.csv")).unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn links_are_written_through_to_their_regular_target() {
        let d = dir("link");
        let f = d.join("real.csv");
        std::fs::write(&f, "x").unwrap();
        let l = d.join("link.csv");
        std::os::unix::fs::symlink("real.csv", &l).unwrap();
        assert_eq!(resolve_output(&l).unwrap(), f.canonicalize().unwrap());
        // A dangling link: the file is created where it points.
        let dl = d.join("dangling.csv");
        std::os::unix::fs::symlink("new.csv", &dl).unwrap();
        assert_eq!(resolve_output(&dl).unwrap(), d.join("new.csv"));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn special_files_and_links_to_them_are_refused() {
        let d = dir("special");
        let e = resolve_output(Path::new("/dev/null"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("/dev/null: is a character device"), "{e}");
        let l = d.join("null.csv");
        std::os::unix::fs::symlink("/dev/null", &l).unwrap();
        let e = resolve_output(&l).unwrap_err().to_string();
        assert!(
            e.contains("is a symbolic link to /dev/null, a character device"),
            "{e}"
        );
        let e = resolve_output(&d).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        let dl = d.join("dir-link");
        std::os::unix::fs::symlink(&d, &dl).unwrap();
        let e = resolve_output(&dl).unwrap_err().to_string();
        assert!(e.contains("a directory, not a regular file"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
