//! The viewer's default layout at its design size, a 1024 × 640 window: how much room the
//! 3-D views and the legend view get. One place for the numbers that the blueprint gives its
//! panes (`sink::blueprint`), the legend's tiles are laid out in (`sink::legend`) and the
//! cameras are fitted to (`draw::views`), so each 3-D view opens framed for the shape it
//! really has.
//!
//! Sizes are in UI points (one point per pixel at 1024 × 640). The window's top bar and the
//! collapsed time panel leave [`DESIGN_HEIGHT`]; the left column (three fifths) holds the 3-D
//! views over the legend view of tiles ([`legend_share`]) when it takes little of the column,
//! the right one the text panel over the plots (and between them a legend too large for tiles,
//! as a list in words: [`LegendPane`]).
//!
//! ```
//! use posecov::scene::{Scene, layout::{DESIGN_WIDTH, views_aspect}};
//! let scene = Scene::new("t", "d");
//! // Without a legend one view has the whole left column: 600 × (584 − 30) points.
//! assert!((views_aspect(&scene, 1) - DESIGN_WIDTH / 554.0).abs() < 1e-12);
//! // Four views in a 2 × 2 grid: each a quarter, so about the same shape.
//! assert!((views_aspect(&scene, 4) - 300.0 / 262.0).abs() < 1e-12);
//! ```

use super::{Color, LegendEntry, Scene, Swatch, color_name, grid_columns};

/// The left column's width at 1024 × 640 (three fifths of the window, less the panes'
/// borders): the 3-D views' width and the legend view's, in points.
pub const DESIGN_WIDTH: f64 = 600.0;
/// The height of the panes' area of a 1024 × 640 window (the viewer's top bar and collapsed
/// time panel left out), in points.
pub const DESIGN_HEIGHT: f64 = 584.0;
/// A view's tab and borders, in points.
pub const VIEW_CHROME: f64 = 30.0;

/// The left column's share of the window (the text panel and plots have the rest).
pub const LEFT_SHARE: f32 = 3.0;
/// The right column's share of the window.
pub const RIGHT_SHARE: f32 = 2.0;

/// The size of the viewer's label text (its 13-point Inter), in points.
const LABEL_SIZE: f64 = 13.0;
/// How much wider than [`text_width`] (Liberation Sans) the legend reckons the viewer's label
/// lines: the viewer's Inter is not bundled here, so its lines were measured instead, in a
/// screenshot at 1024 × 640 (2 pixels a point): five of se3_global_vs_local's legend lines
/// were 0.98–0.99 of their [`text_width`] at 13 points. The 4 % over that is a margin for
/// where the viewer breaks a line.
const VIEWER_WIDER: f64 = 1.04;
/// Height of a line of label text: the viewer's lines are 14.5 points apart (measured in
/// the same screenshot).
const LINE_HEIGHT: f64 = 15.0;
/// Above the words: the bar, and the viewer's 5-point gap and 4-point label padding.
const BAR_SPACE: f64 = 16.0;
/// Below the words, to the next row.
const ROW_GAP: f64 = 8.0;
/// Space between tiles, and the words' inner padding.
const PAD: f64 = 8.0;

/// The most of the left column a legend of tiles takes, shared by the rows of 3-D views (a
/// 2 × 2 grid leaves it half of this): a larger legend is a list in words ([`LegendPane::Text`]).
pub const LEGEND_MOST: f64 = 0.45;

/// The legend view's height in the left column, tab included, for tiles `height` high
/// ([`Tiles::height`]); 0 without tiles. The tiles are laid out only when this is at most
/// their share of the column ([`legend_pane`]), so they are never scaled down.
///
/// ```
/// use posecov::scene::layout::legend_share;
/// assert_eq!(legend_share(0.0), 0.0);
/// assert_eq!(legend_share(100.0), 130.0);
/// ```
pub fn legend_share(height: f64) -> f64 {
    if height <= 0.0 {
        0.0
    } else {
        height + VIEW_CHROME
    }
}

/// How the viewer shows a scene's legend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegendPane {
    /// None: no legend, or a robot log's layout (its views and plots fill the window).
    None,
    /// Tiles (a bar in each entry's colour and mark over its words, [`tiles`]) in a 2-D view
    /// under the 3-D views, as tall as they need.
    Tiles,
    /// A list in words ([`legend_markdown`]: each entry's colour and mark named) in a text
    /// view of the right column, between the text panel and the plots: the tiles would take
    /// more than [`LEGEND_MOST`] of the column (a pose graph's sixteen entries under four
    /// views), so the 3-D views keep the whole left column.
    Text,
}

