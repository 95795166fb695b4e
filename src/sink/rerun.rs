//! Scene → Rerun 0.36 archetypes (the layout is [`super::blueprint`]'s).
//!
//! One item becomes one row on its own entity path (so each pose × method toggles on its
//! own), with all its instances batched in the row: a cloud is one `Points3D`, a path of
//! ellipsoids one `Ellipsoids3D`, a set of triads one `LineStrips3D`. The rows of one path
//! (with the same components, all static or all timed) go out together, up to
//! `ROWS_PER_CHUNK` (256) rows or `BYTES_PER_CHUNK` (4 MiB) a chunk (`Rows`). This is also the only place where `f64` becomes
//! `f32`.

use std::sync::atomic::{AtomicBool, Ordering};

use ::rerun as rr;
use rr::AsComponents;
use rr::log::{Chunk, RowId};

use super::SinkError;
use super::rows::{ItemRows, Rows, slices};
use crate::scene::{
    self, Arrows, Color, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, PointCloud, QuatXyzw,
    ScalarSeries, Scene, SceneItem, Surface, Timing, Triads, Vec3, rotate,
};

/// Name of the sequence timeline that [`Timing::Step`] items are logged on.
pub const STEP_TIMELINE: &str = "step";
/// Name of the time timeline that [`Timing::Stamp`] items (robot logs) are logged on.
pub const STAMP_TIMELINE: &str = "stamp";

/// Whether [`log_scene_cancellable`] logged everything.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogOutcome {
    /// Every item and series was logged.
    Complete,
    /// The cancel flag was raised; everything before `next_step` (and all static items) was
    /// logged, nothing from `next_step` on.
    Cancelled {
        /// First step that was *not* logged (`None`: cancelled among the static items).
        next_step: Option<i64>,
    },
}

/// Logs a validated scene to `rec` (see [`log_scene_cancellable`]).
///
/// # Errors
/// [`SinkError::Scene`] if the scene is invalid (nothing is logged then), or an SDK error.
pub fn log_scene(rec: &rr::RecordingStream, scene: &Scene) -> Result<(), SinkError> {
    log_scene_cancellable(rec, scene, &AtomicBool::new(false)).map(|_| ())
}

/// Logs `scene` to `rec`: validates it first (so NaN never reaches the viewer), then the
/// world's view coordinates (right-handed, z up), the description and the legend's tiles
/// ([`super::legend`]; static), every static
/// item, then the items of each step in ascending order, then the plot series (on a stamp
/// timeline, a robot log's, the series come before the items). `cancel` is
/// checked before every item: when it is raised, logging stops at a step boundary-or-item and
/// the outcome says where (what was logged stays a consistent prefix).
///
/// # Errors
/// [`SinkError::Scene`] if the scene is invalid (nothing is logged then), or an SDK error.
pub fn log_scene_cancellable(
    rec: &rr::RecordingStream,
    scene: &Scene,
    cancel: &AtomicBool,
) -> Result<LogOutcome, SinkError> {
    scene.validate()?;
    rec.set_log_time_enabled(false);
    rec.set_log_tick_enabled(false);
    // The recording's name, sent like `send_recording_name` but as a chunk in sequence.
    let name = rr::RecordingInfo::update_fields().with_name(scene.title.as_str());
    send(
        rec,
        rr::EntityPath::properties(),
        rr::TimePoint::default(),
        &[&name],
    )?;
    send(
        rec,
        scene::WORLD,
        rr::TimePoint::default(),
        // z is up in every scene (planar ones lie in the x–y plane, the grid's plane); each
        // view's camera says where the eye is.
        &[&rr::ViewCoordinates::RIGHT_HAND_Z_UP()],
    )?;
    send(
        rec,
        scene::DESCRIPTION,
        rr::TimePoint::default(),
        &[&rr::TextDocument::from_markdown(
            scene.description_markdown.as_str(),
        )],
    )?;
    if !scene.plots_below {
        // Every time, even empty: a new scene's legend replaces the last one's whole.
        super::legend::log_legend(rec, scene)?;
    }
    // A robot log's plots (on the stamp timeline) are small and what a reader looks at
    // first: they go before its items, so a viewer still loading the recording shows them.
    let series_first = scene.timeline != scene::Timeline::Step;
    if series_first {
        for series in &scene.series {
            log_series(rec, series, scene.timeline)?;
        }
    }
    if let cancelled @ LogOutcome::Cancelled { .. } = log_items(rec, scene, cancel)? {
        return Ok(cancelled);
    }
    if !series_first {
        for series in &scene.series {
            log_series(rec, series, scene.timeline)?;
        }
    }
    Ok(LogOutcome::Complete)
}

