//! Velocities and accelerations with covariance (issue 32): `TwistWithCovarianceStamped`,
//! `AccelWithCovarianceStamped` and the twist half of `nav_msgs/Odometry`, on a ROS 1 bag and a
//! ROS 2 `.db3` bag of the same messages written by PyPI `rosbags` (tests/data/twist): their
//! health classes, σ per axis with units in `report --json`, the plots, and `check`'s exit codes.

use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Class, Issue, SensorKind, SensorTopicSummary};

mod posecov_cli;
use posecov_cli::{json, run};

const BAG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/twist/twist.bag");
const DB3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/twist/twist_db3");

fn sensors(path: &str) -> Vec<SensorTopicSummary> {
    let plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    assert_eq!(plan.topics.len(), 1, "{path}: /odom is the one pose topic");
    plan.sensors
}

#[test]
fn every_kind_and_class_on_both_codecs() {
    for path in [BAG, DB3] {
        let s = sensors(path);
        let names: Vec<(&str, SensorKind, u64)> = s
            .iter()
            .map(|t| (t.name.as_str(), t.kind, t.count))
            .collect();
        assert_eq!(
            names,
            [
                ("/imu/accel", SensorKind::Accel, 40),
                ("/odom", SensorKind::OdometryTwist, 50),
                ("/vo/twist", SensorKind::Twist, 30),
                ("/wheel/twist", SensorKind::Twist, 50),
            ],
            "{path}"
        );
        let [accel, odom, vo, wheel] = &s[..] else {
            unreachable!()
        };
        // An honest velocity: no finding; σ vx grows with the speed, in m/s.
        assert_eq!(wheel.findings().count(), 0, "{path}: {:?}", wheel.blocks);
        assert_eq!(wheel.frame_id, "base_link");
        let vx = wheel.blocks[0].sigma_stats[0].unwrap();
        assert!(vx.min >= 0.02 && vx.max <= 0.02 + 0.05 * 1.1 && vx.min < vx.max);
        assert_eq!(
            wheel.blocks[1].sigma_stats[0].unwrap().max,
            (0.005f64 * 0.005).sqrt()
        );
        // Two defects, each on its block.
        let linear = &vo.blocks[0].health;
        let c = linear
            .issues
            .iter()
            .find(|(i, _)| **i == Issue::NotPsd)
            .unwrap()
            .1;
        assert_eq!((c.count, c.first_index), (20, 10), "{path}");
        assert!(linear.min_eigenvalue.unwrap() < 0.0);
        assert_eq!(vo.blocks[1].health.count(Issue::AllZero), 30);
        assert_eq!(vo.blocks[1].sigma_stats, [None; 3]);
        let defects: Vec<_> = vo
            .findings()
            .filter(|f| f.3 == Class::Defect)
            .map(|f| (f.0, f.1))
            .collect();
        assert_eq!(
            defects,
            [
                (Some("linear_velocity"), Issue::NotPsd),
                (Some("angular_velocity"), Issue::AllZero)
            ]
        );
        // Its ten PSD messages before are identical: `constant`, a note.
        assert_eq!(vo.blocks[0].health.count(Issue::Constant), 10);
        // An acceleration: linear constant (a note), angular not provided (−1, a note).
        assert_eq!(accel.blocks[0].spec.unit, "m/s²");
        assert_eq!(accel.blocks[1].spec.unit, "rad/s²");
        assert_eq!(accel.blocks[0].health.count(Issue::Constant), 40);
        assert_eq!(accel.blocks[1].health.count(Issue::UnknownMarker), 40);
        assert!(accel.findings().all(|f| f.3 == Class::Note));
        // Odometry's twist: in the child frame; roll and pitch rates placeholders (a note).
        assert_eq!(odom.frame_id, "base_link");
        assert_eq!(odom.kind.frame_field(), "child_frame_id");
        assert_eq!(odom.blocks[1].health.count(Issue::Placeholder), 50);
        let angular = odom.blocks[1].sigma_stats;
        assert!(angular[0].is_none() && angular[1].is_none());
        assert!((angular[2].unwrap().max - (0.02f64 + 0.01 * 49.0 / 50.0)).abs() < 1e-12);
        assert_eq!(odom.blocks[0].health.count(Issue::Constant), 50);
        // Its stamps are the pose topic's: no stamp finding of its own.
        assert!(odom.health.issues.is_empty());
    }
}

