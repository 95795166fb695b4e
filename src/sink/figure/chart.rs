//! Axes, ticks, the metric scale bar, the legend and the plots of a figure.

use super::svg::{Anchor, Px, Svg, darker, num, rgb, text_width, wrap};
use super::world::Pen;
/// The numbers of axes and scales, shared with the drawing stage ([`crate::scene::units`]).
pub use crate::scene::units::{length_label, nice_step, tick_label, ticks};
use crate::scene::{AXIS_COLORS, Color, LegendEntry, ScalarSeries, Swatch};

/// A rectangle of the figure (pixels): top-left corner and size.
#[derive(Clone, Copy, Debug)]
pub struct Rect {
    /// Left edge.
    pub x: f64,
    /// Top edge.
    pub y: f64,
    /// Width.
    pub w: f64,
    /// Height.
    pub h: f64,
}

impl Rect {
    /// The bottom edge.
    pub fn bottom(&self) -> f64 {
        self.y + self.h
    }

    /// The right edge.
    pub fn right(&self) -> f64 {
        self.x + self.w
    }

    /// A clip path of this rectangle, with an id.
    pub fn clip(&self, svg: &mut Svg, id: &str) {
        svg.raw(&format!(
            "<clipPath id=\"{id}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>",
            num(self.x),
            num(self.y),
            num(self.w),
            num(self.h)
        ));
    }
}

/// Draws a panel's frame, grid, ticks and axis titles. `x` and `y` give each axis as
/// (ticks with their labels, title); `to_px` maps a tick value to its pixel column or row.
pub struct Axes<'a> {
    /// The data area.
    pub area: Rect,
    /// x ticks (value, pixel column) and their step.
    pub x: (&'a [(f64, f64)], f64),
    /// y ticks (value, pixel row) and their step.
    pub y: (&'a [(f64, f64)], f64),
    /// The axes' titles with units, e.g. "x (m)".
    pub titles: (&'a str, &'a str),
}

impl Axes<'_> {
    /// Draws the grid (under the data).
    pub fn grid(&self, svg: &mut Svg, pen: Pen) {
        let a = self.area;
        svg.open("class=\"grid\" stroke=\"#e3e3e3\"");
        for &(_, px) in self.x.0 {
            svg.raw(&format!(
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke-width=\"{3}\"/>",
                num(px),
                num(a.y),
                num(a.bottom()),
                num(0.8 * pen.unit)
            ));
        }
        for &(_, py) in self.y.0 {
            svg.raw(&format!(
                "<line x1=\"{1}\" y1=\"{0}\" x2=\"{2}\" y2=\"{0}\" stroke-width=\"{3}\"/>",
                num(py),
                num(a.x),
                num(a.right()),
                num(0.8 * pen.unit)
            ));
        }
        svg.close();
    }

    /// Draws the frame, tick labels and titles (over the data).
    pub fn frame(&self, svg: &mut Svg, pen: Pen) {
        let a = self.area;
        svg.raw(&format!(
            "<rect class=\"frame\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\" stroke-width=\"{}\"/>",
            num(a.x),
            num(a.y),
            num(a.w),
            num(a.h),
            num(pen.unit)
        ));
        let f = pen.font;
        svg.open("class=\"ticks\"");
        for &(v, px) in self.x.0 {
            svg.line(
                [px, a.bottom()],
                [px, a.bottom() + 0.4 * f],
                Color::rgb(68, 68, 68),
                pen.unit,
                "",
            );
            svg.text(
                [px, a.bottom() + 1.4 * f],
                f,
                Anchor::Middle,
                "#333",
                &tick_label(v, self.x.1),
            );
        }
        for &(v, py) in self.y.0 {
            svg.line(
                [a.x - 0.4 * f, py],
                [a.x, py],
                Color::rgb(68, 68, 68),
                pen.unit,
                "",
            );
            svg.text(
                [a.x - 0.6 * f, py + 0.35 * f],
                f,
                Anchor::End,
                "#333",
                &tick_label(v, self.y.1),
            );
        }
        svg.close();
        svg.text(
            [a.x + 0.5 * a.w, a.bottom() + 2.7 * f],
            f,
            Anchor::Middle,
            "#222",
            self.titles.0,
        );
        // The y title, turned to read bottom to top.
        let (x, y) = (a.x - 3.6 * f, a.y + 0.5 * a.h);
        svg.raw(&format!(
            "<text x=\"{0}\" y=\"{1}\" font-size=\"{2}\" text-anchor=\"middle\" fill=\"#222\" transform=\"rotate(-90 {0} {1})\">{3}</text>",
            num(x),
            num(y),
            num(f),
            super::svg::escape(self.titles.1)
        ));
    }
}

