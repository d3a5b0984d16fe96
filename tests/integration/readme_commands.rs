//! README.md as a new user reads it: every ```sh block runs as written, in order, in a directory
//! holding what a fresh clone has (`examples/`), with `robocal` on the PATH; every in-page link
//! has its heading; every command has a worked example; every flag of every command is
//! documented; every exit code is listed. The blocks write only into `out/`: nothing else is
//! left in the root, no temporary, no shipped example changed.

use crate::util::*;
use std::path::Path;
use std::process::Command;

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// The fenced blocks of `text` with their info string: (info, body, first line number).
fn blocks(text: &str) -> Vec<(String, String, usize)> {
    let mut out = Vec::new();
    let mut open: Option<(String, String, usize)> = None;
    for (i, line) in text.lines().enumerate() {
        if let Some(rest) = line.strip_prefix("```") {
            match open.take() {
                Some(b) => out.push(b),
                None => open = Some((rest.trim().to_owned(), String::new(), i + 2)),
            }
        } else if let Some((_, body, _)) = open.as_mut() {
            body.push_str(line);
            body.push('\n');
        }
    }
    assert!(open.is_none(), "README.md has an unclosed code block");
    out
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), &target).unwrap();
        }
    }
}

/// The files of `a` that differ from (or are missing in) `b`, recursively.
fn same_files(a: &Path, b: &Path, changed: &mut Vec<String>) {
    for e in std::fs::read_dir(a).unwrap() {
        let e = e.unwrap();
        let (pa, pb) = (e.path(), b.join(e.file_name()));
        if pa.is_dir() {
            same_files(&pa, &pb, changed);
        } else if std::fs::read(&pa).ok() != std::fs::read(&pb).ok() {
            changed.push(pa.display().to_string());
        }
    }
}

#[test]
fn every_sh_block_runs_as_written() {
    let text = readme();
    let sh: Vec<_> = blocks(&text)
        .into_iter()
        .filter(|(info, _, _)| info == "sh")
        .collect();
    assert!(sh.len() >= 10, "only {} runnable blocks", sh.len());
    let clone = Dir::new();
    copy_dir(&root().join("examples"), &clone.join("examples"));
    let bin = Path::new(env!("CARGO_BIN_EXE_robocal")).parent().unwrap();
    let path = std::env::join_paths(std::iter::once(bin.to_owned()).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .unwrap();
    let start = std::time::Instant::now();
    for (_, body, line) in &sh {
        let o = Command::new("sh")
            .args(["-e", "-c", body])
            .current_dir(clone.path())
            .env("PATH", &path)
            .output()
            .expect("sh runs");
        assert!(
            o.status.success(),
            "README.md line {line}: the block failed ({}):\n{body}\n--- stdout\n{}\n--- stderr\n{}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    eprintln!("{} README blocks ran in {:.1?}", sh.len(), start.elapsed());
    // What the quick start promises is there.
    for f in [
        "out/ur5-result.json",
        "out/ur5-commanded.csv",
        "out/ur5-verify.csv",
        "out/ur5-report/report.html",
    ] {
        assert!(clone.join(f).is_file(), "the quick start did not make {f}");
    }
    // The examples write only into `out/` (which .gitignore lists): nothing else is left in the
    // clone's root, and no temporary anywhere.
    let mut left: Vec<String> = std::fs::read_dir(clone.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        ["examples", "out"],
        "the README's examples left these in the root"
    );
    let ignore = std::fs::read_to_string(root().join(".gitignore")).unwrap();
    assert!(
        ignore.lines().any(|l| l == "/out/"),
        ".gitignore does not list /out/"
    );
    fn temporaries(dir: &Path, found: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                temporaries(&p, found);
            } else if p.extension().is_some_and(|x| x == "tmp") {
                found.push(p.display().to_string());
            }
        }
    }
    let mut tmp = Vec::new();
    temporaries(clone.path(), &mut tmp);
    assert!(tmp.is_empty(), "temporaries left: {tmp:?}");
    // Nor did they change a shipped example.
    let mut changed = Vec::new();
    same_files(
        &root().join("examples"),
        &clone.join("examples"),
        &mut changed,
    );
    assert!(changed.is_empty(), "the examples changed: {changed:?}");
}

/// GitHub's anchor of a heading: lower case, punctuation other than `-` and `_` dropped, spaces
/// as `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

#[test]
fn every_in_page_link_has_its_heading() {
    let text = readme();
    let mut in_code = false;
    let mut anchors = Vec::new();
    let mut links = Vec::new();
    for line in text.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        if line.starts_with('#') {
            anchors.push(slug(line.trim_start_matches('#')));
        }
        let mut rest = line;
        while let Some(i) = rest.find("](#") {
            let tail = &rest[i + 3..];
            let end = tail.find(')').expect("closed link");
            links.push(tail[..end].to_owned());
            rest = &tail[end..];
        }
    }
    assert!(links.len() >= 20, "{links:?}");
    for l in &links {
        assert!(
            anchors.contains(l),
            "README.md links to #{l}, which no heading makes"
        );
    }
}

#[test]
fn every_command_and_flag_is_documented() {
    let text = readme();
    let sh: String = blocks(&text)
        .into_iter()
        .filter(|(info, _, _)| info == "sh")
        .map(|b| b.1)
        .collect();
    let commands: &[&[&str]] = &[
        &["robot", "list"],
        &["robot", "show"],
        &["fk"],
        &["simulate"],
        &["import"],
        &["calibrate"],
        &["evaluate"],
        &["compensate"],
        &["plan"],
        &["report"],
        &["export"],
        &["demo"],
        &["completions"],
        &["man"],
    ];
    for cmd in commands {
        let call = format!("robocal {}", cmd.join(" "));
        assert!(sh.contains(&call), "no worked example runs `{call}`");
        let mut args: Vec<&str> = cmd.to_vec();
        args.push("--help");
        let help = ok(&args).stdout();
        for flag in help
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .filter(|w| w.starts_with("--") && w.len() > 2)
        {
            if flag == "--help" || flag == "--version" {
                continue;
            }
            assert!(
                text.contains(&format!("`{flag}")) || text.contains(&format!("{flag} ")),
                "README.md does not document `{call} {flag}`"
            );
        }
    }
    for code in ["0", "1", "2", "3", "4", "5", "6", "130"] {
        assert!(
            text.contains(&format!("{code} ")) && text.contains("## Exit codes"),
            "exit code {code}"
        );
    }
    assert!(!text.contains("DESIGN.md"), "users have no design file");
}
