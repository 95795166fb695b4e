//! The `posecov` command line: every scenario error exits non-zero with a message naming
//! file:line:column and the field; `list`, `report --json`, `check` and `--watch` work.

use std::io::Read as _;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_posecov");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-cli-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

const GOOD: &str = include_str!("../assets/scenarios/camera_on_robot.toml");

/// Runs `posecov check FILE` on `text`; returns (exit code, stderr).
fn check_text(text: &str) -> (Option<i32>, String) {
    let dir = scratch("check");
    let file = dir.join("s.toml");
    std::fs::write(&file, text).expect("write");
    let out = Command::new(BIN)
        .arg("check")
        .arg(&file)
        .output()
        .expect("run posecov");
    std::fs::remove_dir_all(&dir).ok();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .expect("needle")
        + 1
}

#[path = "common/ports.rs"]
mod ports;

#[test]
fn scenario_errors_exit_1_with_file_line_column_and_field() {
    let cases: [(&str, String, &str, &str); 6] = [
        (
            "bad toml",
            GOOD.replace("group = \"se2\"", "group = \"se2"),
            "group = ",
            "toml",
        ),
        (
            "unknown key",
            GOOD.replace("cov = { std_deg", "covariance = { std_deg"),
            "covariance = {",
            "unknown field `covariance`",
        ),
        (
            "non-PSD",
            GOOD.replace(
                "cov = { std_deg = [0.05, 0.05, 20.0] }",
                "cov = { matrix = [[1, 2, 0], [2, 1, 0], [0, 0, 1]] }",
            ),
            "cov = { matrix",
            "not positive semi-definite",
        ),
        (
            "wrong length",
            GOOD.replace("std_deg = [0.05, 0.05, 20.0]", "std_deg = [0.05, 20.0]"),
            "std_deg = [0.05, 20.0]",
            "std_deg needs 3 numbers",
        ),
        (
            "NaN",
            GOOD.replace(
                "std_deg = [0.05, 0.05, 20.0]",
                "std_deg = [0.05, nan, 20.0]",
            ),
            "0.05, nan",
            "is NaN",
        ),
        (
            "unknown operation",
            GOOD.replace("kind = \"change_frame_right\"", "kind = \"change_frame\""),
            "change_frame\"",
            "unknown operation `change_frame`",
        ),
    ];
    for (what, text, needle, message) in cases {
        let (code, stderr) = check_text(&text);
        assert_eq!(code, Some(1), "{what}: {stderr}");
        let place = format!("s.toml:{}:", line_of(&text, needle));
        assert!(
            stderr.contains(&place),
            "{what}: expected {place} in {stderr}"
        );
        assert!(
            stderr.contains(message),
            "{what}: expected {message:?} in {stderr}"
        );
    }
}

#[test]
fn missing_file_and_unknown_name() {
    let out = Command::new(BIN)
        .args(["check", "/no/such/scenario.toml"])
        .output()
        .expect("run");
    // Cannot process (the exit-code table): 2.
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("/no/such/scenario.toml: cannot read input"),
        "{stderr}"
    );
}

#[test]
fn list_names_every_bundled_scenario() {
    let out = Command::new(BIN).arg("list").output().expect("run");
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    for b in posecov::input::scenario::bundled::BUNDLED {
        assert!(
            stdout.lines().any(|l| l.starts_with(b.name)),
            "{} missing",
            b.name
        );
    }
}

#[test]
fn report_json_carries_every_result_and_its_error() {
    let out = Command::new(BIN)
        .args([
            "report",
            "na568_se2_odometry",
            "--json",
            "--samples",
            "300",
            "--seed",
            "5",
        ])
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(json["meta"]["seed"], 5);
    assert_eq!(json["meta"]["samples"], 300);
    let results = json["results"].as_array().expect("results");
    let last = results
        .iter()
        .find(|r| r["label"] == "robot@7" && r["method"] == "first_order")
        .expect("step 7, first order");
    assert!((last["covariance"][1][1].as_f64().unwrap() - 0.358141).abs() < 1e-6);
    assert!(last["relative_error_vs_monte_carlo"].as_f64().unwrap() < 0.2);
}

