//! The control page and its JSON API, served on loopback unless `--bind` says otherwise.
//!
//! | request | answer |
//! |---|---|
//! | `GET /` | the page (controls; beside them the web viewer when one is served) |
//! | `GET /api/state` | title, controls, status, viewer URL, whether saving to disk is possible |
//! | `GET /api/status` | the evaluation status (generation shown, progress, timings, error) |
//! | `POST /api/edit` `{"id", "value"}` | 200 with the new state, or 422 `{"error", "field"}` |
//! | `POST /api/reset` | back to the file's values |
//! | `POST /api/reframe` | the picture again with the layout, cameras fitted to it |
//! | `POST /api/save` | writes the current scenario to the `--save-scenario` file |
//! | `GET /api/scenario.toml` | the current scenario as a download |
//! | `/viewer/…`, `/rerun.…` | the served web viewer and its stream, forwarded to its loopback servers ([`proxy`](super::proxy)) |
//!
//! Every request must name this server in `Host` (and in `Origin` when a browser sends one),
//! so a page elsewhere cannot drive it (nor a DNS-rebinding name); `POST`s must carry JSON,
//! which a cross-site form cannot send. The page never names a path: saving goes to the
//! file given on the command line.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use axum::Router;
use axum::body::{Body, Bytes};
use axum::extract::State;
use axum::http::{HeaderMap, HeaderValue, Method, StatusCode, Uri, header};
use axum::response::Response;
use serde_json::{Value as Json, json};

use super::document::{Edit, EditError};
use super::proxy::{self, Upstream};
use super::worker::Live;
use crate::app::AppError;

const PAGE: &str = include_str!("../../../assets/live/index.html");
const SCRIPT: &str = include_str!("../../../assets/live/live.js");
const STYLE: &str = include_str!("../../../assets/live/live.css");

/// Largest request body accepted (an edit is a few dozen bytes).
const MAX_BODY: usize = 64 * 1024;

/// How the page is served.
#[derive(Clone, Debug)]
pub struct PageOptions {
    /// The web viewer to show beside the controls, if one is served.
    pub viewer_url: Option<String>,
    /// The served viewer's loopback servers: the page then shows the viewer through itself
    /// (same origin, see [`Upstream`]), so whoever reaches the page gets the viewer.
    pub upstream: Option<Upstream>,
    /// Where "save" writes (`--save-scenario`); `None`: download only.
    pub save_to: Option<PathBuf>,
}

struct App {
    live: Arc<Live>,
    options: PageOptions,
    /// `host:port` values that name this server.
    hosts: Vec<String>,
    /// Bound to every interface (`--bind 0.0.0.0:…`).
    open: bool,
}

/// Listens on `addr` for the page (port 0: any free port). Done before the viewer starts, so
/// a port in use stops live mode before anything is shown.
///
/// # Errors
/// [`AppError::Live`] naming `--bind` and the address, with a way out when the port is taken.
///
/// ```
/// let listener = posecov::app::live::bind_page("127.0.0.1:0".parse().unwrap()).unwrap();
/// let port = listener.local_addr().unwrap().port();
/// let taken = posecov::app::live::bind_page(format!("127.0.0.1:{port}").parse().unwrap());
/// assert!(taken.unwrap_err().to_string().contains("--bind 127.0.0.1:0"));
/// ```
pub fn bind_page(addr: SocketAddr) -> Result<std::net::TcpListener, AppError> {
    std::net::TcpListener::bind(addr).map_err(|e| {
        let hint = if e.kind() == std::io::ErrorKind::AddrInUse {
            format!(
                " (another `posecov live`? give another port, or `--bind {}:0` for any free one)",
                addr.ip()
            )
        } else {
            String::new()
        };
        AppError::Live(format!("--bind {addr}: {e}{hint}"))
    })
}

