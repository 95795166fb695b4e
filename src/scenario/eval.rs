//! Evaluating a scenario: every named pose and every operation, with every requested method,
//! Monte Carlo particles flowing through the operations, and errors against Monte Carlo.
//!
//! Monte Carlo here is end to end: each uncertain input is sampled once (n particles, seeded
//! from the scenario seed and the input's index), and every operation maps particles to
//! particles, drawing fresh process noise where the operation has some. Each node's Monte
//! Carlo estimate is the iterative Lie mean and 1/(N−1) covariance of its particles (right
//! side). Analytic methods propagate Gaussians operation by operation.
//!
//! # Blocked Monte Carlo: bounded memory
//! Every random draw comes from the stream of its 1024-sample chunk
//! ([`crate::sample::chunk_rng`]), so any block of samples `k·1024 ..` can be simulated
//! through all operations on its own and gets exactly the particles a whole-sample run would.
//! When the particles of all nodes would exceed [`PARTICLE_MEMORY_BUDGET`] (e.g. 10⁷ samples),
//! the sample is split into blocks: the statistics are summed block by block (one pass over
//! the blocks per Lie-mean iteration, each pass re-simulating the blocks; nothing but the
//! current block is held), the evaluation keeps the first block's particles for drawing, and
//! [`evaluate_block`] re-simulates any later block for its clouds. Memory is then bounded by
//! the budget whatever the sample count; time grows by the number of passes (typically 3–5)
//! plus one. Samples that fit are evaluated exactly as before, in one block.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{DMatrix, Matrix3, Vector3};
use toml::Spanned;

use super::groups::{DiffDriveParams, EvalGroup};
use super::model::{
    AnyEvaluation, Estimate, Evaluation, MatrixFrame, Meta, Node, PointNode, PosePath, Role, Series,
};
use super::schema::{GroupName, OperationSpec};
use super::spec::{cov_for, fixed_matrix, mean_for};
use super::{Scenario, ScenarioError, SpecGroup};
use crate::lie::{LieGroup, Se2, Se3, So2, So3, Tangent, TangentMatrix};
use crate::propagate::first_order::{self, CorrelatedPair};
use crate::propagate::fourth_order::Order;
use crate::propagate::fusion::{FusionOptions, fuse};
use crate::propagate::odometry::{InputNoise, propagate_increments, propagate_tangent_inputs};
use crate::propagate::sigma_point::{self, Unscented};
use crate::propagate::{Propagated, relative_frobenius_error};
use crate::sample::{
    CHUNK_SIZE, LIE_MEAN_MAX_ITERATIONS, LIE_MEAN_TOLERANCE, SampleStatistics, Sampler,
    fill_par_from, retract, sample_statistics, standard_normal, tangent_moments,
};
use crate::uncertain::{Method, Side, UncertainPose};

/// Defaults when neither the file nor the command line says.
pub const DEFAULT_SAMPLES: u64 = 2000;
/// Default confidence of drawn regions.
pub const DEFAULT_CONFIDENCE: f64 = 0.95;
/// Largest Monte Carlo sample count accepted.
pub const MAX_SAMPLES: u64 = 10_000_000;

/// Command-line overrides and controls for [`evaluate`].
#[derive(Debug, Clone, Default)]
pub struct EvalOptions {
    /// Overrides `[scenario] seed`.
    pub seed: Option<u64>,
    /// Overrides `[scenario] samples`.
    pub samples: Option<u64>,
    /// Overrides `[scenario] confidence`.
    pub confidence: Option<f64>,
    /// Set to stop a long evaluation early (Ctrl-C): evaluation returns what it has so far.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Monte Carlo particles held in memory at once (rounded up to a multiple of
    /// [`CHUNK_SIZE`]); `None` chooses from [`PARTICLE_MEMORY_BUDGET`]. See
    /// [blocked Monte Carlo](self#blocked-monte-carlo-bounded-memory).
    pub block_samples: Option<usize>,
}

/// Bytes of Monte Carlo particles (all nodes together) an evaluation holds at once; larger
/// samples are simulated in blocks ([blocked Monte Carlo](self#blocked-monte-carlo-bounded-memory)).
pub const PARTICLE_MEMORY_BUDGET: usize = 128 << 20;
/// Samples up to this count are never split into blocks.
pub const MIN_BLOCK_SAMPLES: usize = 16 * CHUNK_SIZE;
/// At most this many particles per block (also the size of the drawn first block's clouds).
pub const MAX_BLOCK_SAMPLES: usize = 64 * CHUNK_SIZE;

/// Evaluates a parsed scenario.
///
/// ```
/// use posecov::scenario::{Scenario, eval::{evaluate, EvalOptions}};
/// let text = "[scenario]\ntitle='t'\ngroup='se2'\nmethods=['first_order','monte_carlo']\nsamples=500\n\
///             [[pose]]\nname='a'\nmean={xy_theta=[1,0,0]}\ncov={std=[0.1,0.1,0.1]}\n\
///             [[operation]]\nkind='inverse'\ninput='a'\noutput='a_inv'\n";
/// let e = evaluate(&Scenario::parse(text, "t.toml").unwrap(), &EvalOptions::default()).unwrap();
/// let records = e.records();
/// assert!(records.iter().any(|r| r.label == "a_inv" && r.relative_error_vs_monte_carlo.is_some()));
/// ```
pub fn evaluate(
    scenario: &Scenario,
    options: &EvalOptions,
) -> Result<AnyEvaluation, ScenarioError> {
    let meta = meta(scenario, options)?;
    Ok(match meta.group {
        GroupName::So2 => AnyEvaluation::So2(run::<So2, 1>(scenario, meta, options)?),
        GroupName::Se2 => AnyEvaluation::Se2(run::<Se2, 3>(scenario, meta, options)?),
        GroupName::So3 => AnyEvaluation::So3(run::<So3, 3>(scenario, meta, options)?),
        GroupName::Se3 => AnyEvaluation::Se3(run::<Se3, 6>(scenario, meta, options)?),
    })
}

/// Evaluates block `block` (0-based) of a blocked Monte Carlo sample for its particles only:
/// nodes carry the particles of samples `block · b ..` (b = `main.meta().block_samples`) and
/// no Monte Carlo statistics. `None` past the last block. This is what draws the clouds of a
/// large sample a block at a time (`draw::particle_parts`).
///
/// ```
/// use posecov::scenario::{Scenario, eval::{EvalOptions, evaluate, evaluate_block}};
/// let s = Scenario::load_any("so3_sampling").unwrap();
/// let options = EvalOptions { samples: Some(5000), block_samples: Some(2048), ..Default::default() };
/// let main = evaluate(&s, &options).unwrap();
/// assert_eq!(main.meta().block_samples, 2048);
/// assert!(evaluate_block(&s, &options, &main, 2).unwrap().is_some()); // samples 4096..5000
/// assert!(evaluate_block(&s, &options, &main, 3).unwrap().is_none());
/// ```
pub fn evaluate_block(
    scenario: &Scenario,
    options: &EvalOptions,
    main: &AnyEvaluation,
    block: usize,
) -> Result<Option<AnyEvaluation>, ScenarioError> {
    let meta = main.meta().clone();
    let (n, b) = (meta.samples, meta.block_samples.max(1));
    let start = block.saturating_mul(b);
    if start >= n || !meta.methods.contains(&Method::MonteCarlo) {
        return Ok(None);
    }
    let range = start..(start + b).min(n);
    Ok(Some(match meta.group {
        GroupName::So2 => AnyEvaluation::So2(particles_only(scenario, meta, options, range)?),
        GroupName::Se2 => AnyEvaluation::Se2(particles_only(scenario, meta, options, range)?),
        GroupName::So3 => AnyEvaluation::So3(particles_only(scenario, meta, options, range)?),
        GroupName::Se3 => AnyEvaluation::Se3(particles_only(scenario, meta, options, range)?),
    }))
}

/// Samples `range` of a blocked sample, for their particles only (no statistics).
fn particles_only<G: EvalGroup<N>, const N: usize>(
    scenario: &Scenario,
    meta: Meta,
    options: &EvalOptions,
    range: Range<usize>,
) -> Result<Evaluation<G, N>, ScenarioError> {
    Engine::run(scenario, meta, options, range, StatsSource::Skip)
}

/// One evaluation, in one block when the particles fit [`PARTICLE_MEMORY_BUDGET`], else
/// blocked ([`run_blocked`]).
fn run<G: EvalGroup<N>, const N: usize>(
    scenario: &Scenario,
    mut meta: Meta,
    options: &EvalOptions,
) -> Result<Evaluation<G, N>, ScenarioError> {
    let n = meta.samples;
    let block = block_samples::<G, N>(scenario, &meta, options)?;
    meta.block_samples = block.min(n);
    if block >= n {
        return Engine::run(scenario, meta, options, 0..n, StatsSource::Own);
    }
    run_blocked(scenario, meta, options)
}

