//! The orientation errors of 6-DoF measurements (a probe's frame measured beside its point): the
//! angle between the measured and the model's tool frame, before and after calibration, per
//! point set. Left out for point data.

use crate::escape::xml as esc;
use crate::page::Page;
use robocal_core::Result;
use std::fmt::Write;

/// Writes the section when the report has orientation errors.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let rows = &page.data.orientation;
    if rows.is_empty() {
        return Ok(false);
    }
    h.push_str(
        "<section id=\"orientation\">\n<h2>Orientation errors</h2>\n<p class=\"lead\">6-DoF \
         measurements: the angle of R<sub>measured</sub> R<sub>model</sub><sup>T</sup> (a \
         rotation, never a difference of A, B, C), in degrees.</p>\n<table class=\"stats\">\n\
         <thead><tr><th>Points</th><th class=\"num\">n</th><th class=\"num\">Mean</th>\
         <th class=\"num\">Std. dev.</th><th class=\"num\">Max</th><th class=\"num\">RMS</th>\
         </tr></thead>\n<tbody>\n",
    );
    for r in rows {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{:.5}</td>\
             <td class=\"num\">{:.5}</td><td class=\"num\">{:.5}</td><td class=\"num\">{:.5}</td></tr>",
            esc(&r.label),
            r.n,
            r.mean_deg,
            r.std_deg,
            r.max_deg,
            r.rms_deg
        );
    }
    h.push_str("</tbody>\n</table>\n</section>\n");
    Ok(true)
}
