//! The "Points" section, on demand ([`crate::data::ReportData::point_table`]): every point's
//! errors in a table (collapsed until opened), for finding a point by its number.

use crate::escape::xml as esc;
use crate::numfmt::{mm, signed};
use crate::page::Page;
use robocal_core::Result;
use std::fmt::Write;

/// Writes the section when asked for and there are points.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    let n: usize = data.point_sets.iter().map(|s| s.points.len()).sum();
    if !data.point_table || n == 0 {
        return Ok(false);
    }
    h.push_str("<section id=\"points\">\n<h2>Every point</h2>\n");
    let _ = write!(
        h,
        "<details>\n<summary>{n} points: error norms and the error vector after calibration \
         (mm, base frame)</summary>\n<table class=\"points\">\n<thead><tr><th>Set</th>\
         <th class=\"num\">#</th><th class=\"num\">Reach</th><th class=\"num\">Before</th>\
         <th class=\"num\">After</th><th class=\"num\">dx</th><th class=\"num\">dy</th>\
         <th class=\"num\">dz</th></tr></thead>\n<tbody>\n"
    );
    for s in &data.point_sets {
        let name = esc(&s.name);
        for (i, p) in s.points.iter().enumerate() {
            let d = s.details.get(i).map(|d| d.after_mm);
            let c = |k: usize| d.map_or_else(|| "–".to_string(), |v| signed(v[k], 3));
            let _ = writeln!(
                h,
                "<tr><td>{name}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
                 <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
                 <td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
                i + 1,
                crate::numfmt::fixed(p.reach_mm, 1),
                mm(p.before_mm),
                mm(p.after_mm),
                c(0),
                c(1),
                c(2)
            );
        }
    }
    h.push_str("</tbody>\n</table>\n</details>\n</section>\n");
    Ok(true)
}
