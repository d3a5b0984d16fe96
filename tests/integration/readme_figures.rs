//! The figures README.md quotes, against the commands that print them: the quick start's
//! (Tables II and IV of calibrate, the evaluation, the verification against its prediction) and
//! the demo's whole printed output (Tables II to V, the iterations, "Beyond the paper"). Each
//! compared figure is listed in the test's output (`cargo test --release --test main
//! readme_figures -- --nocapture`); a figure that differs fails the test with both values.

use crate::util::*;

/// README.md with every run of white space as one space (quoted phrases may wrap).
fn readme_flat() -> String {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The numbers of a printed line, in order (`(+6%)` gives `+6`, `1.2x` is no number).
fn numbers(line: &str) -> Vec<f64> {
    line.split(|c: char| c.is_whitespace() || "(),;:=".contains(c))
        .map(|w| w.trim_end_matches('%'))
        .filter_map(|w| w.parse::<f64>().ok())
        .collect()
}

/// A figure the README quotes from a command's output: the `n`-th number of the first line
/// starting with `line` after the first line starting with `section` (empty: from the top),
/// shown in the README with `decimals` decimals where `{}` stands in `phrase`.
struct Quoted {
    section: &'static str,
    line: &'static str,
    n: usize,
    decimals: usize,
    phrase: &'static str,
}

const fn q(
    section: &'static str,
    line: &'static str,
    n: usize,
    decimals: usize,
    phrase: &'static str,
) -> Quoted {
    Quoted {
        section,
        line,
        n,
        decimals,
        phrase,
    }
}

/// Checks every figure of `quoted` against `printed` (the output of `what`), listing each.
fn compare(readme: &str, what: &str, printed: &str, quoted: &[Quoted]) {
    for f in quoted {
        let lines: Vec<&str> = printed.lines().map(str::trim).collect();
        let from = lines
            .iter()
            .position(|l| l.starts_with(f.section))
            .unwrap_or_else(|| panic!("{what} printed no `{}`:\n{printed}", f.section));
        let line = lines[from..]
            .iter()
            .find(|l| l.starts_with(f.line))
            .unwrap_or_else(|| panic!("{what} printed no `{}`:\n{printed}", f.line));
        let v = numbers(line)[f.n];
        let shown = format!("{v:.*}", f.decimals);
        let shown = shown.trim_start_matches('+');
        let phrase = f.phrase.replace("{}", shown);
        eprintln!("README `{phrase}` = {what}: `{line}`");
        assert!(
            readme.contains(&phrase),
            "README.md should say `{phrase}` ({what} printed `{line}`)"
        );
    }
}

#[test]
fn the_quick_start_figures_are_the_printed_ones() {
    let readme = readme_flat();
    let d = Dir::new();
    let e = |f: &str| root().join("examples").join(f);
    let (result, commanded, verify) = (d.join("r.json"), d.join("c.csv"), d.join("v.csv"));
    let ur5 = e("ur5.toml");
    let validation = e("data/ur5-validation.csv");
    let cal = ok(&[
        "calibrate".as_ref(),
        "--robot".as_ref(),
        ur5.as_os_str(),
        "--data".as_ref(),
        e("data/ur5-cell.csv").as_os_str(),
        "--validate".as_ref(),
        validation.as_os_str(),
        "--out".as_ref(),
        result.as_os_str(),
    ]);
    compare(
        &readme,
        "calibrate",
        &cal.stdout(),
        &[
            q(
                "Table II.",
                "Mean (mm)",
                0,
                3,
                "(Table II: {} mm mean on the calibration points)",
            ),
            q(
                "Table IV.",
                "Mean (mm)",
                0,
                3,
                "(Table IV: {} mm on the calibration points,",
            ),
            q(
                "Table IV.",
                "Mean (mm)",
                1,
                3,
                "calibration points, {} mm on the validation points)",
            ),
        ],
    );
    let ev = ok(&[
        "evaluate".as_ref(),
        "--params".as_ref(),
        result.as_os_str(),
        "--data".as_ref(),
        validation.as_os_str(),
    ]);
    compare(
        &readme,
        "evaluate (validation)",
        &ev.stdout(),
        &[
            q("", "Mean (mm)", 0, 3, "calibrated model ({} -> "),
            q("", "Mean (mm)", 1, 3, " -> {} mm)."),
        ],
    );
    ok(&[
        "compensate".as_ref(),
        "--params".as_ref(),
        result.as_os_str(),
        "--joints".as_ref(),
        validation.as_os_str(),
        "--out".as_ref(),
        commanded.as_os_str(),
    ]);
    ok(&[
        "simulate".as_ref(),
        "--robot".as_ref(),
        ur5.as_os_str(),
        "--truth".as_ref(),
        e("data/ur5-cell.truth.json").as_os_str(),
        "--joints".as_ref(),
        commanded.as_os_str(),
        "--seed".as_ref(),
        "2".as_ref(),
        "--out".as_ref(),
        verify.as_os_str(),
    ]);
    let ver = ok(&[
        "evaluate".as_ref(),
        "--params".as_ref(),
        result.as_os_str(),
        "--data".as_ref(),
        verify.as_os_str(),
    ]);
    compare(
        &readme,
        "evaluate (verification)",
        &ver.stdout(),
        &[
            q(
                "",
                "verification mean",
                0,
                3,
                "The verification measures {} mm mean",
            ),
            q("", "verification mean", 1, 3, "against {} mm predicted"),
            q(
                "",
                "verification mean",
                2,
                0,
                "predicted at new poses (+{}%)",
            ),
        ],
    );
}

#[test]
fn the_several_reflector_figures_are_the_printed_ones() {
    let readme = readme_flat();
    let d = Dir::new();
    let e = |f: &str| root().join("examples").join(f);
    let out = d.join("r.json");
    let cal = ok(&[
        "calibrate".as_ref(),
        "--robot".as_ref(),
        e("ur5-3reflectors.toml").as_os_str(),
        "--data".as_ref(),
        e("data/ur5-3reflectors.csv").as_os_str(),
        "--validate".as_ref(),
        e("data/ur5-3reflectors-validation.csv").as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    compare(
        &readme,
        "calibrate (three reflectors)",
        &cal.stdout(),
        &[
            q(
                "Table II.",
                "Mean (mm)",
                0,
                3,
                "from {} mm mean before calibration",
            ),
            q(
                "Table IV.",
                "Mean (mm)",
                0,
                3,
                "to {} mm on the calibration points",
            ),
            q(
                "Table IV.",
                "Mean (mm)",
                1,
                3,
                "and {} mm on the 60 validation rows",
            ),
        ],
    );
    let text = cal.stdout();
    for fixed in [
        "alpha6   fixed",
        "d6       fixed",
        "a6       fixed",
        "phi6     fixed",
    ] {
        assert!(text.contains(fixed), "{fixed}:\n{text}");
    }
    // The shipped data are what the command of examples/data/README.md makes.
    ok(&[
        "simulate".as_ref(),
        "--robot".as_ref(),
        e("ur5-3reflectors.toml").as_os_str(),
        "--truth".as_ref(),
        "random".as_ref(),
        "--poses".as_ref(),
        "40".as_ref(),
        "--validation".as_ref(),
        "20".as_ref(),
        "--seed".as_ref(),
        "1".as_ref(),
        "--all-targets".as_ref(),
        "--tracker".as_ref(),
        "1500,-1000,300,125,0,0".as_ref(),
        "--out".as_ref(),
        d.join("c.csv").as_os_str(),
        "--validation-out".as_ref(),
        d.join("v.csv").as_os_str(),
    ]);
    for (shipped, made) in [
        ("data/ur5-3reflectors.csv", "c.csv"),
        ("data/ur5-3reflectors-validation.csv", "v.csv"),
    ] {
        assert!(
            std::fs::read(e(shipped)).unwrap() == std::fs::read(d.join(made)).unwrap(),
            "examples/{shipped} is not what simulate makes"
        );
    }
}

/// The block of README.md after the line containing `intro`, with its first line's number.
fn block_after(intro: &str) -> (Vec<String>, usize) {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.contains(intro))
        .unwrap_or_else(|| panic!("README.md has no `{intro}`"));
    let open = at
        + lines[at..]
            .iter()
            .position(|l| l.starts_with("```"))
            .unwrap();
    let len = lines[open + 1..]
        .iter()
        .position(|l| l.starts_with("```"))
        .unwrap();
    let body = lines[open + 1..open + 1 + len]
        .iter()
        .map(|l| l.trim_end().to_owned())
        .collect();
    (body, open + 2)
}

#[test]
fn the_demo_output_quoted_is_the_printed_one() {
    let d = Dir::new();
    let o = command()
        .args(["demo", "--seed", "1"])
        .current_dir(d.path())
        .output()
        .expect("robocal runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| l.trim_end().to_owned())
        .collect();
    let (quoted, first) = block_after("The output of `cargo run --release -- demo` (seed 1):");
    let mut figures = 0;
    for (i, (r, p)) in quoted.iter().zip(&printed).enumerate() {
        let (rn, pn) = (numbers(r), numbers(p));
        if !rn.is_empty() {
            eprintln!("README.md:{} {:?} = printed {:?}", first + i, rn, pn);
        }
        figures += rn.len();
        assert_eq!(
            r,
            p,
            "README.md line {}: the demo's output quoted differs from the printed one",
            first + i
        );
    }
    assert_eq!(
        quoted.len(),
        printed.len(),
        "README.md quotes {} lines of the demo's output, it prints {}:\n{}",
        quoted.len(),
        printed.len(),
        printed.join("\n")
    );
    eprintln!("{figures} figures of the demo's output compared");
}
