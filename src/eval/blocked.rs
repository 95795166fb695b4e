//! Monte Carlo statistics of a sample too large to hold, gathered block by block
//! ([blocked Monte Carlo](super#blocked-monte-carlo-bounded-memory)): per node the Lie mean
//! and covariance through the crate's one [`LieMeanAccumulator`] (started from block 0's
//! mean), and in the first pass the sums behind the uncentred left covariance about the
//! nominal and the Cartesian position mean; per point node the points' mean and covariance.

use crate::uncertain::Confidence;
use nalgebra::{Matrix3, Vector3};

use super::batch_means::BatchSums;
use super::consistency::ConsistencySums;
use super::engine::position_sum;
use super::groups::EvalGroup;
use super::model::{Estimate, Evaluation, McSummary, Node};
use crate::lie::LieGroup;
use crate::sample::{LieMeanAccumulator, MeanError, tangent_moments};
use crate::uncertain::{Method, Side};

/// One node's running sums.
struct NodeSums<G: LieGroup<N>, const N: usize> {
    mean: LieMeanAccumulator<G, N>,
    /// Σ Log_left(X nominal⁻¹) Log_left(…)ᵀ per batch ([`batch_means`](super::batch_means)),
    /// where asked for.
    left_outer: Option<BatchSums<N, N>>,
    /// Positions are summed relative to `shift` (block 0's mean) to avoid cancellation.
    shift: Vector3<f64>,
    position_sum: Option<BatchSums<3, 1>>,
    /// Coverage counts of the node's analytic estimates (Monte Carlo's own Gaussian is
    /// known only after every block, so it is not counted in a blocked run).
    consistency: Option<ConsistencySums<G, N>>,
}

/// Running sums of 3-vectors relative to a shift: mean and 1/(n−1) covariance.
#[derive(Clone, Copy, Debug)]
pub(super) struct VectorSums {
    shift: Vector3<f64>,
    sum: Vector3<f64>,
    outer: Matrix3<f64>,
    count: usize,
}

impl VectorSums {
    /// Empty sums about `shift`.
    pub(super) fn new(shift: Vector3<f64>) -> Self {
        Self {
            shift,
            sum: Vector3::zeros(),
            outer: Matrix3::zeros(),
            count: 0,
        }
    }

    /// Adds points.
    pub(super) fn add(&mut self, points: &[[f64; 3]]) {
        for x in points {
            let d = Vector3::from(*x) - self.shift;
            self.sum += d;
            self.outer += d * d.transpose();
        }
        self.count += points.len();
    }

    /// Mean and 1/(n−1) covariance.
    pub(super) fn statistics(&self) -> (Vector3<f64>, Matrix3<f64>) {
        let n = self.count as f64;
        let d = self.sum / n;
        let cov = (self.outer - d * d.transpose() * n) / (n - 1.0);
        (self.shift + d, (cov + cov.transpose()) * 0.5)
    }
}

/// The statistics of every node and point over all blocks.
pub(super) struct BlockedStats<G: LieGroup<N>, const N: usize> {
    nodes: Vec<Option<NodeSums<G, N>>>,
    points: Vec<Option<VectorSums>>,
}

impl<G: LieGroup<N>, const N: usize> BlockedStats<G, N> {
    /// Starts from block 0's evaluation of a sample of `total`: its Monte Carlo means start
    /// each iteration and shift each sum.
    pub(super) fn start(first: &Evaluation<G, N>, total: usize) -> Self {
        let nodes = first
            .nodes
            .iter()
            .map(|node| {
                let mc = node.monte_carlo.as_ref()?;
                Some(NodeSums {
                    mean: LieMeanAccumulator::new(mc.stats.mean, Side::Right),
                    left_outer: mc.uncentred_left.map(|_| BatchSums::new(total)),
                    shift: mc.position_mean.unwrap_or_else(Vector3::zeros),
                    position_sum: mc.position_mean.map(|_| BatchSums::new(total)),
                    consistency: None,
                })
            })
            .collect();
        let points = first
            .points
            .iter()
            .map(|p| {
                p.estimates
                    .iter()
                    .find(|e| e.method == Method::MonteCarlo)
                    .map(|e| VectorSums::new(e.mean))
            })
            .collect();
        Self { nodes, points }
    }

