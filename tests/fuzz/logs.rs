//! Robot logs: ROS 1 bags, MCAP files and ROS 2 SQLite bags (`.db3`), mutated byte by byte (bits, lengths and counts set
//! to edge values, pieces repeated, zeroed or cut), run as `posecov check` and `report
//! --json` run a log: read (streamed, every read bounded) → evaluate (a few samples per
//! drawn message) → draw → validate → the JSON report.
//!
//! Seeds: the bundled logs (a real bz2 log, the generated health-case MCAP) and a small
//! uncompressed bag written here, so that mutations reach the records, the index and the
//! messages, not only a compressed stream; for `.db3`, the committed bags of tests/data/ros2
//! (version 9, Humble's version 5, zstd-compressed messages named by the file's own
//! `metadata` table), so that mutations reach SQLite's pages, the rows, the topics and the
//! metadata text.

use std::path::PathBuf;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use posecov::app::Overrides;
use posecov::app::log::report_json;
use posecov::app::run::{Run as AppRun, open};

use crate::harness::{
    Family, Finding, Limits, Run, Stage, finding, json_null, mutate_bytes, run_guarded, settle,
    target_dir,
};

/// Which log format a family mutates.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    Ros1,
    Mcap,
    Db3,
    /// ROS 1 bags of sensor messages: `sensor_msgs/Imu` (tests/data/imu), `sensor_msgs/NavSatFix`
    /// (tests/data/navsat), twists, accelerations and an Odometry's twist (tests/data/twist):
    /// mutations reach their messages.
    Imu,
}

/// A log family (`ros1`, `mcap`, `db3` or `imu`).
pub struct Logs {
    kind: LogKind,
    seeds: Vec<Vec<u8>>,
}

impl Logs {
    pub fn new(kind: LogKind) -> Self {
        let bundled = posecov::input::log::bundled::LOGS
            .iter()
            .filter(|l| l.file.ends_with(kind.extension()))
            .map(|l| l.bytes.to_vec());
        let seeds = match kind {
            LogKind::Ros1 => bundled.chain([small_bag()]).collect(),
            LogKind::Mcap => bundled.collect(),
            LogKind::Db3 => DB3_SEEDS.iter().map(|s| s.to_vec()).collect(),
            LogKind::Imu => vec![IMU_SEED.to_vec(), NAVSAT_SEED.to_vec(), TWIST_SEED.to_vec()],
        };
        Self { kind, seeds }
    }
}

impl LogKind {
    fn extension(self) -> &'static str {
        match self {
            LogKind::Ros1 | LogKind::Imu => "bag",
            LogKind::Mcap => "mcap",
            LogKind::Db3 => "db3",
        }
    }
}

/// The `.db3` seeds: a version 9 bag, Humble's layout, zstd-compressed messages, and the CDR
/// twists, accelerations and Odometry of tests/data/twist.
pub const DB3_SEEDS: [&[u8]; 4] = [
    include_bytes!("../data/ros2/arc_v9/arc_v9.db3"),
    include_bytes!("../data/ros2/arc_humble/arc_humble_0.db3"),
    include_bytes!("../data/ros2/arc_zstd_message/arc_zstd_message.db3"),
    include_bytes!("../data/twist/twist_db3/twist_db3.db3"),
];

/// The `imu` seed: an uncompressed ROS 1 bag of two IMU topics (−1 "not provided", all zero),
/// written by PyPI `rosbags` (tests/data/imu/make_imu.py).
pub const IMU_SEED: &[u8] = include_bytes!("../data/imu/imu_rep145.bag");

/// An `imu` seed: an uncompressed ROS 1 bag of `TwistWithCovarianceStamped`,
/// `AccelWithCovarianceStamped` and `nav_msgs/Odometry` (a PSD defect, all zero, −1, placeholders),
/// written by PyPI `rosbags` (tests/data/twist/make_twist.py).
pub const TWIST_SEED: &[u8] = include_bytes!("../data/twist/twist.bag");
/// An `imu` seed: an uncompressed ROS 1 bag of four `sensor_msgs/NavSatFix` topics
/// (known, unknown with a NO_FIX, approximated, diagonal known with off-diagonal entries),
/// written by PyPI `rosbags` (tests/data/navsat/make_navsat.py).
pub const NAVSAT_SEED: &[u8] = include_bytes!("../data/navsat/navsat.bag");

/// Strings the mutator inserts: record field names and values of both formats.
const TOKENS: &[&str] = &[
    "op=",
    "size=",
    "compression=bz2",
    "compression=lz4",
    "compression=none",
    "index_pos=",
    "conn=",
    "topic=",
    "type=nav_msgs/Odometry",
    "md5sum=",
    "\u{0}\u{0}\u{0}\u{0}",
    "zstd",
    "lz4",
    "cdr",
    "\u{ff}\u{ff}\u{ff}\u{ff}",
    "sqlite3",
    "compression_mode: message",
    "compression_format: lz4",
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "type=sensor_msgs/Imu",
    "sensor_msgs/msg/Imu",
    "type=geometry_msgs/TwistWithCovarianceStamped",
    "geometry_msgs/msg/AccelWithCovarianceStamped",
    "type=sensor_msgs/NavSatFix",
    "sensor_msgs/msg/NavSatFix",
    "\u{3}",
    "\u{7f}",
];

