//! The scene → Rerun path: bytes, deterministic content, valid files, the CLI's sinks.
//!
//! Determinism is checked on decoded content (entity paths, timelines, component arrays),
//! ignoring row/chunk ids and the blueprint, which Rerun randomises.

use std::io::{Read as _, Write as _};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use posecov::app::{Overrides, load, pipeline};
use posecov::scene::{Color, ItemKind, PointCloud, Scene, SceneItem, Timing};
use posecov::sink::{
    LogOutcome, RecordingIds, Sink, SinkError, log_scene_cancellable, open_stream,
    scene_to_rrd_bytes,
};
mod rrd;

use rerun::log::Chunk;
use rrd::{assert_same_content, recording_chunks, rerun_cli};

const BIN: &str = env!("CARGO_BIN_EXE_posecov");

/// The scenario the CLI tests run (small, fast, with a cloud, a banana and an ellipse).
const SCENARIO: &str = "camera_on_robot";

fn ids(seed: u64) -> RecordingIds {
    RecordingIds::for_scenario(SCENARIO, seed)
}

fn small_demo(seed: u64) -> Scene {
    let loaded = load(SCENARIO).expect("bundled");
    let overrides = Overrides {
        seed: Some(seed),
        samples: Some(60),
        ..Default::default()
    };
    pipeline(&loaded, &overrides, None).expect("evaluates").1
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-test-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// `posecov SCENARIO ARGS --save FILE` succeeds.
fn save_with(args: &[&str], file: &std::path::Path) {
    let out = Command::new(BIN)
        .arg(SCENARIO)
        .args(args)
        .arg("--save")
        .arg(file)
        .output()
        .expect("run posecov");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `rerun rrd verify FILE` passes (when the rerun CLI is available; CI always has it).
fn assert_verifies(file: &std::path::Path) {
    if let Some(cli) = rerun_cli() {
        let out = Command::new(cli)
            .args(["rrd", "verify"])
            .arg(file)
            .output()
            .expect("run rerun-cli");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[path = "common/ports.rs"]
mod ports;
use ports::free_port;

#[test]
fn memory_sink_produces_a_decodable_recording_with_every_entity() {
    let scene = small_demo(1);
    let bytes = scene_to_rrd_bytes(&scene, &ids(1)).expect("logged");
    assert!(bytes.len() > 10_000, "{} bytes", bytes.len());
    let chunks = recording_chunks(&bytes);
    let paths: Vec<String> = chunks.iter().map(|c| c.entity_path().to_string()).collect();
    for item in &scene.items {
        assert!(
            paths.contains(&format!("/{}", item.path)),
            "{} missing",
            item.path
        );
    }
    assert!(paths.contains(&"/world".to_owned()), "view coordinates");
    assert!(paths.contains(&"/description".to_owned()), "text panel");
    // One chunk per item, view coordinates, description and name, the legend's three
    // entities (bars, dots, axes), plus two per series.
    assert_eq!(chunks.len(), scene.items.len() + 6 + 2 * scene.series.len());
    // No wall clock anywhere: the only timeline is `step`.
    for chunk in &chunks {
        for name in chunk.timelines().keys() {
            assert_eq!(name.as_str(), "step", "{}", chunk.entity_path());
        }
    }
}

#[test]
fn same_seed_same_content_other_seed_other_content() {
    let a = scene_to_rrd_bytes(&small_demo(5), &ids(5)).expect("logged");
    let b = scene_to_rrd_bytes(&small_demo(5), &ids(5)).expect("logged");
    assert_same_content(&a, &b);
    let c = scene_to_rrd_bytes(&small_demo(6), &ids(6)).expect("logged");
    let differs = recording_chunks(&a)
        .iter()
        .zip(&recording_chunks(&c))
        .any(|(x, y)| Chunk::ensure_similar(x, y).is_err());
    assert!(differs, "a different seed must change the cloud");
}

#[test]
fn nan_is_rejected_before_anything_is_logged() {
    let mut scene = small_demo(1);
    scene.push(SceneItem::new(
        "world/bad",
        Timing::Step(2),
        ItemKind::Points(PointCloud {
            positions: vec![[0.0, f64::NAN, 0.0]],
            color: Color::rgb(1, 1, 1),
            radius: 0.1,
        }),
    ));
    let (rec, guard) = open_stream(&Sink::Memory, &ids(1), &scene).expect("memory sink");
    let err = log_scene_cancellable(&rec, &scene, &AtomicBool::new(false));
    assert!(matches!(err, Err(SinkError::Scene(_))), "{err:?}");
    let bytes = guard.finish(rec).expect("finish").expect("memory bytes");
    assert!(recording_chunks(&bytes).is_empty(), "nothing logged");
}

#[test]
fn a_cancelled_recording_is_still_a_valid_prefix() {
    let scene = small_demo(1);
    let (rec, guard) = open_stream(&Sink::Memory, &ids(1), &scene).expect("memory sink");
    let outcome = log_scene_cancellable(&rec, &scene, &AtomicBool::new(true));
    assert_eq!(
        outcome.ok(),
        Some(LogOutcome::Cancelled { next_step: None })
    );
    let bytes = guard.finish(rec).expect("finish").expect("memory bytes");
    // Name, view coordinates, description and the legend's three entities were logged before
    // the first item.
    assert_eq!(recording_chunks(&bytes).len(), 6);
}

#[test]
fn an_interrupted_save_is_a_valid_file_under_its_name() {
    let dir = scratch_dir("cancel");
    let file = dir.join("cut.rrd");
    let scene = small_demo(2);
    let (rec, guard) = open_stream(&Sink::Save(file.clone()), &ids(2), &scene).expect("save sink");
    let outcome = log_scene_cancellable(&rec, &scene, &AtomicBool::new(true));
    assert!(matches!(outcome, Ok(LogOutcome::Cancelled { .. })));
    guard.finish(rec).expect("finish");
    let bytes = std::fs::read(&file).expect("the file exists under its final name");
    assert_eq!(recording_chunks(&bytes).len(), 6);
    assert_verifies(&file);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_failed_save_leaves_no_file() {
    let dir = scratch_dir("fail");
    let file = dir.join("never.rrd");
    let mut scene = small_demo(2);
    let (rec, guard) = open_stream(&Sink::Save(file.clone()), &ids(2), &scene).expect("save sink");
    scene.items[0].path = "world//x".into();
    assert!(posecov::sink::log_scene(&rec, &scene).is_err());
    drop(guard);
    drop(rec);
    let left = std::fs::read_dir(&dir).expect("read dir").count();
    assert_eq!(left, 0, "neither the file nor its temporary remains");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn save_writes_atomically_and_two_processes_write_the_same_content() {
    let dir = scratch_dir("save");
    let files = [dir.join("a.rrd"), dir.join("b.rrd")];
    for file in &files {
        save_with(&["--seed", "3", "--samples", "80"], file);
    }
    let names: Vec<String> = std::fs::read_dir(&dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "no temporary files left: {names:?}");
    let [a, b] = files
        .each_ref()
        .map(|f| std::fs::read(f).expect("read rrd"));
    assert_same_content(&a, &b);
    match rerun_cli() {
        None => eprintln!("SKIPPED rrd verify/compare: no rerun CLI (set $POSECOV_RERUN_CLI)"),
        Some(cli) => {
            for args in [vec!["rrd", "verify"], vec!["rrd", "compare"]] {
                let out = Command::new(&cli)
                    .args(&args)
                    .args(files.iter().take(if args[1] == "verify" { 1 } else { 2 }))
                    .output()
                    .expect("run rerun-cli");
                assert!(
                    out.status.success(),
                    "{args:?}: {}{}",
                    String::from_utf8_lossy(&out.stdout),
                    String::from_utf8_lossy(&out.stderr)
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn stdout_sink_streams_a_recording() {
    let out = Command::new(BIN)
        .args([SCENARIO, "--samples", "20", "--stdout"])
        .stdout(Stdio::piped())
        .output()
        .expect("run posecov");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!recording_chunks(&out.stdout).is_empty());
}

#[test]
fn png_without_a_viewer_says_what_to_install() {
    let out = Command::new(BIN)
        .args([SCENARIO, "--png", "/nonexistent/x.png"])
        .env("POSECOV_RERUN", "/nonexistent/rerun")
        .output()
        .expect("run posecov");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("pip install rerun-sdk==0.36.3"), "{stderr}");
}

#[test]
fn bad_arguments_fail_with_a_message() {
    for args in [
        vec![SCENARIO, "--confidence", "1.5"],
        vec![SCENARIO, "--save", "x.rrd", "--serve"],
        vec![SCENARIO, "--size", "10x10", "--png", "x.png"],
    ] {
        let out = Command::new(BIN).args(&args).output().expect("run posecov");
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(!out.stderr.is_empty());
    }
    let out = Command::new(BIN)
        .args(["nosuch"])
        .output()
        .expect("run posecov");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("nosuch: cannot read input") && stderr.contains("camera_on_robot"),
        "{stderr}"
    );
}

/// GET `path` on 127.0.0.1:`port`; returns the status line.
fn http_status(port: u16, path: &str) -> Option<String> {
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).ok()?;
    stream.set_read_timeout(Some(Duration::from_secs(5))).ok()?;
    write!(stream, "GET {path} HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n").ok()?;
    let mut head = [0u8; 64];
    let n = stream.read(&mut head).ok()?;
    String::from_utf8_lossy(&head[..n])
        .lines()
        .next()
        .map(str::to_owned)
}

#[test]
fn serve_answers_on_loopback_and_stops_by_itself() {
    let (web, grpc) = (free_port(), free_port());
    let start = Instant::now();
    let mut child = Command::new(BIN)
        .args([SCENARIO, "--samples", "20", "--serve"])
        .args([
            "--web-port",
            &web.to_string(),
            "--grpc-port",
            &grpc.to_string(),
        ])
        .env("POSECOV_SERVE_SECONDS", "6")
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("run posecov");
    let mut status = None;
    while start.elapsed() < Duration::from_secs(5) && status.is_none() {
        status = http_status(web, "/").filter(|s| s.contains("200"));
        std::thread::sleep(Duration::from_millis(100));
    }
    let exit = loop {
        if let Some(exit) = child.try_wait().expect("wait") {
            break exit;
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().ok();
            panic!("--serve did not stop after POSECOV_SERVE_SECONDS");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut stdout = String::new();
    child
        .stdout
        .take()
        .map(|mut s| s.read_to_string(&mut stdout));
    assert!(
        status.is_some(),
        "web viewer did not answer 200 on port {web}"
    );
    assert!(exit.success(), "{exit}");
    assert!(
        stdout.contains(&format!("127.0.0.1:{web}")),
        "URL printed: {stdout}"
    );
}

#[test]
fn check_subcommand_validates_the_demo() {
    let out = Command::new(BIN)
        .args(["check", SCENARIO])
        .output()
        .expect("run posecov");
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("camera_on_robot: ok"));
}

/// A sample larger than a block: the CLI logs the first block with the scene and every later
/// block's cloud after it, as children of the first cloud; the file is complete and valid and
/// the same seed writes the same content.
#[test]
fn blocked_monte_carlo_save_logs_every_block_and_is_deterministic() {
    let dir = scratch_dir("blocked");
    let files = [dir.join("a.rrd"), dir.join("b.rrd")];
    for file in &files {
        save_with(&["--samples", "2500", "--block-samples", "1024"], file);
    }
    let [a, b] = files
        .each_ref()
        .map(|f| std::fs::read(f).expect("read rrd"));
    assert_same_content(&a, &b);
    let paths: Vec<String> = recording_chunks(&a)
        .iter()
        .map(|c| c.entity_path().to_string())
        .collect();
    for suffix in ["cloud", "cloud/block_1", "cloud/block_2"] {
        let path = format!("/world/map_from_camera/monte_carlo/{suffix}");
        assert!(paths.contains(&path), "{path} missing");
    }
    assert!(
        !paths.iter().any(|p| p.ends_with("block_3")),
        "3 blocks only"
    );
    assert_verifies(&files[0]);
    std::fs::remove_dir_all(&dir).ok();
}
