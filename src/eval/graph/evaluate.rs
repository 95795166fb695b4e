//! A plan's pose graph evaluated: optimised, every marginal, each loop closure's residual
//! before and after at the chosen confidence, the joint marginals asked for, and the
//! findings to tell (outliers, parts, duplicated edges, a solve that did not converge).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::plan::graph::PoseGraph;
use crate::uncertain::Confidence;

use super::sigma::{PoseSigma, SigmaBeforeAfter};
use super::timeline::ClosureStep;
use super::{
    Anchor, ClosureTimeline, GraphReading, Iteration, Joint, Optimizer, Solution, SolverSettings,
    SparseError, Stage, Stop, relative_covariance,
};

/// The settings of a graph's evaluation (resolved by `app/`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GraphSettings {
    /// Gauss–Newton or Levenberg–Marquardt.
    pub optimizer: Optimizer,
    /// g2o's or GTSAM's reading of the information matrices.
    pub reading: GraphReading,
    /// Pairs of vertex ids (a, b) whose joint marginal is wanted (`--joint a,b`).
    pub joints: Vec<(u64, u64)>,
    /// Which steps of the loop-closure timeline get every pose's marginal.
    pub step_marginals: StepMarginals,
}

/// Which steps of the loop-closure timeline ([`ClosureTimeline`]) get every pose's marginal
/// besides the final solution's: computed where they are shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StepMarginals {
    /// Every step's (the viewer's `step` timeline shows each state's marginals).
    #[default]
    Every,
    /// Step 0's only (dead reckoning, the σ before of [`GraphEvaluation::sigmas`]): the other
    /// steps keep their poses and χ² but no marginals ([`ClosureStep::covariances`] all None),
    /// for a report, which shows no other step's.
    DeadReckoning,
    /// Step 0's only, and no step between it and the final solution solved at all
    /// ([`ClosureTimeline::steps`] holds step 0 alone): for a figure of the final state, which
    /// draws the graph before (dead reckoning) and after and nothing between.
    DeadReckoningOnly,
}

/// Why a graph could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GraphError {
    /// The linear algebra cannot take it on (too large) or failed.
    #[error(transparent)]
    Sparse(#[from] SparseError),
    /// A joint marginal was asked for a vertex id the graph does not have.
    #[error("no vertex has id {id} (a joint marginal was asked for it)")]
    UnknownVertex {
        /// The id.
        id: u64,
    },
}

/// The joint marginal of two poses a, b and what it says about X_a⁻¹ X_b.
#[derive(Debug, Clone, PartialEq)]
pub struct JointMarginal<G, const N: usize> {
    /// Vertex id a.
    pub a: u64,
    /// Vertex id b.
    pub b: u64,
    /// (Σ_aa, Σ_ab, Σ_bb) over [δ_a; δ_b] (right form; zero blocks for a vertex held fixed;
    /// None for a vertex nothing reaches, or without marginals).
    pub blocks: Option<Joint<N>>,
    /// X_a⁻¹ X_b at the optimised poses.
    pub relative_pose: G,
    /// Cov(Log((X̂_a⁻¹ X̂_b)⁻¹ X_a⁻¹ X_b)), the right-form covariance of the relative pose to
    /// first order ([`relative_covariance`]); None where `blocks` is, or when a and b lie in
    /// different parts (each part's gauge is its own: the graph does not say where one part
    /// is from the other).
    pub relative_cov: Option<TangentMatrix<N>>,
}

/// A loop closure (every edge but the first between consecutive ids k, k + 1), measured
/// before and after the optimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopClosure<const N: usize> {
    /// Index into the graph's edges.
    pub edge: usize,
    /// Vertex id i.
    pub from: u64,
    /// Vertex id j.
    pub to: u64,
    /// The edge's line.
    pub line: usize,
    /// r = Log(Z⁻¹ X_i⁻¹ X_j) at the file's estimates ([ρ; θ]).
    pub residual_before: Tangent<N>,
    /// d = √(rᵀ Λ r) at the file's estimates.
    pub mahalanobis_before: f64,
    /// r at the optimised poses.
    pub residual: Tangent<N>,
    /// d at the optimised poses.
    pub mahalanobis: f64,
    /// Where the loop closure puts X_j at the optimised poses, X_i · Z = X_j · Exp(−r): the
    /// position of that predicted pose in the world (the residual is the step from it to
    /// X_j's own position).
    pub predicted_position: nalgebra::Vector3<f64>,
    /// The covariance of X_i⁻¹ X_j from the joint marginal (None without marginals).
    pub relative_cov: Option<TangentMatrix<N>>,
}

