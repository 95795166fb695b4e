//! Opening a [`Sink`] as a Rerun recording stream, and closing it so that what the user
//! sees (a file, a viewer, a web page) is complete.

use std::any::Any;
use std::io::IsTerminal as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use ::rerun as rr;

use super::{APPLICATION_ID, RecordingIds, Sink, SinkError, find_native_viewer, send_layout};
use crate::scene::Scene;

/// How long a flush to a remote viewer may take before we give up.
const REMOTE_FLUSH_TIMEOUT: Duration = Duration::from_secs(15);

/// Keeps what a sink needs alive (a web server, a temporary file) and finishes it.
///
/// Dropping a guard without [`finish`](Self::finish) removes a `--save` temporary file: a
/// half-written recording is never left under the requested name.
#[must_use = "call finish() so files are completed and viewers receive everything"]
pub struct SinkGuard {
    kind: GuardKind,
}

enum GuardKind {
    Plain {
        remote: bool,
    },
    Save {
        tmp: PathBuf,
        target: PathBuf,
        done: bool,
    },
    Serve {
        _web: Box<dyn Any + Send>,
        url: String,
        /// The web viewer's files and the gRPC server (both loopback).
        addrs: (std::net::SocketAddr, std::net::SocketAddr),
    },
    Memory(rr::sink::MemorySinkStorage),
    Stdout(rr::sink::MemorySinkStorage),
}

/// Opens `sink` as a recording stream with fixed ids, the default layout, and no recording
/// properties (start time) — see the module docs on deterministic content.
///
/// # Errors
/// [`SinkError::Io`] when a `--save` file cannot be created or stdout is a terminal;
/// [`SinkError::NoViewer`] for [`Sink::Spawn`] without a rerun 0.36 viewer;
/// [`SinkError::WebViewer`] when a port is taken; other SDK errors.
pub fn open_stream(
    sink: &Sink,
    ids: &RecordingIds,
    scene: &Scene,
) -> Result<(rr::RecordingStream, SinkGuard), SinkError> {
    let builder = rr::RecordingStreamBuilder::new(APPLICATION_ID)
        .recording_id(ids.recording_id.clone())
        .send_properties(false);
    let plain = |remote| GuardKind::Plain { remote };
    let (rec, kind) = match sink {
        Sink::Save(target) => {
            let tmp = temporary_sibling(target);
            let rec = builder.save(&tmp)?;
            let target = target.clone();
            (
                rec,
                GuardKind::Save {
                    tmp,
                    target,
                    done: false,
                },
            )
        }
        Sink::Stdout => {
            if std::io::stdout().is_terminal() {
                return Err(SinkError::Io {
                    action: "writing a recording to",
                    path: "stdout".into(),
                    source: std::io::Error::other(
                        "stdout is a terminal; pipe it, e.g. `posecov camera_on_robot --stdout | rerun -`",
                    ),
                });
            }
            // Kept in memory and written whole when finished: a reader that closes the pipe
            // early (`| head -c 10`) then ends the run at once and quietly, which the SDK's
            // stdout writer thread does not (it can hang or report a shutdown).
            let (rec, storage) = builder.memory()?;
            (rec, GuardKind::Stdout(storage))
        }
        Sink::Spawn => {
            let viewer = find_native_viewer()?;
            let opts = rr::SpawnOptions {
                executable_path: Some(viewer.path.display().to_string()),
                ..Default::default()
            };
            (builder.spawn_opts(&opts)?, plain(true))
        }
        Sink::Connect(url) => (builder.connect_grpc_opts(url.clone())?, plain(true)),
        Sink::Serve {
            web_port,
            grpc_port,
            open_browser,
        } => serve(builder, *web_port, *grpc_port, *open_browser)?,
        Sink::Memory => {
            let (rec, storage) = builder.memory()?;
            (rec, GuardKind::Memory(storage))
        }
    };
    rec.set_log_time_enabled(false);
    rec.set_log_tick_enabled(false);
    send_layout(&rec, scene)?;
    Ok((rec, SinkGuard { kind }))
}

