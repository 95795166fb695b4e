//! One pure run of any input: [`open`] decides, once, whether the input is a plan (a scenario,
//! a pose graph) or a robot log; [`Run::start`] resolves its settings (one table of flags,
//! [`super::resolve`], the one resolver), evaluates and draws it. A run is the scene
//! plus, for a plan whose Monte Carlo ran in blocks, the later blocks' clouds
//! ([`PlanRun::block`]); every sink shows it through one sequence (`session::show`).
//!
//! ```
//! use posecov::app::{Overrides, run::{Run, RunOptions, open}};
//! let overrides = Overrides { samples: Some(64), ..Default::default() };
//! let plan = Run::start(open("camera_on_robot").unwrap(), &overrides, RunOptions::shown()).unwrap();
//! let log = Run::start(open("covariance_health").unwrap(), &overrides, RunOptions::shown()).unwrap();
//! assert!(matches!(plan, Run::Plan(_)) && matches!(log, Run::Log(_)));
//! assert!(plan.scene().validate().is_ok() && log.scene().validate().is_ok());
//! ```

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};

use super::log::{self, LogRun};
use super::{AppError, Loaded, Overrides, RobotLog, Settings, resolve};
use crate::draw;
use crate::eval::StepProgress;
use crate::eval::graph::{Iteration, ProgressHook, Stage, StepMarginals};
use crate::eval::{self, AnyEvaluation};
use crate::input::{self, InputKind, Located};
use crate::scene::Scene;

/// An input found, its format decided once and its kind with it.
#[derive(Debug, Clone)]
pub enum Opened {
    /// A scenario or a pose graph, read and checked (boxed: a plan is large).
    Plan(Box<Loaded>),
    /// A robot log, found but not read yet (it is streamed by the run).
    Log(Located),
}

/// What a [`Run`] is wanted for: the one set of choices every command passes to
/// [`Run::start`].
///
/// ```
/// use posecov::app::run::RunOptions;
/// assert!(RunOptions::shown().draw && !RunOptions::numbers().draw);
/// assert!(!RunOptions::numbers().progress);
/// use posecov::eval::graph::StepMarginals;
/// assert_eq!(RunOptions::numbers().step_marginals, StepMarginals::DeadReckoning);
/// ```
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Build the scene (the viewer, `--save`, figures). `report` and `check` print numbers and
    /// findings, so their runs draw nothing but a plan's check, whose line counts the items a
    /// scenario draws.
    pub draw: bool,
    /// Show progress on a terminal (a log's bar, a plan's spinner); off when many inputs run
    /// at once under one bar.
    pub progress: bool,
    /// Set by Ctrl-C: a log's read stops and keeps what was read; a plan's evaluation stops.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Which of a pose graph's loop-closure steps get every pose's marginal: every step for
    /// the viewer (its `step` timeline shows them), dead reckoning's only for a report or a
    /// figure of the final state (computed where it is shown).
    pub step_marginals: StepMarginals,
}

impl RunOptions {
    /// A run to show: drawn, with progress.
    pub fn shown() -> Self {
        Self {
            draw: true,
            progress: true,
            cancel: None,
            step_marginals: StepMarginals::Every,
        }
    }

    /// A run for its numbers only: not drawn, no progress shown, no marginals of a pose
    /// graph's intermediate loop-closure steps (a report shows none).
    pub fn numbers() -> Self {
        Self {
            step_marginals: StepMarginals::DeadReckoning,
            ..Self::default()
        }
    }

    /// The same run, stopped by `cancel`.
    ///
    /// ```
    /// use std::sync::{Arc, atomic::AtomicBool};
    /// let o = posecov::app::run::RunOptions::shown().cancelled_by(Arc::new(AtomicBool::new(false)));
    /// assert!(o.cancel.is_some());
    /// ```
    pub fn cancelled_by(self, cancel: Arc<AtomicBool>) -> Self {
        Self {
            cancel: Some(cancel),
            ..self
        }
    }
}

