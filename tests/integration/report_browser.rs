//! The HTML report in a real browser: headless Chromium renders a report of synthetic data, and
//! the report of `robocal demo` (the paper's experiment in simulation), to PNGs, which must show
//! the page's text and both figures (pixels of the "before" and "after" colours). Skips, saying
//! why, where Chromium is not installed (`.ci/run` installs it).

use crate::util::Dir;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 2400;

fn find_chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("ROBOCAL_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let fixed = Path::new("/usr/bin/chromium");
    if fixed.is_file() {
        return Some(fixed.to_owned());
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser"] {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// Runs Chromium to take a screenshot of `html`, killing it after `limit`.
fn screenshot(chromium: &Path, html: &Path, png: &Path, profile: &Path, limit: Duration) {
    let mut child = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("--window-size={WIDTH},{HEIGHT}"))
        .arg(format!("file://{}", html.display()))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("starting chromium");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("waiting for chromium").is_some() {
            return;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Decodes a PNG to (width, height, RGB pixels).
fn decode(png_path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let file = std::fs::File::open(png_path).expect("screenshot written");
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("a PNG frame");
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let step = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => panic!("unexpected PNG colour type {other:?}"),
    };
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(step)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width, info.height, pixels)
}

#[test]
fn report_renders_in_chromium() {
    render_and_check(&robocal_report::ReportData::synthetic_example(11));
}

#[test]
fn demo_report_renders_in_chromium() {
    use robocal_core::experiment::{run_experiment, ExperimentConfig};
    let e = run_experiment(ExperimentConfig::paper(1).unwrap(), &()).unwrap();
    render_and_check(&robocal_report::ReportData::from_experiment(&e, "robocal-report").unwrap());
}

/// Renders `data` in Chromium and checks the screenshot (or skips without Chromium).
fn render_and_check(data: &robocal_report::ReportData) {
    let Some(chromium) = find_chromium() else {
        eprintln!(
            "skipped: Chromium not found (/usr/bin/chromium or chromium on PATH; \
             install the Debian package `chromium` or set ROBOCAL_CHROMIUM)"
        );
        return;
    };
    let tmp = Dir::new();
    let profile = Dir::new();
    let files = robocal_report::write_report(&tmp.join("report"), data).unwrap();
    let png_path = tmp.join("report.png");
    screenshot(
        &chromium,
        &files.html,
        &png_path,
        profile.path(),
        Duration::from_secs(90),
    );
    assert!(
        png_path.is_file(),
        "chromium wrote no screenshot ({} --headless --screenshot)",
        chromium.display()
    );
    let (w, h, px) = decode(&png_path);
    assert_eq!((w, h), (WIDTH, HEIGHT));

    let n = px.len() as f64;
    let non_white = px.iter().filter(|p| p.iter().any(|&c| c < 235)).count() as f64;
    let lum: Vec<f64> = px
        .iter()
        .map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64)
        .collect();
    let mean = lum.iter().sum::<f64>() / n;
    let var = lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n;
    // The "before" colour (vermillion, #D55E00) and the "after" colour (blue, #0072B2), as the
    // histogram bars and scatter markers draw them (also blended with white). Without the
    // figures the page shows about 1300 and 3000 such pixels (cards, links); with them, over
    // 15000 each.
    let before = px
        .iter()
        .filter(|p| p[0] > 180 && (70..170).contains(&p[1]) && p[2] < 110)
        .count();
    let after = px
        .iter()
        .filter(|p| p[0] < 90 && (90..170).contains(&p[1]) && p[2] > 150)
        .count();
    eprintln!(
        "screenshot {}: non-white {:.1}%, luminance std {:.1}, before-colour px {before}, \
         after-colour px {after}",
        png_path.display(),
        100.0 * non_white / n,
        var.sqrt()
    );
    assert!(non_white / n > 0.03, "page looks blank");
    assert!(var.sqrt() > 20.0, "page has almost no contrast");
    assert!(
        before > 8000,
        "histogram/scatter 'before' colour barely visible"
    );
    assert!(
        after > 8000,
        "histogram/scatter 'after' colour barely visible"
    );
}