/// The metric scale bar: `metres` long at `scale` pixels per metre, in the panel's bottom-right
/// corner on a white ground.
pub fn scale_bar(svg: &mut Svg, area: Rect, metres: f64, scale: f64, pen: Pen) {
    let len = metres * scale;
    let f = pen.font;
    let right = area.right() - 1.0 * f;
    let y = area.bottom() - 1.0 * f;
    let left = right - len;
    let ground = scale_bar_box(area, metres, scale, pen);
    svg.open("class=\"scale-bar\"");
    svg.rect(
        [ground.x, ground.y],
        [ground.w, ground.h],
        "white",
        " fill-opacity=\"0.85\"",
    );
    let black = Color::rgb(0, 0, 0);
    svg.line([left, y], [right, y], black, 1.6 * pen.unit, "");
    svg.line(
        [left, y - 0.4 * f],
        [left, y + 0.3 * f],
        black,
        1.6 * pen.unit,
        "",
    );
    svg.line(
        [right, y - 0.4 * f],
        [right, y + 0.3 * f],
        black,
        1.6 * pen.unit,
        "",
    );
    svg.text(
        [0.5 * (left + right), y - 0.5 * f],
        f,
        Anchor::Middle,
        "#000",
        &length_label(metres),
    );
    svg.close();
}

/// The white ground of the scale bar ([`scale_bar`]) in the panel `area`: what labels keep
/// clear of.
pub fn scale_bar_box(area: Rect, metres: f64, scale: f64, pen: Pen) -> Rect {
    let (len, f) = (metres * scale, pen.font);
    Rect {
        x: area.right() - 1.0 * f - len - 0.5 * f,
        y: area.bottom() - 3.0 * f,
        w: len + f,
        h: 2.6 * f,
    }
}

/// Draws the legend in `area` (swatch, then the label wrapped to the width), an entry that
/// reads, looks and is coloured like an earlier one once; returns the height used. Every
/// entry is drawn: when they do not all fit, their details (what the run measured, which the
/// report keeps) are left out and entries that then read alike are drawn once; when they still
/// do not fit, the legend's text is made smaller until they do (down to half size, below which
/// the last entries are left out).
pub fn legend(svg: &mut Svg, area: Rect, entries: &[LegendEntry], pen: Pen) -> f64 {
    let with_details = distinct(entries, true);
    let without = distinct(entries, false);
    let mut chosen = (&with_details, pen.font);
    if legend_height(&with_details, area, pen.font) > area.h {
        chosen = (&without, pen.font);
        let mut f = pen.font;
        while legend_height(&without, area, f) > area.h && f > 0.5 * pen.font {
            f *= 0.92;
            chosen.1 = f;
        }
    }
    let (list, f) = chosen;
    let swatch_w = 2.2 * f;
    let text_x = area.x + swatch_w + 0.6 * f;
    let mut y = area.y;
    svg.open("class=\"legend\"");
    for (entry, text) in list {
        let lines = wrap(text, f, area.right() - text_x);
        let needed = 1.25 * f * lines.len() as f64 + 0.35 * f;
        if y + needed > area.bottom() {
            break;
        }
        swatch(
            svg,
            [area.x, y + 0.15 * f],
            [swatch_w, 0.9 * f],
            entry,
            Pen { font: f, ..pen },
        );
        for (i, line) in lines.iter().enumerate() {
            svg.text(
                [text_x, y + 0.9 * f + 1.25 * f * i as f64],
                f,
                Anchor::Start,
                "#222",
                line,
            );
        }
        y += needed;
    }
    svg.close();
    y - area.y
}

/// The entries to draw, each with its words (with or without its detail), those that read,
/// look and are coloured like an earlier one left out.
fn distinct(entries: &[LegendEntry], details: bool) -> Vec<(&LegendEntry, String)> {
    let mut out: Vec<(&LegendEntry, String)> = Vec::new();
    for entry in entries {
        let text = if details {
            entry.text()
        } else {
            entry.label.clone()
        };
        let same = |(e, t): &(&LegendEntry, String)| {
            *t == text && e.swatch == entry.swatch && e.color == entry.color
        };
        if !out.iter().any(same) {
            out.push((entry, text));
        }
    }
    out
}

