//! An IMU at 400 Hz for an hour (issue 32): 1.44 M `sensor_msgs/Imu` messages, written as an
//! MCAP file (zstd chunks, as rosbag2 and Foxglove write them), read by `read_log` under the
//! harness's counting allocator. The read's peak heap is compared with the same read of a
//! tenth of the log: a sensor topic keeps streamed statistics and a series thinned to
//! `MAX_SERIES` points, so the peak must not grow with the messages.

use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;
use std::time::Duration;

use posecov::input::log::decode::{Header, Time};
use posecov::input::log::sensor::Imu;
use posecov::input::log::{LogOptions, read_log};

use crate::harness::{Limits, Run, run_guarded, target_dir};

/// 400 Hz for an hour.
pub const HOUR_AT_400_HZ: u64 = 400 * 3600;

/// Writes `n` IMU messages on `/imu/data` at 400 Hz to `path`: a gyro whose variance drifts
/// with temperature (every message's block differs, so every one is classified), a constant
/// accelerometer, orientation "not provided" (−1).
pub fn write_imu_mcap(path: &Path, n: u64) {
    let file = std::fs::File::create(path).expect("create the IMU log");
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .create(BufWriter::new(file))
        .expect("mcap writer");
    let schema = w
        .add_schema("sensor_msgs/msg/Imu", "ros2msg", b"")
        .expect("schema");
    let channel = w
        .add_channel(schema, "/imu/data", "cdr", &BTreeMap::new())
        .expect("channel");
    let mut imu = Imu {
        header: Header {
            stamp: Time::default(),
            frame_id: "imu_link".into(),
        },
        orientation: [0.0, 0.0, 0.0, 1.0],
        ..Imu::default()
    };
    imu.orientation_covariance[0] = -1.0;
    imu.linear_acceleration_covariance = [2.5e-3, 0.0, 0.0, 0.0, 2.5e-3, 0.0, 0.0, 0.0, 2.5e-3];
    let mut bytes = Vec::with_capacity(400);
    for k in 0..n {
        let ns = 1_700_000_000_000_000_000u64 + k * 2_500_000;
        imu.header.stamp = Time {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        };
        let gyro = 4e-4 * (1.0 + 0.1 * (k as f64 * 1e-4).sin());
        imu.angular_velocity_covariance = [gyro, 0.0, 0.0, 0.0, gyro, 0.0, 0.0, 0.0, gyro];
        imu.angular_velocity = [0.0, 0.0, 0.3 + 1e-3 * (k % 7) as f64];
        bytes.clear();
        bytes.extend([0, 1, 0, 0]);
        bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&imu).expect("cdr"));
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: k as u32,
            log_time: ns,
            publish_time: ns,
        };
        w.write_to_known_channel(&header, &bytes).expect("write");
    }
    w.finish().expect("finish the IMU log");
}

/// The peak heap (bytes above what was allocated before) of reading `path`, and the messages
/// the IMU topic counted.
pub fn peak_of_read(path: &Path) -> (usize, u64) {
    let limits = Limits {
        // Not a timing: only a hang guard, far beyond any machine's read of the hour.
        hang: Duration::from_secs(3600),
        slow: Duration::from_secs(3600),
        memory: usize::MAX,
        memory_cap: 4 << 30,
    };
    let owned = path.to_owned();
    match run_guarded(&limits, move |_| {
        let plan = read_log(&owned, &LogOptions::default(), &mut |_, _| {}, None)
            .expect("the IMU log reads");
        plan.sensors[0].count
    }) {
        Run::Finished { result, peak, .. } => (peak, result),
        _ => panic!("reading {} did not finish", path.display()),
    }
}

/// The hour's log and a tenth of it, in the fuzz output directory.
pub fn logs() -> [(u64, std::path::PathBuf); 2] {
    let dir = target_dir();
    [HOUR_AT_400_HZ / 10, HOUR_AT_400_HZ].map(|n| (n, dir.join(format!("imu_{n}.mcap"))))
}
