//! Escaping text for HTML and SVG (XML): every piece of caller-supplied text goes through here.

/// Escapes `&`, `<`, `>`, `"` and `'` so that `s` is safe in element content and in quoted
/// attribute values of HTML and XML. Control characters other than tab, newline and carriage
/// return (not allowed in XML 1.0) are replaced by U+FFFD.
pub fn xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if (c as u32) < 0x20 || c == '\u{7f}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn escapes_markup() {
        assert_eq!(
            super::xml("<script>alert(\"x&y\")</script> 'q'\u{1}"),
            "&lt;script&gt;alert(&quot;x&amp;y&quot;)&lt;/script&gt; &#39;q&#39;\u{FFFD}"
        );
        assert_eq!(super::xml("µm ± é"), "µm ± é");
    }
}
