//! The live control page's HTTP API: raw requests with every method, path, `Host`, `Origin`,
//! content type and body (edits of every control to edge values, malformed JSON), some then
//! mutated byte by byte, sent to a real server on loopback.
//!
//! Checked: every request is answered (no hang, no 5xx); a request that does not name this
//! server in `Host` (and in `Origin`, when given) is never served (403); and after every
//! accepted edit or reset, the scenario the page offers for download passes `posecov check`'s
//! path (load, evaluate, draw).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use posecov::app::live::{Live, LiveDocument, PageOptions, bind_page, serve_page};
use posecov::app::{Overrides, load_text, pipeline};
use posecov::sink::{RecordingIds, Sink, open_stream};

use crate::harness::{Family, Finding, Limits, finding, mutate_bytes};

/// The scenario edited: odometry (controls and noise to push), with few samples.
fn scenario() -> String {
    posecov::input::scenario::bundled::find("na568_se2_odometry")
        .expect("bundled")
        .text
        .replace("samples = 5000", "samples = 64")
}

/// A fresh server after this many requests (each accepted edit adds a recording generation
/// to the in-memory sink).
const REQUESTS_PER_SERVER: u64 = 200;

/// A running page server.
struct Server {
    live: Arc<Live>,
    port: u16,
    cancel: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
    served: u64,
}