/// Particles per block: `options.block_samples`, else as many as fit the budget given how
/// many nodes hold particles (counted by an evaluation without Monte Carlo), within
/// [`MIN_BLOCK_SAMPLES`] ..= [`MAX_BLOCK_SAMPLES`]; always a multiple of [`CHUNK_SIZE`].
fn block_samples<G: EvalGroup<N>, const N: usize>(
    scenario: &Scenario,
    meta: &Meta,
    options: &EvalOptions,
) -> Result<usize, ScenarioError> {
    let round = |b: usize| b.div_ceil(CHUNK_SIZE).max(1) * CHUNK_SIZE;
    if let Some(b) = options.block_samples {
        return Ok(round(b));
    }
    if meta.samples <= MIN_BLOCK_SAMPLES || !meta.methods.contains(&Method::MonteCarlo) {
        return Ok(meta.samples);
    }
    let mut dry = meta.clone();
    dry.methods.retain(|m| *m != Method::MonteCarlo);
    let shape = Engine::<G, N>::run(scenario, dry, options, 0..0, StatsSource::Skip)?;
    let nodes = shape.nodes.iter().filter(|n| n.role != Role::Fixed).count();
    let bytes = nodes * std::mem::size_of::<G>() + shape.points.len() * 24;
    let fit = PARTICLE_MEMORY_BUDGET / bytes.max(1);
    Ok(fit.clamp(MIN_BLOCK_SAMPLES, MAX_BLOCK_SAMPLES) / CHUNK_SIZE * CHUNK_SIZE)
}

/// Blocked Monte Carlo: block 0 is evaluated (its particles are what gets drawn), then
/// every block is re-simulated once per pass of the Lie-mean iteration, summing each node's
/// tangent moments ([`BlockedStats`]); finally block 0 again, with those statistics.
fn run_blocked<G: EvalGroup<N>, const N: usize>(
    scenario: &Scenario,
    meta: Meta,
    options: &EvalOptions,
) -> Result<Evaluation<G, N>, ScenarioError> {
    let (n, b) = (meta.samples, meta.block_samples);
    let blocks: Vec<Range<usize>> = (0..n).step_by(b).map(|s| s..(s + b).min(n)).collect();
    let first = Engine::<G, N>::run(scenario, meta.clone(), options, 0..b, StatsSource::Own)?;
    let cancelled = || {
        options
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    };
    let mut stats = BlockedStats::start(&first);
    let mut pass = 0;
    while stats.iterating() && pass < LIE_MEAN_MAX_ITERATIONS {
        for range in &blocks {
            if cancelled() {
                return Engine::run(scenario, meta, options, 0..b, StatsSource::Own);
            }
            if range.start == 0 {
                stats.add(&first, pass == 0);
            } else {
                let e = particles_only(scenario, meta.clone(), options, range.clone())?;
                stats.add(&e, pass == 0);
            }
        }
        stats.finish_pass(n);
        pass += 1;
    }
    drop(first);
    let mut out = Engine::run(
        scenario,
        meta,
        options,
        0..b,
        StatsSource::Blocked(Arc::new(stats)),
    )?;
    out.notes.push(format!(
        "Monte Carlo: {n} samples simulated in {} blocks of {b} to bound memory; the statistics \
         use every sample ({pass} passes of the Lie-mean iteration); the clouds of samples \
         beyond the first block are logged block by block.",
        blocks.len()
    ));
    Ok(out)
}

/// Running sums of one node's particles over the blocks of a sample.
struct NodeMoments<G: LieGroup<N>, const N: usize> {
    /// The Lie-mean estimate μ of the current pass (right side).
    mean: G,
    iterations: usize,
    /// Σ ξ and Σ ξξᵀ of ξ = Log(μ⁻¹ X) in the current pass.
    sum: Tangent<N>,
    outer: TangentMatrix<N>,
    /// Set when the iteration converged; the covariance is the converged pass's
    /// (Σ ξξᵀ − n s sᵀ)/(n − 1) about μ, s = Σ ξ / n (‖s‖ < the tolerance 1e-10, so this
    /// equals the covariance about the final mean to that order).
    result: Option<SampleStatistics<G, N>>,
    failed: bool,
    /// Σ Log_left(X nominal⁻¹) Log_left(…)ᵀ (first pass).
    left_outer: TangentMatrix<N>,
    /// Positions are summed relative to `shift` (block 0's mean) to avoid cancellation.
    shift: Vector3<f64>,
    translation_sum: Vector3<f64>,
}

/// Running sums of one point node's Monte Carlo points (relative to `shift`).
struct PointMoments {
    shift: Vector3<f64>,
    sum: Vector3<f64>,
    outer: Matrix3<f64>,
}

impl PointMoments {
    /// Mean and 1/(n−1) covariance of `n` points.
    fn statistics(&self, n: usize) -> (Vector3<f64>, Matrix3<f64>) {
        let d = self.sum / n as f64;
        let cov = (self.outer - d * d.transpose() * n as f64) / (n as f64 - 1.0);
        (self.shift + d, cov)
    }
}

/// Monte Carlo statistics of a sample too large to hold, gathered block by block: per node
/// the iterative Lie mean (one pass over every block per iteration, as
/// [`crate::sample::lie_mean`] with the same tolerance and iteration cap, started from block
/// 0's mean) and its covariance; the uncentred left covariance about the nominal and the
/// mean position; per point node the mean and covariance of the points.
struct BlockedStats<G: LieGroup<N>, const N: usize> {
    nodes: Vec<Option<NodeMoments<G, N>>>,
    points: Vec<Option<PointMoments>>,
}

impl<G: EvalGroup<N>, const N: usize> BlockedStats<G, N> {
    fn start(first: &Evaluation<G, N>) -> Self {
        let nodes = first
            .nodes
            .iter()
            .map(|node| {
                let particles = node
                    .particles
                    .as_ref()
                    .filter(|_| node.role != Role::Fixed)?;
                let mean = node
                    .estimates
                    .iter()
                    .rev()
                    .find(|e| e.result.method == Method::MonteCarlo)
                    .map_or(*particles.first()?, |e| *e.result.pose.mean());
                let shift = particles
                    .iter()
                    .map(|g| *g.to_se3().translation())
                    .sum::<Vector3<f64>>()
                    / particles.len() as f64;
                Some(NodeMoments {
                    mean,
                    iterations: 0,
                    sum: Tangent::<N>::zeros(),
                    outer: TangentMatrix::<N>::zeros(),
                    result: None,
                    failed: false,
                    left_outer: TangentMatrix::<N>::zeros(),
                    shift,
                    translation_sum: Vector3::zeros(),
                })
            })
            .collect();
        let points = first
            .points
            .iter()
            .map(|p| {
                let q = p.particles.as_ref().filter(|q| !q.is_empty())?;
                let shift =
                    q.iter().map(|x| Vector3::from(*x)).sum::<Vector3<f64>>() / q.len() as f64;
                Some(PointMoments {
                    shift,
                    sum: Vector3::zeros(),
                    outer: Matrix3::zeros(),
                })
            })
            .collect();
        Self { nodes, points }
    }

    fn node(&self, index: usize) -> Option<&NodeMoments<G, N>> {
        self.nodes.get(index).and_then(Option::as_ref)
    }

    /// Whether some node's Lie mean is still iterating.
    fn iterating(&self) -> bool {
        self.nodes
            .iter()
            .flatten()
            .any(|n| n.result.is_none() && !n.failed)
    }

    /// Adds one block's particles (`first_pass`: also the one-pass sums).
    fn add(&mut self, block: &Evaluation<G, N>, first_pass: bool) {
        for (acc, node) in self.nodes.iter_mut().zip(&block.nodes) {
            let (Some(acc), Some(particles)) = (acc.as_mut(), node.particles.as_ref()) else {
                continue;
            };
            if acc.result.is_none() && !acc.failed {
                let (sum, outer) = tangent_moments(particles, &acc.mean, Side::Right);
                acc.sum += sum;
                acc.outer += outer;
            }
            if first_pass {
                acc.left_outer += tangent_moments(particles, &node.nominal, Side::Left).1;
                acc.translation_sum += particles
                    .iter()
                    .map(|g| g.to_se3().translation() - acc.shift)
                    .sum::<Vector3<f64>>();
            }
        }
        if first_pass {
            for (acc, point) in self.points.iter_mut().zip(&block.points) {
                let (Some(acc), Some(q)) = (acc.as_mut(), point.particles.as_ref()) else {
                    continue;
                };
                for x in q {
                    let d = Vector3::from(*x) - acc.shift;
                    acc.sum += d;
                    acc.outer += d * d.transpose();
                }
            }
        }
    }

    /// Ends a pass over all `n` samples: one Lie-mean step per node still iterating.
    fn finish_pass(&mut self, n: usize) {
        for acc in self.nodes.iter_mut().flatten() {
            if acc.result.is_some() || acc.failed {
                continue;
            }
            acc.iterations += 1;
            let step = acc.sum / n as f64;
            let norm = step.norm();
            if !norm.is_finite() {
                acc.failed = true;
            } else if norm < LIE_MEAN_TOLERANCE {
                let centred = acc.outer - step * step.transpose() * n as f64;
                acc.result = Some(SampleStatistics {
                    mean: retract(&acc.mean, &step, Side::Right),
                    cov: (centred + centred.transpose()) * (0.5 / (n as f64 - 1.0)),
                    side: Side::Right,
                    count: n,
                    iterations: acc.iterations,
                });
            } else if acc.iterations >= LIE_MEAN_MAX_ITERATIONS {
                acc.failed = true; // as `lie_mean`'s NotConverged: no Monte Carlo estimate
            } else {
                acc.mean = retract(&acc.mean, &step, Side::Right);
            }
            acc.sum = Tangent::<N>::zeros();
            acc.outer = TangentMatrix::<N>::zeros();
        }
    }
}

