//! The typed plan of a robot log (ROS 1 bag or ROS 2 MCAP): what `input::bag` read, reduced
//! to bounded plain data — per topic its messages' facts, its covariance health, a decimated
//! set of messages to draw and bounded time series. Evaluation (`eval::bag`) turns it into
//! numbers; nothing here reads a file.
//!
//! ```
//! use posecov::plan::bag::{BagPlan, Health, Issue};
//! let mut health = Health::default();
//! health.note(Issue::Placeholder, 1_500_000_000);
//! health.note(Issue::Placeholder, 1_000_000_000);
//! assert_eq!(health.count(Issue::Placeholder), 2);
//! assert_eq!(health.first(Issue::Placeholder), Some(1_000_000_000));
//! assert!(BagPlan::default().topics.is_empty());
//! ```

use std::collections::BTreeMap;

use serde::Serialize;

/// A variance at or above this is a placeholder ("not estimated"), not a measurement.
pub const PLACEHOLDER: f64 = 1e6;

/// Number of entries of a ROS 6 × 6 covariance (row-major).
pub const COV_LEN: usize = 36;

/// Names of the six ROS covariance axes, in order (position in the parent frame's axes,
/// rotation about the body's axes).
pub const ROS_AXES: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];

/// The message types posecov reads a pose with covariance from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseMessageKind {
    /// `nav_msgs/Odometry` (pose part; the twist covariance is kept too).
    Odometry,
    /// `geometry_msgs/PoseWithCovarianceStamped`.
    PoseWithCovarianceStamped,
    /// `geometry_msgs/PoseWithCovariance` (no header: stamps are the log time).
    PoseWithCovariance,
}

impl PoseMessageKind {
    /// The ROS 1 type name (`nav_msgs/Odometry`).
    ///
    /// ```
    /// use posecov::plan::bag::PoseMessageKind;
    /// assert_eq!(PoseMessageKind::Odometry.ros1_name(), "nav_msgs/Odometry");
    /// ```
    pub fn ros1_name(self) -> &'static str {
        match self {
            PoseMessageKind::Odometry => "nav_msgs/Odometry",
            PoseMessageKind::PoseWithCovarianceStamped => "geometry_msgs/PoseWithCovarianceStamped",
            PoseMessageKind::PoseWithCovariance => "geometry_msgs/PoseWithCovariance",
        }
    }

    /// The ROS 2 type name (`nav_msgs/msg/Odometry`).
    ///
    /// ```
    /// use posecov::plan::bag::PoseMessageKind;
    /// assert_eq!(PoseMessageKind::PoseWithCovariance.ros2_name(), "geometry_msgs/msg/PoseWithCovariance");
    /// ```
    pub fn ros2_name(self) -> &'static str {
        match self {
            PoseMessageKind::Odometry => "nav_msgs/msg/Odometry",
            PoseMessageKind::PoseWithCovarianceStamped => {
                "geometry_msgs/msg/PoseWithCovarianceStamped"
            }
            PoseMessageKind::PoseWithCovariance => "geometry_msgs/msg/PoseWithCovariance",
        }
    }

    /// Every kind.
    pub const ALL: [PoseMessageKind; 3] = [
        PoseMessageKind::Odometry,
        PoseMessageKind::PoseWithCovarianceStamped,
        PoseMessageKind::PoseWithCovariance,
    ];
}

/// A decoded pose with covariance, in ROS's own layout and meaning
/// ([CONVENTIONS §6](crate::conventions#6-ros-posewithcovariance)).
#[derive(Debug, Clone, PartialEq)]
pub struct PoseMessage {
    /// When: the header stamp, or the log time when the header has none (see `from_log_time`),
    /// nanoseconds since the epoch (or since the simulation's start).
    pub stamp_ns: i64,
    /// The header stamp was zero or missing and the log (receive) time is used instead.
    pub from_log_time: bool,
    /// `pose.position` (x, y, z) in the parent frame.
    pub position: [f64; 3],
    /// `pose.orientation` (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
    /// `pose.covariance`, row-major (x, y, z, rotX, rotY, rotZ).
    pub covariance: [f64; COV_LEN],
    /// `twist.covariance` of an Odometry message (body frame), if any.
    pub twist_covariance: Option<[f64; COV_LEN]>,
}

/// A covariance problem one message can have (several at once).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Issue {
    /// Every entry is 0: the publisher does not know (REP 105 / REP 145 "unknown").
    AllZero,
    /// `covariance[0] = -1`: ROS's marker for "this covariance is unknown".
    UnknownMarker,
    /// Some diagonal entry ≥ 1e6 (1e6, 1e9, 1.79e308 …): a placeholder for "not estimated".
    Placeholder,
    /// An entry is NaN or ±∞.
    NonFinite,
    /// Σ ≠ Σᵀ beyond rounding.
    Asymmetric,
    /// The smallest eigenvalue (over the estimated axes) is below zero beyond rounding.
    NotPsd,
    /// The orientation is not a unit quaternion (or not finite).
    BadOrientation,
    /// The position covariance shrank suddenly (trace ÷ ≥ 5 from one message to the next):
    /// a relocalisation, a loop closure or a reset.
    SuddenDrop,
    /// The position covariance kept growing without a correction (trace ≥ 100 × its value
    /// after the last drop): dead reckoning only.
    Growth,
    /// The bytes could not be decoded as the message type (truncated or another definition).
    Undecodable,
}

impl Issue {
    /// Whether a message with this issue cannot be drawn as a Gaussian (it is drawn as an
    /// invalid marker instead). Placeholders, drops and growth are facts, not errors.
    ///
    /// ```
    /// use posecov::plan::bag::Issue;
    /// assert!(Issue::NotPsd.unusable() && !Issue::Placeholder.unusable());
    /// ```
    pub fn unusable(self) -> bool {
        !matches!(self, Issue::Placeholder | Issue::SuddenDrop | Issue::Growth)
    }
}

