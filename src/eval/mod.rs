//! Evaluating a [`Plan`]: every pose and every operation, with every requested method,
//! Monte Carlo particles flowing through the operations, and errors against Monte Carlo.
//! Numbers only: nothing here knows entity paths, colours, Markdown or plots.
//!
//! Monte Carlo is end to end: each uncertain input is sampled once (n particles, seeded from
//! the seed and the input's order), and every operation maps particles to particles, drawing
//! fresh process noise where it has some. Each node's Monte Carlo estimate is the iterative
//! Lie mean and 1/(N−1) covariance of its particles, right side
//! ([`LieMeanAccumulator`](crate::sample::LieMeanAccumulator)). Analytic methods propagate
//! Gaussians operation by operation. Statistics are taken as particles pass a node; a long
//! propagation keeps the particles of at most [`StepPolicy::max_detailed`] steps, so memory
//! does not grow with the step count.
//!
//! # Blocked Monte Carlo: bounded memory
//! Every random draw comes from the stream of its 1024-sample chunk
//! ([`crate::sample::chunk_rng`]), so any block of samples `k·1024 ..` can be simulated
//! through all operations on its own and gets exactly the particles a whole-sample run would.
//! When the particles would exceed [`PARTICLE_MEMORY_BUDGET`] (e.g. 10⁷ samples), the sample
//! is split into blocks: the statistics are summed block by block (one pass over the blocks
//! per Lie-mean iteration, each re-simulating the blocks), the evaluation keeps the first
//! block's particles, and [`evaluate_block`] re-simulates any later block for its clouds.
//!
//! ```
//! use posecov::input::scenario::{Scenario, lower};
//! use posecov::eval::{EvalSettings, evaluate};
//! use posecov::uncertain::Method;
//! let text = "[scenario]\ntitle='t'\ngroup='se2'\n[[pose]]\nname='a'\nmean={xy_theta=[1,0,0]}\ncov={std=[0.1,0.1,0.1]}\n\
//!             [[operation]]\nkind='inverse'\ninput='a'\noutput='a_inv'\n";
//! let plan = lower(&Scenario::parse(text, "t.toml").unwrap()).unwrap().plan;
//! let settings = EvalSettings { samples: 500, methods: vec![Method::FirstOrder, Method::MonteCarlo], ..Default::default() };
//! let e = evaluate(&plan, &settings).unwrap();
//! assert!(e.records().iter().any(|r| r.label == "a_inv" && r.relative_error_vs_monte_carlo.is_some()));
//! ```
//!
//! # What this folder owns
//!
//! - `evaluate(&Plan, &EvalSettings) → Evaluation`: numbers only.
//! - `engine.rs` (definitions table, particles, the one place a result becomes a checked node with
//!   its Monte Carlo statistics)
//! - `ops.rs` (one function per `Op`; the propagations — odometry, compounding, differential drive,
//!   Euler vs Exp — in `propagations.rs`)
//! - `reports.rs` (a method that failed, a covariance not PSD: typed findings)
//! - `blocked.rs` (statistics summed over blocks)
//! - `batch_means.rs` (the one Monte Carlo standard error of a mean of the samples: batch means
//!   over 20 consecutive batches, the same for a whole and a blocked sample)
//! - `groups.rs` (what only some groups can do)
//! - `model.rs` (`Evaluation`, `Node`, typed `Finding`s)
//! - `consistency.rs` (the one "inside" rule per region: the share of each node's Monte Carlo
//!   samples inside every region an estimate draws, and their ANEES; counted in `engine.rs` for a
//!   whole sample, in the first pass of a blocked one);
//! - `graph/` (a plan's pose graph: `solve.rs` the Jacobians and the Levenberg–Marquardt /
//!   Gauss–Newton loop, `sparse.rs` the block-sparse normal equations and faer's supernodal
//!   Cholesky with a block AMD ordering, `marginals.rs` selected inversion of the factor, one
//!   supernode at a time on dense blocks with faer's kernels (and two block solves for a pair off
//!   its pattern), `parts.rs` the gauge of each connected part, `evaluate.rs` loop closures'
//!   residuals before and after at the confidence, the joint marginals asked for (`--joint`) and
//!   the relative pose's covariance, `timeline.rs` the graph re-solved loop closure by loop closure
//!   (bounded: 12 steps, 10⁴ poses), every solve's steps reported to a `ProgressHook` the app
//!   draws, `report.rs` the `optimized` records of `report --json`);
//! - `log/` — a robot log's numbers — `mod.rs` (`evaluate_log`: each topic's drawn messages,
//!   trajectory and series moved — never copied — out of its summary as `TopicMessages`; per drawn
//!   message the right-form Gaussian (`meaning.rs`: through `interop::ros_cov_to_right` in the
//!   chosen `RosReading`, in the topic's `GroupKind`, SE(2) or SE(3): its degrees of freedom), a seeded
//!   cloud, RViz's numbers, its σ per estimated axis; per topic its `frame_id`; per topic the σ
//!   summary of each axis — the streamed statistics and the median of the kept series);
//!   - `stamped.rs` (the one home of a pose at a stamp: `StampedPoses`, SE(3) interpolation between
//!     the bracketing samples, never extrapolated — NEES's reference and each `/tf` edge use it);
//!   - `frames.rs` (topics in different frames joined through the log's `/tf`: the tree's problems
//!     — a cycle, several parents, a missing link, a frame never transformed — the lowest common
//!     frame, each drawn message and trajectory point moved by common_from_frame at its stamp, its
//!     covariance by `interop::ros_cov_moved`; called by `evaluate_log`, which then evaluates the
//!     moved topic as any other);
//!   - `nees.rs` + `nees/` (NEES of every message of a log against a reference, streamed:
//!     `NeesObserver`, the `plan::log::LogObserver` the reader hands every reference sample and
//!     estimate message to — SE(3) interpolation of the truth without extrapolation, e = Log(X̂⁻¹
//!     X_ref) in the right form through `log/mod.rs`'s one conversion, joint / position /
//!     orientation NEES, ANEES with its χ² band and the typed `Verdict`, `--align` first / se3
//!     (Umeyama); `model.rs` the settings, `Verdict` and results, `math.rs` the three NEES of one
//!     message and Umeyama's fit)
//!
//! Not here: entity paths, colours, Markdown, plots, draw settings.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

