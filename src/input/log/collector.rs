//! The one collector every log reader feeds ([`Collector`]): each stream (a ROS 1
//! connection, an MCAP channel, a live stream's channel) declared with what posecov makes of
//! it ([`Stream`]), then every message in order — pose topics decoded and counted, the
//! reference and `/tf` kept — and at the end the bounded [`LogSummary`]. A live stream's
//! reader also asks it, as messages arrive, for the summary so far ([`Collector::grow`]).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crate::plan::log::{
    EstimateMessage, LogCut, LogObserver, LogSummary, PoseMessage, PoseMessageKind, ReferenceInLog,
    ReferenceRead, SensorKind, SkippedTopic, StreamNotes,
};

use super::growth::{self, Growth};
use super::reference::{self, ReferenceType};
use super::sensor::{SensorState, decode_sensor};
use super::stream::{Codec, Stream};
use super::topic::TopicState;
use super::{InputError, LogOptions, decode, tf, velocity};
use crate::input::suggest;

/// Receives every message of a log in file order.
pub(super) struct Collector<'a, 'o> {
    options: &'a LogOptions,
    cancel: Option<&'a AtomicBool>,
    cancelled: bool,
    topics: BTreeMap<String, TopicState>,
    /// The sensor topics (covariance-carrying messages that are not poses).
    sensors: BTreeMap<String, SensorState>,
    /// The twist half of each `nav_msgs/Odometry` pose topic, read beside its pose.
    twists: BTreeMap<String, SensorState>,
    /// Per topic of another type: its type, messages and the first one's log time.
    skipped: BTreeMap<String, (String, u64, i64)>,
    not_selected: BTreeMap<String, ()>,
    pub(super) total: u64,
    observer: Option<&'o mut dyn LogObserver>,
    reference: Option<ReferenceRead>,
    /// Where a read without an index stopped before the file's end.
    pub(super) cut: Option<LogCut>,
    tf: tf::TfCollector,
    /// While a live stream is read and drawn: when the read began and when the next summary
    /// so far is due.
    growth: Option<Growth>,
}

impl<'a, 'o> Collector<'a, 'o> {
    pub(super) fn new(
        options: &'a LogOptions,
        cancel: Option<&'a AtomicBool>,
        observer: Option<&'o mut dyn LogObserver>,
    ) -> Self {
        Self {
            options,
            cancel,
            cancelled: false,
            topics: BTreeMap::new(),
            sensors: BTreeMap::new(),
            twists: BTreeMap::new(),
            skipped: BTreeMap::new(),
            not_selected: BTreeMap::new(),
            total: 0,
            observer,
            reference: options.reference.as_ref().map(|_| ReferenceRead::default()),
            cut: None,
            tf: tf::TfCollector::default(),
            growth: None,
        }
    }

    /// The same collector, its summary so far handed on by [`Self::grow`] when `drawn`.
    pub(super) fn growing(mut self, drawn: bool) -> Self {
        self.growth = drawn.then(Growth::new);
        self
    }

    /// The summary read so far (with the stream's `notes` so far) when one is due and a pose
    /// message has arrived, for a [`Self::growing`] collector: a copy of the bounded state,
    /// thinned for a growing picture ([`growth::thin`]); the collector goes on unchanged.
    /// `cost` is what drawing the last one took ([`Growth::handed_on`]).
    pub(super) fn grow(
        &mut self,
        notes: &dyn Fn() -> StreamNotes,
        cost: Duration,
    ) -> Option<LogSummary> {
        if !self.growth.as_ref()?.due() {
            return None;
        }
        let mut plan = assemble(
            self.topics.clone(),
            self.sensors.clone(),
            self.twists.clone(),
            self.skipped.clone(),
            self.not_selected.clone(),
            self.total,
            self.cancelled,
            self.reference.clone(),
            self.cut.clone(),
            self.tf.clone().finish(),
        );
        if plan.topics.iter().all(|t| t.count == 0) && plan.sensors.iter().all(|t| t.count == 0) {
            return None;
        }
        growth::thin(&mut plan);
        plan.stream = Some(notes());
        if let Some(growth) = &mut self.growth {
            growth.handed_on(cost);
        }
        Some(plan)
    }

    /// Whether `topic` carries the reference asked for (its topic, or `/tf` for `tf:CHILD`).
    pub(super) fn is_reference(&self, topic: &str) -> bool {
        self.options.carries_reference(topic)
    }