/// Serves the page on `listener` ([`bind_page`]) until `cancel` is raised or `limit` has
/// passed; calls `ready` with the page's URL.
///
/// # Errors
/// [`AppError::Live`] when the address cannot be bound.
///
/// ```no_run
/// # use std::sync::{Arc, atomic::AtomicBool};
/// # use posecov::app::live::{Live, LiveDocument, PageOptions, bind_page, serve_page};
/// # use posecov::sink::{RecordingIds, Sink, open_stream};
/// let doc = LiveDocument::open("camera_on_robot").unwrap();
/// let layout = posecov::scene::Scene::new("camera", "");
/// let (rec, guard) = open_stream(&Sink::Spawn, &RecordingIds::for_scenario("camera", 7), &layout).unwrap();
/// let live = Live::start(doc, rec, guard, Default::default());
/// let listener = bind_page("127.0.0.1:9091".parse().unwrap()).unwrap();
/// let page = PageOptions { viewer_url: None, upstream: None, save_to: None };
/// serve_page(live, listener, page, Arc::new(AtomicBool::new(false)), None, |url| println!("Controls: {url}")).unwrap();
/// ```
pub fn serve_page(
    live: Arc<Live>,
    listener: std::net::TcpListener,
    options: PageOptions,
    cancel: Arc<AtomicBool>,
    limit: Option<Duration>,
    ready: impl FnOnce(&str),
) -> Result<(), AppError> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| AppError::Live(format!("starting the page server: {e}")))?;
    listener
        .set_nonblocking(true)
        .map_err(|e| AppError::Live(e.to_string()))?;
    let addr = listener
        .local_addr()
        .map_err(|e| AppError::Live(e.to_string()))?;
    let hosts = hosts_of(addr, machine_name().as_deref());
    let url = format!("http://{}/", hosts[0]);
    let app = Arc::new(App {
        live,
        options,
        hosts,
        open: addr.ip().is_unspecified(),
    });
    let router = Router::new().fallback(handle).with_state(app);
    ready(&url);
    let start = Instant::now();
    let stopped = move || {
        let cancel = Arc::clone(&cancel);
        async move {
            while !cancel.load(Ordering::Relaxed) && limit.is_none_or(|l| start.elapsed() < l) {
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
        }
    };
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)
            .map_err(|e| AppError::Live(e.to_string()))?;
        let server = std::future::IntoFuture::into_future(
            axum::serve(listener, router).with_graceful_shutdown(stopped()),
        );
        // A viewer's stream never ends by itself: a second after the stop, whatever is still
        // open is dropped with the runtime.
        let stop = stopped();
        tokio::select! {
            served = server => served.map_err(|e| AppError::Live(format!("serving the page: {e}"))),
            () = async { stop.await; tokio::time::sleep(Duration::from_secs(1)).await } => Ok(()),
        }
    })
}

/// The `Host` values that name a server listening on `addr`: the address itself, for
/// loopback `localhost` too, and bound to every interface also this machine's own name
/// (`machine`, e.g. `lab-pc` and `lab-pc.local`).
fn hosts_of(addr: SocketAddr, machine: Option<&str>) -> Vec<String> {
    let port = addr.port();
    let mut hosts = vec![match addr {
        SocketAddr::V4(a) if a.ip().is_unspecified() => format!("127.0.0.1:{port}"),
        SocketAddr::V6(a) if a.ip().is_unspecified() => format!("[::1]:{port}"),
        a => a.to_string(),
    }];
    if addr.ip().is_loopback() || addr.ip().is_unspecified() {
        hosts.push(format!("localhost:{port}"));
        hosts.push(format!("127.0.0.1:{port}"));
        hosts.push(format!("[::1]:{port}"));
    }
    if let (true, Some(name)) = (addr.ip().is_unspecified(), machine) {
        hosts.push(format!("{name}:{port}"));
        hosts.push(format!("{name}.local:{port}"));
    }
    hosts.dedup();
    hosts
}

/// This machine's host name (Linux: the kernel's), for `--bind` to every interface.
fn machine_name() -> Option<String> {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|path| std::fs::read_to_string(path).ok())
        .map(|name| name.trim().to_owned())
        .filter(|name| !name.is_empty())
}

