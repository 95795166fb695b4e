//! The one table of a log's health findings ([`Issue`]: its `--allow` name, JSON word and
//! [`Class`]), and what a topic's health holds ([`Health`]: per issue its count and first
//! place, the worst eigenvalue, the longest constant stretch).

use std::collections::BTreeMap;

use serde::Serialize;

/// Whether a health finding makes a log's covariance untrustworthy (`posecov check` fails on
/// it unless `--allow`ed) or is worth knowing only. Defects sort first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// The covariance cannot be trusted as published.
    Defect,
    /// A fact about the covariance or the stamps, not an error.
    Note,
}

/// A health finding: of a topic's covariance and stamps (a message can have several), or of
/// the log's `/tf` tree (the `Tf…` kinds, found when frames are joined:
/// [`crate::eval::log::frames::FrameProblemKind`]). This is the one table of findings: its
/// `--allow` name and JSON word is [`Issue::name`], its class [`Issue::class`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Issue {
    /// An entry is NaN or ±∞.
    NonFinite,
    /// Σ ≠ Σᵀ beyond the tolerance.
    Asymmetric,
    /// The smallest eigenvalue (over the estimated axes) is below −tolerance.
    NotPsd,
    /// The bytes could not be decoded as the message type (truncated or another definition).
    Undecodable,
    /// The orientation is not a unit quaternion (or not finite).
    BadOrientation,
    /// `covariance[0] = -1`: ROS's marker for "this covariance is unknown".
    UnknownMarker,
    /// Every entry is 0 on the estimated axes (placeholder axes aside): the publisher does not
    /// know, or never filled it in.
    AllZero,
    /// A variance ≥ 1e6 on an axis the motion uses (x, y, yaw; all six on a 3-D topic).
    PlaceholderUsedAxis,
    /// The covariance stays identical (or, dead-reckoned, does not grow) while the pose moves.
    Constant,
    /// The same header stamp on consecutive messages.
    FrozenStamp,
    /// Messages of another type on the topic (another publisher, a changed definition): not
    /// read; the types are [`Health::other_types`].
    TypeChange,
    /// The log's `/tf` has a chain of parents that comes back to itself: nothing is joined
    /// through it.
    TfCycle,
    /// The log's `/tf` gives a child frame several parents, where tf allows one: nothing is
    /// joined through that frame.
    TfSeveralParents,
    /// A variance ≥ 1e6 on an axis planar motion does not use (z, roll, pitch): "not
    /// estimated".
    Placeholder,
    /// A zero header stamp, replaced by the log time.
    StampFallback,
    /// A stamp earlier than the message before.
    StampOrder,
    /// The position trace divided by ≥ 5 from one usable message to the next: a
    /// relocalisation, a loop closure or a reset.
    Drop,
    /// The position trace ≥ 100 × its smallest value since the last drop: dead reckoning
    /// without correction.
    Growth,
    /// Topics' frames are in `/tf`, but in trees no transform joins: drawn apart.
    TfMissingLink,
    /// A topic's frame never gets a transform in `/tf` or `/tf_static`: drawn apart.
    TfNoTransform,
    /// A planar topic whose transform tilts its plane: drawn apart.
    TfTiltsPlane,
    /// `sensor_msgs/NavSatFix` with `position_covariance_type` = `COVARIANCE_TYPE_UNKNOWN` (0):
    /// the receiver gives no covariance; the block is not checked.
    CovarianceTypeUnknown,
    /// `sensor_msgs/NavSatFix` with `COVARIANCE_TYPE_APPROXIMATED` (1): a covariance made up
    /// from the dilution of precision, not the receiver's estimate.
    CovarianceApproximated,
    /// `sensor_msgs/NavSatFix` with `COVARIANCE_TYPE_DIAGONAL_KNOWN` (2) whose off-diagonal
    /// entries are not all zero: the type and the numbers disagree.
    DiagonalKnownOffDiagonal,
    /// `sensor_msgs/NavSatFix` with `status.status` = `STATUS_NO_FIX` (−1): the position is not
    /// a fix (not drawn).
    NoFix,
}