impl Server {
    fn start() -> Self {
        let doc = LiveDocument::new(&scenario(), "fuzz_live.toml").expect("seed scenario loads");
        let (_, scene) = pipeline(doc.loaded(), &Overrides::default(), None).expect("evaluates");
        let ids = RecordingIds::for_scenario("fuzz_live", 0);
        let (rec, guard) = open_stream(&Sink::Memory, &ids, &scene).expect("memory sink");
        let live = Live::start(doc, rec, guard, Overrides::default());
        let listener = bind_page("127.0.0.1:0".parse().expect("address")).expect("bind");
        let port = listener.local_addr().expect("bound").port();
        let cancel = Arc::new(AtomicBool::new(false));
        let thread = {
            let (live, cancel) = (Arc::clone(&live), Arc::clone(&cancel));
            std::thread::spawn(move || {
                let page = PageOptions {
                    viewer_url: None,
                    upstream: None,
                    save_to: None,
                };
                serve_page(live, listener, page, cancel, None, |_| {}).expect("serves");
            })
        };
        Self {
            live,
            port,
            cancel,
            thread: Some(thread),
            served: 0,
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        let _ = self.live.finish();
    }
}

/// The live API family.
pub struct LiveApi {
    ids: Vec<String>,
    server: Mutex<Option<Server>>,
}

impl LiveApi {
    pub fn new() -> Self {
        let doc = LiveDocument::new(&scenario(), "fuzz_live.toml").expect("seed scenario loads");
        let ids = doc.controls().into_iter().map(|c| c.id).collect();
        Self {
            ids,
            server: Mutex::new(None),
        }
    }
}

const METHODS: &[&str] = &[
    "GET", "POST", "POST", "POST", "PUT", "DELETE", "HEAD", "OPTIONS",
];
const PATHS: &[&str] = &[
    "/",
    "/live.js",
    "/live.css",
    "/api/state",
    "/api/status",
    "/api/scenario.toml",
    "/api/edit",
    "/api/edit",
    "/api/edit",
    "/api/edit",
    "/api/reset",
    "/api/save",
    "/api/reframe",
    "/api/edit?x=1",
    "//api/edit",
    "/api/../api/state",
    "/%2e%2e/etc/passwd",
    "/nope",
];
/// `{PORT}` is this server's port. The first three name it; the rest must be refused.
const HOSTS: &[&str] = &[
    "127.0.0.1:{PORT}",
    "localhost:{PORT}",
    "[::1]:{PORT}",
    "LOCALHOST:{PORT}",
    "evil.example:{PORT}",
    "evil.example",
    "127.0.0.1",
    "127.0.0.1:1",
    "127.0.0.2:{PORT}",
    "0.0.0.0:{PORT}",
    "",
    "127.0.0.1:{PORT}.evil.example",
    "localhost:{PORT}@evil.example",
];
/// `{HOST}` is the request's own `Host`.
const ORIGINS: &[&str] = &[
    "",
    "",
    "http://{HOST}",
    "http://{HOST}",
    "https://{HOST}",
    "http://evil.example",
    "null",
    "http://{HOST}.evil.example",
    "http://127.0.0.1:{PORT}",
];
const TYPES: &[&str] = &[
    "application/json",
    "application/json",
    "application/json; charset=utf-8",
    "text/plain",
    "application/x-www-form-urlencoded",
    "",
];
const VALUES: &[&str] = &[
    "1e16",
    "-1e16",
    "1e308",
    "-1e308",
    "1e309",
    "-1",
    "0",
    "-0",
    "0.5",
    "2",
    "1e-300",
    "5e-324",
    "1e9",
    "7",
    "100000000",
    "true",
    "false",
    "\"1\"",
    "null",
    "[1]",
    "{}",
];

impl Family for LiveApi {
    fn name(&self) -> &'static str {
        "live_api"
    }
    fn extension(&self) -> &'static str {
        "http"
    }
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(case);
        // Half the requests are what the page itself sends (its Host, its Origin or none,
        // JSON), so that edits reach the document; the rest mix every header.
        let proper = rng.random_bool(0.5);
        let mut pick = |list: &[&'static str]| list[rng.random_range(0..list.len())];
        let (method, path, host, origin, kind) = if proper {
            let method = pick(&["POST", "POST", "GET"]);
            let path = if method == "POST" {
                "/api/edit"
            } else {
                pick(PATHS)
            };
            (
                method,
                path,
                pick(&HOSTS[..3]),
                pick(&ORIGINS[..4]),
                "application/json",
            )
        } else {
            (
                pick(METHODS),
                pick(PATHS),
                pick(HOSTS),
                pick(ORIGINS),
                pick(TYPES),
            )
        };
        let value = pick(VALUES);
        let id = match rng.random_range(0..10) {
            0 => "pose[9].mean".to_owned(),
            1 => "scenario.nope".to_owned(),
            _ => self.ids[rng.random_range(0..self.ids.len())].clone(),
        };
        let body = match rng.random_range(0..10) {
            0 => String::new(),
            1 => "{\"id\":".to_owned(),
            2 => format!("{{\"id\":\"{id}\"}}"),
            _ => format!("{{\"id\":\"{id}\",\"value\":{value}}}"),
        };
        let mut request = format!("{method} {path} HTTP/1.1\r\n");
        if !host.is_empty() {
            request.push_str(&format!("Host: {host}\r\n"));
        }
        if !origin.is_empty() {
            request.push_str(&format!("Origin: {}\r\n", origin.replace("{HOST}", host)));
        }
        if !kind.is_empty() {
            request.push_str(&format!("Content-Type: {kind}\r\n"));
        }
        request.push_str(&format!(
            "Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
            body.len()
        ));
        let mut bytes = request.into_bytes();
        let mut how =
            format!("{method} {path} host {host:?} origin {origin:?} {kind} {id}={value}");
        if rng.random_bool(0.1) {
            how.push_str("; ");
            how.push_str(&mutate_bytes(
                &mut rng,
                &mut bytes,
                &["\r\n", ":", "{PORT}", " "],
            ));
        }
        (bytes, how)
    }
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool) {
        let mut server = self.server.lock().unwrap_or_else(|e| e.into_inner());
        if server
            .as_ref()
            .is_none_or(|s| s.served >= REQUESTS_PER_SERVER)
        {
            *server = None;
            *server = Some(Server::start());
        }
        let Some(s) = server.as_mut() else {
            return (vec![finding("harness", "no server")], false);
        };
        s.served += 1;
        let port = s.port.to_string();
        let request = String::from_utf8_lossy(input).replace("{PORT}", &port);
        let found = judge(&request, s.port, limits);
        if found
            .iter()
            .any(|f| f.class != "ok" && f.class != "error_ok")
        {
            // A fresh server for the next case: failures stay apart.
            *server = None;
        }
        (found, false)
    }
}

/// Sends `request` and returns the status and body, or why not.
fn send(port: u16, request: &[u8], limits: &Limits) -> Result<(u16, String), String> {
    let mut stream =
        TcpStream::connect(("127.0.0.1", port)).map_err(|e| format!("connect: {e}"))?;
    stream.set_read_timeout(Some(limits.hang)).ok();
    stream.set_write_timeout(Some(limits.hang)).ok();
    // A server that closes early (a refused request) may reset the rest of the write.
    let _ = stream.write_all(request);
    // Read until the answer is whole (its head and as much body as it says), or the server
    // closes: a kept-alive connection (a request whose `Connection: close` was mutated away)
    // stays open after a whole answer.
    // The answer to a HEAD request has a `Content-Length` and, rightly, no body (RFC 9110
    // §9.3.2): it is whole once its head ends.
    let head_only = request.starts_with(b"HEAD ");
    let mut answer = Vec::new();
    let mut piece = [0u8; 8192];
    loop {
        match stream.read(&mut piece) {
            Ok(0) => break,
            Ok(n) => {
                answer.extend_from_slice(&piece[..n]);
                if whole(&answer, head_only) {
                    break;
                }
            }
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                return Err("hang".into());
            }
            Err(_) => break,
        }
    }
    let text = String::from_utf8_lossy(&answer).into_owned();
    let status = text
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let body = text.split_once("\r\n\r\n").map_or("", |x| x.1).to_owned();
    Ok((status, body))
}

