//! The input files a result was made from (DESIGN.md, "Calibrate: which model": the result's
//! `inputs`): each with its path and the SHA-256 of its bytes, so that a command that reads one
//! of them again (`report`, `evaluate`) can tell that it is still the file that was calibrated.
//!
//! The digest is SHA-256 from the RustCrypto `sha2` crate: a well-kept implementation of a
//! standard function is preferable to one of our own.

use crate::error::{Error, Result};
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// One input file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputFile {
    /// Its path as it was given (relative to the directory the command ran in, as the result's
    /// `settings` record it; the same arguments give the same result, byte for byte).
    pub path: String,
    /// The SHA-256 of its bytes, lower-case hexadecimal.
    pub sha256: String,
}

/// The result's `inputs`: role (`robot`, `data`, `validation`) to file.
pub type Inputs = IndexMap<String, InputFile>;

/// The SHA-256 of `bytes`, lower-case hexadecimal.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(digest: &[u8]) -> String {
    let mut s = String::with_capacity(64);
    for b in digest {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

/// The SHA-256 of the file at `path`, read in blocks (a million-row measurement file is not
/// held in memory to be hashed); its path in the error.
fn sha256_of_file(path: &Path) -> Result<String> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut hasher = Sha256::new();
    std::io::copy(&mut file, &mut hasher).map_err(io)?;
    Ok(hex(&hasher.finalize()))
}

impl InputFile {
    /// The record of the file at `path` as it is now.
    pub fn of(path: &Path) -> Result<InputFile> {
        Ok(InputFile {
            path: path.display().to_string(),
            sha256: sha256_of_file(path)?,
        })
    }

    /// The record of a file at `path` whose bytes are `bytes` (a file about to be written).
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> InputFile {
        InputFile {
            path: path.display().to_string(),
            sha256: sha256_hex(bytes),
        }
    }
}

/// The recorded input whose path is the same file as `path`, if any (compared as canonical
/// paths).
pub fn recorded<'a>(inputs: &'a Inputs, path: &Path) -> Option<(&'a str, &'a InputFile)> {
    let want = std::fs::canonicalize(path).ok()?;
    inputs.iter().find_map(|(role, f)| {
        let have = std::fs::canonicalize(&f.path).ok()?;
        (have == want).then_some((role.as_str(), f))
    })
}

/// Fails ([`Error::Invalid`], exit 3) when `path` is one of the result's recorded inputs and its
/// bytes changed since the calibration; `result_path` names the result in the message. A file
/// the result does not record passes.
pub fn check_unchanged(inputs: &Inputs, path: &Path, result_path: &Path) -> Result<()> {
    let Some((role, f)) = recorded(inputs, path) else {
        return Ok(());
    };
    let now = sha256_of_file(path)?;
    if now != f.sha256 {
        return Err(Error::invalid(
            path.display().to_string(),
            format!(
                "this file changed since it was calibrated: {} records it as `inputs.{role}` with \
                 SHA-256 {}, and it now has {now}. Its points are no longer the ones the result \
                 was made from; calibrate again, or use the original file",
                result_path.display(),
                f.sha256
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_of_known_strings() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn a_changed_file_is_named_and_an_unrecorded_one_passes() {
        let dir = std::env::temp_dir().join(format!("robocal-inputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("cell.csv");
        std::fs::write(&f, "q1,x\n1,2\n").unwrap();
        let mut inputs = Inputs::new();
        inputs.insert("data".into(), InputFile::of(&f).unwrap());
        let result = dir.join("r.json");
        check_unchanged(&inputs, &f, &result).unwrap();
        let other = dir.join("other.csv");
        std::fs::write(&other, "x").unwrap();
        check_unchanged(&inputs, &other, &result).unwrap();
        std::fs::write(&f, "q1,x\n1,3\n").unwrap();
        let e = check_unchanged(&inputs, &f, &result)
            .unwrap_err()
            .to_string();
        assert!(e.contains("changed since it was calibrated"), "{e}");
        assert!(e.contains("inputs.data"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
