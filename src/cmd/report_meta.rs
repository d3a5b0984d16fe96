//! What identifies a report: the robot's serial number, the tracker and reflector, the operator,
//! the temperature and notes, from `report`'s flags or a small run file (`--meta FILE`, TOML),
//! and the dates (when the result was written, when the report was made).

use crate::exit;
use anyhow::Context;
use clap::Args;
use robocal_report::Setting;
use serde::Deserialize;
use std::path::PathBuf;
use std::time::SystemTime;

/// Plausible air temperature of a measurement (°C).
const TEMPERATURE_C: (f64, f64) = (-60.0, 100.0);

#[derive(Args, Debug, Default)]
pub struct MetaArgs {
    /// A run file (TOML) with any of the keys `serial`, `tracker`, `reflector`, `operator`,
    /// `temperature_c`, `measured` (date of the measurement) and `notes`; the flags below
    /// override it.
    #[arg(long, value_name = "RUN.toml")]
    pub meta: Option<PathBuf>,
    /// The robot's serial number.
    #[arg(long)]
    pub serial: Option<String>,
    /// The laser tracker (make, model, serial).
    #[arg(long)]
    pub tracker: Option<String>,
    /// The reflector (e.g. "1.5 in SMR").
    #[arg(long)]
    pub reflector: Option<String>,
    /// Who measured.
    #[arg(long)]
    pub operator: Option<String>,
    /// Air temperature during the measurement (°C).
    #[arg(long, value_name = "DEG_C", allow_hyphen_values = true)]
    pub temperature_c: Option<f64>,
    /// When the measurement was made (free text, e.g. 2026-11-20).
    #[arg(long, value_name = "DATE")]
    pub measured: Option<String>,
    /// Free notes shown under the title.
    #[arg(long)]
    pub notes: Option<String>,
}

/// The run file's keys.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RunFile {
    serial: Option<String>,
    tracker: Option<String>,
    reflector: Option<String>,
    operator: Option<String>,
    temperature_c: Option<f64>,
    measured: Option<String>,
    notes: Option<String>,
}

/// The identifying lines, checked: the run file read (exit 3 naming the file and line when it
/// is malformed), flags over file, the temperature in its plausible range.
pub fn metadata(a: &MetaArgs) -> anyhow::Result<Vec<Setting>> {
    let file = match &a.meta {
        None => RunFile::default(),
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| robocal_core::Error::Io {
                    path: p.clone(),
                    source: e,
                })
                .with_context(|| format!("--meta {}", p.display()))?;
            let f: RunFile = toml::from_str(&text).map_err(|e| {
                exit::input(format!(
                    "--meta {}: {}",
                    p.display(),
                    e.to_string().trim_end().replace('\n', " ")
                ))
            })?;
            if let Some(t) = f.temperature_c {
                check_temperature(t).map_err(|m| {
                    exit::input(format!("--meta {}: temperature_c {m}", p.display()))
                })?;
            }
            f
        }
    };
    if let Some(t) = a.temperature_c {
        check_temperature(t).map_err(|m| exit::usage(format!("--temperature-c {m}")))?;
    }
    let pick = |flag: &Option<String>, key: &Option<String>| flag.clone().or_else(|| key.clone());
    let mut out = Vec::new();
    for (label, v) in [
        ("Robot serial", pick(&a.serial, &file.serial)),
        ("Tracker", pick(&a.tracker, &file.tracker)),
        ("Reflector", pick(&a.reflector, &file.reflector)),
        ("Operator", pick(&a.operator, &file.operator)),
        ("Measured", pick(&a.measured, &file.measured)),
    ] {
        if let Some(v) = v.filter(|v| !v.trim().is_empty()) {
            out.push(Setting::new(label, v));
        }
    }
    if let Some(t) = a.temperature_c.or(file.temperature_c) {
        out.push(Setting::new("Temperature", format!("{t:.1} °C")));
    }
    if let Some(n) = pick(&a.notes, &file.notes).filter(|v| !v.trim().is_empty()) {
        out.push(Setting::new("Notes", n));
    }
    Ok(out)
}

fn check_temperature(t: f64) -> Result<(), String> {
    if t.is_finite() && (TEMPERATURE_C.0..=TEMPERATURE_C.1).contains(&t) {
        Ok(())
    } else {
        Err(format!(
            "= {t} is not a plausible air temperature ({} to {} °C)",
            TEMPERATURE_C.0, TEMPERATURE_C.1
        ))
    }
}

/// A time as `2026-11-24 04:05 UTC`. `SOURCE_DATE_EPOCH` (seconds), the reproducible-builds
/// convention, replaces "now" so that a report can be made byte for byte again.
pub fn now_utc() -> String {
    let t = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .map(|s| SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(s))
        .unwrap_or_else(SystemTime::now);
    utc(t)
}

fn utc(t: SystemTime) -> String {
    // humantime: RFC 3339 in UTC without a calendar crate ("2026-11-24T04:05:00Z").
    let s = humantime::format_rfc3339_seconds(t).to_string();
    format!("{} {} UTC", &s[..10], &s[11..16])
}
