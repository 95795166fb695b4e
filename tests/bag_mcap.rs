//! The MCAP (ROS 2) reader on logs written here with the `mcap` crate's writer: known
//! covariances on a planar Odometry topic and a 3-D PoseWithCovarianceStamped topic, every
//! health case once, bare PoseWithCovariance, another type and another encoding.
//!
//! The committed example `tests/data/mcap/health_cases.mcap` is this generator's output:
//! `POSECOV_UPDATE_GOLDEN=1 cargo test --no-default-features --test bag_mcap` rewrites it.

use std::collections::BTreeMap;
use std::io::Cursor;

use posecov::input::log::decode::{
    Header, Odometry, Pose, PoseWithCovariance, PoseWithCovarianceStamped, Time,
    TwistWithCovariance, nested,
};
use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Issue, PoseMessageKind};

const EXAMPLE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/mcap/health_cases.mcap"
);

/// The planar topic's covariance at message k: x, y and yaw growing, z / roll / pitch
/// placeholders; at k = 25 a relocalisation resets it, and it grows again.
fn planar_cov(k: usize) -> [f64; 36] {
    let scale = 0.01 + 0.05 * (k % 25) as f64;
    let mut c = [0.0; 36];
    c[0] = scale;
    c[1] = 0.3 * scale;
    c[6] = 0.3 * scale;
    c[7] = 0.5 * scale;
    c[14] = 1e6;
    c[21] = 1e6;
    c[28] = 1e6;
    c[35] = 0.1 * scale;
    c[5] = 0.001;
    c[30] = 0.001;
    c
}

/// A full 3-D covariance with off-diagonal terms (positive definite).
fn full_cov(k: usize) -> [f64; 36] {
    let mut c = [0.0; 36];
    for i in 0..6 {
        for j in 0..6 {
            c[i * 6 + j] = if i == j {
                0.04 + 0.001 * (i + k) as f64
            } else {
                0.004 / (1.0 + (i as f64 - j as f64).abs())
            };
        }
    }
    c
}

fn cdr<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    b.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(msg).unwrap());
    b
}

fn header(sec: i32, nanosec: u32, frame: &str) -> Header {
    Header {
        stamp: Time { sec, nanosec },
        frame_id: frame.into(),
    }
}

/// Each message of the 3-D topic: (covariance, quaternion, stamp seconds); the health case
/// it exercises in the comment.
fn amcl_messages() -> Vec<([f64; 36], [f64; 4], i32)> {
    let q = [0.0, 0.0, (0.25f64).sin(), (0.25f64).cos()];
    let mut v = Vec::new();
    v.push((full_cov(0), q, 100)); // 0 fine
    v.push(([0.0; 36], q, 101)); // 1 all zero
    let mut marker = full_cov(2);
    marker[0] = -1.0;
    v.push((marker, q, 102)); // 2 -1 marker
    let mut huge = full_cov(3);
    huge[21] = 1.79e308;
    v.push((huge, q, 103)); // 3 placeholder (roll)
    let mut nan = full_cov(4);
    nan[8] = f64::NAN;
    v.push((nan, q, 104)); // 4 NaN
    let mut asym = full_cov(5);
    asym[1] += 0.01;
    v.push((asym, q, 105)); // 5 asymmetric
    let mut npsd = full_cov(6);
    npsd[1] = 0.2;
    npsd[6] = 0.2;
    v.push((npsd, q, 106)); // 6 not PSD
    v.push((full_cov(7), [0.0, 0.0, 0.0, 0.5], 107)); // 7 bad quaternion
    v.push((full_cov(8), q, 0)); // 8 zero stamp → log time
    v.push((full_cov(9), q, 50)); // 9 out of order
    v.push((full_cov(10), q, 110)); // 10 fine
    v
}

