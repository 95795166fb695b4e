//! NEES of a log against a reference (issue 20, item 2), on logs written here
//! (`common::logs`): a consistent topic falls inside its ANEES band, one publishing a tenth of
//! its covariance is overconfident (ANEES ≈ 60), the body-local reading of the same data is
//! far outside; the reference as a topic, as `tf:CHILD` and as a TUM file gives the same
//! numbers; alignment; every refusal in the user's words.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::logs::{AFTER, BEFORE, ESTIMATES, nees_log, truth_tum};
use posecov::lie::{LieGroup, Se3, So3};

const BIN: &str = env!("CARGO_BIN_EXE_posecov");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-nees-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The log and the TUM truth in a fresh directory.
fn data(name: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    let log = dir.join("nees.mcap");
    std::fs::write(&log, nees_log(7)).unwrap();
    let tum = dir.join("truth.tum");
    std::fs::write(&tum, truth_tum(&Se3::identity())).unwrap();
    (log, tum)
}

fn run_in(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run posecov");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn report(log: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["report", log.to_str().unwrap(), "--json"];
    args.extend(extra);
    let (code, out, err) = run_in(log.parent().unwrap(), &args);
    assert_eq!(code, Some(0), "{err}");
    serde_json::from_str(&out).expect("json")
}

fn topic<'a>(json: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    json["topics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == name)
        .unwrap_or_else(|| panic!("no topic {name}"))
}

fn anees(c: &serde_json::Value) -> (f64, f64, f64) {
    let band = c["anees_band"].as_array().unwrap();
    (
        c["anees"].as_f64().unwrap(),
        band[0].as_f64().unwrap(),
        band[1].as_f64().unwrap(),
    )
}

#[test]
fn a_consistent_topic_is_inside_its_band_and_a_tenth_of_its_covariance_is_overconfident() {
    let (log, _) = data("topic");
    let json = report(&log, &["--reference", "/ground_truth"]);
    let ekf = &topic(&json, "/ekf")["consistency"];
    assert_eq!(ekf["reference"], "topic:/ground_truth");
    assert_eq!(
        (ekf["reading"].as_str(), ekf["dof"].as_u64()),
        (Some("tf2"), Some(6))
    );
    let n = ESTIMATES as u64 - BEFORE - AFTER;
    assert_eq!(ekf["messages"], n);
    assert_eq!(ekf["skipped"]["before_reference"], BEFORE);
    assert_eq!(ekf["skipped"]["after_reference"], AFTER);
    let (value, low, high) = anees(ekf);
    assert!(
        low < value && value < high,
        "ANEES {value} outside [{low}, {high}]"
    );
    // χ²_{6N} is nearly normal: 6 ± 1.96 √(2 · 6N) / N.
    let half = 1.96 * (12.0 * n as f64).sqrt() / n as f64;
    assert!(
        (low - (6.0 - half)).abs() < 0.01 && (high - (6.0 + half)).abs() < 0.01,
        "band for {n} × 6: {low} {high}"
    );
    assert_eq!(ekf["verdict"], "consistent");
    let inside = ekf["inside_95"].as_f64().unwrap();
    assert!((inside - 0.95).abs() < 0.03, "{inside}");
    // Position and orientation alone: d = 3 each, inside their bands too.
    for part in ["position", "orientation"] {
        let a = &ekf[part];
        assert_eq!(a["dof"], 3);
        let v = a["value"].as_f64().unwrap();
        assert!(
            v > a["band"][0].as_f64().unwrap() && v < a["band"][1].as_f64().unwrap(),
            "{part} {v}"
        );
    }
    // The series is thinned as the drawn messages are.
    let series = ekf["nees"]["values"].as_array().unwrap().len();
    let drawn = topic(&json, "/ekf")["drawn"].as_u64().unwrap() as usize;
    assert!(series > 100 && series <= drawn, "{series} of {drawn}");

    let over = &topic(&json, "/ekf_overconfident")["consistency"];
    let (value, _, high) = anees(over);
    assert!(
        (value / 60.0 - 1.0).abs() < 0.12,
        "overconfident ANEES {value}"
    );
    assert!(value > high);
    assert_eq!(over["verdict"], "overconfident");
    // The reference topic itself is not an estimate.
    assert!(topic(&json, "/ekf")["consistency"].is_object());
    assert_eq!(
        json["topics"].as_array().unwrap().len(),
        2,
        "PoseStamped is no estimate topic"
    );
}