/// Logs the items of a part scene (a later block of a large Monte Carlo sample, from
/// [`crate::draw::particle_part`]) after the main scene: validated, then its items in log
/// order, nothing else (no name, view coordinates, description or series). `cancel` as in
/// [`log_scene_cancellable`].
///
/// # Errors
/// [`SinkError::Scene`] if the part is invalid (nothing is logged then), or an SDK error.
///
/// ```
/// use std::sync::atomic::AtomicBool;
/// use posecov::sink::{RecordingIds, Sink, log_part_cancellable, open_stream};
/// let scene = posecov::scene::Scene::new("part", "");
/// let (rec, guard) = open_stream(&Sink::Memory, &RecordingIds::for_scenario("doc", 0), &scene)?;
/// log_part_cancellable(&rec, &scene, &AtomicBool::new(false))?;
/// assert!(!guard.finish(rec)?.unwrap_or_default().is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn log_part_cancellable(
    rec: &rr::RecordingStream,
    part: &Scene,
    cancel: &AtomicBool,
) -> Result<LogOutcome, SinkError> {
    part.validate()?;
    log_items(rec, part, cancel)
}

/// Every item of `scene` in log order, stopping when `cancel` is raised; the rows are sent
/// (the last ones when the items end or stop: what was logged is a consistent prefix).
fn log_items(
    rec: &rr::RecordingStream,
    scene: &Scene,
    cancel: &AtomicBool,
) -> Result<LogOutcome, SinkError> {
    use rayon::prelude::*;
    let items: Vec<&SceneItem> = scene.items_in_log_order();
    let mut rows = Rows::default();
    // Items are turned into Arrow arrays on every core, a slice at a time (the arrays of one
    // slice in memory at once), then grouped and sent in log order.
    for slice in slices(&items) {
        let serialized: Vec<ItemRows> = slice
            .par_iter()
            .map(|item| item_rows(item, scene.timeline))
            .collect();
        for (item, item_rows) in slice.iter().zip(serialized) {
            if cancel.load(Ordering::Relaxed) {
                let next_step = match item.timing {
                    Timing::Static | Timing::Stamp(_) => None,
                    Timing::Step(k) => Some(k),
                };
                rows.send_all(rec)?;
                return Ok(LogOutcome::Cancelled { next_step });
            }
            for row in item_rows.0 {
                rows.push(row);
            }
            rows.send_full(rec)?;
        }
    }
    rows.send_all(rec)?;
    Ok(LogOutcome::Complete)
}

/// Where an item of `timing` is logged: nowhere on a timeline (static), at a step of the `step`
/// sequence, or at a stamp (nanoseconds) of the `stamp` timeline — a date, or a duration when
/// the scene's `timeline` is [`Timeline::Elapsed`](scene::Timeline::Elapsed).
pub(super) fn time_point(timing: Timing, timeline: scene::Timeline) -> rr::TimePoint {
    match timing {
        Timing::Static => rr::TimePoint::default(),
        Timing::Step(k) => {
            rr::TimePoint::default().with(rr::Timeline::new_sequence(STEP_TIMELINE), k)
        }
        Timing::Stamp(ns) => rr::TimePoint::default().with(
            match timeline {
                scene::Timeline::Elapsed => rr::Timeline::new_duration(STAMP_TIMELINE),
                scene::Timeline::Step | scene::Timeline::Stamp => {
                    rr::Timeline::new_timestamp(STAMP_TIMELINE)
                }
            },
            ns,
        ),
    }
}

/// Sends one row with all `parts` as one chunk: no log time, no batcher, fixed order.
pub(super) fn send(
    rec: &rr::RecordingStream,
    path: impl Into<rr::EntityPath>,
    timepoint: rr::TimePoint,
    parts: &[&dyn AsComponents],
) -> Result<(), SinkError> {
    let path = path.into();
    let batches = parts.iter().flat_map(|p| p.as_serialized_batches());
    let chunk = Chunk::builder(path.clone())
        .with_serialized_batches(RowId::new(), timepoint, batches)
        .build()
        .map_err(|err| SinkError::Chunk {
            path: path.to_string(),
            message: err.to_string(),
        })?;
    rec.send_chunk(chunk);
    Ok(())
}

