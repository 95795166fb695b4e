//! The typed plan of a robot log (ROS 1 bag or ROS 2 MCAP): what `input::log` read, reduced
//! to bounded plain data — per topic its messages' facts, its covariance health, a decimated
//! set of messages to draw and bounded time series. Evaluation (`eval::log`) turns it into
//! numbers; nothing here reads a file.
//!
//! ```
//! use posecov::plan::log::{LogSummary, Health, Issue};
//! let mut health = Health::default();
//! health.note(Issue::Placeholder, 1_500_000_000, 0);
//! health.note(Issue::Placeholder, 1_000_000_000, 1);
//! assert_eq!(health.count(Issue::Placeholder), 2);
//! assert_eq!(health.first(Issue::Placeholder), Some(1_000_000_000));
//! assert!(LogSummary::default().topics.is_empty());
//! ```

use serde::Serialize;

use crate::lie::GroupKind;

mod decimate;
mod reference;
pub use decimate::Decimator;
pub use reference::{
    EstimateMessage, LogObserver, Reference, ReferenceInLog, ReferenceRead, ReferenceSample,
};
mod cut;
pub use cut::LogCut;
mod stream;
pub use stream::{MAX_NOTED, StreamNotes};
mod tf;
pub use tf::{MAX_TF_EDGES, MAX_TF_SAMPLES, TfEdge, TfTree, UndecodableTf};
mod health;
pub use health::{Class, Health, Issue, IssueCount, Stretch};
mod sensor;
pub use sensor::{
    BlockSpec, BlockSummary, FixPoint, MAX_BLOCKS, OrientationPoint, SensorDrawn, SensorKind,
    SensorSeriesPoint, SensorTopicSummary,
};

/// A variance at or above this is a placeholder ("not estimated"), not a measurement.
pub const PLACEHOLDER: f64 = 1e6;

/// Default number of messages drawn per topic (at most; evenly spaced).
pub const DEFAULT_MAX_DRAWN: usize = 200;
/// However `--every` is set, at most this many messages per topic are drawn (the stride is
/// doubled beyond, and the text panel says so).
pub const MAX_DRAWN_LIMIT: usize = 5000;

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
    /// A line of an OpenVINS `ov_eval` text trajectory (`input::log::ov_eval`), read into
    /// ROS's layout.
    OvEval,
}

impl PoseMessageKind {
    /// The ROS 1 type name (`nav_msgs/Odometry`).
    ///
    /// ```
    /// use posecov::plan::log::PoseMessageKind;
    /// assert_eq!(PoseMessageKind::Odometry.ros1_name(), "nav_msgs/Odometry");
    /// ```
    pub fn ros1_name(self) -> &'static str {
        match self {
            PoseMessageKind::Odometry => "nav_msgs/Odometry",
            PoseMessageKind::PoseWithCovarianceStamped => "geometry_msgs/PoseWithCovarianceStamped",
            PoseMessageKind::PoseWithCovariance => "geometry_msgs/PoseWithCovariance",
            PoseMessageKind::OvEval => "ov_eval trajectory line",
        }
    }

    /// The ROS 2 type name (`nav_msgs/msg/Odometry`).
    ///
    /// ```
    /// use posecov::plan::log::PoseMessageKind;
    /// assert_eq!(PoseMessageKind::PoseWithCovariance.ros2_name(), "geometry_msgs/msg/PoseWithCovariance");
    /// ```
    pub fn ros2_name(self) -> &'static str {
        match self {
            PoseMessageKind::Odometry => "nav_msgs/msg/Odometry",
            PoseMessageKind::PoseWithCovarianceStamped => {
                "geometry_msgs/msg/PoseWithCovarianceStamped"
            }
            PoseMessageKind::PoseWithCovariance => "geometry_msgs/msg/PoseWithCovariance",
            PoseMessageKind::OvEval => "ov_eval trajectory line",
        }
    }

    /// Every kind a ROS message is read as (not [`OvEval`](Self::OvEval), a text line).
    pub const ALL: [PoseMessageKind; 3] = [
        PoseMessageKind::Odometry,
        PoseMessageKind::PoseWithCovarianceStamped,
        PoseMessageKind::PoseWithCovariance,
    ];
}

