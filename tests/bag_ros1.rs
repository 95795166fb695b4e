//! The ROS 1 reader on a real bag: robot_localization's test2.bag (a Jackal's odometry with
//! 1e6 placeholders for z, roll and pitch; bz2 chunks).

use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Issue, PoseMessageKind};

const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);

#[test]
fn test2_bag_reads_with_its_placeholders() {
    let plan = read_log(TEST2.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    let odom = &plan.topics[0];
    assert_eq!(odom.kind, PoseMessageKind::Odometry);
    assert_eq!(odom.health.count(Issue::Placeholder), odom.count);
    assert!(odom.group.is_planar());
    assert_eq!(odom.name, "/jackal_velocity_controller/odom");
    assert_eq!(
        (odom.frame_id.as_str(), odom.child_frame_id.as_str()),
        ("odom", "base_link")
    );
    assert_eq!(odom.count, 3060);
    assert_eq!(odom.health.first(Issue::Placeholder), Some(47_584_000_000));
    // The covariance is the same in all 3060 messages over 61 s and 84 m of driving: the one
    // other finding, a defect on dead-reckoned odometry.
    assert!(odom.dead_reckoned());
    let stretch = odom.health.constant.expect("a constant stretch");
    assert_eq!((stretch.messages, stretch.first_index), (3060, 0));
    assert_eq!(
        (stretch.first_stamp_ns, stretch.last_stamp_ns),
        (47_584_000_000, 108_764_000_000)
    );
    assert!((stretch.distance_m - 84.18).abs() < 0.01, "{stretch:?}");
    assert_eq!(odom.health.count(Issue::Constant), 3060);
    assert_eq!(odom.health.issues.len(), 2, "{:?}", odom.health);
    assert_eq!(odom.stamps_from_log_time, 0);
    // At most 200 drawn, evenly spaced; the trajectory keeps every message of a small bag.
    assert!(odom.drawn.len() <= 200 && odom.drawn.len() > 100);
    assert_eq!(odom.trajectory.len(), 3060);
    let first = &odom.drawn[0].message;
    assert_eq!(first.covariance[0], 0.001);
    assert_eq!(first.covariance[14], 1e6);
    assert_eq!(first.covariance[35], 0.03);
    assert!((first.position[0] - 0.1571574254425733).abs() < 1e-12);
    // The IMU is a sensor topic: its three covariances checked (bag_imu.rs).
    assert!(plan.skipped.is_empty());
    assert_eq!(plan.sensors[0].name, "/imu/data");
    assert_eq!(plan.sensors[0].kind, posecov::plan::log::SensorKind::Imu);
    assert_eq!(plan.sensors[0].count, 3061);
    assert_eq!(plan.messages_total, 3060 + 3061);
}

#[test]
fn topic_selection_and_every() {
    let only = LogOptions {
        topics: vec!["/jackal_velocity_controller/odom".into()],
        every: Some(100),
        ..Default::default()
    };
    let plan = read_log(TEST2.as_ref(), &only, &mut |_, _| {}, None).unwrap();
    assert_eq!(plan.topics[0].drawn.len(), 31); // messages 0, 100, …, 3000
    assert_eq!(plan.topics[0].stride, 100);
    let wrong = LogOptions {
        topics: vec!["/imu/data".into()],
        every: None,
        ..Default::default()
    };
    // The IMU alone: read as the one sensor topic, the odometry not selected.
    let imu = read_log(TEST2.as_ref(), &wrong, &mut |_, _| {}, None).unwrap();
    assert!(imu.topics.is_empty() && imu.sensors.len() == 1);
    assert_eq!(imu.not_selected, ["/jackal_velocity_controller/odom"]);
    let missing = LogOptions {
        topics: vec!["/odom".into()],
        every: None,
        ..Default::default()
    };
    let e = read_log(TEST2.as_ref(), &missing, &mut |_, _| {}, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no such topic; topics with a covariance in this log: /imu/data, /jackal_velocity_controller/odom"),
        "{e}"
    );
}

#[test]
fn damaged_bags_are_errors_not_panics() {
    let bytes = std::fs::read(TEST2).unwrap();
    let dir = std::env::temp_dir().join(format!("posecov-bag-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, data) in [
        ("truncated.bag", bytes[..bytes.len() / 2].to_vec()),
        ("header_only.bag", bytes[..20].to_vec()),
        ("garbage.bag", {
            let mut b = bytes.clone();
            for (i, v) in b.iter_mut().enumerate().skip(5000).step_by(97) {
                *v = (i % 251) as u8;
            }
            b
        }),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, &data).unwrap();
        match read_log(&path, &LogOptions::default(), &mut |_, _| {}, None) {
            Err(e) => assert!(e.to_string().contains(name), "{e}"),
            // Flipped bytes inside messages are counted, not fatal; a bag cut short keeps its
            // whole chunks and says where it stops (tests/bag_bad_input.rs).
            Ok(plan) => assert!(
                name == "garbage.bag" || (name == "truncated.bag" && plan.cut.is_some()),
                "{name}: {plan:?}"
            ),
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn ctrl_c_keeps_what_was_read_and_draws_it() {
    use std::sync::atomic::{AtomicBool, Ordering};
    let cancel = AtomicBool::new(false);
    // Raise the flag after the first chunk, as Ctrl-C would mid-read.
    let mut plan = read_log(
        TEST2.as_ref(),
        &LogOptions::default(),
        &mut |_, _| cancel.store(true, Ordering::Relaxed),
        Some(&cancel),
    )
    .unwrap();
    assert!(plan.cancelled);
    let odom = &plan.topics[0];
    assert!(odom.count > 0 && odom.count < 3060, "{}", odom.count);
    let e = posecov::eval::log::evaluate_log(&mut plan, &Default::default());
    let about = posecov::input::About {
        title: "t".into(),
        description: String::new(),
        source: String::new(),
    };
    let settings = posecov::draw::log::LogDrawSettings {
        about,
        confidence: posecov::uncertain::Confidence::DEFAULT,
        axis_length: None,
    };
    let text = posecov::draw::log::description(
        &plan,
        posecov::input::Format::Ros1Bag.name(),
        &e,
        posecov::uncertain::Confidence::DEFAULT,
    );
    assert!(text.contains("Interrupted (Ctrl-C)"), "{text}");
    assert!(
        posecov::draw::log::draw_log(&e, &settings, &text)
            .validate()
            .is_ok()
    );
}
