//! The "Identifiability and solver" section: which parameters could be identified, the
//! condition number, the most correlated pairs, and how the solver ended.

use crate::escape::xml as esc;
use crate::markup::kv;
use crate::numfmt::magnitude;
use crate::page::Page;
use robocal_core::Result;
use std::fmt::Write;

/// Writes the section, or nothing without identifiability or solver summaries.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    if data.identifiability.is_none() && data.solver.is_none() {
        return Ok(false);
    }
    h.push_str("<section id=\"identification\">\n<h2>Identifiability and solver</h2>\n<div class=\"two-col\">\n<div>\n<h3>Identifiability</h3>\n");
    match &data.identifiability {
        Some(id) => {
            h.push_str("<dl class=\"kv\">\n");
            match (id.identified, id.total) {
                (Some(i), Some(t)) => kv(h, "Identified parameters", &format!("{i} of {t}")),
                (Some(i), None) => kv(h, "Identified parameters", &i.to_string()),
                _ => {}
            }
            if let Some(c) = id.condition_number {
                kv(h, "Condition number (scaled Jacobian)", &magnitude(c));
            }
            h.push_str("</dl>\n");
            if !id.correlated_pairs.is_empty() {
                h.push_str("<table>\n<thead><tr><th>Most correlated pairs</th><th class=\"num\">Correlation</th></tr></thead>\n<tbody>\n");
                for p in &id.correlated_pairs {
                    let _ = writeln!(
                        h,
                        "<tr><td class=\"code\">{} – {}</td><td class=\"num\">{}</td></tr>",
                        esc(&p.a),
                        esc(&p.b),
                        crate::numfmt::signed(p.correlation, 3)
                    );
                }
                h.push_str("</tbody>\n</table>\n");
            }
        }
        None => h.push_str("<p class=\"empty\">Not available.</p>\n"),
    }
    h.push_str("</div>\n<div>\n<h3>Solver</h3>\n");
    match &data.solver {
        Some(s) => {
            h.push_str("<dl class=\"kv\">\n");
            if !s.method.is_empty() {
                kv(h, "Method", &s.method);
            }
            if !s.objective.is_empty() {
                kv(h, "Objective", &s.objective);
            }
            let unit = s
                .value_unit
                .as_deref()
                .map(|u| format!(" {u}"))
                .unwrap_or_default();
            match (s.initial_value, s.final_value) {
                (Some(a), Some(b)) => kv(
                    h,
                    "Objective value",
                    &format!("{}{unit} → {}{unit}", magnitude(a), magnitude(b)),
                ),
                (None, Some(b)) => kv(
                    h,
                    "Final objective value",
                    &format!("{}{unit}", magnitude(b)),
                ),
                _ => {}
            }
            if !s.termination.is_empty() {
                kv(h, "Termination", &s.termination);
            }
            if let Some(i) = s.iterations {
                kv(h, "Iterations", &i.to_string());
            }
            if let Some(e) = s.evaluations {
                kv(h, "Evaluations", &e.to_string());
            }
            for x in &s.extra {
                kv(h, &x.key, &x.value);
            }
            h.push_str("</dl>\n");
        }
        None => h.push_str("<p class=\"empty\">Not available.</p>\n"),
    }
    h.push_str("</div>\n</div>\n</section>\n");
    Ok(true)
}
