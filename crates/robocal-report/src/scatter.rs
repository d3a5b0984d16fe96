//! Per-point errors across the workspace: error against reach, before calibration (left panel)
//! and after (right panel), one marker shape per point set.

use crate::bins::{decimals_for, nice_step, padded_range};
use crate::data::{PointSet, ReachKind};
use crate::histogram::clean_label;
use crate::plot::{
    axis_number, bold, draw_err, draw_legend, finish_svg, font, legend_layout, series_color,
    text_width, LegendItem, AXIS, GRID, INK, MUTED,
};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use robocal_core::Result;
use std::fmt::Write;

/// Width and height of the figure in CSS pixels.
pub const SIZE: (u32, u32) = (960, 460);

/// Which error of a point a panel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    Before,
    After,
}

/// What a panel drew: points shown, points above the clipped top, points skipped.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PanelCounts {
    /// Points drawn inside the plot.
    pub shown: usize,
    /// Points whose error lies above the panel's top, drawn as arrows on the top edge.
    pub clipped: usize,
    /// Points with a missing or non-finite reach or error.
    pub skipped: usize,
}

/// The rendered scatter plot and what each panel holds.
#[derive(Debug, Clone)]
pub struct ScatterFigure {
    /// A complete SVG document.
    pub svg: String,
    /// Before-calibration panel.
    pub before: PanelCounts,
    /// After-calibration panel.
    pub after: PanelCounts,
    /// Top of the before and after panels' error axes (mm) when clipped.
    pub clip_mm: [Option<f64>; 2],
    /// 1 when every point is drawn; k when a large set is thinned to every k-th point (and
    /// the largest errors), so that the page stays small.
    pub shown_every: usize,
    /// Points in all sets.
    pub total: usize,
}

/// Renders error against reach for `sets`.
pub fn scatter_svg(sets: &[PointSet], reach: ReachKind) -> Result<ScatterFigure> {
    let mut buf = String::new();
    let mut counts = [PanelCounts::default(); 2];
    let mut clip_mm = [None; 2];
    let total: usize = sets.iter().map(|s| s.points.len()).sum();
    let every = total.div_ceil(crate::svgplot::MARKER_LIMIT).max(1);
    {
        let root = SVGBackend::with_string(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err("scatter"))?;
        // One reach range for both panels so that they line up.
        let reaches: Vec<f64> = sets
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.reach_mm))
            .filter(|r| r.is_finite())
            .collect();
        let rmin = reaches.iter().copied().fold(f64::INFINITY, f64::min);
        let rmax = reaches.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let x_range = padded_range(rmin, rmax, false);
        // One legend for both panels, above them: marker shape = point set.
        let (band, body) = root.split_vertically(40);
        let items: Vec<LegendItem<_>> = sets
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.points.is_empty())
            .map(|(i, s)| LegendItem {
                swatch: Box::new(move |at| marker(i, at, INK)),
                text: format!("{} points (n = {})", clean_label(&s.name), s.points.len()),
            })
            .collect();
        let texts: Vec<&str> = items.iter().map(|i| i.text.as_str()).collect();
        let (_, rows) = legend_layout(&texts, SIZE.0 as i32 - 40, 13.0);
        let width = texts
            .iter()
            .map(|t| 24 + text_width(t, 13.0).round() as i32 + 22)
            .sum::<i32>();
        let x0 = if rows == 1 {
            (SIZE.0 as i32 - width) / 2
        } else {
            20
        };
        draw_legend(&band, &items, (x0.max(20), 22), SIZE.0 as i32 - 40, 13.0)?;
        let panels = body.split_evenly((1, 2));
        for (i, (area, stage)) in panels.iter().zip([Stage::Before, Stage::After]).enumerate() {
            let (c, clip) = draw_panel(area, sets, stage, x_range, reach, every)?;
            counts[i] = c;
            clip_mm[i] = clip;
        }
        root.present().map_err(draw_err("scatter"))?;
    }
    let desc = format!(
        "Error against reach. Before calibration: {} points; after calibration: {} points.",
        counts[0].shown + counts[0].clipped,
        counts[1].shown + counts[1].clipped
    );
    Ok(ScatterFigure {
        svg: finish_svg(&buf, "Displacement error across the workspace", &desc),
        before: counts[0],
        after: counts[1],
        clip_mm,
        shown_every: every,
        total,
    })
}

