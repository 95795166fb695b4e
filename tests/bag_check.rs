//! `posecov check` as CI gates on it, and the exit-code table (docs/guide/cli.md, `--help`): 1 on a
//! log's defects, 2 when a log cannot be processed (no topic with a covariance), no empty
//! recording written, `--allow` by name, a closed stdout ends quietly with 0.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::PathBuf;
use std::process::{Command, Stdio};

use posecov::input::log::decode::{
    Header, Odometry, Pose, PoseWithCovariance, Time, TwistWithCovariance, nested,
};

mod posecov_cli;
use posecov_cli::{BIN, run};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-check-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn cdr<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    b.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(msg).unwrap());
    b
}

/// An MCAP file with a ROS 2 `/odom` whose covariances are `cov` (the robot drives 0.1 m per
/// message), and a `/camera` topic of a type posecov skips; or the `/camera` topic alone.
fn write_log(path: &PathBuf, odom_cov: Option<[f64; 36]>) {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let none = BTreeMap::new();
    let image_schema = w
        .add_schema("sensor_msgs/msg/Image", "ros2msg", b"")
        .unwrap();
    let image = w
        .add_channel(image_schema, "/camera", "cdr", &none)
        .unwrap();
    let odom_schema = w
        .add_schema("nav_msgs/msg/Odometry", "ros2msg", b"")
        .unwrap();
    let odom = w.add_channel(odom_schema, "/odom", "cdr", &none).unwrap();
    for k in 0..30u32 {
        let t = u64::from(k) * 100_000_000 + 1_000_000_000;
        let mut put = |channel_id, data: &[u8]| {
            w.write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id,
                    sequence: k,
                    log_time: t,
                    publish_time: t,
                },
                data,
            )
            .unwrap();
        };
        put(image, &[1, 2, 3, 4]);
        if let Some(cov) = odom_cov {
            let msg = Odometry {
                header: Header {
                    stamp: Time {
                        sec: 1,
                        nanosec: k * 100_000_000,
                    },
                    frame_id: "odom".into(),
                },
                child_frame_id: "base_link".into(),
                pose: PoseWithCovariance {
                    pose: Pose {
                        position: [0.1 * f64::from(k), 0.0, 0.0],
                        orientation: [0.0, 0.0, 0.0, 1.0],
                    },
                    covariance: nested(&cov),
                },
                twist: TwistWithCovariance {
                    twist: [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                    covariance: nested(&[0.0; 36]),
                },
            };
            put(odom, &cdr(&msg));
        }
    }
    w.finish().unwrap();
    std::fs::write(path, w.into_inner().into_inner()).unwrap();
}

