//! A graph evaluation as plain records for `report --json` (`optimized`).

use crate::lie::{LieGroup, TangentMatrix};
use crate::uncertain::Confidence;

use super::{GraphEvaluation, GraphReading, Iteration, Joint, Optimizer, Part, PoseSigma, Stop};

/// One optimised pose.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PoseRecord {
    /// The vertex id.
    pub id: u64,
    /// As g2o writes it: [x, y, θ] (2-D) or [x, y, z, qx, qy, qz, qw] (3-D).
    pub pose: Vec<f64>,
    /// The marginal covariance, posecov's right form [ρ; θ], row by row (`null`: held fixed,
    /// isolated, or no marginals).
    pub covariance: Option<Vec<Vec<f64>>>,
    /// σ of the marginal `covariance`: `position` √tr Σ_ρρ (m), `rotation` √tr Σ_θθ (rad;
    /// a 2-D pose's heading σ) ([`PoseSigma`]; `null` with `covariance`).
    pub sigma: Option<PoseSigma>,
    /// The same σ before the loop closures: of the pose's dead-reckoning marginal, the graph
    /// without its loop closures optimised ([`GraphEvaluation::dead_reckoning`]).
    pub sigma_before: Option<PoseSigma>,
}

/// One loop closure.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LoopClosureRecord {
    /// Vertex i.
    pub from: u64,
    /// Vertex j.
    pub to: u64,
    /// The edge's line.
    pub line: usize,
    /// r = Log(Z⁻¹ X_i⁻¹ X_j) at the optimised poses, [ρ; θ].
    pub residual: Vec<f64>,
    /// d = √(rᵀ Λ r) at the optimised poses.
    pub mahalanobis: f64,
    /// r at the file's estimates.
    pub residual_before: Vec<f64>,
    /// d at the file's estimates.
    pub mahalanobis_before: f64,
    /// √χ²_N(confidence).
    pub radius: f64,
    /// d > radius.
    pub outlier: bool,
    /// The covariance of X_i⁻¹ X_j from the joint marginal of the two poses (right form).
    pub relative_covariance: Option<Vec<Vec<f64>>>,
}

/// The joint marginal of two poses (`--joint a,b`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct JointRecord {
    /// Vertex a.
    pub a: u64,
    /// Vertex b.
    pub b: u64,
    /// The 2N×2N covariance over [δ_a; δ_b] (right form, [ρ; θ] each), row by row: the blocks
    /// Σ_aa, Σ_ab / Σ_ba, Σ_bb of H⁻¹ (`null`: a vertex nothing reaches, or no marginals).
    pub covariance: Option<Vec<Vec<f64>>>,
    /// X_a⁻¹ X_b at the optimised poses, as g2o writes a pose.
    pub relative_pose: Vec<f64>,
    /// Its right-form covariance to first order (`null` across unconnected parts).
    pub relative_covariance: Option<Vec<Vec<f64>>>,
}

/// One step of the loop-closure timeline.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TimelineRecord {
    /// k: loop closures in the graph (the first k in file order).
    pub closures: usize,
    /// χ² at the step's optimum.
    pub chi2: f64,
    /// Why its optimiser stopped.
    pub stop: Stop,
}

/// `report --json`'s `optimized` object.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OptimizedReport {
    /// `levenberg_marquardt` or `gauss_newton`.
    pub optimizer: Optimizer,
    /// How the information matrices were read (`g2o` or `gtsam`).
    pub reading: GraphReading,
    /// Accepted steps.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: Stop,
    /// Whether a stop criterion was met.
    pub converged: bool,
    /// χ² = Σ rᵀ Λ r over the edges and priors at the file's estimates (GTSAM's `error()`
    /// is half of it).
    pub chi2_before: f64,
    /// χ² at the optimised poses.
    pub chi2_after: f64,
    /// The stop criteria: relative and absolute decrease of χ²/2, most iterations.
    pub stop_criteria: StopCriteria,
    /// Every step tried.
    pub log: Vec<Iteration>,
    /// The connected parts and their anchors.
    pub parts: Vec<Part>,
    /// Every vertex, optimised, with its marginal.
    pub poses: Vec<PoseRecord>,
    /// Every loop closure.
    pub loop_closures: Vec<LoopClosureRecord>,
    /// The joint marginals asked for (`--joint a,b`), in order.
    pub joints: Vec<JointRecord>,
    /// The graph re-solved as its loop closures are added one by one (empty without loop
    /// closures, or beyond the timeline's size).
    pub timeline: Vec<TimelineRecord>,
    /// The confidence of `radius`.
    pub confidence: Confidence,
    /// χ² of each edge at the optimised poses, in file order.
    pub edge_chi2: Vec<f64>,
    /// Scalar unknowns.
    pub unknowns: usize,
    /// Non-zeros of the sparse Cholesky factor.
    pub factor_nonzeros: usize,
    /// Seconds to optimise and to compute every marginal.
    pub seconds: Seconds,
}

