//! Covariance-carrying messages that are not poses (issue 32): a sensor's message carries one or
//! more 3 × 3 covariance blocks, each of one quantity in one unit. Read (`input::log::sensor`)
//! into a [`SensorTopicSummary`] per topic: its health per block, σ statistics per axis and a
//! bounded σ series; evaluated and reported beside the pose topics.
//!
//! ```
//! use posecov::plan::log::{SensorKind, Class, Issue};
//! let imu = SensorKind::Imu;
//! assert_eq!(imu.ros2_name(), "sensor_msgs/msg/Imu");
//! assert_eq!(imu.blocks()[1].unit, "rad/s");
//! // REP 145's −1 in element 0, "not provided", is a note on a sensor topic.
//! assert_eq!(SensorKind::class(Issue::UnknownMarker), Class::Note);
//! ```

use serde::Serialize;

use super::{AxisStats, Class, Health, Issue};

/// The most blocks a sensor message carries.
pub const MAX_BLOCKS: usize = 3;

/// One 3 × 3 covariance block of a sensor message: which field it is, the unit of its σ and the
/// names of its three axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct BlockSpec {
    /// The quantity (`orientation`, `angular_velocity`, `linear_acceleration`): the message's
    /// field is this with `_covariance` after it.
    pub name: &'static str,
    /// The unit of σ = √Σᵢᵢ.
    pub unit: &'static str,
    /// The axes, in the block's row order.
    pub axes: [&'static str; 3],
}

/// The message types posecov reads covariances from that are not poses, and the twist half of
/// `nav_msgs/Odometry`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorKind {
    /// `sensor_msgs/Imu` (REP 145): orientation, angular velocity and linear acceleration,
    /// each with its 3 × 3 covariance in the message's `header.frame_id` axes.
    Imu,
    /// `sensor_msgs/NavSatFix`: a GNSS fix (WGS84 latitude, longitude, altitude) and its
    /// position covariance, m², in the East-North-Up tangent plane at the fix (REP 145, the
    /// message's comment), with its `position_covariance_type`.
    NavSatFix,
    /// `geometry_msgs/TwistWithCovarianceStamped` (wheel or visual odometry's velocity): the
    /// two 3 × 3 diagonal blocks of `twist.covariance` (linear, angular), in `header.frame_id`.
    Twist,
    /// `geometry_msgs/AccelWithCovarianceStamped`: the two 3 × 3 diagonal blocks of
    /// `accel.covariance` (linear, angular), in `header.frame_id`.
    Accel,
    /// The twist half of a `nav_msgs/Odometry` pose topic: `twist.covariance`'s two diagonal
    /// blocks, in the message's `child_frame_id` (nav_msgs/Odometry: "the twist in this message
    /// should be specified in the coordinate frame given by the child_frame_id"). Read beside
    /// the topic's pose, which it leaves unchanged; its stamps are the pose's, checked there.
    OdometryTwist,
}

/// An IMU's three blocks, in the message's order.
const IMU_BLOCKS: [BlockSpec; 3] = [
    BlockSpec {
        name: "orientation",
        unit: "rad",
        axes: ["x", "y", "z"],
    },
    BlockSpec {
        name: "angular_velocity",
        unit: "rad/s",
        axes: ["x", "y", "z"],
    },
    BlockSpec {
        name: "linear_acceleration",
        unit: "m/s²",
        axes: ["x", "y", "z"],
    },
];

/// A fix's one block: its position in the East-North-Up plane at the fix.
const NAVSAT_BLOCKS: [BlockSpec; 1] = [BlockSpec {
    name: "position",
    unit: "m",
    axes: ["east", "north", "up"],
}];

/// A twist's two blocks (`twist.covariance` rows and columns 0–2, then 3–5).
const TWIST_BLOCKS: [BlockSpec; 2] = [
    BlockSpec {
        name: "linear_velocity",
        unit: "m/s",
        axes: ["x", "y", "z"],
    },
    IMU_BLOCKS[1],
];

/// An acceleration's two blocks (`accel.covariance` rows and columns 0–2, then 3–5).
const ACCEL_BLOCKS: [BlockSpec; 2] = [
    IMU_BLOCKS[2],
    BlockSpec {
        name: "angular_acceleration",
        unit: "rad/s²",
        axes: ["x", "y", "z"],
    },
];

impl SensorKind {
    /// Every sensor kind.
    pub const ALL: [SensorKind; 5] = [
        SensorKind::Imu,
        SensorKind::NavSatFix,
        SensorKind::Twist,
        SensorKind::Accel,
        SensorKind::OdometryTwist,
    ];

    /// Whether the kind is a message type of its own (a topic of it is a sensor topic), not a
    /// part of a pose topic's message ([`SensorKind::OdometryTwist`]).
    ///
    /// ```
    /// use posecov::plan::log::SensorKind;
    /// assert!(SensorKind::Twist.is_own_message() && !SensorKind::OdometryTwist.is_own_message());
    /// ```
    pub fn is_own_message(self) -> bool {
        self != SensorKind::OdometryTwist
    }

