//! The evaluation engine: the table of what each definition evaluated to, particles, and
//! the one place where a result becomes a node (checked, with its Monte Carlo statistics).

use std::ops::Range;
use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::batch_means::BatchSums;
use super::blocked::{BlockedStats, VectorSums};
use super::consistency::ConsistencySums;
use super::groups::EvalGroup;
use super::model::{
    Estimate, Evaluation, FailureReason, Finding, McSummary, Node, PointEstimate, PointNode, Role,
};
use super::{EvalError, EvalSettings};
use crate::lie::LieGroup;
use crate::plan::{OpKind, Operand, Plan, PoseValue, limits};
use crate::propagate::sigma_point::JointInputs;
use crate::propagate::{Propagated, relative_frobenius_error};
use crate::sample::{
    CHUNK_SIZE, MeanError, SampleStatistics, Sampler, sample_statistics, tangent_moments,
};
use crate::uncertain::{Method, Side, UncertainPose};

/// An operand's Gaussian (its primary estimate) and its particles.
pub(super) type Gaussian<G, const N: usize> = (UncertainPose<G, N>, Option<Arc<Vec<G>>>);

/// Where a run takes its Monte Carlo statistics from.
pub(super) enum StatsMode<'s, G: LieGroup<N>, const N: usize> {
    /// From this run's particles: the whole sample, when it fits in one block.
    Own,
    /// Nowhere: one block of a larger sample, for its particles only.
    Skip,
    /// A pass over one block of a larger sample: add to the running sums (`true`: first pass).
    Collect(&'s mut BlockedStats<G, N>, bool),
    /// From the sums over every block.
    Blocked(&'s BlockedStats<G, N>),
}

/// The particles of a new node.
pub(super) enum Particles<'p, G> {
    /// None (no Monte Carlo, or a deterministic result).
    None,
    /// A whole particle set, kept.
    Owned(Arc<Vec<G>>),
    /// The particles of one step of a propagation, kept only at detailed steps.
    Step(&'p [G]),
}

/// Monte Carlo statistics an operation asks for beyond the Lie mean and covariance.
#[derive(Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct Extras {
    /// Uncentred left covariance about the nominal (Barfoot & Furgale's).
    pub uncentred_left: bool,
    /// Cartesian mean of the positions.
    pub position_mean: bool,
}

/// A result about to become a node.
pub(super) struct Draft<'p, G: LieGroup<N>, const N: usize> {
    pub step: Option<u64>,
    pub last_step: Option<u64>,
    /// The estimates; the first is the primary one (first order, exact or closed form).
    pub estimates: Vec<Propagated<G, N>>,
    pub particles: Particles<'p, G>,
    pub extras: Extras,
    /// Where its Monte Carlo statistics can be read off another node's instead of iterated.
    pub stats_from: Option<LeftTranslated<G>>,
}

impl<G: LieGroup<N>, const N: usize> Draft<'_, G, N> {
    /// A single (not per-step) result.
    pub(super) fn single(estimates: Vec<Propagated<G, N>>, particles: Option<Arc<Vec<G>>>) -> Self {
        Draft {
            step: None,
            last_step: None,
            estimates,
            particles: particles.map_or(Particles::None, Particles::Owned),
            extras: Extras::default(),
            stats_from: None,
        }
    }
}

/// A result whose particles are `by · Xᵢ`, the particles Xᵢ of node `of` moved by a known
/// pose (a change of frame on the left): its Monte Carlo statistics are node `of`'s, moved.
/// The right-side Lie mean and covariance are left-invariant (CONVENTIONS §8):
/// Log((by μ)⁻¹ · by Xᵢ) = Log(μ⁻¹ Xᵢ), so the mean of the moved particles is by · μ (the
/// iteration from by X₀ is by times the one from X₀, step for step, with the same number of
/// steps) and the covariance is the same matrix. Read off, not iterated again: a pose graph's
/// drawn loop closures X_i · Z were half of its Lie-mean iterations (issue 33).
#[derive(Debug, Clone, Copy)]
pub(super) struct LeftTranslated<G> {
    /// The node whose particles were moved.
    pub of: usize,
    /// The known pose they were moved by.
    pub by: G,
}

/// The operation an [`Engine`] is evaluating: its index in the plan and its output's name
/// (what every error and finding is located by).
#[derive(Debug, Clone, Default)]
pub struct Current {
    /// Index of the operation in the plan.
    pub operation: usize,
    /// Name of its output.
    pub output: String,
}

