//! The bad-input tests' tools (`cli_bad_input*`, `cli_trust_*`): edits of good files, and a
//! check that a failed command gave its exit code and message and wrote nothing.

use super::fixtures::Cell;
use super::{p, robocal, snapshot, KUKA, TRUTH};
use std::path::Path;

/// `text` (CSV with a header) with the cell of `column` on 1-based `line` replaced.
pub fn with_cell(text: &str, line: usize, column: &str, value: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let k = lines[0]
        .split(',')
        .position(|c| c == column)
        .unwrap_or_else(|| panic!("no column {column}"));
    let mut cells: Vec<String> = lines[line - 1].split(',').map(str::to_owned).collect();
    cells[k] = value.to_owned();
    lines[line - 1] = cells.join(",");
    lines.join("\n") + "\n"
}

/// The first `n` lines of `text`.
pub fn head(text: &str, n: usize) -> String {
    text.lines().take(n).map(|l| format!("{l}\n")).collect()
}

/// Pretty JSON of `text` changed by `edit`.
pub fn json_with(text: &str, edit: impl Fn(&mut serde_json::Value)) -> String {
    let mut v: serde_json::Value = serde_json::from_str(text).expect("fixture JSON");
    edit(&mut v);
    serde_json::to_string_pretty(&v).expect("JSON")
}

/// CRLF line endings and a UTF-8 byte-order mark.
pub fn crlf_bom(text: &str) -> String {
    format!("\u{feff}{}", text.replace('\n', "\r\n"))
}

/// Outputs that exist before every failing run (an earlier run's results): a failed run must
/// leave them as they are and add nothing.
pub const OLD_OUTPUTS: [&str; 4] = ["out.json", "out.csv", "out.truth.json", "per_point.csv"];

/// Runs `args` in `dir` (which holds the bad input and [`OLD_OUTPUTS`], made here when missing)
/// and checks it with [`expect_refused`].
pub fn expect_failure(label: &str, dir: &Path, args: &[String], code: i32, wants: &[String]) {
    for name in OLD_OUTPUTS {
        let f = dir.join(name);
        if !f.exists() {
            std::fs::write(&f, format!("old {name}\n")).expect("write old output");
        }
    }
    expect_refused(label, dir, args, code, wants);
}

/// Runs `args` and checks that it fails with `code`, that stderr has an error line and every
/// string of `wants`, that nothing panicked, and that `dir` is exactly as before (every entry
/// unchanged, nothing added or removed, no temporary file).
pub fn expect_refused<S: AsRef<str>>(
    label: &str,
    dir: &Path,
    args: &[String],
    code: i32,
    wants: &[S],
) {
    let before = snapshot(dir);
    let o = robocal(args);
    let err = o.stderr();
    assert_eq!(o.code(), Some(code), "{label}: exit code\n{}", o.describe());
    assert!(
        !err.contains("panicked"),
        "{label}: panic\n{}",
        o.describe()
    );
    assert!(
        err.contains("error: "),
        "{label}: no error line\n{}",
        o.describe()
    );
    for w in wants {
        let w = w.as_ref();
        assert!(
            err.contains(w),
            "{label}: stderr lacks `{w}`\n{}",
            o.describe()
        );
    }
    let after = snapshot(dir);
    assert_eq!(
        before.keys().collect::<Vec<_>>(),
        after.keys().collect::<Vec<_>>(),
        "{label}: files added or removed"
    );
    for (name, entry) in &before {
        assert!(
            after[name] == *entry,
            "{label}: {name} changed by a failed run"
        );
    }
}

/// A command line from a template: the words `F` (the bad file), `KUKA`, `TRUTH`, `DATA`,
/// `RESULT`, `JOINTS` (the fixture's good files) and `OUT.json`, `OUT.csv`, `PP.csv`, `REPORT`
/// (outputs in the case directory `d`) are replaced; other words are kept.
pub fn expand(template: &str, f: &str, d: &Path, fx: &Cell) -> Vec<String> {
    let out = |name: &str| p(&d.join(name)).to_owned();
    template
        .split(' ')
        .map(|w| match w {
            "F" => f.to_owned(),
            "KUKA" => KUKA.to_owned(),
            "TRUTH" => TRUTH.to_owned(),
            "DATA" => p(&fx.data).to_owned(),
            "RESULT" => p(&fx.result).to_owned(),
            "JOINTS" => p(&fx.joints).to_owned(),
            "OUT.json" => out("out.json"),
            "OUT.csv" => out("out.csv"),
            "PP.csv" => out("per_point.csv"),
            "REPORT" => out("report"),
            w => w.to_owned(),
        })
        .collect()
}