impl Family for Logs {
    fn name(&self) -> &'static str {
        match self.kind {
            LogKind::Ros1 => "ros1",
            LogKind::Mcap => "mcap",
            LogKind::Db3 => "db3",
            LogKind::Imu => "imu",
        }
    }
    fn extension(&self) -> &'static str {
        self.kind.extension()
    }
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(case);
        // The small seeds more often: their mutants are read through in microseconds.
        let k = if self.kind == LogKind::Db3 {
            rng.random_range(0..self.seeds.len())
        } else if rng.random_bool(0.3) {
            0
        } else {
            self.seeds.len() - 1
        };
        let mut bytes = self.seeds[k].clone();
        let mut log = vec![format!("from seed {k}")];
        for _ in 0..[1, 1, 1, 2, 3, 5][rng.random_range(0..6)] {
            log.push(mutate_bytes(&mut rng, &mut bytes, TOKENS));
        }
        (bytes, log.join("; "))
    }
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool) {
        let path = target_dir().join(format!("fuzz-work.{}", self.extension()));
        if let Err(e) = std::fs::write(&path, input) {
            return (
                vec![finding(
                    "harness",
                    format!("writing {}: {e}", path.display()),
                )],
                false,
            );
        }
        let run = {
            let path = path.clone();
            run_guarded(limits, move |stage| run_log(path, stage))
        };
        let stuck = matches!(run, Run::Stuck { .. });
        (judge(&path.display().to_string(), run, limits), stuck)
    }
}

fn run_log(path: PathBuf, stage: Stage) -> Result<serde_json::Value, String> {
    stage("read, evaluate, draw");
    let overrides = Overrides {
        samples: Some(8),
        ..Default::default()
    };
    let opened = open(&path.display().to_string()).map_err(|e| e.to_string())?;
    let AppRun::Log(log) =
        AppRun::start(opened, &overrides, posecov::app::run::RunOptions::shown())
            .map_err(|e| e.to_string())?
    else {
        return Err("read as a plan, not a log".to_owned());
    };
    stage("report");
    Ok(report_json("fuzz", &log))
}

fn judge(file: &str, run: Run<Result<serde_json::Value, String>>, limits: &Limits) -> Vec<Finding> {
    let (result, mut found) = match settle(run, limits) {
        Ok(x) => x,
        Err(ended) => return ended,
    };
    match result {
        Err(e) => {
            let first = e.lines().next().unwrap_or("").to_owned();
            // In the user's words: no Rust paths or type names (`rosbag::Error: …`).
            if first.contains("::") {
                found.push(finding("error_rust_speak", first.clone()));
            }
            if first.starts_with(file) {
                found.push(finding("error_ok", first));
            } else {
                found.push(finding("error_unlocated", first));
            }
        }
        Ok(json) => {
            // Absent by design: no eigenvalue for a covariance that is not finite, no twist
            // σ where the messages have none, no stamps for a topic without messages, no
            // median where no kept point estimates an axis.
            if let Some(path) = json_null(&json, LOG_JSON_OPTIONAL) {
                found.push(finding("nonfinite_json", format!("null at {path}")));
            }
        }
    }
    if found.is_empty() {
        found.push(finding("ok", ""));
    }
    found
}

// =========================================================================================
// A small ROS 1 bag (format 2.0), uncompressed: one chunk of Odometry messages, its index.
// =========================================================================================

/// One record: header fields, then data, each with its length (wiki.ros.org/Bags/Format/2.0).
fn record(fields: &[(&str, &[u8])], data: &[u8]) -> Vec<u8> {
    let mut header = Vec::new();
    for (name, value) in fields {
        let len = (name.len() + 1 + value.len()) as u32;
        header.extend(len.to_le_bytes());
        header.extend(name.as_bytes());
        header.push(b'=');
        header.extend(*value);
    }
    let mut out = (header.len() as u32).to_le_bytes().to_vec();
    out.extend(header);
    out.extend((data.len() as u32).to_le_bytes());
    out.extend(data);
    out
}

fn ros_string(s: &str) -> Vec<u8> {
    let mut out = (s.len() as u32).to_le_bytes().to_vec();
    out.extend(s.as_bytes());
    out
}

