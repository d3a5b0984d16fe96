//! The "x, y, z" section: the distribution of each component of the error vector (dx, dy, dz in
//! the robot's base frame) before and after calibration. A bias or a spread along one axis
//! points at its cause (a scale error of the tracker, a tool length, gravity along z) where the
//! norm hides it.

use crate::bins::bin_series;
use crate::data::PointSet;
use crate::numfmt::signed;
use crate::page::{detailed_sets, Page};
use crate::plot::SERIES_COLORS;
use crate::svgplot::{range_of, Frame, Svg};
use robocal_core::Result;
use std::fmt::Write;

const W: u32 = 960;
const ROW_H: f64 = 210.0;

/// Writes the section, or nothing when no point set has error vectors.
pub(crate) fn section(page: &Page, h: &mut String) -> Result<bool> {
    let Some(set) = detailed_sets(page.data).into_iter().next() else {
        return Ok(false);
    };
    let stages: Vec<(usize, &str)> = [(0, "before"), (1, "after")]
        .into_iter()
        .filter(|&(s, _)| component(set, s, 0).iter().any(|v| v.is_finite()))
        .collect();
    if stages.is_empty() {
        return Ok(false);
    }
    let height = (ROW_H * stages.len() as f64).round() as u32;
    let mut svg = Svg::new(
        W,
        height,
        "Error components in the base frame",
        &format!(
            "Histograms of dx, dy and dz of the {} points, {}.",
            set.name.to_lowercase(),
            stages
                .iter()
                .map(|s| format!("{} calibration", s.1))
                .collect::<Vec<_>>()
                .join(" and ")
        ),
    );
    let pw = W as f64 / 3.0;
    for (row, &(stage, when)) in stages.iter().enumerate() {
        for axis in 0..3 {
            let values = component(set, stage, axis);
            panel(
                &mut svg,
                &values,
                stage,
                axis,
                when,
                (axis as f64 * pw, row as f64 * ROW_H, pw),
            );
        }
    }
    h.push_str("<section id=\"components\">\n<h2>Error components (x, y, z)</h2>\n");
    let mut cap = format!(
        "Each component of the displacement error E = P_act − P_ref of the {} points, in the \
         robot's base frame (mm): top row before calibration, bottom row after. Each panel has \
         its own bins (see Histogram for the rule); the title gives the mean (a bias) and the \
         standard deviation, in mm.",
        set.name.to_lowercase()
    );
    if stages.len() == 1 {
        let _ = write!(
            cap,
            " Only {} calibration is known for these points.",
            stages[0].1
        );
    }
    crate::markup::figure(h, &svg.finish(), &cap);
    h.push_str("</section>\n");
    Ok(true)
}

/// Component `axis` of the error vectors of `set` at `stage` (0 before, 1 after).
fn component(set: &PointSet, stage: usize, axis: usize) -> Vec<f64> {
    set.details
        .iter()
        .map(|d| {
            if stage == 0 {
                d.before_mm[axis]
            } else {
                d.after_mm[axis]
            }
        })
        .collect()
}

/// One histogram panel at (x, y) of width `w`.
fn panel(
    svg: &mut Svg,
    values: &[f64],
    stage: usize,
    axis: usize,
    when: &str,
    at: (f64, f64, f64),
) {
    let (x0, y0, w) = at;
    let name = ["dx", "dy", "dz"][axis];
    let Some(b) = bin_series(&[values]) else {
        return;
    };
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let n = finite.len() as f64;
    let mean = finite.iter().sum::<f64>() / n;
    let std = if n > 1.0 {
        (finite.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    let x_lo = b.bin_range(0).0;
    let x_hi = b.bin_range(b.bins() - 1).1;
    let ymax = b.max_count().max(1) as f64;
    let frame = Frame {
        left: x0 + 56.0,
        top: y0 + 30.0,
        width: w - 72.0,
        height: ROW_H - 30.0 - 46.0,
        x: (x_lo, x_hi),
        y: range_of([0.0, ymax * 1.08].into_iter(), true),
    };
    frame.axes(
        svg,
        &format!(
            "{name} {when}: mean {}, std {}",
            signed(mean, 3),
            crate::numfmt::mm(std)
        ),
        &format!("{name} (mm)"),
        "Points",
    );
    let c = SERIES_COLORS[stage];
    let fill = format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2);
    let mut s = String::new();
    for i in 0..b.bins() {
        let k = b.counts[0][i];
        if k == 0 {
            continue;
        }
        let (l, r) = b.bin_range(i);
        let (pl, pr) = (frame.px(l), frame.px(r));
        let top = frame.py(k as f64);
        let _ = write!(
            s,
            "<rect x=\"{:.1}\" y=\"{top:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{fill}\" fill-opacity=\"0.85\"/>",
            pl + 0.5,
            (pr - pl - 1.0).max(0.8),
            frame.py(0.0) - top
        );
    }
    // zero line
    if x_lo < 0.0 && x_hi > 0.0 {
        let _ = write!(
            s,
            "<path d=\"M{:.1} {:.1}V{:.1}\" stroke=\"#222\" stroke-dasharray=\"3 3\"/>",
            frame.px(0.0),
            frame.top,
            frame.top + frame.height
        );
    }
    s.push('\n');
    svg.raw(&s);
}
