//! Opening input files with errors that name the file and say what is wrong: a directory where
//! a file is expected is an I/O error (not a parse error at "line 1"), and text that is not UTF-8
//! is a parse error naming the line of the first bad byte (not an I/O error).

use crate::error::{Error, Result};
use std::path::Path;

/// Opens `path` for reading. Fails with [`Error::Io`] naming the path if it cannot be opened or
/// is a directory.
pub fn open_input(path: &Path) -> Result<std::fs::File> {
    let io = |e: std::io::Error| Error::Io {
        path: path.to_owned(),
        source: e,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    if file.metadata().map_err(io)?.is_dir() {
        return Err(io(std::io::Error::other("is a directory, expected a file")));
    }
    Ok(file)
}

/// Reads a whole text file (a leading UTF-8 byte-order mark is removed). Fails with [`Error::Io`]
/// if it cannot be read and with [`Error::Parse`] (naming the line) if it is not UTF-8.
pub fn read_text(path: &Path) -> Result<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    open_input(path)?
        .read_to_end(&mut bytes)
        .map_err(|e| Error::Io {
            path: path.to_owned(),
            source: e,
        })?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..at].iter().filter(|b| **b == b'\n').count();
        Error::parse(path, Some(line), None, "not valid UTF-8 text")
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(t) => t.to_owned(),
        None => text,
    })
}

/// Deserializes JSON `text` read from `path`, naming on failure the line and the field (its path,
/// e.g. `parameters.a2.calibrated`) of the first problem. `what` names the kind of file in the
/// message (`not a robocal result: ...`).
///
/// Stricter than serde_json: the text must end after the value (no second document, no trailing
/// garbage), and no object may have a key twice (serde_json would keep the last silently; see
/// [`crate::io::json_keys`]).
pub fn parse_json<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &Path,
    what: &str,
) -> Result<T> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Duplicates first, so that a repeated key reads the same whether serde's derived structs
    // would catch it (`duplicate field`) or a map would keep the last silently. Text that is not
    // one JSON document is left to the typed pass, whose errors name the field.
    if let Ok(Some(d)) = crate::io::json_keys::find_duplicate_key(text) {
        return Err(Error::parse(
            path,
            Some(d.line),
            Some(&d.path),
            format!(
                "not a {what}: the key `{}` appears twice in one object (which one is meant?)",
                d.path.rsplit('.').next().unwrap_or(&d.path)
            ),
        ));
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    let value: T =
        serde_path_to_error::deserialize(&mut *de).map_err(|e| json_error(e, path, what))?;
    de.end().map_err(|e| {
        let line = (e.line() > 0).then_some(e.line());
        Error::parse(
            path,
            line,
            None,
            format!(
                "not a {what}: text after the end of the JSON document (two documents \
                 concatenated, or characters after the last closing brace)"
            ),
        )
    })?;
    Ok(value)
}

fn json_error(e: serde_path_to_error::Error<serde_json::Error>, path: &Path, what: &str) -> Error {
    // The path up to the last known segment (`?` stands for a key not read yet).
    let field = e.path().to_string();
    let field = field.split(".?").next().unwrap_or("").trim_end_matches('?');
    let field = (!field.is_empty() && field != ".").then(|| field.to_owned());
    let inner = e.into_inner();
    let line = (inner.line() > 0).then_some(inner.line());
    let msg = inner.to_string();
    // serde_json appends " at line L column C"; the line is reported separately.
    let msg = msg.split(" at line ").next().unwrap_or(&msg).to_owned();
    Error::parse(path, line, field.as_deref(), format!("not a {what}: {msg}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directory_and_non_utf8_inputs() {
        let dir = std::env::temp_dir().join(format!("robocal-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let e = open_input(&dir).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
        assert!(e.to_string().contains("is a directory"), "{e}");
        let p = dir.join("latin1.txt");
        std::fs::write(&p, b"a = 1\nb = \"caf\xe9\"\n").unwrap();
        let e = read_text(&p).unwrap_err();
        assert!(matches!(e, Error::Parse { line: Some(2), .. }), "{e}");
        assert!(e.to_string().contains("not valid UTF-8"), "{e}");
        std::fs::write(&p, "\u{feff}x\r\n").unwrap();
        let e = parse_json::<std::collections::BTreeMap<String, Vec<f64>>>(
            "{\"a\": [1, 2],\n \"b\": [3, \"x\"]}",
            &p,
            "list",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains(":2: field `b[1]`: not a list: invalid type"),
            "{e}"
        );
        assert_eq!(read_text(&p).unwrap(), "x\r\n");
        let list = |t: &str| {
            parse_json::<std::collections::BTreeMap<String, serde_json::Value>>(t, &p, "list")
                .map_err(|e| e.to_string())
        };
        assert!(list("{\"a\": 1}\n\n").is_ok());
        let e = list("{\"a\": 1}\n{\"a\": 1}\n").unwrap_err();
        assert!(e.contains(":2: not a list: text after the end"), "{e}");
        let e = list("{\"a\": 1} x").unwrap_err();
        assert!(e.contains(":1: not a list: text after the end"), "{e}");
        let e = list("{\"a\": {\"b\": 1,\n\"c\": 2,\n\"b\": 3}}").unwrap_err();
        assert!(
            e.contains(":3: field `a.b`: not a list: the key `b` appears twice"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