/// What a graph evaluates to.
#[derive(Debug, Clone)]
pub struct GraphEvaluation<G: LieGroup<N>, const N: usize> {
    /// Vertex ids, in the order of every per-vertex vector.
    pub ids: Vec<u64>,
    /// The file's estimates (the initial guess).
    pub initial: Vec<G>,
    /// The optimised graph with its marginals.
    pub solution: Solution<G, N>,
    /// Every loop closure.
    pub loop_closures: Vec<LoopClosure<N>>,
    /// The joint marginals asked for ([`GraphSettings::joints`]), in order.
    pub joints: Vec<JointMarginal<G, N>>,
    /// The graph re-solved as its loop closures are added one by one.
    pub timeline: ClosureTimeline<G, N>,
    /// Every pose's dead-reckoning marginal: of the graph without its loop closures
    /// (odometry and priors), optimised, right form [ρ; θ]; None as in
    /// [`Solution::covariances`]. The "before" of [`GraphEvaluation::sigmas`].
    pub dead_reckoning: Vec<Option<TangentMatrix<N>>>,
    /// The confidence the residuals are measured at.
    pub confidence: Confidence,
    /// √χ²_N(confidence): a residual beyond it is an outlier.
    pub radius: f64,
    /// Edges whose (from, to) pair appeared before: (line, line of the first).
    pub duplicates: Vec<(usize, usize)>,
    /// χ² of each edge after the optimisation (by edge).
    pub edge_chi2: Vec<f64>,
}

/// Optimises `graph`, measures its loop closures at `confidence` (the evaluation's one
/// `EvalSettings::confidence`), computes the
/// joint marginals of `settings.joints` and re-solves it loop closure by loop closure
/// ([`ClosureTimeline`]); `progress` sees every step tried, and of which solve.
///
/// ```
/// use posecov::eval::graph::{GraphSettings, evaluate_graph};
/// use posecov::input::graph::read_text;
/// use posecov::plan::AnyPlan;
/// use posecov::uncertain::Confidence;
/// let text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\n\
///             EDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\nEDGE_SE2 1 2 1 0 0 100 0 0 100 0 400\n\
///             EDGE_SE2 0 2 2.1 0 0 100 0 0 100 0 400\n";
/// let AnyPlan::Se2(plan) = read_text(text, "g.g2o").unwrap().1.plan else { unreachable!() };
/// let settings = GraphSettings { joints: vec![(1, 2)], ..Default::default() };
/// let g = evaluate_graph(plan.graph.as_ref().unwrap(), &settings, Confidence::DEFAULT, None, &mut |_, _| {}).unwrap();
/// assert_eq!(g.loop_closures.len(), 1); // 0 → 2
/// assert!(g.loop_closures[0].mahalanobis < g.loop_closures[0].mahalanobis_before);
/// let joint = &g.joints[0];
/// assert!(joint.relative_cov.unwrap()[(0, 0)] > 0.0);
/// let wrong = GraphSettings { joints: vec![(1, 7)], ..Default::default() };
/// let e = evaluate_graph(plan.graph.as_ref().unwrap(), &wrong, Confidence::DEFAULT, None, &mut |_, _| {}).unwrap_err();
/// assert_eq!(e.to_string(), "no vertex has id 7 (a joint marginal was asked for it)");
/// ```
pub fn evaluate_graph<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    settings: &GraphSettings,
    confidence: Confidence,
    cancel: Option<Arc<AtomicBool>>,
    progress: &mut (dyn FnMut(Stage, &Iteration) + Send),
) -> Result<GraphEvaluation<G, N>, GraphError> {
    let index = |id: u64| {
        graph
            .vertices
            .binary_search_by_key(&id, |v| v.id)
            .map_err(|_| GraphError::UnknownVertex { id })
    };
    let pairs = settings
        .joints
        .iter()
        .map(|&(a, b)| Ok((index(a)?, index(b)?)))
        .collect::<Result<Vec<_>, GraphError>>()?;
    let solver = SolverSettings {
        optimizer: settings.optimizer,
        reading: settings.reading,
        pairs,
        cancel,
        ..SolverSettings::default()
    };
    let loop_edges = loop_closure_edges(graph);
    // The full solve and the timeline's re-solves (each warm-started from the step before;
    // the last step is the full solution) depend on nothing of each other: both run at once.
    let progress = std::sync::Mutex::new(progress);
    let report = |stage: Stage, i: &Iteration| {
        if let Ok(mut p) = progress.lock() {
            (*p)(stage, i);
        }
    };
    let (solution, steps) = rayon::join(
        || super::optimize(graph, &solver, &mut |i| report(Stage::Optimizing, i)),
        || {
            let timeline = super::timeline::closure_timeline(
                graph,
                &loop_edges,
                &solver,
                settings.step_marginals,
                &report,
            )?;
            let dead_reckoning =
                super::timeline::dead_reckoning(graph, &loop_edges, &timeline, &solver, &report)?;
            Ok::<_, SparseError>((timeline, dead_reckoning))
        },
    );
    let solution = solution?;
    let (mut timeline, dead_reckoning) = steps?;
    let dead_reckoning = dead_reckoning.unwrap_or_else(|| solution.covariances.clone());
    if solution.stop == Stop::Interrupted {
        timeline = ClosureTimeline {
            steps: Vec::new(),
            too_large: None,
            interrupted: true,
        };
    } else if !timeline.interrupted && timeline.too_large.is_none() && !loop_edges.is_empty() {
        timeline.steps.push(ClosureStep {
            closures: loop_edges.len(),
            poses: solution.poses.clone(),
            covariances: solution.covariances.clone(),
            chi2: solution.chi2_after,
            stop: solution.stop,
        });
    }
    let isolated = |v: usize| {
        matches!(
            solution.parts[solution.part_of[v]].anchor,
            Anchor::Isolated { .. }
        )
    };
    let joints = solver
        .pairs
        .iter()
        .zip(&solution.joints)
        .map(|(&(a, b), blocks)| {
            let (xa, xb) = (&solution.poses[a], &solution.poses[b]);
            let blocks = blocks.filter(|_| !isolated(a) && !isolated(b));
            JointMarginal {
                a: graph.vertices[a].id,
                b: graph.vertices[b].id,
                blocks,
                relative_pose: xa.inverse().compose(xb),
                relative_cov: blocks
                    .filter(|_| solution.part_of[a] == solution.part_of[b])
                    .map(|joint| relative_covariance(xa, xb, &joint)),
            }
        })
        .collect();
    let initial = graph.estimates();
    let mut first_of: std::collections::HashMap<(usize, usize), usize> = Default::default();
    let mut duplicates = Vec::new();
    for (k, e) in graph.edges.iter().enumerate() {
        let pair = (e.from.min(e.to), e.from.max(e.to));
        match first_of.get(&pair) {
            Some(&first) => duplicates.push((e.line, graph.edges[first].line)),
            None => {
                first_of.insert(pair, k);
            }
        }
    }
    let loop_closures = loop_edges
        .iter()
        .map(|&k| {
            let e = &graph.edges[k];
            let lambda = e.information_in(settings.reading);
            let distance = |r: &Tangent<N>| (r.transpose() * lambda * r)[(0, 0)].max(0.0).sqrt();
            let residual_before = e.residual(&initial);
            let residual = e.residual(&solution.poses);
            // X_j = X_i · Z · Exp(r): the predicted pose is X_j · Exp(−r).
            let predicted = solution.poses[e.to].compose(&G::exp(&-residual));
            LoopClosure {
                edge: k,
                from: graph.vertices[e.from].id,
                to: graph.vertices[e.to].id,
                line: e.line,
                mahalanobis_before: distance(&residual_before),
                residual_before,
                mahalanobis: distance(&residual),
                predicted_position: predicted.to_se3().translation().to_owned(),
                residual,
                relative_cov: solution.edge_joints[k].as_ref().map(|joint| {
                    relative_covariance(&solution.poses[e.from], &solution.poses[e.to], joint)
                }),
            }
        })
        .collect();
    let edge_chi2 = graph
        .edges
        .iter()
        .map(|e| {
            let r = e.residual(&solution.poses);
            (r.transpose() * e.information_in(settings.reading) * r)[(0, 0)]
        })
        .collect();
    Ok(GraphEvaluation {
        ids: graph.vertices.iter().map(|v| v.id).collect(),
        initial,
        solution,
        loop_closures,
        joints,
        timeline,
        dead_reckoning,
        confidence,
        radius: confidence.radius(N),
        duplicates,
        edge_chi2,
    })
}