pub(super) struct Engine<'a, 's, G: EvalGroup<N>, const N: usize> {
    pub plan: &'a Plan<G, N>,
    pub settings: &'a EvalSettings,
    pub monte_carlo: bool,
    /// Node index of each definition that is a pose (`None`: a known pose or not a pose).
    defined: Vec<Option<usize>>,
    pub out: Evaluation<G, N>,
    /// Random families already used (one per sampled input or noise source).
    families: u64,
    /// The sample indices this run simulates; `block.start` a multiple of [`CHUNK_SIZE`],
    /// so every random draw is the one the whole sample would make.
    pub block: Range<usize>,
    stats: StatsMode<'s, G, N>,
    /// The operation being evaluated.
    pub current: Current,
    /// Its kind (`None` while sampling the inputs).
    current_kind: Option<OpKind>,
}

impl<'a, 's, G: EvalGroup<N>, const N: usize> Engine<'a, 's, G, N> {
    pub(super) fn run(
        plan: &'a Plan<G, N>,
        settings: &'a EvalSettings,
        block: Range<usize>,
        stats: StatsMode<'s, G, N>,
    ) -> Result<Evaluation<G, N>, EvalError> {
        let monte_carlo = settings.monte_carlo();
        let mut engine = Engine {
            plan,
            settings,
            monte_carlo,
            defined: Vec::with_capacity(plan.definitions()),
            out: Evaluation {
                seed: settings.seed,
                samples: if monte_carlo { block.len() } else { 0 },
                block_samples: block.len(),
                methods: settings.methods.clone(),
                unscented: settings.unscented,
                nodes: Vec::new(),
                points: Vec::new(),
                trajectories: Vec::new(),
                matrix_frames: Vec::new(),
                findings: Vec::new(),
                graph: None,
            },
            families: 0,
            block,
            stats,
            current: Current::default(),
            current_kind: None,
        };
        engine.inputs()?;
        for (i, operation) in plan.operations.iter().enumerate() {
            if settings.cancelled() {
                engine.out.findings.push(Finding::Interrupted);
                break;
            }
            engine.current = Current {
                operation: i,
                output: operation.output.clone(),
            };
            engine.current_kind = Some(operation.op.kind());
            engine.operation(&operation.op)?;
            let node = engine
                .out
                .nodes
                .iter()
                .rposition(|n| n.name == operation.output);
            engine.defined.push(node);
        }
        Ok(engine.out)
    }

    /// The plan's poses: known transforms and sampled inputs.
    fn inputs(&mut self) -> Result<(), EvalError> {
        for def in &self.plan.poses {
            match def.value {
                PoseValue::Known(mean) => {
                    self.out.nodes.push(Node {
                        name: def.name.clone(),
                        role: Role::Fixed,
                        op: None,
                        step: None,
                        last_step: None,
                        nominal: mean,
                        estimates: Vec::new(),
                        monte_carlo: None,
                        particles: None,
                    });
                    self.defined.push(None);
                }
                PoseValue::Uncertain(pose) => {
                    let particles = if self.monte_carlo {
                        let sampled = self.sample(&pose).map_err(|source| EvalError::Pose {
                            pose: def.name.clone(),
                            source,
                        })?;
                        Some(Arc::new(sampled))
                    } else {
                        None
                    };
                    let estimate = Propagated {
                        pose,
                        method: Method::Exact,
                    };
                    self.push(
                        &def.name,
                        Role::Input,
                        Draft::single(vec![estimate], particles),
                    )?;
                    self.defined.push(Some(self.out.nodes.len() - 1));
                }
            }
        }
        Ok(())
    }

    /// The next random family (one per sampled input or noise source, in plan order).
    pub(super) fn next_family(&mut self) -> u64 {
        self.families += 1;
        self.families
    }

    /// The chunk index of this run's first particle.
    pub(super) fn first_chunk(&self) -> u64 {
        (self.block.start / CHUNK_SIZE) as u64
    }

    /// An error about the current operation.
    pub(super) fn math(&self, source: crate::Error) -> EvalError {
        EvalError::Math {
            operation: self.current.operation,
            output: self.current.output.clone(),
            source,
        }
    }

