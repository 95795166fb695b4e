//! The viewer's legend: a small 2-D view under the 3-D views with one tile per
//! [`LegendEntry`] of the scene — a bar in the entry's colour (thick for a region, thin for a
//! line, with dots for a cloud, red, green and blue strokes for axes) and under it the words in
//! that colour, wrapped to the tile, the colour named ("first order: Exp-mapped 95 % region —
//! sky blue"). What the run measured about an entry ([`LegendEntry::detail`]) stays in the text
//! panel's table: the tiles must fit at 1024 × 640.
//!
//! The tiles are laid out here in the view's own units, about one UI point each when the
//! window is 1024 × 640 ([`DESIGN_WIDTH`]); the blueprint frames exactly the tiles
//! (`VisualBounds2D`) and gives the view the height they need ([`Tiles::height`]). A wider
//! window scales the tiles up, and the words, wrapped to each tile's width, keep fitting.

use ::rerun as rr;

use super::SinkError;
use super::rerun::send;
use crate::scene::{self, AXIS_COLORS, Color, LegendEntry, Swatch};

/// Entity of the legend's tiles (static; shown by the legend view only).
pub const LEGEND: &str = "legend";

/// The legend view's width in its own units: the left column of a 1024-point window (three
/// fifths) less the panel borders.
pub const DESIGN_WIDTH: f64 = 600.0;

/// Width of an average character of the viewer's 13-point Inter, with room for word wraps.
const CHAR_WIDTH: f64 = 7.2;
/// Height of a line of label text.
const LINE_HEIGHT: f64 = 17.0;
/// Above the words: the bar, and the viewer's 5-point gap and 4-point label padding.
const BAR_SPACE: f64 = 16.0;
/// Below the words, to the next row.
const ROW_GAP: f64 = 8.0;
/// Space between tiles, and the words' inner padding.
const PAD: f64 = 8.0;
/// Colour of the words and bar of an axes entry (its own colour is not used).
const AXES_WORDS: Color = Color::rgb(210, 210, 210);

/// One tile: where its bar runs, and its entry.
struct Tile<'a> {
    entry: &'a LegendEntry,
    x: [f64; 2],
    y: f64,
}

/// The legend's tiles and the height they take.
pub struct Tiles<'a> {
    tiles: Vec<Tile<'a>>,
    /// The height of all rows, in the view's units.
    pub height: f64,
}

/// The words of a tile: the label and the colour's name.
fn words(entry: &LegendEntry) -> String {
    match (entry.swatch, scene::color_name(entry.color)) {
        (Swatch::Axes, _) | (_, None) => entry.label.clone(),
        (_, Some(name)) => format!("{} — {name}", entry.label),
    }
}

/// Lines the words take in a tile `width` wide (never 0).
fn lines(text: &str, width: f64) -> usize {
    let per_line = ((width - 2.0 * PAD) / CHAR_WIDTH).floor().max(8.0) as usize;
    let mut lines = 1;
    let mut used = 0;
    for word in text.split(' ') {
        let n = word.chars().count();
        if used > 0 && used + 1 + n > per_line {
            lines += 1;
            used = n;
        } else {
            used += if used > 0 { 1 + n } else { n };
        }
    }
    lines
}

/// Lays the entries out in the number of columns (1–4) that takes the least height.
///
/// ```
/// use posecov::scene::{Color, LegendEntry, Swatch};
/// use posecov::sink::legend::tiles;
/// let e = |label: &str| LegendEntry { label: label.into(), detail: String::new(),
///     color: Color::rgb(175, 175, 175), swatch: Swatch::Dots };
/// let entries = [e("Monte Carlo samples (4000)"), e("nominal path"), e("links")];
/// let t = tiles(&entries);
/// assert!(t.height > 0.0 && t.height < 60.0, "{}", t.height);
/// assert_eq!(tiles(&[]).height, 0.0);
/// ```
pub fn tiles(entries: &[LegendEntry]) -> Tiles<'_> {
    // One tile per words and mark: entries that differ only in their detail (the share of
    // samples held by each of two outputs) read the same here.
    let mut seen: Vec<(String, Swatch)> = Vec::new();
    let entries: Vec<&LegendEntry> = entries
        .iter()
        .filter(|e| {
            let key = (words(e), e.swatch);
            let new = !seen.contains(&key);
            if new {
                seen.push(key);
            }
            new
        })
        .collect();
    let texts: Vec<String> = entries.iter().map(|e| words(e)).collect();
    let lay = |columns: usize| {
        let width = DESIGN_WIDTH / columns as f64;
        let mut tiles = Vec::new();
        let mut y = 0.0;
        for (row, chunk) in entries.chunks(columns).enumerate() {
            let first = row * columns;
            let most = (0..chunk.len())
                .map(|i| lines(&texts[first + i], width))
                .max()
                .unwrap_or(1);
            for (i, &entry) in chunk.iter().enumerate() {
                let x0 = i as f64 * width + PAD;
                tiles.push(Tile {
                    entry,
                    x: [x0, x0 + width - 2.0 * PAD],
                    y: y + 4.0,
                });
            }
            y += BAR_SPACE + most as f64 * LINE_HEIGHT + ROW_GAP;
        }
        Tiles { tiles, height: y }
    };
    (1..=4)
        .rev()
        .map(lay)
        .reduce(|best, t| if t.height < best.height { t } else { best })
        .unwrap_or(Tiles {
            tiles: Vec::new(),
            height: 0.0,
        })
}

