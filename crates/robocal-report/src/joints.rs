//! The "Joints" section: the error after calibration against each joint's value. A trend along
//! one joint (a ramp, a wave once per turn) is what a geometric model left behind: a gear or
//! encoder error, an elastic joint, a wrong offset.

use crate::data::ReportData;
use crate::page::{detailed_sets, Page};
use crate::plot::series_color;
use crate::svgplot::{density_color, markers, range_of, Frame, Grid, Svg, MARKER_LIMIT};
use robocal_core::{Result, Unit};
use std::fmt::Write;

const W: u32 = 960;
const COLS: usize = 3;
const ROW_H: f64 = 230.0;
/// Bins along a joint for the median line.
const MEDIAN_BINS: usize = 24;

/// (joint values, errors after calibration) of every point with both.
fn points(data: &ReportData, joint: usize) -> Vec<(f64, f64)> {
    detailed_sets(data)
        .into_iter()
        .flat_map(|s| s.details.iter().zip(&s.points))
        .filter_map(|(d, p)| {
            let q = *d.joints.get(joint)?;
            (q.is_finite() && p.after_mm.is_finite()).then_some((q, p.after_mm))
        })
        .collect()
}

/// Writes the section, or nothing without joint values.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    let dof = detailed_sets(data)
        .iter()
        .flat_map(|s| s.details.iter().map(|d| d.joints.len()))
        .max()
        .unwrap_or(0);
    if dof == 0 || points(data, 0).is_empty() {
        return Ok(false);
    }
    let rows = dof.div_ceil(COLS);
    let all_errors: Vec<f64> = points(data, 0).iter().map(|p| p.1).collect();
    let emax = all_errors.iter().copied().fold(0.0f64, f64::max);
    let top = crate::bins::outlier_cap(&all_errors, 0.0).unwrap_or(emax);
    let y = range_of([0.0, top].into_iter(), true);
    let n = all_errors.len();
    let dense = n > MARKER_LIMIT;
    let mut svg = Svg::new(
        W,
        (rows as f64 * ROW_H).round() as u32,
        "Error after calibration against each joint",
        &format!("{n} points, one panel per joint."),
    );
    let pw = W as f64 / COLS as f64;
    let c = series_color(1);
    let color = format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2);
    for j in 0..dof {
        let pts = points(data, j);
        let unit = match data.joint_units.get(j) {
            Some(Unit::Mm) => "mm",
            _ => "deg",
        };
        let frame = Frame {
            left: (j % COLS) as f64 * pw + 56.0,
            top: (j / COLS) as f64 * ROW_H + 28.0,
            width: pw - 72.0,
            height: ROW_H - 28.0 - 48.0,
            x: range_of(pts.iter().map(|p| p.0), false),
            y,
        };
        frame.axes(
            &mut svg,
            &format!("Joint {}", j + 1),
            &format!("q{} ({unit})", j + 1),
            "Error after (mm)",
        );
        let clipped: Vec<(f64, f64)> = pts.iter().map(|&(q, e)| (q, e.min(y.1))).collect();
        if dense {
            let g = Grid::new(&frame, 48, 24, clipped.iter().map(|&(q, e)| (q, e, 1.0)));
            let max = g.max_count();
            g.draw(&mut svg, &frame, |k, _| density_color(k, max));
        } else {
            let px: Vec<(f64, f64)> = clipped
                .iter()
                .map(|&(q, e)| (frame.px(q), frame.py(e)))
                .collect();
            markers(&mut svg, &px, &color, 4.0, 0.55);
        }
        median_line(&mut svg, &frame, &pts);
    }
    h.push_str("<section id=\"joints\">\n<h2>Error against each joint</h2>\n");
    let mut cap = String::from(
        "Error after calibration of every point with joint values (all point sets), against \
         each joint's value; the dark line is the median error in bins along the joint. A trend \
         that the calibration left along one joint is not geometric (gear, encoder, elasticity).",
    );
    if dense {
        let _ = write!(
            cap,
            " {n} points, shown as cells shaded by how many points they hold (darker: more)."
        );
    }
    if top < emax {
        let _ = write!(
            cap,
            " Errors above {} mm are drawn at the top edge.",
            crate::numfmt::mm(top)
        );
    }
    crate::markup::figure(h, &svg.finish(), &cap);
    h.push_str("</section>\n");
    Ok(true)
}

/// The median error in `MEDIAN_BINS` bins along x (bins of at least 3 points), as a polyline.
fn median_line(svg: &mut Svg, frame: &Frame, pts: &[(f64, f64)]) {
    let mut bins: Vec<Vec<f64>> = vec![Vec::new(); MEDIAN_BINS];
    for &(q, e) in pts {
        let t = (q - frame.x.0) / (frame.x.1 - frame.x.0);
        let i = ((t * MEDIAN_BINS as f64).floor().max(0.0) as usize).min(MEDIAN_BINS - 1);
        bins[i].push(e);
    }
    let mut d = String::new();
    for (i, b) in bins.iter_mut().enumerate() {
        if b.len() < 3 {
            continue;
        }
        let m = robocal_core::stats::percentile(b, 0.5).min(frame.y.1);
        let x = frame.x.0 + (i as f64 + 0.5) / MEDIAN_BINS as f64 * (frame.x.1 - frame.x.0);
        let _ = write!(
            d,
            "{}{:.1} {:.1}",
            if d.is_empty() { "M" } else { "L" },
            frame.px(x),
            frame.py(m)
        );
    }
    if !d.is_empty() {
        svg.raw(&format!(
            "<path d=\"{d}\" stroke=\"#222\" stroke-width=\"2\" fill=\"none\"/>\n"
        ));
    }
}
