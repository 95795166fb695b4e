//! A plan's pose graph evaluated: optimised, every marginal, each loop closure's residual
//! before and after at the chosen confidence, and the findings to tell (outliers, parts,
//! duplicated edges, a solve that did not converge).

use crate::uncertain::Confidence;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::plan::graph::PoseGraph;

use super::{
    GraphReading, Iteration, Optimizer, Solution, SolverSettings, SparseError, Stop,
    relative_covariance,
};

/// The settings of a graph's evaluation (resolved by `app/`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraphSettings {
    /// Gauss–Newton or Levenberg–Marquardt.
    pub optimizer: Optimizer,
    /// g2o's or GTSAM's reading of the information matrices.
    pub reading: GraphReading,
    /// Probability inside the region a loop closure's residual is measured against.
    pub confidence: Confidence,
}

impl Default for GraphSettings {
    fn default() -> Self {
        Self {
            optimizer: Optimizer::default(),
            reading: GraphReading::default(),
            confidence: Confidence::DEFAULT,
        }
    }
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
    /// The covariance of X_i⁻¹ X_j from the joint marginal (None where an end is fixed).
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
    /// The confidence the residuals are measured at.
    pub confidence: Confidence,
    /// √χ²_N(confidence): a residual beyond it is an outlier.
    pub radius: f64,
    /// Edges whose (from, to) pair appeared before: (line, line of the first).
    pub duplicates: Vec<(usize, usize)>,
    /// χ² of each edge after the optimisation (by edge).
    pub edge_chi2: Vec<f64>,
}

/// Optimises `graph` and measures its loop closures at `settings.confidence`.
pub fn evaluate_graph<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    settings: &GraphSettings,
    cancel: Option<Arc<AtomicBool>>,
    progress: &mut dyn FnMut(&Iteration),
) -> Result<GraphEvaluation<G, N>, SparseError> {
    let solver = SolverSettings {
        optimizer: settings.optimizer,
        reading: settings.reading,
        cancel,
        ..SolverSettings::default()
    };
    let solution = super::optimize(graph, &solver, progress)?;
    let gtsam = settings.reading == GraphReading::Gtsam;
    let initial = graph.estimates();
    let mut first_of: std::collections::HashMap<(usize, usize), usize> = Default::default();
    let mut duplicates = Vec::new();
    let mut chain_taken = std::collections::HashSet::new();
    let mut loop_closures = Vec::new();
    for (k, e) in graph.edges.iter().enumerate() {
        let pair = (e.from.min(e.to), e.from.max(e.to));
        match first_of.get(&pair) {
            Some(&first) => duplicates.push((e.line, graph.edges[first].line)),
            None => {
                first_of.insert(pair, k);
            }
        }
        let (i, j) = (graph.vertices[e.from].id, graph.vertices[e.to].id);
        if i.abs_diff(j) == 1 && chain_taken.insert((i.min(j), i.max(j))) {
            continue;
        }
        let lambda = e.information_in(gtsam);
        let distance = |r: &Tangent<N>| (r.transpose() * lambda * r)[(0, 0)].max(0.0).sqrt();
        let residual_before = e.residual(&initial);
        let residual = e.residual(&solution.poses);
        loop_closures.push(LoopClosure {
            edge: k,
            from: i,
            to: j,
            line: e.line,
            mahalanobis_before: distance(&residual_before),
            residual_before,
            mahalanobis: distance(&residual),
            residual,
            relative_cov: solution.edge_joints[k].as_ref().map(|joint| {
                relative_covariance(&solution.poses[e.from], &solution.poses[e.to], joint)
            }),
        });
    }
    let edge_chi2 = graph
        .edges
        .iter()
        .map(|e| {
            let r = e.residual(&solution.poses);
            (r.transpose() * e.information_in(gtsam) * r)[(0, 0)]
        })
        .collect();
    Ok(GraphEvaluation {
        ids: graph.vertices.iter().map(|v| v.id).collect(),
        initial,
        solution,
        loop_closures,
        confidence: settings.confidence,
        radius: settings.confidence.radius(N),
        duplicates,
        edge_chi2,
    })
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

    /// Whether the solve stopped as it should (converged, or LM at a minimum).
    pub fn converged(&self) -> bool {
        self.solution.converged() || self.solution.stop == Stop::Converged
    }
}
