//! Linearisation (the analytic Jacobians) and the Gauss–Newton / Levenberg–Marquardt loop.
//!
//! Every vertex moves by a right perturbation, X ← X · Exp(δ), δ = [ρ; θ]. For an edge with
//! E = Z⁻¹ X_i⁻¹ X_j and r = Log(E):
//! - ∂r/∂δ_j = J_r⁻¹(r) (E · Exp(δ_j));
//! - ∂r/∂δ_i = −J_r⁻¹(r) · Ad(X_j⁻¹ X_i) (X_i Exp(δ_i) = Exp(Ad_{X_i} δ_i) X_i moves E to
//!   E · Exp(−Ad(X_j⁻¹ X_i) δ_i));
//!
//! and for a prior r = Log(Z⁻¹ X): ∂r/∂δ = J_r⁻¹(r) (Solà et al. 2018, eqs. 44, 63, 79).
//! Each step solves (H + λ I) δ = −g with H = Σ Jᵀ Λ J, g = Σ Jᵀ Λ r.

use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::plan::graph::{GraphEdge, GraphReading, PoseGraph};

use super::sparse::{BlockSystem, SparseError};
use super::{Iteration, Optimizer, SolverSettings, Stop};

/// The Jacobians (∂r/∂δ_i, ∂r/∂δ_j) of an edge's residual `r` at `poses`.
///
/// ```
/// use posecov::eval::graph::edge_jacobians;
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::plan::graph::GraphEdge;
/// let e = GraphEdge { from: 0, to: 1, measurement: Se2::from_xy_theta(1.0, 0.0, 0.3), information: nalgebra::Matrix3::identity(), line: 1 };
/// let poses = [Se2::from_xy_theta(0.1, 0.2, 0.3), Se2::from_xy_theta(1.0, 0.5, 0.7)];
/// let (ji, jj) = edge_jacobians(&e, &poses);
/// // Moving both poses together (the same world-frame motion) leaves the residual unchanged:
/// let delta = nalgebra::Vector3::new(0.0, 0.0, 1e-6);
/// let dj = poses[1].inverse().adj() * poses[0].adj() * delta;
/// assert!((ji * delta + jj * dj).norm() < 1e-12);
/// ```
pub fn edge_jacobians<G: LieGroup<N>, const N: usize>(
    edge: &GraphEdge<G, N>,
    poses: &[G],
) -> (TangentMatrix<N>, TangentMatrix<N>) {
    jacobians_at(edge, poses, &edge.residual(poses))
}

/// [`edge_jacobians`] at the residual `r` already computed (the solver's linearisation needs
/// r too: one Log per edge, not two).
fn jacobians_at<G: LieGroup<N>, const N: usize>(
    edge: &GraphEdge<G, N>,
    poses: &[G],
    r: &Tangent<N>,
) -> (TangentMatrix<N>, TangentMatrix<N>) {
    let (xi, xj) = (poses[edge.from], poses[edge.to]);
    let jr_inv = G::jr_inv(r);
    let ad = xj.inverse().compose(&xi).adj();
    (-jr_inv * ad, jr_inv)
}

/// The state of one solve: the system (pattern, ordering, symbolic factor reused), which
/// vertex each unknown block is, and the reading of Λ.
pub(super) struct Problem<'a, G: LieGroup<N>, const N: usize> {
    pub graph: &'a PoseGraph<G, N>,
    /// Per vertex: its block among the unknowns (None: held fixed).
    pub block_of: Vec<Option<usize>>,
    pub system: BlockSystem<N>,
    pub reading: GraphReading,
}

impl<'a, G: LieGroup<N>, const N: usize> Problem<'a, G, N> {
    pub fn new(
        graph: &'a PoseGraph<G, N>,
        fixed: &[bool],
        reading: GraphReading,
    ) -> Result<Self, SparseError> {
        let mut block_of = Vec::with_capacity(graph.vertices.len());
        let mut blocks = 0;
        for &f in fixed {
            block_of.push((!f).then(|| {
                blocks += 1;
                blocks - 1
            }));
        }
        let pairs: Vec<(usize, usize)> = graph
            .edges
            .iter()
            .filter_map(|e| Some((block_of[e.from]?, block_of[e.to]?)))
            .collect();
        Ok(Self {
            graph,
            system: BlockSystem::new(blocks, &pairs)?,
            block_of,
            reading,
        })
    }

    /// Fills the system with H at `poses` and returns g (one entry per unknown).
    pub fn linearize(&mut self, poses: &[G]) -> Vec<f64> {
        let mut g = vec![0.0; self.system.unknowns()];
        self.system.clear();
        let mut add_g = |block: usize, v: &Tangent<N>| {
            for p in 0..N {
                g[block * N + p] += v[p];
            }
        };
        for e in &self.graph.edges {
            let (bi, bj) = (self.block_of[e.from], self.block_of[e.to]);
            if bi.is_none() && bj.is_none() {
                continue;
            }
            let r = e.residual(poses);
            let (ji, jj) = jacobians_at(e, poses, &r);
            let lambda = e.information_in(self.reading);
            let (li, lj) = (lambda * ji, lambda * jj);
            if let Some(bi) = bi {
                self.system.add(bi, bi, &(ji.transpose() * li));
                add_g(bi, &(li.transpose() * r));
            }
            if let Some(bj) = bj {
                self.system.add(bj, bj, &(jj.transpose() * lj));
                add_g(bj, &(lj.transpose() * r));
            }
            if let (Some(bi), Some(bj)) = (bi, bj) {
                self.system.add(bi, bj, &(ji.transpose() * lj));
            }
        }
        for p in &self.graph.priors {
            let Some(b) = self.block_of[p.vertex] else {
                continue;
            };
            let r = p.residual(poses);
            let j = G::jr_inv(&r);
            let lj = p.information_in(self.reading) * j;
            self.system.add(b, b, &(j.transpose() * lj));
            add_g(b, &(lj.transpose() * r));
        }
        g
    }

