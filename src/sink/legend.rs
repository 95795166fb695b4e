//! The viewer's legend: a small 2-D view under the 3-D views with one tile per
//! [`LegendEntry`] of the scene (entries that differ only in their method share one tile) — a
//! bar in the entry's colour (thick for a region, thin for a line, with dots for a cloud, red,
//! green and blue strokes for axes) and under it the words in that colour, wrapped to the tile, the colour named ("first order: Exp-mapped 95 % region —
//! sky blue"). What the run measured about an entry ([`LegendEntry::detail`]) stays in the text
//! panel's table: the tiles must fit at 1024 × 640.
//!
//! The tiles are laid out by [`crate::scene::layout::tiles`] in the view's own units, about one
//! UI point each when the window is 1024 × 640; the blueprint frames exactly the tiles
//! (`VisualBounds2D`) and gives the view the height they need
//! ([`crate::scene::layout::legend_share`]). A wider
//! window scales the tiles up, and the words, wrapped to each tile's width, keep fitting.

use ::rerun as rr;

use super::SinkError;
use super::rerun::send;
use crate::scene::layout::{AXES_WORDS, LegendPane, legend_markdown, legend_pane, tiles};
use crate::scene::{AXIS_COLORS, Color, LegendEntry, Scene, Swatch};

/// Entity of the legend's tiles (static; shown by the legend view only).
pub const LEGEND: &str = "legend";

/// Entity of the legend as a list in words ([`LegendPane::Text`]; its text view's origin).
pub const LEGEND_TEXT: &str = "legend_text";

/// Logs the scene's legend (static): its tiles, always all three entities so that a new scene
/// replaces the last one's legend whole — `legend/bars` (one box per entry, carrying its
/// words), `legend/dots` (a cloud's mark) and `legend/axes` (an axes entry's red, green and
/// blue), none when the legend is a list in words — and that list at [`LEGEND_TEXT`] when it
/// is one ([`LegendPane::Text`]; only its own text view shows it).
///
/// # Errors
/// An SDK error.
pub fn log_legend(rec: &rr::RecordingStream, scene: &Scene) -> Result<(), SinkError> {
    let text = legend_pane(scene, scene.views.len()) == LegendPane::Text;
    let entries: &[LegendEntry] = if text { &[] } else { &scene.legend };
    if text {
        let list = rr::TextDocument::from_markdown(legend_markdown(&scene.legend));
        send(rec, LEGEND_TEXT, rr::TimePoint::default(), &[&list])?;
    }
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
        bars.4.push(tile.words.clone());
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