#[test]
fn the_body_reading_of_the_same_data_is_far_outside_the_band() {
    let (log, _) = data("body");
    let json = report(
        &log,
        &["--reference", "/ground_truth", "--ros-reading", "body"],
    );
    let ekf = &topic(&json, "/ekf")["consistency"];
    assert_eq!(ekf["reading"], "body");
    let (value, _, high) = anees(ekf);
    assert!(
        value > 2.0 * high,
        "body reading ANEES {value}, band top {high}"
    );
    assert_ne!(ekf["verdict"], "consistent");
}

#[test]
fn tf_and_tum_references_give_the_topic_s_numbers() {
    let (log, tum) = data("same");
    let by_topic = report(&log, &["--reference", "topic:/ground_truth"]);
    let by_tf = report(&log, &["--reference", "tf:base_link"]);
    let by_file = report(&log, &["--reference", tum.to_str().unwrap()]);
    let a = anees(&topic(&by_topic, "/ekf")["consistency"]).0;
    let b = anees(&topic(&by_tf, "/ekf")["consistency"]).0;
    let c = anees(&topic(&by_file, "/ekf")["consistency"]).0;
    // POSECOV_NEES_OUT=DIR keeps the log and its TUM truth there (the picture in docs/guide/logs.md).
    if let Some(out) = std::env::var_os("POSECOV_NEES_OUT") {
        let out = PathBuf::from(out);
        std::fs::create_dir_all(&out).unwrap();
        std::fs::copy(&log, out.join("nees.mcap")).unwrap();
        std::fs::copy(&tum, out.join("truth.tum")).unwrap();
    }
    assert_eq!(
        topic(&by_tf, "/ekf")["consistency"]["reference"],
        "tf:base_link"
    );
    assert!(
        topic(&by_file, "/ekf")["consistency"]["reference"]
            .as_str()
            .unwrap()
            .starts_with("file:")
    );
    assert!((a - b).abs() < 1e-9 * a, "{a} {b}");
    // The TUM file rounds the truth to 1e-12 m and 1e-15.
    assert!((a - c).abs() < 1e-6 * a, "{a} {c}");
}

#[test]
fn alignment_recovers_a_reference_in_another_frame() {
    let (log, _) = data("align");
    let dir = log.parent().unwrap();
    let world_from_map = Se3::from_parts(
        nalgebra::Vector3::new(5.0, -3.0, 1.0),
        So3::from_rpy(0.1, -0.2, 1.2),
    );
    let moved = dir.join("moved.tum");
    std::fs::write(&moved, truth_tum(&world_from_map)).unwrap();
    let path = moved.to_str().unwrap();
    let none = anees(&topic(&report(&log, &["--reference", path]), "/ekf")["consistency"]).0;
    let json = report(&log, &["--reference", path, "--align", "se3"]);
    let c = &topic(&json, "/ekf")["consistency"];
    assert_eq!(c["align"], "se3");
    let (se3, low, high) = anees(c);
    assert!(none > 1000.0 * high, "unaligned {none}");
    assert!(
        se3 > 0.9 * low && se3 < 1.1 * high,
        "aligned {se3} vs [{low}, {high}]"
    );
    let t = &c["alignment"]["translation"];
    // T maps the world frame back onto the map: T ≈ world_from_map⁻¹.
    let expect = world_from_map.inverse();
    for i in 0..3 {
        assert!(
            (t[i].as_f64().unwrap() - expect.translation()[i]).abs() < 0.05,
            "{t} vs {:?}",
            expect.translation()
        );
    }
    let first = anees(
        &topic(
            &report(&log, &["--reference", path, "--align", "first"]),
            "/ekf",
        )["consistency"],
    )
    .0;
    assert!(
        first < none / 100.0,
        "first-pose alignment {first} vs {none}"
    );
}