/// A `nav_msgs/Odometry` in ROS 1 serialization: a planar pose at `x` with a growing
/// covariance.
fn odometry(k: u32, x: f64) -> Vec<u8> {
    let mut m = Vec::new();
    m.extend(k.to_le_bytes()); // seq
    m.extend((100 + k).to_le_bytes()); // stamp sec
    m.extend(0u32.to_le_bytes()); // stamp nsec
    m.extend(ros_string("odom"));
    m.extend(ros_string("base_link"));
    for v in [x, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
        m.extend(v.to_le_bytes());
    }
    let s = 0.01 * f64::from(k + 1);
    for i in 0..36 {
        let v = match i {
            0 | 7 | 35 => s,
            14 | 21 | 28 => 1e6,
            _ => 0.0,
        };
        m.extend(f64::to_le_bytes(v));
    }
    for _ in 0..(6 + 36) {
        m.extend(0f64.to_le_bytes());
    }
    m
}

fn time(sec: u32) -> Vec<u8> {
    let mut t = sec.to_le_bytes().to_vec();
    t.extend(0u32.to_le_bytes());
    t
}

/// The bag: magic, header (padded to 4096), one chunk, its index data, the connection and
/// the chunk info.
pub fn small_bag() -> Vec<u8> {
    const MD5: &str = "cd5e73d190d741a2f92e81eda573aca7";
    let conn = 0u32.to_le_bytes();
    let connection = |op: u8| {
        let mut data = Vec::new();
        for (k, v) in [
            ("topic", "/odom"),
            ("type", "nav_msgs/Odometry"),
            ("md5sum", MD5),
            ("message_definition", ""),
        ] {
            let field = format!("{k}={v}");
            data.extend((field.len() as u32).to_le_bytes());
            data.extend(field.as_bytes());
        }
        record(
            &[("op", &[op]), ("conn", &conn), ("topic", b"/odom")],
            &data,
        )
    };
    let count = 6u32;
    let mut chunk_data = connection(0x07);
    let mut offsets = Vec::new();
    for k in 0..count {
        offsets.push(chunk_data.len() as u32);
        chunk_data.extend(record(
            &[("op", &[0x02]), ("conn", &conn), ("time", &time(100 + k))],
            &odometry(k, 0.5 * f64::from(k)),
        ));
    }
    let magic = b"#ROSBAG V2.0\n";
    let header_len = 4096;
    let chunk_pos = (magic.len() + header_len) as u64;
    let chunk = record(
        &[
            ("op", &[0x05]),
            ("compression", b"none"),
            ("size", &(chunk_data.len() as u32).to_le_bytes()),
        ],
        &chunk_data,
    );
    let mut index_data = Vec::new();
    for (k, offset) in offsets.iter().enumerate() {
        index_data.extend(time(100 + k as u32));
        index_data.extend(offset.to_le_bytes());
    }
    let index = record(
        &[
            ("op", &[0x04]),
            ("ver", &1u32.to_le_bytes()),
            ("conn", &conn),
            ("count", &count.to_le_bytes()),
        ],
        &index_data,
    );
    let index_pos = chunk_pos + (chunk.len() + index.len()) as u64;
    let mut info_data = conn.to_vec();
    info_data.extend(count.to_le_bytes());
    let info = record(
        &[
            ("op", &[0x06]),
            ("ver", &1u32.to_le_bytes()),
            ("chunk_pos", &chunk_pos.to_le_bytes()),
            ("start_time", &time(100)),
            ("end_time", &time(100 + count - 1)),
            ("count", &1u32.to_le_bytes()),
        ],
        &info_data,
    );
    let mut bag_header = record(
        &[
            ("op", &[0x03]),
            ("index_pos", &index_pos.to_le_bytes()),
            ("conn_count", &1u32.to_le_bytes()),
            ("chunk_count", &1u32.to_le_bytes()),
        ],
        &[],
    );
    // The header record's data is padding, so that the header fills 4096 bytes.
    let pad = header_len - bag_header.len();
    bag_header.truncate(bag_header.len() - 4);
    bag_header.extend((pad as u32).to_le_bytes());
    bag_header.extend(std::iter::repeat_n(b' ', pad));
    let mut bag = magic.to_vec();
    bag.extend(bag_header);
    bag.extend(chunk);
    bag.extend(index);
    bag.extend(connection(0x07));
    bag.extend(info);
    bag
}

/// The report's keys a log may leave `null` by design (any other `null` is a finding).
pub(crate) const LOG_JSON_OPTIONAL: &[&str] = &[
    "step",
    "min_eigenvalue",
    "twist_sigma_last",
    // No stretch of constant covariance while moving.
    ".topics[#].constant_stretch",
    "first_s",
    "last_s",
    "median_of_kept",
    // No --reference: no NEES.
    ".topics[#].consistency",
    // Read to the end of the file: no cut.
    ".meta.cut_short",
    // A file, not a live stream; a live stream that did not end on its own.
    ".meta.stream",
    ".meta.stream.ended",
    // Drawn in its own frame; nothing left out of a join; a missing link has no stamp.
    ".topics[#].frame_join",
    "first_left_out_s",
    ".frames.problems[#].first_stamp_s",
];
