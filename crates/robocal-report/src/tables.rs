//! HTML tables: error statistics (the paper's Tables II, IV, V, with its figures beside ours),
//! model parameters, fixed parameters, run settings.

use crate::data::{ErrorRow, ErrorTable, FixedParam, ParamRow, ReportData};
use crate::escape::xml as esc;
use crate::numfmt::{fixed, mm, sig2, signed, DASH};
use crate::page::Page;
use robocal_core::Result;
use robocal_core::Unit;
use std::fmt::Write;

/// Decimals of parameter values (mm and degrees).
const PARAM_DECIMALS: usize = 4;

/// The "Error statistics" section.
pub(crate) fn errors_section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    h.push_str("<section id=\"errors\">\n<h2>Error statistics</h2>\n");
    if data.error_tables.is_empty() {
        h.push_str("<p class=\"empty\">No error statistics were given.</p>\n</section>\n");
        return Ok(true);
    }
    let with_paper = data
        .error_tables
        .iter()
        .any(|t| t.rows.iter().any(|r| r.paper.is_some()));
    h.push_str("<p class=\"lead\">Norms of the displacement error ‖Eᵢ‖ = ‖P<sub>act</sub> − P<sub>nom</sub>‖ (eq. 3), in mm. Std. dev. is the sample standard deviation.");
    if with_paper {
        h.push_str(
            " Shaded rows give the paper’s figures for the same points (it reports mean, \
             standard deviation and maximum only).",
        );
    }
    h.push_str(
        "</p>\n<table class=\"stats\">\n<thead><tr><th>Points</th><th class=\"num\">n</th>\
         <th class=\"num\">Mean</th><th class=\"num\">Std. dev.</th><th class=\"num\">Max</th>\
         <th class=\"num\">RMS</th><th class=\"num\">95th pct.</th></tr></thead>\n",
    );
    for t in &data.error_tables {
        error_table(h, t);
    }
    h.push_str("</table>\n</section>\n");
    Ok(true)
}

/// One table of the paper as a group of rows: a heading row, then one row per point set.
fn error_table(h: &mut String, t: &ErrorTable) {
    let _ = write!(
        h,
        "<tbody>\n<tr class=\"group\"><th colspan=\"7\">{}",
        esc(&t.title)
    );
    if let Some(c) = &t.caption {
        let _ = write!(h, "<span class=\"sub\">{}</span>", esc(c));
    }
    h.push_str("</th></tr>\n");
    for r in &t.rows {
        error_row(h, r);
    }
    h.push_str("</tbody>\n");
}

fn error_row(h: &mut String, r: &ErrorRow) {
    let s = &r.stats;
    let n = if s.n == 0 {
        "0".to_string()
    } else {
        s.n.to_string()
    };
    let _ = writeln!(
        h,
        "<tr><th scope=\"row\">{}</th><td class=\"num\">{n}</td><td class=\"num\">{}</td>\
         <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
         <td class=\"num\">{}</td></tr>",
        esc(&r.label),
        mm(s.mean_mm),
        mm(s.std_mm),
        mm(s.max_mm),
        mm(s.rms_mm),
        mm(s.p95_mm),
    );
    if let Some(p) = &r.paper {
        let _ = writeln!(
            h,
            "<tr class=\"paper\"><th scope=\"row\">Paper: {}</th><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            esc(&p.source),
            p.n.map_or_else(|| DASH.to_string(), |n| n.to_string()),
            opt_mm(p.mean_mm),
            opt_mm(p.std_mm),
            opt_mm(p.max_mm),
            opt_mm(p.rms_mm),
            opt_mm(p.p95_mm),
        );
    }
}

fn opt_mm(v: Option<f64>) -> String {
    v.map_or_else(|| DASH.to_string(), mm)
}

fn unit_str(u: Unit) -> &'static str {
    match u {
        Unit::Mm => "mm",
        Unit::Deg => "°",
        Unit::MicroradPerNm => "µrad/(N·m)",
        Unit::MicroradPerM => "µrad/m",
        Unit::PpmPerK => "ppm/K",
    }
}

/// The fixed parameters to list: the identifiability summary's list if given, else the
/// parameter rows marked fixed.
fn fixed_list(data: &ReportData) -> Vec<FixedParam> {
    if let Some(id) = data
        .identifiability
        .as_ref()
        .filter(|i| !i.fixed.is_empty())
    {
        return id.fixed.clone();
    }
    data.parameters
        .iter()
        .filter(|p| p.fixed)
        .map(|p| FixedParam {
            name: p.name.clone(),
            reason: p.reason.clone().unwrap_or_else(|| DASH.into()),
        })
        .collect()
}