/// Whether the request comes from this server's own page (see the module docs). `hosts`:
/// the `host:port` values naming this server; `open`: bound to every interface (`--bind
/// 0.0.0.0:…`), where an IP address with this port is accepted too (whichever interface
/// the request came in on). A DNS name other than this machine's own is refused even then:
/// a foreign name that resolves to this machine is how DNS rebinding reaches it.
fn allowed(
    hosts: &[String],
    open: bool,
    method: &Method,
    path: &str,
    headers: &HeaderMap,
) -> Result<(), &'static str> {
    let host = headers
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .ok_or("a Host header is required")?;
    let port = hosts[0].rsplit_once(':').map_or("", |x| x.1);
    let ip_literal = |name: &str| {
        name.parse::<std::net::IpAddr>().is_ok()
            || name
                .strip_prefix('[')
                .and_then(|n| n.strip_suffix(']'))
                .is_some_and(|n| n.parse::<std::net::Ipv6Addr>().is_ok())
    };
    let own = hosts.iter().any(|o| o.eq_ignore_ascii_case(host))
        || open
            && host
                .rsplit_once(':')
                .is_some_and(|(name, p)| p == port && ip_literal(name));
    if !own {
        return Err("Host is not this server");
    }
    if let Some(origin) = headers.get(header::ORIGIN) {
        let origin = origin.to_str().map_err(|_| "bad Origin")?;
        let Some(rest) = origin.strip_prefix("http://") else {
            return Err("Origin is not this server");
        };
        if !rest.eq_ignore_ascii_case(host) {
            return Err("Origin is not this server");
        }
    }
    if method == Method::POST {
        // Neither type is one a cross-site form can send.
        let (wanted, why) = if proxy::is_viewer_path(path) {
            (
                "application/grpc-web",
                "the viewer's POSTs must be application/grpc-web",
            )
        } else {
            ("application/json", "POST bodies must be application/json")
        };
        let typed = headers
            .get(header::CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .is_some_and(|v| v.starts_with(wanted));
        if !typed {
            return Err(why);
        }
    }
    Ok(())
}

async fn handle(
    State(app): State<Arc<App>>,
    method: Method,
    uri: Uri,
    headers: HeaderMap,
    body: Bytes,
) -> Response {
    if let Err(why) = allowed(&app.hosts, app.open, &method, uri.path(), &headers) {
        return reply(StatusCode::FORBIDDEN, &json!({ "error": why }));
    }
    if body.len() > MAX_BODY {
        return reply(
            StatusCode::PAYLOAD_TOO_LARGE,
            &json!({ "error": "body too large" }),
        );
    }
    let forwarded = app.options.upstream.as_ref().and_then(|up| {
        let path = uri.path_and_query().map_or(uri.path(), |p| p.as_str());
        proxy::target(up, path)
    });
    if let Some((to, path)) = forwarded {
        return proxy::forward(to, path, method, &headers, body).await;
    }
    let app2 = Arc::clone(&app);
    let path = uri.path().to_owned();
    // The document and the evaluation thread use blocking locks: keep them off the runtime.
    tokio::task::spawn_blocking(move || route(&app2, &method, &path, &body))
        .await
        .unwrap_or_else(|_| {
            reply(
                StatusCode::INTERNAL_SERVER_ERROR,
                &json!({ "error": "panic" }),
            )
        })
}

fn route(app: &App, method: &Method, path: &str, body: &[u8]) -> Response {
    match (method.as_str(), path) {
        ("GET", "/") => asset(PAGE, "text/html; charset=utf-8"),
        ("GET", "/live.js") => asset(SCRIPT, "text/javascript; charset=utf-8"),
        ("GET", "/live.css") => asset(STYLE, "text/css; charset=utf-8"),
        ("GET", "/api/state") => reply(StatusCode::OK, &state(app)),
        ("GET", "/api/status") => reply(StatusCode::OK, &json!(app.live.status())),
        ("GET", "/api/scenario.toml") => download(app),
        ("POST", "/api/edit") => match serde_json::from_slice::<Edit>(body) {
            Err(_) => {
                // Name the control when the request does (never serde's enum names).
                let id = serde_json::from_slice::<Json>(body)
                    .ok()
                    .and_then(|v| v.get("id").and_then(Json::as_str).map(str::to_owned));
                let error = match &id {
                    Some(id) => {
                        format!("{id}: the value must be a number, or true/false for a switch")
                    }
                    None => "expected {\"id\": …, \"value\": a number, or true/false for a switch}"
                        .to_owned(),
                };
                reply(
                    StatusCode::BAD_REQUEST,
                    &json!({ "error": error, "field": id }),
                )
            }
            Ok(edit) => match app.live.apply(&edit) {
                Ok(_) => reply(StatusCode::OK, &state(app)),
                Err(e) => refused(&e),
            },
        },
        ("POST", "/api/reset") => match app.live.reset() {
            Ok(_) => reply(StatusCode::OK, &state(app)),
            Err(e) => reply(
                StatusCode::INTERNAL_SERVER_ERROR,
                &json!({ "error": e.to_string() }),
            ),
        },
        ("POST", "/api/save") => save(app),
        ("POST", "/api/reframe") => {
            app.live.reframe();
            reply(StatusCode::OK, &state(app))
        }
        (
            _,
            "/" | "/live.js" | "/live.css" | "/api/state" | "/api/status" | "/api/scenario.toml",
        )
        | (_, "/api/edit" | "/api/reset" | "/api/save" | "/api/reframe") => reply(
            StatusCode::METHOD_NOT_ALLOWED,
            &json!({ "error": "method not allowed" }),
        ),
        _ => reply(StatusCode::NOT_FOUND, &json!({ "error": "not found" })),
    }
}

