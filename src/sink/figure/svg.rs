//! A small SVG writer: elements appended to a string with every number rounded (to 0.01 px,
//! path coordinates to 0.1 px), so the same scene gives the same bytes.

use std::fmt::Write as _;

use crate::scene::Color;

/// The font every figure's text is set in: the bundled Liberation Sans (SIL OFL 1.1), which the
/// PNG and PDF renderers load from the binary; an SVG viewer without it falls back to
/// sans-serif.
pub const FONT_FAMILY: &str = "Liberation Sans";

/// A point in figure pixels (x right, y down).
pub type Px = [f64; 2];

/// A number as SVG writes it: two decimals at most, no trailing zeros, no `-0`.
///
/// ```
/// use posecov::sink::figure::svg::num;
/// assert_eq!(num(1.0), "1");
/// assert_eq!(num(-0.001), "0");
/// assert_eq!(num(2.345_678), "2.35");
/// ```
pub fn num(v: f64) -> String {
    let rounded = (v * 100.0).round() / 100.0;
    let rounded = if rounded == 0.0 { 0.0 } else { rounded };
    let text = format!("{rounded:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// `rgb(r,g,b)` of a colour (its alpha goes into an opacity attribute instead).
pub fn rgb(c: Color) -> String {
    let [r, g, b, _] = c.0;
    format!("rgb({r},{g},{b})")
}

/// A colour darkened towards black by `f` in [0, 1] (outlines of light regions).
pub fn darker(c: Color, f: f64) -> Color {
    let [r, g, b, a] = c.0;
    let d = |v: u8| (f64::from(v) * (1.0 - f)).round() as u8;
    Color([d(r), d(g), d(b), a])
}

/// A colour seen through `alpha` over the white page, as an opaque colour: what a
/// translucent mark looks like, without a transparency group per mark (which PDF would
/// need).
pub fn on_white(c: Color, alpha: f64) -> Color {
    let [r, g, b, _] = c.0;
    let a = alpha.clamp(0.0, 1.0);
    let mix = |v: u8| (f64::from(v) * a + 255.0 * (1.0 - a)).round() as u8;
    Color::rgb(mix(r), mix(g), mix(b))
}

/// Text escaped for XML.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A coordinate in a path's data: one decimal at most, no trailing zeros, no `-0`. A tenth
/// of a pixel is finer than any screen or print shows a figure; a second decimal made the long
/// paths a fifth longer and the PDF conversion slower for nothing seen.
///
/// ```
/// use posecov::sink::figure::svg::coord;
/// assert_eq!(coord(12.0), "12");
/// assert_eq!(coord(-0.04), "0");
/// assert_eq!(coord(2.345_678), "2.3");
/// ```
pub fn coord(v: f64) -> String {
    let mut out = String::new();
    push_coord(&mut out, v);
    out
}

/// Appends [`coord`] of `v` to `out` (no allocation: paths have hundreds of thousands).
fn push_coord(out: &mut String, v: f64) {
    let tenths = (v * 10.0).round();
    if !tenths.is_finite() {
        out.push('0');
        return;
    }
    let tenths = tenths as i64;
    if tenths < 0 {
        out.push('-');
    }
    let t = tenths.unsigned_abs();
    let _ = write!(out, "{}", t / 10);
    if !t.is_multiple_of(10) {
        let _ = write!(out, ".{}", t % 10);
    }
}

/// A path's `d` through points (`M x y L x y …`, closed with `Z` when asked), each
/// coordinate to a tenth of a pixel ([`coord`]); a point that rounds to the one before it is
/// left out.
pub fn path_data(points: &[Px], closed: bool) -> String {
    let mut d = String::with_capacity(points.len() * 12);
    let mut last: Option<[i64; 2]> = None;
    for p in points {
        let here = p.map(|v| (v * 10.0).round() as i64);
        if last == Some(here) {
            continue;
        }
        d.push(if last.is_none() { 'M' } else { 'L' });
        push_coord(&mut d, p[0]);
        d.push(' ');
        push_coord(&mut d, p[1]);
        last = Some(here);
    }
    if closed {
        d.push('Z');
    }
    d
}

/// How far a simplified line may pass from a point it leaves out, in pixels: a tenth, like
/// the coordinates' rounding.
pub const SIMPLIFY_TOLERANCE: f64 = 0.1;

/// A polyline with the points left out that lie within `tolerance` of the straight line
/// between the points kept around them (Douglas–Peucker): the same line to within that
/// distance, with far fewer corners where a smooth curve is small on the page (an ellipse of
/// 96 points a few pixels across). The first and last points are always kept.
///
/// ```
/// use posecov::sink::figure::svg::simplified;
/// let line = [[0.0, 0.0], [1.0, 0.01], [2.0, 0.0], [2.0, 5.0]];
/// assert_eq!(simplified(&line, 0.1), vec![[0.0, 0.0], [2.0, 0.0], [2.0, 5.0]]);
/// ```
pub fn simplified(points: &[Px], tolerance: f64) -> Vec<Px> {
    if points.len() < 3 {
        return points.to_vec();
    }
    let mut keep = vec![false; points.len()];
    keep[0] = true;
    keep[points.len() - 1] = true;
    let mut spans = vec![(0, points.len() - 1)];
    while let Some((a, b)) = spans.pop() {
        let (p, q) = (points[a], points[b]);
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let length = dx.hypot(dy);
        let distance = |r: Px| {
            if length > 0.0 {
                ((r[0] - p[0]) * dy - (r[1] - p[1]) * dx).abs() / length
            } else {
                (r[0] - p[0]).hypot(r[1] - p[1])
            }
        };
        let farthest = (a + 1..b).map(|k| (k, distance(points[k]))).fold(
            None,
            |best: Option<(usize, f64)>, (k, d)| match best {
                Some((_, bd)) if bd >= d => best,
                _ => Some((k, d)),
            },
        );
        if let Some((k, d)) = farthest
            && d > tolerance
        {
            keep[k] = true;
            spans.push((a, k));
            spans.push((k, b));
        }
    }
    points
        .iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(*p))
        .collect()
}

/// Horizontal anchor of a text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// The text starts at x.
    Start,
    /// The text is centred on x.
    Middle,
    /// The text ends at x.
    End,
}