    /// The sigma-point estimate of the current output through `map` over the inputs' joint
    /// tangent, and a finding where a sigma point turns further than π
    /// ([`JointInputs::wrap_around`]); a failure is a finding.
    pub(super) fn sigma_points(
        &mut self,
        inputs: crate::Result<JointInputs<G, N>>,
        map: impl Fn(&[G]) -> G,
    ) -> Option<Propagated<G, N>> {
        let params = &self.settings.unscented;
        let run =
            inputs.and_then(|inputs| Ok((inputs.map(map, params)?, inputs.wrap_around(params)?)));
        match run {
            Ok((estimate, wrap)) => {
                if let Some(w) = wrap {
                    self.out.findings.push(Finding::SigmaPointsWrap {
                        output: self.current.output.clone(),
                        largest_rotation_rad: w.largest_rotation,
                        alpha: w.alpha,
                        alpha_below_pi: w.alpha_below_pi,
                    });
                }
                Some(estimate)
            }
            Err(e) => {
                self.method_failed(
                    None,
                    Method::SigmaPoints,
                    FailureReason::Refused {
                        message: e.to_string(),
                    },
                );
                None
            }
        }
    }

    /// n particles of `pose` for this run's block.
    pub(super) fn sample(&mut self, pose: &UncertainPose<G, N>) -> crate::Result<Vec<G>> {
        let family = self.next_family();
        let mut out = vec![*pose.mean(); self.block.len()];
        let sampler = Sampler::new(pose)?;
        sampler.fill_par_from(&mut out, self.settings.seed, family, self.first_chunk());
        Ok(out)
    }

    /// The Gaussian (the primary estimate) and the particles of an operand.
    pub(super) fn gaussian(&self, operand: Operand<G>) -> Result<Gaussian<G, N>, EvalError> {
        match operand {
            Operand::Known(g) => Ok((UncertainPose::certain(g), None)),
            Operand::Defined(k) => {
                let node = self
                    .defined
                    .get(k)
                    .copied()
                    .flatten()
                    .map(|i| &self.out.nodes[i])
                    .ok_or_else(|| EvalError::Undefined {
                        operation: self.current.operation,
                        output: self.current.output.clone(),
                        definition: k,
                    })?;
                let pose = node
                    .estimates
                    .first()
                    .map_or(UncertainPose::certain(node.nominal), |e| e.result.pose);
                Ok((pose, node.particles.clone()))
            }
        }
    }

    /// The node `operand` names, if it names one (a known pose has none).
    pub(super) fn node_of(&self, operand: Operand<G>) -> Option<usize> {
        match operand {
            Operand::Known(_) => None,
            Operand::Defined(k) => self.defined.get(k).copied().flatten(),
        }
    }

    /// Particles for `operand`: its own, or n copies of its mean.
    pub(super) fn particles_of(
        &self,
        pose: &UncertainPose<G, N>,
        particles: Option<Arc<Vec<G>>>,
    ) -> Arc<Vec<G>> {
        particles.unwrap_or_else(|| Arc::new(vec![*pose.mean(); self.block.len()]))
    }

    /// The kind of the operation being evaluated.
    pub(super) fn current_kind(&self) -> Option<OpKind> {
        self.current_kind
    }

    /// Whether `method` was requested.
    pub(super) fn wants(&self, method: Method) -> bool {
        self.settings.methods.contains(&method)
    }

