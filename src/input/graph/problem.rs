//! The optimisation problem a graph file states ([`PoseGraph`]): its vertices (or, when the
//! file has none, an initial guess chained from the edges), edges, priors and `FIX` records.

use std::collections::BTreeMap;

use super::parse::IdAt;
use crate::lie::{LieGroup, TangentMatrix};
use crate::plan::graph::{FixedVertex, GraphEdge, GraphPrior, GraphVertex, PoseGraph};

/// A checked edge.
pub(super) struct Edge<G: LieGroup<N>, const N: usize> {
    pub from: u64,
    pub to: u64,
    pub line: usize,
    pub measurement: G,
    /// Right-perturbation covariance over [ρ; θ] in the frame of X_from · Z (g2o's reading).
    pub cov: TangentMatrix<N>,
    /// Λ over [ρ; θ], g2o's reading.
    pub information: TangentMatrix<N>,
}

/// A vertex a `FIX` record holds fixed, with the record's line.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fix {
    pub vertex: IdAt,
    pub line: usize,
}

/// A checked prior.
pub(super) struct Prior<G: LieGroup<N>, const N: usize> {
    /// The vertex id and its offset in the text.
    pub vertex: IdAt,
    pub line: usize,
    pub measurement: G,
    /// Λ over [ρ; θ], g2o's reading.
    pub information: TangentMatrix<N>,
}

/// The initial guess of a file without vertex lines, as GTSAM's `load2D` builds it: the
/// smallest id at the identity, then each edge that joins a placed vertex to one not yet
/// placed places it (X_j = X_i · Z, or X_i = X_j · Z⁻¹) — the odometry edges (|i − j| = 1)
/// first, in file order, then the others; a part no edge reaches from a placed vertex starts
/// again at the identity. Line 0 marks a chained estimate.
pub(super) fn chain_initial_guess<G: LieGroup<N>, const N: usize>(
    edges: &[Edge<G, N>],
) -> BTreeMap<u64, (G, usize)> {
    let mut placed: BTreeMap<u64, (G, usize)> = BTreeMap::new();
    let mut ids: Vec<u64> = edges.iter().flat_map(|e| [e.from, e.to]).collect();
    ids.sort_unstable();
    ids.dedup();
    let order: Vec<&Edge<G, N>> = edges
        .iter()
        .filter(|e| e.from.abs_diff(e.to) == 1)
        .chain(edges.iter().filter(|e| e.from.abs_diff(e.to) != 1))
        .collect();
    let mut next_unplaced = ids.iter();
    loop {
        let mut changed = true;
        while changed {
            changed = false;
            for e in &order {
                match (placed.get(&e.from), placed.get(&e.to)) {
                    (Some(&(xi, _)), None) => {
                        placed.insert(e.to, (xi.compose(&e.measurement), 0));
                        changed = true;
                    }
                    (None, Some(&(xj, _))) => {
                        placed.insert(e.from, (xj.compose(&e.measurement.inverse()), 0));
                        changed = true;
                    }
                    _ => {}
                }
            }
        }
        match next_unplaced.find(|id| !placed.contains_key(id)) {
            Some(&id) => {
                placed.insert(id, (G::identity(), 0));
            }
            None => return placed,
        }
    }
}

/// The [`PoseGraph`] of the checked records (every id known to be defined).
pub(super) fn pose_graph<G: LieGroup<N>, const N: usize>(
    vertices: &BTreeMap<u64, (G, usize)>,
    edges: &[Edge<G, N>],
    priors: &[Prior<G, N>],
    fixes: &[Fix],
) -> PoseGraph<G, N> {
    let index: BTreeMap<u64, usize> = vertices
        .keys()
        .enumerate()
        .map(|(k, &id)| (id, k))
        .collect();
    PoseGraph {
        vertices: vertices
            .iter()
            .map(|(&id, &(estimate, line))| GraphVertex { id, estimate, line })
            .collect(),
        edges: edges
            .iter()
            .map(|e| GraphEdge {
                from: index[&e.from],
                to: index[&e.to],
                measurement: e.measurement,
                information: e.information,
                line: e.line,
            })
            .collect(),
        priors: priors
            .iter()
            .map(|p| GraphPrior {
                vertex: index[&p.vertex.id],
                measurement: p.measurement,
                information: p.information,
                line: p.line,
            })
            .collect(),
        fixed: fixes
            .iter()
            .map(|f| FixedVertex {
                index: index[&f.vertex.id],
                line: f.line,
            })
            .collect(),
    }
}