/// The stop criteria used.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct StopCriteria {
    /// Relative decrease of χ²/2.
    pub relative: f64,
    /// Absolute decrease of χ²/2.
    pub absolute: f64,
    /// Most iterations.
    pub max_iterations: usize,
}

/// Timings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Seconds {
    /// The optimisation.
    pub optimize: f64,
    /// Every pose's marginal.
    pub marginals: f64,
}

fn rows<const N: usize>(m: &TangentMatrix<N>) -> Vec<Vec<f64>> {
    (0..N)
        .map(|r| (0..N).map(|c| m[(r, c)]).collect())
        .collect()
}

/// [[Σ_aa, Σ_ab], [Σ_abᵀ, Σ_bb]] row by row.
fn joint_rows<const N: usize>(j: &Joint<N>) -> Vec<Vec<f64>> {
    let [aa, ab, bb] = j;
    (0..2 * N)
        .map(|r| {
            (0..2 * N)
                .map(|c| match (r < N, c < N) {
                    (true, true) => aa[(r, c)],
                    (true, false) => ab[(r, c - N)],
                    (false, true) => ab[(c, r - N)],
                    (false, false) => bb[(r - N, c - N)],
                })
                .collect()
        })
        .collect()
}

/// A pose as g2o writes it.
fn g2o_values<G: LieGroup<N>, const N: usize>(x: &G) -> Vec<f64> {
    let se3 = x.to_se3();
    let t = se3.translation();
    if G::KIND.is_planar() {
        let r = se3.rotation().to_euler_zyx();
        vec![t.x, t.y, r[0]]
    } else {
        let q = se3.rotation().to_quaternion_xyzw();
        vec![t.x, t.y, t.z, q[0], q[1], q[2], q[3]]
    }
}

impl<G: LieGroup<N>, const N: usize> GraphEvaluation<G, N> {
    /// The plain records of `report --json`'s `optimized` object.
    pub fn report(&self) -> OptimizedReport {
        let s = &self.solution;
        let defaults = super::SolverSettings::default();
        OptimizedReport {
            optimizer: s.optimizer,
            reading: s.reading,
            iterations: s.iterations,
            stop: s.stop,
            converged: s.converged(),
            chi2_before: s.chi2_before,
            chi2_after: s.chi2_after,
            stop_criteria: StopCriteria {
                relative: defaults.relative_tolerance,
                absolute: defaults.absolute_tolerance,
                max_iterations: defaults.max_iterations,
            },
            log: s.log.clone(),
            parts: s.parts.clone(),
            poses: self
                .ids
                .iter()
                .zip(&s.poses)
                .zip(&s.covariances)
                .zip(self.sigmas())
                .map(|(((&id, x), cov), sigma)| PoseRecord {
                    id,
                    pose: g2o_values(x),
                    covariance: cov.as_ref().map(rows),
                    sigma: sigma.after,
                    sigma_before: sigma.before,
                })
                .collect(),
            loop_closures: self
                .loop_closures
                .iter()
                .map(|l| LoopClosureRecord {
                    from: l.from,
                    to: l.to,
                    line: l.line,
                    residual: l.residual.iter().copied().collect(),
                    mahalanobis: l.mahalanobis,
                    residual_before: l.residual_before.iter().copied().collect(),
                    mahalanobis_before: l.mahalanobis_before,
                    radius: self.radius,
                    outlier: l.mahalanobis > self.radius,
                    relative_covariance: l.relative_cov.as_ref().map(rows),
                })
                .collect(),
            joints: self
                .joints
                .iter()
                .map(|j| JointRecord {
                    a: j.a,
                    b: j.b,
                    covariance: j.blocks.as_ref().map(joint_rows),
                    relative_pose: g2o_values(&j.relative_pose),
                    relative_covariance: j.relative_cov.as_ref().map(rows),
                })
                .collect(),
            timeline: self
                .timeline
                .steps
                .iter()
                .map(|t| TimelineRecord {
                    closures: t.closures,
                    chi2: t.chi2,
                    stop: t.stop,
                })
                .collect(),
            confidence: self.confidence,
            edge_chi2: self.edge_chi2.clone(),
            unknowns: s.unknowns,
            factor_nonzeros: s.factor_nonzeros,
            seconds: Seconds {
                optimize: s.optimize_seconds,
                marginals: s.marginals_seconds,
            },
        }
    }
}