impl Issue {
    /// Every finding, defects first.
    pub const ALL: [Issue; 25] = [
        Issue::NonFinite,
        Issue::Asymmetric,
        Issue::NotPsd,
        Issue::Undecodable,
        Issue::BadOrientation,
        Issue::UnknownMarker,
        Issue::AllZero,
        Issue::PlaceholderUsedAxis,
        Issue::Constant,
        Issue::FrozenStamp,
        Issue::TypeChange,
        Issue::TfCycle,
        Issue::TfSeveralParents,
        Issue::Placeholder,
        Issue::StampFallback,
        Issue::StampOrder,
        Issue::Drop,
        Issue::Growth,
        Issue::TfMissingLink,
        Issue::TfNoTransform,
        Issue::TfTiltsPlane,
        Issue::CovarianceTypeUnknown,
        Issue::CovarianceApproximated,
        Issue::DiagonalKnownOffDiagonal,
        Issue::NoFix,
    ];

    /// The `--allow` name and JSON key.
    ///
    /// ```
    /// use posecov::plan::log::Issue;
    /// assert_eq!(Issue::PlaceholderUsedAxis.name(), "placeholder_used_axis");
    /// assert_eq!(Issue::from_name("not_psd"), Some(Issue::NotPsd));
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Issue::NonFinite => "non_finite",
            Issue::Asymmetric => "asymmetric",
            Issue::NotPsd => "not_psd",
            Issue::Undecodable => "undecodable",
            Issue::BadOrientation => "bad_orientation",
            Issue::UnknownMarker => "unknown_marker",
            Issue::AllZero => "all_zero",
            Issue::PlaceholderUsedAxis => "placeholder_used_axis",
            Issue::Constant => "constant",
            Issue::FrozenStamp => "frozen_stamp",
            Issue::TypeChange => "type_change",
            Issue::TfCycle => "tf_cycle",
            Issue::TfSeveralParents => "tf_several_parents",
            Issue::Placeholder => "placeholder",
            Issue::StampFallback => "stamp_fallback",
            Issue::StampOrder => "stamp_order",
            Issue::Drop => "drop",
            Issue::Growth => "growth",
            Issue::TfMissingLink => "tf_missing_link",
            Issue::TfNoTransform => "tf_no_transform",
            Issue::TfTiltsPlane => "tf_tilts_plane",
            Issue::CovarianceTypeUnknown => "covariance_type_unknown",
            Issue::CovarianceApproximated => "covariance_approximated",
            Issue::DiagonalKnownOffDiagonal => "diagonal_known_off_diagonal",
            Issue::NoFix => "no_fix",
        }
    }

    /// The finding of an `--allow` name, if any.
    pub fn from_name(name: &str) -> Option<Issue> {
        Issue::ALL.into_iter().find(|i| i.name() == name)
    }

    /// Defect or note; `constant` is a defect on a dead-reckoned topic (its covariance must
    /// grow) and a note elsewhere.
    ///
    /// ```
    /// use posecov::plan::log::{Class, Issue};
    /// assert_eq!(Issue::Constant.class(true), Class::Defect);
    /// assert_eq!(Issue::Constant.class(false), Class::Note);
    /// assert_eq!(Issue::Placeholder.class(true), Class::Note);
    /// assert_eq!(Issue::TfCycle.class(false), Class::Defect);
    /// ```
    pub fn class(self, dead_reckoned: bool) -> Class {
        match self {
            Issue::Constant if !dead_reckoned => Class::Note,
            Issue::Placeholder
            | Issue::StampFallback
            | Issue::StampOrder
            | Issue::Drop
            | Issue::Growth
            | Issue::TfMissingLink
            | Issue::TfNoTransform
            | Issue::TfTiltsPlane
            | Issue::CovarianceTypeUnknown
            | Issue::CovarianceApproximated
            | Issue::NoFix => Class::Note,
            _ => Class::Defect,
        }
    }

    /// Whether a message with this issue cannot be drawn as a Gaussian (it is drawn as an
    /// invalid marker instead). Placeholders, stamps, drops, growth and constancy are facts
    /// about a drawable covariance.
    ///
    /// ```
    /// use posecov::plan::log::Issue;
    /// assert!(Issue::NotPsd.unusable() && !Issue::Placeholder.unusable());
    /// ```
    pub const fn unusable(self) -> bool {
        matches!(
            self,
            Issue::NonFinite
                | Issue::Asymmetric
                | Issue::NotPsd
                | Issue::Undecodable
                | Issue::BadOrientation
                | Issue::UnknownMarker
                | Issue::AllZero
                | Issue::CovarianceTypeUnknown
        )
    }
}

