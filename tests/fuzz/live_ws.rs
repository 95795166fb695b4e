//! A running robot's stream (issue 31): posecov's Foxglove WebSocket client against a
//! scripted server on 127.0.0.1 (std `TcpListener`, the handshake by tungstenite's server
//! side, every frame then written byte for byte), each session a script of frames — a good
//! session (`serverInfo`, `advertise` of a ROS 2 and a ROS 1 pose topic and a camera, pose
//! messages in `cdr` and `ros1`) damaged: frames' bytes mutated (JSON and message data), bad
//! frames inserted (malformed JSON, an `advertise` of an unknown schema or encoding, a frame
//! for an unknown subscription, a truncated or empty frame, a CDR payload cut short or
//! carrying NaN, stamps out of order, a frame header stating 17 MiB, a reserved opcode, a
//! masked frame, invalid UTF-8, a close mid-way, ten thousand channels), frames dropped,
//! repeated or swapped. Run as `report --json` runs a live stream (read → evaluate → the JSON
//! report); the session ends when the server has sent its script and the client has
//! gone (its Ctrl-C then, as a user's).
//!
//! Checked: no panic, no hang, memory bounded (the harness); an error names the URL; a
//! report has no `null` where a number belongs, says what the stream did (`meta.stream`,
//! at most 8 damaged frames in words), and reads no more pose messages than message-data
//! frames were sent.
//!
//! The input file is the script: records `[kind u8][length u32 LE][bytes]`, kind 0 a text
//! frame, 1 a binary frame, 2 bytes written to the socket as they are.