/// An SVG document being written.
pub struct Svg {
    out: String,
}

impl Svg {
    /// A document of `width` × `height` pixels on a white page.
    pub fn new(width: u32, height: u32) -> Self {
        let mut out = String::new();
        let _ = write!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" \
             width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\" \
             font-family=\"{FONT_FAMILY}, sans-serif\">\n\
             <rect width=\"{width}\" height=\"{height}\" fill=\"white\"/>\n"
        );
        Self { out }
    }

    /// Appends raw markup (an element written by the caller).
    pub fn raw(&mut self, markup: &str) {
        self.out.push_str(markup);
        self.out.push('\n');
    }

    /// Opens a group with the given attributes (`class="…" opacity="…"`).
    pub fn open(&mut self, attributes: &str) {
        let _ = writeln!(self.out, "<g {attributes}>");
    }

    /// Closes the last group.
    pub fn close(&mut self) {
        self.out.push_str("</g>\n");
    }

    /// A line segment.
    pub fn line(&mut self, a: Px, b: Px, color: Color, width: f64, extra: &str) {
        let _ = writeln!(
            self.out,
            "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\" stroke-width=\"{}\"{extra}/>",
            num(a[0]),
            num(a[1]),
            num(b[0]),
            num(b[1]),
            rgb(color),
            num(width)
        );
    }

    /// An open polyline (or a closed outline), stroked, not filled, [`simplified`] to
    /// [`SIMPLIFY_TOLERANCE`].
    pub fn polyline(&mut self, points: &[Px], closed: bool, color: Color, width: f64, extra: &str) {
        if points.len() < 2 {
            return;
        }
        let _ = writeln!(
            self.out,
            "<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"{extra}/>",
            path_data(&simplified(points, SIMPLIFY_TOLERANCE), closed),
            rgb(color),
            num(width)
        );
    }

    /// A filled rectangle (a swatch, a panel).
    pub fn rect(&mut self, at: Px, size: Px, fill: &str, extra: &str) {
        let _ = writeln!(
            self.out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{fill}\"{extra}/>",
            num(at[0]),
            num(at[1]),
            num(size[0]),
            num(size[1])
        );
    }

    /// A filled circle (a sample, a swatch dot).
    pub fn circle(&mut self, center: Px, radius: f64) {
        let _ = writeln!(
            self.out,
            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\"/>",
            num(center[0]),
            num(center[1]),
            num(radius)
        );
    }

    /// Dots of one colour, all `radius` wide, as one path with `attributes` (a cloud's
    /// samples; its `stroke` is the dots' colour): each dot a zero-length stroke with round
    /// caps, `Mx yh0`, which SVG and PDF both paint as a filled disc. One element, not one per
    /// dot (converting a figure costs per element: svg2pdf ≈ 40 µs each), and a short one: a
    /// dot written as two arcs was 50 bytes of SVG and four Bézier curves of PDF, which svg2pdf
    /// then compresses (BENCHMARKS.md §9). Nothing is written without dots.
    pub fn dots(&mut self, centers: impl IntoIterator<Item = Px>, radius: f64, attributes: &str) {
        let mut centers = centers.into_iter().peekable();
        if centers.peek().is_none() {
            return;
        }
        let _ = write!(
            self.out,
            "<path {attributes} fill=\"none\" stroke-width=\"{}\" stroke-linecap=\"round\" d=\"",
            num(2.0 * radius)
        );
        for c in centers {
            self.out.push('M');
            push_coord(&mut self.out, c[0]);
            self.out.push(' ');
            push_coord(&mut self.out, c[1]);
            self.out.push_str("h0");
        }
        self.out.push_str("\"/>\n");
    }

    /// A line of text at `at` (the baseline's start, middle or end), `size` pixels high.
    pub fn text(&mut self, at: Px, size: f64, anchor: Anchor, color: &str, text: &str) {
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let _ = writeln!(
            self.out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"{anchor}\" fill=\"{color}\">{}</text>",
            num(at[0]),
            num(at[1]),
            num(size),
            escape(text)
        );
    }

    /// The finished document.
    pub fn finish(mut self) -> String {
        self.out.push_str("</svg>\n");
        self.out
    }
}

/// Text is measured and wrapped with the viewer's legend's own measure (the bundled font's
/// advance widths): one measure for both.
pub use crate::scene::layout::{text_width, wrap};
