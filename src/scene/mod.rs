//! A plain-data scene: what to draw, where, and when — the last stage before a sink.
//!
//! The data path is *scenario → evaluation → [`Scene`] → sink*. A scene knows nothing about
//! Rerun: it is a list of [`SceneItem`]s (frames, triad batches, point clouds, ellipsoids,
//! surfaces, line strips, arrows, text) plus [`ScalarSeries`] for plots, each item placed on
//! an entity path and either static or at an integer `step` of the propagation timeline.
//! `crate::sink` turns it into Rerun archetypes; tests can inspect it directly.
//!
//! # Conventions at this boundary
//! - Numbers are `f64` here; the sink converts to `f32` (Rerun speaks glam/f32). A value
//!   that is not finite, or not finite once converted to `f32`, is rejected by
//!   [`Scene::validate`] — NaN never reaches the viewer.
//! - Positions are in the `world` frame, right-handed, z up.
//! - Quaternions are **`[x, y, z, w]`** ([`QuatXyzw`]), unit norm (±[`QUAT_NORM_TOLERANCE`]).
//!   From nalgebra: `let q: QuatXyzw = unit_quaternion.coords.into();` (nalgebra stores
//!   `[i, j, k, w]`).
//! - Entity paths: 3-D geometry lives under [`WORLD`], scalar series under [`PLOTS`]; the
//!   scenario description is drawn at [`DESCRIPTION`]. Every path is built by one function of
//!   [`paths`] (e.g. `world/T_MC/first_order/ellipsoid`, so each pose × method can be toggled
//!   in the viewer); a sink never parses one: a series carries its plot's [`PlotId`], an item
//!   its [`Origin`].
//!
//! # Example
//! ```
//! use posecov::scene::{Color, ItemKind, PointCloud, Scene, SceneItem, Timing};
//!
//! let mut scene = Scene::new("demo", "A single point.");
//! scene.push(SceneItem::new(
//!     "world/p/monte_carlo/cloud",
//!     Timing::Static,
//!     ItemKind::Points(PointCloud {
//!         positions: vec![[0.0, 0.0, 1.0]],
//!         color: Color::rgb(200, 200, 200),
//!         radius: 0.01,
//!     }),
//! ));
//! assert!(scene.validate().is_ok());
//! ```
//!
//! # What this folder owns
//!
//! The plain-data scene (items on entity paths, each with what it was drawn from, `Origin`;
//! every entity path built in `paths.rs`, one function per kind; plots and their series with
//! typed plot ids, `plot.rs`; the legend (`LegendEntry`: colour,
//! swatch mark, words) and the confidence of its regions; `Timing::Step` / `Timing::Stamp` and the
//! scene's `Timeline`; 3-D views with their cameras: `view.rs`; the viewer's layout at 1024 × 640 —
//! the panes' sizes, the legend's tiles, each 3-D view's shape (a log's views above its rows of
//! plots too), which the cameras are fitted to, and the one measure of text (the bundled font's
//! advance widths) that the legend tiles and the figures wrap with: `layout.rs`), palette, mesh,
//! validation; layout choices as data (`Plot::range`, a value axis fitted by `draw/`;
//! `Scene::plots_below`, the plots under the views for robot logs).
//!
//! It does not know Rerun.

pub mod layout;
mod mesh;
mod palette;
pub mod paths;
mod plot;
pub mod units;
mod validate;
mod view;

pub use mesh::unit_sphere_mesh;
pub use palette::{AXIS_COLORS, LINK, NOMINAL, REFERENCE, color_name};
pub use paths::{MessageOrigin, Origin};
pub use plot::{Corner, Plot, PlotId, ScalarSeries};
pub use view::{Camera, View3d, grid_columns, rotate};

/// A 3-vector in `f64` (a position, a vector or half sizes), in the world frame.
pub type Vec3 = [f64; 3];

/// A unit quaternion in **`[x, y, z, w]`** order (glam / ROS order, not nalgebra's `new(w, …)`).
pub type QuatXyzw = [f64; 4];

/// The identity rotation, `[x, y, z, w] = [0, 0, 0, 1]`.
pub const QUAT_IDENTITY: QuatXyzw = [0.0, 0.0, 0.0, 1.0];

/// How far from 1 a quaternion's norm may be before [`Scene::validate`] rejects it.
pub const QUAT_NORM_TOLERANCE: f64 = 1e-3;

