//! Text tables of `robocal demo`: our figures beside the paper's (Tables II to V).

use crate::tables::num;
use robocal_core::experiment::Experiment;
use robocal_core::{ErrorStats, Unit};
use robocal_report::PaperStats;
use std::fmt::Write;

/// One column group of an error table: a label, our statistics, the paper's.
pub struct Column<'a> {
    /// e.g. "Calibration points".
    pub label: &'a str,
    /// Our figures.
    pub ours: ErrorStats,
    /// The paper's figures for the same points.
    pub paper: PaperStats,
}

/// An error table (n, mean, std, max in mm) with the paper's figures beside ours.
pub fn error_table(title: &str, columns: &[Column]) -> String {
    let mut s = format!("{title}\n");
    let _ = write!(s, "{:<12}", "");
    for c in columns {
        let _ = write!(s, "  {:^22}", c.label);
    }
    s.truncate(s.trim_end().len());
    s.push('\n');
    let _ = write!(s, "{:<12}", "");
    for _ in columns {
        let _ = write!(s, "  {:>10}{:>12}", "this run", "paper");
    }
    s.push('\n');
    type Row = (
        &'static str,
        fn(&ErrorStats) -> f64,
        fn(&PaperStats) -> Option<f64>,
    );
    let rows: [Row; 3] = [
        ("Mean (mm)", |e| e.mean_mm, |p| p.mean_mm),
        ("St. dev.", |e| e.std_mm, |p| p.std_mm),
        ("Max. (mm)", |e| e.max_mm, |p| p.max_mm),
    ];
    let _ = write!(s, "{:<12}", "points");
    for c in columns {
        let paper = c.paper.n.map_or("-".into(), |n| n.to_string());
        let _ = write!(s, "  {:>10}{:>12}", c.ours.n, paper);
    }
    s.push('\n');
    for (label, ours, paper) in rows {
        let _ = write!(s, "{label:<12}");
        for c in columns {
            let p = paper(&c.paper).map_or("-".into(), |v| num(v, 3));
            let _ = write!(s, "  {:>10}{:>12}", num(ours(&c.ours), 3), p);
        }
        s.push('\n');
    }
    s
}

/// Table III as a list: nominal, the paper's Table III (the simulation's truth), the truth in the
/// identified parameters, calibrated value, standard deviation and calibration error; fixed
/// parameters marked `*`, their reasons below.
pub fn parameter_table(exp: &Experiment) -> String {
    let cfg = &exp.config;
    let cal = &exp.calibration;
    let eq = &exp.truth_comparison.equivalent;
    let n_fixed = cal.identifiability.fixed.len();
    let mut s = format!(
        "Table III. Calibrated parameters: {} identified, {n_fixed} fixed at the nominal value (*)\n",
        cal.identifiability.identified.len()
    );
    let _ = writeln!(
        s,
        "{:<13}{:>11}{:>13}{:>13}{:>14}{:>10}{:>12}",
        "", "nominal", "paper's", "true value,", "calibrated", "std", "calibrated"
    );
    let _ = writeln!(
        s,
        "{:<13}{:>11}{:>13}{:>13}{:>14}{:>10}{:>12}",
        "", "(Table I)", "Table III", "same params", "", "", "- true"
    );
    let pv = cal.param_vector();
    for p in cfg.nominal.params() {
        let d = 4;
        let unit = p.unit().as_str();
        let sd = pv.get(p).and_then(|e| e.std.map(|v| e.display(v)));
        let c = exp.calibrated.get_display(p);
        let t = eq.get_display(p);
        let mut err = c - t;
        if p.unit() == Unit::Deg {
            err = (err + 180.0).rem_euclid(360.0) - 180.0;
        }
        let (mark, std, err) = match sd {
            Some(v) => (" ", num(v, d), num(err, d)),
            None => ("*", "-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "{:<9}{:<4}{:>11}{:>13}{:>13}{:>13}{mark}{:>10}{:>12}",
            p.name(),
            unit,
            num(cfg.nominal.get_display(p), d),
            num(cfg.truth.get_display(p), d),
            num(t, d),
            num(c, d),
            std,
            err
        );
    }
    s.push_str("Fixed (*), and why:\n");
    for f in &cal.identifiability.fixed {
        let _ = writeln!(s, "  {:<8} {}", f.param.name(), f.describe());
    }
    let tc = &exp.truth_comparison;
    let _ = writeln!(
        s,
        "\"true value, same params\": the simulated robot (the paper's Table III) expressed in the\n\
         identified parameters and the fitted measurement frame: what a calibration from exact\n\
         measurements without gravity would find (it reproduces the true tool points to {:.0e} mm).",
        tc.fit_max_mm.max(1e-12)
    );
    let _ = writeln!(
        s,
        "The calibrated geometry is {:.3} mm from the true one on average (max {:.3} mm) at the\n\
         validation poses{}",
        tc.model_error.mean_mm,
        tc.model_error.max_mm,
        if cfg.session.gravity.is_some() {
            ": the geometric model absorbs part of the gravity sag, which moves\n\
             some parameters by several standard deviations."
        } else {
            "."
        }
    );
    s
}

/// `a` relative to `b`, as a signed percentage.
pub fn percent(a: f64, b: f64) -> String {
    format!("{:+.1}%", 100.0 * (a - b) / b)
}
