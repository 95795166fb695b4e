//! Where a picture goes, shared by every path that shows one (a scenario, a robot log, live
//! mode, `--watch`): the viewer options, the sink chosen (a native viewer if found, else the
//! embedded web viewer), served for as long as asked, finished with the exit code, and `--png`
//! rendering. Nothing here evaluates or draws.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use super::{AppError, Overrides, SettingsError};
use crate::scene::Scene;
use crate::sink::{
    LogOutcome, RecordingIds, Sink, SinkError, SinkGuard, find_native_viewer, open_stream,
    render_png,
};

pub use super::EXIT_INTERRUPTED;
/// Environment variable bounding how long a served viewer is served (seconds), e.g. for CI.
pub const SERVE_SECONDS_ENV: &str = "POSECOV_SERVE_SECONDS";

/// Where and how to show a scenario.
#[derive(Debug, Clone)]
pub struct ViewOptions {
    /// Bundled name or file.
    pub scenario: String,
    /// Command-line overrides.
    pub overrides: Overrides,
    /// The sink, or `None` for the default (a native viewer if found, else serve).
    pub sink: Option<Sink>,
    /// Web viewer port, gRPC port and whether to open a browser (for serving).
    pub serve: ServeOptions,
    /// Re-evaluate and re-stream on every change of the file.
    pub watch: bool,
    /// Render a PNG (needs the native viewer) of this size in points.
    pub png: Option<(PathBuf, (u32, u32))>,
}

/// Options of a served web viewer.
#[derive(Debug, Clone, Copy)]
pub struct ServeOptions {
    /// HTTP port of the web viewer.
    pub web_port: u16,
    /// gRPC port the web viewer reads from.
    pub grpc_port: u16,
    /// Stop after this many seconds (else `$POSECOV_SERVE_SECONDS`, else Ctrl-C).
    pub seconds: Option<u64>,
    /// Open the default browser.
    pub open_browser: bool,
}

/// Hands everything logged so far to the sink (before the next block is simulated).
pub(crate) fn flush(rec: &rerun::RecordingStream) -> Result<(), AppError> {
    rec.flush_blocking()
        .map_err(|e| AppError::Sink(SinkError::Flush(e.to_string())))
}

/// How often `--watch` looks at the file's modification time.
pub(crate) const WATCH_POLL: Duration = Duration::from_millis(300);

/// The one watch loop of `--watch`: every [`WATCH_POLL`] until Ctrl-C (or `limit` has
/// passed), `tick` is called with whether `path`'s modification time changed since the last
/// call (at the first call: whether the file exists, when `first_counts`). `tick` returns
/// `Some(code)` to stop with that exit code; the loop ends with 0.
///
/// # Errors
/// What `tick` returns.
pub(crate) fn watch_file(
    path: &Path,
    first_counts: bool,
    cancel: &AtomicBool,
    limit: Option<Duration>,
    mut tick: impl FnMut(bool) -> Result<Option<u8>, AppError>,
) -> Result<u8, AppError> {
    let modified = || std::fs::metadata(path).and_then(|m| m.modified()).ok();
    let mut last_seen = if first_counts { None } else { modified() };
    let start = std::time::Instant::now();
    while !cancel.load(std::sync::atomic::Ordering::Relaxed)
        && limit.is_none_or(|l| start.elapsed() < l)
    {
        let now = modified();
        let changed = now != last_seen;
        last_seen = now;
        if let Some(code) = tick(changed)? {
            return Ok(code);
        }
        std::thread::sleep(WATCH_POLL);
    }
    Ok(0)
}

/// Name used in the recording id and in file names offered for download: a bundled name as
/// is, a file by its stem.
pub(crate) fn scenario_name(scenario: &str) -> String {
    Path::new(scenario)
        .file_stem()
        .map_or_else(|| scenario.to_owned(), |s| s.to_string_lossy().into_owned())
}

