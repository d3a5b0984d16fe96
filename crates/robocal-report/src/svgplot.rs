//! A small SVG writer for the panel grids (per-axis, per-joint and workspace views): frames with
//! 1-2-5 ticks, markers, cells and a colour scale, written directly as SVG elements.
//!
//! Written here rather than with plotters because these figures are many small panels with a
//! shared colour scale and binned cells for large sets, where the size of every element in the
//! page counts (coordinates with one decimal, one `<path>` per group of markers): a 200,000-point
//! report must stay a few megabytes.

use crate::bins::{decimals_for, nice_step, padded_range};
use crate::escape::xml as esc;
use crate::plot::{axis_number, FONT_STACK};
use std::fmt::Write;

/// Most markers one panel draws one by one; above it the panel shows binned cells.
pub const MARKER_LIMIT: usize = 3000;

/// An SVG document being written.
pub struct Svg {
    buf: String,
}

impl Svg {
    /// A document of `w` x `h` CSS pixels with an accessible title and description.
    pub fn new(w: u32, h: u32, title: &str, desc: &str) -> Svg {
        let mut buf = String::with_capacity(16 * 1024);
        let _ = write!(
            buf,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" role=\"img\" font-family=\"{FONT_STACK}\">\n<title>{}</title>\n\
             <desc>{}</desc>\n<rect width=\"{w}\" height=\"{h}\" fill=\"#fff\"/>\n",
            esc(title),
            esc(desc)
        );
        Svg { buf }
    }

    /// Text at (x, y); `anchor` is `start`, `middle` or `end`.
    pub fn text(&mut self, x: f64, y: f64, s: &str, px: f64, anchor: &str, style: &str) {
        let _ = writeln!(
            self.buf,
            "<text x=\"{x:.1}\" y=\"{y:.1}\" font-size=\"{px}\" text-anchor=\"{anchor}\" {style}>{}</text>",
            esc(s)
        );
    }

    /// A raw element (already well-formed).
    pub fn raw(&mut self, s: &str) {
        self.buf.push_str(s);
    }

    /// The document.
    pub fn finish(mut self) -> String {
        self.buf.push_str("</svg>\n");
        self.buf
    }
}

/// A plot frame: a pixel box and the data ranges it shows.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// Left edge (px).
    pub left: f64,
    /// Top edge (px).
    pub top: f64,
    /// Width (px).
    pub width: f64,
    /// Height (px).
    pub height: f64,
    /// Data range along x.
    pub x: (f64, f64),
    /// Data range along y.
    pub y: (f64, f64),
}

impl Frame {
    /// Pixel x of a data value.
    pub fn px(&self, x: f64) -> f64 {
        self.left + (x - self.x.0) / (self.x.1 - self.x.0) * self.width
    }

    /// Pixel y of a data value.
    pub fn py(&self, y: f64) -> f64 {
        self.top + self.height - (y - self.y.0) / (self.y.1 - self.y.0) * self.height
    }