/// How often an issue was seen, and where first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IssueCount {
    /// Messages with the issue.
    pub count: u64,
    /// Stamp (ns) of the earliest such message.
    pub first_stamp_ns: i64,
    /// That message's number on its topic (0-based).
    pub first_index: u64,
}

/// The longest stretch of messages over which a topic's covariance stayed identical (or, on a
/// dead-reckoned topic, did not grow) while the pose moved.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stretch {
    /// Messages in it.
    pub messages: u64,
    /// The first one's number on the topic.
    pub first_index: u64,
    /// Its first stamp, ns.
    pub first_stamp_ns: i64,
    /// Its last stamp, ns.
    pub last_stamp_ns: i64,
    /// The distance the position travelled over it, m (sum of the steps).
    pub distance_m: f64,
}

/// A topic's covariance health: per issue, the count and first stamp; the worst smallest
/// eigenvalue of a not-PSD covariance; the longest constant stretch.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Health {
    /// Per issue.
    pub issues: BTreeMap<Issue, IssueCount>,
    /// The most negative smallest eigenvalue seen (only when some message is not PSD).
    pub min_eigenvalue: Option<f64>,
    /// The longest stretch without growth while moving (when it makes a `constant` finding).
    pub constant: Option<Stretch>,
    /// The other message types seen on the topic (a `type_change` finding), in order seen.
    pub other_types: Vec<String>,
}

impl Health {
    /// Counts message number `index` with `issue` at `stamp_ns`.
    pub fn note(&mut self, issue: Issue, stamp_ns: i64, index: u64) {
        self.add(
            issue,
            IssueCount {
                count: 1,
                first_stamp_ns: stamp_ns,
                first_index: index,
            },
        );
    }

    /// Adds `counted` messages with `issue` (the earliest stamp is kept as the first).
    pub fn add(&mut self, issue: Issue, counted: IssueCount) {
        let entry = self.issues.entry(issue).or_insert(IssueCount {
            count: 0,
            ..counted
        });
        entry.count += counted.count;
        if counted.first_stamp_ns < entry.first_stamp_ns {
            entry.first_stamp_ns = counted.first_stamp_ns;
            entry.first_index = counted.first_index;
        }
    }

    /// A message of another type (`type_name`, logged at `log_time_ns`) on the topic, after
    /// `index` messages of its own: not read, a [`Issue::TypeChange`].
    ///
    /// ```
    /// use posecov::plan::log::{Health, Issue};
    /// let mut h = Health::default();
    /// h.other_type("sensor_msgs/msg/Image", 5, 3);
    /// h.other_type("sensor_msgs/msg/Image", 6, 4);
    /// assert_eq!((h.count(Issue::TypeChange), h.other_types.len()), (2, 1));
    /// ```
    pub fn other_type(&mut self, type_name: &str, log_time_ns: i64, index: u64) {
        if !self.other_types.iter().any(|t| t == type_name) {
            self.other_types.push(type_name.to_owned());
        }
        self.note(Issue::TypeChange, log_time_ns, index);
    }

    /// `count` messages of another type (`type_name`, the first logged at `first_log_ns`) seen
    /// on the topic before its own type was known.
    ///
    /// ```
    /// use posecov::plan::log::{Health, Issue};
    /// let mut h = Health::default();
    /// h.other_type_before("std_msgs/String".into(), 3, 7);
    /// assert_eq!(h.first(Issue::TypeChange), Some(7));
    /// ```
    pub fn other_type_before(&mut self, type_name: String, count: u64, first_log_ns: i64) {
        if count == 0 {
            return;
        }
        self.other_types.push(type_name);
        let first = IssueCount {
            count,
            first_stamp_ns: first_log_ns,
            first_index: 0,
        };
        self.add(Issue::TypeChange, first);
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
