//! Robot logs: ROS 1 bags (format 2.0; uncompressed, bz2 and lz4 chunks, through the `rosbag`
//! crate), MCAP files (CDR or ROS 1 messages, through the `mcap` crate's streaming reader and
//! `re_cdr`) and ROS 2 bags (`rosbag2.rs`: a directory of SQLite `.db3` files, `sqlite.rs`, or
//! MCAP files; or one `.db3`). All are streamed: messages are decoded one at a time into a bounded
//! [`LogSummary`] — every message's health is counted, a decimated set of messages is kept for
//! drawing, and time series are kept at a bounded length (halving their density when full).
//!
//! Messages read: `nav_msgs/Odometry`, `geometry_msgs/PoseWithCovarianceStamped`,
//! `geometry_msgs/PoseWithCovariance` (pose topics), `sensor_msgs/Imu` and
//! `sensor_msgs/NavSatFix` (sensor topics, `navsat.rs` for a fix; `sensor.rs`: health and σ of
//! each covariance block), `TwistWithCovarianceStamped`, `AccelWithCovarianceStamped` and each
//! Odometry's twist (`velocity.rs`: the diagonal blocks of their 6 × 6 covariance, as sensor
//! topics), and `/tf` + `/tf_static` kept per edge
//! (`tf.rs`); other types are listed as skipped. Stamps are the header stamp, or the log time when it is zero.
//!
//! ```
//! use posecov::input::log::{LogOptions, read_log};
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
//! let plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
//! assert_eq!(plan.topics[0].name, "/jackal_velocity_controller/odom");
//! assert!(plan.topics[0].group.is_planar());
//! ```

use std::path::Path;
use std::sync::atomic::AtomicBool;

use crate::plan::log::{LogObserver, LogSummary, ReferenceInLog};

use super::format::{self, Format};
use super::{InputError, Located, Place};

pub mod bundled;
mod cdr_pose;
mod collector;
pub mod decode;
mod growth;
pub mod health;
mod mcap;
mod mcap_records;
pub mod navsat;
pub mod ov_eval;
pub mod reference;
mod ros1;
mod ros1_linear;
pub mod rosbag2;
pub mod sensor;
mod sqlite;
mod stream;
mod tf;
mod topic;
pub mod velocity;
pub mod ws;

use collector::Collector;
pub use growth::{GROWN_DRAWN, GROWN_SERIES, growth_interval};
pub use stream::Codec;
use stream::Stream;
use topic::no_covariance_topic;

/// The largest record or decompressed chunk of a log read (1 GiB): larger ones are refused,
/// not allocated.
pub const RECORD_LIMIT: usize = 1 << 30;
/// A compressed chunk may claim at most this many times its compressed length (plus 1 MiB)
/// once decompressed: real logs compress ROS messages about 8:1, and a falsified size is
/// refused before anything is allocated for it.
pub const MAX_CHUNK_RATIO: u64 = 1024;

pub use crate::plan::log::{DEFAULT_MAX_DRAWN, MAX_DRAWN_LIMIT};
/// Points kept per topic for the trajectory and the time series (density halves beyond):
/// 2 048 to 4 096 points a line, more than a plot is pixels wide. Small on purpose: a topic at
/// 100 Hz fills it in 41 s, and from then on what a read keeps is the same whatever its
/// length (an hour keeps what a minute keeps; `benches/live_stream.rs`).
pub const MAX_SERIES: usize = 4096;

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

impl LogOptions {
    /// Whether `topic` is read (`--topic`, or every pose topic when none is given).
    fn selects(&self, topic: &str) -> bool {
        self.topics.is_empty() || self.topics.iter().any(|t| t == topic)
    }

    /// Whether `topic` carries the reference asked for (its topic, or `/tf` for `tf:CHILD`).
    fn carries_reference(&self, topic: &str) -> bool {
        match &self.reference {
            Some(ReferenceInLog::Topic(name)) => name == topic,
            Some(ReferenceInLog::Tf { .. }) => topic == "/tf",
            None => false,
        }
    }
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
    read_located_growing(located, options, progress, cancel, observer, None)
}

/// [`read_located_observed`], and for a live stream the summary read so far handed to
/// `grow` as messages arrive, at most once per [`growth_interval`] (a file is read whole:
/// `grow` is not called). `grow` runs on a thread of its own, so that reading never waits for
/// drawing: a summary that comes while `grow` is still busy with the one before waits in a
/// one-slot mailbox, where a newer one replaces it (skipped, counted in the stream's notes).
/// Each is a bounded copy (the statistics as the end's summary keeps them, the drawn set
/// thinned to [`GROWN_DRAWN`] messages a topic, the trajectory and series to
/// [`GROWN_SERIES`] points), `stream` with the stream's notes so far; what the observer saw is
/// not in it.
///
/// ```
/// use posecov::input::{locate, log::{LogOptions, read_located_growing}};
/// let log = locate("covariance_health").unwrap();
/// let mut grown = 0;
/// let plan = read_located_growing(&log, &LogOptions::default(), &mut |_, _| {}, None, None,
///     Some(&mut |_| grown += 1)).unwrap();
/// assert_eq!((plan.topics.len(), grown), (3, 0));
/// ```
pub fn read_located_growing(
    located: &Located,
    options: &LogOptions,
    progress: &mut dyn FnMut(u64, u64),
    cancel: Option<&AtomicBool>,
    observer: Option<&mut dyn LogObserver>,
    grow: Option<&mut (dyn FnMut(LogSummary) + Send)>,
) -> Result<LogSummary, InputError> {
    let origin = located.origin();
    let example = match &located.place {
        // A running robot: its topics until a limit, Ctrl-C or the stream's end.
        Place::Live(url) => {
            // The observer's borrow shortened to the read's (`&mut dyn` is invariant).
            let observer = observer.map(|o| o as &mut dyn LogObserver);
            let mut collector = Collector::new(options, cancel, observer).growing(grow.is_some());
            let notes = ws::read(url, options, &mut collector, grow, progress)?;
            let mut plan = summary(collector, ws::origin(url))?;
            plan.stream = Some(notes);
            return Ok(plan);
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
        Format::OvEval => ov_eval::read(path, &mut collector, progress)?,
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
    let empty =
        plan.topics.iter().all(|t| t.count == 0) && plan.sensors.iter().all(|t| t.count == 0);
    if !plan.cancelled && empty {
        let cut = match &plan.cut {
            Some(cut) => format!("; the log stops early: {}", cut.reason),
            None => String::new(),
        };
        return Err(InputError::Format {
            file: path.display().to_string(),
            message: format!("{}{cut}", no_covariance_topic(&plan)),
        });
    }
    Ok(plan)
}
