//! One session: evaluate (with a spinner past a moment), draw, log to a sink, then log the
//! clouds of any later Monte Carlo blocks one block at a time. The viewer, `--save`, `--png`,
//! `--watch` and live mode all run it; where its picture goes is [`super::sinks`].

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

use super::sinks::{ViewOptions, choose_sink, finish, flush, render_with, scenario_name, serve};
use super::{AppError, Loaded, Overrides, Settings, load, resolve};
use crate::draw;
use crate::eval::{self, AnyEvaluation};
use crate::scene::Scene;
use crate::sink::{self, LogOutcome, RecordingIds, Sink, open_stream};

/// How often `--watch` looks at the file's modification time.
const WATCH_POLL: Duration = Duration::from_millis(300);

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

/// Shows a scenario once: in the viewer, a file, stdout or a PNG. Returns the process exit
/// code.
///
/// # Errors
/// The scenario's error; the sink's.
pub(crate) fn show(options: &ViewOptions, cancel: &Arc<AtomicBool>) -> Result<u8, AppError> {
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

/// `--watch --save FILE.rrd`: the recording is written whole again on every change of the
/// scenario file (a viewer is re-streamed in place instead, by
/// [`super::live::watch_in_place`]). Errors in the file are printed and the previous recording
/// stays. Returns the exit code: 0 at Ctrl-C between changes, 130 when
/// Ctrl-C cut a recording short ([`EXIT_INTERRUPTED`](super::sinks::EXIT_INTERRUPTED)).
///
/// # Errors
/// The sink's.
pub(crate) fn watch_saving(
    options: &ViewOptions,
    file: &Path,
    cancel: &AtomicBool,
) -> Result<u8, AppError> {
    let path = PathBuf::from(&options.scenario);
    let sink = Sink::Save(file.to_owned());
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
                    let (rec, guard) = open_stream(&sink, &ids, &session.scene)?;
                    let outcome = session.log(&rec, cancel)?;
                    let code = finish(guard, rec, &sink, outcome)?;
                    if code != 0 {
                        return Ok(code);
                    }
                    eprintln!(
                        "[{generation}] recorded {} ({} items); watching {} for changes (Ctrl-C stops)",
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
    Ok(0)
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