fn state(app: &App) -> Json {
    let (title, origin, controls) = app.live.with_doc(|d| {
        (
            d.loaded().input.about.title.clone(),
            d.origin().to_owned(),
            d.controls(),
        )
    });
    json!({
        "title": title,
        "origin": origin,
        "controls": controls,
        "status": app.live.status(),
        // Through this server when it can (the page builds the viewer's `?url=` from the
        // host it was reached at), else the viewer's own loopback URL.
        "viewer_url": match app.options.upstream {
            Some(_) => Some(proxy::VIEWER_PATH.to_owned()),
            None => app.options.viewer_url.clone(),
        },
        "viewer_same_origin": app.options.upstream.is_some(),
        "save_to": app.options.save_to.as_ref().map(|p| p.display().to_string()),
    })
}

fn refused(e: &EditError) -> Response {
    reply(
        StatusCode::UNPROCESSABLE_ENTITY,
        &json!({ "error": e.to_string(), "field": e.field() }),
    )
}

fn save(app: &App) -> Response {
    let Some(path) = &app.options.save_to else {
        return reply(
            StatusCode::CONFLICT,
            &json!({ "error": "no file to save to: start with --save-scenario FILE, or use Download" }),
        );
    };
    let text = app.live.with_doc(|d| d.text());
    match write_atomically(path, &text) {
        Ok(()) => reply(
            StatusCode::OK,
            &json!({ "saved": path.display().to_string() }),
        ),
        Err(e) => reply(
            StatusCode::INTERNAL_SERVER_ERROR,
            &json!({ "error": format!("writing {}: {e}", path.display()) }),
        ),
    }
}

/// Writes `text` to a temporary sibling and renames it over `path`: never half a file.
pub(super) fn write_atomically(path: &std::path::Path, text: &str) -> std::io::Result<()> {
    let name = path.file_name().map_or_else(
        || "scenario.toml".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    let tmp = path.with_file_name(format!(".{name}.partial-{}", std::process::id()));
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        std::fs::remove_file(&tmp).ok();
    })
}

fn download(app: &App) -> Response {
    let (text, origin) = app.live.with_doc(|d| (d.text(), d.origin().to_owned()));
    let stem: String =
        crate::app::sinks::scenario_name(origin.split(' ').next().unwrap_or("scenario"))
            .chars()
            .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
            .collect();
    let mut response = asset_owned(text, "application/toml; charset=utf-8");
    if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{stem}_live.toml\"")) {
        response
            .headers_mut()
            .insert(header::CONTENT_DISPOSITION, v);
    }
    response
}

