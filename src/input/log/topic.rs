//! One topic's streaming state: every message of a pose topic passes through
//! [`TopicState::add`] (stamps, health, constancy, σ statistics, decimated drawn messages and
//! series); [`TopicState::into_plan`] reduces it to a [`TopicSummary`]. Memory is bounded by the
//! decimators, whatever the log's length.

use crate::lie::GroupKind;
use crate::plan::log::{
    Decimator, DrawnMessage, Health, Issue, IssueCount, LogSummary, PoseMessage, PoseMessageKind,
    SensorKind, SeriesPoint, StampRange, TopicSummary, TrackPoint, is_odom_frame,
};

use super::decode::DecodeError;
use super::health::TopicHealth;
use super::{DEFAULT_MAX_DRAWN, MAX_DRAWN_LIMIT, MAX_SERIES};

/// A message [`TopicState::add`] took: what an observer of every message needs beside the
/// message itself.
pub(super) struct Added {
    pub(super) index: u64,
    pub(super) usable: bool,
    pub(super) unestimated: [bool; 6],
    /// Its series point (σ), when the series took it in.
    pub(super) series: Option<SeriesPoint>,
}

/// A series point as kept (each axis's variance) made what a summary shows (its σ).
fn with_sigma(mut p: SeriesPoint) -> SeriesPoint {
    p.sigma = p.sigma.map(|v| v.map(f64::sqrt));
    p
}

/// A topic's stamps, streamed: the one place their findings are made (`stamp_fallback`,
/// `stamp_order`, `frozen_stamp`) for pose and sensor topics alike.
#[derive(Debug, Clone, Default)]
pub(super) struct Stamps {
    /// Messages whose header stamp was zero (the log time used).
    pub(super) from_log: u64,
    /// Messages earlier than the one before.
    pub(super) out_of_order: u64,
    last: Option<i64>,
    /// Earliest and latest stamp.
    pub(super) range: Option<StampRange>,
}

impl Stamps {
    /// Message `index`'s stamp (`from_log_time`: its header's was zero; `headed`: its type has
    /// a header, so a zero or repeated stamp is a finding), its findings noted in `health`.
    pub(super) fn next(
        &mut self,
        stamp_ns: i64,
        from_log_time: bool,
        headed: bool,
        index: u64,
        health: &mut Health,
    ) {
        if from_log_time && headed {
            self.from_log += 1;
            health.note(Issue::StampFallback, stamp_ns, index);
        }
        if self.last.is_some_and(|last| stamp_ns < last) {
            self.out_of_order += 1;
            health.note(Issue::StampOrder, stamp_ns, index);
        }
        if headed && !from_log_time && self.last == Some(stamp_ns) {
            health.note(Issue::FrozenStamp, stamp_ns, index);
        }
        self.last = Some(stamp_ns);
        self.range = Some(
            self.range
                .map_or(StampRange::new(stamp_ns), |r| r.widened(stamp_ns)),
        );
    }
}

/// The per-topic streaming state (cloned for the summary so far of a growing live read).
#[derive(Clone)]
pub(super) struct TopicState {
    pub(super) kind: PoseMessageKind,
    frame_id: Option<String>,
    child_frame_id: Option<String>,
    count: u64,
    stamps: Stamps,
    /// Health classes and σ statistics.
    pub(super) checks: TopicHealth,
    drawn: Decimator<DrawnMessage>,
    trajectory: Decimator<TrackPoint>,
    /// The series, with each axis's variance in place of its σ: the square roots are taken
    /// for the points kept only ([`Self::into_plan`]).
    series: Decimator<SeriesPoint>,
}

impl TopicState {
    pub(super) fn new(kind: PoseMessageKind, every: Option<u64>) -> Self {
        TopicState {
            kind,
            frame_id: None,
            child_frame_id: None,
            count: 0,
            stamps: Stamps::default(),
            checks: TopicHealth::default(),
            drawn: match every {
                Some(n) => Decimator::new(n, MAX_DRAWN_LIMIT),
                None => Decimator::new(1, DEFAULT_MAX_DRAWN),
            },
            trajectory: Decimator::new(1, MAX_SERIES),
            series: Decimator::new(1, MAX_SERIES),
        }
    }

