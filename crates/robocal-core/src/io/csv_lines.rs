//! The true line numbers and the delimiter of a CSV file: a reader wrapper that notes where each
//! line ends as the bytes pass (LF, CRLF and a lone CR each end one line), so that a record's
//! byte offset gives its line whatever the line endings and however many blank lines come
//! before it (the `csv` crate's own count is one line off after CRLF and never advances for CR
//! alone); and the delimiter of the header line (`,`, `;` or a tab).

use std::cell::RefCell;
use std::collections::VecDeque;
use std::io::Read;

/// The runs of line-break bytes seen and not yet passed by a query.
#[derive(Default)]
struct Lines {
    /// Bytes read so far.
    pos: u64,
    /// Each closed run of `\r`/`\n` bytes: its first byte's offset and the line ends in it.
    runs: VecDeque<(u64, usize)>,
    /// The run being read, if the last byte read was a line-break byte.
    open: Option<(u64, usize)>,
    /// The last byte read was a CR: one line end, or half of CR LF.
    pending_cr: bool,
    /// Line ends before the last queried offset.
    counted: usize,
}

/// A reader that counts lines as they pass; see the module documentation.
pub struct LineCounted<R> {
    inner: R,
    /// The bytes read ahead to find the delimiter, given out first.
    head: Vec<u8>,
    head_at: usize,
    lines: RefCell<Lines>,
    delimiter: u8,
}

impl<R: Read> LineCounted<R> {
    /// Wraps `inner`, reading ahead its first line (at most 64 KiB) to find the delimiter:
    /// the one of `,`, `;` and tab that occurs most often outside quotes (`,` when none does).
    pub fn new(mut inner: R) -> LineCounted<R> {
        let mut head = Vec::new();
        let mut buf = [0u8; 4096];
        while head.len() < 65536 && !head.iter().any(|b| *b == b'\n' || *b == b'\r') {
            match inner.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => head.extend_from_slice(&buf[..n]),
            }
        }
        let delimiter = sniff(&head);
        LineCounted {
            inner,
            head,
            head_at: 0,
            lines: RefCell::new(Lines::default()),
            delimiter,
        }
    }

    /// The delimiter of the header line.
    pub fn delimiter(&self) -> u8 {
        self.delimiter
    }

    /// The 1-based line of a record that starts at `offset`, or at the first byte after the
    /// line breaks there: `csv` gives a record's offset as that of the line break before it,
    /// and skips blank lines. Offsets must be asked in nondecreasing order (records are read in
    /// order); the line breaks passed are forgotten.
    pub fn line_at(&self, offset: u64) -> usize {
        let mut l = self.lines.borrow_mut();
        while let Some(&(start, ends)) = l.runs.front() {
            if start > offset {
                break;
            }
            l.runs.pop_front();
            l.counted += ends;
        }
        let open = match l.open {
            Some((start, ends)) if start <= offset => ends + usize::from(l.pending_cr),
            _ => 0,
        };
        l.counted + open + 1
    }

    fn note(&self, bytes: &[u8]) {
        let mut l = self.lines.borrow_mut();
        let start = l.pos;
        let mut k = 0;
        while k < bytes.len() {
            // Outside a run of line breaks a byte that is none changes nothing: skip to the next
            // line-break byte at once.
            if l.open.is_none() && !l.pending_cr {
                match next_break(&bytes[k..]) {
                    Some(j) => k += j,
                    None => break,
                }
            }
            let b = &bytes[k];
            let at = start + k as u64;
            k += 1;
            let is_break = matches!(b, b'\r' | b'\n');
            // A CR not followed by LF is a line end of its own; CR LF is one.
            let mut ends = usize::from(l.pending_cr && *b != b'\n');
            l.pending_cr = *b == b'\r';
            ends += usize::from(*b == b'\n');
            match (&mut l.open, is_break) {
                (Some((_, n)), true) => *n += ends,
                (None, true) => l.open = Some((at, ends)),
                (open, false) => {
                    if let Some((s, n)) = open.take() {
                        l.runs.push_back((s, n + ends));
                    }
                }
            }
        }
        l.pos = start + bytes.len() as u64;
    }
}

/// The offset of the first `\r` or `\n` in `bytes`: eight bytes at a time (a byte equal to
/// either sets the high bit of its lane in `has_zero(word ^ pattern)`).
#[inline]
fn next_break(bytes: &[u8]) -> Option<usize> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGHS: u64 = 0x8080_8080_8080_8080;
    let has_zero = |v: u64| v.wrapping_sub(ONES) & !v & HIGHS;
    let mut chunks = bytes.chunks_exact(8);
    let mut base = 0;
    for c in &mut chunks {
        let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        if has_zero(w ^ (ONES * u64::from(b'\n'))) | has_zero(w ^ (ONES * u64::from(b'\r'))) != 0 {
            break;
        }
        base += 8;
    }
    bytes[base..]
        .iter()
        .position(|b| matches!(b, b'\r' | b'\n'))
        .map(|j| base + j)
}

/// The delimiter of a header line: the most frequent of `,`, `;` and tab outside double quotes.
pub(crate) fn sniff(head: &[u8]) -> u8 {
    let mut counts = [0usize; 3];
    let mut quoted = false;
    for b in head {
        match b {
            b'"' => quoted = !quoted,
            b'\n' | b'\r' if !quoted => break,
            b',' if !quoted => counts[0] += 1,
            b';' if !quoted => counts[1] += 1,
            b'\t' if !quoted => counts[2] += 1,
            _ => {}
        }
    }
    let best = (0..3)
        .max_by_key(|k| (counts[*k], usize::from(*k == 0)))
        .unwrap_or(0);
    if counts[best] == 0 {
        b','
    } else {
        [b',', b';', b'\t'][best]
    }
}

