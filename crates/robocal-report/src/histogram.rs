//! The error histogram before and after calibration (the paper's Fig. 2): grouped bars over
//! common bin edges, counts above the bars, dashed lines at each series' mean.

use crate::bins::{bin_series, decimals_for, nice_step, Binning, Scale};
use crate::data::HistogramSeries;
use crate::plot::{
    axis_number, bold, draw_err, draw_legend, finish_svg, font, legend_layout, legend_row_height,
    series_color, LegendItem, AXIS, GRID, MUTED,
};
use plotters::coord::types::{RangedCoordf64, RangedCoordu32};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use robocal_core::Result;

/// Width and height of the histogram in CSS pixels.
pub const SIZE: (u32, u32) = (960, 470);

/// The rendered histogram and the binning behind it.
#[derive(Debug, Clone)]
pub struct HistogramFigure {
    /// A complete SVG document.
    pub svg: String,
    /// The bins, or `None` when there was no finite value to show.
    pub binning: Option<Binning>,
}

impl HistogramFigure {
    /// Sentences for the figure's caption: bin width, skipped values, overflow bin.
    pub fn notes(&self, series: &[HistogramSeries]) -> Vec<String> {
        let mut notes = Vec::new();
        let Some(b) = &self.binning else {
            return notes;
        };
        let d = decimals_for(b.width()).max(1);
        notes.push(format!(
            "{}; all series share the same bin edges.",
            b.describe()
        ));
        if b.overflow {
            let beyond: usize = b.counts.iter().map(|c| c[c.len() - 1]).sum();
            notes.push(format!(
                "{beyond} value{} above {} mm {} gathered in the last bin (marked “>”).",
                plural(beyond),
                axis_number(b.cap(), d + 1),
                if beyond == 1 { "is" } else { "are" }
            ));
        }
        let under: usize = b.under.iter().sum();
        if under > 0 {
            notes.push(format!(
                "{under} value{} below {} mm (points the fit passes through almost exactly) {} \
                 counted in the first bin.",
                plural(under),
                axis_number(
                    b.edges[0],
                    (1.0 - b.edges[0].log10().floor()).max(1.0) as usize
                ),
                if under == 1 { "is" } else { "are" }
            ));
        }
        for (s, k) in series.iter().zip(&b.skipped) {
            if *k > 0 {
                notes.push(format!(
                    "{}: {k} missing or non-finite value{} not shown.",
                    s.label,
                    plural(*k)
                ));
            }
        }
        notes
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// Replaces control characters (not allowed in SVG text) and line breaks by spaces.
pub(crate) fn clean_label(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// Renders the histogram of `series` (usually "before" and "after") with the title `title`.
pub fn histogram_svg(series: &[HistogramSeries], title: &str) -> Result<HistogramFigure> {
    let values: Vec<&[f64]> = series.iter().map(|s| s.values_mm.as_slice()).collect();
    let binning = bin_series(&values);
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err("histogram"))?;
        let title = clean_label(title);
        match &binning {
            Some(b) => draw_bars(&root, series, b, &title)?,
            None => draw_empty(&root, &title)?,
        }
        root.present().map_err(draw_err("histogram"))?;
    }
    let desc = match &binning {
        Some(b) => series
            .iter()
            .zip(&b.n)
            .zip(&b.mean)
            .map(|((s, n), m)| {
                format!(
                    "{}: {n} points, mean {} mm",
                    clean_label(&s.label),
                    crate::numfmt::mm(*m)
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
        None => "No error values to show.".into(),
    };
    Ok(HistogramFigure {
        svg: finish_svg(&buf, &title_or_default(title), &desc),
        binning,
    })
}

fn title_or_default(title: &str) -> String {
    if title.trim().is_empty() {
        "Displacement error histogram".into()
    } else {
        clean_label(title)
    }
}

fn draw_empty<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let (w, h) = SIZE;
    root.draw(&Text::new(
        title_or_default(title),
        (w as i32 / 2, 14),
        bold(17.0).pos(Pos::new(HPos::Center, VPos::Top)),
    ))
    .map_err(draw_err("histogram"))?;
    root.draw(&Text::new(
        "No error values to show",
        (w as i32 / 2, h as i32 / 2),
        font(15.0)
            .color(&MUTED)
            .pos(Pos::new(HPos::Center, VPos::Center)),
    ))
    .map_err(draw_err("histogram"))?;
    Ok(())
}

/// Legend text of series `s`.
fn legend_text(ser: &HistogramSeries, b: &Binning, s: usize) -> String {
    let mut label = format!("{}  (n = {}", clean_label(&ser.label), b.n[s]);
    if b.n[s] > 0 {
        label.push_str(&format!(", mean {} mm", crate::numfmt::mm(b.mean[s])));
    }
    label.push(')');
    label
}

fn draw_bars<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    series: &[HistogramSeries],
    b: &Binning,
    title: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = draw_err("histogram");
    let plot_area = draw_title_and_legend(root, series, b, title)?;
    let x_lo = b.bin_range(0).0;
    let x_hi = b.bin_range(b.bins() - 1).1;
    let max_count = b.max_count().max(1) as u32;
    // Head room for the count labels and the mean labels.
    let y_hi = max_count + (max_count as f64 * 0.22).ceil() as u32 + 2;
    let mut chart = ChartBuilder::on(&plot_area)
        .margin_top(4)
        .margin_left(14)
        .margin_right(28)
        .margin_bottom(10)
        .x_label_area_size(52)
        .y_label_area_size(64)
        .build_cartesian_2d(x_lo..x_hi, 0u32..y_hi)
        .map_err(&e)?;
    let bars = Bars {
        series,
        b,
        x_lo,
        x_hi,
        y_hi,
    };
    draw_axes(&mut chart, &bars)?;
    draw_series_bars(&mut chart, &bars)?;
    draw_mean_labels(&mut chart, &bars)?;
    if b.overflow {
        let (l, r) = b.bin_range(b.bins() - 1);
        chart
            .draw_series(std::iter::once(Text::new(
                format!("> {}", crate::numfmt::magnitude(b.cap())),
                ((l + r) / 2.0, 0u32),
                font(12.0)
                    .color(&MUTED)
                    .pos(Pos::new(HPos::Center, VPos::Top)),
            )))
            .map_err(&e)?;
    }
    Ok(())
}

/// The chart of [`draw_bars`]: mm on x, counts on y.
type BarChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordu32>>;

/// What the parts of [`draw_bars`] draw: the series, their bins and the chart's ranges.
#[derive(Clone, Copy)]
struct Bars<'a> {
    series: &'a [HistogramSeries],
    b: &'a Binning,
    x_lo: f64,
    x_hi: f64,
    y_hi: u32,
}

/// Draws the title and the legend above the plot, so that neither hides a bar; returns the area
/// below them, for the plot.
fn draw_title_and_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    series: &[HistogramSeries],
    b: &Binning,
    title: &str,
) -> Result<DrawingArea<DB, plotters::coord::Shift>>
where
    DB::ErrorType: 'static,
{
    let e = draw_err("histogram");
    let legend_px = 13.0;
    let texts: Vec<String> = series
        .iter()
        .enumerate()
        .map(|(s, ser)| legend_text(ser, b, s))
        .collect();
    let text_refs: Vec<&str> = texts.iter().map(String::as_str).collect();
    let legend_w = SIZE.0 as i32 - 2 * 78;
    let (_, rows) = legend_layout(&text_refs, legend_w, legend_px);
    let band = 50 + rows as i32 * legend_row_height(legend_px);
    let (top, plot_area) = root.split_vertically(band);
    top.draw(&Text::new(
        title_or_default(title),
        (SIZE.0 as i32 / 2, 14),
        bold(17.0).pos(Pos::new(HPos::Center, VPos::Top)),
    ))
    .map_err(&e)?;
    let items: Vec<LegendItem<DB>> = texts
        .iter()
        .enumerate()
        .map(|(s, t)| {
            let color = series_color(s);
            LegendItem {
                swatch: Box::new(move |(x, y)| {
                    Rectangle::new([(x - 8, y - 6), (x + 8, y + 6)], color.mix(0.85).filled())
                        .into_dyn()
                }),
                text: t.clone(),
            }
        })
        .collect();
    draw_legend(
        &top,
        &items,
        (78, 50 + legend_row_height(legend_px) / 2),
        legend_w,
        legend_px,
    )?;
    Ok(plot_area)
}