    /// A stream the log declares: its topic, and the reference if it is the reference's.
    pub(super) fn declare_stream(&mut self, stream: &Stream) {
        match &stream.sensor {
            Some(Ok(kind)) if self.selected(&stream.topic) => {
                // A topic declared as a pose topic first stays one (its sensor messages are
                // a type change).
                let known = self.topics.contains_key(&stream.topic);
                if !known && !self.sensors.contains_key(&stream.topic) {
                    let state = SensorState::new(*kind, self.options.every);
                    self.sensors.insert(stream.topic.clone(), state);
                }
            }
            Some(Ok(_)) => _ = self.not_selected.insert(stream.topic.clone(), ()),
            Some(Err(why)) => {
                let why = Err(why.clone());
                self.declare(&stream.topic, &stream.type_name, Some(&why));
            }
            None => self.declare(&stream.topic, &stream.type_name, stream.kind.as_ref()),
        }
        self.declare_reference(stream);
    }

    /// One message of a sensor `kind` on `topic`, logged at `log_time_ns`.
    fn sensor_message(
        &mut self,
        stream: &Stream,
        kind: SensorKind,
        log_time_ns: i64,
        bytes: &[u8],
        codec: Codec,
    ) {
        self.total += 1;
        let topic = &stream.topic;
        if !self.selected(topic) {
            self.not_selected.insert(topic.to_owned(), ());
            return;
        }
        if let Some(state) = self.topics.get_mut(topic) {
            // A pose topic that carries a sensor type too: not read, a defect.
            state.other_type(&stream.type_name, log_time_ns);
            return;
        }
        let state = self
            .sensors
            .entry(topic.to_owned())
            .or_insert_with(|| SensorState::new(kind, self.options.every));
        if state.kind != kind {
            let index = state.count();
            state
                .health
                .other_type(&stream.type_name, log_time_ns, index);
            return;
        }
        state.add(decode_sensor(kind, codec, bytes), log_time_ns);
    }

    /// Notes the reference's stream (its type), once.
    pub(super) fn declare_reference(&mut self, stream: &Stream) {
        if self.is_reference(&stream.topic)
            && let Some(read) = &mut self.reference
            && !read.found
        {
            read.found = true;
            read.message_type = Some(match &stream.reference {
                Some(Err(why)) => why.clone(),
                _ => stream.type_name.clone(),
            });
            let tf = matches!(self.options.reference, Some(ReferenceInLog::Tf { .. }));
            read.readable = match stream.reference {
                Some(Ok(ReferenceType::TfMessage)) => tf,
                Some(Ok(_)) => !tf,
                _ => false,
            };
        }
    }

    /// A message on the reference's stream: its poses (those of the child frame asked for, in
    /// `/tf`) to the observer.
    pub(super) fn reference_message(
        &mut self,
        stream: &Stream,
        log_time_ns: i64,
        bytes: &[u8],
        codec: Codec,
    ) {
        self.declare_reference(stream);
        let Some(read) = &mut self.reference else {
            return;
        };
        let Some(Ok(kind)) = stream.reference else {
            return;
        };
        if !read.readable {
            return;
        }
        let poses = match reference::decode_reference(kind, codec, bytes) {
            Ok(poses) => poses,
            Err(_) => {
                read.undecodable += 1;
                return;
            }
        };
        let child = match &self.options.reference {
            Some(ReferenceInLog::Tf { child }) => Some(child.trim_start_matches('/')),
            _ => None,
        };
        for pose in poses {
            if let Some(child) = child {
                if pose.child_frame_id.trim_start_matches('/') != child {
                    continue;
                }
                let parent = pose.frame_id.trim_start_matches('/');
                if !read.parents.iter().any(|p| p == parent) {
                    read.parents.push(parent.to_owned());
                }
            }
            read.samples += 1;
            if let Some(observer) = self.observer.as_deref_mut() {
                observer.reference(&pose.frame_id, pose.sample(log_time_ns));
            }
        }
    }

