//! A running robot's stream (issue 31, BENCHMARKS.md §"live stream"), measured side by side in
//! one run against a server on 127.0.0.1 (tungstenite, `foxglove.websocket.v1`, in this
//! process, on its own thread):
//!
//! 1. **Latency at 100 Hz × 4 topics** (`POSECOV_BENCH_SECONDS`, default 30 s, real time):
//!    each message's header stamp is the wall clock when the server sends it; per message,
//!    from leaving the server to (a) being read by the collector (the read's observer), (b)
//!    its own σ points logged to the viewer's stream (a message its series takes in, once a
//!    picture is shown: `draw::log::message_points`, `sink::log_points`, as the app's live
//!    view does) and (c) its items in the stream: its points, else the first picture of the
//!    growing view taken after it was read (evaluated, drawn, re-streamed in place with
//!    `Restream` and encoded on the read's thread that draws). p50, p95, max; the client's
//!    CPU (the process's less the server thread's, from /proc) as a share of one core.
//! 2. **Memory after a simulated minute and a simulated hour** at 100 Hz × 4 topics (the
//!    server sends as fast as it can, stamps 10 ms apart): the heap the read held at its
//!    peak and what the summary keeps at the end (a counting allocator), and messages
//!    thinned.
//!
//! Run: `cargo bench --bench live_stream` (release; the numbers in BENCHMARKS.md).

use std::alloc::{GlobalAlloc, Layout, System};
use std::net::TcpListener;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use posecov::draw::log::{LogDrawSettings, description, draw_log, message_points};
use posecov::eval::log::{LogEvalSettings, evaluate_log};
use posecov::input::About;
use posecov::input::log::{LogOptions, read_located_growing, ws::LiveOptions};
use posecov::plan::log::{EstimateMessage, LogObserver, LogSummary, ReferenceSample};
use posecov::sink::{Restream, log_points};
use posecov::uncertain::Confidence;

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const TOPICS: [&str; 4] = ["/odom", "/ekf", "/amcl_pose", "/gnss"];

fn now_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// A message-data frame on `subscription`: a PoseWithCovarianceStamped (CDR) of message `i`
/// stamped `stamp_ns`.
fn frame(subscription: u32, i: u64, stamp_ns: u64) -> tungstenite::Message {
    let mut b = vec![1u8];
    b.extend(subscription.to_le_bytes());
    b.extend(stamp_ns.to_le_bytes());
    b.extend([0, 1, 0, 0]);
    b.extend(((stamp_ns / 1_000_000_000) as i32).to_le_bytes());
    b.extend(((stamp_ns % 1_000_000_000) as u32).to_le_bytes());
    b.extend(4u32.to_le_bytes());
    b.extend(b"map\0");
    let t = i as f64 * 0.01;
    let s = 0.05 + 0.02 * (t * 0.1).sin().abs();
    let mut covariance = [0.0; 36];
    for (axis, v) in [s, s, 1e-6, 1e-4, 1e-4, s * 0.1].into_iter().enumerate() {
        covariance[7 * axis] = v;
    }
    let yaw = t * 0.05;
    let pose = [
        50.0 * yaw.cos(),
        50.0 * yaw.sin(),
        0.0,
        0.0,
        0.0,
        (yaw / 2.0).sin(),
        (yaw / 2.0).cos(),
    ];
    for v in pose.iter().chain(&covariance) {
        b.extend(v.to_le_bytes());
    }
    tungstenite::Message::binary(b)
}

/// CPU seconds (user + system) of `/proc/<path>/stat`.
fn cpu_seconds(path: &str) -> f64 {
    let stat = std::fs::read_to_string(path).unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or_default();
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // utime and stime are fields 14 and 15 of the file, 12 and 13 after the command.
    (ticks(11) + ticks(12)) / 100.0
}