fn asset(text: &'static str, content_type: &'static str) -> Response {
    let mut r = Response::new(Body::from(text));
    r.headers_mut()
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

fn asset_owned(text: String, content_type: &'static str) -> Response {
    let mut r = Response::new(Body::from(text));
    r.headers_mut()
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    r
}

fn reply(status: StatusCode, body: &Json) -> Response {
    let mut r = Response::new(Body::from(body.to_string()));
    *r.status_mut() = status;
    r.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/json"),
    );
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(header::HeaderName, &str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.insert(k.clone(), HeaderValue::from_str(v).unwrap());
        }
        h
    }

    #[test]
    fn only_this_servers_own_page_may_drive_it() {
        let hosts = hosts_of("127.0.0.1:8123".parse().unwrap(), Some("lab-pc"));
        let json = (header::CONTENT_TYPE, "application/json");
        let get = |pairs: &[(header::HeaderName, &str)]| {
            allowed(&hosts, false, &Method::GET, "/api/state", &headers(pairs))
        };
        let post = |pairs: &[(header::HeaderName, &str)]| {
            allowed(&hosts, false, &Method::POST, "/api/edit", &headers(pairs))
        };
        assert!(get(&[(header::HOST, "127.0.0.1:8123")]).is_ok());
        assert!(get(&[(header::HOST, "localhost:8123")]).is_ok());
        assert!(get(&[]).is_err(), "no Host");
        // DNS rebinding: a foreign name that resolves to 127.0.0.1.
        assert!(get(&[(header::HOST, "evil.example:8123")]).is_err());
        assert!(
            post(&[
                (header::HOST, "127.0.0.1:8123"),
                (header::ORIGIN, "http://127.0.0.1:8123"),
                json.clone()
            ])
            .is_ok()
        );
        // Another page in the browser.
        assert!(
            post(&[
                (header::HOST, "127.0.0.1:8123"),
                (header::ORIGIN, "http://evil.example"),
                json.clone()
            ])
            .is_err()
        );
        assert!(
            post(&[
                (header::HOST, "127.0.0.1:8123"),
                (header::ORIGIN, "null"),
                json.clone()
            ])
            .is_err()
        );
        // A cross-site form cannot send JSON.
        assert!(
            post(&[
                (header::HOST, "127.0.0.1:8123"),
                (header::CONTENT_TYPE, "text/plain")
            ])
            .is_err()
        );
        // Opened to the network on purpose: an address of this machine or its own name with
        // this port, still same-origin only; never a foreign name (DNS rebinding).
        let open_hosts = hosts_of("0.0.0.0:8123".parse().unwrap(), Some("lab-pc"));
        let open = |pairs: &[(header::HeaderName, &str)]| {
            allowed(&open_hosts, true, &Method::GET, "/viewer/", &headers(pairs))
        };
        for host in [
            "192.168.1.20:8123",
            "[fe80::1]:8123",
            "lab-pc:8123",
            "LAB-PC.local:8123",
            "localhost:8123",
        ] {
            assert!(open(&[(header::HOST, host)]).is_ok(), "{host}");
        }
        for host in [
            "evil.example:8123",
            "lab-pc.evil.example:8123",
            "192.168.1.20:9999",
            "192.168.1.20",
        ] {
            assert!(open(&[(header::HOST, host)]).is_err(), "{host}");
        }
        assert!(
            open(&[
                (header::HOST, "192.168.1.20:8123"),
                (header::ORIGIN, "http://evil.example")
            ])
            .is_err()
        );
        assert!(
            open(&[
                (header::HOST, "192.168.1.20:8123"),
                (header::ORIGIN, "http://192.168.1.20:8123")
            ])
            .is_ok()
        );
        // The viewer's stream through the page: same checks, and gRPC-web only.
        let grpc = "/rerun.sdk_comms.v1alpha1.MessageProxyService/ReadMessages";
        let viewer_post = |pairs: &[(header::HeaderName, &str)]| {
            allowed(&hosts, false, &Method::POST, grpc, &headers(pairs))
        };
        let grpc_web = (header::CONTENT_TYPE, "application/grpc-web+proto");
        assert!(viewer_post(&[(header::HOST, "127.0.0.1:8123"), grpc_web.clone()]).is_ok());
        assert!(viewer_post(&[(header::HOST, "127.0.0.1:8123"), json.clone()]).is_err());
        assert!(
            viewer_post(&[
                (header::HOST, "127.0.0.1:8123"),
                (header::ORIGIN, "http://evil.example"),
                grpc_web
            ])
            .is_err()
        );
        // Bound to loopback, an IP address is no name of this server unless it is loopback.
        assert!(get(&[(header::HOST, "192.168.1.20:8123")]).is_err());
    }

    #[test]
    fn loopback_hosts_include_localhost() {
        let hosts = hosts_of("127.0.0.1:8123".parse().unwrap(), Some("lab-pc"));
        assert!(hosts.contains(&"127.0.0.1:8123".to_owned()));
        assert!(hosts.contains(&"localhost:8123".to_owned()));
        assert!(!hosts.iter().any(|h| h.starts_with("evil")));
    }
}