/// Logs the legend's tiles (static, always all three entities, so a new scene replaces the
/// last one's legend whole): `legend/bars` (one box per entry, carrying its words),
/// `legend/dots` (a cloud's mark) and `legend/axes` (an axes entry's red, green and blue).
///
/// # Errors
/// An SDK error.
pub fn log_legend(rec: &rr::RecordingStream, entries: &[LegendEntry]) -> Result<(), SinkError> {
    let laid = tiles(entries);
    let mut bars = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut dots = (Vec::new(), Vec::new());
    let mut axes = (Vec::new(), Vec::new());
    for tile in &laid.tiles {
        let e = tile.entry;
        let [x0, x1] = tile.x.map(|v| v as f32);
        let y = tile.y as f32;
        let (color, height, radius) = match e.swatch {
            Swatch::Region => (e.color, 5.0, -2.0),
            Swatch::Axes => (AXES_WORDS, 0.0, -0.75),
            Swatch::Line | Swatch::Dashed | Swatch::Dots => (e.color, 0.0, -1.25),
        };
        bars.0.push([x0, y]);
        bars.1.push([x1 - x0, height]);
        bars.2.push(rerun_color(color));
        bars.3.push(radius);
        bars.4.push(words(e));
        match e.swatch {
            Swatch::Dots => {
                for k in 0..5 {
                    let x = x0 + (x1 - x0) * (0.3 + 0.1 * k as f32);
                    dots.0.push([x, y - 3.0]);
                    dots.1.push(rerun_color(e.color));
                }
            }
            Swatch::Axes => {
                for (k, c) in AXIS_COLORS.iter().enumerate() {
                    let x = x0 + (x1 - x0) * (0.4 + 0.1 * k as f32);
                    axes.0.push(vec![[x, y + 3.0], [x, y - 5.0]]);
                    axes.1.push(rerun_color(*c));
                }
            }
            _ => {}
        }
    }
    let at = rr::TimePoint::default();
    let boxes = rr::Boxes2D::from_mins_and_sizes(bars.0, bars.1)
        .with_colors(bars.2)
        .with_radii(bars.3)
        .with_labels(bars.4)
        .with_show_labels(true);
    send(rec, format!("{LEGEND}/bars"), at.clone(), &[&boxes])?;
    let points = rr::Points2D::new(dots.0)
        .with_colors(dots.1)
        .with_radii([-2.0f32]);
    send(rec, format!("{LEGEND}/dots"), at.clone(), &[&points])?;
    let strips = rr::LineStrips2D::new(axes.0)
        .with_colors(axes.1)
        .with_radii([-1.5f32]);
    send(rec, format!("{LEGEND}/axes"), at, &[&strips])
}

fn rerun_color(c: Color) -> rr::Color {
    let [r, g, b, _] = c.0;
    rr::Color::from_rgb(r, g, b)
}

#[cfg(test)]
mod tests {
    use super::lines;

    #[test]
    fn words_wrap_at_the_tile_width() {
        assert_eq!(lines("short", 200.0), 1);
        // 200 − 16 = 184 units: 25 characters a line.
        let long = "first order: Exp-mapped 95 % region — sky blue";
        assert_eq!(lines(long, 200.0), 2);
        assert_eq!(lines(long, 600.0), 1);
    }
}
