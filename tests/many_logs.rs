//! Many logs at once: `posecov report DIR_OR_FILES… --json` (JSON Lines, in parallel) and
//! `posecov check FILES…` (one line per file, the worst exit code).

use std::path::{Path, PathBuf};

mod posecov_cli;
use posecov_cli::run;

fn data(file: &str) -> String {
    format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"))
}

/// A scratch directory holding copies of `files` (as `name`), and a file that is no log.
fn fleet(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-many-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(dir.join("sub")).expect("scratch dir");
    for (from, to) in files {
        std::fs::copy(data(from), dir.join(to)).expect("copy a log");
    }
    std::fs::write(dir.join("notes.txt"), "not a log").expect("write");
    // A log in a subdirectory is not read (a directory means the logs in it).
    std::fs::copy(data("mcap/health_cases.mcap"), dir.join("sub/deep.mcap")).expect("copy");
    dir
}

/// Each line of JSON Lines: one compact object, by its `scenario`.
fn lines_by_input(out: &str) -> Vec<(String, serde_json::Value)> {
    let mut lines: Vec<(String, serde_json::Value)> = out
        .lines()
        .map(|line| {
            let value: serde_json::Value = serde_json::from_str(line).expect("one JSON object");
            (
                value["scenario"]
                    .as_str()
                    .expect("names its input")
                    .to_owned(),
                value,
            )
        })
        .collect();
    lines.sort_by(|a, b| a.0.cmp(&b.0));
    lines
}

fn file_name(path: &str) -> &str {
    Path::new(path)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap()
}

#[test]
fn a_directory_of_logs_reports_json_lines_one_per_log() {
    let dir = fleet(
        "report",
        &[
            ("robot_localization/test2.bag", "a.bag"),
            ("mcap/health_cases.mcap", "b.MCAP"),
        ],
    );
    let (code, out, err) = run(&["report", dir.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(out.lines().count(), 2, "{out}");
    let lines = lines_by_input(&out);
    let names: Vec<&str> = lines.iter().map(|(n, _)| file_name(n)).collect();
    assert_eq!(names, ["a.bag", "b.MCAP"]);
    for (_, report) in &lines {
        assert_eq!(report["schema_version"], 2);
    }
    // The same numbers as one log's report, which stays one indented object.
    let (_, one, _) = run(&["report", &data("robot_localization/test2.bag"), "--json"]);
    assert!(one.starts_with("{\n"), "{one}");
    let one: serde_json::Value = serde_json::from_str(&one).unwrap();
    assert_eq!(lines[0].1["topics"], one["topics"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn several_files_are_json_lines_and_a_failing_one_is_its_own_line() {
    let missing = data("no_such.bag");
    let (code, out, _) = run(&[
        "report",
        &data("mcap/health_cases.mcap"),
        &missing,
        "covariance_health",
        "--json",
    ]);
    // Defects are reported, not failures; the unreadable file is the worst: 2.
    assert_eq!(code, Some(2));
    let lines = lines_by_input(&out);
    assert_eq!(lines.len(), 3, "{out}");
    let failed: Vec<&serde_json::Value> = lines
        .iter()
        .filter(|(_, v)| v.get("error").is_some())
        .map(|(_, v)| v)
        .collect();
    assert_eq!(failed.len(), 1);
    assert_eq!(failed[0]["scenario"], missing.as_str());
    assert_eq!(failed[0]["error"]["exit_code"], 2);
}

#[test]
fn a_directory_without_logs_is_refused() {
    let dir = std::env::temp_dir().join(format!("posecov-many-empty-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "not a log").unwrap();
    let (code, out, err) = run(&["report", dir.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains(
            "no robot log (.bag, .mcap, .db3, or a ROS 2 bag directory) in this directory"
        ),
        "{err}"
    );
    let json: serde_json::Value = serde_json::from_str(&out).expect("the error as JSON");
    assert_eq!(json["error"]["exit_code"], 2);
    let (code, _, _) = run(&["check", dir.to_str().unwrap()]);
    assert_eq!(code, Some(2));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn check_on_many_files_prints_a_line_each_and_exits_with_the_worst() {
    let test2 = data("robot_localization/test2.bag");
    let health = data("mcap/health_cases.mcap");
    // test2's only defect is its constant covariance: allowed, it passes.
    let (code, out, err) = run(&["check", &test2, &health, "--allow", "constant"]);
    assert_eq!(code, Some(1), "{err}");
    let mut lines: Vec<&str> = out.lines().collect();
    lines.sort_unstable();
    assert_eq!(lines.len(), 2, "{out}");
    assert!(lines[0].starts_with(&format!("{health}: defects")), "{out}");
    assert!(lines[1].starts_with(&format!("{test2}: ok (")), "{out}");
    assert!(
        err.contains(&format!("{health}: topic /amcl_pose, message 1")),
        "{err}"
    );
    // An unreadable file is worse than a defect: 2, and it gets its line.
    let missing = data("no_such.bag");
    let (code, out, _) = run(&["check", &test2, &health, &missing]);
    assert_eq!(code, Some(2));
    assert_eq!(out.lines().count(), 3, "{out}");
    assert!(
        out.contains(&format!("{missing}: error: cannot read input")),
        "{out}"
    );
    // Every file passing: 0.
    let (code, out, _) = run(&["check", &test2, "jackal_odometry", "--allow", "constant"]);
    assert_eq!(code, Some(0), "{out}");
    assert_eq!(out.lines().count(), 2);
}