/// Root entity of all 3-D geometry (the 3-D view of the default layout shows this subtree).
pub const WORLD: &str = "world";

/// Root entity of all scalar series (the plot of the default layout shows this subtree).
pub const PLOTS: &str = "plots";

/// Entity of the scenario's markdown description (the text panel of the default layout).
pub const DESCRIPTION: &str = "description";

/// An sRGB colour with unmultiplied alpha, `[r, g, b, a]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Color(pub [u8; 4]);

impl Color {
    /// An opaque colour.
    ///
    /// ```
    /// assert_eq!(posecov::scene::Color::rgb(1, 2, 3).0, [1, 2, 3, 255]);
    /// ```
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Self([r, g, b, 255])
    }

    /// The same colour with alpha `a` (0 = transparent, 255 = opaque).
    ///
    /// ```
    /// let c = posecov::scene::Color::rgb(1, 2, 3).with_alpha(128);
    /// assert_eq!(c.0, [1, 2, 3, 128]);
    /// ```
    pub const fn with_alpha(self, a: u8) -> Self {
        let [r, g, b, _] = self.0;
        Self([r, g, b, a])
    }
}

/// When an item is shown. Ordered: static first, then steps, then stamps, each by value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Timing {
    /// Always, on every timeline (fixed context: frames, descriptions, nominal paths).
    Static,
    /// From this value of the `step` sequence timeline on (until the same entity is logged
    /// at a later step).
    Step(i64),
    /// From this message stamp on (nanoseconds, the `stamp` time timeline): a robot log's
    /// items, so the time slider scrubs the log.
    Stamp(i64),
}

/// The timeline a scene's plot series and its time panel use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Timeline {
    /// The `step` sequence (propagation steps; series points are steps).
    #[default]
    Step,
    /// The `stamp` time timeline as dates (robot logs with wall-clock stamps; series points
    /// are nanoseconds since the epoch).
    Stamp,
    /// The `stamp` time timeline as durations (robot logs whose stamps are not dates —
    /// simulated time, time since boot — [`Timeline::for_stamps`]; series points are
    /// nanoseconds since that clock's zero).
    Elapsed,
}

impl Timeline {
    /// Stamps before this (2000-01-01T00:00:00Z, in nanoseconds since the epoch) are not
    /// wall-clock dates: ROS simulated time starts at 0, time since boot is small.
    pub const FIRST_DATE_NS: i64 = 946_684_800_000_000_000;

    /// The timeline for a robot log's stamps: dates when every stamp is one, else durations
    /// (a log in simulated time reads "47.6 s", not "1970-01-01 00:00:47.6").
    ///
    /// ```
    /// use posecov::scene::Timeline;
    /// assert_eq!(Timeline::for_stamps([47_584_000_000, 108_764_000_000]), Timeline::Elapsed);
    /// assert_eq!(Timeline::for_stamps([1_700_000_000_000_000_000]), Timeline::Stamp);
    /// ```
    pub fn for_stamps(stamps: impl IntoIterator<Item = i64>) -> Self {
        if stamps.into_iter().all(|ns| ns >= Self::FIRST_DATE_NS) {
            Self::Stamp
        } else {
            Self::Elapsed
        }
    }
}

/// How an ellipsoid is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FillMode {
    /// Filled surface, no lines. Hides what is inside: use a low alpha.
    Solid,
    /// Three principal cross-section ellipses (light; clouds stay visible).
    MajorWireframe,
    /// A see-through wireframe mesh.
    DenseWireframe,
    /// A transparent fill with the principal ellipses on top.
    TransparentFillMajorWireframe,
}

/// A coordinate frame drawn as an RGB (x, y, z) axis triad.
///
/// The sink logs it as a transform of its own entity, so nothing else may be placed
/// *under* a frame's entity path ([`Scene::validate`] checks this).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Origin of the frame in the world.
    pub translation: Vec3,
    /// Orientation `world_from_frame`, `[x, y, z, w]`.
    pub rotation: QuatXyzw,
    /// Length of each axis, metres.
    pub axis_length: f64,
    /// Text drawn at the origin (e.g. `"T_MC"`), if any: a figure places it whole.
    pub label: Option<String>,
    /// What the viewer writes there instead, when it differs from `label`: a short tag (the
    /// viewer draws labels at a fixed size, so long words would cover a small view), or an
    /// empty one for none (it would sit on a more important label as the view opens,
    /// `draw::tags`). `None`: the label.
    pub tag: Option<String>,
}