fn meta(scenario: &Scenario, options: &EvalOptions) -> Result<Meta, ScenarioError> {
    let h = &scenario.file.scenario;
    let loc = &scenario.locator;
    let samples = match (options.samples, &h.samples) {
        (Some(n), _) => n,
        (None, Some(n)) => *n.get_ref(),
        (None, None) => DEFAULT_SAMPLES,
    };
    if !(2..=MAX_SAMPLES).contains(&samples) {
        let span = h.samples.as_ref().map_or(0..0, Spanned::span);
        return Err(loc.error(
            span,
            "scenario.samples",
            format!("{samples} is out of range: use 2 ..= {MAX_SAMPLES}"),
        ));
    }
    let confidence = options
        .confidence
        .or(h.confidence.as_ref().map(|c| *c.get_ref()))
        .unwrap_or(DEFAULT_CONFIDENCE);
    if !(confidence > 0.0 && confidence < 1.0) {
        let span = h.confidence.as_ref().map_or(0..0, Spanned::span);
        return Err(loc.error(
            span,
            "scenario.confidence",
            format!("{confidence} is not a probability in (0, 1), e.g. 0.95"),
        ));
    }
    let mut methods = h.methods.clone();
    methods.dedup();
    Ok(Meta {
        block_samples: samples as usize,
        title: h.title.clone(),
        description: h.description.clone(),
        source: h.source.clone(),
        group: h.group,
        seed: options.seed.or(h.seed).unwrap_or(0),
        samples: samples as usize,
        confidence,
        methods,
        draw: scenario.file.draw.clone(),
    })
}

/// The keys each operation kind uses besides `kind` and `output`.
fn operation_keys(kind: &str) -> Option<(&'static [&'static str], &'static [&'static str])> {
    // (required, optional)
    Some(match kind {
        "inverse" => (&["input"], &[]),
        "change_frame_left" | "change_frame_right" => (&["input", "by"], &[]),
        "compose" | "between" => (&["lhs", "rhs"], &[]),
        "compose_correlated" | "between_correlated" => (&["lhs", "rhs", "cross_cov"], &[]),
        "odometry" => (&["input", "controls", "noise", "model"], &["steps"]),
        "compound" => (&["input", "by", "noise", "steps"], &[]),
        "diff_drive" => (
            &[
                "wheel_radius",
                "wheelbase",
                "duration",
                "diffusion",
                "speed",
                "turn_rate",
            ],
            &["input", "dt"],
        ),
        "point_through_pose" => (&["input", "point"], &["point_cov"]),
        "fuse" => (&["inputs"], &[]),
        "euler_vs_exp" => (&["rate", "dt", "steps"], &["input"]),
        _ => return None,
    })
}

fn keys_set(op: &OperationSpec) -> Vec<&'static str> {
    [
        ("input", op.input.is_some()),
        ("lhs", op.lhs.is_some()),
        ("rhs", op.rhs.is_some()),
        ("by", op.by.is_some()),
        ("inputs", op.inputs.is_some()),
        ("cross_cov", op.cross_cov.is_some()),
        ("controls", op.controls.is_some()),
        ("steps", op.steps.is_some()),
        ("noise", op.noise.is_some()),
        ("model", op.model.is_some()),
        ("point", op.point.is_some()),
        ("point_cov", op.point_cov.is_some()),
        ("wheel_radius", op.wheel_radius.is_some()),
        ("wheelbase", op.wheelbase.is_some()),
        ("duration", op.duration.is_some()),
        ("diffusion", op.diffusion.is_some()),
        ("speed", op.speed.is_some()),
        ("turn_rate", op.turn_rate.is_some()),
        ("dt", op.dt.is_some()),
        ("rate", op.rate.is_some()),
    ]
    .iter()
    .filter(|(_, on)| *on)
    .map(|(k, _)| *k)
    .collect()
}

/// Monte Carlo particles of a node, shared between the operations that read it.
type Particles<G> = Option<Arc<Vec<G>>>;

/// Where an engine run takes its Monte Carlo statistics from.
enum StatsSource<G: LieGroup<N>, const N: usize> {
    /// From this run's particles: the whole sample, when it fits in one block.
    Own,
    /// Nowhere: a pass over one block of a larger sample, run for its particles only.
    Skip,
    /// From passes over every block of a larger sample ([`BlockedStats`]).
    Blocked(Arc<BlockedStats<G, N>>),
}

/// A named thing an operation can take as input.
#[derive(Clone, Copy)]
enum Value<G: LieGroup<N>, const N: usize> {
    /// A known transform.
    Fixed(G),
    /// The latest node of that name.
    Node(usize),
}

struct Engine<'a, G: EvalGroup<N>, const N: usize> {
    scenario: &'a Scenario,
    meta: Meta,
    monte_carlo: bool,
    cancel: Option<Arc<AtomicBool>>,
    names: HashMap<String, Value<G, N>>,
    out: Evaluation<G, N>,
    /// Random families already used (one per sampled input or noise source).
    families: u64,
    /// The particles this run simulates: sample indices `block`, `block.start` a multiple of
    /// [`CHUNK_SIZE`], so that every random draw is the one the whole sample would make.
    block: Range<usize>,
    stats: StatsSource<G, N>,
}

impl<'a, G: EvalGroup<N>, const N: usize> Engine<'a, G, N> {
    fn run(
        scenario: &'a Scenario,
        meta: Meta,
        options: &EvalOptions,
        block: Range<usize>,
        stats: StatsSource<G, N>,
    ) -> Result<Evaluation<G, N>, ScenarioError> {
        let monte_carlo = meta.methods.contains(&Method::MonteCarlo);
        let mut engine = Engine {
            scenario,
            monte_carlo,
            cancel: options.cancel.clone(),
            names: HashMap::new(),
            out: Evaluation {
                meta: meta.clone(),
                nodes: Vec::new(),
                points: Vec::new(),
                paths: Vec::new(),
                matrix_frames: Vec::new(),
                series: Vec::new(),
                notes: Vec::new(),
            },
            meta,
            families: 0,
            block,
            stats,
        };
        engine.poses()?;
        for (index, op) in scenario.file.operations.iter().enumerate() {
            if engine.cancelled() {
                engine.out.notes.push(
                    "*Evaluation interrupted: later operations were not evaluated.*".to_owned(),
                );
                break;
            }
            engine.operation(index, op)?;
        }
        engine.errors_against_monte_carlo();
        Ok(engine.out)
    }

    fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    fn err(
        &self,
        span: std::ops::Range<usize>,
        field: &str,
        message: impl Into<String>,
    ) -> ScenarioError {
        self.scenario.locator.error(span, field, message)
    }