/// The loop closures of `graph`, indices into its edges in file order: every edge but the
/// first between consecutive ids k, k + 1.
fn loop_closure_edges<G: LieGroup<N>, const N: usize>(graph: &PoseGraph<G, N>) -> Vec<usize> {
    let mut chain_taken = std::collections::HashSet::new();
    (0..graph.edges.len())
        .filter(|&k| {
            let e = &graph.edges[k];
            let (i, j) = (graph.vertices[e.from].id, graph.vertices[e.to].id);
            !(i.abs_diff(j) == 1 && chain_taken.insert((i.min(j), i.max(j))))
        })
        .collect()
}

impl<G: LieGroup<N>, const N: usize> GraphEvaluation<G, N> {
    /// The loop closures beyond the radius after the optimisation, worst first.
    pub fn outliers(&self) -> Vec<&LoopClosure<N>> {
        let mut out: Vec<&LoopClosure<N>> = self
            .loop_closures
            .iter()
            .filter(|l| l.mahalanobis > self.radius)
            .collect();
        out.sort_by(|a, b| b.mahalanobis.total_cmp(&a.mahalanobis));
        out
    }

    /// Every pose's σ before (dead reckoning, [`GraphEvaluation::dead_reckoning`]) and after
    /// (the optimised marginal), in vertex order: what the loop closures did.
    pub fn sigmas(&self) -> Vec<SigmaBeforeAfter> {
        self.dead_reckoning
            .iter()
            .zip(&self.solution.covariances)
            .map(|(before, after)| SigmaBeforeAfter {
                before: before.as_ref().map(PoseSigma::of::<G, N>),
                after: after.as_ref().map(PoseSigma::of::<G, N>),
            })
            .collect()
    }

    /// Whether the solve stopped as it should (converged, or LM at a minimum).
    pub fn converged(&self) -> bool {
        self.solution.converged() || self.solution.stop == Stop::Converged
    }
}