/// The mesh, the axis labels and, for log bins, the 1-2-5 ticks.
fn draw_axes<DB: DrawingBackend>(chart: &mut BarChart<'_, DB>, bars: &Bars) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let Bars {
        b,
        x_lo,
        x_hi,
        y_hi,
        ..
    } = *bars;
    let e = draw_err("histogram");
    let log = b.scale == Scale::Log;
    let tick_step = nice_step((x_hi - x_lo) / 12.0);
    let x_dec = decimals_for(tick_step);
    let cap = b.cap();
    let cap_axis = b.axis(cap);
    let overflow = b.overflow;
    let x_fmt = move |v: &f64| {
        // The overflow bin is labelled "> cap" below it; no numbers at or beyond the cap.
        if overflow && *v > cap_axis - 1e-9 * tick_step {
            String::new()
        } else {
            axis_number(*v, x_dec + 1)
        }
    };
    chart
        .configure_mesh()
        // Log bins: the mesh draws no x labels; the 1-2-5 ticks are drawn below.
        .x_labels(if log { 0 } else { 14 })
        .y_labels(8)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&|v: &u32| v.to_string())
        .x_desc(if log {
            "Displacement error ‖Eᵢ‖ (mm, log scale)"
        } else {
            "Displacement error ‖Eᵢ‖ (mm)"
        })
        .y_desc("Number of points")
        .axis_desc_style(font(14.0))
        .label_style(font(12.5))
        .axis_style(AXIS)
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT)
        .disable_x_mesh()
        .draw()
        .map_err(&e)?;

    if log {
        log_ticks(chart, b, x_lo, b.axis(b.cap()), y_hi)?;
    }
    Ok(())
}