/// The whole log, deterministic.
fn write_example() -> Vec<u8> {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let none = BTreeMap::new();
    let odom_schema = w
        .add_schema("nav_msgs/msg/Odometry", "ros2msg", b"")
        .unwrap();
    let pwcs_schema = w
        .add_schema(
            "geometry_msgs/msg/PoseWithCovarianceStamped",
            "ros2msg",
            b"",
        )
        .unwrap();
    let pwc_schema = w
        .add_schema("geometry_msgs/msg/PoseWithCovariance", "ros2msg", b"")
        .unwrap();
    let image_schema = w
        .add_schema("sensor_msgs/msg/Image", "ros2msg", b"")
        .unwrap();
    let odom = w
        .add_channel(odom_schema, "/planar/odom", "cdr", &none)
        .unwrap();
    let amcl = w
        .add_channel(pwcs_schema, "/amcl_pose", "cdr", &none)
        .unwrap();
    let bare = w.add_channel(pwc_schema, "/bare", "cdr", &none).unwrap();
    let image = w
        .add_channel(image_schema, "/camera", "cdr", &none)
        .unwrap();
    let json = w
        .add_channel(odom_schema, "/odom_json", "json", &none)
        .unwrap();
    let mut seq = 0;
    let mut put = |w: &mut mcap::Writer<Cursor<Vec<u8>>>, channel_id, log_s: f64, data: &[u8]| {
        seq += 1;
        let t = (log_s * 1e9) as u64;
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id,
                sequence: seq,
                log_time: t,
                publish_time: t,
            },
            data,
        )
        .unwrap();
    };
    for k in 0..50 {
        let yaw = 0.05 * k as f64;
        let msg = Odometry {
            header: header(10 + k as i32, 500_000_000, "odom"),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: Pose {
                    position: [0.2 * k as f64, 0.1 * (k as f64).sqrt(), 0.0],
                    orientation: [0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos()],
                },
                covariance: nested(&planar_cov(k)),
            },
            twist: TwistWithCovariance {
                twist: [0.5, 0.0, 0.0, 0.0, 0.0, 0.05],
                covariance: nested(&full_cov(0)),
            },
        };
        put(&mut w, odom, 10.6 + k as f64, &cdr(&msg));
    }
    for (k, (cov, q, sec)) in amcl_messages().into_iter().enumerate() {
        let msg = PoseWithCovarianceStamped {
            header: header(sec, 0, "map"),
            pose: PoseWithCovariance {
                pose: Pose {
                    position: [1.0 + k as f64, 2.0, 0.3],
                    orientation: q,
                },
                covariance: nested(&cov),
            },
        };
        put(&mut w, amcl, 100.5 + k as f64, &cdr(&msg));
    }
    // 11: truncated bytes.
    let cut = cdr(&PoseWithCovarianceStamped::default());
    put(&mut w, amcl, 111.5, &cut[..30]);
    for k in 0..3 {
        let msg = PoseWithCovariance {
            pose: Pose {
                position: [k as f64, 0.0, 1.0],
                orientation: [0.0, 0.0, 0.0, 1.0],
            },
            covariance: nested(&full_cov(k)),
        };
        put(&mut w, bare, 200.0 + k as f64, &cdr(&msg));
    }
    for k in 0..4 {
        put(&mut w, image, 300.0 + k as f64, &[1, 2, 3, 4]);
    }
    put(&mut w, json, 400.0, b"{}");
    w.finish().unwrap();
    w.into_inner().into_inner()
}