/// The (reach, error) pairs of one set at one stage, and how many were skipped.
fn pairs(set: &PointSet, stage: Stage) -> (Vec<(f64, f64)>, usize) {
    let mut v = Vec::with_capacity(set.points.len());
    let mut skipped = 0;
    for p in &set.points {
        let e = match stage {
            Stage::Before => p.before_mm,
            Stage::After => p.after_mm,
        };
        if p.reach_mm.is_finite() && e.is_finite() {
            v.push((p.reach_mm, e));
        } else {
            skipped += 1;
        }
    }
    (v, skipped)
}

/// Every `every`-th point of `pts` and the 20 largest errors (all points when `every` is 1).
fn thin(pts: Vec<(f64, f64)>, every: usize) -> Vec<(f64, f64)> {
    if every <= 1 {
        return pts;
    }
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&a, &b| pts[b].1.total_cmp(&pts[a].1));
    let mut keep = vec![false; pts.len()];
    for &i in order.iter().take(20) {
        keep[i] = true;
    }
    for i in (0..pts.len()).step_by(every) {
        keep[i] = true;
    }
    pts.into_iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(p))
        .collect()
}

/// Marker shapes by set index: filled circle, open triangle, cross, open circle.
fn marker<DB: DrawingBackend, C: Clone + 'static>(
    i: usize,
    at: C,
    color: RGBColor,
) -> DynElement<'static, DB, C>
where
    DB::ErrorType: 'static,
{
    match i % 4 {
        0 => Circle::new(at, 4, color.mix(0.75).filled()).into_dyn(),
        1 => TriangleMarker::new(at, 5, color.stroke_width(2)).into_dyn(),
        2 => Cross::new(at, 4, color.stroke_width(2)).into_dyn(),
        _ => Circle::new(at, 4, color.stroke_width(2)).into_dyn(),
    }
}

