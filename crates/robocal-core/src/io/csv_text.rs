//! A small CSV file without quotes, read from memory: the records the `csv` reader of
//! [`crate::io::columns`] gives for such a file, without building that reader's parser (a
//! table of 2,560 entries per reader, about as much work as reading 150 rows) or validating
//! each row as UTF-8 again.
//!
//! A file qualifies when it is a regular file of at most [`SMALL_FILE`] bytes, is valid UTF-8,
//! has no `"` byte and has a line break in its first 64 KiB (or is no longer).
//! For such text the `csv` crate's records (robocal's settings: a header row, the header
//! trimmed, equal row lengths, any of `\r`, `\n` and `\r\n` ending a row) are the lines that are
//! not empty, split at the delimiter: a quote is the only byte that makes a field span a
//! delimiter or a line break. Lines are counted as [`crate::io::csv_lines::LineCounted`] counts
//! them (LF, CRLF and a lone CR each end one line), and a row of another length than the
//! header is rejected with the message of [`crate::io::columns::csv_error`]. Any other file is
//! read by the `csv` reader.

use crate::error::{Error, Result};
use crate::io::columns::Cells;
use std::io::Read;
use std::path::Path;

/// The largest file read this way (bytes); larger files are streamed.
pub const SMALL_FILE: u64 = 1 << 20;

/// The bytes `LineCounted` reads ahead at most (but for a last block) to find the delimiter.
const HEAD: usize = 65536;

/// A quote-free CSV text being read row by row.
pub(crate) struct CsvText {
    text: String,
    /// The next byte to read.
    pos: usize,
    /// Line ends passed so far.
    lines: usize,
    /// The field delimiter: that of the header line.
    delimiter: u8,
    /// The header's field count, once read.
    width: usize,
    /// Where each cell of the current row ends (reused from row to row).
    ends: Vec<usize>,
}

impl CsvText {
    /// The whole of `file` when it qualifies (see the module documentation), else `None` with
    /// the file read from its start again.
    pub fn of_file(file: &mut std::fs::File, path: &Path) -> Result<Option<CsvText>> {
        use std::io::{Seek, SeekFrom};
        let io = |source| Error::Io {
            path: path.to_owned(),
            source,
        };
        // Only a regular file: a pipe (`/dev/stdin`, a process substitution) cannot be read
        // again from its start.
        let meta = file.metadata().map_err(io)?;
        let len = meta.len();
        if !meta.is_file() || len > SMALL_FILE {
            return Ok(None);
        }
        let mut bytes = Vec::with_capacity(len as usize + 1);
        file.read_to_end(&mut bytes).map_err(io)?;
        // The `csv` reader takes its delimiter from the first 64 KiB when the first line is
        // longer (`LineCounted`): such a file is left to it.
        let head = &bytes[..bytes.len().min(HEAD)];
        let sniffed_alike = bytes.len() <= HEAD || memchr::memchr2(b'\r', b'\n', head).is_some();
        let text = match String::from_utf8(bytes) {
            Ok(t) if sniffed_alike && !t.as_bytes().contains(&b'"') => t,
            _ => {
                file.seek(SeekFrom::Start(0)).map_err(io)?;
                return Ok(None);
            }
        };
        Ok(Some(CsvText::new(text)))
    }

    /// Reads `text` (which has no `"`).
    fn new(text: String) -> CsvText {
        let delimiter = crate::io::csv_lines::sniff(text.as_bytes());
        CsvText {
            text,
            pos: 0,
            lines: 0,
            delimiter,
            width: 0,
            ends: Vec::new(),
        }
    }

    /// The delimiter (that of the header line).
    pub fn delimiter(&self) -> u8 {
        self.delimiter
    }

    /// The next line that is not empty: its 1-based line number and where it is in the text,
    /// `None` at the end.
    fn next_line(&mut self) -> Option<(usize, std::ops::Range<usize>)> {
        let bytes = self.text.as_bytes();
        let mut k = self.pos;
        while k < bytes.len() && matches!(bytes[k], b'\r' | b'\n') {
            // CR LF ends one line, a lone CR or LF one each.
            self.lines += usize::from(bytes[k] == b'\n' || bytes.get(k + 1) != Some(&b'\n'));
            k += 1;
        }
        if k == bytes.len() {
            self.pos = k;
            return None;
        }
        let end = memchr::memchr2(b'\r', b'\n', &bytes[k..]).map_or(bytes.len(), |j| k + j);
        self.pos = end;
        Some((self.lines + 1, k..end))
    }

    /// The header's fields (trimmed), into `record`; none for a file of no line.
    pub fn header(&mut self, record: &mut csv::StringRecord) {
        record.clear();
        if let Some((_, line)) = self.next_line() {
            for f in self.text[line].split(char::from(self.delimiter)) {
                record.push_field(f.trim());
            }
        }
        self.width = record.len();
    }

    /// The next row that is not blank (a cell that is not whitespace), as
    /// [`crate::io::columns::next_record`] reads it: its line and its cells; `None` at the end.
    /// A row of another length than the header's fails naming its line.
    pub fn next_record(&mut self, path: &Path) -> Result<Option<(usize, LineCells<'_>)>> {
        let (line, at) = loop {
            let Some((line, at)) = self.next_line() else {
                return Ok(None);
            };
            let text = &self.text[at.clone()];
            self.ends.clear();
            self.ends
                .extend(memchr::memchr_iter(self.delimiter, text.as_bytes()));
            self.ends.push(text.len());
            if self.ends.len() != self.width {
                return Err(Error::parse(
                    path,
                    Some(line),
                    None,
                    format!(
                        "{} fields, but the header has {}",
                        self.ends.len(),
                        self.width
                    ),
                ));
            }
            let cells = LineCells {
                text,
                ends: &self.ends,
            };
            if !(0..self.width).all(|k| cells.cell(k).trim().is_empty()) {
                break (line, at);
            }
        };
        let cells = LineCells {
            text: &self.text[at],
            ends: &self.ends,
        };
        Ok(Some((line, cells)))
    }
}