    /// Whether to stop (Ctrl-C).
    pub(super) fn stop(&mut self) -> bool {
        if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            self.cancelled = true;
        }
        self.cancelled
    }

    /// A topic the log declares (a ROS 1 connection, an MCAP channel), so that a topic with
    /// no messages is still listed.
    pub(super) fn declare(
        &mut self,
        topic: &str,
        type_name: &str,
        kind: Option<&Result<PoseMessageKind, String>>,
    ) {
        match kind {
            Some(Ok(kind)) if self.selected(topic) => {
                if !self.topics.contains_key(topic) && !self.sensors.contains_key(topic) {
                    let state = TopicState::new(*kind, self.options.every);
                    self.topics.insert(topic.to_owned(), state);
                }
            }
            Some(Ok(_)) => _ = self.not_selected.insert(topic.to_owned(), ()),
            other => {
                if !self.skipped.contains_key(topic) {
                    let label = match other {
                        Some(Err(why)) => why.clone(),
                        _ => type_name.to_owned(),
                    };
                    self.skipped.insert(topic.to_owned(), (label, 0, i64::MAX));
                }
            }
        }
    }

    pub(super) fn selected(&self, topic: &str) -> bool {
        self.options.selects(topic)
    }

    /// One message on stream `id` (`streams[id]`), logged at `log_time` ns; an undeclared
    /// stream is an error (`what` names connection or channel).
    pub(super) fn message_on(
        &mut self,
        stream: Option<&Stream>,
        what: &str,
        id: u64,
        log_time: u64,
        bytes: &[u8],
        codec: Codec,
    ) -> Result<(), String> {
        let Some(stream) = stream else {
            return Err(format!(
                "a message on {what} {id} that the file never declares"
            ));
        };
        let log_ns = i64::try_from(log_time).unwrap_or(i64::MAX);
        if self.is_reference(&stream.topic) {
            self.reference_message(stream, log_ns, bytes, codec);
        }
        self.tf.message(stream, log_ns, bytes, codec);
        if let Some(Ok(sensor)) = stream.sensor {
            self.sensor_message(stream, sensor, log_ns, bytes, codec);
            return Ok(());
        }
        let kind = stream.kind.as_ref();
        self.message(&stream.topic, &stream.type_name, kind, log_ns, bytes, codec);
        Ok(())
    }

    /// One message: `kind` is `None` for another type, `Some(Err(why))` for a pose type whose
    /// definition does not match.
    pub(super) fn message(
        &mut self,
        topic: &str,
        type_name: &str,
        kind: Option<&Result<PoseMessageKind, String>>,
        log_time_ns: i64,
        bytes: &[u8],
        codec: Codec,
    ) {
        self.total += 1;
        let label = |other: Option<&Result<PoseMessageKind, String>>| match other {
            Some(Err(why)) => why.clone(),
            _ => type_name.to_owned(),
        };
        let kind = match kind {
            Some(Ok(kind)) => *kind,
            other => {
                if let Some(state) = self.topics.get_mut(topic) {
                    // A pose topic that carries another type too: not read, a defect.
                    state.other_type(&label(other), log_time_ns);
                } else if let Some(state) = self.sensors.get_mut(topic) {
                    let index = state.count();
                    state.health.other_type(&label(other), log_time_ns, index);
                } else if let Some(entry) = self.skipped.get_mut(topic) {
                    entry.1 += 1;
                    entry.2 = entry.2.min(log_time_ns);
                } else {
                    self.skipped
                        .insert(topic.to_owned(), (label(other), 1, log_time_ns));
                }
                return;
            }
        };
        let decode = |kind| match codec {
            Codec::Ros1 => decode::decode_ros1(kind, bytes),
            Codec::Cdr => decode::decode_cdr(kind, bytes),
        };
        self.message_decoded(topic, type_name, kind, log_time_ns, decode);
    }

    /// One message of a pose `kind` (type `type_name`) on `topic`, `decode`d once it is to be
    /// read (a text line is decoded already: `ov_eval.rs`).
    pub(super) fn message_decoded(
        &mut self,
        topic: &str,
        type_name: &str,
        kind: PoseMessageKind,
        log_time_ns: i64,
        decode: impl FnOnce(PoseMessageKind) -> Result<PoseMessage, decode::DecodeError>,
    ) {
        if !self.selected(topic) {
            self.not_selected.insert(topic.to_owned(), ());
            return;
        }
        if self.sensors.get(topic).is_some_and(|s| s.count() == 0) {
            // Declared as a sensor topic but without its messages yet: the pose type's.
            self.sensors.remove(topic);
        }
        if let Some(state) = self.sensors.get_mut(topic) {
            // A sensor topic that carries a pose type too: not read, a defect.
            let index = state.count();
            state.health.other_type(type_name, log_time_ns, index);
            return;
        }
        let every = self.options.every;
        if !self.topics.contains_key(topic) {
            self.topics
                .insert(topic.to_owned(), TopicState::new(kind, every));
        }
        let Some(state) = self.topics.get_mut(topic) else {
            return;
        };
        if state.kind != kind {
            state.other_type(type_name, log_time_ns);
            return;
        }
        let decoded = decode(state.kind);
        if state.kind == PoseMessageKind::Odometry {
            let twist = match &decoded {
                Ok(m) => velocity::odometry_twist(m)
                    .ok_or_else(|| decode::DecodeError("no twist".to_owned())),
                Err(e) => Err(e.clone()),
            };
            self.twists
                .entry(topic.to_owned())
                .or_insert_with(|| SensorState::new(SensorKind::OdometryTwist, every))
                .add(twist, log_time_ns);
        }
        let observer = self.observer.as_deref_mut();
        state.add(decoded, log_time_ns, |a, m| {
            if let Some(observer) = observer {
                observer.estimate(&EstimateMessage {
                    topic,
                    frame_id: &m.frame_id,
                    index: a.index,
                    stamp_ns: m.stamp_ns,
                    position: m.position,
                    orientation_xyzw: m.orientation_xyzw,
                    covariance: &m.covariance,
                    usable: a.usable,
                    unestimated: a.unestimated,
                    series: a.series,
                });
            }
        });
    }

    pub(super) fn finish(self, path: &Path) -> Result<LogSummary, InputError> {
        for wanted in &self.options.topics {
            let read = self.topics.contains_key(wanted) || self.sensors.contains_key(wanted);
            if !read && !self.cancelled {
                let why = match self.skipped.get(wanted) {
                    Some((t, ..)) => {
                        format!("its messages are {t}, not a message with a covariance")
                    }
                    None => {
                        let have: Vec<&str> = self
                            .topics
                            .keys()
                            .chain(self.sensors.keys())
                            .chain(self.not_selected.keys())
                            .map(String::as_str)
                            .collect();
                        format!(
                            "no such topic; {}topics with a covariance in this log: {}",
                            suggest::did_you_mean(wanted, have.iter().copied()),
                            if have.is_empty() {
                                "none".to_owned()
                            } else {
                                have.join(", ")
                            }
                        )
                    }
                };
                return Err(InputError::Format {
                    file: path.display().to_string(),
                    message: format!("--topic {wanted}: {why}"),
                });
            }
        }
        Ok(assemble(
            self.topics,
            self.sensors,
            self.twists,
            self.skipped,
            self.not_selected,
            self.total,
            self.cancelled,
            self.reference,
            self.cut,
            self.tf.finish(),
        ))
    }
}