/// Finds an input (a file, or a bundled example by name), decides its format and kind once
/// ([`input::locate`], [`crate::input::Format::kind`]), and reads it if it is a plan. The one
/// place every command and sink routes an input.
///
/// ```
/// use posecov::app::run::{Opened, open};
/// assert!(matches!(open("jackal_odometry").unwrap(), Opened::Log(_)));
/// assert!(matches!(open("gtsam_pose2example").unwrap(), Opened::Plan(_)));
/// ```
pub fn open(name_or_path: &str) -> Result<Opened, AppError> {
    let located = input::locate(name_or_path)?;
    Ok(match located.kind() {
        InputKind::Plan => {
            let (source, input) = input::open_located(&located)?;
            Opened::Plan(Box::new(Loaded { source, input }))
        }
        InputKind::Log => Opened::Log(located),
    })
}

/// A plan evaluated and drawn: the numbers, the scene, and what makes the later Monte Carlo
/// blocks' clouds.
#[derive(Debug)]
pub struct PlanRun {
    /// What was loaded.
    pub loaded: Loaded,
    /// The settings resolved for it.
    pub settings: Settings,
    /// The numbers.
    pub evaluation: AnyEvaluation,
    /// The picture (validated).
    pub scene: Scene,
}

impl PlanRun {
    /// Resolves, evaluates and draws a loaded plan (no spinner: live mode's path).
    ///
    /// ```
    /// use posecov::app::{Overrides, load, run::PlanRun};
    /// let loaded = load("camera_on_robot").unwrap();
    /// let r = PlanRun::from_loaded(loaded, &Overrides { samples: Some(64), ..Default::default() }, None).unwrap();
    /// assert!(!r.scene.items.is_empty() && r.later_blocks() == 0);
    /// ```
    pub fn from_loaded(
        loaded: Loaded,
        overrides: &Overrides,
        cancel: Option<Arc<AtomicBool>>,
    ) -> Result<Self, AppError> {
        let options = RunOptions {
            cancel,
            ..RunOptions::shown()
        };
        Self::run(loaded, overrides, &options, super::Hooks::default())
    }

    /// Resolves and evaluates a loaded plan, a pose graph's solves and the Monte Carlo
    /// reporting their steps to `hooks`, and draws it when [`RunOptions::draw`] (else the scene
    /// holds the title and description).
    fn run(
        loaded: Loaded,
        overrides: &Overrides,
        options: &RunOptions,
        hooks: super::Hooks,
    ) -> Result<Self, AppError> {
        let (settings, evaluation, scene) =
            super::evaluate_and_draw(&loaded, overrides, options, hooks)?;
        Ok(Self {
            loaded,
            settings,
            evaluation,
            scene,
        })
    }

    /// How many Monte Carlo blocks beyond the first are shown after the scene.
    pub fn later_blocks(&self) -> u64 {
        let ran = self.evaluation.ran_with();
        (ran.samples.div_ceil(ran.block_samples.max(1)) as u64).saturating_sub(1)
    }

    /// The clouds of Monte Carlo block `k` (1 ..= [`later_blocks`](Self::later_blocks)),
    /// re-simulated and drawn; `None` when there is no such block.
    ///
    /// # Errors
    /// An evaluation error, located in the file.
    pub fn block(&self, k: usize) -> Result<Option<Scene>, AppError> {
        let plan = &self.loaded.input.plan;
        let Some(block) = eval::evaluate_block(plan, &self.settings.eval, &self.evaluation, k)
            .map_err(|e| self.loaded.locate(&e))?
        else {
            return Ok(None);
        };
        Ok(Some(draw::particle_part(
            &self.evaluation,
            &block,
            k,
            &self.settings.draw,
        )))
    }
}