impl Frame {
    /// The words the viewer draws at the frame: its tag, else its label; `None` for an empty
    /// tag.
    ///
    /// ```
    /// use posecov::scene::Frame;
    /// let f = Frame { translation: [0.0; 3], rotation: [0.0, 0.0, 0.0, 1.0], axis_length: 1.0,
    ///     label: Some("v9: worst loop closure, d = 2.1".into()), tag: Some("v9 worst".into()) };
    /// assert_eq!(f.viewer_label(), Some("v9 worst"));
    /// assert_eq!(Frame { tag: Some(String::new()), ..f.clone() }.viewer_label(), None);
    /// assert_eq!(Frame { tag: None, ..f }.viewer_label(), Some("v9: worst loop closure, d = 2.1"));
    /// ```
    pub fn viewer_label(&self) -> Option<&str> {
        match &self.tag {
            Some(tag) => Some(tag.as_str()).filter(|t| !t.is_empty()),
            None => self.label.as_deref(),
        }
    }
}

/// Many small RGB axis triads on one entity (e.g. a subsample of Monte-Carlo poses).
#[derive(Clone, Debug, PartialEq)]
pub struct Triads {
    /// Origins, one per triad.
    pub translations: Vec<Vec3>,
    /// Orientations `world_from_sample`, `[x, y, z, w]`, one per triad.
    pub rotations: Vec<QuatXyzw>,
    /// Length of each axis, metres.
    pub axis_length: f64,
    /// Line radius, metres (a few percent of `axis_length` reads well).
    pub line_radius: f64,
}

/// A point cloud in one colour.
#[derive(Clone, Debug, PartialEq)]
pub struct PointCloud {
    /// Point positions.
    pub positions: Vec<Vec3>,
    /// Colour of every point.
    pub color: Color,
    /// Radius of every point, metres.
    pub radius: f64,
}

/// One ellipsoid: `{ centre + R · diag(half_sizes) · u : ‖u‖ = 1 }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ellipsoid {
    /// Centre in the world.
    pub center: Vec3,
    /// Semi-axis lengths along the rotated x, y, z axes (k·√λᵢ for a covariance).
    pub half_sizes: Vec3,
    /// Rotation `world_from_principal`, `[x, y, z, w]` (columns = eigenvectors).
    pub rotation: QuatXyzw,
}

/// A batch of ellipsoids sharing colour and style (e.g. one per pose along a path).
#[derive(Clone, Debug, PartialEq)]
pub struct Ellipsoids {
    /// The ellipsoids.
    pub shapes: Vec<Ellipsoid>,
    /// Colour (alpha matters for [`FillMode::Solid`] and the transparent fill).
    pub color: Color,
    /// Drawing style; always sent explicitly (Rerun's default changed in 0.31).
    pub fill: FillMode,
    /// Radius of wireframe lines, metres.
    pub line_radius: f64,
    /// Label shown at each ellipsoid, if any (e.g. `"95 %"`).
    pub label: Option<String>,
}

/// A triangle mesh (e.g. the Exp-image "banana" of a tangent-space ellipsoid).
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Vertex positions.
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Unit vertex normals (same length as `vertices`), or empty to let the viewer compute.
    pub normals: Vec<Vec3>,
    /// Colour; alpha < 255 draws a translucent surface (no order-independent transparency:
    /// keep surfaces few and light).
    pub color: Color,
}

/// Polylines in one colour.
#[derive(Clone, Debug, PartialEq)]
pub struct LineStrips {
    /// Each strip is a polyline through its points.
    pub strips: Vec<Vec<Vec3>>,
    /// Colour of every strip.
    pub color: Color,
    /// Line radius, metres.
    pub radius: f64,
}

/// Arrows `origin → origin + vector` in one colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Arrows {
    /// Tails.
    pub origins: Vec<Vec3>,
    /// Tail-to-head vectors, one per origin.
    pub vectors: Vec<Vec3>,
    /// Colour of every arrow.
    pub color: Color,
    /// Shaft radius, metres.
    pub radius: f64,
}

/// What an item draws.
#[derive(Clone, Debug, PartialEq)]
pub enum ItemKind {
    /// A coordinate frame (axis triad).
    Frame(Frame),
    /// A batch of small axis triads.
    Triads(Triads),
    /// A point cloud.
    Points(PointCloud),
    /// A batch of ellipsoids.
    Ellipsoids(Ellipsoids),
    /// A triangle mesh.
    Surface(Surface),
    /// Polylines.
    LineStrips(LineStrips),
    /// Arrows.
    Arrows(Arrows),
    /// A markdown document (shown in a text view, not in 3-D).
    Text(String),
}