/// The delimiter as a message shows it.
pub fn delimiter_name(d: u8) -> &'static str {
    match d {
        b';' => "semicolons",
        b'\t' => "tabs",
        _ => "commas",
    }
}

impl<R: Read> Read for LineCounted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = if self.head_at < self.head.len() {
            let n = (self.head.len() - self.head_at).min(buf.len());
            buf[..n].copy_from_slice(&self.head[self.head_at..self.head_at + n]);
            self.head_at += n;
            if self.head_at == self.head.len() {
                self.head = Vec::new();
                self.head_at = 0;
            }
            n
        } else {
            self.inner.read(buf)?
        };
        self.note(&buf[..n]);
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record_lines(text: &[u8]) -> Vec<usize> {
        let mut rdr = crate::io::columns::csv_reader(text);
        let mut rec = csv::StringRecord::new();
        let _ = rdr.headers().unwrap();
        let mut lines = Vec::new();
        while let Some(l) =
            crate::io::columns::next_record(&mut rdr, &mut rec, std::path::Path::new("t")).unwrap()
        {
            lines.push(l);
        }
        lines
    }

    #[test]
    fn lines_are_true_for_every_line_ending_and_blank_lines() {
        assert_eq!(record_lines(b"a,b\n1,2\n3,4\n"), [2, 3]);
        assert_eq!(record_lines(b"a,b\r\n1,2\r\n3,4\r\n"), [2, 3]);
        assert_eq!(record_lines(b"a,b\r1,2\r3,4\r"), [2, 3]);
        assert_eq!(record_lines(b"a,b\n\n1,2\n\n\n3,4"), [3, 6]);
        assert_eq!(record_lines(b"a,b\r\n\r\n1,2\r\n\r\n3,4\r\n"), [3, 5]);
        assert_eq!(record_lines(b"a,b\r\r1,2\r\r\r3,4"), [3, 6]);
        // A quoted cell with a line break: the record after it is on its true line.
        assert_eq!(record_lines(b"a,b\n\"x\ny\",2\n3,4\n"), [2, 4]);
    }

    /// Long rows (the line breaks found eight bytes at a time) with every kind of line end and
    /// blank lines: each record's line is its true line.
    #[test]
    fn lines_are_true_for_long_rows() {
        let mut text = b"a,b\n".to_vec();
        let mut want = Vec::new();
        let mut line = 2;
        for k in 0..200usize {
            let cell = "7".repeat(1 + k % 37);
            text.extend_from_slice(format!("{cell},{k}").as_bytes());
            want.push(line);
            let end: &[u8] = [b"\n".as_slice(), b"\r\n", b"\r", b"\n\n", b"\r\n\r\n"][k % 5];
            text.extend_from_slice(end);
            line += [1, 1, 1, 2, 2][k % 5];
        }
        assert_eq!(record_lines(&text), want);
        for k in 0..40 {
            let mut t = vec![b'x'; k];
            t.push(if k % 2 == 0 { b'\r' } else { b'\n' });
            assert_eq!(next_break(&t), Some(k));
            assert_eq!(next_break(&t[..k]), None);
        }
    }

    #[test]
    fn lines_are_true_across_read_boundaries() {
        // One byte at a time: a CR and its LF in different reads.
        struct Bytewise<'a>(&'a [u8]);
        impl Read for Bytewise<'_> {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                if self.0.is_empty() || buf.is_empty() {
                    return Ok(0);
                }
                buf[0] = self.0[0];
                self.0 = &self.0[1..];
                Ok(1)
            }
        }
        let r = LineCounted::new(Bytewise(b"a\r\nb\rc\n\r\nd"));
        let mut all = Vec::new();
        let mut r = r;
        r.read_to_end(&mut all).unwrap();
        assert_eq!([0, 1, 3, 5, 6, 9].map(|o| r.line_at(o)), [1, 2, 2, 3, 5, 5]);
    }

    #[test]
    fn the_delimiter_is_the_header_lines() {
        assert_eq!(sniff(b"q1,q2,x"), b',');
        assert_eq!(sniff(b"q1;q2;x\n1,5;2,5;3"), b';');
        assert_eq!(sniff(b"q1\tq2\tx"), b'\t');
        assert_eq!(sniff(b"\"a;b\",c"), b',');
        assert_eq!(sniff(b"q1"), b',');
    }

    /// Cells are read trimmed (spaces around numbers and labels, a row of spaces is blank),
    /// and a reused row gives the rows a fresh one does.
    #[test]
    fn trimmed_cells_and_reused_rows() {
        use crate::io::measurements::{parse_measurements, MeasurementReader, Positions};
        use crate::model::JointSpace;
        use std::path::Path;
        let text = "q1 , q2,x,y,z, id \n 10 ,20,1,2,3, a \n  ,  , , ,  ,\n30,-40,4,5,6,bb\n";
        let s = parse_measurements(
            text.as_bytes(),
            Path::new("m.csv"),
            &JointSpace::revolute(2),
            Positions::Required,
        )
        .unwrap();
        assert_eq!(s.extra_columns, vec!["id"]);
        assert_eq!(s.rows.len(), 2);
        assert_eq!(
            (s.rows[0].extra.clone(), s.rows[1].line),
            (vec!["a".into()], 4)
        );
        assert_eq!(s.rows[0].q[0], 10f64.to_radians());
        let mut r = MeasurementReader::new(
            text.as_bytes(),
            Path::new("m.csv"),
            &JointSpace::revolute(2),
            Positions::Required,
        )
        .unwrap();
        let mut row = s.rows[1].clone();
        for want in &s.rows {
            assert!(r.next_row_into(&mut row).unwrap());
            assert_eq!(&row, want);
        }
        assert!(!r.next_row_into(&mut row).unwrap());
    }
}
