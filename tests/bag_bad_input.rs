//! Robot logs that are damaged or unusual in ways a robot makes them (issue 19, "Bad input"):
//! each gets a located, plain message, nothing panics, and what was read is kept and said.
//! A ROS 1 bag cut short inside a chunk, one whose recording was interrupted (no index), and
//! a topic whose message type changes. (An MCAP file cut inside a record: `tests/bag_mcap.rs`.)

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use posecov::input::log::decode::{
    Header, Pose, PoseWithCovariance, PoseWithCovarianceStamped, Time, nested,
};
use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Issue, LogSummary};

const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);

/// A temporary file with `bytes`, one per call (tests run in parallel).
fn file(name: &str, bytes: &[u8]) -> PathBuf {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("posecov-bad-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn read(path: &Path) -> LogSummary {
    read_log(path, &LogOptions::default(), &mut |_, _| {}, None)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// test2.bag with its header's index position set to 0, as `rosbag record` leaves a bag whose
/// recording was interrupted.
fn unindexed(bytes: &[u8]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    let at = b
        .windows(10)
        .position(|w| w == b"index_pos=")
        .expect("index_pos field")
        + 10;
    b[at..at + 8].fill(0);
    b
}

#[test]
fn an_interrupted_recording_is_read_chunk_by_chunk_whole() {
    let bytes = std::fs::read(TEST2).unwrap();
    let indexed = read(Path::new(TEST2));
    let path = file("interrupted.bag", &unindexed(&bytes));
    let linear = read(&path);
    // Every chunk read: the same messages, health and σ as through the index.
    assert_eq!(linear.cut, None);
    assert_eq!(linear.messages_total, indexed.messages_total);
    let (a, b) = (&linear.topics[0], &indexed.topics[0]);
    assert_eq!(
        (a.count, &a.health, a.sigma_stats),
        (b.count, &b.health, b.sigma_stats)
    );
    assert_eq!(linear.skipped, indexed.skipped);
}

#[test]
fn a_bag_cut_inside_a_chunk_keeps_its_whole_chunks_and_says_where() {
    let bytes = std::fs::read(TEST2).unwrap();
    let mut last = 0;
    // test2.bag's five bz2 chunks start at bytes 4117, 124853, 243696, …: cut inside the
    // second, the third and inside the index.
    for cut in [200_000, 300_000, bytes.len() - 100] {
        let path = file(&format!("cut{cut}.bag"), &bytes[..cut]);
        let plan = read(&path);
        let count = plan.topics.first().map_or(0, |t| t.count);
        assert!(count >= last, "{cut}: {count} < {last}");
        last = count;
        if cut > 400_000 {
            // Inside the index: every chunk is whole, read without it.
            assert_eq!((count, plan.cut.as_ref()), (3060, None));
            continue;
        }
        let stop = plan.cut.as_ref().expect("the cut is said");
        assert!(stop.reason.contains("cut short"), "{cut}: {}", stop.reason);
        assert!(
            stop.at_byte <= cut as u64 && stop.file_bytes == cut as u64,
            "{stop:?}"
        );
        assert!(
            stop.reason
                .contains(&format!("chunk {} at byte", stop.chunks_read + 1)),
            "{stop:?}"
        );
    }
    assert!(last > 0 && last <= 3060, "{last}");
}

#[test]
fn a_cut_bag_through_the_app_is_drawn_said_and_fails_check() {
    use posecov::app::{
        Overrides, log,
        run::{Run, open},
    };
    let bytes = std::fs::read(TEST2).unwrap();
    let path = file("cut.bag", &bytes[..300_000]);
    let name = path.display().to_string();
    let Run::Log(run) = Run::start(
        open(&name).unwrap(),
        &Overrides::default(),
        posecov::app::run::RunOptions::shown(),
    )
    .unwrap() else {
        panic!("a log")
    };
    assert!(
        run.scene
            .description_markdown
            .contains("**The log stops early**"),
        "{}",
        run.scene.description_markdown
    );
    let json = log::report_json("cut", &run);
    assert_eq!(
        json["meta"]["cut_short"]["chunks_read"], 2,
        "{}",
        json["meta"]
    );
    let checked = log::check(&run, "cut", &posecov::plan::log::Issue::ALL);
    assert_eq!(checked.exit_code(), 1, "{checked:?}");
    assert!(
        checked.defects[0].contains("the log stops early"),
        "{:?}",
        checked.defects
    );
    assert!(
        checked.defects[0].contains("cut.bag"),
        "{:?}",
        checked.defects
    );
}

#[test]
fn a_cut_before_any_whole_chunk_is_no_pose_topic() {
    let bytes = std::fs::read(TEST2).unwrap();
    let path = file("early.bag", &bytes[..60_000]);
    let e = posecov::input::locate(&path.display().to_string())
        .and_then(|l| {
            posecov::input::log::read_located(&l, &LogOptions::default(), &mut |_, _| {}, None)
        })
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("early.bag") && e.contains("no topic with a covariance to check"),
        "{e}"
    );
    assert!(
        e.contains("the log stops early: ") && e.contains("chunk 1 at byte 4117"),
        "{e}"
    );
}

fn cdr<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    let mut v = vec![0, 1, 0, 0];
    v.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(msg).unwrap());
    v
}