/// One run of any input: its scene, and for a plan the later blocks.
#[derive(Debug)]
pub enum Run {
    /// A scenario or a pose graph (boxed, as the log: runs are large).
    Plan(Box<PlanRun>),
    /// A robot log.
    Log(Box<LogRun>),
}

impl Run {
    /// Resolves the settings of an opened input (the one place that matches the input's kind),
    /// evaluates it and, when [`RunOptions::draw`] asks, draws it: a plan with a spinner on a
    /// terminal past 0.3 s, a log streamed with a progress bar ([`RunOptions::progress`];
    /// [`RunOptions::cancel`] stops the read and keeps what was read). Undrawn, the scene holds
    /// the run's title and description only.
    ///
    /// See the [module docs](self) for an example.
    ///
    /// # Errors
    /// A flag the input cannot take; the input's errors, located in its file.
    pub fn start(
        opened: Opened,
        overrides: &Overrides,
        options: RunOptions,
    ) -> Result<Run, AppError> {
        Self::start_growing(opened, overrides, options, None)
    }

    /// [`Run::start`], and for a live stream that is drawn each scene of what has arrived so
    /// far handed to `growing` while it is read (at most once per
    /// [`growth_interval`](crate::input::log::growth_interval), on a thread of the read's
    /// own), and between those each message's point of its σ series as it arrives; the run's
    /// own scene is the end's.
    ///
    /// # Errors
    /// As [`Run::start`].
    pub(crate) fn start_growing(
        opened: Opened,
        overrides: &Overrides,
        options: RunOptions,
        growing: Option<&dyn log::Growing>,
    ) -> Result<Run, AppError> {
        match opened {
            Opened::Plan(loaded) => {
                let what = format!("evaluating {}", loaded.input.about.title);
                let work = |bars: Option<(&ProgressBar, &MultiProgress)>| {
                    let hooks = super::Hooks {
                        graph: bars.map(|(s, _)| graph_progress(s.clone(), what.clone())),
                        monte_carlo: bars.map(|(_, m)| monte_carlo_progress(m.clone())),
                    };
                    PlanRun::run(*loaded, overrides, &options, hooks)
                };
                let run = if options.progress {
                    with_spinner(&what, |spinner, multi| work(Some((spinner, multi))))
                } else {
                    work(None)
                };
                run.map(|run| Run::Plan(Box::new(run)))
            }
            Opened::Log(located) => {
                let settings = resolve(RobotLog, overrides, None)?;
                if let input::Place::Live(url) = &located.place
                    && let Some(reference) = &settings.reference
                    && reference.align == crate::eval::log::nees::Align::Se3
                {
                    return Err(AppError::Input(input::InputError::Read {
                        path: url.clone(),
                        reason: "--align se3 fits the reference to the whole run, which a live \
                                 stream does not have; use --align first or none"
                            .to_owned(),
                    }));
                }
                log::run(&located, &settings, &options, growing).map(|run| Run::Log(Box::new(run)))
            }
        }
    }

    /// The picture.
    pub fn scene(&self) -> &Scene {
        match self {
            Run::Plan(r) => &r.scene,
            Run::Log(r) => &r.scene,
        }
    }

    /// The seed in effect (the recording's id carries it).
    pub fn seed(&self) -> u64 {
        match self {
            Run::Plan(r) => r.settings.eval.seed,
            Run::Log(r) => r.settings.eval.seed,
        }
    }

    /// Monte Carlo blocks shown after the scene (none for a log).
    pub fn later_blocks(&self) -> u64 {
        match self {
            Run::Plan(r) => r.later_blocks(),
            Run::Log(_) => 0,
        }
    }

    /// Ctrl-C cut the input's read short: what is shown is what was read.
    pub fn cut_short(&self) -> bool {
        match self {
            Run::Plan(_) => false,
            Run::Log(r) => r.summary.cancelled,
        }
    }
}

