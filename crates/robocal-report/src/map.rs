//! The "Workspace map" section: where in the workspace the error after calibration lives, seen
//! from above (x, y) and from the side (reach from the base axis, z), coloured by the error.

use crate::data::ReportData;
use crate::page::{detailed_sets, Page};
use crate::svgplot::{colorbar, markers, range_of, viridis, Frame, Grid, Svg, MARKER_LIMIT};
use robocal_core::Result;
use std::fmt::Write;

const W: u32 = 960;
const H: u32 = 470;
/// Colour steps of the markers (one `<path>` each).
const STEPS: usize = 16;

/// (x, y, z, error after) of every point with a position and an error after calibration.
fn points(data: &ReportData) -> Vec<([f64; 3], f64)> {
    detailed_sets(data)
        .into_iter()
        .flat_map(|s| s.details.iter().zip(&s.points))
        .filter(|(d, p)| d.position_mm.iter().all(|v| v.is_finite()) && p.after_mm.is_finite())
        .map(|(d, p)| (d.position_mm, p.after_mm))
        .collect()
}

/// The two views: title, x axis label, y axis label (in the order of [`project`]).
const VIEWS: [(&str, &str, &str); 2] = [
    ("Top view", "x (mm)", "y (mm)"),
    (
        "Side view (around the base axis)",
        "Reach from the base z axis (mm)",
        "z (mm)",
    ),
];

/// Writes the section, or nothing without positions.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let pts = points(page.data);
    if pts.is_empty() {
        return Ok(false);
    }
    let dense = pts.len() > MARKER_LIMIT;
    let frames = view_frames(&pts);
    let grids: Vec<Grid> = if dense {
        view_grids(&pts, &frames)
    } else {
        Vec::new()
    };
    let (lo, top) = colour_range(&pts, &grids, dense);
    let scale = |e: f64| (e - lo) / (top - lo);
    let mut svg = Svg::new(
        W,
        H,
        "Error after calibration across the workspace",
        &format!(
            "{} points seen from above and from the side, coloured by the error after \
             calibration (0 to {:.3} mm).",
            pts.len(),
            top
        ),
    );
    for (i, (title, xl, yl)) in VIEWS.iter().enumerate() {
        let frame = frames[i];
        frame.axes(&mut svg, title, xl, yl);
        if dense {
            grids[i].draw(&mut svg, &frame, |_, mean| viridis(scale(mean)));
        } else {
            draw_markers(&mut svg, &frame, &projected(i, &pts), scale);
        }
    }
    colorbar(
        &mut svg,
        W as f64 / 2.0 - 180.0,
        H as f64 - 38.0,
        360.0,
        lo,
        top,
        "Error after calibration (mm)",
    );
    h.push_str("<section id=\"map\">\n<h2>Workspace map</h2>\n");
    crate::markup::figure(h, &svg.finish(), &caption(pts.len(), dense, lo, top));
    h.push_str("</section>\n");
    Ok(true)
}

/// The plot frames of the two views (side by side, equal scales on their axes), each spanning
/// the points' projections.
fn view_frames(pts: &[([f64; 3], f64)]) -> Vec<Frame> {
    let pw = W as f64 / 2.0;
    (0..2)
        .map(|i| {
            let xy: Vec<(f64, f64)> = pts.iter().map(|(p, _)| project(i, p)).collect();
            Frame {
                left: i as f64 * pw + 66.0,
                top: 30.0,
                width: pw - 86.0,
                height: H as f64 - 30.0 - 100.0,
                x: range_of(xy.iter().map(|p| p.0), false),
                y: range_of(xy.iter().map(|p| p.1), false),
            }
            .equal_aspect()
        })
        .collect()
}

/// The points of each view binned into cells of its frame (for too many points to draw one by
/// one).
fn view_grids(pts: &[([f64; 3], f64)], frames: &[Frame]) -> Vec<Grid> {
    frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let xy = pts.iter().map(|(p, e)| {
                let (x, y) = project(i, p);
                (x, y, *e)
            });
            Grid::new(f, 64, 40, xy)
        })
        .collect()
}

/// The ends of the colour scale (low, top), from the cells' mean errors when `dense`, else from
/// the points' errors.
fn colour_range(pts: &[([f64; 3], f64)], grids: &[Grid], dense: bool) -> (f64, f64) {
    // The colour scale spans the 2nd to the 98th percentile of what is coloured (the points'
    // errors, or the cells' mean errors), so that a few extremes do not darken everything.
    let coloured: Vec<f64> = if dense {
        grids
            .iter()
            .flat_map(|g| {
                g.count
                    .iter()
                    .zip(&g.sum)
                    .filter(|(c, _)| **c > 0)
                    .map(|(c, s)| s / *c as f64)
            })
            .collect()
    } else {
        pts.iter().map(|p| p.1).collect()
    };
    let lo = robocal_core::stats::percentile(&coloured, 0.02);
    let top = robocal_core::stats::percentile(&coloured, 0.98).max(lo + 1e-9);
    (lo, top)
}

/// The points in view `view`: (x, y, error after).
fn projected(view: usize, pts: &[([f64; 3], f64)]) -> Vec<(f64, f64, f64)> {
    pts.iter()
        .map(|(p, e)| {
            let (x, y) = project(view, p);
            (x, y, *e)
        })
        .collect()
}

/// Draws the points `xy` (x, y, error) as markers coloured by `scale`d error, one path per
/// colour step.
fn draw_markers(svg: &mut Svg, frame: &Frame, xy: &[(f64, f64, f64)], scale: impl Fn(f64) -> f64) {
    // Smallest errors first, so that the largest are on top.
    let mut order: Vec<usize> = (0..xy.len()).collect();
    order.sort_by(|&a, &b| xy[a].2.total_cmp(&xy[b].2));
    let mut buckets: Vec<Vec<(f64, f64)>> = vec![Vec::new(); STEPS];
    for k in order {
        let (x, y, e) = xy[k];
        let b = ((scale(e).max(0.0) * STEPS as f64).floor() as usize).min(STEPS - 1);
        // One marker path per colour step, drawn from the smallest step up.
        buckets[b].push((frame.px(x), frame.py(y)));
    }
    for (b, px) in buckets.iter().enumerate() {
        markers(svg, px, &viridis((b as f64 + 0.5) / STEPS as f64), 6.0, 0.9);
    }
}

/// The figure's caption for `n` points: what is shown and the colour scale's range.
fn caption(n: usize, dense: bool, lo: f64, top: f64) -> String {
    let mut cap = String::from(
        "Where the error after calibration lives: each point at its nominal tool position, seen \
         from above (base frame x, y) and from the side (reach from the base z axis, z), \
         coloured by its error after calibration (all point sets). Both views have equal scales \
         on their axes.",
    );
    if dense {
        let _ = write!(
            cap,
            " {} points, shown as cells coloured by the mean error of the points in them.",
            n
        );
    }
    let _ = write!(
        cap,
        " The colour scale runs from the 2nd to the 98th percentile of the {} ({} to {} mm); \
         values beyond it have the colour of its end.",
        if dense {
            "cells' mean errors"
        } else {
            "errors"
        },
        crate::numfmt::mm(lo),
        crate::numfmt::mm(top)
    );
    cap
}

/// A point in view `view`: 0 from above (x, y), 1 from the side (reach from the base z axis, z).
fn project(view: usize, p: &[f64; 3]) -> (f64, f64) {
    if view == 0 {
        (p[0], p[1])
    } else {
        (p[0].hypot(p[1]), p[2])
    }
}