/// Whether `127.0.0.1:port` can be listened on now (`flag` names it in the error).
///
/// # Errors
/// [`SinkError::Port`] with the OS's reason.
fn port_available(flag: &'static str, port: u16) -> Result<(), SinkError> {
    std::net::TcpListener::bind(("127.0.0.1", port))
        .map(drop)
        .map_err(|e| SinkError::Port {
            flag,
            port,
            reason: e.to_string(),
        })
}

fn serve(
    builder: rr::RecordingStreamBuilder,
    web_port: u16,
    grpc_port: u16,
    open_browser: bool,
) -> Result<(rr::RecordingStream, GuardKind), SinkError> {
    // The SDK's gRPC server binds on its own thread and, on a port in use, only fails later
    // ("gRPC server thread shut down"): check both ports first, before anything is served.
    for (flag, port) in [("--grpc-port", grpc_port), ("--web-port", web_port)] {
        port_available(flag, port)?;
    }
    let rec = builder.serve_grpc_opts("127.0.0.1", grpc_port, rr::ServerOptions::default())?;
    let grpc_url = format!("rerun+http://127.0.0.1:{grpc_port}/proxy");
    let web = rr::serve_web_viewer(rr::web_viewer::WebViewerConfig {
        bind_ip: "127.0.0.1".into(),
        web_port: web_port.into(),
        connect_to: vec![grpc_url.clone()],
        open_browser,
        ..Default::default()
    })
    .map_err(|err| SinkError::WebViewer(err.to_string()))?;
    let url = format!("{}/?url={}", web.server_url(), percent_encode(&grpc_url));
    let web_addr = web
        .server_url()
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .parse()
        .map_err(|e| SinkError::WebViewer(format!("{}: {e}", web.server_url())))?;
    let grpc_addr = std::net::SocketAddr::from(([127, 0, 0, 1], grpc_port));
    Ok((
        rec,
        GuardKind::Serve {
            _web: Box::new(web),
            url,
            addrs: (web_addr, grpc_addr),
        },
    ))
}