    /// X ← X · Exp(δ) for every unknown.
    pub fn retract(&self, poses: &[G], delta: &[f64]) -> Vec<G> {
        poses
            .iter()
            .zip(&self.block_of)
            .map(|(x, b)| match b {
                Some(b) => x.compose(&G::exp(&Tangent::<N>::from_fn(|p, _| delta[b * N + p]))),
                None => *x,
            })
            .collect()
    }

    pub fn chi2(&self, poses: &[G]) -> f64 {
        self.graph.chi2(poses, self.reading)
    }
}

/// What the loop returns: the estimate (the last accepted), its χ², the stop and the log.
pub(super) struct Run<G> {
    /// χ² at the start.
    pub chi2_before: f64,
    pub poses: Vec<G>,
    pub chi2: f64,
    pub stop: Stop,
    pub log: Vec<Iteration>,
}

/// Levenberg–Marquardt's λ: start, factor, bound (GTSAM's `LevenbergMarquardtParams`
/// defaults: 1e-5, ×10 on a rejected step and ÷10 on an accepted one, give up at 1e5).
const LAMBDA_START: f64 = 1e-5;
const LAMBDA_FACTOR: f64 = 10.0;
const LAMBDA_MAX: f64 = 1e5;

/// Runs the chosen optimiser from `start` (see [`SolverSettings`] for the stop criteria).
pub(super) fn run<G: LieGroup<N>, const N: usize>(
    problem: &mut Problem<'_, G, N>,
    start: Vec<G>,
    settings: &SolverSettings,
    progress: &mut dyn FnMut(&Iteration),
) -> Run<G> {
    let mut poses = start;
    let chi2_before = problem.chi2(&poses);
    let mut chi2 = chi2_before;
    let mut log = Vec::new();
    let lm = settings.optimizer == Optimizer::LevenbergMarquardt;
    let mut lambda = LAMBDA_START;
    let stop = 'outer: {
        if !chi2.is_finite() {
            break 'outer Stop::NotFinite;
        }
        if chi2 <= 0.0 {
            break 'outer Stop::Converged;
        }
        for iteration in 1..=settings.max_iterations {
            if settings.cancelled() {
                break 'outer Stop::Interrupted;
            }
            let g = problem.linearize(&poses);
            let undamped = problem.system.values.clone();
            loop {
                if lm {
                    problem.system.values.copy_from_slice(&undamped);
                    problem.system.add_to_diagonal(lambda);
                }
                let factored = problem.system.factorize();
                let step = match factored {
                    Ok(()) => {
                        let mut delta: Vec<f64> = g.iter().map(|v| -v).collect();
                        problem.system.solve_in_place(&mut delta, 1);
                        Some(delta)
                    }
                    Err(SparseError::NotPositiveDefinite) if lm => None,
                    Err(SparseError::NotPositiveDefinite) => break 'outer Stop::Singular,
                    Err(_) => break 'outer Stop::Singular,
                };
                let (candidate, new_chi2, norm) = match &step {
                    Some(delta) => {
                        let candidate = problem.retract(&poses, delta);
                        let new_chi2 = problem.chi2(&candidate);
                        let norm = delta.iter().map(|v| v * v).sum::<f64>().sqrt();
                        (Some(candidate), new_chi2, Some(norm))
                    }
                    None => (None, f64::INFINITY, None),
                };
                let accepted = new_chi2.is_finite() && new_chi2 <= chi2;
                let entry = Iteration {
                    iteration,
                    chi2: Some(new_chi2).filter(|c| c.is_finite()),
                    lambda: lm.then_some(lambda),
                    step_norm: norm.filter(|n| n.is_finite()),
                    accepted,
                };
                progress(&entry);
                log.push(entry);
                if !accepted {
                    if !lm {
                        break 'outer Stop::Diverged;
                    }
                    lambda *= LAMBDA_FACTOR;
                    if lambda > LAMBDA_MAX {
                        break 'outer Stop::LambdaLimit;
                    }
                    continue;
                }
                let previous = chi2;
                if let Some(c) = candidate {
                    poses = c;
                }
                chi2 = new_chi2;
                if lm {
                    lambda = (lambda / LAMBDA_FACTOR).max(1e-12);
                }
                // GTSAM's checkConvergence on its error f = χ²/2.
                let decrease = 0.5 * (previous - new_chi2);
                if new_chi2 <= 0.0
                    || decrease <= settings.absolute_tolerance
                    || decrease <= settings.relative_tolerance * 0.5 * previous
                {
                    break 'outer Stop::Converged;
                }
                break;
            }
        }
        Stop::MaxIterations
    };
    Run {
        chi2_before,
        poses,
        chi2,
        stop,
        log,
    }
}
