//! The layout sent with a scene, written as Rerun blueprint archetypes.
//!
//! Rerun 0.36's Rust builder (`rerun::blueprint::Spatial3DView`) has no setter for a 3-D view's
//! eye (`EyeControls3D`) or for an entity's default visibility (`EntityBehavior`), and keeps its
//! view ids private. A blueprint is an ordinary store of archetypes, though — the Python SDK
//! writes it that way — so this module logs the same archetypes itself to a blueprint stream
//! (`RecordingStreamBuilder::blueprint().memory()`) and hands the messages to
//! [`RecordingStream::send_blueprint`](rr::RecordingStream::send_blueprint) with an activation
//! command, exactly as `Blueprint::send` does:
//!
//! - `viewport`: `ViewportBlueprint` (root container, no automatic views or layout);
//! - `container/<id>`: `ContainerBlueprint` (kind, contents, shares);
//! - `view/<id>`: `ViewBlueprint` (class, name, origin), `view/<id>/ViewContents` (the query),
//!   `view/<id>/EyeControls3D` (a view property: eye position, look target, up);
//! - `view/<id>/ViewContents/overrides/<entity>/visualizers`: `EntityBehavior { visible:
//!   false }` for entities that start hidden (where the viewer's own eye toggle writes it; the
//!   children inherit it);
//! - `blueprint_panel`, `selection_panel`, `time_panel`: panel states.
//!
//! Ids are fixed per position in the layout, so the blueprint's content is deterministic too.

use ::rerun as rr;
use rr::blueprint::components::{
    ContainerKind, Eye3DKind, IncludedContent, PanelState, PlayState, QueryExpression,
    RootContainer, RowShare, TimelineName, ViewClass,
};
use rr::components::{Name, Position3D, Vector3D, Visible};
use rr::external::re_log_types::BlueprintActivationCommand;
use rr::external::re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, EntityBehavior, EyeControls3D, LineGrid3D, PanelBlueprint, PlotLegend,
    ScalarAxis, TimeAxis, TimePanelBlueprint, ViewBlueprint, ViewContents, ViewportBlueprint,
    VisualBounds2D,
};
use rr::external::re_sdk_types::blueprint::components::{
    ColumnShare, Corner2D, GridColumns, GridSpacing, TimeRange,
};
use rr::external::re_sdk_types::datatypes::{self, Range1D, Range2D, TimeInt, TimeRangeBoundary};
use rr::external::re_sdk_types::datatypes::{Float32, UInt32, Uuid};

use super::legend::{LEGEND, LEGEND_TEXT};
use super::rerun::{STAMP_TIMELINE, STEP_TIMELINE};
use super::{APPLICATION_ID, SinkError};
use crate::scene::layout::{
    DESIGN_HEIGHT, DESIGN_WIDTH, LEFT_SHARE, LegendPane, RIGHT_SHARE, legend_pane, legend_share,
    tiles, views_over_plots,
};
use crate::scene::{self, Camera, Corner, Scene, View3d};

pub use crate::scene::layout::PLOTS_PER_ROW;

/// Sends the layout of `scene` through `rec` and makes it the active and default blueprint:
/// the 3-D views on the left (three fifths; several views in a grid, each with its camera, its
/// hidden entities and its ground grid's spacing in its title) above the legend view
/// ([`super::legend`], as tall as its tiles), on the right the description above one
/// time-series view per [`Plot`](crate::scene::Plot) (its title and unit as the view's name,
/// its value range when the scene fits one, its legend in the plot's corner; several plots are
/// tabs of one pane); a legend too large for tiles ([`LegendPane::Text`]) is a list in words
/// between the description and the plots, the 3-D views keeping the whole left column; with [`Scene::plots_below`], the plots in rows of at most
/// [`PLOTS_PER_ROW`] under the views (a log with `--reference` adds its NEES plots, which a
/// single row would squeeze to a fifth of the width each) and the description the whole
/// right column (two fifths), no legend view. Panels collapsed; the time
/// panel shows the `step` timeline following the latest data, so a recording opens on its
/// last step.
///
/// # Errors
/// An SDK error building the blueprint.
///
/// ```
/// use posecov::sink::send_layout;
/// let (rec, storage) = rerun::RecordingStreamBuilder::new("doc").memory()?;
/// send_layout(&rec, &posecov::scene::Scene::new("t", "d"))?;
/// assert!(!storage.take().is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn send_layout(rec: &rr::RecordingStream, scene: &Scene) -> Result<(), SinkError> {
    let (messages, activation) = layout_messages(scene)?;
    rec.send_blueprint(messages, activation);
    Ok(())
}