/// Whether an answer has its head and the body its `Content-Length` gives (the head alone
/// for the answer to a HEAD request).
fn whole(answer: &[u8], head_only: bool) -> bool {
    let text = String::from_utf8_lossy(answer);
    let Some((head, body)) = text.split_once("\r\n\r\n") else {
        return false;
    };
    if head_only {
        return true;
    }
    head.split("\r\n")
        .filter_map(|l| l.split_once(':'))
        .find(|(k, _)| k.trim().eq_ignore_ascii_case("content-length"))
        .and_then(|(_, v)| v.trim().parse::<usize>().ok())
        .is_some_and(|n| body.len() >= n)
}

/// Whether the request names this server in `Host` and, if it has one, in `Origin`.
fn own(request: &str, port: u16) -> bool {
    let head = request.split("\r\n\r\n").next().unwrap_or("");
    let header = |name: &str| -> Vec<&str> {
        head.split("\r\n")
            .skip(1)
            .filter_map(|l| l.split_once(':'))
            .filter(|(k, _)| k.trim().eq_ignore_ascii_case(name))
            .map(|(_, v)| v.trim())
            .collect()
    };
    let names: Vec<String> = ["127.0.0.1", "localhost", "[::1]"]
        .iter()
        .map(|n| format!("{n}:{port}"))
        .collect();
    let hosts = header("host");
    let origins = header("origin");
    let [host] = hosts[..] else { return false };
    names.iter().any(|n| n.eq_ignore_ascii_case(host))
        && origins.len() <= 1
        && origins.first().is_none_or(|o| {
            o.strip_prefix("http://")
                .is_some_and(|r| r.eq_ignore_ascii_case(host))
        })
}

/// Whether the request is whole: its head ends, and its body is as long as it says. A
/// server rightly waits for the rest of one that is not.
fn complete(request: &str) -> bool {
    let Some((head, body)) = request.split_once("\r\n\r\n") else {
        return false;
    };
    let declared = head
        .split("\r\n")
        .filter_map(|l| l.split_once(':'))
        .find(|(k, _)| k.trim().eq_ignore_ascii_case("content-length"))
        .map(|(_, v)| v.trim().parse::<usize>());
    !matches!(declared, Some(Ok(n)) if n > body.len())
}

fn judge(request: &str, port: u16, limits: &Limits) -> Vec<Finding> {
    if !complete(request) {
        // Sent, left waiting briefly; whatever the server does then is its right.
        let short = Limits {
            hang: std::time::Duration::from_millis(100),
            ..Limits::from_env()
        };
        let _ = send(port, request.as_bytes(), &short);
        return vec![finding("error_ok", "an incomplete request")];
    }
    let (status, body) = match send(port, request.as_bytes(), limits) {
        Ok(x) => x,
        Err(e) if e == "hang" => return vec![finding("hang", "no answer in time")],
        Err(e) => return vec![finding("harness", e)],
    };
    let mut found = Vec::new();
    if (200..300).contains(&status) && !own(request, port) {
        found.push(finding(
            "accepted_foreign_host",
            format!(
                "{status} for a request naming another server: {}",
                request.lines().take(4).collect::<Vec<_>>().join(" | ")
            ),
        ));
    }
    if status >= 500 || status == 0 {
        found.push(finding("server_error", format!("status {status}: {body}")));
    }
    let line = request.lines().next().unwrap_or("");
    let changes = line.starts_with("POST /api/edit ") || line.starts_with("POST /api/reset ");
    if changes && (200..300).contains(&status) {
        let get = format!(
            "GET /api/scenario.toml HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n"
        );
        match send(port, get.as_bytes(), limits) {
            Ok((200, text)) => {
                let checked = load_text(&text, "download.toml").and_then(|loaded| {
                    let quick = Overrides {
                        samples: Some(16),
                        ..Default::default()
                    };
                    pipeline(&loaded, &quick, None).map(drop)
                });
                if let Err(e) = checked {
                    found.push(finding(
                        "accepted_invalid_value",
                        format!("an accepted edit left a file `check` refuses: {e}"),
                    ));
                }
            }
            Ok((status, body)) => found.push(finding(
                "server_error",
                format!("download: {status} {body}"),
            )),
            Err(e) => found.push(finding("hang", format!("download: {e}"))),
        }
    }
    if found.is_empty() {
        let class = if (200..300).contains(&status) {
            "ok"
        } else {
            "error_ok"
        };
        found.push(finding(class, format!("{status}")));
    }
    found
}
