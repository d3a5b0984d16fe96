//! The demo's honest cell: what it adds to the paper's cell, the by-hand flags that simulate it,
//! and the calibration with the real cell's families beside the geometric one.

use super::demo_text::{command_line, para};
use robocal_core::experiment::{files, Experiment, PAPER_NOMINAL};
use robocal_report::number_list;
use std::path::Path;

/// Describes the real cell's additions (nothing for an ideal cell).
pub(super) fn print_cell(exp: &Experiment) -> anyhow::Result<()> {
    let s = &exp.config.session;
    if let Some(r) = &s.repeatability {
        let shown: Vec<String> = r.std_deg.iter().map(|v| format!("{v:.5}")).collect();
        let same = shown.iter().all(|v| *v == shown[0]);
        outln!(
            "  repeatability  {} deg per joint and move (1 sigma, the class default), in both \
             sessions",
            if same {
                shown[0].clone()
            } else {
                shown.join(",")
            }
        )?;
    }
    if let Some(b) = &s.backlash {
        outln!(
            "  backlash       half plays {} deg: each joint stops short",
            number_list(&b.half_play_deg, ",")
        )?;
        outln!("                 on the side it came from, the poses visited in row order")?;
    }
    if let Some(t) = &s.thermal {
        let temps = temperatures(exp);
        outln!(
            "  thermal growth {} K warm-up, time constant {} s, {} s per pose, {} ppm/K: the arm",
            t.rise_c,
            t.time_constant_s,
            t.seconds_per_pose,
            t.expansion_per_k * 1e6
        )?;
        outln!(
            "                 goes from {:.1} to {:.1} deg C during the session",
            temps.0,
            temps.1
        )?;
    }
    if let Some(r) = &exp.config.real_cell {
        outln!(
            "  verification   {:.1} h after the arm started working (the session started cold), from",
            r.verification_start_s / 3600.0
        )?;
        outln!(
            "                 tracker station {} (registered again), every pose approached from below",
            r.verification_station
        )?;
    }
    Ok(())
}

/// The lowest and highest temperature of the session's rows (deg C).
fn temperatures(exp: &Experiment) -> (f64, f64) {
    let m = &exp.session.measurements;
    let Some(k) = m.extra_columns.iter().position(|c| c == "temperature_c") else {
        return (f64::NAN, f64::NAN);
    };
    let t: Vec<f64> = m
        .rows
        .iter()
        .filter_map(|r| r.extra[k].parse().ok())
        .collect();
    (
        t.iter().copied().fold(f64::INFINITY, f64::min),
        t.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

/// The flags of `simulate` that give the real cell's session (`verification`: its
/// verification session).
pub(super) fn simulate_flags(exp: &Experiment, verification: bool) -> Vec<String> {
    let s = &exp.config.session;
    let mut out = Vec::new();
    if s.repeatability.is_some() {
        out.push("--repeatability-deg default".to_owned());
    }
    if s.backlash.is_some() {
        out.push("--backlash-deg auto".to_owned());
    }
    if s.thermal.is_some() {
        out.push("--thermal auto".to_owned());
    }
    if let (true, Some(r)) = (verification, &exp.config.real_cell) {
        if s.thermal.is_some() {
            out.push(format!("--thermal-start-s {}", r.verification_start_s));
        }
        if r.verification_station != 0 {
            out.push(format!("--station {}", r.verification_station));
        }
    }
    out
}

/// The geometric and elasto-geometric calibrations beside the one with the real cell's
/// families (compliance, backlash, thermal expansion), and the verification of each.
pub(super) fn print_families(
    geo: &Experiment,
    el: &Experiment,
    fam: &Experiment,
    dir: &Path,
) -> anyhow::Result<()> {
    para(
        "Beyond the paper: the same measurements calibrated with joint compliance under gravity \
         (elasto-geometric, the payload known), then also with backlash (against each row's \
         approach direction, dir1..dirN) and thermal expansion (against temperature_c), each \
         compensated for the verification's conditions (the arm's temperature when it starts, \
         every pose approached from below) and verified the same way, against the calibration's \
         prediction at new poses (noise and parameter uncertainty; Table IV is the fit's own \
         residual):",
    )?;
    let val = |e: &Experiment| {
        e.result
            .errors
            .validation
            .map_or(f64::NAN, |v| v.after.mean_mm)
    };
    // One prediction everywhere (as `calibrate` prints it and `evaluate` compares with it): the
    // expected mean error at new poses spread like the calibration poses, a new measurement's
    // noise and the parameters' uncertainty included. Table IV's figure is the fit's own
    // residual, smaller by the fitted parameters' degrees of freedom.
    let predicted = |e: &Experiment| e.result.prediction.as_ref().map_or(f64::NAN, |p| p.mean_mm);
    let ratio = |e: &Experiment| e.verified().mean_mm / predicted(e);
    outln!(
        "{:<34} {:>12} {:>18} {:>18}",
        "",
        "Geometric",
        "Elasto-geometric",
        "+ backlash, heat"
    )?;
    for (label, f) in [
        ("Validation mean (mm)", &val as &dyn Fn(&Experiment) -> f64),
        ("Predicted at new poses (mm)", &predicted),
        ("Verification mean (mm)", &|e: &Experiment| {
            e.verified().mean_mm
        }),
        ("Verification max (mm)", &|e: &Experiment| {
            e.verified().max_mm
        }),
        ("Verification / prediction", &ratio),
    ] {
        outln!(
            "{label:<34} {:>12.3} {:>18.3} {:>18.3}",
            f(geo),
            f(el),
            f(fam)
        )?;
    }
    outln!(
        "{:<34} {:>12} {:>18} {:>18}",
        "Identified parameters",
        geo.calibration.identifiability.identified.len(),
        el.calibration.identifiability.identified.len(),
        fam.calibration.identifiability.identified.len()
    )?;
    let payload = geo
        .config
        .session
        .gravity
        .as_ref()
        .map_or(0.0, |g| g.payload_kg);
    para("By hand, on the files below:")?;
    command_line(&[
        "robocal calibrate".to_owned(),
        format!("--robot {PAPER_NOMINAL}"),
        format!("--data {}", super::demo_text::sh(&dir.join(files::CELL))),
        format!(
            "--validate {}",
            super::demo_text::sh(&dir.join(files::VALIDATION))
        ),
        "--compliance auto".to_owned(),
        format!("--payload-kg {payload}"),
        "--backlash auto --thermal auto".to_owned(),
        "--model geometric".to_owned(),
        format!(
            "--out {}",
            super::demo_text::sh(&dir.join("result-real-cell.json"))
        ),
    ])?;
    outln!()?;
    Ok(())
}