/// The mean lines, then each series' bars side by side in their bins, with their counts above
/// them when the bars are wide enough.
fn draw_series_bars<DB: DrawingBackend>(chart: &mut BarChart<'_, DB>, bars: &Bars) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let Bars {
        series,
        b,
        x_lo,
        x_hi,
        y_hi,
    } = *bars;
    let e = draw_err("histogram");
    let (gap, slot) = bar_slots(series);
    let (plot_w, _) = chart.plotting_area().dim_in_pixel();
    let bar_px = plot_w as f64 * b.width() * slot / (x_hi - x_lo);
    let show_counts = bar_px >= 11.0;
    // Mean lines first, so that bars and counts stay on top of them.
    for s in (0..series.len()).filter(|&s| shows_mean(b, s, x_hi)) {
        let m = b.axis(b.mean[s]);
        chart
            .draw_series(DashedLineSeries::new(
                [(m, 0u32), (m, y_hi)],
                6,
                4,
                series_color(s).stroke_width(2),
            ))
            .map_err(&e)?;
    }
    for s in 0..series.len() {
        let color = series_color(s);
        let counts = &b.counts[s];
        let bars = (0..b.bins()).filter(|&i| counts[i] > 0).map(|i| {
            let (l, r) = b.bin_range(i);
            let w = r - l;
            let x0 = l + w * (gap + s as f64 * slot);
            Rectangle::new(
                [(x0, 0u32), (x0 + w * slot, counts[i] as u32)],
                color.mix(0.85).filled(),
            )
        });
        chart.draw_series(bars).map_err(&e)?;
        if show_counts {
            let texts = (0..b.bins()).filter(|&i| counts[i] > 0).map(|i| {
                let (l, r) = b.bin_range(i);
                let w = r - l;
                let xc = l + w * (gap + (s as f64 + 0.5) * slot);
                let text = counts[i].to_string();
                // A white box behind the count keeps it readable where a mean line passes.
                let hw = (text.len() as f64 * 3.6 + 2.0).round() as i32;
                EmptyElement::at((xc, counts[i] as u32))
                    + Rectangle::new([(-hw, -15), (hw, -2)], WHITE.filled())
                    + Text::new(
                        text,
                        (0, -2),
                        font(11.0)
                            .color(&MUTED)
                            .pos(Pos::new(HPos::Center, VPos::Bottom)),
                    )
            });
            chart.draw_series(texts).map_err(&e)?;
        }
    }
    Ok(())
}

