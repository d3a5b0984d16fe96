//! What the figures share: fonts, colours, number formatting for axes, and turning plotters'
//! SVG into a self-contained, accessible figure.
//!
//! Plotting uses `plotters` with only its SVG backend and without its `ttf` feature: text is then
//! written as SVG `<text>` elements for the viewer to render, so neither building nor running
//! needs a font file or fontconfig (plotters only estimates text widths, which the layouts here do
//! not rely on).

use plotters::prelude::*;
use plotters::style::{FontFamily, FontStyle};
use robocal_core::Error;

/// System font stack used in figures (the HTML page's own stack overrides it when inlined).
pub const FONT_STACK: &str =
    "system-ui, -apple-system, 'Segoe UI', Roboto, 'Helvetica Neue', Arial, 'Liberation Sans', \
     'DejaVu Sans', sans-serif";

/// Colour-blind-safe colours (Okabe & Ito): before, after, then further series.
pub const SERIES_COLORS: [RGBColor; 4] = [
    RGBColor(0xD5, 0x5E, 0x00), // vermillion: before calibration
    RGBColor(0x00, 0x72, 0xB2), // blue: after calibration
    RGBColor(0x00, 0x9E, 0x73), // bluish green
    RGBColor(0xCC, 0x79, 0xA7), // reddish purple
];

/// Text colour.
pub const INK: RGBColor = RGBColor(0x22, 0x22, 0x22);
/// Secondary text colour.
pub const MUTED: RGBColor = RGBColor(0x55, 0x55, 0x55);
/// Axis and frame colour.
pub const AXIS: RGBColor = RGBColor(0x66, 0x66, 0x66);
/// Grid colour.
pub const GRID: RGBColor = RGBColor(0xE3, 0xE3, 0xE3);

/// Colour of series `i`.
pub fn series_color(i: usize) -> RGBColor {
    SERIES_COLORS[i % SERIES_COLORS.len()]
}

/// A text style of `px` CSS pixels (plotters writes `size / 1.24` as the SVG font size).
pub fn font(px: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::Name(FONT_STACK), px * 1.24, FontStyle::Normal).color(&INK)
}

/// A bold text style of `px` CSS pixels.
pub fn bold(px: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::Name(FONT_STACK), px * 1.24, FontStyle::Bold).color(&INK)
}

/// Estimated width in pixels of `text` at `px` pixels in a proportional sans-serif font (the
/// viewer's font is unknown; this errs on the wide side).
pub fn text_width(text: &str, px: f64) -> f64 {
    text.chars().count() as f64 * px * 0.58
}

/// Draws a legend swatch centred at a pixel position.
pub type Swatch<'a, DB> = Box<dyn Fn((i32, i32)) -> DynElement<'static, DB, (i32, i32)> + 'a>;

/// One legend entry: a swatch and its text.
pub struct LegendItem<'a, DB: DrawingBackend> {
    /// Draws the swatch centred at the given pixel.
    pub swatch: Swatch<'a, DB>,
    /// The entry's text.
    pub text: String,
}

/// Offsets of legend entries laid out left to right, wrapping into rows within `width` pixels,
/// and the number of rows.
pub fn legend_layout(texts: &[&str], width: i32, px: f64) -> (Vec<(i32, i32)>, usize) {
    let row_h = legend_row_height(px);
    let (mut cx, mut cy, mut rows) = (0, 0, usize::from(!texts.is_empty()));
    let mut out = Vec::with_capacity(texts.len());
    for t in texts {
        let w = 24 + text_width(t, px).round() as i32 + 22;
        if cx > 0 && cx + w > width {
            cx = 0;
            cy += row_h;
            rows += 1;
        }
        out.push((cx, cy));
        cx += w;
    }
    (out, rows)
}

/// Height of one legend row.
pub fn legend_row_height(px: f64) -> i32 {
    (px * 1.65).round() as i32
}

/// Draws legend entries (see [`legend_layout`]) with the first row's centre line at `(x, y)`.
pub fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    items: &[LegendItem<'_, DB>],
    (x, y): (i32, i32),
    width: i32,
    px: f64,
) -> Result<(), Error>
where
    DB::ErrorType: 'static,
{
    let e = draw_err("legend");
    let texts: Vec<&str> = items.iter().map(|i| i.text.as_str()).collect();
    let (pos, _) = legend_layout(&texts, width, px);
    for (it, (dx, dy)) in items.iter().zip(pos) {
        let (cx, cy) = (x + dx, y + dy);
        area.draw(&(it.swatch)((cx + 8, cy))).map_err(&e)?;
        area.draw(&Text::new(
            it.text.clone(),
            (cx + 22, cy),
            font(px).pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Left,
                plotters::style::text_anchor::VPos::Center,
            )),
        ))
        .map_err(&e)?;
    }
    Ok(())
}

/// Formats an axis value compactly: up to `decimals` places, trailing zeros removed.
pub fn axis_number(v: f64, decimals: usize) -> String {
    if v.abs() >= 1e6 {
        return format!("{v:.2e}");
    }
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// A drawing error as a library error naming the figure.
pub fn draw_err<E: std::fmt::Display>(figure: &str) -> impl Fn(E) -> Error + '_ {
    move |e| Error::invalid(format!("report figure `{figure}`"), e.to_string())
}

/// Adds an accessible title and description to plotters' SVG and marks it as an image.
pub fn finish_svg(svg: &str, title: &str, desc: &str) -> String {
    let mut out = String::with_capacity(svg.len() + title.len() + desc.len() + 200);
    match svg
        .find("<svg")
        .and_then(|s| svg[s..].find('>').map(|e| s + e))
    {
        Some(end) => {
            out.push_str(&svg[..end]);
            out.push_str(" role=\"img\">\n<title>");
            out.push_str(&crate::escape::xml(title));
            out.push_str("</title>\n<desc>");
            out.push_str(&crate::escape::xml(desc));
            out.push_str("</desc>\n");
            out.push_str(&svg[end + 1..]);
        }
        None => out.push_str(svg),
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_numbers() {
        assert_eq!(axis_number(1.50, 3), "1.5");
        assert_eq!(axis_number(2.0, 3), "2");
        assert_eq!(axis_number(-0.0001, 3), "0");
        assert_eq!(axis_number(1200.0, 0), "1200");
        assert_eq!(axis_number(3.0e7, 1), "3.00e7");
    }

    #[test]
    fn title_goes_inside_the_root() {
        let s = finish_svg(
            "<svg width=\"1\" xmlns=\"http://www.w3.org/2000/svg\">\n<rect/>\n</svg>\n",
            "A <b> & c",
            "d",
        );
        assert!(
            s.starts_with("<svg width=\"1\" xmlns=\"http://www.w3.org/2000/svg\" role=\"img\">")
        );
        assert!(s.contains("<title>A &lt;b&gt; &amp; c</title>"), "{s}");
        assert!(s.contains("<rect/>"));
    }
}
