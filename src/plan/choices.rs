//! What an input asks to be drawn, typed and free of file places: the input stage checks a
//! file's `[draw]` table (and a log's or graph's defaults) into these, and the draw stage reads
//! them (`draw` never imports `input`).

use std::collections::BTreeMap;

use serde::Serialize;

/// What an input describes, for the text panel and `posecov list`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct About {
    /// One-line title.
    pub title: String,
    /// Markdown: what the picture teaches.
    pub description: String,
    /// Where the example comes from (lecture, paper, figure), or empty.
    pub source: String,
}

/// What an input file asks to draw (validated).
#[derive(Debug, Clone, PartialEq)]
pub struct DrawChoices {
    /// Mean frames as axis triads.
    pub axes: bool,
    /// Monte Carlo sample positions.
    pub clouds: bool,
    /// Axis triads (or headings) on a subsample of the samples.
    pub sample_axes: bool,
    /// Cartesian position ellipsoids.
    pub ellipsoids: bool,
    /// Exp-mapped banana surfaces.
    pub bananas: bool,
    /// Orientation sprays and their Exp-mapped ellipses.
    pub orientation: bool,
    /// Nominal and sampled trajectories.
    pub trajectories: bool,
    /// Length of the mean frames' axes (m), if given.
    pub axis_length: Option<f64>,
    /// Face the x–y plane from above (`Some(true)`), or not; `None`: by group.
    pub top_view: Option<bool>,
    /// Per pose name, whether to draw it (overrides the default rule).
    pub shown: BTreeMap<String, bool>,
    /// Pairs of poses joined by a line (a pose graph's loop closures).
    pub links: Vec<Link>,
    /// Whether frames carry their names (off for a graph's many vertices).
    pub labels: bool,
    /// Where the 3-D camera looks from, if the file says; `None`: chosen per scene.
    pub camera: Option<CameraChoice>,
    /// How the 3-D views split the methods and poses; `None`: chosen per scene.
    pub layout: Option<Layout>,
    /// A pose graph file's facts, from which the draw stage writes its description (`None`
    /// for any other input: its own description is the file's words).
    pub graph: Option<GraphFacts>,
}

/// A camera asked for by an input (`[draw] camera = {...}`), every part optional: the eye at
/// `position`, or at the distance that fits the scene along `direction` (from the target
/// towards the eye); looking at `target` (default: the middle of what is drawn); `up` the
/// world direction shown up on screen (default +z).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CameraChoice {
    /// Eye position, world frame (m).
    pub position: Option<[f64; 3]>,
    /// Direction from the target towards the eye (any length > 0).
    pub direction: Option<[f64; 3]>,
    /// The point looked at, world frame (m).
    pub target: Option<[f64; 3]>,
    /// World direction up on screen.
    pub up: Option<[f64; 3]>,
}

/// How the 3-D views show several methods and poses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// One view, every method drawn and shown.
    Together,
    /// One view: the main method in full and Monte Carlo shown, the other methods' outlines
    /// hidden at first (one click away in the entity tree).
    Main,
    /// One view per method, each with the Monte Carlo cloud.
    PerMethod,
    /// One view per drawn pose (rotations that would all sit at the origin).
    PerPose,
}

impl Default for DrawChoices {
    fn default() -> Self {
        Self {
            axes: true,
            clouds: true,
            sample_axes: true,
            ellipsoids: true,
            bananas: true,
            orientation: true,
            trajectories: true,
            axis_length: None,
            top_view: None,
            shown: BTreeMap::new(),
            links: Vec::new(),
            labels: true,
            camera: None,
            layout: None,
            graph: None,
        }
    }
}

/// Two poses joined by a line (a pose graph's loop closure), by name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Link {
    /// One end's pose name.
    pub from: String,
    /// The other end's pose name.
    pub to: String,
}

/// The counts a pose graph file holds: for messages, the text panel and `report --json`'s
/// `input` (serialised as they stand).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct GraphCounts {
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Edges in the odometry chain (between consecutive vertex ids from the first).
    pub chain_edges: usize,
    /// Loop closures (every other edge).
    pub loop_closures: usize,
    /// Loop closures evaluated and drawn with their uncertainty (at most the graph reader's
    /// bound on drawn loop closures).
    pub loop_closures_drawn: usize,
    /// Vertex estimates drawn as axes (at most 300, plus the drawn loop closures' ends).
    pub vertices_drawn: usize,
}

/// What a pose graph file holds, as facts: the drawing stage writes the graph's description
/// from them (its `input_description`); the input stage writes no words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GraphFacts {
    /// SE(2) vertices (else SE(3)).
    pub planar: bool,
    /// Its counts.
    pub counts: GraphCounts,
    /// The first vertex id: where the chain starts.
    pub first: u64,
    /// The vertex id the chain ends at.
    pub chain_end: u64,
    /// The file has no VERTEX lines: the estimates were chained from the edges.
    pub chained: bool,
    /// Records valid but not drawn, per tag, in the file's order.
    pub skipped: Vec<SkippedRecords>,
}

/// Valid records of one tag that are not drawn (landmarks, parameters), counted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkippedRecords {
    /// The record's tag, e.g. `VERTEX_XY`.
    pub tag: String,
    /// How many.
    pub count: usize,
}