    /// A key the operation kind requires (checked by `operation_keys`; an error, not a panic,
    /// if that ever disagrees).
    fn need<'b, T>(
        &self,
        value: &'b Option<T>,
        op: &OperationSpec,
        field: &str,
        key: &str,
    ) -> Result<&'b T, ScenarioError> {
        value.as_ref().ok_or_else(|| {
            self.err(
                op.kind.span(),
                &format!("{field}.{key}"),
                format!("`{}` needs `{key}`", op.kind.get_ref()),
            )
        })
    }

    fn wants(&self, method: Method) -> bool {
        self.meta.methods.contains(&method)
    }

    /// The chunk index of this run's first particle (see [`fill_par_from`]).
    fn first_chunk(&self) -> u64 {
        (self.block.start / CHUNK_SIZE) as u64
    }

    /// Monte Carlo Lie mean and covariance (right side) of node `index`.
    fn mc_stats(&self, index: usize) -> Option<SampleStatistics<G, N>> {
        match &self.stats {
            StatsSource::Own => self.out.nodes[index]
                .particles
                .as_ref()
                .and_then(|p| sample_statistics(p, Side::Right).ok()),
            StatsSource::Skip => None,
            StatsSource::Blocked(b) => b.node(index).and_then(|n| n.result),
        }
    }

    /// Monte Carlo E[ξξᵀ] of node `index` about its nominal, left side (uncentred).
    fn mc_uncentred_left(&self, index: usize) -> Option<TangentMatrix<N>> {
        let node = &self.out.nodes[index];
        match &self.stats {
            StatsSource::Own => node.particles.as_ref().and_then(|p| {
                crate::sample::uncentred_covariance(p, &node.nominal, Side::Left).ok()
            }),
            StatsSource::Skip => None,
            StatsSource::Blocked(b) => b
                .node(index)
                .map(|n| n.left_outer / self.meta.samples as f64),
        }
    }

    /// Mean of the particles' positions (Cartesian) of node `index`.
    fn mc_translation_mean(&self, index: usize) -> Option<Vector3<f64>> {
        match &self.stats {
            StatsSource::Own => self.out.nodes[index].particles.as_ref().map(|p| {
                p.iter()
                    .map(|g| *g.to_se3().translation())
                    .sum::<Vector3<f64>>()
                    / p.len() as f64
            }),
            StatsSource::Skip => None,
            StatsSource::Blocked(b) => b
                .node(index)
                .map(|n| n.shift + n.translation_sum / self.meta.samples as f64),
        }
    }

    /// Mean and 1/(N−1) covariance of the Monte Carlo points of point node `index`
    /// (`moved`: this run's points).
    fn mc_point_stats(
        &self,
        index: usize,
        moved: &[[f64; 3]],
    ) -> Option<(Vector3<f64>, Matrix3<f64>)> {
        match &self.stats {
            StatsSource::Own => {
                let n = moved.len() as f64;
                let m = moved
                    .iter()
                    .fold(Vector3::zeros(), |a, q| a + Vector3::from(*q))
                    / n;
                let c = moved.iter().fold(Matrix3::zeros(), |a, q| {
                    let d = Vector3::from(*q) - m;
                    a + d * d.transpose()
                }) / (n - 1.0);
                Some((m, c))
            }
            StatsSource::Skip => None,
            StatsSource::Blocked(b) => b
                .points
                .get(index)
                .and_then(Option::as_ref)
                .map(|p| p.statistics(self.meta.samples)),
        }
    }

    fn next_family(&mut self) -> u64 {
        self.families += 1;
        self.families
    }

    // ------------------------------------------------------------------------------------
    // Inputs.

    /// Whether a pose is drawn by default: `a_from_b` only when `a` is the scenario's root
    /// frame (the parent of its first uncertain pose) — a relative pose such as `a_from_b` or
    /// `b_from_world` drawn at world coordinates would mislead; names without the convention
    /// are drawn.
    fn drawn_by_default(&self, name: &str) -> bool {
        match (self.root(), parent_frame(name)) {
            (Some(root), Some(parent)) => parent == root,
            _ => true,
        }
    }

    fn root(&self) -> Option<&str> {
        self.scenario
            .file
            .poses
            .iter()
            .find(|p| p.cov.is_some())
            .and_then(|p| parent_frame(p.name.get_ref()))
    }

    fn poses(&mut self) -> Result<(), ScenarioError> {
        let root = self.root().map(str::to_owned);
        for (i, spec) in self.scenario.file.poses.iter().enumerate() {
            let field = format!("pose[{i}]");
            let name = spec.name.get_ref().clone();
            check_name(&name)
                .map_err(|m| self.err(spec.name.span(), &format!("{field}.name"), m))?;
            if self.names.contains_key(&name) {
                return Err(self.err(
                    spec.name.span(),
                    &format!("{field}.name"),
                    format!("`{name}` is already defined"),
                ));
            }
            let mean: G = mean_for(spec.mean.get_ref())
                .map_err(|m| self.err(spec.mean.span(), &format!("{field}.mean"), m))?;
            let Some(cov) = &spec.cov else {
                self.names.insert(name.clone(), Value::Fixed(mean));
                let draw = spec
                    .draw
                    .unwrap_or_else(|| root.is_some() && parent_frame(&name) == root.as_deref());
                self.out.nodes.push(Node {
                    name,
                    role: Role::Fixed,
                    step: None,
                    draw,
                    nominal: mean,
                    estimates: Vec::new(),
                    particles: None,
                });
                continue;
            };
            let (cov_matrix, side) = cov_for::<G, N>(cov.get_ref(), &mean)
                .map_err(|m| self.err(cov.span(), &format!("{field}.cov"), m))?;
            let pose = UncertainPose::new_unchecked(mean, cov_matrix, side);
            let particles = if self.monte_carlo {
                Some(Arc::new(self.sample(&pose)))
            } else {
                None
            };
            let estimate = Estimate {
                result: Propagated {
                    pose,
                    method: Method::Exact,
                },
                error_vs_monte_carlo: None,
            };
            let draw = spec.draw.unwrap_or_else(|| self.drawn_by_default(&name));
            self.push_node(Node {
                name,
                role: Role::Input,
                step: None,
                draw,
                nominal: mean,
                estimates: vec![estimate],
                particles,
            });
        }
        Ok(())
    }

    fn sample(&mut self, pose: &UncertainPose<G, N>) -> Vec<G> {
        let family = self.next_family();
        let mut out = vec![*pose.mean(); self.block.len()];
        // A valid covariance always has a square root; fall back to the mean if not.
        if let Ok(sampler) = Sampler::new(pose) {
            sampler.fill_par_from(&mut out, self.meta.seed, family, self.first_chunk());
        }
        out
    }

    fn push_node(&mut self, node: Node<G, N>) {
        self.names
            .insert(node.name.clone(), Value::Node(self.out.nodes.len()));
        self.out.nodes.push(node);
    }

    fn lookup(&self, name: &Spanned<String>, field: &str) -> Result<Value<G, N>, ScenarioError> {
        self.names.get(name.get_ref()).copied().ok_or_else(|| {
            let mut known: Vec<&String> = self.names.keys().collect();
            known.sort();
            let known: Vec<&str> = known.iter().map(|s| s.as_str()).collect();
            self.err(
                name.span(),
                field,
                format!(
                    "no pose named `{}` (defined so far: {})",
                    name.get_ref(),
                    known.join(", ")
                ),
            )
        })
    }

    /// The first-order Gaussian and the particles of a named value.
    fn gaussian(&self, value: Value<G, N>) -> (UncertainPose<G, N>, Particles<G>) {
        match value {
            Value::Fixed(g) => (UncertainPose::certain(g), None),
            Value::Node(i) => {
                let node = &self.out.nodes[i];
                let pose = node
                    .estimates
                    .iter()
                    .find(|e| {
                        matches!(
                            e.result.method,
                            Method::Exact | Method::FirstOrder | Method::ClosedForm
                        )
                    })
                    .or(node.estimates.first())
                    .map_or(UncertainPose::certain(node.nominal), |e| e.result.pose);
                (pose, node.particles.clone())
            }
        }
    }

    /// The Gaussian and particles of the pose an operation key (`input`, `lhs`, `rhs`) names.
    fn input_gaussian(
        &self,
        op: &OperationSpec,
        field: &str,
        key: &str,
        value: &Option<Spanned<String>>,
    ) -> Result<(UncertainPose<G, N>, Particles<G>), ScenarioError> {
        let name = self.need(value, op, field, key)?;
        Ok(self.gaussian(self.lookup(name, &format!("{field}.{key}"))?))
    }

    fn fixed(&self, name: &Spanned<String>, field: &str) -> Result<G, ScenarioError> {
        match self.lookup(name, field)? {
            Value::Fixed(g) => Ok(g),
            Value::Node(_) => Err(self.err(
                name.span(),
                field,
                format!(
                    "`{}` must be a known transform (a pose without `cov`)",
                    name.get_ref()
                ),
            )),
        }
    }

    // ------------------------------------------------------------------------------------
    // Operations.

    fn operation(&mut self, index: usize, op: &OperationSpec) -> Result<(), ScenarioError> {
        let field = format!("operation[{index}]");
        let kind = op.kind.get_ref().as_str();
        let Some((required, optional)) = operation_keys(kind) else {
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.kind"),
                format!(
                    "unknown operation `{kind}`; expected one of {}",
                    super::schema::OPERATION_KINDS.join(", ")
                ),
            ));
        };
        let set = keys_set(op);
        if let Some(extra) = set
            .iter()
            .find(|k| !required.contains(k) && !optional.contains(k))
        {
            let mut takes: Vec<&str> = required.to_vec();
            takes.extend(optional);
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.{extra}"),
                format!(
                    "`{extra}` does not apply to `{kind}`, which takes {} (and output)",
                    takes.join(", ")
                ),
            ));
        }
        if let Some(missing) = required.iter().find(|k| !set.contains(k)) {
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.{missing}"),
                format!("`{kind}` needs `{missing}`"),
            ));
        }
        let output = op.output.get_ref().clone();
        check_name(&output)
            .map_err(|m| self.err(op.output.span(), &format!("{field}.output"), m))?;
        if self.names.contains_key(&output) {
            return Err(self.err(
                op.output.span(),
                &format!("{field}.output"),
                format!("`{output}` is already defined"),
            ));
        }
        let f = |k: &str| format!("{field}.{k}");
        match kind {
            "inverse" => {
                let (x, px) = self.input_gaussian(op, &field, "input", &op.input)?;
                let fo = first_order::inverse(&x);
                let particles = px.map(|p| map_particles(&p, |g| g.inverse()));
                self.output(output, fo, particles, |g: &[G]| g[0].inverse(), &[x]);
            }
            "change_frame_left" => {
                let (x, px) = self.input_gaussian(op, &field, "input", &op.input)?;
                let a = self.fixed(self.need(&op.by, op, &field, "by")?, &f("by"))?;
                let fo = first_order::change_frame_left(&a, &x);
                let particles = px.map(|p| map_particles(&p, |g| a.compose(g)));
                let extra = self
                    .vector_space(&UncertainPose::certain(a), &x, &output)
                    .into_iter()
                    .collect();
                self.output_with(
                    output,
                    None,
                    fo,
                    extra,
                    particles,
                    move |g: &[G]| a.compose(&g[0]),
                    &[x],
                );
            }
            "change_frame_right" => {
                let (x, px) = self.input_gaussian(op, &field, "input", &op.input)?;
                let b = self.fixed(self.need(&op.by, op, &field, "by")?, &f("by"))?;
                let fo = first_order::change_frame_right(&x, &b);
                let particles = px.map(|p| map_particles(&p, |g| g.compose(&b)));
                let extra = self
                    .vector_space(&x, &UncertainPose::certain(b), &output)
                    .into_iter()
                    .collect();
                self.output_with(
                    output,
                    None,
                    fo,
                    extra,
                    particles,
                    move |g: &[G]| g[0].compose(&b),
                    &[x],
                );
            }
            "compose" | "between" => {
                let (x, px) = self.input_gaussian(op, &field, "lhs", &op.lhs)?;
                let (y, py) = self.input_gaussian(op, &field, "rhs", &op.rhs)?;
                let compose = kind == "compose";
                let fo = if compose {
                    first_order::compose(&x, &y)
                } else {
                    first_order::between(&x, &y)
                };
                let particles = self.pair_particles(px, py, &x, &y, |a, b| {
                    if compose { a.compose(b) } else { a.between(b) }
                });
                let mut extra = Vec::new();
                if compose {
                    for (order, method) in [
                        (Order::Second, Method::SecondOrder),
                        (Order::Fourth, Method::FourthOrder),
                    ] {
                        if self.wants(method) {
                            extra.extend(G::compound(&x, &y, order));
                        }
                    }
                    extra.extend(self.vector_space(&x, &y, &output));
                }
                let map = move |g: &[G]| {
                    if compose {
                        g[0].compose(&g[1])
                    } else {
                        g[0].between(&g[1])
                    }
                };
                self.output_with(output, None, fo, extra, particles, map, &[x, y]);
            }
            "compose_correlated" | "between_correlated" => {
                self.correlated(op, &field, output, kind == "compose_correlated")?
            }
            "odometry" => self.odometry(op, &field, output)?,
            "compound" => self.compound(op, &field, output)?,
            "point_through_pose" => self.point_through_pose(op, &field, output)?,
            "fuse" => self.fuse(op, &field, output)?,
            "diff_drive" => self.diff_drive(op, &field, output)?,
            "euler_vs_exp" => self.euler_vs_exp(op, &field, output)?,
            _ => {
                return Err(self.err(
                    op.kind.span(),
                    &format!("{field}.kind"),
                    format!("`{kind}` is not available for {} yet", G::NAME),
                ));
            }
        }
        Ok(())
    }

    /// The Smith–Self–Cheeseman compose X·Y in vector coordinates, when requested and defined.
    fn vector_space(
        &mut self,
        x: &UncertainPose<G, N>,
        y: &UncertainPose<G, N>,
        output: &str,
    ) -> Option<Propagated<G, N>> {
        if !self.wants(Method::VectorSpace) {
            return None;
        }
        match G::ssc_compose(x, y)? {
            Ok(r) => Some(r),
            Err(e) => {
                self.out
                    .notes
                    .push(format!("Vector-space compose for `{output}` failed: {e}."));
                None
            }
        }
    }

    /// Particles of Z = f(X, Y) for independent X, Y (a fixed operand is a constant).
    fn pair_particles(
        &mut self,
        px: Option<Arc<Vec<G>>>,
        py: Option<Arc<Vec<G>>>,
        x: &UncertainPose<G, N>,
        y: &UncertainPose<G, N>,
        f: impl Fn(&G, &G) -> G + Sync,
    ) -> Option<Arc<Vec<G>>> {
        if !self.monte_carlo || (px.is_none() && py.is_none()) {
            return None;
        }
        let n = self.block.len();
        let px = px.unwrap_or_else(|| Arc::new(vec![*x.mean(); n]));
        let py = py.unwrap_or_else(|| Arc::new(vec![*y.mean(); n]));
        Some(Arc::new(
            px.iter().zip(py.iter()).map(|(a, b)| f(a, b)).collect(),
        ))
    }

    /// Adds an output node with the first-order result and, where requested, the other
    /// general methods (sigma points through `map`, Monte Carlo from the particles).
    fn output(
        &mut self,
        name: String,
        first: Propagated<G, N>,
        particles: Option<Arc<Vec<G>>>,
        map: impl Fn(&[G]) -> G + Sync,
        inputs: &[UncertainPose<G, N>],
    ) {
        self.output_with(name, None, first, Vec::new(), particles, map, inputs);
    }

    #[allow(clippy::too_many_arguments)]
    fn output_with(
        &mut self,
        name: String,
        step: Option<u64>,
        first: Propagated<G, N>,
        extra: Vec<Propagated<G, N>>,
        particles: Option<Arc<Vec<G>>>,
        map: impl Fn(&[G]) -> G + Sync,
        inputs: &[UncertainPose<G, N>],
    ) {
        let mut estimates = vec![Estimate {
            result: first,
            error_vs_monte_carlo: None,
        }];
        estimates.extend(extra.into_iter().map(|result| Estimate {
            result,
            error_vs_monte_carlo: None,
        }));
        if self.wants(Method::SigmaPoints) && !inputs.is_empty() {
            match sigma_point::map(inputs, &map, &Unscented::default()) {
                Ok(result) => estimates.push(Estimate {
                    result,
                    error_vs_monte_carlo: None,
                }),
                Err(e) => self
                    .out
                    .notes
                    .push(format!("Sigma points for `{name}` failed: {e}.")),
            }
        }
        let nominal = *first.pose.mean();
        let draw = self.drawn_by_default(&name);
        self.push_node(Node {
            name,
            role: Role::Output,
            step,
            draw,
            nominal,
            estimates,
            particles,
        });
    }

    fn correlated(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
        compose: bool,
    ) -> Result<(), ScenarioError> {
        let (x, _) = self.input_gaussian(op, field, "lhs", &op.lhs)?;
        let (y, _) = self.input_gaussian(op, field, "rhs", &op.rhs)?;
        let cross = self.need(&op.cross_cov, op, field, "cross_cov")?;
        let cross_xy: TangentMatrix<N> = fixed_matrix::<N, N>("cross_cov", cross.get_ref())
            .map_err(|m| self.err(cross.span(), &format!("{field}.cross_cov"), m))?;
        let y = y.to_side(x.side());
        let mut joint = DMatrix::zeros(2 * N, 2 * N);
        joint.view_mut((0, 0), (N, N)).copy_from(x.cov());
        joint.view_mut((0, N), (N, N)).copy_from(&cross_xy);
        joint
            .view_mut((N, 0), (N, N))
            .copy_from(&cross_xy.transpose());
        joint.view_mut((N, N), (N, N)).copy_from(y.cov());
        let pair =
            CorrelatedPair::try_new(*x.mean(), *y.mean(), &joint, x.side()).map_err(|e| {
                self.err(
                    cross.span(),
                    &format!("{field}.cross_cov"),
                    format!("the joint covariance [[Σ_X, Σ_XY], [Σ_XYᵀ, Σ_Y]] is invalid: {e}"),
                )
            })?;
        let fo = if compose {
            first_order::compose_correlated(&pair)
        } else {
            first_order::between_correlated(&pair)
        };
        let particles = if self.monte_carlo {
            Some(Arc::new(self.joint_particles(&pair, compose)))
        } else {
            None
        };
        let map = move |g: &[G]| {
            if compose {
                g[0].compose(&g[1])
            } else {
                g[0].between(&g[1])
            }
        };
        self.output(output, fo, particles, map, &[x, y]);
        Ok(())
    }

    /// Jointly sampled pairs (X, Y) from a correlated pair, mapped through compose/between.
    /// The pair is re-sampled here from its joint Gaussian (upstream particles carry no
    /// correlation to reuse).
    fn joint_particles(&mut self, pair: &CorrelatedPair<G, N>, compose: bool) -> Vec<G> {
        let family = self.next_family();
        let joint = pair.joint();
        let factor = joint_square_root(&joint);
        let (mx, my) = pair.means();
        let side = pair.side();
        let mut out = vec![mx; self.block.len()];
        fill_par_from(
            &mut out,
            self.meta.seed,
            family,
            self.first_chunk(),
            |rng, chunk| {
                for z in chunk.iter_mut() {
                    let a = standard_normal::<N, _>(rng);
                    let b = standard_normal::<N, _>(rng);
                    let stacked =
                        nalgebra::DVector::from_iterator(2 * N, a.iter().chain(b.iter()).copied());
                    let e = &factor * stacked;
                    let ex = Tangent::<N>::from_iterator(e.rows(0, N).iter().copied());
                    let ey = Tangent::<N>::from_iterator(e.rows(N, N).iter().copied());
                    let (x, y) = match side {
                        Side::Right => (mx.rplus(&ex), my.rplus(&ey)),
                        Side::Left => (mx.lplus(&ex), my.lplus(&ey)),
                    };
                    *z = if compose {
                        x.compose(&y)
                    } else {
                        x.between(&y)
                    };
                }
            },
        );
        out
    }

    fn noise_cov(
        &self,
        op: &OperationSpec,
        field: &str,
        mean: &G,
    ) -> Result<(TangentMatrix<N>, Side), ScenarioError> {
        let noise = self.need(&op.noise, op, field, "noise")?;
        cov_for::<G, N>(noise.get_ref(), mean)
            .map_err(|m| self.err(noise.span(), &format!("{field}.noise"), m))
    }

    fn steps(&self, op: &OperationSpec, field: &str) -> Result<Option<u64>, ScenarioError> {
        match &op.steps {
            None => Ok(None),
            Some(s) if (1..=100_000).contains(s.get_ref()) => Ok(Some(*s.get_ref())),
            Some(s) => Err(self.err(
                s.span(),
                &format!("{field}.steps"),
                format!("{} is out of range: use 1 ..= 100000", s.get_ref()),
            )),
        }
    }

    fn odometry(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
    ) -> Result<(), ScenarioError> {
        let (start, start_particles) = self.input_gaussian(op, field, "input", &op.input)?;
        let model_spec = self.need(&op.model, op, field, "model")?;
        let increment = match model_spec.get_ref().as_str() {
            "increment" => true,
            "exp" => false,
            other => return Err(self.err(model_spec.span(), &format!("{field}.model"), format!("unknown odometry model `{other}`; use `increment` (X·U·Exp(w), NA 568) or `exp` (X·Exp(u + w))"))),
        };
        let (noise, noise_side) = self.noise_cov(op, field, start.mean())?;
        if noise_side != Side::Right {
            return Err(self.err(
                self.need(&op.noise, op, field, "noise")?.span(),
                &format!("{field}.noise"),
                "odometry noise enters on the right (body frame): remove `side = \"left\"`",
            ));
        }
        let controls_spec = self.need(&op.controls, op, field, "controls")?;
        let mut controls = Vec::new();
        for (i, c) in controls_spec.get_ref().iter().enumerate() {
            let control = control_for::<G, N>(c, increment).map_err(|m| {
                self.err(controls_spec.span(), &format!("{field}.controls[{i}]"), m)
            })?;
            controls.push(control);
        }
        if controls.is_empty() {
            return Err(self.err(
                controls_spec.span(),
                &format!("{field}.controls"),
                "needs at least one control",
            ));
        }
        if let Some(steps) = self.steps(op, field)? {
            if controls.len() != 1 {
                return Err(self.err(
                    self.need(&op.steps, op, field, "steps")?.span(),
                    &format!("{field}.steps"),
                    "`steps` repeats a single control: give one control, or drop `steps`",
                ));
            }
            controls = vec![controls[0]; steps as usize];
        }
        // Analytic recursions, one result per step (index 0 is the start).
        let mut tracks: Vec<Vec<Propagated<G, N>>> = Vec::new();
        let start_right = start.to_side(Side::Right);
        let at = |e: crate::Error| {
            self.err(
                controls_spec.span(),
                &format!("{field}.controls"),
                e.to_string(),
            )
        };
        if increment {
            let increments: Vec<G> = controls.iter().map(|(g, _)| *g).collect();
            tracks.push(propagate_increments(&start_right, &increments, &noise).map_err(at)?);
        } else {
            let inputs: Vec<Tangent<N>> = controls.iter().map(|(_, u)| *u).collect();
            tracks.push(
                propagate_tangent_inputs(&start_right, &inputs, &noise, InputNoise::RightJacobian)
                    .map_err(at)?,
            );
            if self.wants(Method::LectureNoJr) {
                tracks.push(
                    propagate_tangent_inputs(
                        &start_right,
                        &inputs,
                        &noise,
                        InputNoise::LectureNoJr,
                    )
                    .map_err(at)?,
                );
            }
        }
        if self.wants(Method::VectorSpace) {
            let increments: Vec<G> = controls.iter().map(|(g, _)| *g).collect();
            match G::ssc_odometry(&start_right, &increments, &noise) {
                Some(Ok(track)) => tracks.push(track),
                Some(Err(e)) => self
                    .out
                    .notes
                    .push(format!("Vector-space odometry failed: {e}.")),
                None => {}
            }
        }
        // Monte Carlo: every particle takes every step with fresh noise.
        let mut particle_steps: Vec<Option<Arc<Vec<G>>>> = vec![None; controls.len() + 1];
        if self.monte_carlo {
            let mut current: Vec<G> = match start_particles {
                Some(p) => p.as_ref().clone(),
                None => vec![*start.mean(); self.block.len()],
            };
            particle_steps[0] = Some(Arc::new(current.clone()));
            let noise_pose = UncertainPose::new_unchecked(G::identity(), noise, Side::Right);
            let sampler = Sampler::new(&noise_pose).ok();
            for (k, (u_group, u_tangent)) in controls.iter().enumerate() {
                if self.cancelled() {
                    break;
                }
                let family = self.next_family();
                let (seed, first_chunk) = (self.meta.seed, self.first_chunk());
                if let Some(sampler) = &sampler {
                    fill_par_map(&mut current, seed, family, first_chunk, |rng, x| {
                        let w = sampler.draw_tangent(rng);
                        if increment {
                            x.compose(u_group).rplus(&w)
                        } else {
                            x.rplus(&(u_tangent + w))
                        }
                    });
                }
                particle_steps[k + 1] = Some(Arc::new(current.clone()));
            }
        }
        let first = &tracks[0];
        for (k, result) in first.iter().enumerate() {
            let extra: Vec<Propagated<G, N>> = tracks[1..]
                .iter()
                .filter_map(|t| t.get(k).copied())
                .collect();
            let particles = particle_steps.get(k).cloned().flatten();
            self.output_with(
                output.clone(),
                Some(k as u64),
                *result,
                extra,
                particles,
                |g: &[G]| g[0],
                &[],
            );
        }
        self.out.paths.push(PosePath {
            name: format!("{output}/nominal"),
            method: None,
            poses: first.iter().map(|r| *r.pose.mean()).collect(),
        });
        self.trace_series(&output);
        Ok(())
    }

    /// Barfoot & Furgale's repeated compounding T_k = (Exp(w) T̄) · T_{k−1}, left form.
    fn compound(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
    ) -> Result<(), ScenarioError> {
        let (start, start_particles) = self.input_gaussian(op, field, "input", &op.input)?;
        let step_mean = self.fixed(self.need(&op.by, op, field, "by")?, &format!("{field}.by"))?;
        let (noise, noise_side) = self.noise_cov(op, field, &step_mean)?;
        let steps = self.steps(op, field)?.unwrap_or(1);
        let increment = UncertainPose::new_unchecked(step_mean, noise, noise_side);
        let orders: Vec<(Order, Method)> = [
            (Order::Second, Method::SecondOrder),
            (Order::Fourth, Method::FourthOrder),
        ]
        .into_iter()
        .filter(|(_, m)| self.wants(*m))
        .collect();
        let mut first = Propagated {
            pose: start.to_side(noise_side),
            method: Method::FirstOrder,
        };
        let mut higher: Vec<Propagated<G, N>> = orders
            .iter()
            .map(|(_, m)| Propagated {
                pose: start.to_side(Side::Left),
                method: *m,
            })
            .collect();
        let mut current: Option<Vec<G>> = if self.monte_carlo {
            Some(start_particles.map_or_else(
                || vec![*start.mean(); self.block.len()],
                |p| p.as_ref().clone(),
            ))
        } else {
            None
        };
        let sampler = Sampler::new(&increment).ok();
        self.output_with(
            output.clone(),
            Some(0),
            first,
            higher.clone(),
            current.clone().map(Arc::new),
            |g: &[G]| g[0],
            &[],
        );
        for k in 1..=steps {
            if self.cancelled() {
                break;
            }
            first = first_order::compose(&increment, &first.pose);
            for (h, (order, _)) in higher.iter_mut().zip(&orders) {
                if let Some(next) = G::compound(&increment, &h.pose, *order) {
                    *h = next;
                }
            }
            if let (Some(particles), Some(sampler)) = (current.as_mut(), &sampler) {
                let family = self.next_family();
                let first_chunk = self.first_chunk();
                fill_par_map(particles, self.meta.seed, family, first_chunk, |rng, x| {
                    sampler.draw(rng).compose(x)
                });
            }
            self.output_with(
                output.clone(),
                Some(k),
                first,
                higher.clone(),
                current.clone().map(Arc::new),
                |g: &[G]| g[0],
                &[],
            );
        }
        let poses = self
            .out
            .nodes
            .iter()
            .filter(|n| n.name == output)
            .map(|n| n.nominal)
            .collect();
        self.out.paths.push(PosePath {
            name: format!("{output}/nominal"),
            method: None,
            poses,
        });
        self.trace_series(&output);
        self.along_track_series(&output);
        Ok(())
    }

    fn point_through_pose(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
    ) -> Result<(), ScenarioError> {
        let (pose, particles) = self.input_gaussian(op, field, "input", &op.input)?;
        let point = self.need(&op.point, op, field, "point")?;
        let cov = op.point_cov.as_ref();
        let at = |span: std::ops::Range<usize>, key: &str, m: String| {
            self.err(span, &format!("{field}.{key}"), m)
        };
        let dims = G::point_dims();
        if point.get_ref().len() != dims || point.get_ref().iter().any(|v| !v.is_finite()) {
            return Err(at(
                point.span(),
                "point",
                format!(
                    "needs {dims} finite coordinates for {}, got {:?}",
                    G::NAME,
                    point.get_ref()
                ),
            ));
        }
        let zeros = vec![vec![0.0; dims]; dims];
        let cov_rows = cov.map_or(&zeros, |c| c.get_ref());
        let cov_span = cov.map_or(point.span(), Spanned::span);
        let (mean, cov_world) = G::point_through(&pose, point.get_ref(), cov_rows)
            .map_err(|m| at(cov_span.clone(), "point_cov", m))?;
        let mut estimates = vec![(Method::FirstOrder, mean, cov_world)];
        let mut cloud = None;
        if let Some(particles) = particles.filter(|_| self.monte_carlo) {
            let family = self.next_family();
            let factor = joint_square_root(&DMatrix::from_fn(dims, dims, |r, c| cov_rows[r][c]));
            let local = point.get_ref().clone();
            let mut points = vec![[0.0; 3]; particles.len()];
            let (seed, first_chunk) = (self.meta.seed, self.first_chunk());
            fill_par_from(&mut points, seed, family, first_chunk, |rng, chunk| {
                for (i, q) in chunk.iter_mut().enumerate() {
                    let _ = i;
                    let z = standard_normal::<3, _>(rng);
                    let noise = &factor
                        * nalgebra::DVector::from_iterator(dims, z.iter().take(dims).copied());
                    let p: Vec<f64> = local.iter().zip(noise.iter()).map(|(a, b)| a + b).collect();
                    *q = [
                        p[0],
                        p.get(1).copied().unwrap_or(0.0),
                        p.get(2).copied().unwrap_or(0.0),
                    ];
                }
            });
            let moved: Vec<[f64; 3]> = particles
                .iter()
                .zip(&points)
                .map(|(x, q)| {
                    let w = x.to_se3().act(&Vector3::new(q[0], q[1], q[2]));
                    [w.x, w.y, w.z]
                })
                .collect();
            if let Some((m, c)) = self.mc_point_stats(self.out.points.len(), &moved) {
                estimates.push((
                    Method::MonteCarlo,
                    [m.x, m.y, m.z],
                    [
                        [c[(0, 0)], c[(0, 1)], c[(0, 2)]],
                        [c[(1, 0)], c[(1, 1)], c[(1, 2)]],
                        [c[(2, 0)], c[(2, 1)], c[(2, 2)]],
                    ],
                ));
            }
            cloud = Some(moved);
        }
        self.names
            .insert(output.clone(), Value::Fixed(G::identity()));
        self.out.points.push(PointNode {
            name: output,
            estimates,
            particles: cloud,
        });
        Ok(())
    }

    fn fuse(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
    ) -> Result<(), ScenarioError> {
        let inputs = op.inputs.as_deref().unwrap_or(&[]);
        let mut estimates = Vec::new();
        for (i, name) in inputs.iter().enumerate() {
            let (pose, _) = self.gaussian(self.lookup(name, &format!("{field}.inputs[{i}]"))?);
            estimates.push(pose);
        }
        let fused = fuse(&estimates, FusionOptions::default())
            .map_err(|e| self.err(op.kind.span(), &format!("{field}.inputs"), e.to_string()))?;
        self.out.notes.push(format!("Fusion of {} estimates into `{output}`: final cost {:.4} after {} Gauss–Newton iterations.", estimates.len(), fused.cost, fused.iterations));
        self.output(output, fused.result, None, |g: &[G]| g[0], &[]);
        Ok(())
    }

    fn positive(
        &self,
        value: &Option<Spanned<f64>>,
        op: &OperationSpec,
        field: &str,
        key: &str,
        allow_zero: bool,
    ) -> Result<f64, ScenarioError> {
        let v = self.need(value, op, field, key)?;
        let x = *v.get_ref();
        if x.is_finite() && (x > 0.0 || (allow_zero && x == 0.0)) {
            Ok(x)
        } else {
            Err(self.err(
                v.span(),
                &format!("{field}.{key}"),
                format!(
                    "{x} is out of range: must be finite and {}",
                    if allow_zero { "≥ 0" } else { "> 0" }
                ),
            ))
        }
    }

    fn diff_drive(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
    ) -> Result<(), ScenarioError> {
        let start = match &op.input {
            Some(name) => self.fixed(name, &format!("{field}.input"))?,
            None => G::identity(),
        };
        let turn = self.need(&op.turn_rate, op, field, "turn_rate")?;
        if !turn.get_ref().is_finite() {
            return Err(self.err(
                turn.span(),
                &format!("{field}.turn_rate"),
                format!("{} is not finite", turn.get_ref()),
            ));
        }
        let params = DiffDriveParams {
            wheel_radius: self.positive(&op.wheel_radius, op, field, "wheel_radius", false)?,
            wheelbase: self.positive(&op.wheelbase, op, field, "wheelbase", false)?,
            duration: self.positive(&op.duration, op, field, "duration", false)?,
            diffusion: self.positive(&op.diffusion, op, field, "diffusion", true)?,
            speed: self.positive(&op.speed, op, field, "speed", false)?,
            turn_rate: *turn.get_ref(),
            dt: if op.dt.is_some() {
                self.positive(&op.dt, op, field, "dt", false)?
            } else {
                1e-3
            },
            samples: if self.monte_carlo {
                self.block.len()
            } else {
                0
            },
            first_chunk: self.first_chunk(),
            seed: self.meta.seed.wrapping_add(self.next_family()),
        };
        let outcome = match G::diff_drive(&params) {
            None => {
                return Err(self.err(
                    op.kind.span(),
                    &format!("{field}.kind"),
                    format!(
                        "`diff_drive` is a planar robot: it needs group = \"se2\", not {}",
                        G::NAME
                    ),
                ));
            }
            Some(Err(e)) => return Err(self.err(op.kind.span(), field, e.to_string())),
            Some(Ok(o)) => o,
        };
        let moved = |g: &G| start.compose(g);
        // Results are relative to the start pose: move them with a (deterministic) left change of frame.
        let mut estimates: Vec<Propagated<G, N>> = outcome
            .estimates
            .iter()
            .filter(|e| self.wants(e.method) || e.method == Method::ClosedForm)
            .map(|e| Propagated {
                pose: first_order::change_frame_left(&start, &e.pose).pose,
                method: e.method,
            })
            .collect();
        let particles = (!outcome.end_poses.is_empty())
            .then(|| Arc::new(outcome.end_poses.iter().map(moved).collect::<Vec<G>>()));
        let first = estimates.remove(0);
        self.output_with(
            output.clone(),
            None,
            first,
            estimates,
            particles,
            |g: &[G]| g[0],
            &[],
        );
        let node = self.out.nodes.len() - 1;
        if let (Some(stats), Some(cartesian), Some(nominal)) = (
            self.mc_stats(node),
            self.mc_translation_mean(node),
            outcome.nominal_path.last(),
        ) {
            let lie = stats.mean.to_se3();
            let nominal = moved(nominal).to_se3();
            self.out.notes.push(format!(
                "`{output}` (D = {}): nominal end ({:.3}, {:.3}); **Lie mean** of the samples ({:.3}, {:.3}); **Cartesian mean** of their positions ({:.3}, {:.3}) — it retreats inside the banana.",
                params.diffusion, nominal.translation().x, nominal.translation().y, lie.translation().x, lie.translation().y, cartesian.x, cartesian.y
            ));
        }
        self.out.paths.push(PosePath {
            name: format!("{output}/nominal"),
            method: None,
            poses: outcome.nominal_path.iter().map(moved).collect(),
        });
        for (i, t) in outcome.trajectories.iter().enumerate() {
            self.out.paths.push(PosePath {
                name: format!("{output}/samples/{i}"),
                method: Some(Method::MonteCarlo),
                poses: t.iter().map(moved).collect(),
            });
        }
        Ok(())
    }

    fn euler_vs_exp(
        &mut self,
        op: &OperationSpec,
        field: &str,
        output: String,
    ) -> Result<(), ScenarioError> {
        let rate_spec = self.need(&op.rate, op, field, "rate")?;
        let rate = rate_spec.get_ref();
        if rate.len() != 3 || rate.iter().any(|v| !v.is_finite()) {
            return Err(self.err(
                rate_spec.span(),
                &format!("{field}.rate"),
                format!("needs 3 finite numbers (rad/s), got {rate:?}"),
            ));
        }
        let dt = self.positive(&op.dt, op, field, "dt", false)?;
        let steps = self.steps(op, field)?.unwrap_or(1);
        let Some(track) = G::euler_vs_exp(&Vector3::new(rate[0], rate[1], rate[2]), dt, steps)
        else {
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.kind"),
                format!(
                    "`euler_vs_exp` integrates a 3D body rate: it needs group = \"so3\", not {}",
                    G::NAME
                ),
            ));
        };
        let drift = |m: &Matrix3<f64>| (m.transpose() * m - Matrix3::identity()).amax();
        let mut euler_line = Vec::new();
        let mut exp_line = Vec::new();
        for (k, (euler, exp)) in track.iter().enumerate() {
            let step = k as u64;
            euler_line.push((step as i64, drift(euler)));
            exp_line.push((step as i64, drift(&exp.to_se3().rotation().to_matrix())));
            self.out.matrix_frames.push(MatrixFrame {
                name: format!("{output}/euler"),
                step: Some(step),
                columns: *euler,
                origin: [0.0; 3],
            });
            self.push_node(Node {
                name: format!("{output}_exp"),
                role: Role::Output,
                step: Some(step),
                draw: true,
                nominal: *exp,
                estimates: Vec::new(),
                particles: None,
            });
        }
        let (last_euler, last_exp) = track.last().map_or((f64::NAN, f64::NAN), |(m, g)| {
            (drift(m), drift(&g.to_se3().rotation().to_matrix()))
        });
        self.out.notes.push(format!(
            "After {steps} steps of dt = {dt} s: Euler max |R^T R − I| = **{last_euler:.3}**; exponential map {last_exp:.1e}. The Euler frame (the columns of its matrix, drawn as arrows) stretches; the Exp frame stays a rotation."
        ));
        let quantity = "orthogonality error max |R^T R − I|";
        self.out.series.push(Series {
            quantity: quantity.to_owned(),
            method: None,
            label: "Euler steps R(I + ω̂dt)".to_owned(),
            points: euler_line,
        });
        self.out.series.push(Series {
            quantity: quantity.to_owned(),
            method: Some(Method::Exact),
            label: "exponential map R·Exp(ωdt)".to_owned(),
            points: exp_line,
        });
        Ok(())
    }

    /// Trace of the position (or rotation) covariance per method and step, for the plot.
    fn trace_series(&mut self, name: &str) {
        let block = if G::rotation_range().start == 0 {
            G::rotation_range()
        } else {
            0..G::rotation_range().start
        };
        let quantity = if G::rotation_range().start == 0 {
            "trace of rotation covariance (rad²)"
        } else {
            "trace of position covariance (m², body frame)"
        };
        let mut lines: Vec<Series> = Vec::new();
        for (index, node) in self.nodes_named(name) {
            let step = node.step.unwrap_or(0) as i64;
            let mut values: Vec<(Method, f64)> = node
                .estimates
                .iter()
                .map(|e| {
                    let cov = e.result.pose.cov_right();
                    (e.result.method, block.clone().map(|i| cov[(i, i)]).sum())
                })
                .collect();
            if let Some(stats) = self.mc_stats(index) {
                values.push((
                    Method::MonteCarlo,
                    block.clone().map(|i| stats.cov[(i, i)]).sum(),
                ));
            }
            add_to_lines(&mut lines, quantity, step, values);
        }
        self.out.series.extend(lines);
    }

    /// The nodes (one per step) of the output `name`, with their indices.
    fn nodes_named<'b>(&'b self, name: &'b str) -> impl Iterator<Item = (usize, &'b Node<G, N>)> {
        self.out
            .nodes
            .iter()
            .enumerate()
            .filter(move |(_, n)| n.name == name)
    }

    /// Σ_ρxρx in the left (world) form per method and step: the along-track variance that
    /// second-order compounding misses (Barfoot & Furgale 2014, Fig. 2). Monte Carlo uses the
    /// uncentred E[ξξᵀ] about the propagated mean, as in their experiments.
    fn along_track_series(&mut self, name: &str) {
        if G::rotation_range().start == 0 {
            return;
        }
        let mut lines: Vec<Series> = Vec::new();
        for (index, node) in self.nodes_named(name) {
            let step = node.step.unwrap_or(0) as i64;
            let mut values: Vec<(Method, f64)> = node
                .estimates
                .iter()
                .map(|e| (e.result.method, e.result.pose.cov_left()[(0, 0)]))
                .collect();
            if let Some(cov) = self.mc_uncentred_left(index) {
                values.push((Method::MonteCarlo, cov[(0, 0)]));
            }
            add_to_lines(
                &mut lines,
                "along-track variance Σ_ρxρx, left form (m²)",
                step,
                values,
            );
        }
        if let Some(last) = self.out.nodes.iter().rev().find(|n| n.name == name) {
            let summary: Vec<String> = lines
                .iter()
                .filter_map(|l| {
                    l.points
                        .last()
                        .map(|(_, v)| format!("{} {:.4}", l.label, v))
                })
                .collect();
            self.out.notes.push(format!(
                "Along-track variance Σ_ρxρx (left form) at step {}: {}.",
                last.step.unwrap_or(0),
                summary.join(", ")
            ));
        }
        self.out.series.extend(lines);
    }

    /// Adds each node's Monte Carlo estimate and every other estimate's error against it.
    fn errors_against_monte_carlo(&mut self) {
        let all_stats: Vec<Option<SampleStatistics<G, N>>> = (0..self.out.nodes.len())
            .map(|i| self.mc_stats(i))
            .collect();
        for (node, stats) in self.out.nodes.iter_mut().zip(all_stats) {
            if node.role == Role::Fixed {
                continue;
            }
            let Some(stats) = stats else {
                continue;
            };
            for e in &mut node.estimates {
                e.error_vs_monte_carlo = Some(relative_frobenius_error(
                    &e.result.pose.cov_right(),
                    &stats.cov,
                ));
            }
            node.estimates.push(Estimate {
                result: Propagated {
                    pose: stats.to_pose(),
                    method: Method::MonteCarlo,
                },
                error_vs_monte_carlo: Some(0.0),
            });
        }
    }
}

