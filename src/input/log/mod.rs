//! Robot logs: ROS 1 bags (format 2.0; uncompressed, bz2 and lz4 chunks, through the `rosbag`
//! crate), MCAP files (CDR or ROS 1 messages, through the `mcap` crate's streaming reader and
//! `re_cdr`) and ROS 2 bags (`rosbag2.rs`: a directory of SQLite `.db3` files, `sqlite.rs`, or
//! MCAP files; or one `.db3`). All are streamed: messages are decoded one at a time into a bounded
//! [`LogSummary`] — every message's health is counted, a decimated set of messages is kept for
//! drawing, and time series are kept at a bounded length (halving their density when full).
//!
//! Messages read: `nav_msgs/Odometry`, `geometry_msgs/PoseWithCovarianceStamped`,
//! `geometry_msgs/PoseWithCovariance`, and `/tf` + `/tf_static` kept per edge (`tf.rs`); other
//! types are listed as skipped. Stamps are the header stamp, or the log time when it is zero.
//!
//! ```
//! use posecov::input::log::{LogOptions, read_log};
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
//! let plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
//! assert_eq!(plan.topics[0].name, "/jackal_velocity_controller/odom");
//! assert!(plan.topics[0].group.is_planar());
//! ```

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::plan::log::{
    EstimateMessage, LogCut, LogObserver, LogSummary, PoseMessageKind, ReferenceInLog,
    ReferenceRead, SkippedTopic,
};

use super::format::{self, Format};
use super::suggest;
use super::{InputError, Located, Place};

pub mod bundled;
pub mod decode;
pub mod health;
mod mcap;
mod mcap_records;
pub mod reference;
mod ros1;
mod ros1_linear;
pub mod rosbag2;
mod sqlite;
mod tf;
mod topic;
pub mod ws;

use reference::ReferenceType;
use topic::{TopicState, no_pose_topic};

/// The largest record or decompressed chunk of a log read (1 GiB): larger ones are refused,
/// not allocated.
pub const RECORD_LIMIT: usize = 1 << 30;
/// A compressed chunk may claim at most this many times its compressed length (plus 1 MiB)
/// once decompressed: real logs compress ROS messages about 8:1, and a falsified size is
/// refused before anything is allocated for it.
pub const MAX_CHUNK_RATIO: u64 = 1024;

pub use crate::plan::log::{DEFAULT_MAX_DRAWN, MAX_DRAWN_LIMIT};
/// Points kept per topic for the trajectory and the time series (density halves beyond).
pub const MAX_SERIES: usize = 20_000;

/// What to read and how much to keep.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LogOptions {
    /// Topics to read (`--topic`, repeatable); empty: every pose topic.
    pub topics: Vec<String>,
    /// Draw every N-th message (`--every N`); `None`: at most [`DEFAULT_MAX_DRAWN`].
    pub every: Option<u64>,
    /// The reference in the log (`--reference`): its samples go to the observer of
    /// [`read_located_observed`], and what was seen of it to [`LogSummary::reference`].
    pub reference: Option<ReferenceInLog>,
    /// A live stream's limits and recording (`--duration`, `--messages`, `--record`); refused
    /// for a file.
    pub live: ws::LiveOptions,
}

/// Reads a log file into a [`LogSummary`], its format by content and extension
/// ([`format::detect`]): [`locate`](crate::input::locate) the file, then [`read_located`].
/// For tests and benchmarks that hold a path; the application locates once and calls
/// [`read_located`].
///
/// See the [module docs](self) for an example.
pub fn read_log(
    path: &Path,
    options: &LogOptions,
    progress: &mut dyn FnMut(u64, u64),
    cancel: Option<&AtomicBool>,
) -> Result<LogSummary, InputError> {
    let file = path.display().to_string();
    let located = Located {
        place: Place::File(path.to_owned()),
        format: if path.is_dir() {
            format::detect_dir(path)?
        } else {
            format::detect(&file, &format::read_head(path)?)?
        },
    };
    read_located(&located, options, progress, cancel)
}