#[test]
fn report_json_has_units_frames_and_the_pose_unchanged() {
    let v = json(&["report", "--json", BAG]);
    let db3 = json(&["report", "--json", DB3]);
    assert_eq!(
        v["sensors"], db3["sensors"],
        "the .db3's CDR gives the bag's numbers"
    );
    assert_eq!(v["topics"], db3["topics"]);
    let by_name = |name: &str| {
        v["sensors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["name"] == name)
            .unwrap()
            .clone()
    };
    let wheel = by_name("/wheel/twist");
    assert_eq!(wheel["type"], "geometry_msgs/TwistWithCovarianceStamped");
    assert_eq!(wheel["kind"], "twist");
    assert_eq!(wheel["frame_field"], "header.frame_id");
    for (block, unit) in [("linear_velocity", "m/s"), ("angular_velocity", "rad/s")] {
        assert_eq!(wheel["blocks"][block]["unit"], unit);
        assert_eq!(wheel["blocks"][block]["sigma"]["z"]["unit"], unit);
    }
    let accel = by_name("/imu/accel");
    assert_eq!(accel["type"], "geometry_msgs/AccelWithCovarianceStamped");
    assert_eq!(accel["blocks"]["angular_acceleration"]["unit"], "rad/s²");
    assert_eq!(
        accel["blocks"]["linear_acceleration"]["sigma"]["x"]["max"],
        (0.05f64 * 0.05).sqrt()
    );
    let odom = by_name("/odom");
    assert_eq!(odom["type"], "nav_msgs/Odometry");
    assert_eq!(odom["kind"], "odometry_twist");
    assert_eq!(
        (&odom["frame_id"], &odom["frame_field"]),
        (&"base_link".into(), &"child_frame_id".into())
    );
    let vo = by_name("/vo/twist");
    let not_psd = &vo["blocks"]["linear_velocity"]["health"]["not_psd"];
    assert_eq!(not_psd["class"], "defect");
    assert_eq!(not_psd["first_message"], 10);
    assert!(
        not_psd["sentence"]
            .as_str()
            .unwrap()
            .starts_with("twist.covariance[0:3, 0:3] has a negative variance"),
        "{not_psd}"
    );
    // The pose topic keeps its own results: the twist's placeholders and constant blocks are
    // findings of the twist entry only; the pose's one finding is its own growth.
    let pose = &v["topics"][0];
    assert_eq!(pose["name"], "/odom");
    let pose_findings: Vec<&String> = pose["health"].as_object().unwrap().keys().collect();
    assert_eq!(pose_findings, ["growth"], "{}", pose["health"]);
}

#[test]
fn check_names_the_topic_and_block_and_allow_accepts() {
    for path in [BAG, DB3] {
        let (code, out, err) = run(&["check", path]);
        assert_eq!(code, Some(1), "{out}{err}");
        assert!(
            out.contains("defects on 0 of 1 pose topic(s) and 1 of 4 sensor topic(s)"),
            "{out}"
        );
        assert!(
            err.contains(
                "topic /vo/twist, message 0 (stamp 1700000000.000 s): all_zero on twist.covariance[3:6, 3:6] — every entry of twist.covariance[3:6, 3:6] is 0"
            ),
            "{err}"
        );
        assert!(err.contains("1 more defect(s) on this topic"), "{err}");
        assert!(
            !err.contains("/wheel/twist") && !err.contains("/imu/accel"),
            "{err}"
        );
        let (code, out, err) = run(&["check", path, "--allow", "all_zero"]);
        assert_eq!(code, Some(1), "{out}{err}");
        assert!(
            err.contains(
                "message 10 (stamp 1700000000.200 s): not_psd on twist.covariance[0:3, 0:3]"
            ),
            "{err}"
        );
        let (code, out, err) = run(&["check", path, "--allow", "all_zero", "--allow", "not_psd"]);
        assert_eq!(code, Some(0), "{out}{err}");
        let (code, out, err) = run(&["check", path, "--topic", "/wheel/twist"]);
        assert_eq!(code, Some(0), "{out}{err}");
        assert!(
            out.contains("ok (0 pose topic(s), 1 sensor topic(s)"),
            "{out}"
        );
    }
}

#[test]
fn velocities_are_sigma_plots_over_the_stamp() {
    use posecov::draw::log::{LogDrawSettings, description, draw_log};
    use posecov::eval::log::{LogEvalSettings, evaluate_log};
    let mut plan = read_log(BAG.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    let e = evaluate_log(&mut plan, &LogEvalSettings::default());
    let confidence = posecov::uncertain::Confidence::DEFAULT;
    let settings = LogDrawSettings {
        about: posecov::input::About {
            title: "twist".into(),
            description: String::new(),
            source: String::new(),
        },
        confidence,
        axis_length: None,
    };
    let text = description(&plan, "ROS 1 bag", &e, confidence);
    assert!(
        text.contains(
            "**/odom** (`nav_msgs/Odometry`, frame `base_link` (child_frame_id)): 50 messages."
        ),
        "{text}"
    );
    assert!(text.contains("- σ linear velocity (m/s): x "), "{text}");
    let scene = draw_log(&e, &settings, &text);
    scene.validate().unwrap();
    let ids: Vec<&str> = scene.plots.iter().map(|p| p.id.as_str()).collect();
    for id in [
        "sigma_angular_velocity",
        "sigma_linear_acceleration",
        "sigma_linear_velocity",
    ] {
        assert_eq!(ids.iter().filter(|i| **i == id).count(), 1, "{id}: {ids:?}");
    }
    // angular acceleration is "not provided" on the one topic that carries it: no plot.
    assert!(!ids.contains(&"sigma_angular_acceleration"), "{ids:?}");
    // The linear velocity plot: x, y, z of /odom's twist, /vo/twist (before it is not PSD) and
    // /wheel/twist, over the stamp; no shape in the world view for a velocity.
    let lines: Vec<_> = scene
        .series
        .iter()
        .filter(|s| s.plot.as_str() == "sigma_linear_velocity")
        .collect();
    assert_eq!(lines.len(), 9);
    let vo_x = lines.iter().find(|l| l.name == "/vo/twist σx").unwrap();
    assert_eq!(vo_x.points.len(), 10);
}

#[test]
fn the_report_keeps_an_odometrys_last_twist_sigma_after_evaluation() {
    // `twist_sigma_last` is read from the plan after the evaluation has moved the drawn
    // messages out: it was `null` on every log until the plan kept it.
    let test2 = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/robot_localization/test2.bag"
    );
    let report = json(&["report", test2, "--json"]);
    let twist = &report["topics"][0]["twist_sigma_last"];
    assert!(
        (twist["vx"].as_f64().unwrap() - 0.001f64.sqrt()).abs() < 1e-12,
        "{twist}"
    );
    assert!(twist["wx"].is_null(), "a 1e6 placeholder: {twist}");
}