    /// Whether (x, y) lies inside the ranges.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x.0 && x <= self.x.1 && y >= self.y.0 && y <= self.y.1
    }

    /// Makes both axes show the same mm per pixel (a map), widening the narrower range.
    pub fn equal_aspect(mut self) -> Frame {
        let sx = (self.x.1 - self.x.0) / self.width;
        let sy = (self.y.1 - self.y.0) / self.height;
        if sx > sy {
            let c = 0.5 * (self.y.0 + self.y.1);
            let half = 0.5 * sx * self.height;
            self.y = (c - half, c + half);
        } else {
            let c = 0.5 * (self.x.0 + self.x.1);
            let half = 0.5 * sy * self.width;
            self.x = (c - half, c + half);
        }
        self
    }

    /// Draws the frame, grid lines, ticks and labels, a title above and the axis labels.
    pub fn axes(&self, svg: &mut Svg, title: &str, xlabel: &str, ylabel: &str) {
        let (l, t, w, h) = (self.left, self.top, self.width, self.height);
        let mut s = String::new();
        // y ticks
        let ys = nice_step((self.y.1 - self.y.0) / 5.0);
        let yd = decimals_for(ys);
        let mut v = (self.y.0 / ys).ceil() * ys;
        while v <= self.y.1 + 1e-9 * ys {
            let y = self.py(v);
            let _ = writeln!(
                s,
                "<path d=\"M{l:.1} {y:.1}h{w:.1}\" stroke=\"#e3e3e3\"/>\
                 <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"end\" fill=\"#444\">{}</text>",
                l - 4.0,
                y + 3.5,
                axis_number(v, yd + 1)
            );
            v += ys;
        }
        // x ticks
        let xs = nice_step((self.x.1 - self.x.0) / (w / 70.0).max(2.0));
        let xd = decimals_for(xs);
        let mut v = (self.x.0 / xs).ceil() * xs;
        while v <= self.x.1 + 1e-9 * xs {
            let x = self.px(v);
            let _ = writeln!(
                s,
                "<path d=\"M{x:.1} {:.1}v4\" stroke=\"#666\"/>\
                 <text x=\"{x:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\" fill=\"#444\">{}</text>",
                t + h,
                t + h + 15.0,
                axis_number(v, xd + 1)
            );
            v += xs;
        }
        let _ = writeln!(
            s,
            "<rect x=\"{l:.1}\" y=\"{t:.1}\" width=\"{w:.1}\" height=\"{h:.1}\" fill=\"none\" stroke=\"#666\"/>"
        );
        svg.raw(&s);
        svg.text(
            l + w / 2.0,
            t - 8.0,
            title,
            13.0,
            "middle",
            "font-weight=\"600\"",
        );
        svg.text(
            l + w / 2.0,
            t + h + 31.0,
            xlabel,
            11.5,
            "middle",
            "fill=\"#333\"",
        );
        let (cx, cy) = (l - 36.0, t + h / 2.0);
        let _ = writeln!(
            svg.buf,
            "<text x=\"{cx:.1}\" y=\"{cy:.1}\" font-size=\"11.5\" text-anchor=\"middle\" fill=\"#333\" \
             transform=\"rotate(-90 {cx:.1} {cy:.1})\">{}</text>",
            esc(ylabel)
        );
    }
}

/// A range `lo..hi` for the finite values of `v`, padded (from 0 when `from_zero`).
pub fn range_of(v: impl Iterator<Item = f64>, from_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    padded_range(lo, hi, from_zero)
}

/// Small circles of one colour at the pixel positions `pts`, as one `<path>` (a zero-length
/// line with round caps per point: far smaller than one `<circle>` each).
pub fn markers(svg: &mut Svg, pts: &[(f64, f64)], color: &str, size: f64, opacity: f64) {
    if pts.is_empty() {
        return;
    }
    let mut d = String::with_capacity(pts.len() * 14);
    for (x, y) in pts {
        let _ = write!(d, "M{x:.1} {y:.1}h0");
    }
    let _ = writeln!(
        svg.buf,
        "<path d=\"{d}\" stroke=\"{color}\" stroke-width=\"{size}\" stroke-linecap=\"round\" \
         stroke-opacity=\"{opacity}\" fill=\"none\"/>"
    );
}

/// A colour of the perceptually uniform "viridis" scale at `t` in 0..1 (dark blue to yellow),
/// linearly between five of its stops.
pub fn viridis(t: f64) -> String {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = t * (STOPS.len() - 1) as f64;
    let i = (f.floor() as usize).min(STOPS.len() - 2);
    let u = f - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let c = |x: f64, y: f64| (x + u * (y - x)).round() as u8;
    format!("#{:02x}{:02x}{:02x}", c(a.0, b.0), c(a.1, b.1), c(a.2, b.2))
}

/// A horizontal colour bar from `lo` to `hi` (mm) at (x, y), `w` wide, labelled.
pub fn colorbar(svg: &mut Svg, x: f64, y: f64, w: f64, lo: f64, hi: f64, label: &str) {
    let steps = 40;
    let mut s = String::new();
    for i in 0..steps {
        let _ = write!(
            s,
            "<rect x=\"{:.1}\" y=\"{y:.1}\" width=\"{:.2}\" height=\"10\" fill=\"{}\"/>",
            x + w * i as f64 / steps as f64,
            w / steps as f64 + 0.3,
            viridis((i as f64 + 0.5) / steps as f64)
        );
    }
    s.push('\n');
    svg.raw(&s);
    let d = decimals_for(nice_step((hi - lo) / 4.0)) + 1;
    svg.text(
        x,
        y + 23.0,
        &axis_number(lo, d),
        11.0,
        "start",
        "fill=\"#444\"",
    );
    svg.text(
        x + w,
        y + 23.0,
        &axis_number(hi, d),
        11.0,
        "end",
        "fill=\"#444\"",
    );
    svg.text(
        x + w / 2.0,
        y + 23.0,
        label,
        11.0,
        "middle",
        "fill=\"#333\"",
    );
}