/// Reads a located robot log (a file, or a bundled log) into a [`LogSummary`] by its decided
/// format: the one arm per log source. `progress(done, total)` is called as the read advances
/// (chunks or bytes); a raised `cancel` stops the read at the next message and marks the plan
/// `cancelled` (everything before is kept). Errors name the file: unreadable, damaged, not a
/// log, or a `--topic` it lacks.
///
/// A new log source (a live topic subscription is the next one) is one module that hands
/// every message to the per-topic collector, as `ros1.rs` and `mcap.rs` do, and one arm here.
///
/// ```
/// use posecov::input::{locate, log::{LogOptions, read_located}};
/// let log = locate("covariance_health").unwrap();
/// let plan = read_located(&log, &LogOptions::default(), &mut |_, _| {}, None).unwrap();
/// assert_eq!(plan.topics.len(), 3);
/// ```
pub fn read_located(
    located: &Located,
    options: &LogOptions,
    progress: &mut dyn FnMut(u64, u64),
    cancel: Option<&AtomicBool>,
) -> Result<LogSummary, InputError> {
    read_located_observed(located, options, progress, cancel, None)
}

/// [`read_located`], handing every reference sample (`options.reference`) and every estimate
/// message to `observer` in file order, while the log streams by.
///
/// ```
/// use posecov::input::{locate, log::{LogOptions, read_located_observed}};
/// use posecov::plan::log::{EstimateMessage, LogObserver, ReferenceSample};
/// struct Count(u64);
/// impl LogObserver for Count {
///     fn reference(&mut self, _: &str, _: ReferenceSample) {}
///     fn estimate(&mut self, _: &EstimateMessage<'_>) { self.0 += 1; }
/// }
/// let mut count = Count(0);
/// let log = locate("covariance_health").unwrap();
/// let plan = read_located_observed(&log, &LogOptions::default(), &mut |_, _| {}, None, Some(&mut count)).unwrap();
/// // Every message that decodes (an undecodable one has no pose to hand on).
/// use posecov::plan::log::Issue;
/// let decoded: u64 = plan.topics.iter().map(|t| t.count - t.health.count(Issue::Undecodable)).sum();
/// assert_eq!(count.0, decoded);
/// ```
pub fn read_located_observed(
    located: &Located,
    options: &LogOptions,
    progress: &mut dyn FnMut(u64, u64),
    cancel: Option<&AtomicBool>,
    observer: Option<&mut dyn LogObserver>,
) -> Result<LogSummary, InputError> {
    let origin = located.origin();
    let example = match &located.place {
        // A running robot: its topics until a limit, Ctrl-C or the stream's end.
        Place::Live(url) => {
            let mut collector = Collector::new(options, cancel, observer);
            ws::read(url, &options.live, &mut collector, progress)?;
            return summary(collector, ws::origin(url));
        }
        Place::File(_) | Place::Bundled(_) if !options.live.is_empty() => {
            let (flag, value) = options.live.first_flag().unwrap_or_default();
            return Err(InputError::Format {
                file: origin,
                message: format!(
                    "{flag} {value}: applies to a live stream (ws://HOST:PORT) only, not a log file"
                ),
            });
        }
        Place::File(path) => {
            return read_path(
                path,
                located.format,
                &origin,
                options,
                progress,
                cancel,
                observer,
            );
        }
        Place::Bundled(example) => example,
    };
    // The readers take a file: the bundled bytes go to a temporary one, named back to the
    // bundled log in every message.
    let log = bundled::find(example.name).ok_or_else(|| InputError::Read {
        path: origin.clone(),
        reason: "not a bundled robot log".to_owned(),
    })?;
    let tmp = std::env::temp_dir().join(format!("posecov-{}-{}", std::process::id(), log.file));
    std::fs::write(&tmp, log.bytes).map_err(|e| InputError::Read {
        path: tmp.display().to_string(),
        reason: e.to_string(),
    })?;
    let plan = read_path(
        &tmp,
        located.format,
        &origin,
        options,
        progress,
        cancel,
        observer,
    );
    std::fs::remove_file(&tmp).ok();
    plan.map_err(|e| e.renamed(&tmp.display().to_string(), &origin))
}