/// A row of a [`CsvText`]: its line and where each cell ends (at a delimiter or the line's
/// end).
pub(crate) struct LineCells<'a> {
    text: &'a str,
    ends: &'a [usize],
}

impl Cells for LineCells<'_> {
    #[inline]
    fn cell(&self, k: usize) -> &str {
        let start = if k == 0 { 0 } else { self.ends[k - 1] + 1 };
        &self.text[start..self.ends[k]]
    }
}

#[cfg(test)]
mod tests {
    use crate::io::measurements::{parse_measurements, read_measurements, Positions};
    use crate::model::JointSpace;
    use std::path::Path;

    /// Files of every dialect and defect read from memory give what the `csv` reader gives:
    /// the same rows, lines, extra cells and warnings, or the same message.
    #[test]
    fn small_files_read_as_the_csv_reader_reads_them() {
        let dir = std::env::temp_dir().join(format!("robocal-csv-text-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let lf = "id,q1,q2,x,y,z\na,1,2,7,8,9\n\nb,1,5,7,8,9\n";
        let mut texts: Vec<String> = vec![
            lf.to_owned(),
            lf.replace('\n', "\r\n"),
            lf.replace('\n', "\r"),
            lf.replace('\n', "\n\r"),
            lf.replace(',', ";"),
            lf.replace(',', "\t"),
            format!("\u{feff}{}", lf.replace("q", "Q")),
            format!("\n\r\n{lf}"),
            lf.trim_end().to_owned(),
            format!("{lf}\n\n\n"),
            format!(" id , q1 ,q2, x,y ,z \n a , 1 , 2 ,7,8,9 \n"),
            "q1;q2;x;y;z\n1,5;2;7,25;8;9\n".to_owned(),
            "q1,q2,x,y,z\n1,2,7,8,9\n,,,,\n  ,\t, , , \n3,4,7,8,9\n".to_owned(),
            "q1,q2,x,y,z\n1,2,7,8,9\n   \n".to_owned(),
            "q1,q2,x,y,z\n1,2,7,8\n".to_owned(),
            "q1,q2,x,y,z\r\n\r\n1,2,7,8,9\r\n1,2,7,8,9,\r\n".to_owned(),
            "q1,q2,x,y,z\n1,oops,7,8,9\n".to_owned(),
            "q1,q2,x,y,z\n".to_owned(),
            String::new(),
            "\n\n".to_owned(),
            "q1,,x,y,z\n1,2,7,8,9\n".to_owned(),
            "q1|q2|x|y|z\n1|2|7|8|9\n".to_owned(),
            "q1,q2,x,y,z,note\n1,2,7,8,9,caf\u{e9} \u{2003}\n".to_owned(),
            "q1,q2\n0.1,0.2\n0.3,-1\n1.2,0.5\n".to_owned(),
        ];
        texts.push(format!("q1,q2,x,y,z\n{}", "1,2,3,4,5\n".repeat(500)));
        for (k, text) in texts.iter().enumerate() {
            let file = dir.join(format!("{k}.csv"));
            std::fs::write(&file, text).unwrap();
            for positions in [Positions::Required, Positions::Optional, Positions::Ignored] {
                let joints = JointSpace::revolute(2);
                let streamed = parse_measurements(text.as_bytes(), &file, &joints, positions)
                    .map_err(|e| e.to_string());
                let read = read_measurements(&file, &joints, positions).map_err(|e| e.to_string());
                assert_eq!(read, streamed, "{text:?}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Files with quotes, bytes that are not UTF-8, or larger than [`super::SMALL_FILE`] are
    /// left to the `csv` reader.
    #[test]
    fn other_files_are_left_to_the_csv_reader() {
        let dir = std::env::temp_dir().join(format!("robocal-csv-other-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let small = |name: &str, bytes: &[u8]| {
            let p = dir.join(name);
            std::fs::write(&p, bytes).unwrap();
            let mut f = std::fs::File::open(&p).unwrap();
            let t = super::CsvText::of_file(&mut f, &p).unwrap();
            // A file left to the csv reader is read from its start.
            let mut rest = Vec::new();
            std::io::Read::read_to_end(&mut f, &mut rest).unwrap();
            (t.is_some(), rest == bytes)
        };
        assert_eq!(small("plain.csv", b"q1,q2\n1,2\n"), (true, false));
        assert_eq!(small("quoted.csv", b"q1,\"q2\"\n1,2\n"), (false, true));
        assert_eq!(
            small("latin1.csv", b"q1,q2,n\n1,2,caf\xe9\n"),
            (false, true)
        );
        let big = format!("q1,q2\n{}", "1,2\n".repeat(300_000));
        assert_eq!(small("big.csv", big.as_bytes()), (false, true));
        let wide = format!("q1,q2,{}\n1,2,3\n", "w".repeat(70_000));
        assert_eq!(small("wide.csv", wide.as_bytes()), (false, true));
        // Quotes are read the csv way, whichever path.
        let p = dir.join("quoted.csv");
        std::fs::write(&p, "q1,q2,x,y,z,note\n1,2,7,8,9,\"a,b\"\n").unwrap();
        let s = read_measurements(&p, &JointSpace::revolute(2), Positions::Required).unwrap();
        assert_eq!(s.rows[0].extra, vec!["a,b"]);
        let _ = Path::new("");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
