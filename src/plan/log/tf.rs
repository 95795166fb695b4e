//! The transforms a log carries in `/tf` and `/tf_static` ([`TfTree`]): per edge (parent
//! frame → child frame) its samples, bounded, as the reader kept them. Nothing here looks a
//! transform up (`eval::log::frames` does, through `eval::log::stamped`).
//! What is kept, and why memory stays bounded: [`TfTree`].
//!
//! # In the plan
//!
//! `plan/log/tf.rs` (`TfTree`: a log's transforms per parent → child edge, at most 8192 `/tf`
//! samples per edge evenly thinned, the latest `/tf_static` value, at most 64 edges).

use super::ReferenceSample;

/// Samples of `/tf` kept per edge (evenly thinned beyond).
pub const MAX_TF_SAMPLES: usize = 8192;
/// Edges whose transforms are kept (a further edge's transforms are counted only).
pub const MAX_TF_EDGES: usize = 64;

/// One edge of the tree: parent_from_child over time (`/tf`), or once (`/tf_static`).
#[derive(Debug, Clone, PartialEq)]
pub struct TfEdge {
    /// The parent frame (`header.frame_id`, without a leading `/`).
    pub parent: String,
    /// The child frame (`child_frame_id`, without a leading `/`).
    pub child: String,
    /// The topic it was first read on (`/tf` or `/tf_static`).
    pub topic: String,
    /// The stamp of its first transform, ns.
    pub first_stamp_ns: i64,
    /// Transforms read (`/tf` and `/tf_static`).
    pub messages: u64,
    /// The kept `/tf` samples (every `stride`-th), in read order.
    pub samples: Vec<ReferenceSample>,
    /// One `/tf` sample kept in this many.
    pub stride: u64,
    /// The latest `/tf_static` value (valid at every stamp), if any.
    pub static_value: Option<ReferenceSample>,
    /// Beyond [`MAX_TF_EDGES`]: counted, nothing kept.
    pub dropped: bool,
}

impl TfEdge {
    /// An edge with nothing read yet, first seen on `topic` at `first_stamp_ns`.
    ///
    /// See [`TfTree`] for an example.
    pub fn new(parent: &str, child: &str, topic: &str, first_stamp_ns: i64) -> Self {
        Self {
            parent: parent.to_owned(),
            child: child.to_owned(),
            topic: topic.to_owned(),
            first_stamp_ns,
            messages: 0,
            samples: Vec::new(),
            stride: 1,
            static_value: None,
            dropped: false,
        }
    }

    /// `parent→child`.
    ///
    /// See [`TfTree`] for an example.
    pub fn name(&self) -> String {
        format!("{}→{}", self.parent, self.child)
    }
}

/// The transforms of a log, per edge in the order first seen. What is kept, so that memory
/// does not grow with the log's length: per edge at most [`MAX_TF_SAMPLES`] samples of `/tf`
/// (evenly thinned beyond, as the trajectory is: every `stride`-th transform), the latest
/// `/tf_static` value, and at most [`MAX_TF_EDGES`] edges (a further edge's transforms are
/// counted, not kept). A sample is 64 bytes: at most ≈ 0.5 MB per edge, ≈ 34 MB in all.
///
/// ```
/// use posecov::plan::log::{ReferenceSample, TfEdge, TfTree};
/// let s = ReferenceSample { stamp_ns: 1, position: [1.0, 0.0, 0.0], orientation_xyzw: [0.0, 0.0, 0.0, 1.0] };
/// let edge = TfEdge::new("map", "odom", "/tf", 1);
/// let tf = TfTree { edges: vec![TfEdge { samples: vec![s], messages: 1, ..edge }], ..Default::default() };
/// assert_eq!(tf.edges[0].name(), "map→odom");
/// assert_eq!(tf.edge("map", "odom").map(|e| e.samples.len()), Some(1));
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TfTree {
    /// The edges.
    pub edges: Vec<TfEdge>,
    /// `/tf` or `/tf_static` messages that could not be decoded, per topic.
    pub undecodable: Vec<UndecodableTf>,
}

/// The `/tf` or `/tf_static` messages of one topic that could not be decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UndecodableTf {
    /// `/tf` or `/tf_static`.
    pub topic: String,
    /// How many.
    pub count: u64,
    /// The first one's log time, ns.
    pub first_log_time_ns: i64,
}

impl TfTree {
    /// The edge parent → child, if the log has it.
    ///
    /// See [`TfTree`] for an example.
    pub fn edge(&self, parent: &str, child: &str) -> Option<&TfEdge> {
        self.edges
            .iter()
            .find(|e| e.parent == parent && e.child == child)
    }
}