/// The rows `item` is logged as.
fn item_rows(item: &SceneItem, timeline: scene::Timeline) -> ItemRows {
    let mut rows = ItemRows::default();
    let (path, at) = (item.path.as_str(), time_point(item.timing, timeline));
    match &item.kind {
        ItemKind::Frame(frame) => log_frame(&mut rows, path, at, frame),
        ItemKind::Triads(triads) => rows.add(path, at, &[&triad_strips(triads)]),
        ItemKind::Points(cloud) => rows.add(path, at, &[&points(cloud)]),
        ItemKind::Ellipsoids(e) => rows.add(path, at, &[&ellipsoids(e)]),
        ItemKind::Surface(surface) => rows.add(path, at, &[&mesh(surface)]),
        ItemKind::LineStrips(strips) => rows.add(path, at, &[&line_strips(strips)]),
        ItemKind::Arrows(arrows) => rows.add(path, at, &[&arrows3d(arrows)]),
        ItemKind::Text(markdown) => rows.add(
            path,
            at,
            &[&rr::TextDocument::from_markdown(markdown.as_str())],
        ),
    }
    rows
}

/// A frame is a transform of its own entity plus its axes; its viewer label
/// ([`Frame::viewer_label`]) is a tiny point at the frame's origin (in the frame's coordinates, hence `[0, 0, 0]`).
fn log_frame(rows: &mut ItemRows, path: &str, at: rr::TimePoint, frame: &Frame) {
    let transform =
        rr::Transform3D::from_translation_rotation(v3(&frame.translation), quat(&frame.rotation));
    let axes = rr::TransformAxes3D::new(f(frame.axis_length));
    match frame.viewer_label() {
        None => rows.add(path, at, &[&transform, &axes]),
        Some(label) => {
            let marker = rr::Points3D::new([[0.0f32; 3]])
                .with_radii([f(0.04 * frame.axis_length)])
                .with_colors([color(Color::rgb(128, 128, 128))])
                .with_labels([label])
                .with_show_labels(true);
            rows.add(path, at, &[&transform, &axes, &marker]);
        }
    }
}

/// N triads as 3N two-point strips coloured x red, y green, z blue.
fn triad_strips(triads: &Triads) -> rr::LineStrips3D {
    const AXIS_COLORS: [Color; 3] = [
        Color::rgb(230, 60, 60),
        Color::rgb(60, 200, 60),
        Color::rgb(70, 110, 255),
    ];
    let mut strips = Vec::with_capacity(3 * triads.translations.len());
    let mut colors = Vec::with_capacity(strips.capacity());
    for (t, q) in triads.translations.iter().zip(&triads.rotations) {
        for (axis, c) in AXIS_COLORS.iter().enumerate() {
            let mut unit = [0.0; 3];
            unit[axis] = triads.axis_length;
            let tip = rotate(q, unit);
            strips.push([v3(t), v3(&[t[0] + tip[0], t[1] + tip[1], t[2] + tip[2]])]);
            colors.push(color(*c));
        }
    }
    rr::LineStrips3D::new(strips)
        .with_colors(colors)
        .with_radii([f(triads.line_radius)])
}

fn points(cloud: &PointCloud) -> rr::Points3D {
    rr::Points3D::new(cloud.positions.iter().map(v3))
        .with_colors([color(cloud.color)])
        .with_radii([f(cloud.radius)])
}

fn ellipsoids(e: &Ellipsoids) -> rr::Ellipsoids3D {
    let fill = match e.fill {
        FillMode::Solid => rr::FillMode::Solid,
        FillMode::MajorWireframe => rr::FillMode::MajorWireframe,
        FillMode::DenseWireframe => rr::FillMode::DenseWireframe,
        FillMode::TransparentFillMajorWireframe => rr::FillMode::TransparentFillMajorWireframe,
    };
    let archetype = rr::Ellipsoids3D::from_centers_and_half_sizes(
        e.shapes.iter().map(|s| v3(&s.center)),
        e.shapes.iter().map(|s| v3(&s.half_sizes)),
    )
    .with_quaternions(e.shapes.iter().map(|s| quat(&s.rotation)))
    .with_colors([color(e.color)])
    .with_fill_mode(fill)
    .with_line_radii([f(e.line_radius)]);
    match &e.label {
        Some(label) => archetype.with_labels([label.as_str()]),
        None => archetype,
    }
}

fn mesh(surface: &Surface) -> rr::Mesh3D {
    let archetype = rr::Mesh3D::new(surface.vertices.iter().map(v3))
        .with_triangle_indices(
            surface
                .triangles
                .iter()
                .map(|t| rr::TriangleIndices::from(*t)),
        )
        .with_albedo_factor(color(surface.color).0);
    if surface.normals.is_empty() {
        archetype
    } else {
        archetype.with_vertex_normals(surface.normals.iter().map(v3))
    }
}

