//! A small SVG writer: elements appended to a string with every number rounded to 0.01 px, so
//! the same scene gives the same bytes.

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

/// A path's `d` through points (`M x y L x y …`, closed with `Z` when asked).
pub fn path_data(points: &[Px], closed: bool) -> String {
    let mut d = String::with_capacity(points.len() * 14);
    for (i, p) in points.iter().enumerate() {
        let _ = write!(
            d,
            "{}{} {}",
            if i == 0 { "M" } else { "L" },
            num(p[0]),
            num(p[1])
        );
    }
    if closed {
        d.push('Z');
    }
    d
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

    /// An open polyline (or a closed outline), stroked, not filled.
    pub fn polyline(&mut self, points: &[Px], closed: bool, color: Color, width: f64, extra: &str) {
        if points.len() < 2 {
            return;
        }
        let _ = writeln!(
            self.out,
            "<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"{extra}/>",
            path_data(points, closed),
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

    /// Filled dots of one colour, all `radius` wide, as one path of circles with `attributes`
    /// (a cloud's samples). One element, not one per dot: converting a figure costs per
    /// element (svg2pdf ≈ 40 µs each), and se3_global_vs_local's 36 000 dots as circles took
    /// 1.4 s to become a PDF (BENCHMARKS.md §9). Nothing is written without dots.
    pub fn dots(&mut self, centers: impl IntoIterator<Item = Px>, radius: f64, attributes: &str) {
        let mut centers = centers.into_iter().peekable();
        if centers.peek().is_none() {
            return;
        }
        let (r, across) = (num(radius), num(2.0 * radius));
        let _ = write!(self.out, "<path {attributes} d=\"");
        for c in centers {
            // Two half-circle arcs from the leftmost point round and back.
            let _ = write!(
                self.out,
                "M{} {}a{r} {r} 0 1 0 {across} 0a{r} {r} 0 1 0 -{across} 0",
                num(c[0] - radius),
                num(c[1])
            );
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

/// Roughly how wide `text` is at `size` pixels in the bundled font (its average advance is
/// about 0.53 em): enough to wrap legend lines and keep labels apart.
pub fn text_width(text: &str, size: f64) -> f64 {
    0.53 * size * text.chars().count() as f64
}

/// `text` broken into lines no wider than `width` at `size` pixels (at word boundaries; a
/// single longer word stays whole).
///
/// ```
/// use posecov::sink::figure::svg::wrap;
/// // At 10 px a line of 100 px holds about 18 characters.
/// assert_eq!(wrap("first order: Cartesian ellipse", 10.0, 100.0), vec!["first order:", "Cartesian ellipse"]);
/// ```
pub fn wrap(text: &str, size: f64, width: f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if text_width(&format!("{line} {word}"), size) <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}