/// The gap at each side of a bin and each series' share of it.
fn bar_slots(series: &[HistogramSeries]) -> (f64, f64) {
    let k = series.len().max(1);
    let gap = 0.08;
    (gap, (1.0 - 2.0 * gap) / k as f64)
}

/// Whether series `s`'s mean is drawn: it has points and its mean is on the axis.
fn shows_mean(b: &Binning, s: usize, x_hi: f64) -> bool {
    b.n[s] > 0 && b.mean[s].is_finite() && b.axis(b.mean[s]) <= x_hi
}

/// The mean labels at the top, staggered so that close means stay readable.
fn draw_mean_labels<DB: DrawingBackend>(chart: &mut BarChart<'_, DB>, bars: &Bars) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let Bars {
        series,
        b,
        x_lo,
        x_hi,
        y_hi,
    } = *bars;
    let e = draw_err("histogram");
    let (plot_w, plot_h) = chart.plotting_area().dim_in_pixel();
    let px_per_count = plot_h as f64 / y_hi as f64;
    for (row, s) in (0..series.len())
        .filter(|&s| shows_mean(b, s, x_hi))
        .enumerate()
    {
        let m = b.axis(b.mean[s]);
        let y = y_hi.saturating_sub(((4.0 + 16.0 * row as f64) / px_per_count).round() as u32);
        let near_right = (m - x_lo) / (x_hi - x_lo) > 0.85;
        let px = 5.0 * (x_hi - x_lo) / plot_w as f64;
        let (anchor, dx) = if near_right {
            (HPos::Right, -px)
        } else {
            (HPos::Left, px)
        };
        chart
            .draw_series(std::iter::once(Text::new(
                format!("mean {}", crate::numfmt::mm(b.mean[s])),
                (m + dx, y),
                font(12.0)
                    .color(&series_color(s))
                    .pos(Pos::new(anchor, VPos::Top)),
            )))
            .map_err(&e)?;
    }
    Ok(())
}

/// Tick marks and labels of a log axis at 1, 2 and 5 times the powers of ten in `lo..hi`
/// (axis units: log10 mm), with a vertical grid line at each power of ten.
fn log_ticks<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordu32>>,
    b: &Binning,
    lo: f64,
    hi: f64,
    y_hi: u32,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = draw_err("histogram");
    let _ = b;
    let mut ticks = Vec::new();
    let first = lo.floor() as i32;
    let last = hi.ceil() as i32;
    for k in first..=last {
        for m in [1.0, 2.0, 5.0] {
            let v = m * 10f64.powi(k);
            let a = v.log10();
            if a >= lo - 1e-9 && a <= hi + 1e-9 {
                ticks.push((a, v, m == 1.0));
            }
        }
    }
    for &(a, _, major) in &ticks {
        if major {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(a, 0u32), (a, y_hi)],
                    GRID,
                )))
                .map_err(&e)?;
        }
    }
    let (plot_w, _) = chart.plotting_area().dim_in_pixel();
    let span = chart.x_range().end - chart.x_range().start;
    let mut last_px = f64::NEG_INFINITY;
    for (a, v, _) in ticks {
        // Skip a label that would touch the previous one.
        let px = (a - chart.x_range().start) / span * plot_w as f64;
        if px - last_px < 34.0 {
            continue;
        }
        last_px = px;
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((a, 0u32))
                    + PathElement::new(vec![(0, 0), (0, 5)], AXIS)
                    + Text::new(
                        tick_label(v),
                        (0, 8),
                        font(12.5).pos(Pos::new(HPos::Center, VPos::Top)),
                    ),
            ))
            .map_err(&e)?;
    }
    Ok(())
}

/// A 1-2-5 tick value with just the decimals it needs (0.01, 0.2, 5, 100).
fn tick_label(v: f64) -> String {
    let k = v.log10().floor() as i32;
    if k >= 0 {
        format!("{v:.0}")
    } else {
        format!("{v:.*}", (-k) as usize)
    }
}
