//! Showing a run ([`super::run::Run`]) through one sequence for every input and sink: the
//! scene logged, then for a plan the clouds of any later Monte Carlo blocks one block at a
//! time; the viewer, `--save`, `--stdout`, `--png` and `--watch --save` all run it (live mode
//! streams [`PlanRun::log_blocks`] too). Where its picture goes is [`super::sinks`].

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use indicatif::{ProgressBar, ProgressStyle};

use super::log::Growing;
use super::run::{Opened, PlanRun, Run, RunOptions, open, with_spinner};
use super::sinks::{
    EXIT_INTERRUPTED, ViewOptions, choose_sink, finish, flush, render_with, scenario_name, serve,
    watch_file,
};
use super::{AppError, Overrides, RobotLog, resolve};
use crate::draw::log::message_points;
use crate::input::Place;
use crate::plan::log::SeriesPoint;
use crate::scene::Scene;
use crate::sink::{
    self, LogOutcome, RecordingIds, Restream, Sink, SinkError, SinkGuard, log_points, open_stream,
};

impl Run {
    /// Logs the scene, then the clouds of any later Monte Carlo blocks one block at a time
    /// (each re-simulated, drawn, logged, flushed and dropped: memory stays bounded); reports
    /// how far it got if Ctrl-C interrupted it.
    pub fn log(
        &self,
        rec: &rerun::RecordingStream,
        cancel: &AtomicBool,
    ) -> Result<LogOutcome, AppError> {
        let outcome = sink::log_scene_cancellable(rec, self.scene(), cancel)?;
        if outcome != LogOutcome::Complete {
            report_interrupted(outcome);
            return Ok(outcome);
        }
        match self {
            Run::Plan(plan) => plan.log_blocks(rec, cancel, |part| {
                Ok(sink::log_part_cancellable(rec, &part, cancel)?)
            }),
            Run::Log(_) => Ok(outcome),
        }
    }

    /// The recording id: the input's name (a file by its stem) and the seed in effect.
    fn ids(&self, name: &str) -> RecordingIds {
        RecordingIds::for_scenario(&scenario_name(name), self.seed())
    }

    /// The exit code of a run shown with `code`: 130 when Ctrl-C cut the read short (what
    /// was read is shown, complete).
    fn exit_code(&self, code: u8) -> u8 {
        if self.cut_short() {
            EXIT_INTERRUPTED
        } else {
            code
        }
    }
}

impl PlanRun {
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
                let Some(part) = self.block(k)? else {
                    break;
                };
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
}

fn report_interrupted(outcome: LogOutcome) {
    if let LogOutcome::Cancelled { next_step } = outcome {
        match next_step {
            Some(k) => eprintln!("Interrupted: recorded the static items and steps before {k}."),
            None => eprintln!("Interrupted: recorded part of the static items."),
        }
    }
}

/// Shows an opened input once, whatever it is: in the viewer, a file, stdout or a PNG — the
/// one sequence every input and sink goes through. Returns the process exit code.
///
/// # Errors
/// The input's error; the sink's.
pub(crate) fn show(
    options: &ViewOptions,
    opened: Opened,
    cancel: &Arc<AtomicBool>,
) -> Result<u8, AppError> {
    if options.png.is_none()
        && let Opened::Log(located) = &opened
        && matches!(located.place, Place::Live(_))
    {
        return show_growing(options, opened, cancel);
    }
    let run = Run::start(
        opened,
        &options.overrides,
        RunOptions::shown().cancelled_by(Arc::clone(cancel)),
    )?;
    let ids = run.ids(&options.scenario);
    if let Some((png, size)) = &options.png {
        let log = |rec: &rerun::RecordingStream| run.log(rec, cancel);
        return render_with(options, run.scene(), &log, &ids, png, *size)
            .map(|code| run.exit_code(code));
    }
    let sink = choose_sink(options)?;
    let (rec, guard) = open_stream(&sink, &ids, run.scene())?;
    if let Some(url) = guard.viewer_url() {
        println!("Web viewer: {url}");
    }
    // Logging and encoding a large scene (a pose graph's) takes seconds: a spinner says so.
    let outcome = with_spinner("logging the recording", |_, _| run.log(&rec, cancel))?;
    if guard.viewer_url().is_some() && outcome == LogOutcome::Complete {
        serve(&options.serve, &guard, cancel)?;
    }
    finish(guard, rec, &sink, outcome).map(|code| run.exit_code(code))
}

/// A live stream shown as it grows: the sink opens with the first scene of what has arrived,
/// each later one (at most once per [`growth_interval`](crate::input::log::growth_interval))
/// and at last the run's own scene replace it in place ([`Restream`]: the viewer keeps its
/// camera, a recording holds one generation per scene); between pictures each message's σ
/// points extend the lines of the picture shown last as it arrives ([`LiveView`]). Returns
/// the exit code.
///
/// # Errors
/// The input's error; the sink's (the first one stops the drawing, the read goes on to its
/// end and the error is returned then).
fn show_growing(
    options: &ViewOptions,
    opened: Opened,
    cancel: &Arc<AtomicBool>,
) -> Result<u8, AppError> {
    let seed = resolve(RobotLog, &options.overrides, None)?.eval.seed;
    let view = LiveView {
        ids: RecordingIds::for_scenario(&scenario_name(&options.scenario), seed),
        sink: choose_sink(options)?,
        shown: Mutex::new(None),
        tail: Mutex::new(None),
        failed: Mutex::new(None),
    };
    let run = Run::start_growing(
        opened,
        &options.overrides,
        RunOptions::shown().cancelled_by(Arc::clone(cancel)),
        Some(&view),
    );
    let LiveView {
        ids,
        sink,
        shown,
        failed,
        ..
    } = view;
    if let Some(e) = failed.into_inner().unwrap_or_else(PoisonError::into_inner) {
        return Err(e);
    }
    let run = run?;
    let mut shown = shown.into_inner().unwrap_or_else(PoisonError::into_inner);
    let outcome = LiveView::show(&sink, &mut shown, &ids, run.scene(), cancel)?;
    report_interrupted(outcome);
    let Some((rec, guard, _)) = shown else {
        unreachable!("the run's scene was shown, so the sink is open");
    };
    if guard.viewer_url().is_some() && outcome == LogOutcome::Complete {
        serve(&options.serve, &guard, cancel)?;
    }
    finish(guard, rec, &sink, outcome).map(|code| run.exit_code(code))
}

