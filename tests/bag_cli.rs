//! Robot logs on the command line: `check`, `report --json`, `--topic`, `--every`, `--save`,
//! bundled logs, and errors that name the file.

use std::path::PathBuf;

mod posecov_cli;
use posecov_cli::run;

mod rrd;

const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-bagcli-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

#[test]
fn check_and_list_know_both_log_formats() {
    // The Jackal's odometry covariance never grows over 84 m: a defect, so `check` fails. The
    // sensor topics: the IMU and the odometry's twist (its placeholders and constancy notes).
    let (code, out, err) = run(&["check", TEST2]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        out.contains(": defects on 1 of 1 pose topic(s) and 0 of 2 sensor topic(s) (6121 messages"),
        "{out}"
    );
    assert!(
        err.contains(
            "topic /jackal_velocity_controller/odom, message 0 (stamp 47.584 s): constant"
        ),
        "{err}"
    );
    let (code, out, err) = run(&["check", TEST2, "--allow", "constant"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        out.contains(": ok (1 pose topic(s), 2 sensor topic(s), 6121 messages"),
        "{out}"
    );
    let (code, out, _) = run(&["list"]);
    assert_eq!(code, Some(0));
    assert!(
        out.contains("jackal_odometry") && out.contains("covariance_health"),
        "{out}"
    );
    let (code, out, err) = run(&["check", "covariance_health"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        out.starts_with(
            "covariance_health: defects on 1 of 3 pose topic(s) and 0 of 1 sensor topic(s) (70 messages"
        ),
        "{out}"
    );
}

#[test]
fn report_json_gives_the_health_to_scripts() {
    let (code, out, err) = run(&["report", "--json", TEST2]);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["format"], "ros1_bag");
    let odom = &v["topics"][0];
    assert_eq!(odom["name"], "/jackal_velocity_controller/odom");
    assert_eq!(odom["type"], "nav_msgs/Odometry");
    assert_eq!(odom["messages"], 3060);
    assert_eq!(odom["planar"], true);
    assert_eq!(
        (odom["position_dof"].as_u64(), odom["pose_dof"].as_u64()),
        (Some(2), Some(3))
    );
    assert_eq!(odom["health"]["placeholder"]["count"], 3060);
    assert_eq!(odom["health"]["placeholder"]["first_stamp_s"], 47.584);
    assert_eq!(v["sensors"][0]["type"], "sensor_msgs/Imu");
    assert_eq!(v["skipped"], serde_json::json!([]));
    let (_, out, _) = run(&[
        "report",
        "--json",
        "covariance_health",
        "--topic",
        "/amcl_pose",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let amcl = &v["topics"][0];
    for issue in [
        "all_zero",
        "unknown_marker",
        "placeholder_used_axis",
        "non_finite",
        "asymmetric",
        "not_psd",
        "bad_orientation",
        "undecodable",
    ] {
        assert_eq!(amcl["health"][issue]["count"], 1, "{issue}");
    }
    assert_eq!(amcl["stamps"]["from_log_time"], 1);
    assert_eq!(amcl["stamps"]["out_of_order"], 1);
    assert_eq!(amcl["drawn_invalid"], 7);
    assert_eq!(v["not_selected"][0], "/bare");
}

#[test]
fn save_writes_a_recording_and_every_thins_it() {
    let dir = scratch("save");
    let all = dir.join("all.rrd");
    let thin = dir.join("thin.rrd");
    let (code, _, err) = run(&[TEST2, "--save", all.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let (code, _, err) = run(&[TEST2, "--every", "500", "--save", thin.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let size = |p: &PathBuf| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    // Every 500th message drawn: a file well under a third of the size (the σ plots keep
    // every message's points in both).
    assert!(
        size(&thin) > 10_000 && size(&thin) * 3 < size(&all),
        "{} {}",
        size(&thin),
        size(&all)
    );
    // The Jackal's stamps are simulated time (47.580 s, its IMU's first σ plotted, … 108.764 s): the `stamp` timeline
    // holds durations, not 1970 dates, and every stamped chunk agrees.
    let bytes = std::fs::read(&thin).unwrap();
    let stamped: Vec<_> = rrd::recording_chunks(&bytes)
        .into_iter()
        .filter_map(|c| c.timelines().get(&"stamp".into()).cloned())
        .collect();
    assert!(!stamped.is_empty());
    for column in &stamped {
        assert_eq!(
            column.timeline().typ(),
            rerun::external::re_log_types::TimeType::DurationNs
        );
    }
    let first = stamped.iter().map(|c| c.time_range().min().as_i64()).min();
    assert_eq!(first, Some(47_580_000_000), "{first:?}");
    // Each plot's time axis spans the log (the viewer's default window would cut its start).
    let ranges = rrd::store_chunks(&bytes, rerun::StoreKind::Blueprint)
        .iter()
        .filter(|c| c.entity_path().to_string().ends_with("/TimeAxis"))
        .count();
    assert_eq!(
        ranges, 7,
        "σ of position, σ of rotation, trace; the IMU's σ orientation, angular velocity (with the odometry twist's), linear acceleration; the twist's σ linear velocity"
    );
    // And each plot's value axis is fitted to the data (a flat σ is not lost in ±1).
    let values = rrd::store_chunks(&bytes, rerun::StoreKind::Blueprint)
        .iter()
        .filter(|c| c.entity_path().to_string().ends_with("/ScalarAxis"))
        .count();
    assert_eq!(values, 7);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn errors_name_the_file_and_the_flag() {
    let (code, _, err) = run(&["check", TEST2, "--topic", "/odom"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("test2.bag: --topic /odom: no such topic; topics with a covariance in this log: /imu/data, /jackal_velocity_controller/odom"), "{err}");
    let (code, _, err) = run(&["check", "camera_on_robot", "--topic", "/odom"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains(
            "--topic /odom: applies to robot logs (ROS 1 bags, MCAP files, ROS 2 SQLite bags) only"
        ),
        "{err}"
    );
    // A flag for the other kind of input is refused once, by name, with what it is for.
    let (code, _, err) = run(&["camera_on_robot", "--every", "3", "--save", "x.rrd"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("--every 3: applies to robot logs (ROS 1 bags, MCAP files, ROS 2 SQLite bags) only (it draws every N-th message of a log); this input is a scenario"),
        "{err}"
    );
    let (code, _, err) = run(&["report", TEST2, "--block-samples", "4096"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("--block-samples 4096: applies to scenarios and pose graphs only")
            && err.contains("this input is a robot log"),
        "{err}"
    );
    let dir = scratch("bad");
    let fake = dir.join("fake.bag");
    std::fs::write(&fake, "not a bag\n").unwrap();
    let (code, _, err) = run(&["check", fake.to_str().unwrap()]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("fake.bag: the extension .bag says ROS 1 bag"),
        "{err}"
    );
    let cut = dir.join("cut.bag");
    let bytes = std::fs::read(TEST2).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    // A bag cut short keeps its whole chunks (read without the index it lost) and says where
    // it stops: drawn and reported, and `check` fails on it.
    let (code, out, _) = run(&["report", cut.to_str().unwrap()]);
    assert_eq!(code, Some(0));
    assert!(
        out.contains("The log stops early") && out.contains("outside the file"),
        "{out}"
    );
    let (code, _, err) = run(&["check", cut.to_str().unwrap()]);
    assert_eq!(code, Some(1));
    assert!(
        err.contains("cut.bag") && err.contains("the log stops early"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