/// The blueprint messages of [`send_layout`] and their activation command. Ids are made in
/// creation order (the root after its children), so one scene gives the same messages.
fn layout_messages(
    scene: &Scene,
) -> Result<(Vec<rr::log::LogMsg>, BlueprintActivationCommand), SinkError> {
    let (bp, storage) = rr::RecordingStreamBuilder::new(APPLICATION_ID)
        .blueprint()
        .memory()?;
    bp.set_time_sequence("blueprint", 0);
    let mut ids = Ids::default();
    let left = views_and_legend(&bp, &mut ids, scene)?;
    let description = log_view(
        &bp,
        &mut ids,
        "TextDocument",
        "Description",
        scene::DESCRIPTION,
    )?;
    let legend = match legend_pane(scene, scene.views.len()) {
        LegendPane::Text => Some(log_view(
            &bp,
            &mut ids,
            "TextDocument",
            &legend_title(scene),
            LEGEND_TEXT,
        )?),
        LegendPane::Tiles | LegendPane::None => None,
    };
    let plots = plot_views(&bp, &mut ids, scene)?;
    let root = root_container(&bp, &mut ids, scene, left, (description, legend), &plots)?;
    bp.log(
        "viewport",
        &ViewportBlueprint::new()
            .with_root_container(RootContainer(root.uuid))
            .with_auto_layout(false)
            .with_auto_views(false),
    )?;
    panels(&bp, scene)?;
    let messages = storage.take();
    let store = messages
        .first()
        .map(|m| m.store_id().clone())
        .ok_or_else(|| SinkError::Flush("the blueprint stream produced no messages".into()))?;
    Ok((messages, BlueprintActivationCommand::make_active(store)))
}

/// The scene's 3-D views (one default view when it has none; several in a grid), with the
/// legend view under them when it has one, as tall as its tiles need at 1024 × 640.
fn views_and_legend(
    bp: &rr::RecordingStream,
    ids: &mut Ids,
    scene: &Scene,
) -> Result<String, SinkError> {
    let default_view = [View3d {
        name: "3D".to_owned(),
        ..Default::default()
    }];
    let views: &[View3d] = if scene.views.is_empty() {
        &default_view
    } else {
        &scene.views
    };
    let mut left = Vec::new();
    for view in views {
        left.push(log_view3d(bp, ids, view)?);
    }
    let left = match left.as_slice() {
        [one] => one.clone(),
        _ => {
            let grid = log_container(bp, ids, ContainerKind::Grid, &left, &[])?;
            bp.log(
                grid.as_str(),
                &ContainerBlueprint::update_fields()
                    .with_grid_columns(GridColumns(UInt32(scene::grid_columns(left.len()) as u32))),
            )?;
            grid
        }
    };
    if legend_pane(scene, views.len()) != LegendPane::Tiles {
        return Ok(left);
    }
    let height = tiles(&scene.legend).height;
    let legend = log_view(bp, ids, "2D", &legend_title(scene), LEGEND)?;
    bp.log(
        format!("{legend}/VisualBounds2D"),
        &VisualBounds2D::new(Range2D {
            x_range: Range1D([0.0, DESIGN_WIDTH]),
            y_range: Range1D([0.0, height]),
        }),
    )?;
    let share = legend_share(height);
    log_container(
        bp,
        ids,
        ContainerKind::Vertical,
        &[left, legend],
        &[(DESIGN_HEIGHT - share) as f32, share as f32],
    )
}

/// One time-series view per plot, origin `plots/<id>`: its time axis over the whole log (a
/// robot log's), its value range and its legend's corner.
fn plot_views(
    bp: &rr::RecordingStream,
    ids: &mut Ids,
    scene: &Scene,
) -> Result<Vec<String>, SinkError> {
    let mut plots = Vec::new();
    for plot in &scene.plots {
        let origin = scene::paths::plot(&plot.id);
        let view = log_view(bp, ids, "TimeSeries", &plot.label(), &origin)?;
        if let Some(range) = stamp_range(scene, &plot.id) {
            bp.log(
                format!("{view}/TimeAxis"),
                &TimeAxis::new().with_view_range(range),
            )?;
        }
        if let Some([low, high]) = plot.range {
            bp.log(
                format!("{view}/ScalarAxis"),
                &ScalarAxis::new().with_range(rr::components::Range1D::new(low, high)),
            )?;
        }
        bp.log(
            format!("{view}/PlotLegend"),
            &PlotLegend::new().with_corner(corner(plot.legend)),
        )?;
        plots.push(view);
    }
    Ok(plots)
}