/// Keeps a served web viewer up: for `options.seconds` (else `$POSECOV_SERVE_SECONDS`), or
/// until Ctrl-C.
pub(crate) fn serve(
    options: &ServeOptions,
    guard: &SinkGuard,
    cancel: &AtomicBool,
) -> Result<(), AppError> {
    let limit = serve_limit(options)?;
    say_serving(limit);
    guard.serve_until(cancel, limit);
    Ok(())
}

/// Tells the user how long a server stays up.
pub(crate) fn say_serving(limit: Option<Duration>) {
    match limit {
        Some(l) => eprintln!("Serving for {} s (Ctrl-C stops).", l.as_secs()),
        None => eprintln!("Serving until Ctrl-C."),
    }
}

/// Closes the sink (a `--save` file is written whole now) and returns the exit code: 0, or
/// [`EXIT_INTERRUPTED`] when Ctrl-C cut the logging short.
pub(crate) fn finish(
    guard: SinkGuard,
    rec: rerun::RecordingStream,
    sink: &Sink,
    outcome: LogOutcome,
) -> Result<u8, AppError> {
    guard.finish(rec)?;
    if let Sink::Save(path) = sink {
        eprintln!("Wrote {}", path.display());
    }
    Ok(match outcome {
        LogOutcome::Complete => 0,
        LogOutcome::Cancelled { .. } => EXIT_INTERRUPTED,
    })
}

/// The sink asked for; without one: a native 0.36 viewer if available, else serve.
pub(crate) fn choose_sink(options: &ViewOptions) -> Result<Sink, AppError> {
    if let Some(sink) = &options.sink {
        return Ok(sink.clone());
    }
    let serve = Sink::Serve {
        web_port: options.serve.web_port,
        grpc_port: options.serve.grpc_port,
        open_browser: options.serve.open_browser,
    };
    Ok(match find_native_viewer() {
        Ok(_) => Sink::Spawn,
        Err(why) => {
            eprintln!("{why}\nServing the embedded web viewer instead.");
            serve
        }
    })
}

/// How long a server stays up: `--serve-seconds`, else `$POSECOV_SERVE_SECONDS`, else until
/// Ctrl-C (`None`).
pub(crate) fn serve_limit(options: &ServeOptions) -> Result<Option<Duration>, AppError> {
    if let Some(s) = options.seconds {
        return Ok(Some(Duration::from_secs(s)));
    }
    match std::env::var(SERVE_SECONDS_ENV) {
        Ok(s) => {
            let secs: u64 = s.trim().parse().map_err(|_| SettingsError::OutOfRange {
                flag: "$POSECOV_SERVE_SECONDS",
                value: format!("{s:?}"),
                expected: "a whole number of seconds".to_owned(),
            })?;
            Ok(Some(Duration::from_secs(secs)))
        }
        Err(_) => Ok(None),
    }
}

/// Saves a scene to an .rrd (`--save`, else a temporary file) with `log`, then renders it to
/// `png` in the native viewer.
pub(crate) fn render_with(
    options: &ViewOptions,
    scene: &Scene,
    log: &dyn Fn(&rerun::RecordingStream) -> Result<LogOutcome, AppError>,
    ids: &RecordingIds,
    png: &Path,
    size: (u32, u32),
) -> Result<u8, AppError> {
    let viewer = find_native_viewer()?;
    let (rrd, temporary) = match &options.sink {
        Some(Sink::Save(path)) => (path.clone(), false),
        _ => (
            std::env::temp_dir().join(format!("posecov-{}.rrd", std::process::id())),
            true,
        ),
    };
    let sink = Sink::Save(rrd.clone());
    let (rec, guard) = open_stream(&sink, ids, scene)?;
    let outcome = log(&rec)?;
    guard.finish(rec)?;
    if outcome != LogOutcome::Complete {
        return Ok(EXIT_INTERRUPTED);
    }
    let rendered = render_png(&viewer, &rrd, png, size);
    if temporary {
        std::fs::remove_file(&rrd).ok();
    }
    rendered?;
    eprintln!("Wrote {}", png.display());
    Ok(0)
}
