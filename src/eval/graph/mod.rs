//! Pose-graph optimisation and marginals: a [`PoseGraph`] in, the optimised poses with every
//! pose's marginal covariance out ([`optimize`]).
//!
//! - **Error.** Edge i → j: r = Log(Z⁻¹ X_i⁻¹ X_j), cost rᵀ Λ r; prior: r = Log(Z⁻¹ X_i)
//!   ([CONVENTIONS §10]: X_j = X_i · Z · Exp(ξ), ξ ~ N(0, Λ⁻¹), right perturbation, [ρ; θ]).
//!   χ² = Σ rᵀ Λ r over edges and priors; GTSAM's `NonlinearFactorGraph::error` is χ²/2.
//!   Λ is the file's information read as g2o defines it, or as GTSAM's `readG2o` reads it
//!   ([`GraphReading`]; they differ for `EDGE_SE3:QUAT` by the half-angle factor).
//! - **Optimiser.** Levenberg–Marquardt by default (λ from 10⁻⁵, ×10 after a rejected step,
//!   ÷10 after an accepted one, giving up beyond 10⁵), or Gauss–Newton, which stops as
//!   `Diverged` the first time a step raises χ² and keeps the last good estimate. Both stop
//!   as GTSAM's `checkConvergence` does, on f = χ²/2: after a step that lowers f by at most
//!   [`SolverSettings::absolute_tolerance`] or by at most
//!   [`SolverSettings::relative_tolerance`] · f, or when f = 0, or after
//!   [`SolverSettings::max_iterations`] (GTSAM's defaults: 10⁻⁵, 10⁻⁵, 100).
//! - **Gauge.** Each connected part is anchored by its priors or `FIX` records, or else by
//!   holding its first vertex at its estimate ([`parts`](Part)); a vertex nothing reaches is
//!   kept as given with no marginal.
//! - **Linear algebra.** (H + λ I) δ = −g with faer's supernodal sparse Cholesky, the pose
//!   blocks ordered by approximate minimum degree; no dense n×n matrix anywhere.
//! - **Marginals.** From the *undamped* H at the final estimate, by selected inversion of its
//!   factor, supernode by supernode ([`marginals`]): Σ_k is the N×N block of H⁻¹, the covariance of δ_k in
//!   X_k = X̂_k · Exp(δ_k): posecov's right form over [ρ; θ]. GTSAM's `Marginals` gives the
//!   same for `Pose2` (tangent (x, y, θ), right); for `Pose3` its tangent is [ω; v], so its
//!   matrix is P Σ Pᵀ with P the one rotation-first permutation
//!   ([`crate::interop::cov_to_rotation_first`]).
//!
//! ```
//! use posecov::eval::graph::{SolverSettings, optimize};
//! use posecov::lie::{LieGroup, Se2};
//! use posecov::plan::graph::{GraphEdge, GraphVertex, PoseGraph};
//! let mut graph = PoseGraph::<Se2, 3>::default();
//! for (id, x) in [(0, 0.0), (1, 1.2), (2, 1.9)] {
//!     graph.vertices.push(GraphVertex { id, estimate: Se2::from_xy_theta(x, 0.0, 0.0), line: 0 });
//! }
//! let info = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(100.0, 100.0, 400.0));
//! for (from, to) in [(0, 1), (1, 2)] {
//!     graph.edges.push(GraphEdge { from, to, measurement: Se2::from_xy_theta(1.0, 0.0, 0.0), information: info, line: 0 });
//! }
//! let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
//! assert!(s.converged() && s.chi2_after < 1e-20);
//! assert!((s.poses[2].x() - 2.0).abs() < 1e-9);
//! // Vertex 0 holds the gauge; vertex 2's x variance is the two edges' together.
//! assert!(s.covariances[0].is_none());
//! assert!((s.covariances[2].unwrap()[(0, 0)] - 0.02).abs() < 1e-12);
//! ```
//!
//! [CONVENTIONS §10]: crate::conventions#10-pose-graphs-g2o-and-gtsam

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::lie::{LieGroup, TangentMatrix};
use crate::plan::graph::PoseGraph;

mod evaluate;
pub mod marginals;
mod parts;
mod report;
mod sigma;
mod solve;
pub mod sparse;
mod timeline;