/// The "Model parameters" section: all parameters, and the fixed ones with reasons.
pub(crate) fn parameters_section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    h.push_str("<section id=\"parameters\">\n<h2>Model parameters</h2>\n");
    if data.parameters.is_empty() {
        h.push_str("<p class=\"empty\">No parameters were given.</p>\n</section>\n");
        return Ok(true);
    }
    let identified = data.parameters.iter().filter(|p| !p.fixed).count();
    let with_truth = data.parameters.iter().any(|p| p.truth.is_some());
    let _ = write!(
        h,
        "<p class=\"lead\">{identified} of {} parameters identified; the others were held at \
         their nominal values. Lengths in mm, angles in degrees; difference = calibrated − \
         nominal; std. dev. from the covariance of the fit.",
        data.parameters.len()
    );
    if with_truth {
        h.push_str(
            " True: the simulated robot’s values in the same parameters (what a calibration \
             from exact measurements would find); cal. − true is the calibration’s error.",
        );
    }
    h.push_str("</p>\n");
    let columns = if with_truth { 8 } else { 6 };
    let layout = if with_truth {
        "params-layout wide"
    } else {
        "params-layout"
    };
    let _ = write!(h, "<div class=\"{layout}\">\n<div>\n<table class=\"params\">\n<thead><tr><th>Parameter</th><th>Unit</th><th class=\"num\">Nominal</th><th class=\"num\">Calibrated</th><th class=\"num\">Difference</th><th class=\"num\">Std. dev.</th>");
    if with_truth {
        h.push_str("<th class=\"num\">True</th><th class=\"num\">Cal. − true</th>");
    }
    h.push_str("</tr></thead>\n<tbody>\n");
    let reflectors = data
        .parameters
        .iter()
        .filter_map(|p| crate::build::reflector(&p.name))
        .map(|(j, _)| j)
        .max()
        .unwrap_or(1);
    let groups: Vec<String> = data
        .parameters
        .iter()
        .map(|p| param_group(&p.name, reflectors))
        .collect();
    let grouped = groups.windows(2).any(|w| w[0] != w[1]);
    for (i, p) in data.parameters.iter().enumerate() {
        if grouped && (i == 0 || groups[i] != groups[i - 1]) {
            let _ = writeln!(
                h,
                "<tr class=\"group\"><th colspan=\"{columns}\">{}</th></tr>",
                esc(&groups[i])
            );
        }
        param_row(h, p, with_truth);
    }
    h.push_str("</tbody>\n</table>\n</div>\n<div>\n<h3>Fixed parameters</h3>\n");
    let fixed = fixed_list(data);
    if fixed.is_empty() {
        h.push_str("<p class=\"empty\">None: every parameter was identified.</p>\n");
    } else {
        h.push_str("<table class=\"fixed-params\">\n<thead><tr><th>Parameter</th><th>Why it is fixed</th></tr></thead>\n<tbody>\n");
        for f in &fixed {
            let _ = writeln!(
                h,
                "<tr><td class=\"code\">{}</td><td>{}</td></tr>",
                esc(&f.name),
                esc(&f.reason)
            );
        }
        h.push_str("</tbody>\n</table>\n");
    }
    h.push_str("</div>\n</div>\n</section>\n");
    Ok(true)
}

/// The group a parameter belongs to, from its name: a joint, the base frame or the tool; with
/// several reflectors (`reflectors` > 1), each reflector's tool is a group of its own.
fn param_group(name: &str, reflectors: usize) -> String {
    if name.starts_with("base_") {
        return "Base frame (column B)".into();
    }
    match crate::build::reflector(name) {
        Some((1, _)) if reflectors == 1 => return "Tool (column T)".into(),
        Some((1, _)) => return format!("Reflector 1 of {reflectors}: its tool (column T)"),
        Some((j, _)) => {
            return format!("Reflector {j} of {reflectors}: its tool (offset on the flange)")
        }
        None => {}
    }
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    if digits > 0 && digits < name.len() {
        format!("Joint {}", &name[name.len() - digits..])
    } else {
        "Other".into()
    }
}

fn param_row(h: &mut String, p: &ParamRow, with_truth: bool) {
    let d = PARAM_DECIMALS;
    let (class, std) = if p.fixed {
        (
            " class=\"fixed\"",
            "<span class=\"tag\">fixed</span>".to_string(),
        )
    } else {
        ("", p.std.map_or_else(|| DASH.to_string(), sig2))
    };
    let diff = if p.fixed && p.difference() == 0.0 {
        DASH.to_string()
    } else {
        signed(p.difference(), d)
    };
    let _ = write!(
        h,
        "<tr{class}><td class=\"code\">{}</td><td>{}</td><td class=\"num\">{}</td>\
         <td class=\"num\">{}</td><td class=\"num\">{diff}</td><td class=\"num\">{std}</td>",
        esc(&p.name),
        unit_str(p.unit),
        fixed(p.nominal, d),
        fixed(p.calibrated, d),
    );
    if with_truth {
        match p.truth {
            Some(t) => {
                let err = ParamRow {
                    nominal: t,
                    ..p.clone()
                }
                .difference();
                let err = if p.fixed && err == 0.0 {
                    DASH.to_string()
                } else {
                    signed(err, d)
                };
                let _ = write!(
                    h,
                    "<td class=\"num\">{}</td><td class=\"num\">{err}</td>",
                    fixed(t, d)
                );
            }
            None => {
                let _ = write!(
                    h,
                    "<td class=\"num\">{DASH}</td><td class=\"num\">{DASH}</td>"
                );
            }
        }
    }
    h.push_str("</tr>\n");
}

/// The "Run settings" section.
pub(crate) fn settings_section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    if data.settings.is_empty() {
        return Ok(false);
    }
    h.push_str("<section id=\"settings\">\n<h2>Run settings</h2>\n<dl class=\"kv\">\n");
    for s in &data.settings {
        crate::markup::kv(h, &s.key, &s.value);
    }
    h.push_str("</dl>\n</section>\n");
    Ok(true)
}