/// Reads the log file at `path` in `format` (`origin` names it in errors).
fn read_path(
    path: &Path,
    format: Format,
    origin: &str,
    options: &LogOptions,
    progress: &mut dyn FnMut(u64, u64),
    cancel: Option<&AtomicBool>,
    observer: Option<&mut dyn LogObserver>,
) -> Result<LogSummary, InputError> {
    let mut collector = Collector::new(options, cancel, observer);
    match format {
        // A rosbag2 directory (metadata.yaml and its files, sqlite3 or mcap storage).
        Format::Ros2Sqlite | Format::Mcap if path.is_dir() => {
            rosbag2::read_dir(path, &mut collector, progress)?;
        }
        Format::Ros1Bag => ros1::read(path, &mut collector, progress)?,
        Format::Mcap => mcap::read(path, &mut collector, progress)?,
        Format::Ros2Sqlite => sqlite::read(path, None, &mut collector, progress)?,
        other => {
            return Err(InputError::Format {
                file: origin.to_owned(),
                message: format!("a {}, not a robot log (ROS 1 bag or MCAP)", other.name()),
            });
        }
    }
    summary(collector, path)
}

/// The collector's summary of the log at `path`; nothing to draw is an error.
fn summary(collector: Collector<'_, '_>, path: &Path) -> Result<LogSummary, InputError> {
    let plan = collector.finish(path)?;
    // Nothing to draw is an error for every command (no empty recording), unless Ctrl-C
    // stopped the read before the first pose message.
    if !plan.cancelled && plan.topics.iter().all(|t| t.count == 0) {
        let cut = match &plan.cut {
            Some(cut) => format!("; the log stops early: {}", cut.reason),
            None => String::new(),
        };
        return Err(InputError::Format {
            file: path.display().to_string(),
            message: format!("{}{cut}", no_pose_topic(&plan)),
        });
    }
    Ok(plan)
}

/// A connection (ROS 1) or channel (MCAP): its topic, type and what posecov makes of it
/// (`None`: another type; `Some(Err(why))`: a pose type in another definition or encoding).
struct Stream {
    topic: String,
    type_name: String,
    kind: Option<Result<PoseMessageKind, String>>,
    /// What a reference can be read from it (`Err(why)`: a reference type in another
    /// definition or encoding).
    reference: Option<Result<ReferenceType, String>>,
}

/// How a message's bytes are encoded.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Codec {
    Ros1,
    Cdr,
}

/// Receives every message of a log in file order.
struct Collector<'a, 'o> {
    options: &'a LogOptions,
    cancel: Option<&'a AtomicBool>,
    cancelled: bool,
    topics: BTreeMap<String, TopicState>,
    /// Per topic of another type: its type, messages and the first one's log time.
    skipped: BTreeMap<String, (String, u64, i64)>,
    not_selected: BTreeMap<String, ()>,
    total: u64,
    observer: Option<&'o mut dyn LogObserver>,
    reference: Option<ReferenceRead>,
    /// Where a read without an index stopped before the file's end.
    cut: Option<LogCut>,
    tf: tf::TfCollector,
}

impl<'a, 'o> Collector<'a, 'o> {
    fn new(
        options: &'a LogOptions,
        cancel: Option<&'a AtomicBool>,
        observer: Option<&'o mut dyn LogObserver>,
    ) -> Self {
        Self {
            options,
            cancel,
            cancelled: false,
            topics: BTreeMap::new(),
            skipped: BTreeMap::new(),
            not_selected: BTreeMap::new(),
            total: 0,
            observer,
            reference: options.reference.as_ref().map(|_| ReferenceRead::default()),
            cut: None,
            tf: tf::TfCollector::default(),
        }
    }