pub mod batch_means;
mod blocked;
pub mod consistency;
mod engine;
mod error;
mod findings;
pub mod graph;
pub mod groups;
pub mod log;
mod model;
mod ops;
mod propagations;
mod reports;

pub use consistency::{Anees, Consistency, CoverageSummary};
pub use error::EvalError;
pub use model::{
    AlongTrack, AnyEvaluation, Estimate, Evaluation, FailureReason, Finding, MatrixFrame,
    McSummary, MonteCarloRecord, Node, PathKind, PointEstimate, PointNode, PosePath, RanWith, Role,
    orthogonality_error,
};

use crate::lie::{Se2, Se3, So2, So3};
use crate::plan::{AnyPlan, Op, Plan, PoseValue, StepPolicy, limits};
use crate::sample::CHUNK_SIZE;
use crate::uncertain::{Confidence, Method};
use blocked::BlockedStats;
use engine::{Engine, StatsMode};
use groups::EvalGroup;

/// Bytes of Monte Carlo particles (all nodes together) an evaluation holds at once; larger
/// samples are simulated in blocks ([blocked Monte Carlo](self#blocked-monte-carlo-bounded-memory)).
pub const PARTICLE_MEMORY_BUDGET: usize = 128 << 20;
/// At most this many particles per block (also the size of the drawn first block's clouds).
pub const MAX_BLOCK_SAMPLES: usize = 64 * CHUNK_SIZE;
/// At least this many particles per block, however many nodes hold particles.
pub const MIN_BLOCK_SAMPLES: usize = 4 * CHUNK_SIZE;

/// What an evaluation needs besides the plan, resolved once by the caller.
#[derive(Debug, Clone)]
pub struct EvalSettings {
    /// Seed of every random draw.
    pub seed: u64,
    /// Monte Carlo samples (used when `methods` has Monte Carlo), 2 ..= 10⁷.
    pub samples: usize,
    /// Methods to compare (the first-order or exact result is always computed).
    pub methods: Vec<Method>,
    /// Particles held at once (rounded up to a multiple of [`CHUNK_SIZE`]); `None` chooses
    /// from [`PARTICLE_MEMORY_BUDGET`].
    pub block_samples: Option<usize>,
    /// Which steps of long propagations keep numbers and particles.
    pub steps: StepPolicy,
    /// The probability p of the regions whose coverage is measured against Monte Carlo
    /// ([`consistency`]) and of the region a pose graph's loop-closure residuals are measured
    /// against, 0 < p < 1 (default [`Confidence::DEFAULT`]).
    pub confidence: Confidence,
    /// Sigma-point parameters α, β, κ (default 1, 2, 0).
    pub unscented: crate::propagate::sigma_point::Unscented,
    /// Set to stop early (Ctrl-C): the evaluation returns what it has, with
    /// [`Finding::Interrupted`].
    pub cancel: Option<Arc<AtomicBool>>,
    /// How a plan's pose graph is optimised and its loop closures measured.
    pub graph: graph::GraphSettings,
    /// Where a pose graph's solves report their steps (a progress bar), if anywhere.
    pub graph_progress: Option<graph::ProgressHook>,
    /// Where a Monte Carlo propagation reports the steps its particles have taken (a progress
    /// bar), if anywhere.
    pub monte_carlo_progress: Option<StepProgress>,
}