/// The [`LogSummary`] of a collector's parts (at the end, or a copy while a stream grows).
#[allow(clippy::too_many_arguments)]
fn assemble(
    mut topics: BTreeMap<String, TopicState>,
    mut sensors: BTreeMap<String, SensorState>,
    twists: BTreeMap<String, SensorState>,
    mut skipped: BTreeMap<String, (String, u64, i64)>,
    not_selected: BTreeMap<String, ()>,
    total: u64,
    cancelled: bool,
    reference: Option<ReferenceRead>,
    cut: Option<LogCut>,
    tf: crate::plan::log::TfTree,
) -> LogSummary {
    // A topic declared (or first seen) with another type before its pose messages: those
    // messages are the pose topic's type change, not a topic of their own.
    for (name, state) in &mut topics {
        if let Some((label, count, first)) = skipped.remove(name) {
            state.other_type_before(label, count, first);
        }
    }
    for (name, state) in &mut sensors {
        if let Some((label, count, first)) = skipped.remove(name) {
            state.health.other_type_before(label, count, first);
        }
    }
    LogSummary {
        topics: topics
            .into_iter()
            .map(|(name, s)| s.into_plan(name))
            .collect(),
        sensors: {
            let mut all: Vec<_> = sensors.into_iter().chain(twists).collect();
            all.sort_by(|a, b| a.0.cmp(&b.0));
            all.into_iter().map(|(name, s)| s.into_plan(name)).collect()
        },
        skipped: skipped
            .into_iter()
            .map(|(name, (message_type, count, _))| SkippedTopic {
                name,
                message_type,
                count,
            })
            .collect(),
        not_selected: not_selected.into_keys().collect(),
        messages_total: total,
        cancelled,
        reference,
        cut,
        stream: None,
        tf,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_declared_topic_without_messages_is_listed() {
        let options = LogOptions::default();
        let mut c = Collector::new(&options, None, None);
        let kind = Ok(PoseMessageKind::PoseWithCovarianceStamped);
        c.declare(
            "/empty",
            "geometry_msgs/PoseWithCovarianceStamped",
            Some(&kind),
        );
        c.declare("/camera", "sensor_msgs/Image", None);
        let plan = c.finish(Path::new("x.bag")).unwrap();
        assert_eq!(plan.topics.len(), 1);
        assert_eq!(
            (plan.topics[0].name.as_str(), plan.topics[0].count),
            ("/empty", 0)
        );
        assert!(!plan.topics[0].group.is_planar());
        assert_eq!(plan.skipped[0].count, 0);
        // Evaluating and drawing it: tests/bag_mcap.rs (`a_topic_without_messages_is_drawn`).
    }
}