    /// Whether some node's Lie mean is still iterating.
    pub(super) fn iterating(&self) -> bool {
        self.nodes.iter().flatten().any(|n| n.mean.is_iterating())
    }

    /// Adds one block's particles of node `index`, the samples `offset ..` of the whole
    /// sample (`first_pass`: also the one-pass sums).
    pub(super) fn add_node(
        &mut self,
        index: usize,
        node: &Node<G, N>,
        particles: &[G],
        offset: usize,
        first_pass: bool,
    ) {
        let Some(Some(sums)) = self.nodes.get_mut(index) else {
            return;
        };
        sums.mean.add(particles, None);
        if first_pass {
            if let Some(outer) = sums.left_outer.as_mut() {
                outer.add(offset, particles.len(), |r| {
                    tangent_moments(&particles[r], None, &node.nominal, Side::Left).1
                });
            }
            if let Some(sum) = sums.position_sum.as_mut() {
                let shift = sums.shift;
                sum.add(offset, particles.len(), |r| {
                    let n = r.len() as f64;
                    position_sum(&particles[r]) - shift * n
                });
            }
        }
    }

    /// Adds one block's points of point node `index` (first pass only).
    pub(super) fn add_point(&mut self, index: usize, points: &[[f64; 3]], first_pass: bool) {
        if let (true, Some(Some(sums))) = (first_pass, self.points.get_mut(index)) {
            sums.add(points);
        }
    }

    /// Ends a pass over all samples: one Lie-mean step per node still iterating.
    pub(super) fn finish_pass(&mut self) {
        for sums in self.nodes.iter_mut().flatten() {
            sums.mean.finish_pass();
        }
    }

    /// Adds one block's particles of node `index` to the coverage counts of its estimates
    /// (the first pass only; the counts start with the first block).
    pub(super) fn add_consistency(
        &mut self,
        index: usize,
        estimates: &[Estimate<G, N>],
        particles: &[G],
        confidence: Confidence,
    ) where
        G: EvalGroup<N>,
    {
        let Some(Some(sums)) = self.nodes.get_mut(index) else {
            return;
        };
        if sums.consistency.is_none() {
            sums.consistency = ConsistencySums::new(estimates, confidence);
        }
        if let Some(c) = sums.consistency.as_mut() {
            c.add(particles);
        }
    }

    /// Writes node `index`'s coverage over every block into its estimates.
    pub(super) fn finish_consistency(&self, index: usize, estimates: &mut [Estimate<G, N>])
    where
        G: EvalGroup<N>,
    {
        if let Some(Some(NodeSums {
            consistency: Some(c),
            ..
        })) = self.nodes.get(index)
        {
            c.finish(estimates);
        }
    }

    /// Node `index`'s statistics over every block (`None` where it has no particles).
    pub(super) fn node(&self, index: usize) -> Option<Result<McSummary<G, N>, MeanError<G>>> {
        let sums = self.nodes.get(index)?.as_ref()?;
        let left = sums.left_outer.as_ref().map(BatchSums::mean_and_stderr);
        let position = sums.position_sum.as_ref().map(BatchSums::mean_and_stderr);
        Some(sums.mean.statistics().map(|stats| McSummary {
            stats,
            uncentred_left: left.map(|(mean, _)| mean),
            uncentred_left_stderr: left.and_then(|(_, se)| se),
            position_mean: position.map(|(mean, _)| sums.shift + mean),
            position_mean_stderr: position.and_then(|(_, se)| se),
        }))
    }

    /// Point node `index`'s mean and covariance over every block.
    pub(super) fn point(&self, index: usize) -> Option<(Vector3<f64>, Matrix3<f64>)> {
        self.points.get(index)?.as_ref().map(VectorSums::statistics)
    }
}