/// Adds each method's value at `step` to its line of `quantity` (a new line per method).
fn add_to_lines(lines: &mut Vec<Series>, quantity: &str, step: i64, values: Vec<(Method, f64)>) {
    for (method, value) in values {
        match lines.iter_mut().find(|l| l.method == Some(method)) {
            Some(line) => line.points.push((step, value)),
            None => lines.push(Series {
                quantity: quantity.to_owned(),
                method: Some(method),
                label: method.label().to_owned(),
                points: vec![(step, value)],
            }),
        }
    }
}

/// `x ← f(rng, x)` over a slice, in parallel, deterministic per seed and family.
fn fill_par_map<G: Copy + Send + Sync>(
    xs: &mut [G],
    seed: u64,
    family: u64,
    first_chunk: u64,
    f: impl Fn(&mut rand_chacha::ChaCha8Rng, &G) -> G + Sync,
) {
    fill_par_from(xs, seed, family, first_chunk, |rng, chunk| {
        for x in chunk.iter_mut() {
            *x = f(rng, x);
        }
    });
}

fn map_particles<G: Copy + Send + Sync>(p: &[G], f: impl Fn(&G) -> G + Sync) -> Arc<Vec<G>> {
    Arc::new(p.iter().map(f).collect())
}

/// A lower-triangular square root of a PSD joint covariance (eigen-based: tolerates zero rows).
fn joint_square_root(joint: &DMatrix<f64>) -> DMatrix<f64> {
    let eig = nalgebra::SymmetricEigen::new(joint.clone());
    let sqrt = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| l.max(0.0).sqrt()));
    &eig.eigenvectors * sqrt
}

