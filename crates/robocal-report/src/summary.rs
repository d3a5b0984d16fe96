//! The "Summary" section: the mean error of each point set before and after calibration, and
//! the report's warnings and notes.

use crate::data::{Note, NoteLevel, PointSet};
use crate::escape::xml as esc;
use crate::numfmt::{fixed, mm};
use crate::page::Page;
use crate::values::finite;
use robocal_core::Result;
use std::fmt::Write;

/// Mean and max of the finite values, and their count.
fn mean_max(v: impl IntoIterator<Item = f64>) -> Option<(f64, f64, usize)> {
    let (v, _) = finite(v);
    if v.is_empty() {
        return None;
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some((mean, max, v.len()))
}

fn card(h: &mut String, set: &PointSet) {
    let before = mean_max(set.points.iter().map(|p| p.before_mm));
    let after = mean_max(set.points.iter().map(|p| p.after_mm));
    let name = esc(&set.name);
    match (before, after) {
        (Some((mb, xb, nb)), Some((ma, xa, na))) => {
            let change = if mb > 0.0 {
                format!(" ({}%)", fixed(100.0 * (ma - mb) / mb, 0))
            } else {
                String::new()
            };
            let n = if nb == na {
                format!("n = {nb}")
            } else {
                format!("n = {nb} / {na}")
            };
            let _ = writeln!(
                h,
                "<div class=\"card\"><div class=\"label\">{name} points – mean error</div>\
                 <div class=\"big\"><span class=\"before\">{}</span><span class=\"arrow\">→</span>\
                 <span class=\"after\">{}</span> <span class=\"small\">mm{change}</span></div>\
                 <div class=\"small\">max {} → {} mm · {n}</div></div>",
                mm(mb),
                mm(ma),
                mm(xb),
                mm(xa),
            );
        }
        (None, Some((m, x, n))) | (Some((m, x, n)), None) => {
            let class = if after.is_some() { "after" } else { "before" };
            let what = if after.is_some() {
                "after calibration"
            } else {
                "before calibration"
            };
            let _ = writeln!(
                h,
                "<div class=\"card\"><div class=\"label\">{name} points – mean error {what}</div>\
                 <div class=\"big\"><span class=\"{class}\">{}</span> <span class=\"small\">mm</span></div>\
                 <div class=\"small\">max {} mm · n = {n}</div></div>",
                mm(m),
                mm(x),
            );
        }
        (None, None) => {}
    }
}

/// Writes the section.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    h.push_str("<section id=\"summary\">\n<h2>Summary</h2>\n");
    let any = data.point_sets.iter().any(|s| {
        s.points
            .iter()
            .any(|p| p.before_mm.is_finite() || p.after_mm.is_finite())
    });
    if any {
        h.push_str("<div class=\"cards\">\n");
        for s in &data.point_sets {
            card(h, s);
        }
        h.push_str("</div>\n");
    } else if let Some(r) = data.error_tables.first().and_then(|t| t.rows.first()) {
        let _ = writeln!(
            h,
            "<p>{}: mean error {} mm (n = {}).</p>",
            esc(&r.label),
            mm(r.stats.mean_mm),
            r.stats.n
        );
    } else {
        h.push_str("<p class=\"empty\">No errors were given.</p>\n");
    }
    notes(h, &data.notes);
    h.push_str("</section>\n");
    Ok(true)
}

fn notes(h: &mut String, notes: &[Note]) {
    // Warnings first: they are what a reader must not miss.
    let order = [NoteLevel::Warning, NoteLevel::Info];
    for level in order {
        for n in notes.iter().filter(|n| n.level == level) {
            let (class, label) = match n.level {
                NoteLevel::Warning => ("note warning", "Warning"),
                NoteLevel::Info => ("note", "Note"),
            };
            let _ = writeln!(
                h,
                "<div class=\"{class}\"><strong>{label}</strong>{}</div>",
                esc(&n.text)
            );
        }
    }
}