/// The root container: with `plots_below`, the views above rows of plots on the left and the
/// text panel the whole right column; otherwise the views on the left and the text panel over
/// the plots on the right (several plots are tabs of one pane, so the one shown is tall enough
/// for its legend to sit beside its lines), a legend in words between them.
fn root_container(
    bp: &rr::RecordingStream,
    ids: &mut Ids,
    scene: &Scene,
    left: String,
    (description, legend): (String, Option<String>),
    plots: &[String],
) -> Result<Id, SinkError> {
    let (left, right) = if scene.plots_below && !plots.is_empty() {
        let mut column = vec![left];
        for row in plots.chunks(PLOTS_PER_ROW) {
            column.push(log_container(bp, ids, ContainerKind::Horizontal, row, &[])?);
        }
        // The views keep three fifths of the height with one row, half with more.
        let shares = views_over_plots(column.len() - 1);
        let left = log_container(bp, ids, ContainerKind::Vertical, &column, &shares)?;
        (left, description)
    } else {
        let plots = match plots {
            [] => None,
            [one] => Some(one.clone()),
            _ => Some(log_container(bp, ids, ContainerKind::Tabs, plots, &[])?),
        };
        let (panes, shares): (Vec<String>, &[f32]) = match (legend, plots) {
            (None, None) => (vec![description], &[]),
            (Some(legend), None) => (vec![description, legend], &[3.0, 2.0]),
            (None, Some(plots)) => (vec![description, plots], &[3.0, 2.0]),
            (Some(legend), Some(plots)) => (vec![description, legend, plots], &[2.0, 2.0, 2.5]),
        };
        let right = match panes.as_slice() {
            [one] => one.clone(),
            _ => log_container(bp, ids, ContainerKind::Vertical, &panes, shares)?,
        };
        (left, right)
    };
    // The root is created after its children.
    let root = ids.next();
    log_container_at(
        bp,
        &root,
        ContainerKind::Horizontal,
        &[left, right],
        &[LEFT_SHARE, RIGHT_SHARE],
    )?;
    Ok(root)
}

/// The panels around the views: blueprint and selection collapsed, the time panel collapsed
/// on the scene's timeline, following the latest data (a recording opens on its last step).
fn panels(bp: &rr::RecordingStream, scene: &Scene) -> Result<(), SinkError> {
    let collapsed = PanelBlueprint::new().with_state(PanelState::Collapsed);
    bp.log("blueprint_panel", &collapsed)?;
    bp.log("selection_panel", &collapsed)?;
    bp.log(
        "time_panel",
        &TimePanelBlueprint::new()
            .with_state(PanelState::Collapsed)
            .with_timeline(TimelineName(
                match scene.timeline {
                    scene::Timeline::Step => STEP_TIMELINE,
                    scene::Timeline::Stamp | scene::Timeline::Elapsed => STAMP_TIMELINE,
                }
                .into(),
            ))
            .with_play_state(PlayState::Following),
    )?;
    Ok(())
}

/// The legend view's title: what its regions hold.
fn legend_title(scene: &Scene) -> String {
    match scene.confidence {
        Some(p) => format!("Legend · regions hold {p}"),
        None => "Legend".to_owned(),
    }
}

/// The viewer's corner.
fn corner(c: Corner) -> Corner2D {
    match c {
        Corner::LeftTop => Corner2D::LeftTop,
        Corner::RightTop => Corner2D::RightTop,
        Corner::LeftBottom => Corner2D::LeftBottom,
        Corner::RightBottom => Corner2D::RightBottom,
    }
}

/// A robot log's plot shows the whole log: the time axis spans the first to the last stamp of
/// the series of plot `plot` (without it the viewer opens a time plot on a window around the
/// time cursor, cutting off the start). Step plots keep the viewer's own fit (`None`).
fn stamp_range(scene: &Scene, plot: &scene::PlotId) -> Option<TimeRange> {
    if scene.timeline == scene::Timeline::Step {
        return None;
    }
    let stamps = scene
        .series
        .iter()
        .filter(|s| s.plot == *plot)
        .flat_map(|s| s.points.iter().map(|p| p.0));
    let (first, last) = stamps.fold(None, |r: Option<(i64, i64)>, t| {
        Some(r.map_or((t, t), |(a, b)| (a.min(t), b.max(t))))
    })?;
    Some(TimeRange(datatypes::TimeRange {
        start: TimeRangeBoundary::Absolute(TimeInt(first)),
        end: TimeRangeBoundary::Absolute(TimeInt(last)),
    }))
}

/// A blueprint id: the UUID and its text, as used in entity paths.
#[derive(Clone)]
struct Id {
    uuid: Uuid,
    text: String,
}

/// Fixed ids in layout order (version-4 form, so any UUID parser accepts them).
#[derive(Default)]
struct Ids(u64);

