//! Writes the synthetic example report: `cargo run -p robocal-report --example preview -- DIR [SEED]`.
fn main() {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .unwrap_or_else(|| "robocal-report-preview".into());
    let seed = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let data = robocal_report::ReportData::synthetic_example(seed);
    match robocal_report::write_report(std::path::Path::new(&dir), &data) {
        Ok(f) => println!("{}", f.html.display()),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