    /// Takes the next message: `observe` sees it once its stamp is resolved (not when it
    /// could not be decoded); then it moves into the drawn set when drawn.
    pub(super) fn add(
        &mut self,
        decoded: Result<PoseMessage, DecodeError>,
        log_time_ns: i64,
        observe: impl FnOnce(&Added, &PoseMessage),
    ) {
        let index = self.count;
        self.count += 1;
        let mut d = match decoded {
            Ok(d) => d,
            Err(_) => {
                self.checks
                    .health
                    .note(Issue::Undecodable, log_time_ns, index);
                return;
            }
        };
        if d.from_log_time {
            d.stamp_ns = log_time_ns;
        }
        let stamp_ns = d.stamp_ns;
        let headed = self.kind != PoseMessageKind::PoseWithCovariance;
        self.stamps.next(
            stamp_ns,
            d.from_log_time,
            headed,
            index,
            &mut self.checks.health,
        );
        if self.frame_id.is_none() && !d.frame_id.is_empty() {
            self.frame_id = Some(d.frame_id.clone());
        }
        if self.child_frame_id.is_none() && !d.child_frame_id.is_empty() {
            self.child_frame_id = Some(d.child_frame_id.clone());
        }
        let dead_reckoned = self.kind == PoseMessageKind::Odometry
            && self.frame_id.as_deref().is_some_and(is_odom_frame);
        let (h, variance) = self.checks.add(index, stamp_ns, &d, dead_reckoned);
        let usable = h.usable();
        if usable && d.position.iter().all(|v| v.is_finite()) {
            self.trajectory.push(
                index,
                TrackPoint {
                    stamp_ns,
                    position: d.position,
                },
            );
        }
        let point = SeriesPoint {
            stamp_ns,
            sigma: variance,
            position_trace: h.position_trace,
        };
        let in_series = self.series.wants(index);
        self.series.push(index, point);
        let added = Added {
            index,
            usable,
            unestimated: h.unestimated,
            series: in_series.then(|| with_sigma(point)),
        };
        observe(&added, &d);
        if self.drawn.wants(index) {
            let unusable = h.issues.iter().filter(|i| i.unusable()).collect();
            self.drawn.push(
                index,
                DrawnMessage {
                    index,
                    message: d,
                    unusable,
                    unestimated: h.unestimated,
                },
            );
        }
    }

    /// A message of another type on this topic (`type_name`, logged at `log_time_ns`): not
    /// read, counted as a [`Issue::TypeChange`] after the messages read so far.
    pub(super) fn other_type(&mut self, type_name: &str, log_time_ns: i64) {
        let health = &mut self.checks.health;
        health.other_type(type_name, log_time_ns, self.count);
    }

    /// `count` messages of another type (`type_name`, the first logged at `first_log_ns`)
    /// seen on this topic before it was known as a pose topic.
    pub(super) fn other_type_before(&mut self, type_name: String, count: u64, first_log_ns: i64) {
        let health = &mut self.checks.health;
        health.other_type_before(type_name, count, first_log_ns);
    }

    pub(super) fn into_plan(self, name: String) -> TopicSummary {
        let stride = self.drawn.stride();
        let mut trajectory = self.trajectory.into_items();
        trajectory.sort_by_key(|p| p.stamp_ns);
        let mut series: Vec<SeriesPoint> = self
            .series
            .into_items()
            .into_iter()
            .map(with_sigma)
            .collect();
        series.sort_by_key(|p| p.stamp_ns);
        let checks = self.checks;
        let sigma_stats = checks.sigma_stats();
        let planar = checks.planar && checks.usable > 0;
        let (mut health, constant) = checks.into_findings();
        if !planar && let Some(on_used_axes) = health.issues.remove(&Issue::Placeholder) {
            // z, roll and pitch are axes a 3-D topic uses.
            health.add(Issue::PlaceholderUsedAxis, on_used_axes);
        }
        if let Some(stretch) = constant {
            health.add(
                Issue::Constant,
                IssueCount {
                    count: stretch.messages,
                    first_stamp_ns: stretch.first_stamp_ns,
                    first_index: stretch.first_index,
                },
            );
            health.constant = Some(stretch);
        }
        let drawn = self.drawn.into_items();
        let last_twist_covariance = drawn.last().and_then(|d| d.message.twist_covariance);
        TopicSummary {
            name,
            kind: self.kind,
            frame_id: self.frame_id.unwrap_or_default(),
            child_frame_id: self.child_frame_id.unwrap_or_default(),
            count: self.count,
            stamps_from_log_time: self.stamps.from_log,
            stamps_out_of_order: self.stamps.out_of_order,
            stamp_range: self.stamps.range,
            health,
            group: if planar {
                GroupKind::Se2
            } else {
                GroupKind::Se3
            },
            drawn,
            last_twist_covariance,
            stride,
            trajectory,
            series,
            sigma_stats,
        }
    }
}

/// Why a log has nothing to check: the topics it has (type and count), its topics with a
/// covariance but without messages, and the types posecov reads.
pub(super) fn no_covariance_topic(plan: &LogSummary) -> String {
    const SHOWN: usize = 12;
    let mut has: Vec<String> = plan
        .skipped
        .iter()
        .take(SHOWN)
        .map(|k| format!("{} ({}, {} messages)", k.name, k.message_type, k.count))
        .collect();
    if plan.skipped.len() > SHOWN {
        has.push(format!("… and {} more topics", plan.skipped.len() - SHOWN));
    }
    let empty: Vec<&str> = plan
        .topics
        .iter()
        .map(|t| t.name.as_str())
        .chain(plan.sensors.iter().map(|t| t.name.as_str()))
        .collect();
    if !empty.is_empty() {
        has.push(format!(
            "topics with a covariance but no messages: {}",
            empty.join(", ")
        ));
    }
    let has = if has.is_empty() {
        "no messages at all".to_owned()
    } else {
        has.join(", ")
    };
    let names = PoseMessageKind::ALL
        .iter()
        .map(|k| (k.ros1_name(), k.ros2_name()))
        .chain(
            SensorKind::ALL
                .iter()
                .filter(|k| k.is_own_message())
                .map(|k| (k.ros1_name(), k.ros2_name())),
        );
    let reads: Vec<String> = names
        .map(|(ros1, ros2)| format!("{ros1} (ROS 2: {ros2})"))
        .collect();
    format!(
        "no topic with a covariance to check; the log has {has}; posecov reads {}",
        reads.join(", ")
    )
}