/// What a Monte Carlo propagation calls each time its particles reach one of the steps its
/// statistics are taken at: with (k, n), step k of the propagation's n, and the samples.
///
/// ```
/// use std::sync::{Arc, Mutex};
/// use posecov::eval::StepProgress;
/// let seen = Arc::new(Mutex::new(Vec::new()));
/// let into = seen.clone();
/// let hook = StepProgress(Arc::new(move |k, n, _samples| into.lock().unwrap().push((k, n))));
/// (hook.0)(3, 10, 2000);
/// assert_eq!(*seen.lock().unwrap(), [(3, 10)]);
/// ```
#[derive(Clone)]
pub struct StepProgress(pub Arc<dyn Fn(usize, usize, usize) + Send + Sync>);

impl std::fmt::Debug for StepProgress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("StepProgress")
    }
}

impl Default for EvalSettings {
    fn default() -> Self {
        Self {
            seed: 0,
            samples: limits::DEFAULT_SAMPLES as usize,
            methods: Vec::new(),
            block_samples: None,
            steps: StepPolicy::default(),
            confidence: Confidence::DEFAULT,
            unscented: Default::default(),
            cancel: None,
            graph: Default::default(),
            graph_progress: None,
            monte_carlo_progress: None,
        }
    }
}

impl EvalSettings {
    fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    fn monte_carlo(&self) -> bool {
        self.methods.contains(&Method::MonteCarlo)
    }
}

/// Evaluates a plan of any group.
///
/// ```
/// use posecov::eval::{EvalSettings, evaluate};
/// use posecov::plan::{AnyPlan, Plan};
/// use posecov::uncertain::Method;
/// let settings = EvalSettings { samples: 1, methods: vec![Method::MonteCarlo], ..Default::default() };
/// let e = evaluate(&AnyPlan::So2(Plan::default()), &settings).unwrap_err();
/// assert!(e.to_string().starts_with("samples = 1 is out of range"), "{e}");
/// ```
pub fn evaluate(plan: &AnyPlan, settings: &EvalSettings) -> Result<AnyEvaluation, EvalError> {
    check_settings(settings)?;
    Ok(match plan {
        AnyPlan::So2(p) => AnyEvaluation::So2(run::<So2, 1>(p, settings)?),
        AnyPlan::Se2(p) => AnyEvaluation::Se2(run::<Se2, 3>(p, settings)?),
        AnyPlan::So3(p) => AnyEvaluation::So3(run::<So3, 3>(p, settings)?),
        AnyPlan::Se3(p) => AnyEvaluation::Se3(run::<Se3, 6>(p, settings)?),
    })
}

/// Evaluates block `block` (0-based) of a blocked Monte Carlo sample for its particles only:
/// nodes carry the particles of samples `block · b ..` (b = `main`'s block size) and no
/// statistics. `None` past the last block. The caller draws and logs each block's clouds
/// in turn, holding one block at a time.
///
/// ```
/// use posecov::input::scenario::{Scenario, lower};
/// use posecov::eval::{EvalSettings, evaluate, evaluate_block};
/// use posecov::uncertain::Method;
/// let plan = lower(&Scenario::load_any("so3_sampling").unwrap()).unwrap().plan;
/// let settings = EvalSettings { samples: 5000, block_samples: Some(2048), methods: vec![Method::MonteCarlo], ..Default::default() };
/// let main = evaluate(&plan, &settings).unwrap();
/// assert_eq!(main.ran_with().block_samples, 2048);
/// assert!(evaluate_block(&plan, &settings, &main, 2).unwrap().is_some()); // samples 4096..5000
/// assert!(evaluate_block(&plan, &settings, &main, 3).unwrap().is_none());
/// ```
pub fn evaluate_block(
    plan: &AnyPlan,
    settings: &EvalSettings,
    main: &AnyEvaluation,
    block: usize,
) -> Result<Option<AnyEvaluation>, EvalError> {
    let ran = main.ran_with();
    let (n, b) = (ran.samples, ran.block_samples);
    let start = block.saturating_mul(b.max(1));
    if start >= n || !settings.monte_carlo() {
        return Ok(None);
    }
    let range = start..(start + b).min(n);
    Ok(Some(match plan {
        AnyPlan::So2(p) => AnyEvaluation::So2(Engine::run(p, settings, range, StatsMode::Skip)?),
        AnyPlan::Se2(p) => AnyEvaluation::Se2(Engine::run(p, settings, range, StatsMode::Skip)?),
        AnyPlan::So3(p) => AnyEvaluation::So3(Engine::run(p, settings, range, StatsMode::Skip)?),
        AnyPlan::Se3(p) => AnyEvaluation::Se3(Engine::run(p, settings, range, StatsMode::Skip)?),
    }))
}