/// Percent-encodes everything but ASCII alphanumerics (what the web viewer's `url=` expects).
fn percent_encode(s: &str) -> String {
    s.bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() {
                char::from(b).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect()
}

/// `dir/.name.partial-<pid>`: same directory (so the final rename is atomic), hidden, and
/// unique per process.
fn temporary_sibling(target: &Path) -> PathBuf {
    let name = target.file_name().map_or_else(
        || "recording.rrd".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    target.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

impl SinkGuard {
    /// The URL to open in a browser, for [`Sink::Serve`].
    pub fn viewer_url(&self) -> Option<&str> {
        match &self.kind {
            GuardKind::Serve { url, .. } => Some(url),
            _ => None,
        }
    }

    /// For [`Sink::Serve`]: where the web viewer's files and its gRPC stream are served
    /// (both on loopback), for a page that shows the viewer through itself.
    pub fn served_addrs(&self) -> Option<(std::net::SocketAddr, std::net::SocketAddr)> {
        match &self.kind {
            GuardKind::Serve { addrs, .. } => Some(*addrs),
            _ => None,
        }
    }

    /// For [`Sink::Serve`]: keeps serving until `cancel` is raised or `limit` has passed
    /// (`None`: no limit). Returns at once for other sinks.
    pub fn serve_until(&self, cancel: &AtomicBool, limit: Option<Duration>) {
        if !matches!(self.kind, GuardKind::Serve { .. }) {
            return;
        }
        let start = Instant::now();
        while !cancel.load(Ordering::Relaxed) && limit.is_none_or(|l| start.elapsed() < l) {
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Flushes everything logged to `rec` and closes the sink: a `--save` file gets its
    /// footer and is renamed to its final name; a remote viewer receives everything (within
    /// a timeout); a served web viewer stops. Returns the bytes for [`Sink::Memory`].
    ///
    /// # Errors
    /// [`SinkError::Flush`] when data could not be delivered, [`SinkError::Io`] when the
    /// rename fails.
    pub fn finish(mut self, rec: rr::RecordingStream) -> Result<Option<Vec<u8>>, SinkError> {
        match &mut self.kind {
            GuardKind::Save { tmp, target, done } => {
                rec.flush_blocking()
                    .map_err(|err| SinkError::Flush(err.to_string()))?;
                // Writes the footer and joins the writer thread.
                rec.finalize_deferred_sinks();
                drop(rec);
                std::fs::rename(&*tmp, &*target).map_err(|source| SinkError::Io {
                    action: "renaming the finished recording to",
                    path: target.clone(),
                    source,
                })?;
                *done = true;
                Ok(None)
            }
            GuardKind::Plain { remote } => {
                let flushed = if *remote {
                    rec.flush_with_timeout(REMOTE_FLUSH_TIMEOUT)
                } else {
                    rec.flush_blocking()
                };
                flushed.map_err(|err| SinkError::Flush(err.to_string()))?;
                Ok(None)
            }
            GuardKind::Serve { .. } => {
                rec.flush_with_timeout(REMOTE_FLUSH_TIMEOUT)
                    .map_err(|err| SinkError::Flush(err.to_string()))?;
                drop(rec);
                Ok(None)
            }
            GuardKind::Stdout(storage) => {
                let bytes = storage
                    .drain_as_bytes()
                    .map_err(|err| SinkError::Flush(err.to_string()))?;
                write_stdout(&bytes)?;
                Ok(None)
            }
            GuardKind::Memory(storage) => storage
                .drain_as_bytes()
                .map(Some)
                .map_err(|err| SinkError::Flush(err.to_string())),
        }
    }
}

/// Writes a finished recording to stdout. A reader that closed the pipe (`| head -c 10`)
/// wanted no more: that is not an error (as `ripgrep` and `cat` do).
fn write_stdout(bytes: &[u8]) -> Result<(), SinkError> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        result => result.map_err(|source| SinkError::Io {
            action: "writing a recording to",
            path: "stdout".into(),
            source,
        }),
    }
}

impl Drop for SinkGuard {
    fn drop(&mut self) {
        if let GuardKind::Save {
            tmp, done: false, ..
        } = &self.kind
        {
            // Best effort: the writer may still hold it open, which is fine on Unix.
            std::fs::remove_file(tmp).ok();
        }
    }
}

/// Logs `scene` into an in-memory recording and returns the complete .rrd bytes (tests,
/// golden files). Uses the same path as every other sink, with ids `ids`.
///
/// # Errors
/// Anything [`log_scene`](super::log_scene) or [`SinkGuard::finish`] returns.
///
/// ```
/// use posecov::{scene::Scene, sink::{RecordingIds, scene_to_rrd_bytes}};
/// let scene = Scene::new("empty", "Nothing but a description.");
/// let bytes = scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("empty", 0))?;
/// assert!(!bytes.is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn scene_to_rrd_bytes(scene: &Scene, ids: &RecordingIds) -> Result<Vec<u8>, SinkError> {
    let (rec, guard) = open_stream(&Sink::Memory, ids, scene)?;
    super::log_scene(&rec, scene)?;
    Ok(guard.finish(rec)?.unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_file_is_a_hidden_sibling() {
        let tmp = temporary_sibling(Path::new("/a/b/x.rrd"));
        assert_eq!(tmp.parent(), Some(Path::new("/a/b")));
        assert!(
            tmp.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(".x.rrd.partial-"))
        );
    }

    #[test]
    fn percent_encoding_matches_the_notes() {
        assert_eq!(
            percent_encode("rerun+http://127.0.0.1:9876/proxy"),
            "rerun%2Bhttp%3A%2F%2F127%2E0%2E0%2E1%3A9876%2Fproxy"
        );
    }
}