    /// The message field whose value names the frame the covariances are in.
    ///
    /// ```
    /// use posecov::plan::log::SensorKind;
    /// assert_eq!(SensorKind::OdometryTwist.frame_field(), "child_frame_id");
    /// ```
    pub fn frame_field(self) -> &'static str {
        match self {
            SensorKind::OdometryTwist => "child_frame_id",
            _ => "header.frame_id",
        }
    }

    /// The message field a block's covariance is, as a user reads it in the message
    /// (`orientation_covariance`; `twist.covariance[0:3, 0:3]` for a 6 × 6 field's block: its
    /// rows and columns, end excluded).
    ///
    /// ```
    /// use posecov::plan::log::SensorKind;
    /// let k = SensorKind::Accel;
    /// assert_eq!(k.field(&k.blocks()[1]), "accel.covariance[3:6, 3:6]");
    /// assert_eq!(SensorKind::Imu.field(&SensorKind::Imu.blocks()[0]), "orientation_covariance");
    /// ```
    pub fn field(self, block: &BlockSpec) -> String {
        let six = match self {
            SensorKind::Twist | SensorKind::OdometryTwist => "twist",
            SensorKind::Accel => "accel",
            _ => return format!("{}_covariance", block.name),
        };
        let k = self.blocks().iter().position(|b| b == block).unwrap_or(0) * 3;
        format!("{six}.covariance[{k}:{}, {k}:{}]", k + 3, k + 3)
    }

    /// The ROS 1 type name (`sensor_msgs/Imu`).
    ///
    /// ```
    /// assert_eq!(posecov::plan::log::SensorKind::Imu.ros1_name(), "sensor_msgs/Imu");
    /// ```
    pub fn ros1_name(self) -> &'static str {
        match self {
            SensorKind::Imu => "sensor_msgs/Imu",
            SensorKind::NavSatFix => "sensor_msgs/NavSatFix",
            SensorKind::Twist => "geometry_msgs/TwistWithCovarianceStamped",
            SensorKind::Accel => "geometry_msgs/AccelWithCovarianceStamped",
            SensorKind::OdometryTwist => "nav_msgs/Odometry",
        }
    }

    /// The ROS 2 type name (`sensor_msgs/msg/Imu`).
    ///
    /// ```
    /// assert_eq!(posecov::plan::log::SensorKind::Imu.ros2_name(), "sensor_msgs/msg/Imu");
    /// ```
    pub fn ros2_name(self) -> &'static str {
        match self {
            SensorKind::Imu => "sensor_msgs/msg/Imu",
            SensorKind::NavSatFix => "sensor_msgs/msg/NavSatFix",
            SensorKind::Twist => "geometry_msgs/msg/TwistWithCovarianceStamped",
            SensorKind::Accel => "geometry_msgs/msg/AccelWithCovarianceStamped",
            SensorKind::OdometryTwist => "nav_msgs/msg/Odometry",
        }
    }

    /// Its covariance blocks, in the message's order.
    ///
    /// ```
    /// let b = posecov::plan::log::SensorKind::Imu.blocks();
    /// assert_eq!((b[0].name, b[0].unit, b[2].unit), ("orientation", "rad", "m/s²"));
    /// ```
    pub fn blocks(self) -> &'static [BlockSpec] {
        match self {
            SensorKind::Imu => &IMU_BLOCKS,
            SensorKind::NavSatFix => &NAVSAT_BLOCKS,
            SensorKind::Twist | SensorKind::OdometryTwist => &TWIST_BLOCKS,
            SensorKind::Accel => &ACCEL_BLOCKS,
        }
    }

    /// The class of `issue` on a sensor's block or topic. As on a pose topic
    /// ([`Issue::class`] of a topic that is not dead-reckoned), except `unknown_marker`: REP 145
    /// defines −1 in element 0 as "not provided", a note (the block is then not checked).
    /// A NavSatFix's `covariance_type_unknown`, `covariance_approximated` and `no_fix` are
    /// notes, `diagonal_known_off_diagonal` a defect ([`Issue::class`]).
    ///
    /// ```
    /// use posecov::plan::log::{Class, Issue, SensorKind};
    /// assert_eq!(SensorKind::class(Issue::AllZero), Class::Defect);
    /// assert_eq!(SensorKind::class(Issue::CovarianceTypeUnknown), Class::Note);
    /// assert_eq!(SensorKind::class(Issue::DiagonalKnownOffDiagonal), Class::Defect);
    /// assert_eq!(SensorKind::class(Issue::Constant), Class::Note);
    /// ```
    pub fn class(issue: Issue) -> Class {
        match issue {
            Issue::UnknownMarker => Class::Note,
            other => other.class(false),
        }
    }

    /// The class of `issue` on a block or topic of this kind: [`SensorKind::class`], except
    /// `all_zero` on an Odometry's twist, a note: many odometry publishers leave the twist
    /// covariance unset, and a consumer of the pose never reads it (on a
    /// `TwistWithCovarianceStamped`, published to be fused, it stays a defect).
    ///
    /// ```
    /// use posecov::plan::log::{Class, Issue, SensorKind};
    /// assert_eq!(SensorKind::OdometryTwist.class_of(Issue::AllZero), Class::Note);
    /// assert_eq!(SensorKind::Twist.class_of(Issue::AllZero), Class::Defect);
    /// ```
    pub fn class_of(self, issue: Issue) -> Class {
        match (self, issue) {
            (SensorKind::OdometryTwist, Issue::AllZero) => Class::Note,
            _ => Self::class(issue),
        }
    }
}