/// Serves one client on 127.0.0.1: advertises the four topics, waits for the subscription,
/// then sends `messages` per topic, paced at `rate_hz` (`None`: as fast as it can, stamps
/// 10 ms apart from 0). Returns the port, and the server thread's CPU seconds when done.
#[allow(clippy::result_large_err)] // tungstenite's callback type: its error is an HTTP response
fn server(messages: u64, rate_hz: Option<u64>) -> (u16, std::thread::JoinHandle<f64>) {
    use tungstenite::handshake::server::{ErrorResponse, Request, Response};
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let port = listener.local_addr().expect("addr").port();
    let thread = std::thread::spawn(move || {
        let (stream, _) = listener.accept().expect("accept");
        let answer = |_: &Request, mut response: Response| -> Result<Response, ErrorResponse> {
            let v = "foxglove.websocket.v1".parse().expect("header");
            response.headers_mut().insert("Sec-WebSocket-Protocol", v);
            Ok(response)
        };
        let mut ws = tungstenite::accept_hdr(stream, answer).expect("handshake");
        let channels: Vec<String> = TOPICS
            .iter()
            .enumerate()
            .map(|(k, t)| format!(r#"{{"id":{k},"topic":"{t}","encoding":"cdr","schemaName":"geometry_msgs/msg/PoseWithCovarianceStamped","schema":""}}"#))
            .collect();
        let advertise = format!(
            r#"{{"op":"advertise","channels":[{}]}}"#,
            channels.join(",")
        );
        ws.send(tungstenite::Message::text(advertise))
            .expect("advertise");
        let subscriptions: Vec<u32> = loop {
            if let tungstenite::Message::Text(t) = ws.read().expect("subscribe") {
                let v: serde_json::Value = serde_json::from_str(&t).expect("json");
                let mut s: Vec<(u64, u32)> = v["subscriptions"]
                    .as_array()
                    .expect("subscriptions")
                    .iter()
                    .map(|s| {
                        (
                            s["channelId"].as_u64().unwrap_or(0),
                            s["id"].as_u64().unwrap_or(0) as u32,
                        )
                    })
                    .collect();
                s.sort_unstable();
                break s.into_iter().map(|(_, id)| id).collect();
            }
        };
        let start = Instant::now();
        for i in 0..messages {
            let stamp = match rate_hz {
                Some(hz) => {
                    let due = start + Duration::from_nanos(i * 1_000_000_000 / hz);
                    std::thread::sleep(due.saturating_duration_since(Instant::now()));
                    now_ns()
                }
                None => 1_000_000_000 + i * 10_000_000,
            };
            for &s in &subscriptions {
                if ws.write(frame(s, i, stamp)).is_err() {
                    return cpu_seconds("/proc/thread-self/stat");
                }
            }
            let _ = ws.flush();
        }
        let cpu = cpu_seconds("/proc/thread-self/stat");
        while ws.read().is_ok() {}
        cpu
    });
    (port, thread)
}

/// The picture shown last: its lines (points left out) and generation, which each message's
/// points extend until the next (as the app's live view does, `app/session.rs`).
type Tail = std::sync::Mutex<Option<(posecov::scene::Scene, u64)>>;

/// Every message's send stamp, when the collector read it and, for a message its series took
/// in once a picture was shown, when its points were in the stream (ns since the epoch).
struct Arrivals<'t> {
    seen: Vec<(u64, u64, Option<u64>)>,
    rec: &'t rerun::RecordingStream,
    tail: &'t Tail,
}

impl LogObserver for Arrivals<'_> {
    fn reference(&mut self, _: &str, _: ReferenceSample) {}
    fn estimate(&mut self, m: &EstimateMessage<'_>) {
        let read = now_ns();
        let mut streamed = None;
        if let Some(point) = &m.series
            && let Some((lines, generation)) = &*self.tail.lock().expect("tail")
        {
            let mut points = message_points(lines, m.topic, point);
            for line in &mut points {
                line.generation = Some(*generation);
            }
            log_points(self.rec, &points, lines.timeline).expect("points logged");
            streamed = Some(now_ns());
        }
        self.seen.push((m.stamp_ns as u64, read, streamed));
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

/// The stream on `port`, `messages` per topic (and an hour at most).
fn stream(port: u16, messages: u64) -> (posecov::input::Located, LogOptions) {
    let located = posecov::input::locate(&format!("ws://127.0.0.1:{port}")).expect("a ws URL");
    let options = LogOptions {
        live: LiveOptions {
            messages: Some(messages * TOPICS.len() as u64),
            duration: Some(Duration::from_secs(3600)),
            record: None,
        },
        ..LogOptions::default()
    };
    (located, options)
}

fn latency(seconds: u64) {
    let per_topic = seconds * 100;
    let (port, server) = server(per_topic, Some(100));
    let (located, options) = stream(port, per_topic);
    let (rec, storage) = rerun::RecordingStreamBuilder::new("bench")
        .memory()
        .expect("memory");
    let mut restream = Restream::new();
    let never = std::sync::atomic::AtomicBool::new(false);
    let tail: Tail = std::sync::Mutex::new(None);
    // Per picture: when its summary was taken, when its items were in the stream.
    let mut pictures: Vec<(u64, u64, f64)> = Vec::new();
    let mut grow = |mut plan: LogSummary| {
        let taken = now_ns();
        let e = evaluate_log(&mut plan, &LogEvalSettings::default());
        let about = About {
            title: "bench".into(),
            description: String::new(),
            source: String::new(),
        };
        let settings = LogDrawSettings {
            about,
            confidence: Confidence::DEFAULT,
            axis_length: None,
        };
        let text = description(&plan, "Live stream", &e, Confidence::DEFAULT);
        let scene = draw_log(&e, &settings, &text);
        let mut lines = posecov::scene::Scene::new("", "");
        lines.timeline = scene.timeline;
        lines.plots = scene.plots.clone();
        lines.series = scene.series.clone();
        for line in &mut lines.series {
            line.points.clear();
        }
        restream.log(&rec, scene, &never).expect("logged");
        let bytes = storage.drain_as_bytes().expect("encoded").len();
        *tail.lock().expect("tail") = Some((lines, restream.generations() - 1));
        let done = now_ns();
        pictures.push((taken, done, bytes as f64));
    };
    let mut arrivals = Arrivals {
        seen: Vec::new(),
        rec: &rec,
        tail: &tail,
    };
    let cpu_before = cpu_seconds("/proc/self/stat");
    let wall = Instant::now();
    let plan = read_located_growing(
        &located,
        &options,
        &mut |_, _| {},
        None,
        Some(&mut arrivals),
        Some(&mut grow),
    )
    .expect("the stream reads");
    let wall = wall.elapsed().as_secs_f64();
    let cpu = cpu_seconds("/proc/self/stat") - cpu_before;
    let server_cpu = server.join().expect("server");
    let seen = arrivals.seen;
    let mut read_ms: Vec<f64> = seen.iter().map(|(s, r, _)| (r - s) as f64 / 1e6).collect();
    let mut points_ms: Vec<f64> = seen
        .iter()
        .filter_map(|(s, _, p)| p.map(|p| (p - s) as f64 / 1e6))
        .collect();
    // Every message: its own points, else the first picture taken after it was read.
    let mut shown_ms: Vec<f64> = seen
        .iter()
        .filter_map(|(s, r, p)| {
            p.or_else(|| pictures.iter().find(|q| q.0 >= *r).map(|q| q.1))
                .map(|at| (at - s) as f64 / 1e6)
        })
        .collect();
    let mut redraw_ms: Vec<f64> = pictures.iter().map(|p| (p.1 - p.0) as f64 / 1e6).collect();
    for v in [&mut read_ms, &mut points_ms, &mut shown_ms, &mut redraw_ms] {
        v.sort_by(f64::total_cmp);
    }
    let line = |what: &str, v: &[f64]| {
        println!(
            "| {what} | {} | {:.2} | {:.2} | {:.2} |",
            v.len(),
            percentile(v, 0.5),
            percentile(v, 0.95),
            v.last().copied().unwrap_or(f64::NAN)
        );
    };
    println!(
        "\n## latency, {seconds} s at 100 Hz x 4 topics ({} messages read, thinned {}, pictures skipped {})",
        plan.topics.iter().map(|t| t.count).sum::<u64>(),
        plan.stream.as_ref().map_or(0, |s| s.thinned),
        plan.stream.as_ref().map_or(0, |s| s.pictures_skipped)
    );
    println!(
        "| from leaving the server to | n | p50 ms | p95 ms | max ms |\n|---|---|---|---|---|"
    );
    line("read by the collector", &read_ms);
    line("its own points in the viewer's stream", &points_ms);
    line(
        "its items in the viewer's stream (its points, else the next picture)",
        &shown_ms,
    );
    line(
        "(one picture: evaluate, draw, re-stream, encode)",
        &redraw_ms,
    );
    let mb: f64 = pictures.iter().map(|p| p.2).sum::<f64>() / 1e6;
    println!(
        "pictures {}, {mb:.1} MB streamed; client CPU {:.1} s of {wall:.1} s wall = {:.1} % of one core (server thread {server_cpu:.1} s not counted)",
        pictures.len(),
        cpu - server_cpu,
        100.0 * (cpu - server_cpu) / wall
    );
}

fn memory(label: &str, seconds: u64) -> (usize, usize) {
    let per_topic = seconds * 100;
    let (port, server) = server(per_topic, None);
    let (located, options) = stream(port, per_topic);
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let started = Instant::now();
    let plan =
        read_located_growing(&located, &options, &mut |_, _| {}, None, None, None).expect("reads");
    let peak = PEAK.load(Ordering::Relaxed) - base;
    let kept = CURRENT.load(Ordering::Relaxed).saturating_sub(base);
    server.join().expect("server");
    let read: u64 = plan.topics.iter().map(|t| t.count).sum();
    let thinned = plan.stream.as_ref().map_or(0, |s| s.thinned);
    println!(
        "| {label} | {} | {read} | {thinned} | {:.2} | {:.2} | {:.1} |",
        per_topic * 4,
        peak as f64 / (1 << 20) as f64,
        kept as f64 / (1 << 20) as f64,
        started.elapsed().as_secs_f64()
    );
    drop(plan);
    (peak, kept)
}

fn main() {
    // `cargo bench` passes `--bench`; nothing else is read from the command line.
    let seconds = std::env::var("POSECOV_BENCH_SECONDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(30);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("load average at start: {}", load.trim());
    latency(seconds);
    println!(
        "\n## memory, simulated, 100 Hz x 4 topics, sent as fast as the server can\n| run | sent | read | thinned | peak heap MiB | kept MiB | s |\n|---|---|---|---|---|---|---|"
    );
    let (minute_peak, minute_kept) = memory("one minute", 60);
    let (hour_peak, hour_kept) = memory("one hour", 3600);
    println!(
        "hour / minute: peak {:.2}x, kept {:.2}x",
        hour_peak as f64 / minute_peak as f64,
        hour_kept as f64 / minute_kept as f64
    );
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("load average at end: {}", load.trim());
}
