//! One session: evaluate (with a spinner past a moment), draw, log to a sink, then log the
//! clouds of any later Monte Carlo blocks one block at a time. The viewer, `--save`, `--png`
//! and `--watch` all run it.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

use super::{AppError, Loaded, Overrides, Settings, SettingsError, load, resolve};
use crate::draw;
use crate::eval::{self, AnyEvaluation};
use crate::scene::Scene;
use crate::sink::{
    self, LogOutcome, RecordingIds, Sink, SinkError, SinkGuard, find_native_viewer, open_stream,
    render_png,
};

/// Hands everything logged so far to the sink (before the next block is simulated).
fn flush(rec: &rerun::RecordingStream) -> Result<(), AppError> {
    rec.flush_blocking()
        .map_err(|e| AppError::Sink(SinkError::Flush(e.to_string())))
}

/// Exit code after Ctrl-C (128 + SIGINT), as shells expect.
pub const EXIT_INTERRUPTED: u8 = 130;
/// How often `--watch` looks at the file's modification time.
const WATCH_POLL: Duration = Duration::from_millis(300);
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

/// A scenario evaluated and drawn, ready to log.
pub struct Session {
    /// What was loaded.
    pub loaded: Loaded,
    /// The settings resolved for it.
    pub settings: Settings,
    /// The numbers.
    pub evaluation: AnyEvaluation,
    /// The picture (validated).
    pub scene: Scene,
}

impl Session {
    /// Loads, resolves, evaluates (showing a spinner on a terminal after 0.3 s) and draws.
    ///
    /// ```no_run
    /// use posecov::app::{Overrides, session::Session};
    /// let s = Session::start("camera_on_robot", &Overrides::default(), None).unwrap();
    /// assert!(!s.scene.items.is_empty());
    /// ```
    pub fn start(
        scenario: &str,
        overrides: &Overrides,
        cancel: Option<Arc<AtomicBool>>,
    ) -> Result<Self, AppError> {
        let loaded = load(scenario)?;
        with_spinner(&format!("evaluating {scenario}"), || {
            Self::from_loaded(loaded, overrides, cancel)
        })
    }

    /// Resolves, evaluates and draws an input already loaded (live mode: no spinner).
    ///
    /// ```
    /// use posecov::app::{Overrides, load, session::Session};
    /// let loaded = load("camera_on_robot").unwrap();
    /// let s = Session::from_loaded(loaded, &Overrides { samples: Some(64), ..Default::default() }, None).unwrap();
    /// assert!(!s.scene.items.is_empty());
    /// ```
    pub fn from_loaded(
        loaded: Loaded,
        overrides: &Overrides,
        cancel: Option<Arc<AtomicBool>>,
    ) -> Result<Self, AppError> {
        let settings = resolve(&loaded.input, overrides, cancel)?;
        let evaluation = super::evaluate(&loaded, &settings.eval)?;
        let scene = draw::scene(&evaluation, &settings.draw);
        scene.validate()?;
        Ok(Self {
            loaded,
            settings,
            evaluation,
            scene,
        })
    }

    /// How many Monte Carlo blocks beyond the first get logged after the main scene.
    fn later_blocks(&self) -> u64 {
        let (_, n, b, _) = self.evaluation.run();
        (n.div_ceil(b.max(1)) as u64).saturating_sub(1)
    }

    /// Logs the scene, then the clouds of any later Monte Carlo blocks one block at a time
    /// (each re-simulated, drawn, logged, flushed and dropped: memory stays bounded); reports
    /// how far it got if Ctrl-C interrupted it.
    pub fn log(
        &self,
        rec: &rerun::RecordingStream,
        cancel: &AtomicBool,
    ) -> Result<LogOutcome, AppError> {
        let outcome = sink::log_scene_cancellable(rec, &self.scene, cancel)?;
        if outcome != LogOutcome::Complete {
            report_interrupted(outcome);
            return Ok(outcome);
        }
        self.log_blocks(rec, cancel, |part| {
            Ok(sink::log_part_cancellable(rec, &part, cancel)?)
        })
    }