/// A decoded pose with covariance, in ROS's own layout and meaning
/// ([CONVENTIONS §6](crate::conventions#6-ros-posewithcovariance)): the one message struct of
/// the log wing, from the decoders (`input::log::decode`) to the drawn messages.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseMessage {
    /// When: the header stamp, or the log time when the header has none (see `from_log_time`),
    /// nanoseconds since the epoch (or since the simulation's start). A decoder that finds no
    /// header stamp sets 0 and `from_log_time`; the log reader puts the log time in.
    pub stamp_ns: i64,
    /// The header stamp was zero or missing and the log (receive) time is used instead.
    pub from_log_time: bool,
    /// `header.frame_id` (empty when the message has no header).
    pub frame_id: String,
    /// `child_frame_id` (Odometry; else empty).
    pub child_frame_id: String,
    /// `pose.position` (x, y, z) in the parent frame.
    pub position: [f64; 3],
    /// `pose.orientation` (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
    /// `pose.covariance`, row-major (x, y, z, rotX, rotY, rotZ).
    pub covariance: [f64; COV_LEN],
    /// `twist.covariance` of an Odometry message (body frame), if any.
    pub twist_covariance: Option<[f64; COV_LEN]>,
}

/// The earliest and latest header stamp among a topic's messages (ns since the epoch), in
/// message order's min and max: `first_ns ≤ last_ns`.
///
/// ```
/// use posecov::plan::log::StampRange;
/// let r = StampRange::new(5).widened(2).widened(9);
/// assert_eq!(r, StampRange { first_ns: 2, last_ns: 9 });
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StampRange {
    /// Earliest stamp, ns.
    pub first_ns: i64,
    /// Latest stamp, ns.
    pub last_ns: i64,
}

impl StampRange {
    /// The range of one stamp.
    ///
    /// ```
    /// # use posecov::plan::log::StampRange;
    /// assert_eq!(StampRange::new(3).last_ns, 3);
    /// ```
    pub fn new(stamp_ns: i64) -> Self {
        Self {
            first_ns: stamp_ns,
            last_ns: stamp_ns,
        }
    }

    /// The range widened to hold `stamp_ns`.
    ///
    /// ```
    /// # use posecov::plan::log::StampRange;
    /// assert_eq!(StampRange::new(3).widened(1).first_ns, 1);
    /// ```
    pub fn widened(self, stamp_ns: i64) -> Self {
        Self {
            first_ns: self.first_ns.min(stamp_ns),
            last_ns: self.last_ns.max(stamp_ns),
        }
    }
}

/// One point of a topic's trajectory: where a message put its child frame (`position`, m, in
/// the message's `frame_id`, or the common frame once joined) at its stamp.
///
/// ```
/// use posecov::plan::log::TrackPoint;
/// let p = TrackPoint { stamp_ns: 1_000, position: [1.0, 2.0, 0.0] };
/// assert_eq!(p.position[1], 2.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackPoint {
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// Position, m.
    pub position: [f64; 3],
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

/// Statistics of one axis's σ, streamed over every message where the axis is estimated (a
/// usable message, the axis neither a placeholder nor zero): memory does not grow with the
/// log. The median needs the values, so it is taken over the kept series in `eval::log`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisStats {
    /// Messages counted.
    pub messages: u64,
    /// σ of the first such message (in file order).
    pub first: f64,
    /// σ of the last.
    pub last: f64,
    /// Smallest σ.
    pub min: f64,
    /// Largest σ.
    pub max: f64,
}

impl AxisStats {
    /// Adds the next message's σ to `stats` (starting them with the first).
    ///
    /// ```
    /// use posecov::plan::log::AxisStats;
    /// let mut s = None;
    /// for sigma in [0.2, 0.1, 0.3] {
    ///     AxisStats::add(&mut s, sigma);
    /// }
    /// let s = s.unwrap();
    /// assert_eq!((s.messages, s.first, s.last, s.min, s.max), (3, 0.2, 0.3, 0.1, 0.3));
    /// ```
    pub fn add(stats: &mut Option<AxisStats>, sigma: f64) {
        match stats {
            Some(s) => {
                s.messages += 1;
                s.last = sigma;
                s.min = s.min.min(sigma);
                s.max = s.max.max(sigma);
            }
            None => {
                *stats = Some(AxisStats {
                    messages: 1,
                    first: sigma,
                    last: sigma,
                    min: sigma,
                    max: sigma,
                })
            }
        }
    }