/// An MCAP log whose `/pose` is a PoseWithCovarianceStamped for its first 5 messages, then
/// carries 3 `sensor_msgs/msg/Imu` and 2 `nav_msgs/msg/Odometry` messages (another publisher).
fn type_change_log() -> Vec<u8> {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let none = BTreeMap::new();
    let pose = w
        .add_schema(
            "geometry_msgs/msg/PoseWithCovarianceStamped",
            "ros2msg",
            b"",
        )
        .unwrap();
    let imu = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"").unwrap();
    let odom = w
        .add_schema("nav_msgs/msg/Odometry", "ros2msg", b"")
        .unwrap();
    let channels = [
        w.add_channel(pose, "/pose", "cdr", &none).unwrap(),
        w.add_channel(imu, "/pose", "cdr", &none).unwrap(),
        w.add_channel(odom, "/pose", "cdr", &none).unwrap(),
    ];
    let mut cov = [0.0; 36];
    for i in 0..6 {
        cov[i * 7] = 0.01;
    }
    for k in 0..10u32 {
        let channel = match k {
            0..5 => 0,
            5..8 => 1,
            _ => 2,
        };
        let msg = PoseWithCovarianceStamped {
            header: Header {
                stamp: Time {
                    sec: 1 + k as i32,
                    nanosec: 0,
                },
                frame_id: "map".into(),
            },
            pose: PoseWithCovariance {
                pose: Pose {
                    position: [k as f64, 0.0, 0.0],
                    orientation: [0.0, 0.0, 0.0, 1.0],
                },
                covariance: nested(&cov),
            },
        };
        let t = u64::from(1 + k) * 1_000_000_000;
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: channels[channel],
                sequence: k,
                log_time: t,
                publish_time: t,
            },
            &cdr(&msg),
        )
        .unwrap();
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

#[test]
fn a_topic_whose_type_changes_is_read_in_its_first_type_and_said() {
    let path = file("type_change.mcap", &type_change_log());
    let plan = read(&path);
    assert_eq!(plan.topics.len(), 1, "{:?}", plan.topics);
    assert!(plan.skipped.is_empty(), "{:?}", plan.skipped);
    let t = &plan.topics[0];
    // The five messages of the first type are read; none of the others is decoded as one.
    assert_eq!(t.count, 5);
    assert_eq!(t.health.count(Issue::Undecodable), 0);
    let change = t.health.issues[&Issue::TypeChange];
    assert_eq!(
        (change.count, change.first_stamp_ns, change.first_index),
        (5, 6_000_000_000, 5)
    );
    assert_eq!(
        t.health.other_types,
        ["sensor_msgs/msg/Imu", "nav_msgs/msg/Odometry"]
    );
    let sentence = posecov::draw::log::issue_sentence(Issue::TypeChange, t);
    assert!(
        sentence.contains("sensor_msgs/msg/Imu, nav_msgs/msg/Odometry"),
        "{sentence}"
    );
    assert_eq!(
        Issue::TypeChange.class(false),
        posecov::plan::log::Class::Defect
    );
    assert_eq!(Issue::from_name("type_change"), Some(Issue::TypeChange));
}