/// The legend pane of `scene` with `views` 3-D views ([`LegendPane`]).
///
/// ```
/// use posecov::scene::{Color, LegendEntry, Scene, Swatch};
/// use posecov::scene::layout::{LegendPane, legend_pane};
/// let mut scene = Scene::new("t", "d");
/// assert_eq!(legend_pane(&scene, 1), LegendPane::None);
/// let entry = |k: usize| LegendEntry { label: format!("what colour {k} marks, in a few words"),
///     detail: String::new(), color: Color::rgb(0, 114, 178), swatch: Swatch::Line };
/// scene.legend = (0..3).map(entry).collect();
/// assert_eq!(legend_pane(&scene, 1), LegendPane::Tiles);
/// scene.legend = (0..16).map(entry).collect();
/// assert_eq!(legend_pane(&scene, 4), LegendPane::Text);
/// ```
pub fn legend_pane(scene: &Scene, views: usize) -> LegendPane {
    if scene.plots_below || scene.legend.is_empty() {
        return LegendPane::None;
    }
    let rows = views.max(1).div_ceil(grid_columns(views));
    if legend_share(tiles(&scene.legend).height) <= LEGEND_MOST * DESIGN_HEIGHT / rows as f64 {
        LegendPane::Tiles
    } else {
        LegendPane::Text
    }
}

/// The legend as a Markdown list for the viewer's text view ([`LegendPane::Text`]): per
/// distinct entry (grouped as [`tiles`] groups them), its colour in bold, its mark and its
/// words ("- **sky blue** region: first order: Exp-mapped 95 % region").
///
/// ```
/// use posecov::scene::{Color, LegendEntry, Swatch, layout::legend_markdown};
/// let e = LegendEntry { label: "nominal path".into(), detail: String::new(),
///     color: Color::rgb(0, 114, 178), swatch: Swatch::Line };
/// assert_eq!(legend_markdown(&[e]), "- **blue** line: nominal path\n");
/// ```
pub fn legend_markdown(entries: &[LegendEntry]) -> String {
    grouped(entries)
        .into_iter()
        .map(|(e, label)| {
            let mark = match e.swatch {
                Swatch::Region => "region",
                Swatch::Line => "line",
                Swatch::Dashed => "dashed line",
                Swatch::Dots => "dots",
                Swatch::Axes => "axes",
            };
            match (e.swatch, color_name(e.color)) {
                (Swatch::Axes, _) | (_, None) => format!("- {mark}: {label}\n"),
                (_, Some(name)) => format!("- **{name}** {mark}: {label}\n"),
            }
        })
        .collect()
}

/// Whether the layout has a legend view of tiles under the 3-D views ([`LegendPane::Tiles`]
/// with the scene's views, one when it has none).
pub fn has_legend_view(scene: &Scene) -> bool {
    legend_pane(scene, scene.views.len()) == LegendPane::Tiles
}

/// The most plots side by side in one row under a log's views ([`Scene::plots_below`]).
pub const PLOTS_PER_ROW: usize = 3;

/// The heights of a log's views and of its `rows` rows of plots under them
/// ([`Scene::plots_below`]), as shares of the left column: the views keep three fifths with
/// one row, half with more.
///
/// ```
/// use posecov::scene::layout::views_over_plots;
/// assert_eq!(views_over_plots(1), [3.0, 2.0]);
/// assert_eq!(views_over_plots(2), [4.0, 2.0, 2.0]);
/// ```
pub fn views_over_plots(rows: usize) -> Vec<f32> {
    std::iter::once(if rows <= 1 { 3.0 } else { 2.0 * rows as f32 })
        .chain(std::iter::repeat_n(2.0, rows.max(1)))
        .collect()
}

/// Width over height of each of `count` 3-D views of `scene` (a grid of them,
/// [`grid_columns`]) at 1024 × 640: above its legend of tiles, if it has one
/// ([`legend_pane`]), or, for a log ([`Scene::plots_below`]), above its rows of plots
/// ([`views_over_plots`]).
pub fn views_aspect(scene: &Scene, count: usize) -> f64 {
    let columns = grid_columns(count);
    let rows = count.max(1).div_ceil(columns);
    let height = if scene.plots_below && !scene.plots.is_empty() {
        let shares = views_over_plots(scene.plots.len().div_ceil(PLOTS_PER_ROW));
        DESIGN_HEIGHT * f64::from(shares[0]) / f64::from(shares.iter().sum::<f32>())
    } else if legend_pane(scene, count) == LegendPane::Tiles {
        DESIGN_HEIGHT - legend_share(tiles(&scene.legend).height)
    } else {
        DESIGN_HEIGHT
    };
    let view_height = (height / rows as f64 - VIEW_CHROME).max(1.0);
    DESIGN_WIDTH / columns as f64 / view_height
}