    /// The statistics of the square roots (statistics kept over variances, σ²: `√` keeps
    /// their order, so the smallest and largest root are the roots of the smallest and
    /// largest, to the bit).
    ///
    /// ```
    /// use posecov::plan::log::AxisStats;
    /// let mut s = None;
    /// for variance in [0.25, 0.0625, 0.5625] {
    ///     AxisStats::add(&mut s, variance);
    /// }
    /// let s = s.unwrap().sqrt();
    /// assert_eq!((s.first, s.last, s.min, s.max), (0.5, 0.75, 0.25, 0.75));
    /// ```
    pub fn sqrt(self) -> AxisStats {
        AxisStats {
            messages: self.messages,
            first: self.first.sqrt(),
            last: self.last.sqrt(),
            min: self.min.sqrt(),
            max: self.max.sqrt(),
        }
    }
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
pub struct TopicSummary {
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
    pub stamp_range: Option<StampRange>,
    /// Covariance health.
    pub health: Health,
    /// The topic's group, which gives its degrees of freedom ([`GroupKind::dof`],
    /// [`GroupKind::position_dims`]): SE(2) when every usable message has z, roll and pitch
    /// unestimated (zero or placeholder), so the topic is drawn in the x–y plane; else SE(3).
    pub group: GroupKind,
    /// Messages kept for drawing (at most the configured count; evenly spaced by `stride`).
    pub drawn: Vec<DrawnMessage>,
    /// The twist covariance (row-major 6 × 6, child frame) of the last drawn Odometry
    /// message, kept when the log is read: [`TopicSummary::twist_sigmas`] reads it after the
    /// evaluation has moved `drawn` out.
    pub last_twist_covariance: Option<[f64; COV_LEN]>,
    /// One kept message in `stride`.
    pub stride: u64,
    /// Positions along the trajectory (bounded, in stamp order), with their stamps.
    pub trajectory: Vec<TrackPoint>,
    /// Time series (bounded, in stamp order).
    pub series: Vec<SeriesPoint>,
    /// σ statistics per ROS axis (x, y, z, roll, pitch, yaw) over every message where the
    /// axis is estimated; `None` where it never is.
    pub sigma_stats: [Option<AxisStats>; 6],
}

/// Whether `frame_id` names an odometry frame as REP 105 does (`odom`, or a namespaced
/// `robot1/odom`, `odom_combined`): poses in it are dead-reckoned, so their covariance grows.
///
/// ```
/// use posecov::plan::log::is_odom_frame;
/// assert!(is_odom_frame("odom") && is_odom_frame("/robot1/odom") && !is_odom_frame("map"));
/// ```
pub fn is_odom_frame(frame_id: &str) -> bool {
    frame_id
        .rsplit('/')
        .next()
        .is_some_and(|last| last.starts_with("odom"))
}

impl TopicSummary {
    /// An Odometry topic in an odometry frame ([`is_odom_frame`]): dead reckoning, whose
    /// covariance must grow while the robot moves.
    pub fn dead_reckoned(&self) -> bool {
        self.kind == PoseMessageKind::Odometry && is_odom_frame(&self.frame_id)
    }

    /// The class of `issue` on this topic ([`Issue::class`]).
    pub fn class(&self, issue: Issue) -> Class {
        issue.class(self.dead_reckoned())
    }

    /// The defects found, with their counts, in the order of [`Issue::ALL`].
    pub fn defects(&self) -> impl Iterator<Item = (Issue, IssueCount)> + '_ {
        self.health
            .issues
            .iter()
            .filter(|(i, _)| self.class(**i) == Class::Defect)
            .map(|(i, c)| (*i, *c))
    }

    /// √ of the twist covariance's diagonal (vx vy vz ωx ωy ωz, in the child frame) of the last
    /// drawn Odometry message, where finite and not a placeholder (`None` per entry otherwise;
    /// `None` for other types).
    ///
    /// ```
    /// use posecov::input::log::{LogOptions, read_log};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
    /// let plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    /// let sigma = plan.topics[0].twist_sigmas().unwrap();
    /// assert!((sigma[0].unwrap() - 0.001f64.sqrt()).abs() < 1e-12);
    /// assert_eq!(sigma[3], None); // a 1e6 placeholder
    /// ```
    pub fn twist_sigmas(&self) -> Option<[Option<f64>; 6]> {
        let twist = self.last_twist_covariance?;
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

/// A whole log, reduced: the pose topics, the sensor topics and what was skipped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LogSummary {
    /// The pose-with-covariance topics read (filtered by `--topic`), in name order.
    pub topics: Vec<TopicSummary>,
    /// The covariance-carrying topics that are not poses (`sensor_msgs/Imu`), filtered by
    /// `--topic`, in name order.
    pub sensors: Vec<SensorTopicSummary>,
    /// Other topics, in name order.
    pub skipped: Vec<SkippedTopic>,
    /// Pose topics present but not asked for with `--topic`.
    pub not_selected: Vec<String>,
    /// Messages in the whole log.
    pub messages_total: u64,
    /// The read stopped early (Ctrl-C): everything before was read.
    pub cancelled: bool,
    /// What the reader saw of the reference asked for in the log (`--reference`), if any.
    pub reference: Option<ReferenceRead>,
    /// The read stopped at a cut or a damage before the file's end: everything before was
    /// read.
    pub cut: Option<LogCut>,
    /// A live stream's notes (`ws://…`): damaged frames skipped, connections lost; `None`
    /// for a file.
    pub stream: Option<StreamNotes>,
    /// The log's `/tf` and `/tf_static` transforms, bounded ([`TfTree`]): what joins topics
    /// in different frames (`eval::log::frames`).
    pub tf: TfTree,
}
