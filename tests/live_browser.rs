//! End to end: `posecov live camera_on_robot --serve` in a child process, its control page
//! in headless Chromium (`tests/browser/live.mjs`, playwright-core) dragging the heading σ
//! slider, and a gRPC client reading the served viewer stream as the web viewer does. The
//! test passes when what that client received shows, entity by entity, exactly what a fresh
//! recording of the edited scenario shows.
//!
//! Needs `chromium` (Debian's, at /usr/bin/chromium), `node` and `npm ci` in tests/browser
//! (`.ci/run` installs them). Without them the test is skipped, except under CI.
//!
//! The same stream check covers `--watch` on a served viewer (no browser needed).

use std::io::{BufRead as _, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use posecov::app::live::{Edit, EditValue, LiveDocument};
use posecov::app::{Overrides, load_text, pipeline};
use posecov::sink::{RecordingIds, scene_to_rrd_bytes};
use rerun::external::re_entity_db::EntityDb;
use rerun::external::re_grpc_client;
use rerun::log::LogMsg;
use rerun::{EntityPath, StoreKind};

mod rrd;

/// Kills the child on drop (the test may panic).
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        self.0.kill().ok();
        self.0.wait().ok();
    }
}

fn browser_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser")
}

/// Whether Chromium, node and playwright-core are here; under CI their absence fails.
fn tools_present() -> bool {
    let chromium = std::env::var_os("CHROMIUM")
        .map_or_else(|| PathBuf::from("/usr/bin/chromium"), PathBuf::from);
    let node = Command::new("node")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    let playwright = browser_dir().join("node_modules/playwright-core").is_dir();
    let present = chromium.is_file() && node && playwright;
    if !present {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must provide chromium ({}: {}), node ({node}) and tests/browser/node_modules ({playwright})",
            chromium.display(),
            chromium.is_file()
        );
        eprintln!("skipped: needs chromium, node and `npm ci` in tests/browser");
    }
    present
}

#[path = "common/ports.rs"]
mod ports;
use ports::free_port;

/// Every message a gRPC client of the served viewer stream has received so far.
fn read_stream(url: &str) -> Arc<Mutex<Vec<LogMsg>>> {
    let received = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&received);
    let uri: rerun::external::re_uri::ProxyUri = url.parse().unwrap();
    std::thread::spawn(move || {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .unwrap();
        let handle = re_async::AsyncRuntimeHandle::new_native(runtime.handle().clone());
        let rx = re_grpc_client::read::stream(&handle, uri);
        while let Ok(msg) = rx.recv_timeout(Duration::from_secs(300)) {
            if let Some(re_log_channel::DataSourceMessage::LogMsg(m)) = msg.into_data() {
                sink.lock().unwrap().push(m);
            }
        }
        drop(runtime);
    });
    received
}

/// The recording's entities under `world/` as an `EntityDb`, from what the client received.
fn db_from(msgs: &[LogMsg]) -> EntityDb {
    let store = msgs
        .iter()
        .find(|m| m.store_id().kind() == StoreKind::Recording)
        .map(|m| m.store_id().clone())
        .expect("recording messages");
    let mut db = EntityDb::new(store);
    for msg in msgs {
        if let LogMsg::ArrowMsg(id, arrow) = msg
            && id.kind() == StoreKind::Recording
        {
            let chunk = rerun::log::Chunk::from_arrow_msg(arrow).unwrap();
            db.add_chunk(&Arc::new(chunk)).unwrap();
        }
    }
    db
}

fn cloud(db: &EntityDb) -> Option<rerun::external::arrow::array::ArrayRef> {
    use rerun::external::re_entity_db::external::re_chunk_store::LatestAtQuery;
    let path: EntityPath = "world/map_from_camera/monte_carlo/cloud".into();
    let positions = rerun::Points3D::descriptor_positions().component;
    let query = LatestAtQuery::new("step".into(), rerun::external::re_log_types::TimeInt::MIN);
    db.latest_at(&query, &path, [positions])
        .component_batch_raw(positions)
}