fn read(bytes: &[u8], options: &LogOptions) -> posecov::plan::log::LogSummary {
    let dir = std::env::temp_dir().join(format!("posecov-mcap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Tests run in parallel: one file each.
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = dir.join(format!("log-{n}.mcap"));
    std::fs::write(&path, bytes).unwrap();
    let plan = read_log(&path, options, &mut |_, _| {}, None).unwrap();
    std::fs::remove_file(&path).ok();
    plan
}

#[test]
fn committed_example_is_the_generators_output() {
    let bytes = write_example();
    if std::env::var_os("POSECOV_UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(std::path::Path::new(EXAMPLE).parent().unwrap()).unwrap();
        std::fs::write(EXAMPLE, &bytes).unwrap();
    }
    let committed = std::fs::read(EXAMPLE).expect("run with POSECOV_UPDATE_GOLDEN=1 once");
    // The writer's summary order is not byte-stable; what it says must be the same.
    let (a, b) = (
        read(&committed, &LogOptions::default()),
        read(&bytes, &LogOptions::default()),
    );
    assert_eq!(
        format!("{a:?}"),
        format!("{b:?}"),
        "the committed example differs from the generator"
    );
}

#[test]
fn topics_types_and_skips() {
    let plan = read(&write_example(), &LogOptions::default());
    let names: Vec<&str> = plan.topics.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["/amcl_pose", "/bare", "/planar/odom"]);
    let kinds: Vec<PoseMessageKind> = plan.topics.iter().map(|t| t.kind).collect();
    assert_eq!(
        kinds,
        [
            PoseMessageKind::PoseWithCovarianceStamped,
            PoseMessageKind::PoseWithCovariance,
            PoseMessageKind::Odometry
        ]
    );
    assert_eq!(plan.skipped.len(), 2);
    assert_eq!(plan.skipped[0].name, "/camera");
    assert_eq!(plan.skipped[0].message_type, "sensor_msgs/msg/Image");
    assert_eq!(plan.skipped[0].count, 4);
    assert_eq!(plan.skipped[1].name, "/odom_json");
    assert!(
        plan.skipped[1].message_type.contains("json encoding"),
        "{:?}",
        plan.skipped[1]
    );
    assert_eq!(plan.messages_total, 50 + 12 + 3 + 4 + 1);
    let only = read(
        &write_example(),
        &LogOptions {
            topics: vec!["/bare".into()],
            every: None,
            ..Default::default()
        },
    );
    assert_eq!(only.topics.len(), 1);
    assert_eq!(only.not_selected, ["/amcl_pose", "/planar/odom"]);
}

#[test]
fn planar_odometry_numbers_are_exact() {
    let plan = read(&write_example(), &LogOptions::default());
    let odom = &plan.topics[2];
    assert!(odom.group.is_planar());
    assert_eq!(
        (odom.frame_id.as_str(), odom.child_frame_id.as_str()),
        ("odom", "base_link")
    );
    assert_eq!(odom.count, 50);
    assert_eq!(odom.drawn.len(), 50);
    for d in &odom.drawn {
        let k = d.index as usize;
        let m = &d.message;
        assert_eq!(m.stamp_ns, (10 + k as i64) * 1_000_000_000 + 500_000_000);
        assert!(!m.from_log_time);
        for (a, b) in m.covariance.iter().zip(planar_cov(k)) {
            assert!((a - b).abs() <= 1e-12, "message {k}");
        }
        assert!((m.position[0] - 0.2 * k as f64).abs() <= 1e-12);
        let yaw = 0.05 * k as f64;
        assert!((m.orientation_xyzw[2] - (yaw / 2.0).sin()).abs() <= 1e-12);
        assert_eq!(m.twist_covariance.unwrap(), full_cov(0));
        assert!(d.unusable.is_empty());
        assert_eq!(d.unestimated, [false, false, true, true, true, false]);
    }
    let h = &odom.health;
    assert_eq!(h.count(Issue::Placeholder), 50);
    // One drop (k = 25: trace 1.815 → 0.015).
    assert_eq!(h.count(Issue::Drop), 1);
    assert_eq!(h.first(Issue::Drop), Some(35_500_000_000));
    // Growth: trace_k = 1.5 (0.01 + 0.05 (k mod 25)) reaches 100 × 0.015 at k mod 25 ≥ 20:
    // k = 20 … 24 and, measured from the drop, 45 … 49.
    assert_eq!(h.count(Issue::Growth), 10);
    assert_eq!(h.first(Issue::Growth), Some(30_500_000_000));
    assert_eq!(h.issues.len(), 3, "{h:?}");
    // σx series: √Σxx where estimated; z / roll / pitch are not.
    let s = &odom.series[3];
    assert!((s.sigma[0].unwrap() - planar_cov(3)[0].sqrt()).abs() <= 1e-12);
    assert_eq!(s.sigma[2], None);
    assert!((s.position_trace.unwrap() - 1.5 * planar_cov(3)[0]).abs() <= 1e-12);
}

#[test]
fn every_health_case_is_counted_once() {
    let plan = read(&write_example(), &LogOptions::default());
    let amcl = &plan.topics[0];
    assert_eq!(amcl.count, 12);
    assert!(!amcl.group.is_planar());
    let h = &amcl.health;
    let s = 1_000_000_000;
    for (issue, stamp) in [
        (Issue::AllZero, 101 * s),
        (Issue::UnknownMarker, 102 * s),
        // A placeholder on roll of a 3-D topic: an axis its motion uses.
        (Issue::PlaceholderUsedAxis, 103 * s),
        (Issue::NonFinite, 104 * s),
        (Issue::Asymmetric, 105 * s),
        (Issue::NotPsd, 106 * s),
        (Issue::BadOrientation, 107 * s),
        (Issue::Undecodable, 111 * s + 500_000_000),
        (Issue::StampFallback, 108 * s + 500_000_000),
        (Issue::StampOrder, 50 * s),
    ] {
        assert_eq!(h.count(issue), 1, "{issue:?}: {h:?}");
        assert_eq!(h.first(issue), Some(stamp), "{issue:?}");
    }
    assert_eq!(h.issues.len(), 10, "{h:?}");
    let lo = h.min_eigenvalue.unwrap();
    assert!(lo < -0.1, "{lo}");
    // Message 8 had a zero stamp: its log time is used, and said.
    assert_eq!(amcl.stamps_from_log_time, 1);
    let m8 = &amcl.drawn[8].message;
    assert!(m8.from_log_time);
    assert_eq!(m8.stamp_ns, 108 * s + 500_000_000);
    // Message 9 (stamp 50 s) is earlier than message 8's.
    assert_eq!(amcl.stamps_out_of_order, 1);
    assert_eq!(
        amcl.stamp_range,
        Some(posecov::plan::log::StampRange {
            first_ns: 50 * s,
            last_ns: 110 * s
        })
    );
    assert!(
        amcl.series
            .windows(2)
            .all(|w| w[0].stamp_ns <= w[1].stamp_ns)
    );
    // Unusable messages are kept for drawing as invalid, with their reasons.
    let reasons: Vec<Vec<Issue>> = amcl.drawn.iter().map(|d| d.unusable.clone()).collect();
    assert_eq!(reasons[0], []);
    assert_eq!(reasons[1], [Issue::AllZero]);
    assert_eq!(reasons[3], []);
    assert_eq!(reasons[6], [Issue::NotPsd]);
    for (a, b) in amcl.drawn[0].message.covariance.iter().zip(full_cov(0)) {
        assert!((a - b).abs() <= 1e-12);
    }
    // Bare PoseWithCovariance has no header: log time, not counted as a fallback.
    let bare = &plan.topics[1];
    assert_eq!(bare.stamps_from_log_time, 0);
    assert_eq!(bare.drawn[2].message.stamp_ns, 202 * s);
    assert!(bare.health.issues.is_empty());
}

#[test]
fn damaged_mcap_is_an_error_not_a_panic() {
    let bytes = write_example();
    let dir = std::env::temp_dir().join(format!("posecov-mcap-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for cut in [9, 100, bytes.len() / 2, bytes.len() - 3] {
        let path = dir.join(format!("cut{cut}.mcap"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let e = read_log(&path, &LogOptions::default(), &mut |_, _| {}, None).unwrap_err();
        assert!(e.to_string().contains(&format!("cut{cut}.mcap")), "{e}");
        // Cut inside a record: said in plain words, not as a length limit.
        let e = e.to_string();
        assert!(
            e.contains("ended in the middle of a record") || e.contains("the file is cut short"),
            "{e}"
        );
    }
    let mut flipped = bytes.clone();
    for i in (40..flipped.len()).step_by(13) {
        flipped[i] ^= 0x5a;
    }
    let path = dir.join("flipped.mcap");
    std::fs::write(&path, &flipped).unwrap();
    let _ = read_log(&path, &LogOptions::default(), &mut |_, _| {}, None);
    std::fs::remove_dir_all(&dir).ok();
}

/// A chunk whose header gives another uncompressed size than its data has (a few falsified
/// bytes) ends with an error naming the file, at once: it once made the reader spin without
/// end.
#[test]
fn a_falsified_chunk_size_ends_with_an_error() {
    let bytes = write_example();
    // The data section's records: opcode, length, body; a chunk's body starts with its
    // start and end times, then its uncompressed size.
    let mut chunks = Vec::new();
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        if bytes[at] == 0x06 {
            chunks.push(at + 9 + 16);
        }
        if bytes[at] == 0x0f || bytes[at] == 0x02 {
            break; // data end, footer
        }
        at += 9 + len;
    }
    assert!(!chunks.is_empty(), "the example has chunks");
    let dir = std::env::temp_dir().join(format!("posecov-mcap-size-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (k, change) in [1i64, 64, -1, 1 << 20].into_iter().enumerate() {
        let mut damaged = bytes.clone();
        for &size_at in &chunks {
            let size = u64::from_le_bytes(damaged[size_at..size_at + 8].try_into().unwrap());
            let falsified = size.wrapping_add_signed(change);
            damaged[size_at..size_at + 8].copy_from_slice(&falsified.to_le_bytes());
        }
        let path = dir.join(format!("size{k}.mcap"));
        std::fs::write(&path, &damaged).unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        let p = path.clone();
        std::thread::spawn(move || {
            let r = read_log(&p, &LogOptions::default(), &mut |_, _| {}, None).map(drop);
            tx.send(r.map_err(|e| e.to_string())).ok();
        });
        let result = rx
            .recv_timeout(std::time::Duration::from_secs(30))
            .unwrap_or_else(|_| panic!("uncompressed size {change:+}: still reading after 30 s"));
        let e = result.expect_err("a falsified chunk size is an error");
        assert!(
            e.contains(&format!("size{k}.mcap")) && e.contains("header says"),
            "{change:+}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A declared topic without messages beside one with messages is listed, evaluated and
/// drawn: a scene that validates and says "0 messages" (the stages after reading, through
/// the public API). Alone, it is no pose topic to draw: an error naming it.
#[test]
fn a_topic_without_messages_is_drawn() {
    use posecov::draw::log::{LogDrawSettings, description, draw_log};
    use posecov::eval::log::evaluate_log;
    use posecov::input::{About, Format};
    use posecov::uncertain::Confidence;
    let log = |with_messages: bool| {
        let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
        let schema = w
            .add_schema(
                "geometry_msgs/msg/PoseWithCovarianceStamped",
                "ros2msg",
                b"",
            )
            .unwrap();
        w.add_channel(schema, "/empty", "cdr", &BTreeMap::new())
            .unwrap();
        if with_messages {
            let full = w
                .add_channel(schema, "/amcl_pose", "cdr", &BTreeMap::new())
                .unwrap();
            let msg = PoseWithCovarianceStamped {
                header: header(5, 0, "map"),
                pose: PoseWithCovariance {
                    pose: Pose {
                        position: [1.0, 2.0, 0.0],
                        orientation: [0.0, 0.0, 0.0, 1.0],
                    },
                    covariance: nested(&full_cov(0)),
                },
            };
            let header = mcap::records::MessageHeader {
                channel_id: full,
                sequence: 1,
                log_time: 5_000_000_000,
                publish_time: 5_000_000_000,
            };
            w.write_to_known_channel(&header, &cdr(&msg)).unwrap();
        }
        w.finish().unwrap();
        w.into_inner().into_inner()
    };
    let path = std::env::temp_dir().join(format!("posecov-mcap-empty-{}.mcap", std::process::id()));
    std::fs::write(&path, log(false)).unwrap();
    let err = read_log(&path, &LogOptions::default(), &mut |_, _| {}, None)
        .unwrap_err()
        .to_string();
    std::fs::remove_file(&path).ok();
    assert!(
        err.contains("topics with a covariance but no messages: /empty"),
        "{err}"
    );
    let mut plan = read(&log(true), &LogOptions::default());
    assert_eq!(plan.topics.len(), 2);
    let empty = plan.topics.iter().find(|t| t.name == "/empty").unwrap();
    assert_eq!(empty.count, 0);
    let e = evaluate_log(&mut plan, &Default::default());
    let text = description(&plan, Format::Mcap.name(), &e, Confidence::DEFAULT);
    assert!(text.contains("0 messages"), "{text}");
    let settings = LogDrawSettings {
        about: About {
            title: "t".into(),
            description: String::new(),
            source: String::new(),
        },
        confidence: Confidence::DEFAULT,
        axis_length: None,
    };
    assert!(draw_log(&e, &settings, &text).validate().is_ok());
}