fn check_settings(settings: &EvalSettings) -> Result<(), EvalError> {
    let n = settings.samples as u64;
    if settings.monte_carlo()
        && let Err(expected) = limits::check_samples(n)
    {
        return Err(EvalError::Setting {
            what: "samples",
            value: n.to_string(),
            expected,
        });
    }
    if settings.block_samples == Some(0) {
        return Err(EvalError::Setting {
            what: "block_samples",
            value: "0".to_owned(),
            expected: "at least 1".to_owned(),
        });
    }
    Ok(())
}

/// Refuses plans whose Monte Carlo work exceeds [`limits::MAX_PARTICLE_STEPS`], naming the
/// operation at which the sum crosses it.
fn check_work<G: EvalGroup<N>, const N: usize>(
    plan: &Plan<G, N>,
    settings: &EvalSettings,
) -> Result<(), EvalError> {
    if !settings.monte_carlo() {
        return Ok(());
    }
    let samples = settings.samples;
    let mut work = samples as f64 * plan.poses.len() as f64;
    for (i, o) in plan.operations.iter().enumerate() {
        let steps = o.op.particle_steps();
        work += samples as f64 * steps as f64;
        if work > limits::MAX_PARTICLE_STEPS {
            return Err(EvalError::TooMuchWork {
                operation: i,
                output: o.output.clone(),
                samples,
                steps,
                work,
                limit: limits::MAX_PARTICLE_STEPS,
            });
        }
    }
    Ok(())
}

/// One evaluation, in one block when the particles fit [`PARTICLE_MEMORY_BUDGET`], else
/// blocked.
fn run<G: EvalGroup<N>, const N: usize>(
    plan: &Plan<G, N>,
    settings: &EvalSettings,
) -> Result<Evaluation<G, N>, EvalError> {
    check_work(plan, settings)?;
    let n = if settings.monte_carlo() {
        settings.samples
    } else {
        0
    };
    let b = block_samples(plan, settings)?.min(n);
    let monte_carlo = || {
        if b >= n {
            Engine::run(plan, settings, 0..n, StatsMode::Own)
        } else {
            run_blocked(plan, settings, n, b)
        }
    };
    let Some(g) = &plan.graph else {
        return monte_carlo();
    };
    // A pose graph's optimisation (mostly sequential sparse algebra) and the Monte Carlo of
    // its odometry chain and loop closures share nothing: both run at once, each on the
    // cores the other leaves idle.
    let (out, evaluation) = rayon::join(monte_carlo, || {
        graph::evaluate_graph(
            g,
            &settings.graph,
            settings.confidence,
            settings.cancel.clone(),
            &mut |stage, i| {
                if let Some(hook) = &settings.graph_progress {
                    (hook.0)(stage, i);
                }
            },
        )
    });
    let mut out = out?;
    let evaluation = evaluation.map_err(|e| EvalError::Graph(e.to_string()))?;
    out.findings.extend(graph_findings(&evaluation));
    out.graph = Some(evaluation);
    Ok(out)
}

/// Most loop-closure outliers listed one by one in the findings.
pub const MAX_LISTED_OUTLIERS: usize = 50;

