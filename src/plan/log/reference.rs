//! A log's reference (ground truth) as the reader hands it on: where it comes from
//! ([`ReferenceInLog`]: a topic of the log or a child frame in `/tf`), its samples
//! ([`ReferenceSample`]), and the [`LogObserver`] that receives every reference sample and
//! every estimate message while the log streams by (`eval::log::nees` is the one that computes NEES
//! from them). Nothing here reads a file or computes.
//!
//! ```
//! use posecov::plan::log::{ReferenceInLog, ReferenceSample};
//! let tf = ReferenceInLog::Tf { child: "base_link".into() };
//! assert_eq!(tf.to_string(), "tf:base_link");
//! let s = ReferenceSample { stamp_ns: 1, position: [0.0; 3], orientation_xyzw: [0.0, 0.0, 0.0, 1.0] };
//! assert_eq!(s.stamp_ns, 1);
//! ```
//!
//! # In the plan
//!
//! `plan/log/reference.rs` (a reference in the log, its samples, what the reader saw of it, and
//! `LogObserver`, the streamed per-message hook from the reader to evaluation).

use std::fmt;

use super::COV_LEN;

/// Where in a log the reference is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReferenceInLog {
    /// A topic of pose messages (`PoseStamped`, `PoseWithCovarianceStamped`, `Odometry`,
    /// `TransformStamped`).
    Topic(String),
    /// The transforms in `/tf` whose `child_frame_id` is `child` (their parent must be the
    /// estimate's `frame_id`).
    Tf {
        /// The child frame.
        child: String,
    },
}

impl fmt::Display for ReferenceInLog {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReferenceInLog::Topic(name) => write!(f, "topic:{name}"),
            ReferenceInLog::Tf { child } => write!(f, "tf:{child}"),
        }
    }
}

/// The truth a log's estimates are compared with (`--reference`, typed from the flag to the
/// NEES settings): something in the log, or a TUM trajectory file. Shown as the user names it.
///
/// ```
/// use posecov::plan::log::{Reference, ReferenceInLog};
/// let r = Reference::InLog(ReferenceInLog::Topic("/truth".into()));
/// assert_eq!((r.to_string(), r.topic()), ("topic:/truth".to_owned(), Some("/truth")));
/// assert!(Reference::InLog(ReferenceInLog::Tf { child: "base".into() }).is_tf());
/// assert_eq!(Reference::File("gt.txt".into()).to_string(), "file:gt.txt");
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reference {
    /// A topic of the log, or its `/tf` transforms of one child frame.
    InLog(ReferenceInLog),
    /// A TUM trajectory file (its path as given).
    File(String),
}

impl Reference {
    /// The topic of the log that is the reference itself (left out of the estimates), if any.
    pub fn topic(&self) -> Option<&str> {
        match self {
            Reference::InLog(ReferenceInLog::Topic(name)) => Some(name),
            Reference::InLog(ReferenceInLog::Tf { .. }) | Reference::File(_) => None,
        }
    }

    /// Whether the samples are `/tf` transforms: only estimate topics whose `frame_id` is
    /// their parent are compared.
    pub fn is_tf(&self) -> bool {
        matches!(self, Reference::InLog(ReferenceInLog::Tf { .. }))
    }
}

impl fmt::Display for Reference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reference::InLog(r) => r.fmt(f),
            Reference::File(path) => write!(f, "file:{path}"),
        }
    }
}

/// One pose of the reference trajectory: parent_from_child at `stamp_ns`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceSample {
    /// Stamp, ns (the header stamp; a TUM file's seconds).
    pub stamp_ns: i64,
    /// Position (x, y, z) in the parent frame.
    pub position: [f64; 3],
    /// Orientation (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
}

/// One pose-with-covariance message of an estimate topic, as read (every message that
/// decodes, usable or not).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateMessage<'a> {
    /// The topic.
    pub topic: &'a str,
    /// Its `header.frame_id` (the parent frame).
    pub frame_id: &'a str,
    /// Its number on the topic (0-based).
    pub index: u64,
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// Position (x, y, z).
    pub position: [f64; 3],
    /// Orientation (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
    /// The ROS covariance, row-major.
    pub covariance: &'a [f64; COV_LEN],
    /// The covariance is usable as a Gaussian (no health defect that forbids it).
    pub usable: bool,
    /// Per ROS axis: a placeholder (≥ 1e6) or zero variance, "not estimated".
    pub unestimated: [bool; 6],
    /// Its point of the topic's σ series (σ per axis, the position trace) as a summary's
    /// [`TopicSummary::series`](super::TopicSummary::series) holds it, when the series takes
    /// the message in as it arrives (`None`: thinned, the series' density halved already):
    /// what a live view streams of each message between its whole pictures.
    pub series: Option<super::SeriesPoint>,
}

/// Receives, in file order, every reference sample and every estimate message of a log while
/// it is read: what a streamed computation over every message (NEES) needs.
pub trait LogObserver {
    /// A reference sample whose parent frame is `frame_id` (empty when the message has none).
    fn reference(&mut self, frame_id: &str, sample: ReferenceSample);
    /// A message of a pose-with-covariance topic (the reference topic's own included: the
    /// observer leaves it out).
    fn estimate(&mut self, message: &EstimateMessage<'_>);
}

/// What the reader saw of the reference in the log.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReferenceRead {
    /// The log declares the reference topic (or `/tf`).
    pub found: bool,
    /// Its message type as the log names it, if found.
    pub message_type: Option<String>,
    /// The type is one a reference can be read from.
    pub readable: bool,
    /// Samples handed on (a `/tf` message can hold several transforms, others none).
    pub samples: u64,
    /// Messages that could not be decoded.
    pub undecodable: u64,
    /// `/tf` only: the parent frames seen for the child.
    pub parents: Vec<String>,
}
