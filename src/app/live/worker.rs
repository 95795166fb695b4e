//! The evaluation thread of live mode: it owns the recording stream, takes the newest
//! change, shows a quick preview (fewer samples from the same random streams), then the
//! full picture, each re-streamed in place ([`Restream`]). A newer change cancels the
//! refinement in flight (the full pass, through the evaluation's own cancel flag), never a
//! change's first picture: while a slider is dragged faster than pictures are made, each
//! finished picture shows the newest value then, instead of every one being cancelled by the
//! next mouse event until the drag stops. Only stopping live mode cancels a first picture.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde::Serialize;

use super::document::{Edit, EditError, LiveDocument};
use crate::app::run::PlanRun;
use crate::app::{AppError, Loaded, Overrides, resolve};
use crate::eval::CoverageSummary;
use crate::plan::StepPolicy;
use crate::sample::CHUNK_SIZE;
use crate::sink::{LogOutcome, Restream, SinkError, SinkGuard};
use crate::uncertain::Method;

/// Samples of the quick preview shown before a larger full sample: the first half of the
/// first random chunk, so the preview's draws are the first draws of the full run (a chunk
/// draws its samples in order from one stream). Half a chunk, because one chunk is one
/// thread's work: 1024 samples took diff_drive_banana's preview to ≈ 60–75 ms on this
/// machine's slower days, 512 take it to ≈ 35 ms (BENCHMARKS §6).
pub const PREVIEW_SAMPLES: u64 = CHUNK_SIZE as u64 / 2;

/// The steps the quick preview keeps of a propagation longer than `max_recorded`: numbers
/// at 25 of them (and the last), clouds and surfaces at 5. Every step is still simulated
/// with the same draws; the full pass then fills in the rest.
pub const PREVIEW_STEPS: StepPolicy = StepPolicy {
    max_recorded: 25,
    max_detailed: 5,
    max_sampled: 25,
};

/// Monte Carlo work (particle-steps, [`AnyPlan::monte_carlo_work`](crate::plan::AnyPlan::monte_carlo_work))
/// up to which the full sample is shown at once, without a preview: it takes a few
/// milliseconds, and a preview would only make the cloud flicker from sparse to dense.
pub const PREVIEW_WORK: f64 = 50_000.0;

/// The shortest time between the starts of two pictures. A slider dragged fast then starts
/// at most 40 pictures a second — each is new data in the viewer and in the served history
/// (Rerun's gRPC server keeps up to 1 GiB of it for viewers that join later), 200 KB for
/// camera_on_robot — at the cost of at most this much latency after a picture just started.
pub const MIN_PICTURE_INTERVAL: Duration = Duration::from_millis(25);

/// How long to wait before starting a picture when the previous one started `since_last`
/// ago (`None`: none yet).
fn wait_before(since_last: Option<Duration>) -> Duration {
    since_last.map_or(Duration::ZERO, |d| MIN_PICTURE_INTERVAL.saturating_sub(d))
}

/// How long a remote viewer may take to receive a generation before we move on.
const FLUSH_TIMEOUT: Duration = Duration::from_secs(5);

/// What the page shows about the evaluation.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Status {
    /// The newest accepted change (0: the file as loaded).
    pub generation: u64,
    /// The generation whose picture was sent last (`None` before the first).
    pub shown: Option<u64>,
    /// Monte Carlo samples of the picture sent last (0 without Monte Carlo).
    pub shown_samples: u64,
    /// Whether the picture sent last is final for its generation (not a preview).
    pub done: bool,
    /// What the thread is doing: `idle`, `preview`, `full`.
    pub phase: &'static str,
    /// Samples being evaluated now.
    pub samples: u64,
    /// Milliseconds from the change to its first picture sent.
    pub first_picture_ms: Option<f64>,
    /// Milliseconds from the change to its final picture sent.
    pub final_picture_ms: Option<f64>,
    /// Entity items in the picture sent last.
    pub items: usize,
    /// How many Monte Carlo samples the last output's regions hold, per method, in the
    /// picture sent last (empty without Monte Carlo).
    pub coverage: Vec<CoverageSummary>,
    /// Why the newest generation could not be drawn (the last good picture stays).
    pub error: Option<String>,
}

/// One evaluation to run.
struct Job {
    generation: u64,
    loaded: Loaded,
    cancel: Arc<AtomicBool>,
    since: Instant,
    /// Send the layout again, cameras fitted to this picture.
    reframe: bool,
}