/// The height the legend's entries take at font size `f` in `area`'s width.
fn legend_height(list: &[(&LegendEntry, String)], area: Rect, f: f64) -> f64 {
    let text_x = area.x + 2.2 * f + 0.6 * f;
    list.iter()
        .map(|(_, text)| 1.25 * f * wrap(text, f, area.right() - text_x).len() as f64 + 0.35 * f)
        .sum()
}

/// One swatch: the same mark as what it names.
fn swatch(svg: &mut Svg, at: Px, size: Px, entry: &LegendEntry, pen: Pen) {
    let c = entry.color;
    let mid = at[1] + 0.5 * size[1];
    match entry.swatch {
        Swatch::Region => {
            svg.rect(
                at,
                size,
                &rgb(c),
                &format!(
                    " fill-opacity=\"0.45\" stroke=\"{}\" stroke-width=\"{}\"",
                    rgb(darker(c, 0.35)),
                    num(pen.unit)
                ),
            );
        }
        Swatch::Line => svg.line(
            [at[0], mid],
            [at[0] + size[0], mid],
            darker(c, 0.1),
            2.0 * pen.unit,
            "",
        ),
        Swatch::Dashed => svg.line(
            [at[0], mid],
            [at[0] + size[0], mid],
            darker(c, 0.1),
            1.6 * pen.unit,
            " stroke-dasharray=\"7 4\"",
        ),
        Swatch::Dots => {
            svg.open(&format!("fill=\"{}\"", rgb(darker(c, 0.25))));
            for k in 0..5 {
                let x = at[0] + size[0] * (0.1 + 0.2 * k as f64);
                let y = at[1] + size[1] * [0.3, 0.7, 0.45, 0.2, 0.65][k];
                svg.circle([x, y], 1.4 * pen.unit);
            }
            svg.close();
        }
        Swatch::Axes => {
            let o = [at[0] + 0.2 * size[0], at[1] + size[1]];
            let w = 1.6 * pen.unit;
            svg.line(
                o,
                [at[0] + 0.95 * size[0], o[1]],
                darker(AXIS_COLORS[0], 0.15),
                w,
                "",
            );
            svg.line(
                o,
                [o[0], at[1] - 0.1 * size[1]],
                darker(AXIS_COLORS[1], 0.15),
                w,
                "",
            );
            svg.line(
                o,
                [o[0] - 0.2 * size[0], o[1] + 0.2 * size[1]],
                darker(AXIS_COLORS[2], 0.15),
                w,
                "",
            );
        }
    }
}

/// One plot: its title with unit, a line per series, step (or time) ticks below and value ticks
/// to the left; `marker` draws a vertical line at that x (the figure's step).
pub struct PlotPanel<'a> {
    /// "trace Σ_ρρ, body frame (m²)".
    pub title: String,
    /// The series drawn.
    pub series: Vec<&'a ScalarSeries>,
    /// The x axis title ("step", "time (s)").
    pub x_title: &'a str,
    /// Converts a series' x (step or nanoseconds) to the axis' value.
    pub x_of: &'a dyn Fn(i64) -> f64,
    /// A vertical marker at this axis value.
    pub marker: Option<f64>,
}

