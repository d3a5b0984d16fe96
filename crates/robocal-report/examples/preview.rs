//! Writes a report into DIR: of made-up data (`preview DIR [SEED]`), or of a `ReportData` saved
//! as JSON (`preview DIR DATA.json`).
//!
//! `cargo run -p robocal-report --example preview -- /tmp/robocal-preview`
fn main() {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .unwrap_or_else(|| "robocal-report-preview".into());
    let what = args.next().unwrap_or_else(|| "1".into());
    let data = if what.ends_with(".json") {
        let text = std::fs::read_to_string(&what).unwrap_or_else(|e| fail(&format!("{what}: {e}")));
        serde_json::from_str(&text).unwrap_or_else(|e| fail(&format!("{what}: {e}")))
    } else {
        let seed = what
            .parse()
            .unwrap_or_else(|_| fail(&format!("not a seed or a .json file: {what}")));
        robocal_report::ReportData::synthetic_example(seed)
    };
    match robocal_report::write_report(std::path::Path::new(&dir), &data) {
        Ok(f) => println!("{}", f.html.display()),
        Err(e) => fail(&e.to_string()),
    }
}

fn fail(msg: &str) -> ! {
    eprintln!("error: {msg}");
    std::process::exit(1)
}
