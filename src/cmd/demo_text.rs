//! The demo's text: paragraphs wrapped at 100 columns, shell words quoted, command lines
//! continued with backslashes (for `demo` and its honest-cell part alike).

use std::path::Path;

/// A path as the user would type it in a POSIX shell (quoted when needed).
pub(super) fn sh(p: &Path) -> String {
    let s = p.display().to_string();
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_./-+:@%,".contains(c))
    {
        s
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Prints `text` wrapped at 100 columns.
pub(super) fn para(text: &str) -> anyhow::Result<()> {
    let mut line = String::new();
    for w in text.split_whitespace() {
        if !line.is_empty() && line.len() + 1 + w.len() > 100 {
            outln!("{line}")?;
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(w);
    }
    if !line.is_empty() {
        outln!("{line}")?;
    }
    Ok(())
}

/// Prints a shell command made of `parts`, continued with `\` on new lines before 100 columns.
pub(super) fn command_line(parts: &[String]) -> anyhow::Result<()> {
    let mut line = String::from("  ");
    let mut out = String::new();
    for (i, part) in parts.iter().enumerate() {
        if i > 0 && line.len() + 1 + part.len() + 2 > 100 {
            out.push_str(&line);
            out.push_str(" \\\n");
            line = String::from("      ");
        } else if i > 0 {
            line.push(' ');
        }
        line.push_str(part);
    }
    out.push_str(&line);
    outln!("{out}")?;
    Ok(())
}