/// The evaluation thread; it returns the bytes of a memory sink when it ends.
type Worker = JoinHandle<Result<Option<Vec<u8>>, AppError>>;

struct Shared {
    status: Mutex<Status>,
    changed: Condvar,
}

/// A live session: the document being edited and the thread that evaluates and streams it.
///
/// ```
/// use std::time::Duration;
/// use posecov::app::live::{Edit, EditValue, Live, LiveDocument};
/// use posecov::sink::{RecordingIds, Sink, open_stream};
/// let doc = LiveDocument::open("camera_on_robot").unwrap();
/// let layout = posecov::scene::Scene::new("camera", "");
/// let (rec, guard) = open_stream(&Sink::Memory, &RecordingIds::for_scenario("doc", 0), &layout).unwrap();
/// let live = Live::start(doc, rec, guard, Default::default());
/// let edit = Edit { id: "pose[0].cov.std_deg[2]".into(), value: EditValue::Number(40.0) };
/// let generation = live.apply(&edit).unwrap();
/// assert_eq!(live.wait_done(generation, Duration::from_secs(120)).shown, Some(generation));
/// assert!(live.finish().unwrap().is_some_and(|bytes| !bytes.is_empty()));
/// ```
pub struct Live {
    doc: Mutex<LiveDocument>,
    jobs: Mutex<Option<Sender<Job>>>,
    in_flight: Mutex<Arc<AtomicBool>>,
    /// Raised when live mode stops: cancels whatever is in flight, a first picture too.
    stop: Arc<AtomicBool>,
    shared: Arc<Shared>,
    thread: Mutex<Option<Worker>>,
    generation: Mutex<u64>,
}

impl Live {
    /// Starts the evaluation thread on `rec` (whose `guard` it keeps) and shows `doc`.
    /// `overrides` apply to every generation (the block size; seed and samples come from
    /// the document's controls).
    pub fn start(
        doc: LiveDocument,
        rec: rerun::RecordingStream,
        guard: SinkGuard,
        overrides: Overrides,
    ) -> Arc<Self> {
        let (tx, rx) = channel();
        let shared = Arc::new(Shared {
            status: Mutex::new(Status {
                phase: "idle",
                ..Status::default()
            }),
            changed: Condvar::new(),
        });
        let worker_shared = Arc::clone(&shared);
        let stop = Arc::new(AtomicBool::new(false));
        let worker_stop = Arc::clone(&stop);
        let thread = std::thread::Builder::new()
            .name("posecov-live".into())
            .spawn(move || run(rx, rec, guard, &overrides, &worker_shared, &worker_stop))
            .expect("spawning the live evaluation thread");
        let live = Arc::new(Self {
            doc: Mutex::new(doc),
            jobs: Mutex::new(Some(tx)),
            in_flight: Mutex::new(Arc::new(AtomicBool::new(false))),
            stop,
            shared,
            thread: Mutex::new(Some(thread)),
            generation: Mutex::new(0),
        });
        live.submit(false, false);
        live
    }

    /// Applies an edit; on success a new generation is evaluated and streamed (the refinement
    /// in flight is cancelled; a first picture in flight is finished first). Returns the new
    /// generation.
    ///
    /// # Errors
    /// [`EditError`]: nothing changes, the last good picture stays.
    pub fn apply(&self, edit: &Edit) -> Result<u64, EditError> {
        lock(&self.doc).apply(edit)?;
        Ok(self.submit(true, false))
    }

    /// Returns to the file's values.
    pub fn reset(&self) -> Result<u64, AppError> {
        lock(&self.doc).reset()?;
        Ok(self.submit(true, false))
    }

    /// Shows the current picture again with the layout re-sent, each 3-D view's camera fitted
    /// to it (the viewer otherwise keeps the user's camera, e.g. after σ grew the banana out
    /// of view). Returns the new generation.
    pub fn reframe(&self) -> u64 {
        self.submit(true, true)
    }

    /// Replaces the source text (`--watch`: the file changed).
    ///
    /// # Errors
    /// The new text's error; the last good picture stays.
    pub fn replace_source(&self, text: &str) -> Result<u64, AppError> {
        lock(&self.doc).replace_source(text)?;
        Ok(self.submit(true, false))
    }

    /// Runs `f` on the document (controls, text, origin).
    pub fn with_doc<T>(&self, f: impl FnOnce(&LiveDocument) -> T) -> T {
        f(&lock(&self.doc))
    }

    /// The status now.
    pub fn status(&self) -> Status {
        lock(&self.shared.status).clone()
    }

