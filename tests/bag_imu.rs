//! `sensor_msgs/Imu` (issue 32): its three covariances checked on a real bag (test2.bag's
//! 3061 IMU messages), REP 145's −1 "not provided" and all-zero "unknown" on a bag written by
//! PyPI `rosbags` (tests/data/imu), the CDR path on the ROS 2 bags, and `check` on a log that
//! holds only IMUs.

use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Class, Issue, SensorKind};

mod posecov_cli;
use posecov_cli::{json, run};

const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);
const REP145: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/imu/imu_rep145.bag");
const ARC: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2/arc.mcap");

#[test]
fn test2_bag_imu_is_checked_with_its_constant_covariances() {
    let plan = read_log(TEST2.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    let imu = &plan.sensors[0];
    assert_eq!(
        (imu.name.as_str(), imu.kind),
        ("/imu/data", SensorKind::Imu)
    );
    assert_eq!(imu.count, 3061);
    let names: Vec<&str> = imu.blocks.iter().map(|b| b.spec.name).collect();
    assert_eq!(
        names,
        ["orientation", "angular_velocity", "linear_acceleration"]
    );
    // One covariance per block throughout: `constant`, a note on a sensor.
    for b in &imu.blocks {
        assert_eq!(b.health.count(Issue::Constant), 3061, "{}", b.spec.name);
        let x = b.sigma_stats[0].expect("σx");
        assert_eq!(x.messages, 3061);
        assert_eq!(x.min, x.max);
    }
    assert_eq!(
        SensorKind::class(Issue::Constant),
        Class::Note,
        "a datasheet constant is no defect"
    );
    let v = json(&["report", "--json", TEST2]);
    let s = &v["sensors"][0];
    assert_eq!(s["name"], "/imu/data");
    assert_eq!(s["type"], "sensor_msgs/Imu");
    assert_eq!(s["kind"], "imu");
    assert_eq!(s["messages"], 3061);
    for (block, unit) in [
        ("orientation", "rad"),
        ("angular_velocity", "rad/s"),
        ("linear_acceleration", "m/s²"),
    ] {
        let b = &s["blocks"][block];
        assert_eq!(b["unit"], unit);
        assert_eq!(b["sigma"]["x"]["unit"], unit);
        assert_eq!(b["health"]["constant"]["class"], "note");
        let sigma = b["sigma"]["z"]["median_of_kept"].as_f64().unwrap();
        assert!(sigma > 0.0 && sigma.is_finite(), "{block}: {sigma}");
    }
    // The pose topic's report is as before.
    assert_eq!(v["topics"][0]["health"]["constant"]["class"], "defect");
    assert_eq!(v["topics"].as_array().unwrap().len(), 1);
}

#[test]
fn rep145_not_provided_is_a_note_and_all_zero_a_defect() {
    let plan = read_log(
        REP145.as_ref(),
        &LogOptions::default(),
        &mut |_, _| {},
        None,
    )
    .unwrap();
    assert!(plan.topics.is_empty());
    let [no_orientation, zeros] = &plan.sensors[..] else {
        panic!("{:?}", plan.sensors)
    };
    assert_eq!(no_orientation.name, "/imu/no_orientation");
    assert_eq!(no_orientation.count, 40);
    assert_eq!(no_orientation.frame_id, "imu_link");
    let orientation = &no_orientation.blocks[0];
    assert_eq!(orientation.health.count(Issue::UnknownMarker), 40);
    // Not provided: not checked, no σ.
    assert_eq!(
        orientation.health.issues.len(),
        1,
        "{:?}",
        orientation.health
    );
    assert_eq!(orientation.sigma_stats, [None; 3]);
    // The other two are read: σ 0.02 rad/s and 0.05 m/s², to the bit of √(σ²).
    let gyro = no_orientation.blocks[1].sigma_stats[2].unwrap();
    assert_eq!(
        (gyro.min, gyro.max),
        ((0.02f64 * 0.02).sqrt(), (0.02f64 * 0.02).sqrt())
    );
    let accel = no_orientation.blocks[2].sigma_stats[0].unwrap();
    assert_eq!(accel.max, (0.05f64 * 0.05).sqrt());
    assert!(no_orientation.findings().all(|f| f.3 == Class::Note));
    assert_eq!(zeros.count, 20);
    for b in &zeros.blocks {
        assert_eq!(b.health.count(Issue::AllZero), 20, "{}", b.spec.name);
        assert_eq!(b.sigma_stats, [None; 3]);
    }
    // `check`: an IMU-only log is checked; all zero fails it, named with its block.
    let (code, out, err) = run(&["check", REP145]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(
        out.contains("defects on 0 of 0 pose topic(s) and 1 of 2 sensor topic(s)"),
        "{out}"
    );
    assert!(
        err.contains(
            "imu_rep145.bag: topic /imu/zeros, message 0 (stamp 1700000000.000 s): all_zero on orientation_covariance — every entry of orientation_covariance is 0"
        ),
        "{err}"
    );
    assert!(
        err.contains("`--allow all_zero` accepts it; 2 more defect(s)"),
        "{err}"
    );
    assert!(!err.contains("unknown_marker"), "a note: {err}");
    let (code, out, err) = run(&["check", REP145, "--allow", "all_zero"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(
        out.contains("ok (0 pose topic(s), 2 sensor topic(s)"),
        "{out}"
    );
    assert!(out.contains("defects allowed: all_zero"), "{out}");
    let v = json(&["report", "--json", REP145]);
    let marker = &v["sensors"][0]["blocks"]["orientation"]["health"]["unknown_marker"];
    assert_eq!(marker["class"], "note");
    assert_eq!(marker["count"], 40);
    assert!(
        marker["sentence"]
            .as_str()
            .unwrap()
            .contains("REP 145's \"not provided\""),
        "{marker}"
    );
    assert_eq!(
        v["sensors"][0]["blocks"]["orientation"]["sigma"],
        serde_json::json!({})
    );
    assert_eq!(
        v["sensors"][1]["blocks"]["linear_acceleration"]["health"]["all_zero"]["class"],
        "defect"
    );
}

#[test]
fn cdr_imu_messages_are_read_from_ros2_bags() {
    let plan = read_log(ARC.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    let imu = &plan.sensors[0];
    assert_eq!((imu.name.as_str(), imu.count), ("/imu", 20));
    assert_eq!(imu.frame_id, "imu_link");
    assert_eq!(imu.blocks[0].health.count(Issue::UnknownMarker), 20);
    assert_eq!(imu.blocks[1].sigma_stats[0].unwrap().max, 1e-4f64.sqrt());
    assert_eq!(imu.blocks[2].sigma_stats[2].unwrap().max, 1e-2f64.sqrt());
    assert!(plan.skipped.iter().all(|s| s.name != "/imu"));
}

#[test]
fn sensor_sigmas_are_plotted_over_the_stamp() {
    use posecov::draw::log::{LogDrawSettings, description, draw_log};
    use posecov::eval::log::{LogEvalSettings, evaluate_log};
    let mut plan = read_log(
        REP145.as_ref(),
        &LogOptions::default(),
        &mut |_, _| {},
        None,
    )
    .unwrap();
    let e = evaluate_log(&mut plan, &LogEvalSettings::default());
    let about = posecov::input::About {
        title: "imu".into(),
        description: String::new(),
        source: String::new(),
    };
    let confidence = posecov::uncertain::Confidence::DEFAULT;
    let settings = LogDrawSettings {
        about,
        confidence,
        axis_length: None,
    };
    let text = description(&plan, "ROS 1 bag", &e, confidence);
    assert!(
        text.contains(
            "**/imu/no_orientation** (`sensor_msgs/Imu`, frame `imu_link`): 40 messages."
        ),
        "{text}"
    );
    let scene = draw_log(&e, &settings, &text);
    scene.validate().unwrap();
    let ids: Vec<&str> = scene.plots.iter().map(|p| p.id.as_str()).collect();
    // After the pose plots (empty here); no orientation plot: no topic provides one.
    assert_eq!(
        ids[ids.len() - 2..],
        ["sigma_angular_velocity", "sigma_linear_acceleration"]
    );
    assert!(!ids.contains(&"sigma_orientation"));
    let gyro = &scene.plots[ids.len() - 2];
    assert_eq!(gyro.unit, "mrad/s");
    let lines: Vec<_> = scene
        .series
        .iter()
        .filter(|s| s.plot.as_str() == "sigma_angular_velocity")
        .collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0].points.len(), 40);
    assert!(
        (lines[0].points[0].1 - 20.0).abs() < 1e-9,
        "{:?}",
        lines[0].points[0]
    );
}