/// One legend tile: where its bar runs, its entry and its words.
pub struct Tile<'a> {
    /// The entry it shows (its colour and mark; the first of those it stands for).
    pub entry: &'a LegendEntry,
    /// Its words: [`tile_words`] of the entry, with the methods of the entries it stands for
    /// joined ("given (input), first order, exact: Exp-mapped 95 % region — sky blue").
    pub words: String,
    /// The bar's left and right ends.
    pub x: [f64; 2],
    /// The bar's height in the view (down from the top).
    pub y: f64,
}

/// The legend's tiles and the height they take, in the legend view's own units (about one
/// point each at 1024 × 640: the view is [`DESIGN_WIDTH`] wide).
pub struct Tiles<'a> {
    /// The tiles, row by row.
    pub tiles: Vec<Tile<'a>>,
    /// The height of all rows, in the view's units.
    pub height: f64,
}

/// The words of a tile: the label and the colour's name (an axes entry names its three
/// colours in its label).
///
/// ```
/// use posecov::scene::{Color, LegendEntry, Swatch, layout::tile_words};
/// let e = LegendEntry { label: "nominal path".into(), detail: String::new(),
///     color: Color::rgb(0, 114, 178), swatch: Swatch::Line };
/// assert_eq!(tile_words(&e), "nominal path — blue");
/// ```
pub fn tile_words(entry: &LegendEntry) -> String {
    match (entry.swatch, color_name(entry.color)) {
        (Swatch::Axes, _) | (_, None) => entry.label.clone(),
        (_, Some(name)) => format!("{} — {name}", entry.label),
    }
}

/// Colour of the words and bar of an axes entry (its own colour is not used).
pub const AXES_WORDS: Color = Color::rgb(210, 210, 210);

/// Lines the words take in a tile `width` wide (never 0): [`wrap`] at the viewer's label size,
/// widened for its font.
fn lines(text: &str, width: f64) -> usize {
    wrap(text, LABEL_SIZE * VIEWER_WIDER, width - 2.0 * PAD)
        .len()
        .max(1)
}

/// How wide the viewer writes `text` as a label, in points: [`text_width`] at its 13-point
/// size, widened for its font (measured in a screenshot).
///
/// ```
/// use posecov::scene::layout::{text_width, viewer_text_width};
/// assert!(viewer_text_width("v12 first") > text_width("v12 first", 13.0));
/// ```
pub fn viewer_text_width(text: &str) -> f64 {
    text_width(text, LABEL_SIZE) * VIEWER_WIDER
}

/// Advance widths of the printable ASCII characters, `' '` to `'~'`, in Liberation Sans (the
/// figures' bundled font, `assets/fonts/LiberationSans-Regular.ttf`; its `hmtx` table at 2048
/// units per em), in thousandths of an em.
#[rustfmt::skip]
const ASCII_ADVANCES: [u16; 95] = [
    278, 278, 355, 556, 556, 889, 667, 191, 333, 333, 389, 584, 278, 333, 278, 278, // ' '..'/'
    556, 556, 556, 556, 556, 556, 556, 556, 556, 556, 278, 278, 584, 584, 584, 556, // '0'..'?'
    1015, 667, 667, 722, 722, 667, 611, 778, 722, 278, 500, 667, 556, 833, 722, 778, // '@'..'O'
    667, 778, 722, 667, 611, 722, 667, 944, 667, 667, 611, 278, 278, 278, 469, 556, // 'P'..'_'
    333, 556, 556, 500, 556, 556, 278, 556, 556, 222, 222, 500, 222, 833, 556, 556, // '`'..'o'
    556, 556, 333, 500, 278, 556, 500, 722, 500, 500, 500, 334, 260, 334, 584, // 'p'..'~'
];

/// A character's advance width in Liberation Sans, in thousandths of an em: the font's own for
/// ASCII and the signs posecov's words use; a full em for anything else (errs wide).
fn advance(c: char) -> u16 {
    match c {
        ' '..='~' => ASCII_ADVANCES[c as usize - ' ' as usize],
        '·' | '²' | '³' | '¹' => 333,
        '°' => 400,
        '–' => 556,
        '×' => 584,
        '±' | '≈' | '≤' | '≥' | '√' => 549,
        // Greek: σ 617, Σ 618, ρ 569, θ 556, ω 781 …
        'α'..='ω' | 'Α'..='Ω' => 650,
        _ => 1000,
    }
}

/// How wide `text` is set at `size` (points or pixels) in Liberation Sans, the figures' font:
/// the sum of its characters' advance widths (kerning, which only narrows, left out). The
/// figures wrap and place their words with it, and the viewer's legend with it widened for
/// the viewer's font.
///
/// ```
/// use posecov::scene::layout::text_width;
/// assert!((text_width("Hi", 10.0) - 9.44).abs() < 1e-9); // H 722 + i 222 thousandths
/// ```
pub fn text_width(text: &str, size: f64) -> f64 {
    let thousandths: u32 = text.chars().map(|c| u32::from(advance(c))).sum();
    f64::from(thousandths) * size / 1000.0
}

