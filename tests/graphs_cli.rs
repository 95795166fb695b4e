//! `posecov` on pose graphs: `report --json`, `check`, `list` and `--save` on the GTSAM files,
//! and errors that name the file and line.

use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_posecov");
const FILES: &[&str] = &[
    "tests/data/gtsam/pose2example.txt",
    "tests/data/gtsam/noisyToyGraph.txt",
    "tests/data/gtsam/pose3example.txt",
    "tests/data/gtsam/pose3example-offdiagonal.txt",
];

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(BIN).args(args).output().expect("run posecov");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn check_reads_every_graph() {
    for file in FILES {
        let (ok, stdout, stderr) = run(&["check", file]);
        assert!(ok, "{file}: {stderr}");
        assert!(stdout.starts_with(&format!("{file}: ok (")), "{stdout}");
    }
}

#[test]
fn report_json_gives_the_chain_and_the_loop_closures() {
    let (ok, stdout, stderr) = run(&[
        "report",
        "tests/data/gtsam/pose2example.txt",
        "--json",
        "--samples",
        "2000",
    ]);
    assert!(ok, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).expect("JSON");
    assert_eq!(json["format"], "graph");
    assert_eq!(json["meta"]["group"], "SE(2)");
    assert_eq!(json["input"]["vertices"], 11);
    assert_eq!(json["input"]["edges"], 12);
    assert_eq!(json["input"]["chain_edges"], 10);
    assert_eq!(json["input"]["loop_closures"], 2);
    let results = json["results"].as_array().expect("results");
    let labels: Vec<&str> = results.iter().filter_map(|r| r["label"].as_str()).collect();
    for label in [
        "odometry_chain@0",
        "odometry_chain@10",
        "v9_via_v5",
        "v10_via_v3",
    ] {
        assert!(labels.contains(&label), "{label} missing from {labels:?}");
    }
    // The first chain step is edge 0 → 1: Σ = Ω⁻¹ with Ω = diag(44.72136, 44.72136, 30.901699).
    let step1 = results
        .iter()
        .find(|r| r["label"] == "odometry_chain@1" && r["method"] == "first_order")
        .expect("step 1");
    let cov = &step1["covariance"];
    assert!((cov[0][0].as_f64().expect("number") - 1.0 / 44.721360).abs() < 1e-12);
    assert!((cov[2][2].as_f64().expect("number") - 1.0 / 30.901699).abs() < 1e-12);
}

#[test]
fn list_shows_the_bundled_graphs_and_they_run() {
    let (ok, stdout, _) = run(&["list"]);
    assert!(ok);
    assert!(
        stdout.contains("g2o / GTSAM pose graphs (.g2o, .txt, .graph):"),
        "{stdout}"
    );
    for name in ["gtsam_pose2example", "gtsam_pose3example"] {
        assert!(stdout.lines().any(|l| l.starts_with(name)), "{stdout}");
        let (ok, stdout, stderr) = run(&["check", name]);
        assert!(ok && stdout.starts_with(&format!("{name}: ok")), "{stderr}");
    }
}

#[test]
fn save_writes_a_recording_of_a_graph() {
    let path = std::env::temp_dir().join(format!("posecov-graph-{}.rrd", std::process::id()));
    let (ok, _, stderr) = run(&[
        "tests/data/gtsam/pose3example.txt",
        "--samples",
        "500",
        "--save",
        path.to_str().expect("utf-8"),
    ]);
    assert!(ok, "{stderr}");
    assert!(std::fs::metadata(&path).expect("written").len() > 1000);
    std::fs::remove_file(&path).ok();
}

#[test]
fn a_bad_graph_exits_1_naming_file_line_and_field() {
    let dir = std::env::temp_dir().join(format!("posecov-graph-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let file = dir.join("bad.g2o");
    std::fs::write(
        &file,
        "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 -1\n",
    )
    .expect("write");
    let out = Command::new(BIN)
        .arg("check")
        .arg(&file)
        .output()
        .expect("run");
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let want = format!(
        "error: {}:3:20: EDGE_SE2 0 1 information: the information matrix",
        file.display()
    );
    assert!(stderr.starts_with(&want), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn joint_flag_reports_the_pair_and_refuses_what_is_not_a_pair_of_vertices() {
    let file = "tests/data/gtsam/pose2example.txt";
    let (ok, stdout, stderr) = run(&[
        "report",
        file,
        "--json",
        "--samples",
        "64",
        "--joint",
        "3,10",
    ]);
    assert!(ok, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).expect("JSON");
    assert_eq!(json["optimized"]["joints"][0]["b"], 10);
    for (value, expected) in [
        ("3", "expected two vertex ids separated by a comma"),
        ("3,x", "expected two vertex ids A,B"),
        (
            "3,12",
            "--joint 3,12: this pose graph has no vertex 12 (11 vertices, ids 0 ..= 10)",
        ),
    ] {
        let (ok, _, stderr) = run(&["report", file, "--json", "--joint", value]);
        assert!(!ok && stderr.contains(expected), "{value}: {stderr}");
    }
    let (ok, _, stderr) = run(&["report", "camera_on_robot", "--json", "--joint", "1,2"]);
    assert!(
        !ok && stderr.contains("--joint 1,2: applies to pose graphs"),
        "{stderr}"
    );
}
