//! What `robocal calibrate` prints: the model selection, Tables II-IV, the parameters, the
//! solver, the prediction, the weighting and the plausibility gate.

use super::super::common;
use crate::tables::{layout, num};
use robocal_core::identification::{Calibration, CheckKind};
use robocal_core::{ErrorStats, Param};

/// Prints the automatic model choice: every candidate with its cross-validated error.
pub(crate) fn print_selection(
    sel: &robocal_core::identification::ModelSelection,
) -> anyhow::Result<()> {
    outln!()?;
    outln!(
        "model: {} (--model auto: cross-validation over the calibration data, {} folds by pose; \
         a family stays only when it lowers the error by more than the standard error)",
        sel.chosen().name(),
        sel.folds
    )?;
    // The name column as wide as the longest name (four families' names exceed 40 characters).
    let w = sel
        .candidates
        .iter()
        .map(|c| c.name().len())
        .chain([40])
        .max()
        .unwrap_or(40);
    outln!(
        "  {:<w$} {:>10} {:>16} {:>10}",
        "candidate",
        "parameters",
        "CV mean (mm)",
        "std. err."
    )?;
    for c in &sel.candidates {
        let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
        outln!(
            "{} {:<w$} {:>10} {:>16} {:>10}{}",
            if c.chosen { "*" } else { " " },
            c.name(),
            c.identified,
            f(c.cv_mean_mm),
            f(c.cv_std_error_mm),
            match (&c.rejected, c.reference) {
                (Some(r), _) => format!("  not selectable: {r}"),
                (None, true) => "  (reference: the families given are fixed)".into(),
                (None, false) if c.screened => {
                    "  (screened: estimated from the model it extends, not fitted)".into()
                }
                (None, false) => String::new(),
            }
        )?;
    }
    if let Some(r) = &sel.remark {
        outln!("remark: {r}")?;
    }
    Ok(())
}

/// Prints the plausibility gate's outcome: one line when it passed, every failed check with its
/// likely cause otherwise.
pub(super) fn print_plausibility(c: &Calibration) -> anyhow::Result<()> {
    let p = &c.plausibility;
    outln!()?;
    if p.passed() {
        let names: Vec<&str> = p.checks.iter().map(|c| c.kind.name()).collect();
        outln!(
            "plausibility: all {} checks passed ({})",
            p.checks.len(),
            names.join(", ")
        )?;
        return Ok(());
    }
    outln!(
        "plausibility: {} of {} checks FAILED",
        p.failures().count(),
        p.checks.len()
    )?;
    if !c.solver().termination.converged() {
        if let Some(f) = p.failures().find(|f| f.kind == CheckKind::Convergence) {
            outln!("  convergence: {}", f.detail)?;
        }
    }
    if p.implausible() {
        outln!("{}", common::indent(&p.summary()))?;
    }
    Ok(())
}

