//! Reading text exports line by line (a UTF-8 byte-order mark, CRLF), splitting lines into
//! fields by the file's delimiter, and reading numbers with a decimal point or comma. Every
//! error names the file, the line and the field.

use crate::error::{Error, Result};
use std::fmt;
use std::io::BufRead;
use std::path::{Path, PathBuf};

/// How fields are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    /// `,`
    Comma,
    /// `;`
    Semicolon,
    /// A tab.
    Tab,
    /// Runs of spaces or tabs.
    Whitespace,
}

impl Delimiter {
    /// The most frequent of `;`, tab and `,` in a header line, or whitespace when it has none.
    pub fn of_header(line: &str) -> Delimiter {
        let count = |c: char| line.chars().filter(|&x| x == c).count();
        let (sc, tab, comma) = (count(';'), count('\t'), count(','));
        if sc == 0 && tab == 0 && comma == 0 {
            Delimiter::Whitespace
        } else if sc >= tab && sc >= comma {
            Delimiter::Semicolon
        } else if tab >= comma {
            Delimiter::Tab
        } else {
            Delimiter::Comma
        }
    }

    /// Splits a line into trimmed fields (surrounding double quotes removed).
    pub fn split<'a>(self, line: &'a str, out: &mut Vec<&'a str>) {
        out.clear();
        // Quotes are looked for only where a field has them (this runs for every field of
        // logs of millions of rows).
        let unquote = |t: &'a str| {
            if t.starts_with('"') || t.ends_with('"') {
                t.trim_matches('"').trim()
            } else {
                t
            }
        };
        let clean = |f: &'a str| unquote(f.trim());
        match self {
            Delimiter::Comma => out.extend(line.split(',').map(clean)),
            Delimiter::Semicolon => out.extend(line.split(';').map(clean)),
            Delimiter::Tab => out.extend(line.split('\t').map(clean)),
            Delimiter::Whitespace if line.is_ascii() => {
                out.extend(line.split_ascii_whitespace().map(unquote))
            }
            Delimiter::Whitespace => out.extend(line.split_whitespace().map(unquote)),
        }
    }
}

impl fmt::Display for Delimiter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Delimiter::Comma => "comma",
            Delimiter::Semicolon => "semicolon",
            Delimiter::Tab => "tab",
            Delimiter::Whitespace => "whitespace",
        })
    }
}

/// How a file was read: its delimiter, decimal mark and header line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dialect {
    /// The field separator.
    pub delimiter: Delimiter,
    /// `.` or `,`.
    pub decimal: char,
    /// The 1-based line of the column header, if the file has one.
    pub header_line: Option<usize>,
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} separated, decimal {}",
            self.delimiter,
            if self.decimal == ',' {
                "comma"
            } else {
                "point"
            }
        )?;
        match self.header_line {
            Some(l) => write!(f, ", header on line {l}"),
            None => write!(f, ", no header"),
        }
    }
}

/// A text file read line by line, with true 1-based line numbers.
pub struct LineReader<R> {
    reader: R,
    buf: Vec<u8>,
    line: usize,
    path: PathBuf,
}