impl PlotPanel<'_> {
    /// Draws the plot with its title above `area`'s data rectangle.
    pub fn draw(&self, svg: &mut Svg, area: Rect, id: &str, pen: Pen) {
        let f = pen.font;
        let data = Rect {
            x: area.x + 4.2 * f,
            y: area.y + 3.0 * f,
            w: (area.w - 4.8 * f).max(10.0),
            h: (area.h - 6.4 * f).max(10.0),
        };
        svg.text([area.x, area.y + f], f, Anchor::Start, "#222", &self.title);
        // The plot's own legend, in rows above the data: a line swatch and name per name.
        let small = 0.85 * f;
        let (mut x, mut row) = (area.x, area.y + 2.3 * f);
        svg.open("class=\"plot-legend\"");
        let mut named: Vec<&str> = Vec::new();
        for s in &self.series {
            // Lines that share a name (a band's two edges) share an entry, as in the viewer.
            if named.contains(&s.name.as_str()) {
                continue;
            }
            named.push(&s.name);
            let width = 1.8 * small + text_width(&s.name, small) + 1.2 * small;
            if x > area.x && x + width > area.right() {
                (x, row) = (area.x, row + 1.3 * small);
            }
            let y = row - 0.3 * small;
            if s.marks {
                svg.open(&format!("fill=\"{}\"", rgb(darker(s.color, 0.1))));
                svg.circle([x + 0.75 * small, y], 0.3 * small);
                svg.close();
            } else {
                svg.line(
                    [x, y],
                    [x + 1.5 * small, y],
                    darker(s.color, 0.1),
                    2.0 * pen.unit,
                    "",
                );
            }
            svg.text(
                [x + 1.8 * small, row],
                small,
                Anchor::Start,
                "#222",
                &s.name,
            );
            x += width;
        }
        svg.close();
        let legend_rows = row - (area.y + 2.3 * f);
        let data = Rect {
            y: data.y + legend_rows,
            h: (data.h - legend_rows).max(10.0),
            ..data
        };
        let points: Vec<(f64, f64)> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|&(x, v)| ((self.x_of)(x), v)))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let (mut x0, mut x1) = bounds(points.iter().map(|p| p.0));
        let (mut y0, mut y1) = bounds(points.iter().map(|p| p.1));
        if x1 <= x0 {
            (x0, x1) = (x0 - 0.5, x0 + 0.5);
        }
        if y1 <= y0 {
            (y0, y1) = (
                y0 - 0.5 * y0.abs().max(1e-12),
                y0 + 0.5 * y0.abs().max(1e-12),
            );
        }
        // Variances and traces start from zero: the growth reads against it.
        if y0 > 0.0 && y0 < 0.5 * y1 {
            y0 = 0.0;
        }
        let pad = 0.05 * (y1 - y0);
        let (y0, y1) = (y0 - if y0 == 0.0 { 0.0 } else { pad }, y1 + pad);
        let sx = data.w / (x1 - x0);
        let sy = data.h / (y1 - y0);
        let px = |x: f64, v: f64| [data.x + sx * (x - x0), data.bottom() - sy * (v - y0)];
        let xs = nice_step(x1 - x0, 5);
        let ys = nice_step(y1 - y0, 4);
        let x_ticks: Vec<(f64, f64)> = ticks(x0, x1, xs)
            .into_iter()
            .map(|v| (v, px(v, y0)[0]))
            .collect();
        let y_ticks: Vec<(f64, f64)> = ticks(y0, y1, ys)
            .into_iter()
            .map(|v| (v, px(x0, v)[1]))
            .collect();
        let axes = Axes {
            area: data,
            x: (&x_ticks, xs),
            y: (&y_ticks, ys),
            titles: (self.x_title, ""),
        };
        axes.grid(svg, pen);
        data.clip(svg, id);
        svg.open(&format!("class=\"plot\" clip-path=\"url(#{id})\""));
        if let Some(x) = self.marker {
            let p = px(x, y0)[0];
            svg.line(
                [p, data.y],
                [p, data.bottom()],
                Color::rgb(120, 120, 120),
                pen.unit,
                " stroke-dasharray=\"3 3\"",
            );
        }
        for s in &self.series {
            let line: Vec<Px> = s
                .points
                .iter()
                .map(|&(x, v)| px((self.x_of)(x), v))
                .filter(|p| p[0].is_finite() && p[1].is_finite())
                .collect();
            if line.len() == 1 || s.marks {
                svg.open(&format!("fill=\"{}\"", rgb(darker(s.color, 0.1))));
                for p in &line {
                    svg.circle(*p, if s.marks { 1.2 } else { 1.0 } * 2.0 * pen.unit);
                }
                svg.close();
            }
            if !s.marks {
                svg.polyline(&line, false, darker(s.color, 0.1), 1.6 * pen.unit, "");
            }
        }
        svg.close();
        axes.frame(svg, pen);
    }
}

/// The smallest and largest of some finite values ((0, 0) for none).
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold(None, |acc: Option<(f64, f64)>, v| {
            Some(acc.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))))
        })
        .unwrap_or((0.0, 0.0))
}