/// A pose graph's progress on the spinner: the solve, its iteration, χ² and λ (Ctrl-C stops
/// between iterations, keeping the last accepted estimate). The optimisation's iterations
/// are not known in advance (a spinner); the loop-closure timeline's steps are, so it turns
/// into a bar of its steps.
fn graph_progress(spinner: ProgressBar, what: String) -> ProgressHook {
    ProgressHook(Arc::new(move |stage: Stage, i: &Iteration| {
        let solve = match stage {
            Stage::Optimizing => "optimising".to_owned(),
            Stage::Timeline { step, of } => {
                if spinner.length() != Some(of as u64) {
                    spinner.set_style(
                        ProgressStyle::with_template(
                            "{spinner} {msg} [{bar:24}] {pos}/{len} steps done ({elapsed})",
                        )
                        .unwrap_or_else(|_| ProgressStyle::default_bar()),
                    );
                    spinner.set_length(of as u64);
                }
                spinner.set_position(step.saturating_sub(1) as u64);
                format!("loop closures one by one, step {step} of {of}")
            }
        };
        let lambda = i.lambda.map_or(String::new(), |l| format!(", λ {l:.0e}"));
        let chi2 = i
            .chi2
            .map_or("not finite".to_owned(), |c| format!("{c:.6e}"));
        spinner.set_message(format!(
            "{what}: {solve}, iteration {}, χ² {chi2}{lambda} (Ctrl-C keeps the last estimate)",
            i.iteration
        ));
    }))
}

/// The Monte Carlo's steps on a bar of their own under the spinner (added at its first report,
/// cleared with the spinner): "Monte Carlo, 2000 samples [####    ] 800/1727 steps".
fn monte_carlo_progress(multi: MultiProgress) -> StepProgress {
    let bar = std::sync::OnceLock::<ProgressBar>::new();
    StepProgress(Arc::new(move |k, of, samples| {
        let bar = bar.get_or_init(|| {
            let bar = ProgressBar::new(of as u64)
                .with_message(format!("Monte Carlo, {samples} samples"))
                .with_style(
                    ProgressStyle::with_template("  {msg} [{bar:24}] {pos}/{len} steps")
                        .unwrap_or_else(|_| ProgressStyle::default_bar()),
                );
            multi.add(bar)
        });
        bar.set_length(of as u64);
        bar.set_position(k as u64);
    }))
}

/// Tells a spinner's ticker thread to end, when dropped.
struct StopTicker<'a>(&'a AtomicBool, &'a std::thread::Thread);

impl Drop for StopTicker<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
        self.1.unpark();
    }
}

/// Runs `work`, showing a spinner on a terminal (stderr; nothing when it is not one) when it
/// takes more than 0.3 s; `work` may change its message and add bars under it to the
/// [`MultiProgress`] it is given.
pub(crate) fn with_spinner<T>(
    message: &str,
    work: impl FnOnce(&ProgressBar, &MultiProgress) -> T,
) -> T {
    let multi = MultiProgress::new();
    let spinner = multi.add(ProgressBar::new_spinner().with_message(message.to_owned()));
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
        // However `work` ends: a panic unwinding through the scope would otherwise wait for
        // the ticker forever (a hang, not a crash).
        let _stop = StopTicker(&done, ticker.thread());
        work(&spinner, &multi)
    });
    spinner.finish_and_clear();
    let _ = multi.clear();
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic inside the spinner's work unwinds out of it (a crash, said), never a hang:
    /// the ticker thread is told to end however the work ends.
    #[test]
    fn a_panic_inside_the_spinner_unwinds_and_does_not_hang() {
        let (sent, received) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let outcome = std::panic::catch_unwind(|| {
                with_spinner("working", |_, _| -> () { panic!("inside the work") })
            });
            let _ = sent.send(outcome.is_err());
        });
        let unwound = received
            .recv_timeout(Duration::from_secs(10))
            .expect("with_spinner returned within 10 s of a panic in its work");
        assert!(unwound);
    }
}