    /// Waits until generation `generation`'s final picture was sent, or an error for it or a
    /// later one, or `timeout`. Returns the status then.
    pub fn wait_done(&self, generation: u64, timeout: Duration) -> Status {
        let deadline = Instant::now() + timeout;
        let mut status = lock(&self.shared.status);
        loop {
            let finished = status.shown.is_some_and(|g| g >= generation) && status.done;
            if finished || (status.error.is_some() && status.generation >= generation) {
                return status.clone();
            }
            let now = Instant::now();
            if now >= deadline {
                return status.clone();
            }
            status = self
                .shared
                .changed
                .wait_timeout(status, deadline - now)
                .map(|(s, _)| s)
                .unwrap_or_else(|e| e.into_inner().0);
        }
    }

    /// Stops the thread and closes the sink; returns the bytes of a memory sink.
    ///
    /// # Errors
    /// What the thread or the sink reported.
    pub fn finish(&self) -> Result<Option<Vec<u8>>, AppError> {
        self.stop.store(true, Ordering::SeqCst);
        lock(&self.in_flight).store(true, Ordering::SeqCst);
        lock(&self.jobs).take();
        let handle = lock(&self.thread).take();
        match handle.map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(AppError::Live("the live evaluation thread panicked".into())),
            None => Ok(None),
        }
    }

    fn submit(&self, newer: bool, reframe: bool) -> u64 {
        let generation = {
            let mut g = lock(&self.generation);
            if newer {
                *g += 1;
            }
            *g
        };
        let cancel = Arc::new(AtomicBool::new(false));
        let previous = std::mem::replace(&mut *lock(&self.in_flight), Arc::clone(&cancel));
        previous.store(true, Ordering::SeqCst);
        {
            let mut status = lock(&self.shared.status);
            status.generation = generation;
            status.error = None;
        }
        let job = Job {
            generation,
            loaded: lock(&self.doc).loaded().clone(),
            cancel,
            since: Instant::now(),
            reframe,
        };
        if let Some(tx) = lock(&self.jobs).as_ref() {
            tx.send(job).ok();
        }
        generation
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn run(
    rx: Receiver<Job>,
    rec: rerun::RecordingStream,
    guard: SinkGuard,
    overrides: &Overrides,
    shared: &Shared,
    stop: &Arc<AtomicBool>,
) -> Result<Option<Vec<u8>>, AppError> {
    let mut restream = Restream::new();
    let mut last_start: Option<Instant> = None;
    while let Ok(mut job) = rx.recv() {
        std::thread::sleep(wait_before(last_start.map(|t| t.elapsed())));
        last_start = Some(Instant::now());
        while let Ok(newer) = rx.try_recv() {
            let reframe = job.reframe || newer.reframe;
            job = Job { reframe, ..newer };
        }
        if job.reframe {
            // Kept by the restream until a layout is sent, even if this job is cancelled.
            restream.reframe();
        }
        if let Err(err) = show(&job, &rec, &mut restream, overrides, shared, stop) {
            if job.cancel.load(Ordering::SeqCst) {
                continue;
            }
            let mut status = lock(&shared.status);
            status.phase = "idle";
            if status.generation == job.generation {
                status.error = Some(err.to_string());
            }
            shared.changed.notify_all();
        }
    }
    Ok(guard.finish(rec)?)
}

/// The passes of one job, as the overrides of each: a quick preview when the full picture is
/// large — fewer samples ([`PREVIEW_SAMPLES`], when Monte Carlo has more than twice as many
/// and more than [`PREVIEW_WORK`] particle-steps) and fewer steps kept ([`PREVIEW_STEPS`],
/// when a propagation is longer than its `max_recorded`) — then the full one. The preview's
/// draws are the full run's first.
///
/// # Errors
/// The settings' error (a value out of range).
///
/// ```
/// use posecov::app::{Overrides, load};
/// use posecov::app::live::{PREVIEW_SAMPLES, PREVIEW_STEPS, passes};
/// let barfoot = passes(&load("barfoot_compounding").unwrap(), &Overrides::default()).unwrap();
/// assert_eq!(barfoot.len(), 2);
/// assert_eq!((barfoot[0].samples, barfoot[0].steps), (Some(PREVIEW_SAMPLES), Some(PREVIEW_STEPS)));
/// assert_eq!((barfoot[1].samples, barfoot[1].steps), (Some(5000), None));
/// let so3 = passes(&load("so3_sampling").unwrap(), &Overrides { samples: Some(1500), ..Default::default() }).unwrap();
/// assert_eq!(so3.len(), 1);
/// // 4000 samples of one composition: shown at once.
/// assert_eq!(passes(&load("camera_on_robot").unwrap(), &Overrides::default()).unwrap().len(), 1);
/// let dense = Overrides { samples: Some(40_000), ..Default::default() };
/// assert_eq!(passes(&load("camera_on_robot").unwrap(), &dense).unwrap()[0].samples, Some(PREVIEW_SAMPLES));
/// ```
pub fn passes(loaded: &Loaded, overrides: &Overrides) -> Result<Vec<Overrides>, AppError> {
    let full = resolve(&loaded.input, overrides, None)?;
    let samples = full.eval.samples as u64;
    let fewer_samples = full.eval.methods.contains(&Method::MonteCarlo)
        && samples > 2 * PREVIEW_SAMPLES
        && loaded.input.plan.monte_carlo_work(samples) > PREVIEW_WORK;
    let fewer_steps = loaded.input.plan.longest_propagation() > PREVIEW_STEPS.max_recorded
        && overrides.steps.is_none();
    let full = Overrides {
        samples: Some(samples),
        ..overrides.clone()
    };
    if !(fewer_samples || fewer_steps) {
        return Ok(vec![full]);
    }
    let preview = Overrides {
        samples: Some(if fewer_samples {
            PREVIEW_SAMPLES
        } else {
            samples
        }),
        steps: if fewer_steps {
            Some(PREVIEW_STEPS)
        } else {
            overrides.steps
        },
        ..overrides.clone()
    };
    Ok(vec![preview, full])
}

/// Shows `job`'s passes. The first is cancelled only by `stop` (live mode ending), the later
/// ones also by a newer change (the job's own flag; see the module docs).
fn show(
    job: &Job,
    rec: &rerun::RecordingStream,
    restream: &mut Restream,
    overrides: &Overrides,
    shared: &Shared,
    stop: &Arc<AtomicBool>,
) -> Result<(), AppError> {
    let passes = passes(&job.loaded, overrides)?;
    let last = passes.len() - 1;
    for (i, pass) in passes.iter().enumerate() {
        let cancel = if i == 0 { stop } else { &job.cancel };
        if cancel.load(Ordering::SeqCst) {
            // A newer change is waiting (or live mode stops): this refinement is not wanted.
            return Ok(());
        }
        let samples = pass.samples.unwrap_or_default();
        {
            let mut status = lock(&shared.status);
            status.phase = if i < last { "preview" } else { "full" };
            status.samples = samples;
            shared.changed.notify_all();
        }
        let mut session = PlanRun::from_loaded(job.loaded.clone(), pass, Some(Arc::clone(cancel)))?;
        if cancel.load(Ordering::SeqCst) {
            return Ok(());
        }
        let scene = std::mem::take(&mut session.scene);
        let items = scene.items.len();
        let mut outcome = restream.log(rec, scene, cancel)?;
        if outcome == LogOutcome::Complete && i == last {
            outcome = session.log_blocks(rec, &job.cancel, |part| {
                Ok(restream.log_part(rec, part, &job.cancel)?)
            })?;
        }
        rec.flush_with_timeout(FLUSH_TIMEOUT)
            .map_err(|e| AppError::Sink(SinkError::Flush(e.to_string())))?;
        if outcome != LogOutcome::Complete {
            // A newer change is on its way; it clears whatever this one left half-logged.
            return Ok(());
        }
        let ms = job.since.elapsed().as_secs_f64() * 1e3;
        let mut status = lock(&shared.status);
        status.shown = Some(job.generation);
        status.shown_samples = if session.settings.eval.methods.contains(&Method::MonteCarlo) {
            samples
        } else {
            0
        };
        status.items = items;
        status.coverage = session.evaluation.coverage_summary();
        if i == 0 {
            status.first_picture_ms = Some(ms);
            status.final_picture_ms = None;
        }
        status.done = i == last;
        if i == last {
            status.final_picture_ms = Some(ms);
            status.phase = "idle";
        }
        shared.changed.notify_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_start_at_most_every_interval() {
        assert_eq!(wait_before(None), Duration::ZERO);
        assert_eq!(
            wait_before(Some(Duration::from_millis(10))),
            Duration::from_millis(15)
        );
        assert_eq!(wait_before(Some(Duration::from_millis(25))), Duration::ZERO);
        assert_eq!(wait_before(Some(Duration::from_secs(3))), Duration::ZERO);
    }
}