/// One drawable thing at one entity path and one time.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneItem {
    /// Entity path, `/`-separated; segments use `[A-Za-z0-9_.-]`.
    pub path: String,
    /// Static, at a `step`, or at a stamp.
    pub timing: Timing,
    /// What to draw.
    pub kind: ItemKind,
    /// What it was drawn from (a robot log's topic and message), when the drawing stage knows:
    /// the place an undrawable item is reported at.
    pub origin: Option<Origin>,
}

impl SceneItem {
    /// An item at `path`.
    ///
    /// ```
    /// use posecov::scene::{ItemKind, SceneItem, Timing};
    /// let item = SceneItem::new("description/extra", Timing::Step(3), ItemKind::Text("hi".into()));
    /// assert_eq!(item.timing, Timing::Step(3));
    /// ```
    pub fn new(path: impl Into<String>, timing: Timing, kind: ItemKind) -> Self {
        Self {
            path: path.into(),
            timing,
            kind,
            origin: None,
        }
    }
}

/// How a legend entry's swatch is drawn: the same mark as the thing it names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Swatch {
    /// A filled patch: a region (an Exp-mapped banana surface).
    Region,
    /// A solid line: an outline, a path or a plot line.
    Line,
    /// A dashed line: a Cartesian (first-order position) ellipse.
    Dashed,
    /// A few dots: a sample cloud.
    Dots,
    /// An x/y/z axis triad in red, green and blue (the colour is not used).
    Axes,
}

/// One line of a scene's legend: a swatch in the colour of what it names, and words.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendEntry {
    /// What is drawn in this colour, e.g. "first order: Exp-mapped 95 % region".
    pub label: String,
    /// What the run measured about it, written after the label ("; holds 95.2 % of
    /// map_from_camera's samples"), or empty. A figure's legend shows it; the viewer's compact
    /// legend leaves it to the text panel's table.
    pub detail: String,
    /// The colour (opaque; sinks choose their own transparency).
    pub color: Color,
    /// The mark of the swatch.
    pub swatch: Swatch,
}

impl LegendEntry {
    /// The label followed by its detail, as a figure's legend writes it.
    ///
    /// ```
    /// use posecov::scene::{Color, LegendEntry, Swatch};
    /// let e = LegendEntry { label: "first order: 95 % ellipse".into(), detail: "; holds 70 %".into(),
    ///     color: Color::rgb(0, 0, 0), swatch: Swatch::Line };
    /// assert_eq!(e.text(), "first order: 95 % ellipse; holds 70 %");
    /// ```
    pub fn text(&self) -> String {
        format!("{}{}", self.label, self.detail)
    }
}

/// Everything one scenario draws.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Scene {
    /// Short title (also the recording name).
    pub title: String,
    /// Markdown shown in the text panel: what is drawn, conventions, formulas, measured errors.
    pub description_markdown: String,
    /// Drawables, logged in order (static ones first, then by step; stable within a step).
    pub items: Vec<SceneItem>,
    /// Plots (one view each), in display order.
    pub plots: Vec<Plot>,
    /// Plot lines, each under the path of its plot.
    pub series: Vec<ScalarSeries>,
    /// A planar scene (SE(2), SO(2), or `view = "top"`) lies in the x–y plane: its views are
    /// seen from straight above ([`View3d::camera`]).
    pub planar: bool,
    /// The timeline of the plot series and the time panel.
    pub timeline: Timeline,
    /// The 3-D views, each with its camera; empty: one view of the whole world, framed by the
    /// viewer.
    pub views: Vec<View3d>,
    /// What each colour and mark means, in drawing order (one entry per label).
    pub legend: Vec<LegendEntry>,
    /// The probability inside every drawn region, if the scene draws regions.
    pub confidence: Option<crate::uncertain::Confidence>,
    /// Layout: the plots in a row under the 3-D views and the text panel the whole right
    /// column (robot logs, whose health findings need the height); else the plots stand under
    /// the text panel on the right.
    pub plots_below: bool,
    /// A subtree whose items at several steps are successive states of one picture (a pose
    /// graph's after view, re-solved loop closure by loop closure), if any: a figure of every
    /// step draws each of its entities' last state only, and a figure at step K its state
    /// after K loop closures ([`States`]).
    pub states: Option<States>,
}