/// A set shown in a panel: its index, the set, its (reach, error) pairs.
type ShownSet<'a> = (usize, &'a PointSet, Vec<(f64, f64)>);

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    sets: &[PointSet],
    stage: Stage,
    x_range: (f64, f64),
    reach: ReachKind,
    every: usize,
) -> Result<(PanelCounts, Option<f64>)>
where
    DB::ErrorType: 'static,
{
    let e = draw_err("scatter");
    // A set without any value at this stage (a verification set has no "before") is simply not
    // in the panel; within a shown set, points without a value are counted as skipped.
    let mut skipped = 0;
    let data: Vec<ShownSet> = sets
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let (v, k) = pairs(s, stage);
            if v.is_empty() {
                return None;
            }
            skipped += k;
            Some((i, s, v))
        })
        .collect();
    let errors: Vec<f64> = data
        .iter()
        .flat_map(|(_, _, v)| v.iter().map(|p| p.1))
        .collect();
    let emax = errors.iter().copied().fold(0.0f64, f64::max);
    // A few gross errors would flatten the rest: clip the axis as the histogram does.
    let clip = crate::bins::outlier_cap(&errors, 0.0);
    let top = clip.unwrap_or(emax);
    let y_hi = if top > 0.0 { top * 1.12 } else { 1.0 };
    let (title, color) = match stage {
        Stage::Before => ("Before calibration", series_color(0)),
        Stage::After => ("After calibration", series_color(1)),
    };
    let mut chart = ChartBuilder::on(area)
        .caption(title, bold(15.0).color(&color))
        .margin_top(10)
        .margin_left(10)
        .margin_right(22)
        .margin_bottom(8)
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(x_range.0..x_range.1, 0f64..y_hi)
        .map_err(&e)?;
    let x_dec = decimals_for(nice_step((x_range.1 - x_range.0) / 6.0));
    let y_dec = decimals_for(nice_step(y_hi / 8.0));
    let x_desc = reach.axis_label();
    chart
        .configure_mesh()
        .x_labels(7)
        .y_labels(8)
        .x_label_formatter(&|v| axis_number(*v, x_dec + 1))
        .y_label_formatter(&|v| axis_number(*v, y_dec + 1))
        .x_desc(x_desc)
        .y_desc("Displacement error (mm)")
        .axis_desc_style(font(13.5))
        .label_style(font(12.0))
        .axis_style(AXIS)
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT)
        .draw()
        .map_err(&e)?;

    let mut counts = PanelCounts {
        skipped,
        ..PanelCounts::default()
    };
    if data.is_empty() {
        let mid = ((x_range.0 + x_range.1) / 2.0, y_hi / 2.0);
        chart
            .draw_series(std::iter::once(Text::new(
                "No values",
                mid,
                font(14.0)
                    .color(&MUTED)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            )))
            .map_err(&e)?;
        return Ok((counts, clip));
    }
    for (i, _set, pts) in &data {
        let inside: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.1 <= top).collect();
        let above: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.1 > top).collect();
        counts.shown += inside.len();
        counts.clipped += above.len();
        let inside = thin(inside, every);
        let above = thin(above, every);
        let i = *i;
        chart
            .draw_series(
                inside
                    .iter()
                    .map(|&p| marker::<DB, (f64, f64)>(i, p, color)),
            )
            .map_err(&e)?;
        chart
            .draw_series(above.iter().map(|&(x, _)| {
                TriangleMarker::new((x, y_hi * 0.985), 6, RGBColor(0x33, 0x33, 0x33).filled())
            }))
            .map_err(&e)?;
    }
    if let Some(t) = clip {
        if counts.clipped > 0 {
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("▲ {} above {} mm", counts.clipped, axis_number(t, 3)),
                    (x_range.0, y_hi),
                    font(11.5)
                        .color(&MUTED)
                        .pos(Pos::new(HPos::Left, VPos::Top)),
                )))
                .map_err(&e)?;
        }
    }
    Ok((counts, clip))
}

/// The error-against-reach section, or nothing when no point has a reach.
pub(crate) fn section(page: &crate::page::Page, h: &mut String) -> Result<bool> {
    let data = page.data;
    let has_points = data
        .point_sets
        .iter()
        .any(|s| s.points.iter().any(|p| p.reach_mm.is_finite()));
    if !has_points {
        return Ok(false);
    }
    let fig = &scatter_svg(&data.point_sets, data.reach)?;
    h.push_str("<section id=\"workspace\">\n<h2>Error against reach</h2>\n");
    let mut cap = format!(
        "Displacement error of each point against its reach ({}). Left: nominal model with \
         the fitted measurement frame; right: calibrated model (for a verification set: as \
         measured after compensation). The panels have their own error scales.",
        data.reach.description()
    );
    for (name, c, clip) in [
        ("before", fig.before, fig.clip_mm[0]),
        ("after", fig.after, fig.clip_mm[1]),
    ] {
        if c.skipped > 0 {
            let _ = write!(
                cap,
                " {} point{} without a finite reach or error {name} calibration not shown.",
                c.skipped,
                if c.skipped == 1 { "" } else { "s" }
            );
        }
        if let (Some(t), true) = (clip, c.clipped > 0) {
            let _ = write!(
                cap,
                " {} point{} above {} mm {name} calibration drawn as ▲ at the top edge.",
                c.clipped,
                if c.clipped == 1 { "" } else { "s" },
                crate::numfmt::fixed(t, 3)
            );
        }
    }
    if fig.shown_every > 1 {
        let _ = write!(
            cap,
            " {} points: every {}th point of each set is drawn, and the 20 largest errors of \
             each panel (the statistics use them all).",
            fig.total, fig.shown_every
        );
    }
    crate::markup::figure(h, &fig.svg, &cap);
    h.push_str("</section>\n");
    Ok(true)
}