impl<R: BufRead> LineReader<R> {
    /// Reads `reader`; `path` names it in errors.
    pub fn new(reader: R, path: &Path) -> Self {
        LineReader {
            reader,
            buf: Vec::with_capacity(256),
            line: 0,
            path: path.to_owned(),
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The number of the last line read (0 before the first).
    pub fn line(&self) -> usize {
        self.line
    }

    /// The next whole lines, about `size` bytes of them (more to end the last line), into
    /// `block` (cleared first; its memory reused): the bytes as the file has them (line endings
    /// kept); `false` at the end of the file. The caller numbers the lines: [`LineReader::line`]
    /// is not advanced, so use [`LineReader::skip_lines`].
    pub fn read_block_into(&mut self, size: usize, block: &mut Vec<u8>) -> Result<bool> {
        let io = |e| Error::Io {
            path: self.path.clone(),
            source: e,
        };
        block.clear();
        while block.len() < size {
            let buf = self.reader.fill_buf().map_err(io)?;
            if buf.is_empty() {
                break;
            }
            let take = buf.len().min(size - block.len());
            block.extend_from_slice(&buf[..take]);
            self.reader.consume(take);
        }
        if block.is_empty() {
            return Ok(false);
        }
        if block.last() != Some(&b'\n') {
            self.reader.read_until(b'\n', block).map_err(io)?;
        }
        Ok(true)
    }

    /// Counts `n` lines as read (after [`LineReader::read_block_into`]).
    pub fn skip_lines(&mut self, n: usize) {
        self.line += n;
    }

    /// The next line (without its line ending or a leading byte-order mark) and its number.
    pub fn next_line(&mut self) -> Result<Option<(usize, &str)>> {
        self.buf.clear();
        let n = self
            .reader
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| Error::Io {
                path: self.path.clone(),
                source: e,
            })?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        while matches!(self.buf.last(), Some(b'\n' | b'\r')) {
            self.buf.pop();
        }
        let mut s = std::str::from_utf8(&self.buf)
            .map_err(|_| Error::parse(&self.path, Some(self.line), None, "not UTF-8 text"))?;
        if self.line == 1 {
            s = s.strip_prefix('\u{feff}').unwrap_or(s);
        }
        Ok(Some((self.line, s)))
    }
}

/// Reads a number written with `decimal` as its decimal mark. Errors name the file, line and
/// field.
pub fn number(path: &Path, line: usize, field: &str, text: &str, decimal: char) -> Result<f64> {
    let parsed = if decimal == ',' && text.contains(',') {
        text.replace(',', ".").parse::<f64>()
    } else {
        text.parse::<f64>()
    };
    match parsed {
        Ok(v) if v.is_finite() => Ok(v),
        _ if text.is_empty() => Err(Error::parse(path, Some(line), Some(field), "empty value")),
        _ => Err(Error::parse(
            path,
            Some(line),
            Some(field),
            format!("`{text}` is not a number"),
        )),
    }
}

/// Whether `text` reads as a number with a decimal point.
pub fn is_number(text: &str) -> bool {
    text.parse::<f64>().is_ok()
}

/// Whether `text` reads as a number with a decimal comma (and holds a comma).
pub fn is_comma_number(text: &str) -> bool {
    text.contains(',') && text.replace(',', ".").parse::<f64>().is_ok()
}

/// The error for a decimal comma in a file whose fields are separated by commas.
pub fn comma_ambiguity(path: &Path, line: usize, expected: usize, got: usize) -> Error {
    Error::parse(
        path,
        Some(line),
        None,
        format!(
            "{got} comma-separated fields where the header has {expected}: decimal commas with \
             comma separators cannot be read unambiguously; export with `;` or tab separators, \
             or with a decimal point"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delimiters_and_numbers() {
        assert_eq!(Delimiter::of_header("X;Y;Z"), Delimiter::Semicolon);
        assert_eq!(Delimiter::of_header("x\ty\tz"), Delimiter::Tab);
        assert_eq!(Delimiter::of_header("X  [mm],Y  [mm]"), Delimiter::Comma);
        assert_eq!(
            Delimiter::of_header("timestamp actual_q_0"),
            Delimiter::Whitespace
        );
        let mut v = Vec::new();
        Delimiter::Whitespace.split("  1  2\t3 ", &mut v);
        assert_eq!(v, ["1", "2", "3"]);
        Delimiter::Semicolon.split("P5;\"1,5\";;", &mut v);
        assert_eq!(v, ["P5", "1,5", "", ""]);
        let p = Path::new("f");
        assert_eq!(number(p, 1, "x", "1,5", ',').unwrap(), 1.5);
        assert!(number(p, 1, "x", "1,5", '.').is_err());
        let e = number(p, 7, "x", "abc", '.').unwrap_err().to_string();
        assert!(e.contains("f:7: field `x`: `abc` is not a number"), "{e}");
        assert!(number(p, 1, "x", "inf", '.').is_err());
    }

    #[test]
    fn lines_are_numbered_without_bom_and_crlf() {
        let text = "\u{feff}a\r\n\r\nb\n";
        let mut r = LineReader::new(text.as_bytes(), Path::new("f"));
        assert_eq!(r.next_line().unwrap(), Some((1, "a")));
        assert_eq!(r.next_line().unwrap(), Some((2, "")));
        assert_eq!(r.next_line().unwrap(), Some((3, "b")));
        assert_eq!(r.next_line().unwrap(), None);
    }
}