/// Successive states of one subtree on the `step` timeline ([`Scene::states`]).
///
/// ```
/// use posecov::scene::{State, States};
/// let at = |closures, step| State { closures, step };
/// let s = States { path: "world/optimized".into(), steps: vec![at(0, 0), at(5, 12), at(9, 13)] };
/// assert_eq!(s.step_after(6), Some(12));
/// assert_eq!(s.step_after(100), Some(13));
/// assert!(s.contains("world/optimized/marginals") && !s.contains("world/optimized_x"));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct States {
    /// The subtree's path.
    pub path: String,
    /// Each state in order.
    pub steps: Vec<State>,
}

/// One state of a pose graph's picture on the `step` timeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct State {
    /// How many loop closures the state has.
    pub closures: u64,
    /// Its step.
    pub step: i64,
}

impl States {
    /// The step of the last state with at most `count` loop closures (the first state's when
    /// none has so few).
    pub fn step_after(&self, count: u64) -> Option<i64> {
        self.steps
            .iter()
            .rev()
            .find(|s| s.closures <= count)
            .or(self.steps.first())
            .map(|s| s.step)
    }

    /// Whether `path` is in the subtree.
    pub fn contains(&self, path: &str) -> bool {
        paths::is_under(path, &self.path)
    }
}

impl Scene {
    /// An empty scene with a title and a description.
    ///
    /// ```
    /// let scene = posecov::scene::Scene::new("t", "**d**");
    /// assert!(scene.items.is_empty());
    /// ```
    pub fn new(title: impl Into<String>, description_markdown: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            description_markdown: description_markdown.into(),
            items: Vec::new(),
            plots: Vec::new(),
            series: Vec::new(),
            planar: false,
            timeline: Timeline::Step,
            views: Vec::new(),
            legend: Vec::new(),
            confidence: None,
            plots_below: false,
            states: None,
        }
    }

    /// Adds a legend entry unless one with the same label and colour is there already.
    ///
    /// ```
    /// use posecov::scene::{Color, LegendEntry, Scene, Swatch};
    /// let mut scene = Scene::new("t", "");
    /// let entry = LegendEntry { label: "nominal path".into(), detail: String::new(), color: Color::rgb(0, 0, 255), swatch: Swatch::Line };
    /// scene.add_legend(entry.clone());
    /// scene.add_legend(entry);
    /// assert_eq!(scene.legend.len(), 1);
    /// ```
    pub fn add_legend(&mut self, entry: LegendEntry) {
        if !self
            .legend
            .iter()
            .any(|e| e.label == entry.label && e.detail == entry.detail && e.color == entry.color)
        {
            self.legend.push(entry);
        }
    }

    /// Appends an item.
    pub fn push(&mut self, item: SceneItem) {
        self.items.push(item);
    }

    /// The distinct steps used by items and series, ascending (empty for a static scene).
    ///
    /// ```
    /// use posecov::scene::{ItemKind, Scene, SceneItem, Timing};
    /// let mut scene = Scene::new("t", "");
    /// for k in [3, 1, 3] {
    ///     scene.push(SceneItem::new("description/k", Timing::Step(k), ItemKind::Text(String::new())));
    /// }
    /// assert_eq!(scene.steps(), vec![1, 3]);
    /// ```
    pub fn steps(&self) -> Vec<i64> {
        let mut steps: Vec<i64> = self
            .items
            .iter()
            .filter_map(|item| match item.timing {
                Timing::Static | Timing::Stamp(_) => None,
                Timing::Step(k) => Some(k),
            })
            .chain(
                self.series
                    .iter()
                    .filter(|_| self.timeline == Timeline::Step)
                    .flat_map(|s| s.points.iter().map(|p| p.0)),
            )
            .collect();
        steps.sort_unstable();
        steps.dedup();
        steps
    }

    /// Items in logging order: static items first, then ascending step; insertion order is
    /// kept within each group (so the output is deterministic).
    pub fn items_in_log_order(&self) -> Vec<&SceneItem> {
        let mut items: Vec<&SceneItem> = self.items.iter().collect();
        items.sort_by_key(|item| match item.timing {
            Timing::Static => (0, 0),
            Timing::Step(k) => (1, k),
            Timing::Stamp(ns) => (2, ns),
        });
        items
    }
}

pub use validate::SceneError;