fn stats_table(title: &str, cols: &[(&str, ErrorStats)]) -> String {
    use std::fmt::Write;
    let mut s = format!("{title}\n");
    let _ = write!(s, "{:<16}", "");
    for (name, _) in cols {
        let _ = write!(s, "{name:>14}");
    }
    s.push('\n');
    type Row = (&'static str, fn(&ErrorStats) -> String);
    let rows: [Row; 5] = [
        ("points", |e| e.n.to_string()),
        ("Mean (mm)", |e| format!("{:.4}", e.mean_mm)),
        ("St. dev. (mm)", |e| format!("{:.4}", e.std_mm)),
        ("Max. (mm)", |e| format!("{:.4}", e.max_mm)),
        ("RMS (mm)", |e| format!("{:.4}", e.rms_mm)),
    ];
    for (label, f) in rows {
        let _ = write!(s, "{label:<16}");
        for (_, e) in cols {
            let _ = write!(s, "{:>14}", f(e));
        }
        s.push('\n');
    }
    s
}

/// Prints the calibration: the measurement frame and the weights, Table II, the
/// identifiability, Table III with the standard deviations, the solver, Table IV and the
/// prediction. `converged` and `implausible` mark the tables of a fit that is not a calibration.
pub(super) fn print_report(
    c: &Calibration,
    converged: bool,
    implausible: bool,
) -> anyhow::Result<()> {
    let partial = if !converged {
        " -- PARTIAL: the solver did not converge; not a calibration"
    } else if implausible {
        " -- IMPLAUSIBLE: failed the plausibility gate; not a calibration"
    } else {
        ""
    };
    print_registration(c)?;
    print_before(c)?;
    print_identifiability(c)?;
    print_parameters(c, partial)?;
    print_solver(c)?;
    print_after(c, partial)?;
    print_prediction(c)
}

/// The initial and the fitted measurement frame (eq. 8-11), and the point weights.
fn print_registration(c: &Calibration) -> anyhow::Result<()> {
    let reg = &c.registration;
    let tf = robocal_core::io::result::FrameVec::from_tracker_frame(&reg.frame);
    outln!()?;
    match reg.initial {
        robocal_core::registration::InitialFrame::Plane {
            n,
            tilt_deg,
            max_error_mm,
            ..
        } => outln!(
            "initial measurement frame from {n} plane points (plane tilt {tilt_deg:.3} deg; \
             largest error under it {max_error_mm:.3} mm)"
        )?,
        robocal_core::registration::InitialFrame::LeastSquares => {
            outln!("initial measurement frame: least-squares fit (no plane points)")?
        }
    }
    outln!(
        "tracker frame in the base frame (mm, deg): x {:.4}  y {:.4}  z {:.4}  A {:.5}  B {:.5}  C {:.5}",
        tf.x, tf.y, tf.z, tf.a, tf.b, tf.c
    )?;
    print_weighting(&c.weighting)
}

/// Table II (the nominal model in the fitted frame), with the fitted tools, the orientation
/// errors of 6-DoF rows and the affine registration.
fn print_before(c: &Calibration) -> anyhow::Result<()> {
    let reg = &c.registration;
    let before_cols: Vec<(&str, ErrorStats)> =
        std::iter::once(("Calibration", c.calibration.before_stats()))
            .chain(
                c.validation
                    .as_ref()
                    .map(|v| ("Validation", v.before_stats())),
            )
            .collect();
    outln!()?;
    out!(
        "{}",
        stats_table(
            "Table II. Error before calibration (nominal model, fitted measurement frame)",
            &before_cols
        )
    )?;
    let tf = &c.tool_fit;
    let tools: Vec<String> = tf
        .tools
        .iter()
        .map(|t| format!("({:.3}, {:.3}, {:.3})", t[0], t[1], t[2]))
        .collect();
    outln!(
        "with the fitted tool{} {} (mm, flange frame): mean {:.4} mm, RMS {:.4} mm, max {:.4} mm{}",
        if tools.len() > 1 { "s" } else { "" },
        tools.join(", "),
        tf.stats.mean_mm,
        tf.stats.rms_mm,
        tf.stats.max_mm,
        if tf.applied {
            ""
        } else {
            " (not used: the nominal geometry misses the data even so)"
        }
    )?;
    if let Some(o) = &c.calibration.orientation_deg {
        let (b, a) = (ErrorStats::from_norms(&o.0), ErrorStats::from_norms(&o.1));
        outln!(
            "orientation error (deg): before mean {:.4}, max {:.4}; after mean {:.4}, max {:.4}",
            b.mean_mm,
            b.max_mm,
            a.mean_mm,
            a.max_mm
        )?;
    }
    if let Some(af) = &reg.affine {
        let sv = af.tr.singular_values();
        outln!(
            "affine Tr (eq. 8-11): mean {:.4} mm, max {:.4} mm; singular values {:.6} {:.6} {:.6}",
            af.stats.mean_mm,
            af.stats.max_mm,
            sv[0],
            sv[1],
            sv[2]
        )?;
    }
    Ok(())
}

/// What was identified, and why each other parameter is fixed.
fn print_identifiability(c: &Calibration) -> anyhow::Result<()> {
    let id = &c.identifiability;
    outln!()?;
    outln!(
        "identifiability: {} parameters identified, {} fixed (rank tolerance {:.0e}); condition \
         number of the scaled Jacobian {:.1}",
        id.identified.len(),
        id.fixed.len(),
        id.rank_tolerance,
        id.condition_number
    )?;
    for f in &id.fixed {
        outln!(
            "  {:<8} fixed: {}",
            f.param.name(),
            super::super::flags::with_flags(&f.describe())
        )?;
    }
    outln!()?;
    Ok(())
}

/// Table III: the calibrated parameters, their standard deviations and the most correlated
/// pairs.
fn print_parameters(c: &Calibration, partial: &str) -> anyhow::Result<()> {
    let pv = c.param_vector();
    let entry = |p: Param| pv.get(p).expect("a parameter of the calibrated robot");
    outln!(
        "Table III. Calibrated parameters of the robot (* fixed at its nominal value){partial}"
    )?;
    out!(
        "{}",
        layout(&c.calibrated, &|p| {
            let v = num(c.calibrated.get_display(p), 4);
            if !entry(p).identified() {
                format!("{v}*")
            } else {
                format!("{v} ")
            }
        })
    )?;
    outln!("Standard deviations (same layout; - fixed, n/a unavailable)")?;
    out!(
        "{}",
        layout(&c.calibrated, &|p| {
            let e = entry(p);
            match e.std {
                Some(sd) => format!("{:.4} ", e.display(sd)),
                None if e.identified() => "n/a ".to_string(),
                None => "- ".to_string(),
            }
        })
    )?;
    let corr = c.covariance.most_correlated(5);
    if !corr.is_empty() {
        outln!(
            "most correlated: {}",
            corr.iter()
                .map(|k| format!("{}/{} {:+.3}", k.a.name(), k.b.name(), k.rho))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    outln!()?;
    Ok(())
}

/// How the solve ended, over all its stages, and the points the robust objective down-weighted.
fn print_solver(c: &Calibration) -> anyhow::Result<()> {
    let s = c.solver();
    let whole = c.whole_solve();
    let warm = c
        .stages
        .iter()
        .filter_map(|s| s.points.map(|p| (p, s.report.iterations)))
        .fold(None, |acc: Option<(usize, usize)>, (p, it)| {
            Some((p, acc.map_or(0, |a| a.1) + it))
        });
    let warm = warm.map_or(String::new(), |(points, iterations)| {
        format!(
            " ({iterations} of them on an even {points} of the {} points, to start)",
            c.calibration.after.len()
        )
    });
    outln!(
        "solver ({}): {} after {} iteration(s){warm}; objective {:.6} -> {:.6}",
        c.settings.objective.name(),
        s.termination.describe(),
        whole.iterations,
        whole.initial_objective,
        s.final_objective
    )?;
    if let Some(scale) = c.robust_scale_mm {
        outln!(
            "robust scale {scale:.4} mm; {} point(s) down-weighted{}",
            c.downweighted.len(),
            if c.downweighted.is_empty() { "" } else { ":" }
        )?;
        for d in &c.downweighted {
            let orientation = d
                .orientation_deg
                .map_or(String::new(), |a| format!(", orientation {a:.4} deg"));
            outln!(
                "  line {:>5}: error {:.4} mm{orientation}, weight {:.4}",
                d.line,
                d.error_mm,
                d.weight
            )?;
        }
    }
    Ok(())
}

/// Table IV: the calibrated model's errors.
fn print_after(c: &Calibration, partial: &str) -> anyhow::Result<()> {
    let after_cols: Vec<(&str, ErrorStats)> =
        std::iter::once(("Calibration", c.calibration.after_stats()))
            .chain(
                c.validation
                    .as_ref()
                    .map(|v| ("Validation", v.after_stats())),
            )
            .collect();
    outln!()?;
    out!(
        "{}",
        stats_table(
            &format!("Table IV. Error after calibration (calibrated model){partial}"),
            &after_cols
        )
    )?;
    Ok(())
}

/// The predicted error at new poses, beside the measured validation mean when there is one.
fn print_prediction(c: &Calibration) -> anyhow::Result<()> {
    let Some(p) = &c.prediction else {
        outln!("predicted error at new poses: unavailable (no standard deviations)")?;
        return Ok(());
    };
    let measured = c.validation.as_ref().map(|v| v.after_stats().mean_mm);
    outln!(
        "Predicted at new poses like the calibration poses: mean {:.4} mm, std {:.4} mm, RMS \
         {:.4} mm (noise {:.4} mm per axis, parameter uncertainty {:.4} mm RMS){}",
        p.mean_mm,
        p.std_mm,
        p.rms_mm,
        p.noise_sigma_mm,
        p.model_rms_mm,
        match measured {
            Some(m) => format!(
                "; validation measured {m:.4} mm ({:+.1}%)",
                100.0 * (m / p.mean_mm - 1.0)
            ),
            None => String::new(),
        }
    )?;
    Ok(())
}

/// One line on the point weights the fit used.
fn print_weighting(w: &robocal_core::observations::AppliedWeighting) -> anyhow::Result<()> {
    use robocal_core::observations::WeightSource;
    let model = |t: &Option<robocal_core::observations::TrackerSigma>| {
        t.map(|t| format!("{} mm + {} mm/m per axis", t.fixed_mm, t.per_m_mm))
            .unwrap_or_default()
    };
    match w.source {
        WeightSource::Column => outln!("points weighted by their sigma_mm column")?,
        WeightSource::Given => outln!(
            "points weighted by the tracker model {} (--tracker-sigma)",
            model(&w.tracker)
        )?,
        WeightSource::Automatic => outln!(
            "points weighted by a typical tracker, {}: the data are in a tracker's frame (the \
             tracker {:.0} mm from the base); --tracker-sigma gives your tracker's model, \
             --tracker-sigma off weighs every point the same",
            model(&w.tracker),
            w.tracker_distance_mm
        )?,
        WeightSource::None => outln!(
            "every point weighs the same (the measurement frame's origin is {:.0} mm from the \
             base: not a tracker's own frame, or --tracker-sigma off)",
            w.tracker_distance_mm
        )?,
    }
    Ok(())
}