pub use crate::plan::graph::GraphReading;
pub use evaluate::{
    GraphError, GraphEvaluation, GraphSettings, JointMarginal, LoopClosure, StepMarginals,
    evaluate_graph,
};
pub use parts::{Anchor, Part, Parts, parts};
pub use report::{
    JointRecord, LoopClosureRecord, OptimizedReport, PoseRecord, Seconds, StopCriteria,
    TimelineRecord,
};
pub use sigma::{PoseSigma, SigmaBeforeAfter};
pub use solve::edge_jacobians;
pub use sparse::{MAX_FACTOR_NONZEROS, SparseError};
pub use timeline::{
    ClosureStep, ClosureTimeline, MAX_TIMELINE_POSES, MAX_TIMELINE_STEPS, closure_counts,
};

/// Gauss–Newton or Levenberg–Marquardt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Optimizer {
    /// Levenberg–Marquardt (the default): damped steps, robust from a poor initial guess.
    #[default]
    LevenbergMarquardt,
    /// Gauss–Newton: undamped steps; stops as diverged when a step raises χ².
    GaussNewton,
}

/// The optimiser, its stop criteria and the reading (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct SolverSettings {
    /// Which optimiser.
    pub optimizer: Optimizer,
    /// Most iterations (outer iterations; LM's retries with a larger λ count within one).
    pub max_iterations: usize,
    /// Stop when a step lowers f = χ²/2 by at most this fraction of f.
    pub relative_tolerance: f64,
    /// Stop when a step lowers f = χ²/2 by at most this much.
    pub absolute_tolerance: f64,
    /// The reading of the information matrices.
    pub reading: GraphReading,
    /// Pairs of vertices (indices into the graph's vertices) whose joint marginal is wanted
    /// besides every edge's ([`Solution::joints`]).
    pub pairs: Vec<(usize, usize)>,
    /// Set to stop between iterations (Ctrl-C): the last accepted estimate is kept.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Whether to compute the marginals once optimised (default true; without them every
    /// covariance and joint is None and [`Solution::marginals_error`] says why).
    pub marginals: bool,
    /// Whether the marginals include every edge's joint marginal
    /// ([`Solution::edge_joints`]; default true; the loop-closure timeline's states keep each
    /// pose's only, and leave these None).
    pub edge_joints: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            optimizer: Optimizer::default(),
            max_iterations: 100,
            relative_tolerance: 1e-5,
            absolute_tolerance: 1e-5,
            reading: GraphReading::default(),
            pairs: Vec::new(),
            cancel: None,
            marginals: true,
            edge_joints: true,
        }
    }
}

impl SolverSettings {
    fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

impl Optimizer {
    /// The flag's value: `lm` or `gn`.
    ///
    /// ```
    /// assert_eq!(posecov::eval::graph::Optimizer::GaussNewton.name(), "gn");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Optimizer::LevenbergMarquardt => "lm",
            Optimizer::GaussNewton => "gn",
        }
    }
}

/// Which solve a step belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The graph with every edge.
    Optimizing,
    /// Step `step` (1-based) of `of` of the loop-closure timeline ([`ClosureTimeline`]).
    Timeline {
        /// This step.
        step: usize,
        /// Steps to solve.
        of: usize,
    },
}

/// Where a long solve reports each step it tries: the front end shows it (a progress bar);
/// the evaluation only calls it.
#[derive(Clone)]
pub struct ProgressHook(pub Arc<ProgressFn>);

/// What a [`ProgressHook`] calls: the solve and the step it tried.
pub type ProgressFn = dyn Fn(Stage, &Iteration) + Send + Sync;

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressHook")
    }
}

/// One step tried.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Iteration {
    /// The outer iteration (1-based).
    pub iteration: usize,
    /// χ² after the step (absent when the damped system could not be factored, or the step
    /// overflowed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chi2: Option<f64>,
    /// LM's λ for this try.
    pub lambda: Option<f64>,
    /// ‖δ‖ (absent when there was no step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_norm: Option<f64>,
    /// Whether the step was kept.
    pub accepted: bool,
}

/// Why the optimiser stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// A stop criterion was met.
    Converged,
    /// [`SolverSettings::max_iterations`] reached first.
    MaxIterations,
    /// LM could not lower χ² even with λ at its bound (a local minimum to within rounding).
    LambdaLimit,
    /// Gauss–Newton: a step raised χ²; the estimate before it is kept.
    Diverged,
    /// The normal equations were singular (Gauss–Newton) or could not be factored.
    Singular,
    /// χ² of the initial guess is not finite.
    NotFinite,
    /// Stopped by the user.
    Interrupted,
}

