//! The two scanning steps every program reader takes: past a comment to the end of its line,
//! and past a quoted string (which ends at its closing quote or, unclosed, at the line's end).

/// The index of the line break ending the line that byte `i` is on (or the text's end).
pub(crate) fn line_end(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i] != b'\n' {
        i += 1;
    }
    i
}

/// The index just past the string whose opening quote is at `i` (the quote is `b[i]`).
pub(crate) fn past_string(b: &[u8], mut i: usize) -> usize {
    let q = b[i];
    i += 1;
    while i < b.len() && b[i] != q && b[i] != b'\n' {
        i += 1;
    }
    i + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_and_strings_end_where_they_should() {
        let b = b"; comment\nX \"a;b\" 'c\nY";
        assert_eq!(line_end(b, 0), 9);
        assert_eq!(line_end(b, 12), 20);
        assert_eq!(line_end(b"no break", 3), 8);
        assert_eq!(past_string(b, 12), 17);
        // Unclosed: it ends at the line break (the caller resumes after it).
        assert_eq!(past_string(b, 18), 21);
    }
}