/// An odometry control: (increment as a group element, tangent) — the `increment` model reads
/// the numbers as the group's natural coordinates, the `exp` model as a tangent vector.
fn control_for<G: SpecGroup<N>, const N: usize>(
    numbers: &[f64],
    increment: bool,
) -> Result<(G, Tangent<N>), String> {
    if let Some(i) = numbers.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "element {i} is {}, every number must be finite",
            numbers[i]
        ));
    }
    if numbers.len() != N {
        return Err(format!(
            "each control needs {N} numbers for {}, got {}",
            G::NAME,
            numbers.len()
        ));
    }
    let tangent = Tangent::<N>::from_column_slice(numbers);
    if !increment {
        return Ok((G::exp(&tangent), tangent));
    }
    let spec = match N {
        1 => super::schema::MeanSpec {
            angle: Some(numbers[0]),
            ..Default::default()
        },
        3 if G::rotation_range().start == 2 => super::schema::MeanSpec {
            xy_theta: Some([numbers[0], numbers[1], numbers[2]]),
            ..Default::default()
        },
        3 => super::schema::MeanSpec {
            rpy: Some([numbers[0], numbers[1], numbers[2]]),
            ..Default::default()
        },
        _ => super::schema::MeanSpec {
            xyz: Some([numbers[0], numbers[1], numbers[2]]),
            rpy: Some([numbers[3], numbers[4], numbers[5]]),
            ..Default::default()
        },
    };
    let g = mean_for::<G, N>(&spec)?;
    Ok((g, g.log()))
}

/// The parent frame of a name `a_from_b` (`a`), if it follows that convention.
fn parent_frame(name: &str) -> Option<&str> {
    name.split_once("_from_").map(|(parent, _)| parent)
}

/// Names become entity-path segments: letters, digits, `_`, `-`, `.`.
fn check_name(name: &str) -> Result<(), String> {
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
    {
        return Err(format!(
            "`{name}` is not a valid name: use letters, digits, `_`, `-` or `.` (e.g. `world_from_body`)"
        ));
    }
    Ok(())
}