#[test]
fn dragging_a_slider_in_chromium_re_streams_the_viewer() {
    if !tools_present() {
        return;
    }
    let grpc_port = free_port();
    let dir = std::env::temp_dir().join(format!("posecov-live-browser-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let saved = dir.join("saved.toml");
    let child = Command::new(env!("CARGO_BIN_EXE_posecov"))
        .args([
            "live",
            "camera_on_robot",
            "--serve",
            "--web-port",
            "0",
            "--grpc-port",
        ])
        .arg(grpc_port.to_string())
        .args([
            "--bind",
            "127.0.0.1:0",
            "--serve-seconds",
            "300",
            "--save-scenario",
        ])
        .arg(&saved)
        .env("POSECOV_RERUN", "/nonexistent")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut child = Running(child);
    let mut lines = BufReader::new(child.0.stdout.take().unwrap()).lines();
    let page = loop {
        let line = lines
            .next()
            .expect("posecov live printed its URLs")
            .unwrap();
        if let Some(url) = line.strip_prefix("Controls: ") {
            break url.to_owned();
        }
    };
    let received = read_stream(&format!("rerun+http://127.0.0.1:{grpc_port}/proxy"));
    let output = Command::new("node")
        .arg(browser_dir().join("live.mjs"))
        .arg(&page)
        .args(std::env::var_os("POSECOV_LIVE_SCREENSHOT"))
        .stderr(Stdio::inherit())
        .output()
        .unwrap();
    assert!(output.status.success(), "the browser test failed");
    let report: serde_json::Value =
        serde_json::from_slice(output.stdout.trim_ascii()).expect("one JSON line");
    let value = report["value"].as_f64().unwrap();
    assert!(value > 20.0, "{report}");
    // Only the methods that apply: no closed form on a camera mount.
    let methods: Vec<&str> = report["methods"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m.as_str())
        .collect();
    assert!(methods.contains(&"sigma_points"), "{report}");
    assert!(!methods.contains(&"closed_form"), "{report}");
    // Plain words on the status line.
    let status = report["statusText"].as_str().unwrap();
    assert!(status.starts_with("showing change "), "{status}");
    assert!(!status.contains("generation"), "{status}");
    // A cleared field names the field, not serde's enum.
    let empty = report["emptyError"].as_str().unwrap();
    assert!(
        empty.contains("pose map_from_robot σ θ is empty: type a number"),
        "{empty}"
    );
    assert!(!empty.contains("EditValue"), "{empty}");
    // At 800 px the controls stack above the viewer, both the page's width.
    let narrow = &report["narrow"];
    let (panel, viewer) = (&narrow["panel"], &narrow["viewer"]);
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    assert!(
        f(panel, "y") + f(panel, "height") <= f(viewer, "y") + 1.0,
        "not stacked: {narrow}"
    );
    assert!(
        f(viewer, "width") >= 780.0 && f(panel, "width") >= 780.0,
        "{narrow}"
    );
    assert!(f(viewer, "height") >= 360.0, "{narrow}");
    // "Save" wrote a scenario that `posecov check` accepts, with the new σ and the file's
    // comments.
    assert_eq!(report["saved"].as_str(), saved.to_str(), "{report}");
    let text = std::fs::read_to_string(&saved).unwrap();
    assert!(text.contains("# x, y in metres; θ in degrees"), "{text}");
    posecov::app::commands::check(saved.to_str().unwrap(), &Overrides::default(), &[]).unwrap();

    // What a fresh recording of the edited scenario shows.
    let mut doc = LiveDocument::open("camera_on_robot").unwrap();
    doc.apply(&Edit {
        id: report["id"].as_str().unwrap().to_owned(),
        value: EditValue::Number(value),
    })
    .unwrap();
    assert_eq!(doc.text(), text, "the saved file is the edited scenario");
    let loaded = load_text(&doc.text(), "edited.toml").unwrap();
    let (_, scene) = pipeline(&loaded, &Overrides::default(), None).unwrap();
    let fresh = scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("fresh", 0)).unwrap();
    let expected = cloud(&EntityDb::from_bytes_for_test(&fresh));
    assert!(expected.is_some());

    // The viewer's stream reaches it (it may still be arriving).
    wait_until_stream_shows(&received, expected.as_ref().unwrap());
    std::fs::remove_dir_all(&dir).ok();
}

/// Waits (up to a minute) until the stream received so far shows `expected` as the camera's
/// cloud, then checks it holds one recording.
fn wait_until_stream_shows(
    received: &Mutex<Vec<LogMsg>>,
    expected: &rerun::external::arrow::array::ArrayRef,
) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let msgs = received.lock().unwrap().clone();
        let seen = (!msgs.is_empty()).then(|| cloud(&db_from(&msgs))).flatten();
        if seen.as_ref().map(|a| a.as_ref()) == Some(expected.as_ref()) {
            let recordings: std::collections::BTreeSet<_> = msgs
                .iter()
                .filter(|m| m.store_id().kind() == StoreKind::Recording)
                .map(|m| format!("{:?}", m.store_id()))
                .collect();
            assert_eq!(recordings.len(), 1, "one recording");
            return;
        }
        assert!(
            Instant::now() < deadline,
            "the viewer stream never showed the edited cloud ({} messages received)",
            msgs.len()
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// `EntityDb` from .rrd bytes.
trait FromBytes {
    fn from_bytes_for_test(bytes: &[u8]) -> EntityDb;
}

impl FromBytes for EntityDb {
    fn from_bytes_for_test(bytes: &[u8]) -> EntityDb {
        let msgs: Vec<LogMsg> =
            rerun::external::re_log_encoding::DecoderApp::decode_eager(std::io::Cursor::new(bytes))
                .unwrap()
                .map(Result::unwrap)
                .collect();
        db_from(&msgs)
    }
}

/// `--watch` on a served viewer: one recording, re-streamed in place when the file changes;
/// a broken save is reported and the picture stays until the next good one.
#[test]
fn watch_re_streams_in_place_on_the_served_viewer() {
    let dir = std::env::temp_dir().join(format!("posecov-watch-live-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("camera.toml");
    let original = posecov::input::scenario::bundled::find("camera_on_robot")
        .unwrap()
        .text;
    std::fs::write(&file, original).unwrap();
    let grpc_port = free_port();
    let child = Command::new(env!("CARGO_BIN_EXE_posecov"))
        .arg(&file)
        .args(["--watch", "--serve", "--web-port", "0", "--grpc-port"])
        .arg(grpc_port.to_string())
        .args(["--serve-seconds", "120"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut child = Running(child);
    let mut errors = BufReader::new(child.0.stderr.take().unwrap()).lines();
    let mut wait_for = |needle: &str| loop {
        let line = errors.next().expect("posecov --watch is running").unwrap();
        if line.contains(needle) {
            break;
        }
    };
    wait_for("[0] streamed");
    let received = read_stream(&format!("rerun+http://127.0.0.1:{grpc_port}/proxy"));
    let expected_for = |text: &str| {
        let loaded = load_text(text, "edited.toml").unwrap();
        let (_, scene) = pipeline(&loaded, &Overrides::default(), None).unwrap();
        let bytes = scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("fresh", 0)).unwrap();
        cloud(&EntityDb::from_bytes_for_test(&bytes)).unwrap()
    };
    let broken = original.replace("[0.05, 0.05, 20.0]", "[0.05, 0.05, -1.0]");
    std::fs::write(&file, &broken).unwrap();
    wait_for("is negative");
    let edited = original.replace("[0.05, 0.05, 20.0]", "[0.05, 0.05, 35.0]");
    std::fs::write(&file, &edited).unwrap();
    wait_for("[1] streamed");
    wait_until_stream_shows(&received, &expected_for(&edited));
    std::fs::remove_dir_all(&dir).ok();
}

/// One HTTP/1.1 request to `port` on loopback (`Host` as given); the status, the headers and
/// up to `want` bytes of the body (a stream is not read to its end).
fn http(port: u16, host: &str, request: &str, body: &[u8], want: usize) -> (u16, String, Vec<u8>) {
    use std::io::{Read as _, Write as _};
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    let head = format!("{request} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n");
    stream.write_all(head.as_bytes()).unwrap();
    stream.write_all(b"\r\n").unwrap();
    stream.write_all(body).unwrap();
    let mut got = Vec::new();
    let mut buf = [0u8; 65536];
    loop {
        let end = got.windows(4).position(|w| w == b"\r\n\r\n");
        if end.is_some_and(|e| got.len() >= (e + 4).saturating_add(want)) {
            break;
        }
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => got.extend_from_slice(&buf[..n]),
        }
    }
    let end = got
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("an HTTP answer");
    let headers = String::from_utf8_lossy(&got[..end]).into_owned();
    let status = headers.split(' ').nth(1).unwrap().parse().unwrap();
    (status, headers, got[end + 4..].to_vec())
}

/// The page shows the served web viewer through itself (same origin): the viewer's files and
/// its gRPC-web stream come from the page's port, under the page's Host checks, while the
/// viewer's own servers stay on loopback; and the page still stops on time with a stream
/// open.
#[test]
fn the_page_serves_the_viewer_and_its_stream_from_its_own_origin() {
    let grpc_port = free_port();
    let child = Command::new(env!("CARGO_BIN_EXE_posecov"))
        .args(["live", "camera_on_robot", "--serve", "--web-port", "0"])
        .args(["--grpc-port", &grpc_port.to_string()])
        .args(["--bind", "127.0.0.1:0", "--serve-seconds", "25"])
        .env("POSECOV_RERUN", "/nonexistent")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut child = Running(child);
    let mut lines = BufReader::new(child.0.stdout.take().unwrap()).lines();
    let page = loop {
        let line = lines.next().expect("the Controls URL").unwrap();
        if let Some(url) = line.strip_prefix("Controls: ") {
            break url.to_owned();
        }
    };
    let host = page
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_owned();
    let port: u16 = host.rsplit_once(':').unwrap().1.parse().unwrap();

    let (status, _, body) = http(port, &host, "GET /api/state", b"", usize::MAX);
    assert_eq!(status, 200);
    let state: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(state["viewer_url"], "/viewer/", "{state}");
    assert_eq!(state["viewer_same_origin"], true, "{state}");

    let (status, _, body) = http(port, &host, "GET /viewer/", b"", usize::MAX);
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&body).contains("re_viewer.js"));
    // (Chunked or not: the module's magic number within the first bytes.)
    let (status, _, body) = http(port, &host, "GET /viewer/re_viewer_bg.wasm", b"", 16);
    assert_eq!(status, 200);
    assert!(body.windows(4).any(|w| w == b"\0asm"), "{:?}", &body[..16]);
    // Another name for this machine is refused, as for the page itself (DNS rebinding).
    let (status, ..) = http(
        port,
        &format!("evil.example:{port}"),
        "GET /viewer/",
        b"",
        0,
    );
    assert_eq!(status, 403);

    // The viewer's stream, as the web viewer asks for it: gRPC-web, one empty request frame.
    let request = "POST /rerun.sdk_comms.v1alpha1.MessageProxyService/ReadMessages";
    let frame = [0u8, 0, 0, 0, 0];
    let head = format!(
        "{request} HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/grpc-web+proto\r\nX-Grpc-Web: 1\r\nContent-Length: {}\r\nConnection: close",
        frame.len()
    );
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    {
        use std::io::{Read as _, Write as _};
        stream
            .set_read_timeout(Some(Duration::from_secs(30)))
            .unwrap();
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(b"\r\n\r\n").unwrap();
        stream.write_all(&frame).unwrap();
        let mut got = Vec::new();
        let mut buf = [0u8; 65536];
        // Headers and the first kilobytes of the recording.
        while !got.windows(4).any(|w| w == b"\r\n\r\n") || got.len() < 4096 {
            match stream.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => got.extend_from_slice(&buf[..n]),
            }
        }
        let text = String::from_utf8_lossy(&got);
        assert!(
            text.starts_with("HTTP/1.1 200"),
            "{}",
            &text[..text.len().min(400)]
        );
        assert!(
            text.to_ascii_lowercase()
                .contains("content-type: application/grpc-web"),
            "{}",
            &text[..text.len().min(400)]
        );
        assert!(got.len() >= 4096, "the stream sent {} bytes", got.len());
    }
    // The stream is still open: the page stops at --serve-seconds all the same.
    let deadline = Instant::now() + Duration::from_secs(90);
    loop {
        if child.0.try_wait().unwrap().is_some() {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "posecov live did not stop with a viewer stream open"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    drop(stream);
}