/// Counts of points in a grid of `nx` x `ny` cells over a frame, with a value summed per cell.
pub struct Grid {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Points per cell (row-major, y from the bottom).
    pub count: Vec<usize>,
    /// Sum of the values per cell.
    pub sum: Vec<f64>,
}

impl Grid {
    /// Bins `(x, y, value)` over `frame`; points outside the frame are left out.
    pub fn new(
        frame: &Frame,
        nx: usize,
        ny: usize,
        pts: impl Iterator<Item = (f64, f64, f64)>,
    ) -> Grid {
        let mut g = Grid {
            nx,
            ny,
            count: vec![0; nx * ny],
            sum: vec![0.0; nx * ny],
        };
        for (x, y, v) in pts {
            if !frame.contains(x, y) || !v.is_finite() {
                continue;
            }
            let i = (((x - frame.x.0) / (frame.x.1 - frame.x.0)) * nx as f64).floor() as usize;
            let j = (((y - frame.y.0) / (frame.y.1 - frame.y.0)) * ny as f64).floor() as usize;
            let k = j.min(ny - 1) * nx + i.min(nx - 1);
            g.count[k] += 1;
            g.sum[k] += v;
        }
        g
    }

    /// Draws the non-empty cells, coloured by `color(count, mean value)`.
    pub fn draw(&self, svg: &mut Svg, frame: &Frame, color: impl Fn(usize, f64) -> String) {
        let cw = frame.width / self.nx as f64;
        let ch = frame.height / self.ny as f64;
        let mut s = String::new();
        for j in 0..self.ny {
            for i in 0..self.nx {
                let k = j * self.nx + i;
                if self.count[k] == 0 {
                    continue;
                }
                let _ = write!(
                    s,
                    "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{}\"/>",
                    frame.left + i as f64 * cw,
                    frame.top + frame.height - (j + 1) as f64 * ch,
                    cw + 0.4,
                    ch + 0.4,
                    color(self.count[k], self.sum[k] / self.count[k] as f64)
                );
            }
        }
        s.push('\n');
        svg.raw(&s);
    }

    /// The largest count of a cell.
    pub fn max_count(&self) -> usize {
        self.count.iter().copied().max().unwrap_or(0)
    }
}

/// A shade of the "after" blue for a cell holding `count` of at most `max` points (log scale, so
/// that a cell of one point still shows).
pub fn density_color(count: usize, max: usize) -> String {
    let t = ((count as f64).ln_1p() / (max.max(1) as f64).ln_1p()).clamp(0.0, 1.0);
    let t = 0.15 + 0.85 * t;
    let mix = |c: f64| (255.0 + t * (c - 255.0)).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        mix(0.0),
        mix(0x72 as f64),
        mix(0xB2 as f64)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_maps_and_keeps_aspect() {
        let f = Frame {
            left: 10.0,
            top: 20.0,
            width: 200.0,
            height: 100.0,
            x: (0.0, 100.0),
            y: (0.0, 100.0),
        };
        assert_eq!(f.px(50.0), 110.0);
        assert_eq!(f.py(0.0), 120.0);
        let e = f.equal_aspect();
        assert!(((e.x.1 - e.x.0) / e.width - (e.y.1 - e.y.0) / e.height).abs() < 1e-12);
        assert!(e.x.0 <= 0.0 && e.x.1 >= 100.0 && e.y.0 <= 0.0 && e.y.1 >= 100.0);
    }

    #[test]
    fn grid_counts_every_point_inside() {
        let f = Frame {
            left: 0.0,
            top: 0.0,
            width: 10.0,
            height: 10.0,
            x: (0.0, 1.0),
            y: (0.0, 1.0),
        };
        let pts = (0..1000).map(|i| ((i % 10) as f64 / 10.0, (i / 100) as f64 / 10.0, 1.0));
        let g = Grid::new(&f, 5, 5, pts.chain([(2.0, 0.5, 1.0)]));
        assert_eq!(g.count.iter().sum::<usize>(), 1000);
        assert_eq!(g.max_count(), 40);
        assert_eq!(viridis(0.0), "#440154");
        assert_eq!(viridis(1.0), "#fde725");
    }
}