impl Ids {
    fn next(&mut self) -> Id {
        self.0 += 1;
        let mut bytes = [0u8; 16];
        bytes[8..].copy_from_slice(&self.0.to_be_bytes());
        bytes[0..4].copy_from_slice(b"posc");
        bytes[6] = 0x40; // version 4
        bytes[8] = 0x80 | (bytes[8] & 0x3f); // RFC 4122 variant
        let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
        let text = format!(
            "{}-{}-{}-{}-{}",
            &hex[0..8],
            &hex[8..12],
            &hex[12..16],
            &hex[16..20],
            &hex[20..32]
        );
        Id {
            uuid: Uuid { bytes },
            text,
        }
    }
}

/// Logs a view and returns its blueprint path.
fn log_view(
    bp: &rr::RecordingStream,
    ids: &mut Ids,
    class: &str,
    name: &str,
    origin: &str,
) -> Result<String, SinkError> {
    let path = format!("view/{}", ids.next().text);
    bp.log(
        format!("{path}/ViewContents"),
        &ViewContents::new([QueryExpression("$origin/**".into())]),
    )?;
    bp.log(
        path.as_str(),
        &ViewBlueprint::new(ViewClass(class.into()))
            .with_display_name(Name(name.into()))
            .with_space_origin(format!("/{origin}")),
    )?;
    Ok(path)
}

/// Logs a 3-D view of the world: its query, its eye and its hidden entities.
fn log_view3d(bp: &rr::RecordingStream, ids: &mut Ids, view: &View3d) -> Result<String, SinkError> {
    let path = format!("view/{}", ids.next().text);
    bp.log(
        format!("{path}/ViewContents"),
        &ViewContents::new(query(view).into_iter().map(|q| QueryExpression(q.into()))),
    )?;
    bp.log(
        path.as_str(),
        &ViewBlueprint::new(ViewClass("3D".into()))
            .with_display_name(Name(view.title().into()))
            .with_space_origin(format!("/{}", scene::WORLD)),
    )?;
    if let Some(camera) = &view.camera {
        bp.log(format!("{path}/EyeControls3D"), &eye(camera))?;
    }
    if let Some(spacing) = view.grid_spacing {
        bp.log(
            format!("{path}/LineGrid3D"),
            &LineGrid3D::new().with_spacing(GridSpacing(Float32(spacing as f32))),
        )?;
    }
    for hidden in &view.hidden {
        // The viewer's own eye toggle writes here (`ViewContents::blueprint_base_visualizer_
        // path_for_entity`: the entity's override base, `…/overrides/<entity>/visualizers`).
        bp.log(
            format!("{path}/ViewContents/overrides/{hidden}/visualizers"),
            &EntityBehavior::new().with_visible(Visible::from(false)),
        )?;
    }
    Ok(path)
}

/// The view's query: its subtrees (or the whole world), minus the excluded ones.
fn query(view: &View3d) -> Vec<String> {
    let mut q: Vec<String> = if view.include.is_empty() {
        vec![format!("+ /{}/**", scene::WORLD)]
    } else {
        view.include.iter().map(|p| format!("+ /{p}/**")).collect()
    };
    q.extend(view.exclude.iter().map(|p| format!("- /{p}/**")));
    q
}

/// An orbiting eye at the camera's position, around its target.
fn eye(camera: &Camera) -> EyeControls3D {
    let f = |v: &scene::Vec3| v.map(|x| x as f32);
    let [px, py, pz] = f(&camera.position);
    let [tx, ty, tz] = f(&camera.target);
    EyeControls3D::new()
        .with_kind(Eye3DKind::Orbital)
        .with_position(Position3D::new(px, py, pz))
        .with_look_target(Position3D::new(tx, ty, tz))
        .with_eye_up(Vector3D::from(f(&camera.up)))
}

/// Logs a container under a new id and returns its blueprint path.
fn log_container(
    bp: &rr::RecordingStream,
    ids: &mut Ids,
    kind: ContainerKind,
    contents: &[String],
    shares: &[f32],
) -> Result<String, SinkError> {
    let id = ids.next();
    log_container_at(bp, &id, kind, contents, shares)
}

/// Logs a container at `id`: `shares` are column shares (horizontal) or row shares (vertical).
fn log_container_at(
    bp: &rr::RecordingStream,
    id: &Id,
    kind: ContainerKind,
    contents: &[String],
    shares: &[f32],
) -> Result<String, SinkError> {
    let path = format!("container/{}", id.text);
    let mut archetype = ContainerBlueprint::new(kind)
        .with_contents(contents.iter().map(|c| IncludedContent(c.as_str().into())));
    if !shares.is_empty() {
        archetype = match kind {
            ContainerKind::Horizontal => {
                archetype.with_col_shares(shares.iter().map(|&s| ColumnShare(Float32(s))))
            }
            _ => archetype.with_row_shares(shares.iter().map(|&s| RowShare(Float32(s)))),
        };
    }
    bp.log(path.as_str(), &archetype)?;
    Ok(path)
}