fn line_strips(strips: &LineStrips) -> rr::LineStrips3D {
    rr::LineStrips3D::new(
        strips
            .strips
            .iter()
            .map(|s| s.iter().map(v3).collect::<Vec<_>>()),
    )
    .with_colors([color(strips.color)])
    .with_radii([f(strips.radius)])
}

fn arrows3d(arrows: &Arrows) -> rr::Arrows3D {
    rr::Arrows3D::from_vectors(arrows.vectors.iter().map(v3))
        .with_origins(arrows.origins.iter().map(v3))
        .with_colors([color(arrows.color)])
        .with_radii([f(arrows.radius)])
}

/// Series style (static, once: a line, or marks) and all samples in one column chunk.
fn log_series(
    rec: &rr::RecordingStream,
    series: &ScalarSeries,
    timeline: scene::Timeline,
) -> Result<(), SinkError> {
    let path = series.path();
    if series.marks {
        let style = rr::SeriesPoints::new()
            .with_names([series.name.as_str()])
            .with_colors([color(series.color)])
            .with_marker_sizes([f(series.width)]);
        send(rec, path.as_str(), rr::TimePoint::default(), &[&style])?;
    } else {
        let style = rr::SeriesLines::new()
            .with_names([series.name.as_str()])
            .with_colors([color(series.color)])
            .with_widths([f(series.width)]);
        send(rec, path.as_str(), rr::TimePoint::default(), &[&style])?;
    }
    log_samples(rec, series, timeline)
}

/// Points added to lines already logged (their style with them): each series' samples only,
/// at its path (its generation's). A live view streams a message's points so, between whole
/// pictures ([`crate::draw::log::message_points`]).
///
/// # Errors
/// [`SinkError::Scene`] for a value beyond `f32` or not finite (nothing is logged then), or
/// an SDK error.
///
/// ```
/// use posecov::scene::{Color, PlotId, ScalarSeries, Scene, Timeline};
/// use posecov::sink::{RecordingIds, Sink, log_points, open_stream};
/// let (rec, guard) = open_stream(&Sink::Memory, &RecordingIds::for_scenario("doc", 0), &Scene::new("t", ""))?;
/// let point = ScalarSeries::new(PlotId::new("sigma_position"), "odom/x", "σx", Color::rgb(0, 0, 0), 1.5, vec![(5, 1.0)]);
/// log_points(&rec, &[point.clone()], Timeline::Stamp)?;
/// let mut bad = point;
/// bad.points[0].1 = f64::NAN;
/// assert!(log_points(&rec, &[bad], Timeline::Stamp).is_err());
/// # guard.finish(rec)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn log_points(
    rec: &rr::RecordingStream,
    series: &[ScalarSeries],
    timeline: scene::Timeline,
) -> Result<(), SinkError> {
    let mut part = Scene::new(String::new(), String::new());
    part.timeline = timeline;
    part.series = series.to_vec();
    part.validate()?;
    for s in series {
        log_samples(rec, s, timeline)?;
    }
    Ok(())
}

/// A series' samples, one column chunk (its style is logged apart).
fn log_samples(
    rec: &rr::RecordingStream,
    series: &ScalarSeries,
    timeline: scene::Timeline,
) -> Result<(), SinkError> {
    if series.points.is_empty() {
        return Ok(());
    }
    let path = series.path();
    let times = series.points.iter().map(|p| p.0);
    let steps = match timeline {
        scene::Timeline::Step => rr::TimeColumn::new_sequence(STEP_TIMELINE, times),
        scene::Timeline::Elapsed => rr::TimeColumn::new_duration_nanos(STAMP_TIMELINE, times),
        scene::Timeline::Stamp => {
            rr::TimeColumn::new_timestamp_nanos_since_epoch(STAMP_TIMELINE, times)
        }
    };
    let values = rr::Scalars::new(series.points.iter().map(|p| p.1))
        .columns_of_unit_batches()
        .map_err(rr::RecordingStreamError::from)?;
    rec.send_columns(path.as_str(), [steps], values)?;
    Ok(())
}

/// `f64 → f32` at the rendering boundary (validated values fit).
fn f(x: f64) -> f32 {
    x as f32
}

fn v3(v: &Vec3) -> [f32; 3] {
    v.map(f)
}

fn quat(q: &QuatXyzw) -> rr::Quaternion {
    rr::Quaternion::from_xyzw(q.map(f))
}

fn color(c: Color) -> rr::Color {
    let [r, g, b, a] = c.0;
    rr::Color::from_unmultiplied_rgba(r, g, b, a)
}