#[test]
fn a_log_without_pose_topics_cannot_be_processed_and_writes_nothing() {
    let dir = scratch("nopose");
    let log = dir.join("camera_only.mcap");
    write_log(&log, None);
    let log = log.to_str().unwrap();
    let (code, out, err) = run(&["check", log]);
    assert_eq!(code, Some(2), "{out}{err}");
    assert!(
        err.contains("camera_only.mcap: no topic with a covariance to check; the log has /camera (sensor_msgs/msg/Image, 30 messages), topics with a covariance but no messages: /odom; posecov reads nav_msgs/Odometry (ROS 2: nav_msgs/msg/Odometry)"),
        "{err}"
    );
    assert!(
        err.ends_with(
            "sensor_msgs/Imu (ROS 2: sensor_msgs/msg/Imu), sensor_msgs/NavSatFix (ROS 2: sensor_msgs/msg/NavSatFix), geometry_msgs/TwistWithCovarianceStamped (ROS 2: geometry_msgs/msg/TwistWithCovarianceStamped), geometry_msgs/AccelWithCovarianceStamped (ROS 2: geometry_msgs/msg/AccelWithCovarianceStamped)\n"
        ),
        "{err}"
    );
    let (code, _, err) = run(&["report", "--json", log]);
    assert_eq!(code, Some(2), "{err}");
    let rrd = dir.join("out.rrd");
    let (code, _, err) = run(&[log, "--save", rrd.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(!rrd.exists(), "no empty recording is written");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn all_zero_covariances_fail_check_unless_allowed() {
    let dir = scratch("zero");
    let log = dir.join("zero_odom.mcap");
    write_log(&log, Some([0.0; 36]));
    let log = log.to_str().unwrap();
    let (code, out, err) = run(&["check", log]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(
        // The odometry's twist, all zero too: a note (an odometry's twist covariance is often unset).
        out.contains("defects on 1 of 1 pose topic(s) and 0 of 1 sensor topic(s) (60 messages"),
        "{out}"
    );
    assert!(
        err.contains("zero_odom.mcap: topic /odom, message 0 (stamp 1.000 s): all_zero — every estimated entry is 0")
            && err.contains("(30 message(s); `--allow all_zero` accepts it"),
        "{err}"
    );
    let (code, out, err) = run(&["check", log, "--allow", "all_zero"]);
    assert_eq!(code, Some(0), "{out}{err}");
    // Other commands show and report defects: not an error.
    let (code, _, err) = run(&["report", log]);
    assert_eq!(code, Some(0), "{err}");
    // An unknown name is a usage error, with the names.
    let (code, _, err) = run(&["check", log, "--allow", "zero"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("--allow zero: out of range: one of non_finite, asymmetric"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_constant_dead_reckoned_covariance_is_a_defect_with_its_stretch() {
    let dir = scratch("constant");
    let log = dir.join("constant_odom.mcap");
    let mut cov = [0.0; 36];
    for (i, v) in [0.01, 0.01, 1e6, 1e6, 1e6, 0.03].into_iter().enumerate() {
        cov[i * 7] = v;
    }
    write_log(&log, Some(cov));
    let (code, out, err) = run(&["report", "--json", log.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let health = &v["topics"][0]["health"];
    // 30 messages 0.1 m apart: 2.9 m over 2.9 s without growth.
    assert_eq!(health["constant"]["count"], 30, "{health}");
    assert_eq!(health["constant"]["class"], "defect", "{health}");
    assert_eq!(health["placeholder"]["class"], "note", "{health}");
    let (code, _, err) = run(&["check", log.to_str().unwrap()]);
    assert_eq!(code, Some(1));
    assert!(
        err.contains(
            "constant — the covariance never grows over 30 messages, 2.9 s and 2.9 m of motion"
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn help_shows_the_exit_codes_and_a_closed_stdout_is_quiet() {
    let (code, out, _) = run(&["check", "--help"]);
    assert_eq!(code, Some(0));
    assert!(
        out.contains("Exit codes") && out.contains("2    cannot process"),
        "{out}"
    );
    // `posecov check … | head -c 0`: the reader is gone before the line is written.
    let mut child = Command::new(BIN)
        .args(["check", "covariance_health"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    let status = child.wait().expect("wait");
    assert_eq!(
        status.code(),
        Some(0),
        "a closed stdout ends quietly with 0"
    );
}

#[test]
fn values_beyond_f32_are_drawn_clipped_and_said() {
    let dir = scratch("overflow");
    let planar = [(7, 0.01), (14, 1e6), (21, 1e6), (28, 1e6), (35, 0.03)];
    for (name, entries) in [
        // A variance of 4.5e153 on x (σ = 6.7e76 m, beyond f32) on a planar topic: a
        // placeholder on an axis in use, drawn as RViz's clipped picture and a cross.
        ("huge_x", vec![(0, 4.5e153)]),
        // On z of a planar topic: a placeholder like 1e6.
        ("huge_z", vec![(0, 0.01), (14, 4.5e153)]),
    ] {
        let log = dir.join(format!("{name}.mcap"));
        let mut cov = [0.0; 36];
        for (i, v) in planar.into_iter().chain(entries) {
            cov[i] = v;
        }
        write_log(&log, Some(cov));
        let rrd = dir.join(format!("{name}.rrd"));
        let (code, out, err) = run(&[log.to_str().unwrap(), "--save", rrd.to_str().unwrap()]);
        let log = log.display().to_string();
        assert_eq!(code, Some(0), "{name}: {out}{err}");
        let (code, out, err) = run(&["report", "--json", &log]);
        assert_eq!(code, Some(0), "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let topic = &v["topics"][0];
        if name == "huge_x" {
            assert_eq!(
                topic["health"]["placeholder_used_axis"]["count"], 30,
                "{topic}"
            );
            assert_eq!(topic["drawn_invalid"], 30, "{topic}");
            assert!(topic["sigma"].get("x").is_none(), "not estimated: {topic}");
        } else {
            assert_eq!(topic["drawn_invalid"], 0, "{topic}");
            assert_eq!(topic["health"]["placeholder"]["class"], "note", "{topic}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