/// What a graph's evaluation has to tell besides its numbers.
fn graph_findings<G: EvalGroup<N>, const N: usize>(
    g: &graph::GraphEvaluation<G, N>,
) -> Vec<Finding> {
    let s = &g.solution;
    let mut out = Vec::new();
    if !s.converged() {
        out.push(Finding::GraphNotConverged {
            stop: s.stop,
            optimizer: s.optimizer,
            iterations: s.iterations,
            chi2_before: s.chi2_before,
            chi2_after: s.chi2_after,
            log: s.log[s.log.len().saturating_sub(50)..].to_vec(),
        });
    }
    if let Some(reason) = &s.marginals_error {
        out.push(Finding::GraphMarginalsFailed {
            reason: reason.clone(),
        });
    }
    if s.parts.len() > 1 {
        out.push(Finding::GraphParts {
            parts: s.parts.clone(),
        });
    }
    if !g.duplicates.is_empty() {
        out.push(Finding::DuplicateEdges {
            count: g.duplicates.len(),
            lines: g.duplicates.iter().take(10).copied().collect(),
        });
    }
    let outliers = g.outliers();
    for l in outliers.iter().take(MAX_LISTED_OUTLIERS) {
        out.push(Finding::LoopClosureOutlier {
            from: l.from,
            to: l.to,
            line: l.line,
            mahalanobis: l.mahalanobis,
            mahalanobis_before: l.mahalanobis_before,
            radius: g.radius,
            confidence: g.confidence,
        });
    }
    if outliers.len() > MAX_LISTED_OUTLIERS {
        out.push(Finding::MoreLoopClosureOutliers {
            more: outliers.len() - MAX_LISTED_OUTLIERS,
            outliers: outliers.len(),
            loop_closures: g.loop_closures.len(),
        });
    }
    out
}

/// Particles per block: the settings', else as many as fit the budget given how many
/// particle sets are held at once (counted from the plan), within
/// [`MIN_BLOCK_SAMPLES`] ..= [`MAX_BLOCK_SAMPLES`]; always a multiple of [`CHUNK_SIZE`].
fn block_samples<G: EvalGroup<N>, const N: usize>(
    plan: &Plan<G, N>,
    settings: &EvalSettings,
) -> Result<usize, EvalError> {
    let round = |b: usize| b.div_ceil(CHUNK_SIZE).max(1) * CHUNK_SIZE;
    if let Some(b) = settings.block_samples {
        return Ok(round(b));
    }
    if !settings.monte_carlo() {
        return Ok(0);
    }
    // Particle sets held at once: one per uncertain input and single result, the detailed
    // steps of each propagation, and the step in flight.
    let policy = settings.steps;
    let uncertain = plan
        .poses
        .iter()
        .filter(|p| matches!(p.value, PoseValue::Uncertain(_)))
        .count();
    let results: usize = plan
        .operations
        .iter()
        .map(|o| match o.op.steps() {
            0 => 1,
            last => (0..=last).filter(|k| policy.detailed(*k, last)).count(),
        })
        .sum();
    let held = uncertain + results + 1;
    let points = plan
        .operations
        .iter()
        .filter(|o| matches!(o.op, Op::PointThroughPose { .. }))
        .count();
    let bytes = held * std::mem::size_of::<G>() + points * 24;
    let fit = PARTICLE_MEMORY_BUDGET / bytes.max(1);
    Ok(fit.clamp(MIN_BLOCK_SAMPLES, MAX_BLOCK_SAMPLES) / CHUNK_SIZE * CHUNK_SIZE)
}

/// Blocked Monte Carlo: block 0 is evaluated (its Lie means start the iteration), then
/// every block is re-simulated once per pass of the Lie-mean iteration, summing each node's
/// tangent moments ([`BlockedStats`]); finally block 0 again, with those statistics.
fn run_blocked<G: EvalGroup<N>, const N: usize>(
    plan: &Plan<G, N>,
    settings: &EvalSettings,
    n: usize,
    b: usize,
) -> Result<Evaluation<G, N>, EvalError> {
    let blocks: Vec<Range<usize>> = (0..n).step_by(b).map(|s| s..(s + b).min(n)).collect();
    let first = Engine::<G, N>::run(plan, settings, 0..b, StatsMode::Own)?;
    let mut stats = BlockedStats::start(&first, n);
    drop(first);
    let mut passes = 0;
    while stats.iterating() {
        for range in &blocks {
            if settings.cancelled() {
                let mut out = Engine::run(plan, settings, 0..b, StatsMode::Own)?;
                out.findings.push(Finding::Interrupted);
                return Ok(out);
            }
            Engine::run(
                plan,
                settings,
                range.clone(),
                StatsMode::Collect(&mut stats, passes == 0),
            )?;
        }
        stats.finish_pass();
        passes += 1;
    }
    let mut out = Engine::run(plan, settings, 0..b, StatsMode::Blocked(&stats))?;
    out.samples = n;
    out.findings.push(Finding::Blocked {
        samples: n,
        blocks: blocks.len(),
        block_samples: b,
        passes,
    });
    Ok(out)
}