/// `--watch` re-evaluates on change, reports a broken file without dying, and recovers.
#[test]
fn watch_rewrites_on_change_and_survives_errors() {
    let dir = scratch("watch");
    let scenario = dir.join("s.toml");
    let rrd = dir.join("out.rrd");
    std::fs::write(&scenario, GOOD.replace("samples = 4000", "samples = 50")).expect("write");
    let mut child = Command::new(BIN)
        .arg(&scenario)
        .args(["--watch", "--save"])
        .arg(&rrd)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn posecov --watch");
    let wait_for = |pred: &dyn Fn() -> bool| {
        let start = Instant::now();
        while !pred() {
            assert!(start.elapsed() < Duration::from_secs(60), "timed out");
            std::thread::sleep(Duration::from_millis(100));
        }
    };
    wait_for(&|| rrd.exists());
    let first = std::fs::metadata(&rrd)
        .and_then(|m| m.modified())
        .expect("mtime");
    // A broken edit: reported, the process keeps running.
    std::thread::sleep(Duration::from_millis(1100));
    std::fs::write(&scenario, "[scenario]\ntitle = 'broken'\n").expect("write");
    std::thread::sleep(Duration::from_millis(1500));
    assert!(
        child.try_wait().expect("poll").is_none(),
        "watch died on a bad file"
    );
    // A good edit: the recording is rewritten.
    std::fs::write(&scenario, GOOD.replace("samples = 4000", "samples = 60")).expect("write");
    wait_for(&|| {
        std::fs::metadata(&rrd)
            .and_then(|m| m.modified())
            .is_ok_and(|t| t > first)
    });
    child.kill().ok();
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut stderr)
        .ok();
    child.wait().ok();
    assert!(stderr.contains("missing field `group`"), "{stderr}");
    assert!(stderr.contains("[1] recorded"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// At most one place for the recording, named as the user typed it; live mode takes the
/// evaluation flags but not the robot-log ones. Nothing is written when the flags conflict.
#[test]
fn conflicting_sinks_are_refused_by_name() {
    let dir = scratch("sinks");
    let rrd = dir.join("x.rrd");
    let rrd_arg = rrd.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (
            &["camera_on_robot", "--save", rrd_arg, "--serve"],
            "'--save <FILE.rrd>' cannot be used with '--serve'",
        ),
        (
            &["camera_on_robot", "--stdout", "--connect"],
            "'--stdout' cannot be used with '--connect [<URL>]'",
        ),
        (
            &["camera_on_robot", "--spawn", "--serve"],
            "'--spawn' cannot be used with '--serve'",
        ),
        (
            &["camera_on_robot", "--save", rrd_arg, "--stdout"],
            "'--save <FILE.rrd>' cannot be used with '--stdout'",
        ),
        (
            &["live", "camera_on_robot", "--spawn", "--connect"],
            "'--spawn' cannot be used with '--connect [<URL>]'",
        ),
        (
            &["live", "camera_on_robot", "--topic", "/odom"],
            "unexpected argument '--topic'",
        ),
    ];
    for (args, expected) in cases {
        let out = Command::new(BIN).args(args).output().expect("run posecov");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!rrd.exists(), "{args:?} wrote a recording");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A control-page port in use stops `live` with the flag, the address and a way out.
#[test]
fn live_refuses_a_taken_page_port_with_a_way_out() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let page = taken.local_addr().expect("addr").port();
    let out = Command::new(BIN)
        .args(["live", "camera_on_robot", "--serve", "--serve-seconds", "5"])
        .args(["--bind", &format!("127.0.0.1:{page}")])
        .output()
        .expect("run posecov live");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(&format!("--bind 127.0.0.1:{page}: "))
            && stderr.contains("`--bind 127.0.0.1:0` for any free one"),
        "{stderr}"
    );
}

/// A served viewer's port in use is refused up front, naming its flag, before a URL is
/// printed (the SDK's gRPC server would only fail later, on its own thread).
#[test]
fn serve_refuses_a_taken_viewer_port_up_front() {
    let free = ports::free_port;
    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let busy = taken.local_addr().expect("addr").port();
    for (flag, other) in [("--grpc-port", "--web-port"), ("--web-port", "--grpc-port")] {
        let out = Command::new(BIN)
            .args(["camera_on_robot", "--serve", "--serve-seconds", "30"])
            .args([flag, &busy.to_string(), other, &free().to_string()])
            .output()
            .expect("run posecov --serve");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag}: {stderr}");
        assert!(
            stderr.contains(&format!("{flag} {busy}: 127.0.0.1:{busy} cannot be served")),
            "{flag}: {stderr}"
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(!stdout.contains("Web viewer"), "{flag}: {stdout}");
    }
}

/// `posecov NAME --stdout | head -c 10`: a reader that closes the pipe early ends the run at
/// once, quietly, with exit code 0 (as ripgrep does), in every one of 100 runs.
#[test]
fn a_closed_stdout_ends_the_run_quietly() {
    for run in 0..100 {
        let mut child = Command::new(BIN)
            .args(["camera_on_robot", "--stdout", "--samples", "50"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn posecov --stdout");
        let mut stdout = child.stdout.take().expect("stdout");
        let mut head = [0u8; 10];
        stdout.read_exact(&mut head).expect("the first 10 bytes");
        drop(stdout);
        let start = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().expect("poll") {
                break status;
            }
            if start.elapsed() > Duration::from_secs(60) {
                child.kill().ok();
                panic!("run {run}: still running 60 s after its reader closed stdout");
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        let mut stderr = String::new();
        child
            .stderr
            .take()
            .expect("stderr")
            .read_to_string(&mut stderr)
            .ok();
        assert_eq!(status.code(), Some(0), "run {run}: {stderr}");
        assert!(stderr.is_empty(), "run {run}: not quiet: {stderr}");
    }
}