/// The viewer's side of a growing live view: the pictures (the sink opened at the first,
/// each re-streamed in place), and the lines of the picture shown last, which each message's
/// points extend until the next (their paths are that picture's generation's, so the next
/// picture hides them with its own lines: nothing is drawn twice).
struct LiveView {
    ids: RecordingIds,
    sink: Sink,
    /// The open sink and its re-streaming state (the thread that draws only).
    shown: Mutex<Option<(rerun::RecordingStream, SinkGuard, Restream)>>,
    /// Where the newest messages go: the recording, the generation shown last and its lines.
    tail: Mutex<Option<Tail>>,
    /// The first error of the sink: it stops the drawing.
    failed: Mutex<Option<AppError>>,
}

/// The picture shown last, as messages extend it.
struct Tail {
    rec: rerun::RecordingStream,
    generation: u64,
    /// Its plots and lines (their points left out).
    lines: Scene,
}

impl LiveView {
    /// Shows `scene` in place of the one before on the sink, opened with it if not yet.
    fn show(
        sink: &Sink,
        shown: &mut Option<(rerun::RecordingStream, SinkGuard, Restream)>,
        ids: &RecordingIds,
        scene: &Scene,
        cancel: &AtomicBool,
    ) -> Result<LogOutcome, AppError> {
        let (rec, _, restream) = match shown {
            Some(open) => open,
            None => {
                let (rec, guard) = open_stream(sink, ids, scene)?;
                if let Some(url) = guard.viewer_url() {
                    println!("Web viewer: {url}");
                }
                shown.insert((rec, guard, Restream::new()))
            }
        };
        let outcome = restream.log(rec, scene.clone(), cancel)?;
        flush(rec)?;
        Ok(outcome)
    }

    /// Keeps the first error; later ones follow from it.
    fn fail(&self, e: AppError) {
        let mut failed = self.failed.lock().unwrap_or_else(PoisonError::into_inner);
        failed.get_or_insert(e);
    }

    fn failed(&self) -> bool {
        self.failed
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .is_some()
    }
}

impl Growing for LiveView {
    fn picture(&self, scene: &Scene) {
        if self.failed() {
            return;
        }
        let mut shown = self.shown.lock().unwrap_or_else(PoisonError::into_inner);
        let never = AtomicBool::new(false);
        match Self::show(&self.sink, &mut shown, &self.ids, scene, &never) {
            Err(e) => self.fail(e),
            Ok(_) => {
                if let Some((rec, _, restream)) = shown.as_ref() {
                    let mut lines = Scene::new(String::new(), String::new());
                    lines.timeline = scene.timeline;
                    lines.plots = scene.plots.clone();
                    lines.series = scene.series.clone();
                    for line in &mut lines.series {
                        line.points = Vec::new();
                    }
                    let tail = Tail {
                        rec: rec.clone(),
                        generation: restream.generations().saturating_sub(1),
                        lines,
                    };
                    *self.tail.lock().unwrap_or_else(PoisonError::into_inner) = Some(tail);
                }
            }
        }
    }

    fn message(&self, topic: &str, point: &SeriesPoint) {
        let mut tail = self.tail.lock().unwrap_or_else(PoisonError::into_inner);
        let Some(shown) = tail.as_ref() else {
            // Before the first picture: that picture will have it.
            return;
        };
        let mut points = message_points(&shown.lines, topic, point);
        for line in &mut points {
            line.generation = Some(shown.generation);
        }
        match log_points(&shown.rec, &points, shown.lines.timeline) {
            // A value the viewer cannot hold: left out here, located by the end's picture.
            Ok(()) | Err(SinkError::Scene(_)) => {}
            Err(e) => {
                // Not streamed again: the pictures go on and the error is said at the end.
                *tail = None;
                self.fail(e.into());
            }
        }
    }
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
    watch_file(&path, true, cancel, None, |changed| {
        if !changed {
            return Ok(None);
        }
        match start(&options.scenario, &options.overrides) {
            Err(err) => eprintln!(
                "error: {err}\n(waiting for the next change of {})",
                path.display()
            ),
            Ok(run) => {
                let mut ids = run.ids(&options.scenario);
                ids.recording_id = format!("{}/gen-{generation}", ids.recording_id);
                let (rec, guard) = open_stream(&sink, &ids, run.scene())?;
                let outcome = run.log(&rec, cancel)?;
                let code = finish(guard, rec, &sink, outcome)?;
                if code != 0 {
                    return Ok(Some(code));
                }
                eprintln!(
                    "[{generation}] recorded {} ({} items); watching {} for changes (Ctrl-C stops)",
                    path.display(),
                    run.scene().items.len(),
                    path.display()
                );
                generation += 1;
            }
        }
        Ok(None)
    })
}

/// Opens and runs the watched file again.
fn start(scenario: &str, overrides: &Overrides) -> Result<Run, AppError> {
    Run::start(open(scenario)?, overrides, RunOptions::shown())
}