/// `text` broken at spaces into lines no wider than `width` at `size` ([`text_width`]); a
/// single longer word stays whole on its line.
///
/// ```
/// use posecov::scene::layout::wrap;
/// assert_eq!(wrap("first order: Cartesian ellipse", 10.0, 100.0), ["first order: Cartesian", "ellipse"]);
/// assert!(wrap("", 10.0, 100.0).is_empty());
/// ```
pub fn wrap(text: &str, size: f64, width: f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let space = text_width(" ", size);
    let mut used = 0.0;
    for word in text.split_whitespace() {
        let w = text_width(word, size);
        match lines.last_mut() {
            Some(line) if used + space + w <= width => {
                line.push(' ');
                line.push_str(word);
                used += space + w;
            }
            _ => {
                lines.push(word.to_owned());
                used = w;
            }
        }
    }
    lines
}

/// The entries' labels as the viewer's legend shows them: an entry whose words, mark and
/// colour equal an earlier one's is left out (entries that differ only in their detail, the share of samples held by each
/// of two outputs, read the same here), and entries that differ only in the method before
/// their label's first ": " share one tile naming the methods (each view's title names the
/// method it draws). Axes entries, whose labels name what carries the axes, are never joined.
fn grouped(entries: &[LegendEntry]) -> Vec<(&LegendEntry, String)> {
    // (first entry, its methods, the label after the methods or the whole words)
    let mut groups: Vec<(&LegendEntry, Vec<&str>, &str)> = Vec::new();
    for e in entries {
        let split = match e.swatch {
            Swatch::Axes => None,
            _ => e.label.split_once(": "),
        };
        let (method, rest) = split.unwrap_or(("", e.label.as_str()));
        let same = |g: &&mut (&LegendEntry, Vec<&str>, &str)| {
            g.2 == rest
                && g.0.swatch == e.swatch
                && g.0.color == e.color
                && g.1.is_empty() == method.is_empty()
        };
        match groups.iter_mut().find(same) {
            Some(g) => {
                if !g.1.contains(&method) {
                    g.1.push(method);
                }
            }
            None => groups.push((
                e,
                if method.is_empty() {
                    Vec::new()
                } else {
                    vec![method]
                },
                rest,
            )),
        }
    }
    groups
        .into_iter()
        .map(|(e, methods, rest)| {
            let label = if methods.is_empty() {
                rest.to_string()
            } else {
                format!("{}: {rest}", methods.join(", "))
            };
            (e, label)
        })
        .collect()
}

/// Lays the entries out in the number of columns (1–4) that takes the least height, one tile
/// per distinct words: entries that differ only in the method before their label's first
/// ": " share a tile naming the methods.
///
/// ```
/// use posecov::scene::{Color, LegendEntry, Swatch};
/// use posecov::scene::layout::tiles;
/// let e = |label: &str| LegendEntry { label: label.into(), detail: String::new(),
///     color: Color::rgb(175, 175, 175), swatch: Swatch::Dots };
/// let entries = [e("Monte Carlo samples (4000)"), e("nominal path"), e("links"),
///     e("first order: region"), e("exact: region")];
/// let t = tiles(&entries);
/// assert!(t.height > 0.0 && t.height < 100.0, "{}", t.height);
/// assert_eq!(t.tiles.len(), 4);
/// assert_eq!(t.tiles[3].words, "first order, exact: region — grey");
/// assert_eq!(tiles(&[]).height, 0.0);
/// ```
pub fn tiles(entries: &[LegendEntry]) -> Tiles<'_> {
    let grouped: Vec<(&LegendEntry, String)> = grouped(entries)
        .into_iter()
        .map(|(e, label)| {
            let joined = LegendEntry { label, ..e.clone() };
            (e, tile_words(&joined))
        })
        .collect();
    let lay = |columns: usize| {
        let width = DESIGN_WIDTH / columns as f64;
        let mut tiles = Vec::new();
        let mut y = 0.0;
        for chunk in grouped.chunks(columns) {
            let most = chunk
                .iter()
                .map(|(_, words)| lines(words, width))
                .max()
                .unwrap_or(1);
            for (i, (entry, words)) in chunk.iter().enumerate() {
                let x0 = i as f64 * width + PAD;
                tiles.push(Tile {
                    entry,
                    words: words.clone(),
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

#[cfg(test)]
mod tests {
    use super::lines;

    #[test]
    fn words_wrap_at_the_tile_width() {
        assert_eq!(lines("short", 200.0), 1);
        // 200 − 16 = 184 units at 13.5 points: about 27 characters a line.
        let long = "first order: Exp-mapped 95 % region — sky blue";
        assert_eq!(lines(long, 200.0), 2);
        assert_eq!(lines(long, 600.0), 1);
    }
}