#[test]
fn refusals_say_what_to_write() {
    let (log, tum) = data("refuse");
    let dir = log.parent().unwrap();
    let log_arg = log.to_str().unwrap();
    let fails = |args: &[&str]| {
        let (code, _, err) = run_in(dir, args);
        assert_ne!(code, Some(0), "{args:?}");
        err
    };
    // A bare value that is neither a topic nor a file.
    let e = fails(&["report", log_arg, "--reference", "/nothing"]);
    assert!(e.contains("--reference /nothing: neither a topic of this log nor a file; say `topic:NAME` or `file:PATH`"), "{e}");
    assert!(e.contains("/ground_truth"), "{e}");
    // /tf is read by child frame.
    let e = fails(&["report", log_arg, "--reference", "/tf"]);
    assert!(
        e.contains(
            "--reference /tf: its messages are tf2_msgs/msg/TFMessage; a reference topic is"
        ),
        "{e}"
    );
    assert!(e.contains("say `tf:CHILD`"), "{e}");
    assert!(tum.is_file());
    let e = fails(&["report", log_arg, "--reference", "tf:odom"]);
    assert!(
        e.contains("no transform in /tf has child_frame_id odom"),
        "{e}"
    );
    // A bad TUM line: file, line, column, field and value.
    let bad = dir.join("bad.tum");
    std::fs::write(&bad, "100.0 1 2 3 0 0 0 1\n100.01 1 2 x 0 0 0 1\n").unwrap();
    let e = fails(&["report", log_arg, "--reference", bad.to_str().unwrap()]);
    assert!(e.contains("bad.tum:2:12: tz: `x` is not a number"), "{e}");
    // No overlap.
    let late = dir.join("late.tum");
    std::fs::write(&late, "1000.0 1 2 3 0 0 0 1\n1001.0 1 2 3 0 0 0 1\n").unwrap();
    let e = fails(&["report", log_arg, "--reference", late.to_str().unwrap()]);
    assert!(e.contains("no estimate message could be compared with the reference (spanning 1000.000 s … 1001.000 s)"), "{e}");
    assert!(
        e.contains("/ekf: 99.804 s … 160.204 s, 605 before it"),
        "{e}"
    );
    // Scenarios refuse it through the kind-only flag table.
    let e = fails(&["report", "camera_on_robot", "--reference", "/ground_truth"]);
    assert!(
        e.starts_with("error: --reference /ground_truth: applies to robot logs"),
        "{e}"
    );
    let e = fails(&["report", log_arg, "--align", "se3"]);
    assert!(e.contains("--align se3"), "{e}");
}

#[test]
fn a_value_that_is_both_a_topic_and_a_file_is_refused() {
    let (log, tum) = data("both");
    let dir = log.parent().unwrap();
    // A log whose truth topic is named like the file next to it.
    let renamed = dir.join("renamed.mcap");
    std::fs::write(&renamed, common::logs::nees_log_named(7, "ground_truth_")).unwrap();
    std::fs::copy(&tum, dir.join("ground_truth_")).unwrap();
    let (code, _, err) = run_in(
        dir,
        &[
            "report",
            renamed.to_str().unwrap(),
            "--reference",
            "ground_truth_",
        ],
    );
    assert_ne!(code, Some(0));
    assert!(err.contains("--reference ground_truth_: both a topic of this log and a file; say `topic:ground_truth_` or `file:ground_truth_`"), "{err}");
    let json = report(&renamed, &["--reference", "topic:ground_truth_"]);
    assert_eq!(
        topic(&json, "/ekf")["consistency"]["reference"],
        "topic:ground_truth_"
    );
    let json = report(&renamed, &["--reference", "file:ground_truth_"]);
    assert_eq!(
        topic(&json, "/ekf")["consistency"]["reference"],
        "file:ground_truth_"
    );
}
