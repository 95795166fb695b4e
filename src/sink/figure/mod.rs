//! Static figures of a [`Scene`] for slides, papers and notebooks: SVG written directly, PNG
//! rendered from it by resvg, PDF converted from it by svg2pdf — pure Rust, no viewer, no
//! system library, text in the bundled Liberation Sans (SIL OFL 1.1, `assets/fonts/`).
//!
//! A figure is the scene projected orthographically on a coordinate [`Plane`], at equal scale
//! on both axes, one panel per 3-D view of the scene (the viewer's layout: a log's frames and
//! its robot-scale view, a graph's before and after, one method each), with every step of a
//! propagation at once ([`Steps::All`], each step's frame numbered; a robot log's messages:
//! the last, as the viewer opens) or the state at one step ([`Steps::At`], what the viewer
//! shows with its time cursor there). A pose graph ([`Scene::states`]) is drawn as its before
//! and its **final** after: with every step, the odometry chain's steps at once and the after
//! view's last state only — the intermediate loop-closure states stay on the viewer's `step`
//! timeline, never overlaid; `--step K` draws the state after K loop closures (the last
//! timeline state with at most K). Around it: the title, the confidence of every drawn
//! region, axes in metres with a grid whose spacing is stated and a scale bar, the legend with
//! colour swatches ([`Scene::legend`]) and the scene's plots against step or time.
//!
//! The same scene gives the same bytes (every number is rounded to 0.01 px and written in
//! order; PNG and PDF are rendered from that text).
//!
//! ```
//! use posecov::app::{Overrides, load, pipeline};
//! use posecov::sink::figure::{FigureOptions, svg};
//! let loaded = load("camera_on_robot").unwrap();
//! let (_, scene) = pipeline(&loaded, &Overrides { samples: Some(200), ..Default::default() }, None).unwrap();
//! let text = svg(&scene, &FigureOptions::default());
//! assert!(text.starts_with("<svg") && text.contains("class=\"legend\""));
//! ```

use std::path::{Path, PathBuf};

use crate::scene::{ItemKind, Scene, SceneItem, Timeline};

pub mod chart;
pub mod labels;
mod layout;
mod panel;
mod raster;
mod region;
mod steps;
pub mod svg;
pub mod world;

pub use steps::MAX_DRAWN_STEPS;
use steps::{drawn_steps, selected};

pub use world::Plane;

use chart::{Axes, PlotPanel, Rect};
use layout::PAGE;
use panel::{cells, fit_line, panels, title_lines};
use svg::{Anchor, Svg};
use world::{Mapping, Pen};

/// Which steps of a propagation a figure draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Steps {
    /// Every step at once, each step's frame labelled with its number.
    #[default]
    All,
    /// The state at this step: per entity, its latest item at or before it (static items
    /// always), as the viewer shows it with the time cursor there.
    At(i64),
}

impl std::str::FromStr for Steps {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "all" {
            return Ok(Self::All);
        }
        s.parse::<i64>()
            .ok()
            .filter(|k| *k >= 0)
            .map(Self::At)
            .ok_or_else(|| format!("{s:?} is not a step: give a step number (0, 1, …) or `all`"))
    }
}

/// How a figure is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FigureOptions {
    /// Width and height in pixels (SVG and PNG) or points (PDF).
    pub size: (u32, u32),
    /// The plane the world is projected on.
    pub plane: Plane,
    /// Which steps are drawn.
    pub steps: Steps,
}

impl Default for FigureOptions {
    /// 1280 × 800 (16:10 slides), the x–y plane, every step.
    fn default() -> Self {
        Self {
            size: (1280, 800),
            plane: Plane::Xy,
            steps: Steps::All,
        }
    }
}

/// A figure's file format, chosen by the output's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureFormat {
    /// `.svg`: the figure as written.
    Svg,
    /// `.png`: rendered by resvg, one pixel per SVG pixel.
    Png,
    /// `.pdf`: vector, converted by svg2pdf (text embedded as a font subset).
    Pdf,
}