    /// Whether `topic` carries the reference asked for (its topic, or `/tf` for `tf:CHILD`).
    fn is_reference(&self, topic: &str) -> bool {
        match &self.options.reference {
            Some(ReferenceInLog::Topic(name)) => name == topic,
            Some(ReferenceInLog::Tf { .. }) => topic == "/tf",
            None => false,
        }
    }

    /// A stream the log declares: its topic, and the reference if it is the reference's.
    fn declare_stream(&mut self, stream: &Stream) {
        self.declare(&stream.topic, &stream.type_name, stream.kind.as_ref());
        self.declare_reference(stream);
    }

    /// Notes the reference's stream (its type), once.
    fn declare_reference(&mut self, stream: &Stream) {
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
    fn reference_message(&mut self, stream: &Stream, log_time_ns: i64, bytes: &[u8], codec: Codec) {
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
    fn stop(&mut self) -> bool {
        if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            self.cancelled = true;
        }
        self.cancelled
    }

    /// A topic the log declares (a ROS 1 connection, an MCAP channel), so that a topic with
    /// no messages is still listed.
    fn declare(
        &mut self,
        topic: &str,
        type_name: &str,
        kind: Option<&Result<PoseMessageKind, String>>,
    ) {
        match kind {
            Some(Ok(kind)) if self.selected(topic) => {
                if !self.topics.contains_key(topic) {
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

    fn selected(&self, topic: &str) -> bool {
        self.options.topics.is_empty() || self.options.topics.iter().any(|t| t == topic)
    }

    /// One message on stream `id` (`streams[id]`), logged at `log_time` ns; an undeclared
    /// stream is an error (`what` names connection or channel).
    fn message_on(
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
        let kind = stream.kind.as_ref();
        self.message(&stream.topic, &stream.type_name, kind, log_ns, bytes, codec);
        Ok(())
    }

    /// One message: `kind` is `None` for another type, `Some(Err(why))` for a pose type whose
    /// definition does not match.
    fn message(
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
        if !self.selected(topic) {
            self.not_selected.insert(topic.to_owned(), ());
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
        let decoded = match codec {
            Codec::Ros1 => decode::decode_ros1(state.kind, bytes),
            Codec::Cdr => decode::decode_cdr(state.kind, bytes),
        };
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
                });
            }
        });
    }

    fn finish(mut self, path: &Path) -> Result<LogSummary, InputError> {
        // A topic declared (or first seen) with another type before its pose messages: those
        // messages are the pose topic's type change, not a topic of their own.
        for (name, state) in &mut self.topics {
            if let Some((label, count, first)) = self.skipped.remove(name) {
                state.other_type_before(label, count, first);
            }
        }
        for wanted in &self.options.topics {
            if !self.topics.contains_key(wanted) && !self.cancelled {
                let why = match self.skipped.get(wanted) {
                    Some((t, ..)) => format!("its messages are {t}, not a pose with covariance"),
                    None => {
                        let have: Vec<&str> = self
                            .topics
                            .keys()
                            .chain(self.not_selected.keys())
                            .map(String::as_str)
                            .collect();
                        format!(
                            "no such topic; {}pose topics in this log: {}",
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
        Ok(LogSummary {
            topics: self
                .topics
                .into_iter()
                .map(|(name, s)| s.into_plan(name))
                .collect(),
            skipped: self
                .skipped
                .into_iter()
                .map(|(name, (message_type, count, _))| SkippedTopic {
                    name,
                    message_type,
                    count,
                })
                .collect(),
            not_selected: self.not_selected.into_keys().collect(),
            messages_total: self.total,
            cancelled: self.cancelled,
            reference: self.reference,
            cut: self.cut,
            tf: self.tf.finish(),
        })
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