use std::io::{Read as _, Write as _};
use std::net::{TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use posecov::app::Overrides;
use posecov::app::log::report_json;
use posecov::app::run::{Run as AppRun, RunOptions, open};

use crate::harness::{Family, Finding, Limits, Run, Stage, finding, json_null, mutate_bytes};
use crate::harness::{run_guarded, settle};

/// A text frame, a binary frame, raw bytes.
const TEXT: u8 = 0;
const BINARY: u8 = 1;
const RAW: u8 = 2;

type Script = Vec<(u8, Vec<u8>)>;

/// The script as the input file's bytes.
fn encode(script: &Script) -> Vec<u8> {
    let mut out = Vec::new();
    for (kind, bytes) in script {
        out.push(*kind);
        out.extend((bytes.len() as u32).to_le_bytes());
        out.extend(bytes);
    }
    out
}

/// The script of an input file; a record cut short is taken as far as it goes.
fn decode(mut input: &[u8]) -> Script {
    let mut script = Vec::new();
    while let [kind, rest @ ..] = input {
        let len = rest
            .get(..4)
            .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        let body = rest.get(4..).unwrap_or_default();
        let take = len.min(body.len());
        script.push((*kind % 3, body[..take].to_vec()));
        input = &body[take..];
    }
    script
}

/// A server's unmasked WebSocket frame of `opcode` (final) carrying `payload`.
fn frame(opcode: u8, payload: &[u8]) -> Vec<u8> {
    let mut out = vec![0x80 | opcode];
    match payload.len() {
        n if n < 126 => out.push(n as u8),
        n if n < 65536 => {
            out.push(126);
            out.extend((n as u16).to_be_bytes());
        }
        n => {
            out.push(127);
            out.extend((n as u64).to_be_bytes());
        }
    }
    out.extend(payload);
    out
}

const ADVERTISE: &str = r#"{"op":"advertise","channels":[{"id":1,"topic":"/pose","encoding":"cdr","schemaName":"geometry_msgs/msg/PoseWithCovarianceStamped","schema":"","schemaEncoding":"ros2msg"},{"id":2,"topic":"/pose_ros1","encoding":"ros1","schemaName":"geometry_msgs/PoseWithCovarianceStamped","schema":"","schemaEncoding":"ros1msg"},{"id":3,"topic":"/camera","encoding":"cdr","schemaName":"sensor_msgs/msg/Image","schema":""}]}"#;

/// Pose, covariance of message `i` (σ growing, driving 0.1 m a message).
fn pose_values(i: u32, nan: bool) -> Vec<f64> {
    let s = 0.01 * f64::from(1 + i % 50);
    let mut covariance = [0.0; 36];
    for (axis, v) in [s, s, 1e-6, 1e-4, 1e-4, s].into_iter().enumerate() {
        covariance[7 * axis] = v;
    }
    if nan {
        covariance[0] = f64::NAN;
    }
    let mut v = vec![0.1 * f64::from(i), 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    v.extend(covariance);
    v
}

/// A message-data frame's body on `subscription` at `stamp_s`, the message `message`.
fn data(subscription: u32, stamp_s: u32, message: &[u8]) -> Vec<u8> {
    let mut b = vec![1u8];
    b.extend(subscription.to_le_bytes());
    b.extend((u64::from(stamp_s) * 1_000_000_000).to_le_bytes());
    b.extend(message);
    b
}

/// PoseWithCovarianceStamped in CDR (little endian).
fn cdr_pose(i: u32, stamp_s: u32, nan: bool) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    b.extend((stamp_s as i32).to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b.extend(4u32.to_le_bytes());
    b.extend(b"map\0");
    for v in pose_values(i, nan) {
        b.extend(v.to_le_bytes());
    }
    b
}

/// PoseWithCovarianceStamped in ROS 1 serialisation.
fn ros1_pose(i: u32, stamp_s: u32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend(i.to_le_bytes());
    b.extend(stamp_s.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b.extend(3u32.to_le_bytes());
    b.extend(b"map");
    for v in pose_values(i, false) {
        b.extend(v.to_le_bytes());
    }
    b
}

/// The good session: `serverInfo`, the channels, `n` messages on each pose topic.
fn good(n: u32) -> Script {
    let mut script = vec![
        (
            TEXT,
            br#"{"op":"serverInfo","name":"fuzz","capabilities":[]}"#.to_vec(),
        ),
        (TEXT, ADVERTISE.as_bytes().to_vec()),
    ];
    for i in 0..n {
        script.push((BINARY, data(1, 100 + i, &cdr_pose(i, 100 + i, false))));
        script.push((BINARY, data(2, 100 + i, &ros1_pose(i, 100 + i))));
    }
    script
}

/// A bad frame of the catalogue (the issue's "bad input from the network").
fn bad(rng: &mut ChaCha8Rng) -> ((u8, Vec<u8>), &'static str) {
    let k = rng.random_range(0..16);
    let text = |t: &str| (TEXT, t.as_bytes().to_vec());
    match k {
        0 => (text(r#"{"op":"#), "malformed JSON"),
        1 => (
            text(
                r#"{"op":"advertise","channels":[{"id":9,"topic":"/x","encoding":"cdr","schemaName":"foo/msg/Bar","schema":""}]}"#,
            ),
            "advertise of an unknown schema",
        ),
        2 => (
            text(
                r#"{"op":"advertise","channels":[{"id":8,"topic":"/pose_json","encoding":"json","schemaName":"geometry_msgs/msg/PoseWithCovarianceStamped","schema":""}]}"#,
            ),
            "advertise in an unknown encoding",
        ),
        3 => ((BINARY, data(77, 1, &[0; 8])), "an unknown subscription"),
        4 => ((BINARY, vec![1, 1, 0]), "a truncated frame"),
        5 => ((BINARY, Vec::new()), "an empty binary frame"),
        6 => {
            let mut m = cdr_pose(3, 150, false);
            m.truncate(rng.random_range(0..m.len()));
            ((BINARY, data(1, 150, &m)), "a CDR payload cut short")
        }
        7 => (
            (BINARY, data(1, 150, &cdr_pose(3, 150, true))),
            "a NaN covariance",
        ),
        8 => (
            (BINARY, data(1, 1, &cdr_pose(3, 1, false))),
            "a stamp out of order",
        ),
        9 => {
            let mut header = vec![0x82u8, 127];
            header.extend((17u64 << 20).to_be_bytes());
            ((RAW, header), "a frame header stating 17 MiB")
        }
        10 => ((RAW, vec![0x83, 0]), "a reserved opcode"),
        11 => ((RAW, vec![0x82, 0x81, 1, 2, 3, 4, 9]), "a masked frame"),
        12 => (
            (RAW, frame(1, &[0xff, 0xfe])),
            "invalid UTF-8 in a text frame",
        ),
        13 => ((RAW, frame(8, &[])), "a close mid-way"),
        14 => {
            let channels: Vec<String> = (0..10_000)
                .map(|i| {
                    format!(r#"{{"id":{},"topic":"/t{i}","encoding":"cdr","schemaName":"std_msgs/msg/Empty","schema":""}}"#, 1000 + i)
                })
                .collect();
            let t = format!(
                r#"{{"op":"advertise","channels":[{}]}}"#,
                channels.join(",")
            );
            ((TEXT, t.into_bytes()), "ten thousand channels")
        }
        _ => (
            text(r#"{"op":"unadvertise","channelIds":[1]}"#),
            "unadvertise",
        ),
    }
}

const TOKENS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    "\"",
    ",",
    ":",
    "null",
    "NaN",
    "1e309",
    "-1",
    "\"op\"",
    "\"advertise\"",
    "\"channels\"",
    "\u{0}",
    "\\u0000",
    "4294967296",
];

/// The live stream family.
pub struct LiveWs;

impl Family for LiveWs {
    fn name(&self) -> &'static str {
        "live_ws"
    }
    fn extension(&self) -> &'static str {
        "script"
    }
    /// A quarter of the others': each case is a whole session over a socket (about half a
    /// second on 2 cores), not a file read.
    fn smoke_cases(&self, default: u64) -> u64 {
        default.div_ceil(4)
    }
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(case);
        let n = rng.random_range(1..12);
        let mut script = good(n);
        let mut log = vec![format!("{n} messages a topic")];
        for _ in 0..[1, 1, 2, 3, 5][rng.random_range(0..5)] {
            let at = rng.random_range(0..script.len());
            match rng.random_range(0..6) {
                0 | 1 => {
                    let how = mutate_bytes(&mut rng, &mut script[at].1, TOKENS);
                    log.push(format!("record {at}: {how}"));
                }
                2 => {
                    let (record, what) = bad(&mut rng);
                    script.insert(at, record);
                    log.push(format!("{what} at {at}"));
                }
                3 if script.len() > 1 => {
                    script.remove(at);
                    log.push(format!("record {at} dropped"));
                }
                4 => {
                    let record = script[at].clone();
                    script.insert(at, record);
                    log.push(format!("record {at} repeated"));
                }
                _ => {
                    let other = rng.random_range(0..script.len());
                    script.swap(at, other);
                    log.push(format!("records {at} and {other} swapped"));
                }
            }
        }
        (encode(&script), log.join("; "))
    }
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool) {
        let script = decode(input);
        let sent = script.iter().filter(|(k, _)| *k == BINARY).count();
        let raw = script.iter().any(|(k, _)| *k == RAW);
        let listener = match TcpListener::bind("127.0.0.1:0") {
            Ok(l) => l,
            Err(e) => return (vec![finding("harness", format!("bind: {e}"))], false),
        };
        let url = match listener.local_addr() {
            Ok(a) => format!("ws://127.0.0.1:{}", a.port()),
            Err(e) => return (vec![finding("harness", format!("addr: {e}"))], false),
        };
        let cancel = Arc::new(AtomicBool::new(false));
        {
            let cancel = Arc::clone(&cancel);
            std::thread::spawn(move || {
                serve(listener, &script);
                cancel.store(true, Ordering::Release);
            });
        }
        let run = {
            let url = url.clone();
            run_guarded(limits, move |stage| run_live(&url, cancel, stage))
        };
        let stuck = matches!(run, Run::Stuck { .. });
        // Frames written raw may carry more message data than the binary records.
        let bound = (!raw).then_some(sent as u64);
        (judge(&url, run, bound, limits), stuck)
    }
}

/// Serves one session of `script` on `listener`: the handshake (`foxglove.websocket.v1`),
/// every record written, a close; then reads until the client has gone (at most 5 s). The
/// listener is closed on accepting, so that connecting again is refused.
#[allow(clippy::result_large_err)] // tungstenite's callback type: its error is an HTTP response
fn serve(listener: TcpListener, script: &Script) {
    use tungstenite::handshake::server::{ErrorResponse, Request, Response};
    let _ = listener.set_nonblocking(true);
    let started = Instant::now();
    let stream = loop {
        match listener.accept() {
            Ok((s, _)) => break s,
            Err(_) if started.elapsed() < Duration::from_secs(5) => {
                std::thread::sleep(Duration::from_millis(2));
            }
            Err(_) => return,
        }
    };
    drop(listener);
    let _ = stream.set_nonblocking(false);
    let _ = stream.set_read_timeout(Some(Duration::from_secs(5)));
    let _ = stream.set_write_timeout(Some(Duration::from_secs(5)));
    let answer = |_: &Request, mut response: Response| -> Result<Response, ErrorResponse> {
        let v = "foxglove.websocket.v1".parse().expect("header");
        response.headers_mut().insert("Sec-WebSocket-Protocol", v);
        Ok(response)
    };
    let Ok(ws) = tungstenite::accept_hdr(stream, answer) else {
        return;
    };
    let mut stream: TcpStream = ws.into_inner();
    for (kind, bytes) in script {
        let written = match *kind {
            TEXT => stream.write_all(&frame(1, bytes)),
            BINARY => stream.write_all(&frame(2, bytes)),
            _ => stream.write_all(bytes),
        };
        if written.is_err() {
            return;
        }
    }
    let _ = stream.write_all(&frame(8, &[]));
    let mut sink = [0u8; 4096];
    while matches!(stream.read(&mut sink), Ok(n) if n > 0) {}
}

/// The stream read as `report --json` reads it, Ctrl-C raised once the server is done.
fn run_live(url: &str, cancel: Arc<AtomicBool>, stage: Stage) -> Result<serde_json::Value, String> {
    stage("read, evaluate");
    let overrides = Overrides {
        samples: Some(8),
        ..Default::default()
    };
    let opened = open(url).map_err(|e| e.to_string())?;
    // As `report --json` runs (numbers, nothing drawn).
    let options = RunOptions::numbers().cancelled_by(cancel);
    let AppRun::Log(log) = AppRun::start(opened, &overrides, options).map_err(|e| e.to_string())?
    else {
        return Err("read as a plan, not a log".to_owned());
    };
    stage("report");
    Ok(report_json("fuzz", &log))
}

/// The error names the URL; the report has no `null` where a number belongs, says what the
/// stream did, and reads no more messages than were sent (`bound`, when known).
fn judge(
    url: &str,
    run: Run<Result<serde_json::Value, String>>,
    bound: Option<u64>,
    limits: &Limits,
) -> Vec<Finding> {
    let (result, mut found) = match settle(run, limits) {
        Ok(x) => x,
        Err(ended) => return ended,
    };
    match result {
        Err(e) if e.contains(url) => found.push(finding("error_ok", "")),
        Err(e) => found.push(finding("error_unlocated", e)),
        Ok(json) => {
            if let Some(path) = json_null(&json, crate::logs::LOG_JSON_OPTIONAL) {
                found.push(finding("nonfinite_json", format!("null at {path}")));
            }
            let stream = &json["meta"]["stream"];
            let noted = stream["damaged_first"].as_array().map(Vec::len);
            if stream["url"].as_str() != Some(url) || noted.is_none_or(|n| n > 8) {
                found.push(finding("stream_unsaid", format!("meta.stream: {stream}")));
            }
            let read: u64 = json["topics"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|t| t["messages"].as_u64())
                .sum();
            if let Some(sent) = bound
                && read > sent
            {
                let message = format!("{read} messages read of {sent} frames sent");
                found.push(finding("accepted_invalid_value", message));
            }
        }
    }
    if found.is_empty() {
        found.push(finding("ok", ""));
    }
    found
}

#[test]
fn a_good_session_reads_every_message() {
    let _guard = crate::harness::RUN_LOCK
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let url = format!("ws://{}", listener.local_addr().expect("addr"));
    let cancel = Arc::new(AtomicBool::new(false));
    let server = {
        let cancel = Arc::clone(&cancel);
        std::thread::spawn(move || {
            serve(listener, &good(5));
            cancel.store(true, Ordering::Release);
        })
    };
    let json = run_live(&url, cancel, &|_| {}).expect("the good session reads");
    server.join().expect("served");
    let read: Vec<(&str, u64)> = json["topics"]
        .as_array()
        .expect("topics")
        .iter()
        .map(|t| {
            (
                t["name"].as_str().unwrap_or(""),
                t["messages"].as_u64().unwrap_or(0),
            )
        })
        .collect();
    assert_eq!(read, [("/pose", 5), ("/pose_ros1", 5)]);
    assert_eq!(json["meta"]["stream"]["damaged"], 0);
    // The script reads back as written.
    assert_eq!(decode(&encode(&good(3))), good(3));
}