    /// Adds a node for the current output (checked: a non-finite primary result is an error,
    /// any other non-finite estimate is dropped with a finding, an indefinite covariance is
    /// reported), with its Monte Carlo statistics and errors against them. Steps that the
    /// [`StepPolicy`](crate::plan::StepPolicy) does not record are skipped.
    pub(super) fn push(
        &mut self,
        name: &str,
        role: Role,
        draft: Draft<'_, G, N>,
    ) -> Result<(), EvalError> {
        let policy = self.settings.steps;
        if let (Some(k), Some(last)) = (draft.step, draft.last_step)
            && !policy.records(k, last)
        {
            return Ok(());
        }
        let mut estimates = Vec::with_capacity(draft.estimates.len() + 1);
        for (i, result) in draft.estimates.into_iter().enumerate() {
            if !finite_pose(&result) {
                if i == 0 {
                    return Err(EvalError::NonFinite {
                        operation: self.current.operation,
                        output: self.current.output.clone(),
                        step: draft.step,
                        method: result.method.label(),
                    });
                }
                self.method_failed(draft.step, result.method, FailureReason::NotFinite);
                continue;
            }
            self.check_psd(name, draft.step, result.method, result.pose.cov());
            estimates.push(Estimate {
                result,
                error_vs_monte_carlo: None,
                consistency: None,
            });
        }
        let nominal = estimates
            .first()
            .map_or_else(G::identity, |e| *e.result.pose.mean());
        let index = self.out.nodes.len();
        let mut node = Node {
            name: name.to_owned(),
            role,
            op: self.current_kind,
            step: draft.step,
            last_step: draft.last_step,
            nominal,
            estimates,
            monte_carlo: None,
            particles: None,
        };
        let particles: Option<&[G]> = match &draft.particles {
            Particles::None => None,
            Particles::Owned(p) => Some(p),
            Particles::Step(p) => Some(p),
        };
        if let Some(p) = particles.filter(|_| self.monte_carlo) {
            self.blocked_consistency(index, &mut node, p);
            let summary = self.summary(index, &node, p, draft.extras, draft.stats_from);
            let overflow = summary.as_ref().is_some_and(|r| {
                r.as_ref().is_ok_and(|mc| {
                    !finite_pose(&Propagated {
                        pose: mc.stats.to_pose(),
                        method: Method::MonteCarlo,
                    })
                })
            });
            match summary {
                Some(Ok(_)) if overflow => {
                    self.method_failed(
                        draft.step,
                        Method::MonteCarlo,
                        FailureReason::StatisticsNotFinite,
                    );
                }
                Some(Ok(mc)) => {
                    for e in &mut node.estimates {
                        // Undefined (not reported) when the Monte Carlo covariance is zero.
                        let error =
                            relative_frobenius_error(&e.result.pose.cov_right(), &mc.stats.cov);
                        e.error_vs_monte_carlo = error.is_finite().then_some(error);
                    }
                    node.estimates.push(Estimate {
                        result: Propagated {
                            pose: mc.stats.to_pose(),
                            method: Method::MonteCarlo,
                        },
                        error_vs_monte_carlo: Some(0.0),
                        consistency: None,
                    });
                    if matches!(self.stats, StatsMode::Own)
                        && let Some(mut sums) =
                            ConsistencySums::new(&node.estimates, self.settings.confidence)
                    {
                        // Every estimate, Monte Carlo's own Gaussian too (how Gaussian the
                        // cloud is in the tangent).
                        sums.add(p);
                        sums.finish(&mut node.estimates);
                    }
                    self.check_psd(name, draft.step, Method::MonteCarlo, &mc.stats.cov);
                    node.monte_carlo = Some(mc);
                }
                Some(Err(e)) => {
                    let message = crate::Error::from(e).to_string();
                    self.method_failed(
                        draft.step,
                        Method::MonteCarlo,
                        FailureReason::Refused { message },
                    );
                }
                None => {}
            }
        }
        node.particles = match draft.particles {
            Particles::None => None,
            Particles::Owned(p) => Some(p),
            Particles::Step(p) => {
                let detailed = match (draft.step, draft.last_step) {
                    (Some(k), Some(last)) => policy.detailed(k, last),
                    _ => true,
                };
                detailed.then(|| Arc::new(p.to_vec()))
            }
        };
        self.out.nodes.push(node);
        Ok(())
    }

    /// In a blocked run, the coverage and ANEES of `node`'s analytic estimates against its
    /// particles ([`consistency`](super::consistency)): added to the sums in the first pass,
    /// written from them in the last run. (A whole sample is counted once Monte Carlo's
    /// statistics stand, in [`push`](Self::push).)
    fn blocked_consistency(&mut self, index: usize, node: &mut Node<G, N>, particles: &[G]) {
        let confidence = self.settings.confidence;
        match &mut self.stats {
            StatsMode::Own | StatsMode::Skip => {}
            StatsMode::Collect(stats, first_pass) => {
                if *first_pass {
                    stats.add_consistency(index, &node.estimates, particles, confidence);
                }
            }
            StatsMode::Blocked(stats) => stats.finish_consistency(index, &mut node.estimates),
        }
    }