/// One point of a sensor topic's σ series: per block, σ of each axis where it is checked and
/// estimated (`None`: not provided, unusable, or a placeholder).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorSeriesPoint {
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// √Σᵢᵢ per block and axis, in the block's unit.
    pub sigma: [[Option<f64>; 3]; MAX_BLOCKS],
}

/// One block of a sensor topic, reduced.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockSummary {
    /// Which block.
    pub spec: BlockSpec,
    /// Its health: per issue the messages and the first (`unknown_marker`: the messages whose
    /// block is "not provided").
    pub health: Health,
    /// σ statistics per axis over the messages whose block is usable and estimates the axis.
    pub sigma_stats: [Option<AxisStats>; 3],
}

/// What a sensor topic's messages were, reduced to bounded data.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorTopicSummary {
    /// Topic name as in the log.
    pub name: String,
    /// Message type.
    pub kind: SensorKind,
    /// `header.frame_id` of the first message that has one.
    pub frame_id: String,
    /// Messages read.
    pub count: u64,
    /// Messages whose header stamp was zero (log time used).
    pub stamps_from_log_time: u64,
    /// Messages whose stamp is earlier than the one before.
    pub stamps_out_of_order: u64,
    /// Earliest and latest stamp (ns), if any message.
    pub stamp_range: Option<super::StampRange>,
    /// The topic's own findings: stamps, undecodable messages, other types.
    pub health: Health,
    /// Per covariance block, in the message's order.
    pub blocks: Vec<BlockSummary>,
    /// σ over the stamp (bounded, in stamp order).
    pub series: Vec<SensorSeriesPoint>,
    /// What is drawn of it ([`SensorDrawn`]).
    pub drawn: SensorDrawn,
}

/// What a sensor topic keeps for drawing: a NavSatFix's fixes, an IMU's newest orientation.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorDrawn {
    /// A NavSatFix's fixes (status not `NO_FIX`, a finite position), thinned as a pose topic's
    /// drawn messages (`--every`), in message order.
    pub fixes: Vec<FixPoint>,
    /// An IMU's newest message whose orientation is a unit quaternion and whose orientation
    /// block is usable and estimates some axis.
    pub orientation: Option<OrientationPoint>,
}

/// One GNSS fix kept for drawing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixPoint {
    /// The message's number on its topic.
    pub index: u64,
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// WGS84 latitude, degrees (north positive).
    pub latitude_deg: f64,
    /// WGS84 longitude, degrees (east positive).
    pub longitude_deg: f64,
    /// Altitude above the WGS84 ellipsoid, m.
    pub altitude_m: f64,
    /// The position covariance, row-major over (east, north, up), m², when its block is usable
    /// and checked.
    pub covariance_enu: Option<[f64; 9]>,
}

/// An IMU's orientation at one message and its orientation covariance (for the spray of
/// SO(3) samples).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientationPoint {
    /// The message's number on its topic.
    pub index: u64,
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// `orientation` (x, y, z, w): parent_from_imu.
    pub orientation_xyzw: [f64; 4],
    /// `orientation_covariance`, row-major over rotations about x, y, z, rad², with the rows
    /// and columns of an axis not estimated zeroed.
    pub covariance: [f64; 9],
    /// The axes whose variance is not estimated (0 or ≥ 1e6): not sprayed.
    pub unestimated: [bool; 3],
}

impl SensorTopicSummary {
    /// Every finding of the topic and its blocks with the block it is on (`None`: the
    /// topic's own), defects first, then in block order.
    ///
    /// ```
    /// use posecov::input::log::{LogOptions, read_log};
    /// use posecov::plan::log::{Class, Issue};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
    /// let plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    /// let imu = &plan.sensors[0];
    /// let found: Vec<_> = imu.findings().map(|(b, i, _, c)| (b, i, c)).collect();
    /// assert!(found.contains(&(Some("orientation"), Issue::Constant, Class::Note)));
    /// ```
    pub fn findings(
        &self,
    ) -> impl Iterator<Item = (Option<&'static str>, Issue, super::IssueCount, Class)> + '_ {
        let own = self.health.issues.iter().map(|(i, c)| (None, *i, *c));
        let blocks = self.blocks.iter().flat_map(|b| {
            b.health
                .issues
                .iter()
                .map(move |(i, c)| (Some(b.spec.name), *i, *c))
        });
        let mut all: Vec<_> = own
            .chain(blocks)
            .map(|(b, i, c)| (b, i, c, self.kind.class_of(i)))
            .collect();
        all.sort_by_key(|f| f.3);
        all.into_iter()
    }
}