/// How often an issue was seen, and when first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IssueCount {
    /// Messages with the issue.
    pub count: u64,
    /// Stamp (ns) of the earliest such message.
    pub first_stamp_ns: i64,
}

/// A topic's covariance health: per issue, the count and first stamp; the worst smallest
/// eigenvalue of a not-PSD covariance.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Health {
    /// Per issue.
    pub issues: BTreeMap<Issue, IssueCount>,
    /// The most negative smallest eigenvalue seen (only when some message is not PSD).
    pub min_eigenvalue: Option<f64>,
}

impl Health {
    /// Counts one message with `issue` at `stamp_ns`.
    pub fn note(&mut self, issue: Issue, stamp_ns: i64) {
        let entry = self.issues.entry(issue).or_insert(IssueCount {
            count: 0,
            first_stamp_ns: stamp_ns,
        });
        entry.count += 1;
        entry.first_stamp_ns = entry.first_stamp_ns.min(stamp_ns);
    }

    /// Messages with `issue`.
    pub fn count(&self, issue: Issue) -> u64 {
        self.issues.get(&issue).map_or(0, |c| c.count)
    }

    /// Stamp of the first message with `issue`.
    pub fn first(&self, issue: Issue) -> Option<i64> {
        self.issues.get(&issue).map(|c| c.first_stamp_ns)
    }
}

/// One point of a topic's time series: σ of each ROS axis (NaN-free: `None` where the axis is
/// a placeholder, unknown or the message unusable) and the position trace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesPoint {
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// √Σᵢᵢ per ROS axis (x, y, z in the parent's axes; roll, pitch, yaw), where meaningful.
    pub sigma: [Option<f64>; 6],
    /// Trace of the estimated position block (m²).
    pub position_trace: Option<f64>,
}

/// A message kept for drawing: its number on the topic (0-based), the message, and whether
/// it can be drawn as a Gaussian (else the issues that prevent it).
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnMessage {
    /// Index among the topic's messages.
    pub index: u64,
    /// The message.
    pub message: PoseMessage,
    /// Issues that make it unusable (empty: usable).
    pub unusable: Vec<Issue>,
    /// Axes whose variance is a placeholder (≥ 1e6) or exactly zero, per ROS axis.
    pub unestimated: [bool; 6],
}

/// What a topic's messages were, reduced to bounded data.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicPlan {
    /// Topic name as in the log.
    pub name: String,
    /// Message type.
    pub kind: PoseMessageKind,
    /// `header.frame_id` of the first message (the parent frame), if any.
    pub frame_id: String,
    /// `child_frame_id` of the first Odometry message, if any.
    pub child_frame_id: String,
    /// Messages read.
    pub count: u64,
    /// Messages whose header stamp was missing or zero (log time used).
    pub stamps_from_log_time: u64,
    /// Messages whose stamp is earlier than the one before (kept; series are sorted).
    pub stamps_out_of_order: u64,
    /// Earliest and latest stamp (ns), if any message.
    pub stamp_range: Option<(i64, i64)>,
    /// Covariance health.
    pub health: Health,
    /// Every usable message has z, roll and pitch unestimated (zero or placeholder): the
    /// topic is drawn in the x–y plane as SE(2).
    pub planar: bool,
    /// Messages kept for drawing (at most the configured count; evenly spaced by `stride`).
    pub drawn: Vec<DrawnMessage>,
    /// One kept message in `stride`.
    pub stride: u64,
    /// Positions along the trajectory (bounded, in stamp order), with their stamps.
    pub trajectory: Vec<(i64, [f64; 3])>,
    /// Time series (bounded, in stamp order).
    pub series: Vec<SeriesPoint>,
}

impl TopicPlan {
    /// √ of the twist covariance's diagonal (vx vy vz ωx ωy ωz, in the child frame) of the last
    /// drawn Odometry message, where finite and not a placeholder (`None` per entry otherwise;
    /// `None` for other types).
    ///
    /// ```
    /// use posecov::input::bag::{BagOptions, read_bag};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
    /// let plan = read_bag(path.as_ref(), &BagOptions::default(), &mut |_, _| {}, None).unwrap();
    /// let sigma = plan.topics[0].twist_sigmas().unwrap();
    /// assert!((sigma[0].unwrap() - 0.001f64.sqrt()).abs() < 1e-12);
    /// assert_eq!(sigma[3], None); // a 1e6 placeholder
    /// ```
    pub fn twist_sigmas(&self) -> Option<[Option<f64>; 6]> {
        let twist = self.drawn.last()?.message.twist_covariance?;
        Some(std::array::from_fn(|i| {
            let v = twist[i * 7];
            (v.is_finite() && (0.0..PLACEHOLDER).contains(&v)).then(|| v.sqrt())
        }))
    }
}

/// A topic of another message type, skipped.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedTopic {
    /// Topic name.
    pub name: String,
    /// Its message type (and why it was skipped, when not simply another type).
    pub message_type: String,
    /// Messages on it.
    pub count: u64,
}

/// A whole log, reduced: the pose topics and what was skipped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BagPlan {
    /// The pose-with-covariance topics read (filtered by `--topic`), in name order.
    pub topics: Vec<TopicPlan>,
    /// Other topics, in name order.
    pub skipped: Vec<SkippedTopic>,
    /// Pose topics present but not asked for with `--topic`.
    pub not_selected: Vec<String>,
    /// Messages in the whole log.
    pub messages_total: u64,
    /// The read stopped early (Ctrl-C): everything before was read.
    pub cancelled: bool,
}