/// An optimised graph with its marginals.
#[derive(Debug, Clone)]
pub struct Solution<G: LieGroup<N>, const N: usize> {
    /// The optimiser used.
    pub optimizer: Optimizer,
    /// The reading of the information matrices.
    pub reading: GraphReading,
    /// Accepted steps.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: Stop,
    /// Every step tried, in order.
    pub log: Vec<Iteration>,
    /// χ² at the initial guess.
    pub chi2_before: f64,
    /// χ² at the result.
    pub chi2_after: f64,
    /// The result, one per vertex (the last accepted estimate if it did not converge).
    pub poses: Vec<G>,
    /// Each vertex's marginal covariance, right form [ρ; θ] (None: held fixed, isolated, or
    /// the marginals failed, see `marginals_error`).
    pub covariances: Vec<Option<TangentMatrix<N>>>,
    /// The joint marginal (Σ_ii, Σ_ij, Σ_jj) of each edge's two poses, by edge (a vertex held
    /// fixed has zero blocks; None: no marginals, or [`SolverSettings::edge_joints`] false).
    pub edge_joints: Vec<Option<Joint<N>>>,
    /// The joint marginal of each of [`SolverSettings::pairs`], in order (as `edge_joints`).
    pub joints: Vec<Option<Joint<N>>>,
    /// The graph's connected parts and their anchors.
    pub parts: Vec<Part>,
    /// Per vertex: its part (an index into `parts`).
    pub part_of: Vec<usize>,
    /// Why there are no marginals, if there are none.
    pub marginals_error: Option<String>,
    /// Scalar unknowns.
    pub unknowns: usize,
    /// Non-zeros of the Cholesky factor.
    pub factor_nonzeros: usize,
    /// Seconds spent optimising.
    pub optimize_seconds: f64,
    /// Seconds spent on every pose's marginal (factor of the undamped H and selected inversion).
    pub marginals_seconds: f64,
}

impl<G: LieGroup<N>, const N: usize> Solution<G, N> {
    /// Whether a stop criterion was met (or LM reached its λ bound at a minimum).
    pub fn converged(&self) -> bool {
        matches!(self.stop, Stop::Converged | Stop::LambdaLimit)
    }
}

/// Optimises `graph` and computes every pose's marginal (see the [module docs](self) for the
/// method and an example). `progress` sees every step tried. Errors only when the problem
/// cannot be set up (too large, see [`MAX_FACTOR_NONZEROS`]); a solve that does not converge
/// is a [`Solution`] whose [`Stop`] and log say so.
pub fn optimize<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    settings: &SolverSettings,
    progress: &mut dyn FnMut(&Iteration),
) -> Result<Solution<G, N>, SparseError> {
    let parts::Parts {
        parts,
        fixed,
        part_of,
    } = parts::parts(graph);
    let mut problem = solve::Problem::new(graph, &fixed, settings.reading)?;
    let start = graph.estimates();
    let clock = Instant::now();
    let run = solve::run(&mut problem, start, settings, progress);
    let optimize_seconds = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    let mut covariances = vec![None; graph.vertices.len()];
    let mut edge_joints = vec![None; graph.edges.len()];
    let mut joints = vec![None; settings.pairs.len()];
    let marginals_error = if settings.marginals {
        marginals_at(
            &mut problem,
            &run.poses,
            &settings.pairs,
            &mut covariances,
            settings.edge_joints.then_some(&mut edge_joints[..]),
            &mut joints,
        )
        .err()
    } else {
        Some(NOT_ASKED.to_owned())
    };
    let marginals_seconds = clock.elapsed().as_secs_f64();
    Ok(Solution {
        optimizer: settings.optimizer,
        reading: settings.reading,
        iterations: run.log.iter().filter(|i| i.accepted).count(),
        stop: run.stop,
        log: run.log,
        chi2_before: run.chi2_before,
        chi2_after: run.chi2,
        poses: run.poses,
        covariances,
        edge_joints,
        joints,
        parts,
        part_of,
        marginals_error,
        unknowns: problem.system.unknowns(),
        factor_nonzeros: problem.system.factor_nonzeros(),
        optimize_seconds,
        marginals_seconds,
    })
}

/// [`Solution::marginals_error`] of a solve whose marginals were not asked for
/// ([`SolverSettings::marginals`] false).
pub const NOT_ASKED: &str = "marginals not asked for";