    /// Logs the clouds of the later Monte Carlo blocks (after the scene) with `log_part`,
    /// one block at a time, each re-simulated, drawn, logged, flushed and dropped (memory
    /// stays bounded); reports how far it got if `cancel` interrupted it.
    pub fn log_blocks(
        &self,
        rec: &rerun::RecordingStream,
        cancel: &AtomicBool,
        mut log_part: impl FnMut(Scene) -> Result<LogOutcome, AppError>,
    ) -> Result<LogOutcome, AppError> {
        let mut outcome = LogOutcome::Complete;
        let later = self.later_blocks();
        if later > 0 {
            let bar = ProgressBar::new(later).with_message("logging Monte Carlo blocks");
            bar.set_style(
                ProgressStyle::with_template("{msg} {pos}/{len} ({elapsed}, eta {eta})")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            for k in 1..=later as usize {
                if cancel.load(Ordering::Relaxed) {
                    outcome = LogOutcome::Cancelled { next_step: None };
                    break;
                }
                let plan = &self.loaded.input.plan;
                let Some(block) =
                    eval::evaluate_block(plan, &self.settings.eval, &self.evaluation, k)
                        .map_err(|e| self.loaded.locate(&e))?
                else {
                    break;
                };
                let part = draw::particle_part(&self.evaluation, &block, k, &self.settings.draw);
                drop(block);
                outcome = log_part(part)?;
                flush(rec)?;
                bar.inc(1);
                if outcome != LogOutcome::Complete {
                    break;
                }
            }
            bar.finish_and_clear();
            if outcome != LogOutcome::Complete {
                eprintln!(
                    "Interrupted: recorded the scene and the clouds of the first {} of {} Monte Carlo blocks.",
                    bar.position() + 1,
                    later + 1
                );
            }
        }
        Ok(outcome)
    }

    /// The recording id: the scenario's name (a file by its stem) and the seed in effect.
    fn ids(&self, scenario: &str) -> RecordingIds {
        RecordingIds::for_scenario(&scenario_name(scenario), self.settings.eval.seed)
    }
}

fn report_interrupted(outcome: LogOutcome) {
    if let LogOutcome::Cancelled { next_step } = outcome {
        match next_step {
            Some(k) => eprintln!("Interrupted: recorded the static items and steps before {k}."),
            None => eprintln!("Interrupted: recorded part of the static items."),
        }
    }
}

/// Runs `work`, showing a spinner on a terminal when it takes more than 0.3 s.
fn with_spinner<T>(message: &str, work: impl FnOnce() -> T) -> T {
    let spinner = ProgressBar::new_spinner().with_message(message.to_owned());
    spinner.set_style(
        ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    // indicatif draws only on a terminal; the work wakes the ticker when done.
    let done = AtomicBool::new(false);
    let result = std::thread::scope(|scope| {
        let ticker = scope.spawn(|| {
            let start = std::time::Instant::now();
            while !done.load(Ordering::Acquire) {
                if start.elapsed() > Duration::from_millis(300) {
                    spinner.tick();
                }
                std::thread::park_timeout(Duration::from_millis(80));
            }
        });
        let result = work();
        done.store(true, Ordering::Release);
        ticker.thread().unpark();
        result
    });
    spinner.finish_and_clear();
    result
}

/// Name used in the recording id: a bundled name as is, a file by its stem.
pub(crate) fn scenario_name(scenario: &str) -> String {
    Path::new(scenario)
        .file_stem()
        .map_or_else(|| scenario.to_owned(), |s| s.to_string_lossy().into_owned())
}

/// Shows a scenario: in the viewer, a file, stdout or a PNG; with `watch`, again on every
/// change. Returns the process exit code.
pub fn view(options: &ViewOptions, cancel: &Arc<AtomicBool>) -> Result<u8, AppError> {
    if let Some(place) = super::bag::locate(&options.scenario)? {
        return super::bag::view(options, &place, cancel);
    }
    if options.watch {
        return watch(options, cancel);
    }
    let session = Session::start(
        &options.scenario,
        &options.overrides,
        Some(Arc::clone(cancel)),
    )?;
    let ids = session.ids(&options.scenario);
    if let Some((png, size)) = &options.png {
        return render(options, &session, &ids, png, *size, cancel);
    }
    let sink = choose_sink(options)?;
    let (rec, guard) = open_stream(&sink, &ids, &session.scene)?;
    if let Some(url) = guard.viewer_url() {
        println!("Web viewer: {url}");
    }
    let outcome = session.log(&rec, cancel)?;
    if guard.viewer_url().is_some() && outcome == LogOutcome::Complete {
        serve(&options.serve, &guard, cancel)?;
    }
    finish(guard, rec, &sink, outcome)
}

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

/// `--watch`: evaluate, stream, and again whenever the file changes. A viewer gets one
/// recording re-streamed in place ([`super::live::watch_in_place`]); a `--save` file is
/// rewritten whole on every change. Errors in the file are printed and the previous picture
/// stays up.
fn watch(options: &ViewOptions, cancel: &AtomicBool) -> Result<u8, AppError> {
    let path = PathBuf::from(&options.scenario);
    if !path.is_file() {
        return Err(AppError::Watch(format!(
            "needs a scenario file to watch; {path:?} is not one (copy a bundled scenario from assets/scenarios/)"
        )));
    }
    if matches!(options.sink, Some(Sink::Stdout)) || options.png.is_some() {
        return Err(AppError::Watch(
            "streams to a viewer or rewrites a --save file; it does not combine with --stdout or --png"
                .to_owned(),
        ));
    }
    if !matches!(options.sink, Some(Sink::Save(_))) {
        // A viewer: one recording, re-streamed in place (see `sink::restream`).
        return super::live::watch_in_place(options, cancel);
    }
    let first_sink = choose_sink(options)?;
    // Later generations connect to the viewer the first one reached.
    let next_sink = match &first_sink {
        Sink::Spawn => Sink::Connect(rerun::DEFAULT_CONNECT_URL.to_owned()),
        Sink::Serve { grpc_port, .. } => {
            Sink::Connect(format!("rerun+http://127.0.0.1:{grpc_port}/proxy"))
        }
        other => other.clone(),
    };
    let mut keep_alive: Option<(rerun::RecordingStream, SinkGuard)> = None;
    let mut generation = 0u64;
    let mut last_seen = None;
    while !cancel.load(Ordering::Relaxed) {
        let modified = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
        if modified != last_seen {
            last_seen = modified;
            match Session::start(&options.scenario, &options.overrides, None) {
                Err(err) => eprintln!(
                    "error: {err}\n(waiting for the next change of {})",
                    path.display()
                ),
                Ok(session) => {
                    let mut ids = session.ids(&options.scenario);
                    ids.recording_id = format!("{}/gen-{generation}", ids.recording_id);
                    let sink = if generation == 0 {
                        &first_sink
                    } else {
                        &next_sink
                    };
                    let (rec, guard) = open_stream(sink, &ids, &session.scene)?;
                    if let Some(url) = guard.viewer_url() {
                        println!("Web viewer: {url}");
                    }
                    session.log(&rec, cancel)?;
                    if matches!(sink, Sink::Serve { .. }) {
                        // The served viewer lives as long as this first stream's guard.
                        flush(&rec)?;
                        keep_alive = Some((rec, guard));
                    } else {
                        guard.finish(rec)?;
                        if let Sink::Save(file) = sink {
                            eprintln!("Wrote {}", file.display());
                        }
                    }
                    eprintln!(
                        "[{generation}] streamed {} ({} items); watching {} for changes (Ctrl-C stops)",
                        path.display(),
                        session.scene.items.len(),
                        path.display()
                    );
                    generation += 1;
                }
            }
        }
        std::thread::sleep(WATCH_POLL);
    }
    if let Some((rec, guard)) = keep_alive {
        guard.finish(rec)?;
    }
    Ok(0)
}

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

pub(crate) fn serve_limit(options: &ServeOptions) -> Result<Option<Duration>, AppError> {
    if let Some(s) = options.seconds {
        return Ok(Some(Duration::from_secs(s)));
    }
    match std::env::var(SERVE_SECONDS_ENV) {
        Ok(s) => {
            let secs: u64 = s.trim().parse().map_err(|_| SettingsError {
                flag: "$POSECOV_SERVE_SECONDS",
                value: format!("{s:?}"),
                expected: "a whole number of seconds".to_owned(),
            })?;
            Ok(Some(Duration::from_secs(secs)))
        }
        Err(_) => Ok(None),
    }
}

/// `--png`: record to an .rrd (the `--save` file, or a temporary one) and render it.
fn render(
    options: &ViewOptions,
    session: &Session,
    ids: &RecordingIds,
    png: &Path,
    size: (u32, u32),
    cancel: &AtomicBool,
) -> Result<u8, AppError> {
    render_with(
        options,
        &session.scene,
        &|rec| session.log(rec, cancel),
        ids,
        png,
        size,
    )
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