    /// Monte Carlo statistics of node `index` from the current [`StatsMode`].
    fn summary(
        &mut self,
        index: usize,
        node: &Node<G, N>,
        particles: &[G],
        extras: Extras,
        stats_from: Option<LeftTranslated<G>>,
    ) -> Option<Result<McSummary<G, N>, MeanError<G>>> {
        let moved = stats_from.and_then(|from| {
            let mc = self.out.nodes.get(from.of)?.monte_carlo.as_ref()?;
            let plain = extras == Extras::default() && mc.stats.side == Side::Right;
            plain.then(|| McSummary {
                stats: SampleStatistics {
                    mean: from.by.compose(&mc.stats.mean),
                    ..mc.stats
                },
                uncentred_left: None,
                uncentred_left_stderr: None,
                position_mean: None,
                position_mean_stderr: None,
            })
        });
        match &mut self.stats {
            StatsMode::Own if moved.is_some() => moved.map(Ok),
            StatsMode::Own => Some(sample_statistics(particles, Side::Right).map(|stats| {
                let (uncentred_left, uncentred_left_stderr) = if extras.uncentred_left {
                    let mut sums = BatchSums::new(particles.len());
                    sums.add(0, particles.len(), |r| {
                        tangent_moments(&particles[r], None, &node.nominal, Side::Left).1
                    });
                    let (mean, stderr) = sums.mean_and_stderr();
                    (Some(mean), stderr)
                } else {
                    (None, None)
                };
                let (position_mean, position_mean_stderr) = if extras.position_mean {
                    let mut sums = BatchSums::new(particles.len());
                    sums.add(0, particles.len(), |r| position_sum(&particles[r]));
                    let (mean, stderr) = sums.mean_and_stderr();
                    (Some(mean), stderr)
                } else {
                    (None, None)
                };
                McSummary {
                    stats,
                    uncentred_left,
                    uncentred_left_stderr,
                    position_mean,
                    position_mean_stderr,
                }
            })),
            StatsMode::Skip => None,
            StatsMode::Collect(stats, first_pass) => {
                stats.add_node(index, node, particles, self.block.start, *first_pass);
                None
            }
            StatsMode::Blocked(stats) => stats.node(index),
        }
    }

    /// Adds a point node with its first-order estimate and, where Monte Carlo ran, its cloud
    /// and statistics.
    pub(super) fn push_point(
        &mut self,
        name: &str,
        first_order: (Vector3<f64>, Matrix3<f64>),
        cloud: Option<Vec<[f64; 3]>>,
    ) -> Result<(), EvalError> {
        let (mean, cov) = first_order;
        if !(mean.iter().all(|v| v.abs() <= limits::OVERFLOW_COORDINATE)
            && cov.iter().all(|v| v.abs() <= limits::OVERFLOW_VARIANCE))
        {
            return Err(EvalError::NonFinite {
                operation: self.current.operation,
                output: self.current.output.clone(),
                step: None,
                method: Method::FirstOrder.label(),
            });
        }
        let mut estimates = vec![PointEstimate {
            method: Method::FirstOrder,
            mean,
            cov,
        }];
        let index = self.out.points.len();
        if let Some(points) = &cloud {
            let stats = match &mut self.stats {
                StatsMode::Own if points.len() >= 2 => {
                    let mut sums = VectorSums::new(Vector3::from(points[0]));
                    sums.add(points);
                    Some(sums.statistics())
                }
                StatsMode::Collect(stats, first_pass) => {
                    stats.add_point(index, points, *first_pass);
                    None
                }
                StatsMode::Blocked(stats) => stats.point(index),
                _ => None,
            };
            if let Some((m, c)) = stats {
                if m.iter().chain(c.iter()).all(|v| v.is_finite()) {
                    estimates.push(PointEstimate {
                        method: Method::MonteCarlo,
                        mean: m,
                        cov: c,
                    });
                } else {
                    self.method_failed(
                        None,
                        Method::MonteCarlo,
                        FailureReason::StatisticsNotFinite,
                    );
                }
            }
        }
        self.out.points.push(PointNode {
            name: name.to_owned(),
            estimates,
            particles: cloud,
        });
        Ok(())
    }
}

/// The sum of the samples' positions (x, y, z; z = 0 in the plane).
pub(super) fn position_sum<G: LieGroup<N>, const N: usize>(particles: &[G]) -> Vector3<f64> {
    particles.iter().map(|g| *g.to_se3().translation()).sum()
}

/// Whether a result's mean and covariance are finite and within the magnitudes that can be
/// computed on and drawn ([`limits::OVERFLOW_COORDINATE`], [`limits::OVERFLOW_VARIANCE`]).
fn finite_pose<G: LieGroup<N>, const N: usize>(result: &Propagated<G, N>) -> bool {
    let mean = result.pose.mean().to_se3();
    result
        .pose
        .cov()
        .iter()
        .all(|v| v.abs() <= limits::OVERFLOW_VARIANCE)
        && mean
            .translation()
            .iter()
            .all(|v| v.abs() <= limits::OVERFLOW_COORDINATE)
        && mean
            .rotation()
            .to_quaternion_xyzw()
            .iter()
            .all(|v| v.is_finite())
}