/// The joint marginal of two poses a, b: (Σ_aa, Σ_ab, Σ_bb), the blocks of H⁻¹ over
/// [δ_a; δ_b] (right form, [ρ; θ]; Σ_ba = Σ_abᵀ).
pub type Joint<const N: usize> = [TangentMatrix<N>; 3];

/// Every unknown pose's marginal, every edge's joint marginal (when `edge_joints` is given)
/// and the joint marginal of each of `pairs` from the undamped H at `poses`. A block in the
/// factor's pattern (every pose's, every edge's) comes from the selected inverse; another
/// pair's Σ_ab from two block solves with the same factor ([`marginals::joint_by_solves`]). A
/// vertex held fixed has zero blocks.
fn marginals_at<G: LieGroup<N>, const N: usize>(
    problem: &mut solve::Problem<'_, G, N>,
    poses: &[G],
    pairs: &[(usize, usize)],
    covariances: &mut [Option<TangentMatrix<N>>],
    edge_joints: Option<&mut [Option<Joint<N>>]>,
    joints: &mut [Option<Joint<N>>],
) -> Result<(), String> {
    let zero = TangentMatrix::<N>::zeros();
    if problem.system.unknowns() == 0 {
        if let Some(edge_joints) = edge_joints {
            edge_joints.iter_mut().for_each(|j| *j = Some([zero; 3]));
        }
        joints.iter_mut().for_each(|j| *j = Some([zero; 3]));
        return Ok(());
    }
    problem.linearize(poses);
    problem.system.factorize().map_err(|e| e.to_string())?;
    let inverse = marginals::selected_inverse(&problem.system)
        .ok_or("selected inversion met an entry outside the factor's pattern")?;
    let system = &problem.system;
    let block_of = &problem.block_of;
    for (v, block) in block_of.iter().enumerate() {
        if let Some(b) = block {
            covariances[v] = inverse.block::<N>(*b, *b);
        }
    }
    let covariances: &[Option<TangentMatrix<N>>] = covariances;
    let diagonal = |v: usize| match block_of[v] {
        Some(_) => covariances[v],
        None => Some(zero),
    };
    let joint = |a: usize, b: usize| -> Option<Joint<N>> {
        let cross = match (block_of[a], block_of[b]) {
            (Some(ba), Some(bb)) => inverse
                .block::<N>(ba, bb)
                .unwrap_or_else(|| marginals::joint_by_solves(system, ba, bb)),
            _ => zero,
        };
        Some([diagonal(a)?, cross, diagonal(b)?])
    };
    if let Some(edge_joints) = edge_joints {
        for (k, e) in problem.graph.edges.iter().enumerate() {
            edge_joints[k] = joint(e.from, e.to);
        }
    }
    for (k, &(a, b)) in pairs.iter().enumerate() {
        joints[k] = joint(a, b);
    }
    Ok(())
}

/// The covariance of X_i⁻¹ X_j (right form) from the joint marginal of X_i and X_j:
/// δ_ij ≈ −Ad(X_j⁻¹ X_i) δ_i + δ_j, so Σ = A Σ_ii Aᵀ − A Σ_ij − Σ_ji Aᵀ + Σ_jj with
/// A = Ad(X_j⁻¹ X_i) (a fixed end contributes nothing: pass zeros).
///
/// ```
/// use posecov::eval::graph::relative_covariance;
/// use posecov::lie::{LieGroup, Se2};
/// use nalgebra::Matrix3;
/// let (xi, xj) = (Se2::identity(), Se2::from_xy_theta(1.0, 0.0, 0.0));
/// let s = Matrix3::identity() * 0.01;
/// // Perfectly correlated poses (Σ_ij = Σ_ii Aᵀ, Σ_jj = A Σ_ii Aᵀ) move together:
/// let a = xj.inverse().compose(&xi).adj();
/// let rel = relative_covariance(&xi, &xj, &[s, s * a.transpose(), a * s * a.transpose()]);
/// assert!(rel.norm() < 1e-15);
/// ```
pub fn relative_covariance<G: LieGroup<N>, const N: usize>(
    xi: &G,
    xj: &G,
    joint: &[TangentMatrix<N>; 3],
) -> TangentMatrix<N> {
    let a = xj.inverse().compose(xi).adj();
    let [ii, ij, jj] = joint;
    let s = a * ii * a.transpose() - a * ij - ij.transpose() * a.transpose() + jj;
    (s + s.transpose()) * 0.5
}