impl FigureFormat {
    /// The format of `path`'s extension (`.svg`, `.png`, `.pdf`, any case).
    ///
    /// # Errors
    /// [`FigureError::Extension`] for anything else.
    ///
    /// ```
    /// use posecov::sink::figure::FigureFormat;
    /// assert_eq!(FigureFormat::of(std::path::Path::new("a/b.PNG")).unwrap(), FigureFormat::Png);
    /// assert!(FigureFormat::of(std::path::Path::new("b.jpg")).is_err());
    /// ```
    pub fn of(path: &Path) -> Result<Self, FigureError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("svg") => Ok(Self::Svg),
            Some("png") => Ok(Self::Png),
            Some("pdf") => Ok(Self::Pdf),
            _ => Err(FigureError::Extension(path.to_owned())),
        }
    }
}

/// Why a figure could not be made.
#[derive(Debug, thiserror::Error)]
pub enum FigureError {
    /// The output's extension names no figure format.
    #[error("-o {}: a figure is written as .svg, .png or .pdf (by the file's extension)", .0.display())]
    Extension(PathBuf),
    /// The SVG could not be rendered (a bug: posecov wrote it).
    #[error("rendering the figure: {0}")]
    Render(String),
    /// This build has no PNG/PDF renderer.
    #[error("this posecov was built without the `figure` feature: write an .svg")]
    NoRenderer,
    /// Writing the file failed.
    #[error("writing {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// The figure as SVG text. See the [module docs](self).
pub fn svg(scene: &Scene, options: &FigureOptions) -> String {
    let (w, h) = (f64::from(options.size.0), f64::from(options.size.1));
    let pen = Pen {
        unit: (w.min(h) / PAGE.reference_side).max(PAGE.min_unit),
        font: (w.min(h) / PAGE.reference_side * PAGE.font_at_reference)
            .clamp(PAGE.font_range[0], PAGE.font_range[1]),
    };
    let f = pen.font;
    let mut out = Svg::new(options.size.0, options.size.1);
    let panels = panels(scene, options.steps);
    // Title and what the figure shows.
    let line = w - 2.0 * PAGE.title_at[0] * f;
    out.text(
        [PAGE.title_at[0] * f, PAGE.title_at[1] * f],
        PAGE.title_size * f,
        Anchor::Start,
        "#000",
        &fit_line(&scene.title, PAGE.title_size * f, line),
    );
    let steps = scene.steps();
    let mut about = about_steps(scene, options, &steps);
    // Body: the world on the left, the legend and the plots on the right.
    let top = PAGE.top * f;
    let column = if scene.legend.is_empty() && scene.plots.is_empty() {
        0.0
    } else {
        (PAGE.column_share * w).max(PAGE.column_min * f)
    };
    let body = Rect {
        x: 0.0,
        y: top,
        w: (w - column).max(PAGE.min_size),
        h: h - top,
    };
    let grids = draw_panels(&mut out, &panels, options, body, pen, steps.len() > 1);
    if let [grid] = grids.as_slice() {
        about.push(format!("grid {}", chart::length_label(*grid)));
    }
    if panels.len() > 1 {
        about.push("one panel per view, grid lines a scale bar apart".to_owned());
    }
    // A robot log's scene is on a time line (the scene says so: its timeline).
    let log = scene.timeline != Timeline::Step;
    if log && options.steps == Steps::All {
        about.push("the last message, every drawn one's outline faint".to_owned());
    }
    out.text(
        [PAGE.title_at[0] * f, PAGE.about_y * f],
        PAGE.about_size * f,
        Anchor::Start,
        "#444",
        &fit_line(&about.join(" · "), PAGE.about_size * f, line),
    );
    if column > 0.0 {
        let col = Rect {
            x: w - column + PAGE.column_inset * f,
            y: top,
            w: column - PAGE.column_trim * f,
            h: h - top - PAGE.column_bottom * f,
        };
        draw_column(&mut out, scene, options, col, pen);
    }
    out.finish()
}

/// What the figure shows, in words, before its worlds are drawn: the confidence, the plane,
/// and which states or steps (a graph's before and after, a propagation's steps at once or
/// one step).
fn about_steps(scene: &Scene, options: &FigureOptions, steps: &[i64]) -> Vec<String> {
    let (right, up) = options.plane.names();
    let mut about = vec![format!("{right}–{up} plane")];
    if let Some(p) = scene.confidence {
        about.insert(0, format!("regions at {} confidence", p));
    }
    let graph_states = scene.states.as_ref().map(|s| &s.steps);
    match (options.steps, graph_states) {
        (Steps::All, Some(states)) => {
            if let Some(last) = states.last() {
                about.push(format!(
                    "before, and after: the final solution ({} loop closures)",
                    last.closures
                ));
            }
        }
        (Steps::At(k), Some(states)) => {
            let step = scene
                .states
                .as_ref()
                .and_then(|s| s.step_after(k.max(0) as u64));
            if let Some(state) = states.iter().find(|s| Some(s.step) == step) {
                about.push(format!(
                    "after {} loop closures (--step {k})",
                    state.closures
                ));
            }
        }
        _ => {}
    }
    match (options.steps, steps.first(), steps.last()) {
        _ if graph_states.is_some() => {}
        (Steps::All, Some(a), Some(b)) if a != b => {
            let drawn = drawn_steps(scene);
            if drawn.len() == steps.len() {
                about.push(format!("steps {a}–{b} at once"));
            } else {
                let list: Vec<String> = drawn.iter().map(i64::to_string).collect();
                about.push(format!("steps {a}–{b}: {} drawn", list.join(", ")));
            }
        }
        (Steps::At(k), Some(_), Some(_)) => about.push(format!("step {k}")),
        _ => {}
    }
    about
}

/// Draws each world panel in its cell of `body`, its name (several panels) in at most two
/// lines above it; returns each panel's grid spacing (metres). Every panel keeps the same room
/// for its name, so the worlds line up.
fn draw_panels(
    out: &mut Svg,
    panels: &[panel::Panel<'_>],
    options: &FigureOptions,
    body: Rect,
    pen: Pen,
    steps: bool,
) -> Vec<f64> {
    let f = pen.font;
    let cells = cells(body, panels.len());
    let titles: Vec<Vec<String>> = panels
        .iter()
        .zip(&cells)
        .map(|(panel, cell)| {
            panel.title.map_or_else(Vec::new, |t| {
                title_lines(t, f, cell.w - PAGE.world_across * f)
            })
        })
        .collect();
    let title_room =
        titles.iter().map(Vec::len).max().unwrap_or(0) as f64 * PAGE.panel_title_line * f;
    let mut grids = Vec::with_capacity(panels.len());
    for (i, ((panel, cell), title)) in panels.iter().zip(cells).zip(&titles).enumerate() {
        // The world inside the cell, with room for the axes' ticks and titles.
        let area = Rect {
            x: cell.x + PAGE.world_left * f,
            y: cell.y + title_room,
            w: (cell.w - PAGE.world_across * f).max(PAGE.min_size),
            h: (cell.h - title_room - PAGE.world_below * f).max(PAGE.min_size),
        };
        for (k, line) in title.iter().enumerate() {
            let y =
                cell.y + PAGE.panel_title_line * f * (k as f64 + 1.0) - PAGE.panel_title_raise * f;
            out.text([area.x, y], f, Anchor::Start, "#222", line);
        }
        let clip = if i == 0 {
            "world".to_owned()
        } else {
            format!("world{i}")
        };
        grids.push(draw_world(
            out,
            &panel.items,
            options,
            (area, &clip),
            pen,
            steps,
        ));
    }
    grids
}

/// Draws the right column `col`: the legend, then the plots below it (the legend takes at
/// most half the column when there are plots).
fn draw_column(out: &mut Svg, scene: &Scene, options: &FigureOptions, col: Rect, pen: Pen) {
    let f = pen.font;
    let max_legend = if scene.plots.is_empty() {
        col.h
    } else {
        PAGE.legend_share * col.h
    };
    let used = chart::legend(
        out,
        Rect {
            h: max_legend,
            ..col
        },
        &scene.legend,
        pen,
    );
    draw_plots(
        out,
        scene,
        options,
        Rect {
            y: col.y + used + PAGE.legend_gap * f,
            h: col.h - used - PAGE.legend_gap * f,
            ..col
        },
        pen,
    );
}

/// Draws the world panel; returns the grid spacing (metres).
fn draw_world(
    out: &mut Svg,
    items: &[&SceneItem],
    options: &FigureOptions,
    (area, clip): (Rect, &str),
    pen: Pen,
    steps: bool,
) -> f64 {
    let plane = options.plane;
    let mut extent = Vec::new();
    for item in items {
        world::extent_points(item, plane, &mut extent);
    }
    // Clouds count by their central 99.6 % per axis: one far sample does not shrink the rest.
    for item in items {
        if let ItemKind::Points(cloud) = &item.kind {
            for axis in 0..2 {
                let mut v: Vec<f64> = cloud
                    .positions
                    .iter()
                    .map(|p| plane.project(*p)[axis])
                    .collect();
                if v.is_empty() {
                    continue;
                }
                v.sort_by(f64::total_cmp);
                let lo = v[(v.len() as f64 * 0.002) as usize];
                let hi = v[((v.len() as f64 * 0.998) as usize).min(v.len() - 1)];
                let other = extent.first().map_or(0.0, |p: &[f64; 2]| p[1 - axis]);
                for x in [lo, hi] {
                    let mut p = [other; 2];
                    p[axis] = x;
                    extent.push(p);
                }
            }
        }
    }
    let finite = extent
        .iter()
        .filter(|p| p[0].is_finite() && p[1].is_finite());
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in finite {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !(lo[0].is_finite() && hi[0].is_finite()) {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    let span = [(hi[0] - lo[0]).max(1e-6), (hi[1] - lo[1]).max(1e-6)];
    let biggest = span[0].max(span[1]);
    let span = span.map(|s| s.max(0.05 * biggest) * 1.1);
    let scale = (area.w / span[0]).min(area.h / span[1]);
    let center = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let m = Mapping {
        scale,
        center,
        origin: [area.x + 0.5 * area.w, area.y + 0.5 * area.h],
    };
    let bl = m.metres([area.x, area.bottom()]);
    let tr = m.metres([area.right(), area.y]);
    let step = world_step(
        chart::nice_step(area.w.max(area.h) / scale, 8),
        scale,
        [bl[0], tr[0]],
        pen,
    );
    let xs: Vec<(f64, f64)> = chart::ticks(bl[0], tr[0], step)
        .into_iter()
        .map(|v| (v, m.px([v, 0.0])[0]))
        .collect();
    let ys: Vec<(f64, f64)> = chart::ticks(bl[1], tr[1], step)
        .into_iter()
        .map(|v| (v, m.px([0.0, v])[1]))
        .collect();
    let (right, up) = plane.names();
    let (xt, yt) = (format!("{right} (m)"), format!("{up} (m)"));
    let axes = Axes {
        area,
        x: (&xs, step),
        y: (&ys, step),
        titles: (&xt, &yt),
    };
    axes.grid(out, pen);
    area.clip(out, clip);
    out.open(&format!("class=\"world\" clip-path=\"url(#{clip})\""));
    region::draw_regions(out, items, plane, &m, pen);
    world::draw_clouds(out, items, plane, &m, pen);
    world::draw_lines(out, items, plane, &m, pen);
    labels::draw_labels(
        out,
        items,
        (plane, &m),
        pen,
        (steps && options.steps == Steps::All, area),
        &[chart::scale_bar_box(area, step, scale, pen)],
    );
    out.close();
    axes.frame(out, pen);
    chart::scale_bar(out, area, step, scale, pen);
    step
}

/// The world panel's grid step, `step` widened (1, 2, 5 × 10ᵏ up) until the x tick labels over
/// `x_range` stand apart: each tick at least its widest label plus one font size from the
/// next (a close-up's many-digit labels, "29.2 29.4 …", would otherwise run together). The
/// same step serves both axes and the scale bar, so the grid stays square.
fn world_step(mut step: f64, scale: f64, x_range: [f64; 2], pen: Pen) -> f64 {
    for _ in 0..12 {
        let widest = chart::ticks(x_range[0], x_range[1], step)
            .into_iter()
            .map(|v| svg::text_width(&chart::tick_label(v, step), pen.font))
            .fold(0.0, f64::max);
        if step * scale >= widest + pen.font {
            break;
        }
        step = chart::nice_step(2.0 * step, 1);
    }
    step
}

/// Draws the scene's plots stacked in `area` (as many as fit at a readable height).
fn draw_plots(out: &mut Svg, scene: &Scene, options: &FigureOptions, area: Rect, pen: Pen) {
    let f = pen.font;
    let fit = ((area.h / (PAGE.plot_height * f)).floor() as usize).min(scene.plots.len());
    if fit == 0 {
        return;
    }
    let first_ns = scene
        .series
        .iter()
        .flat_map(|s| s.points.first())
        .map(|p| p.0)
        .min()
        .unwrap_or(0);
    let (x_title, x_of): (&str, Box<dyn Fn(i64) -> f64>) = match scene.timeline {
        Timeline::Step => ("step", Box::new(|k| k as f64)),
        Timeline::Stamp | Timeline::Elapsed => (
            "time (s)",
            Box::new(move |ns| (ns - first_ns) as f64 * 1e-9),
        ),
    };
    let height = area.h / fit as f64;
    for (i, plot) in scene.plots.iter().take(fit).enumerate() {
        let series: Vec<&crate::scene::ScalarSeries> =
            scene.series.iter().filter(|s| s.plot == plot.id).collect();
        let panel = PlotPanel {
            title: plot.label(),
            series,
            x_title,
            x_of: &*x_of,
            marker: match options.steps {
                Steps::At(k) if scene.timeline == Timeline::Step => Some(k as f64),
                _ => None,
            },
        };
        let rect = Rect {
            y: area.y + height * i as f64,
            h: height,
            ..area
        };
        panel.draw(out, rect, &format!("plot{i}"), pen);
    }
}

/// The figure in `format`.
///
/// # Errors
/// [`FigureError::Render`] if the SVG cannot be rendered (a bug), [`FigureError::NoRenderer`]
/// for PNG or PDF in a build without the `figure` feature.
pub fn render(
    scene: &Scene,
    options: &FigureOptions,
    format: FigureFormat,
) -> Result<Vec<u8>, FigureError> {
    let text = svg(scene, options);
    match format {
        FigureFormat::Svg => Ok(text.into_bytes()),
        FigureFormat::Png => raster::png(&text),
        FigureFormat::Pdf => raster::pdf(&text),
    }
}

/// Writes the figure to `path` in the format of its extension, whole or not at all (a
/// temporary file beside it, renamed when complete).
///
/// # Errors
/// [`FigureError`]: the extension, rendering, or the file.
pub fn write(scene: &Scene, options: &FigureOptions, path: &Path) -> Result<(), FigureError> {
    let format = FigureFormat::of(path)?;
    let bytes = render(scene, options, format)?;
    let io = |source| FigureError::Io {
        path: path.to_owned(),
        source,
    };
    let mut partial = path.as_os_str().to_owned();
    partial.push(".partial");
    let partial = PathBuf::from(partial);
    std::fs::write(&partial, &bytes).map_err(io)?;
    std::fs::rename(&partial, path).map_err(|e| {
        let _ = std::fs::remove_file(&partial);
        io(e)
    })
}
