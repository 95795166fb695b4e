//! What an evaluation produces: numbers only, for drawing and for `report --json`.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

use crate::lie::{GroupKind, LieGroup, Se2, Se3, So2, So3, TangentMatrix};
use crate::plan::OpKind;
use crate::propagate::{MatrixRows, Propagated, ResultRecord};
use crate::sample::SampleStatistics;
use crate::uncertain::Method;

use super::consistency::Consistency;
pub use super::findings::{FailureReason, Finding};

/// Where a node comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// A pose given with a covariance.
    Input,
    /// A known transform (no covariance).
    Fixed,
    /// The result of an operation.
    Output,
}

/// One method's estimate of a node, with its error against Monte Carlo and the coverage of
/// its regions where that ran.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate<G: LieGroup<N>, const N: usize> {
    /// Mean, covariance, side and method.
    pub result: Propagated<G, N>,
    /// ‖Σ − Σ_MC‖_F / ‖Σ_MC‖_F with both on the right side, where Monte Carlo ran.
    pub error_vs_monte_carlo: Option<f64>,
    /// How many Monte Carlo samples its regions hold, and their ANEES, where Monte Carlo ran
    /// ([`consistency`](super::consistency)).
    pub consistency: Option<Consistency>,
}

/// Monte Carlo statistics of a node beyond its Lie mean and covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McSummary<G: LieGroup<N>, const N: usize> {
    /// The Lie mean and centred 1/(N−1) covariance (right side).
    pub stats: SampleStatistics<G, N>,
    /// E\[ξξᵀ\] about the nominal pose, left (world) side, uncentred — Barfoot & Furgale's
    /// Monte Carlo covariance (2014, §IV), where the operation asks for it.
    pub uncentred_left: Option<TangentMatrix<N>>,
    /// The standard error of each entry of `uncentred_left`, by batch means
    /// ([`batch_means`](super::batch_means); `None` with fewer than two samples per batch).
    pub uncentred_left_stderr: Option<TangentMatrix<N>>,
    /// The Cartesian mean of the samples' positions, where the operation asks for it.
    pub position_mean: Option<Vector3<f64>>,
    /// The standard error of each coordinate of `position_mean`, by batch means.
    pub position_mean_stderr: Option<Vector3<f64>>,
}

/// The Monte Carlo statistics of one node as plain data, for `report --json` (keys stable).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonteCarloRecord {
    /// The node (`name`, or `name@step` in a propagation).
    pub label: String,
    /// Samples the statistics use.
    pub samples: usize,
    /// The nominal (noise-free) pose as a matrix, row-major rows.
    pub nominal_matrix: Vec<Vec<f64>>,
    /// The samples' iterative Lie mean as a matrix, row-major rows.
    pub lie_mean_matrix: Vec<Vec<f64>>,
    /// The Lie mean as a tangent vector Log(μ), in the conventions' order.
    pub lie_mean_tangent: Vec<f64>,
    /// The centred 1/(N−1) covariance about the Lie mean, right side (the `monte_carlo`
    /// estimate in `results`).
    pub covariance_right: Vec<Vec<f64>>,
    /// Barfoot & Furgale's uncentred E\[ξξᵀ\] about the nominal pose, left (world) side,
    /// ξ = Log(X μ̄⁻¹); `null` where the operation does not compute it.
    pub uncentred_about_nominal_left: Option<Vec<Vec<f64>>>,
    /// The same about the nominal pose on the right (body) side, ξ = Log(μ̄⁻¹ X) = Ad_μ̄⁻¹ ξ_left,
    /// hence Ad_μ̄⁻¹ E\[ξξᵀ\]_left Ad_μ̄⁻¹ᵀ; `null` with the left one.
    pub uncentred_about_nominal_right: Option<Vec<Vec<f64>>>,
    /// The Monte Carlo standard error of each entry of `uncentred_about_nominal_left`, by batch
    /// means over 20 consecutive batches of the sample; `null` where that is `null` or a batch
    /// has fewer than two samples.
    pub uncentred_about_nominal_left_stderr: Option<Vec<Vec<f64>>>,
    /// The Cartesian mean of the samples' positions (x, y, z), which a curved cloud pulls
    /// inside its banana; `null` where the operation does not compute it.
    pub cartesian_mean: Option<[f64; 3]>,
    /// The Monte Carlo standard error of each coordinate of `cartesian_mean`, by batch means;
    /// `null` where that is `null` or a batch has fewer than two samples.
    pub cartesian_mean_stderr: Option<[f64; 3]>,
}

/// A named pose at one step, with every method's estimate.
#[derive(Debug, Clone)]
pub struct Node<G: LieGroup<N>, const N: usize> {
    /// Pose name.
    pub name: String,
    /// Input, fixed or output.
    pub role: Role,
    /// The operation that produced it (`None` for the input's poses).
    pub op: Option<OpKind>,
    /// Step on the `step` timeline (propagations); `None` for single results.
    pub step: Option<u64>,
    /// The last step of this name's propagation (`None` for single results).
    pub last_step: Option<u64>,
    /// The nominal (noise-free) pose.
    pub nominal: G,
    /// One estimate per method that applies (Monte Carlo last, where it ran).
    pub estimates: Vec<Estimate<G, N>>,
    /// Monte Carlo statistics, where Monte Carlo ran.
    pub monte_carlo: Option<McSummary<G, N>>,
    /// Monte Carlo particles, kept for the input's nodes and the detailed steps of a
    /// propagation ([`StepPolicy`](crate::plan::StepPolicy)); shared with the operations that
    /// read them.
    pub particles: Option<Arc<Vec<G>>>,
}

/// An uncertain point (a landmark seen from an uncertain pose), in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct PointNode {
    /// Name.
    pub name: String,
    /// One estimate per method.
    pub estimates: Vec<PointEstimate>,
    /// Monte Carlo particles, world coordinates.
    pub particles: Option<Vec<[f64; 3]>>,
}

/// One method's estimate of an uncertain point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointEstimate {
    /// The method.
    pub method: Method,
    /// Mean, world coordinates.
    pub mean: Vector3<f64>,
    /// 3×3 covariance, world coordinates.
    pub cov: Matrix3<f64>,
}

/// What a path of poses shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathKind {
    /// The noise-free trajectory.
    Nominal,
    /// Sampled trajectory `k` (Monte Carlo).
    Sample(usize),
}

/// A polyline of poses (nominal trajectories, sampled trajectories) of an output.
#[derive(Debug, Clone)]
pub struct PosePath<G> {
    /// The output it belongs to.
    pub output: String,
    /// Nominal or sampled.
    pub kind: PathKind,
    /// The poses, in order.
    pub poses: Vec<G>,
}

/// A 3×3 matrix that need not be a rotation, per step: what Euler integration leaves of one.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixFrame {
    /// The output it belongs to.
    pub output: String,
    /// The node of the exponential map it is compared with, at the same step.
    pub exp_node: String,
    /// Step on the `step` timeline.
    pub step: u64,
    /// The matrix; column k is the image of axis k.
    pub columns: Matrix3<f64>,
    /// Its drift from a rotation, max |RᵀR − I| ([`orthogonality_error`]).
    pub orthogonality_error: f64,
    /// The same of the exponential map's rotation at this step.
    pub exp_orthogonality_error: f64,
}

/// What an evaluation ran with ([`AnyEvaluation::ran_with`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RanWith<'a> {
    /// Seed of every random draw.
    pub seed: u64,
    /// Monte Carlo samples.
    pub samples: usize,
    /// Particles per block.
    pub block_samples: usize,
    /// The methods compared.
    pub methods: &'a [Method],
}

/// One method's along-track variance at one step of a compounding
/// ([`Evaluation::along_track`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlongTrack {
    /// The compounding's output.
    pub output: String,
    /// Step on the `step` timeline.
    pub step: u64,
    /// The method.
    pub method: Method,
    /// Σ_ρxρx, left (world) form (m²).
    pub variance_m2: f64,
    /// Its Monte Carlo standard error by batch means (m²; Monte Carlo only, where a batch
    /// has two samples or more).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stderr_m2: Option<f64>,
}

/// How far a 3×3 matrix is from a rotation: max |RᵀR − I| over the entries.
///
/// ```
/// use nalgebra::Matrix3;
/// use posecov::eval::orthogonality_error;
/// assert_eq!(orthogonality_error(&Matrix3::identity()), 0.0);
/// assert!((orthogonality_error(&(Matrix3::identity() * 1.1)) - 0.21).abs() < 1e-12);
/// ```
pub fn orthogonality_error(m: &Matrix3<f64>) -> f64 {
    (m.transpose() * m - Matrix3::identity()).amax()
}

/// Everything a plan evaluates to, for one group: numbers, no drawing.
#[derive(Debug, Clone)]
pub struct Evaluation<G: LieGroup<N>, const N: usize> {
    /// The seed every random draw came from.
    pub seed: u64,
    /// Monte Carlo samples (0 when Monte Carlo was not requested).
    pub samples: usize,
    /// Particles simulated and held at once (= `samples` unless blocked).
    pub block_samples: usize,
    /// Methods compared.
    pub methods: Vec<Method>,
    /// The sigma-point parameters used.
    pub unscented: crate::propagate::sigma_point::Unscented,
    /// Every pose at every recorded step, in evaluation order.
    pub nodes: Vec<Node<G, N>>,
    /// Uncertain points.
    pub points: Vec<PointNode>,
    /// Polylines of poses.
    pub trajectories: Vec<PosePath<G>>,
    /// Non-orthonormal frames (Euler integration).
    pub matrix_frames: Vec<MatrixFrame>,
    /// What the user should know besides the estimates.
    pub findings: Vec<Finding>,
    /// A pose graph's optimisation and marginals (g2o / GTSAM inputs).
    pub graph: Option<super::graph::GraphEvaluation<G, N>>,
}

impl<G: LieGroup<N>, const N: usize> Evaluation<G, N> {
    /// Every method's along-track variance per step of each compounding (`compound`):
    /// Σ_ρxρx of the left (world) form, in m², the variance second-order compounding misses
    /// (Barfoot & Furgale 2014, Fig. 2). Monte Carlo's is the uncentred E\[ξξᵀ\] about the
    /// propagated mean, as in their experiments. Empty for rotations.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::Se3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert!(e.along_track().is_empty());
    /// ```
    pub fn along_track(&self) -> Vec<AlongTrack> {
        if G::KIND.is_rotation_only() {
            return Vec::new();
        }
        self.nodes
            .iter()
            .filter(|n| n.op == Some(OpKind::Compound) && n.role == Role::Output)
            .filter_map(|n| n.step.map(|step| (n, step)))
            .flat_map(|(n, step)| {
                let analytic = n
                    .estimates
                    .iter()
                    .filter(|e| e.result.method != Method::MonteCarlo)
                    .map(|e| (e.result.method, e.result.pose.cov_left()[(0, 0)], None));
                let monte_carlo = n.monte_carlo.as_ref().and_then(|mc| {
                    mc.uncentred_left.map(|c| {
                        let stderr = mc.uncentred_left_stderr.map(|s| s[(0, 0)]);
                        (Method::MonteCarlo, c[(0, 0)], stderr)
                    })
                });
                analytic
                    .chain(monte_carlo)
                    .map(move |(method, variance_m2, stderr_m2)| AlongTrack {
                        output: n.name.clone(),
                        step,
                        method,
                        variance_m2,
                        stderr_m2,
                    })
            })
            .collect()
    }
}

impl<G: LieGroup<N>, const N: usize> Evaluation<G, N>
where
    G::Matrix: MatrixRows,
{
    /// Every estimate as a plain record (label `name` or `name@step`).
    ///
    /// ```
    /// use posecov::input::scenario::{Scenario, lower};
    /// use posecov::eval::{EvalSettings, evaluate};
    /// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='se2'\nmethods=['first_order']\n[[pose]]\nname='a'\nmean={xy_theta=[1,2,0]}\ncov={std=[0.1,0.1,0.1]}\n", "t.toml").unwrap();
    /// let e = evaluate(&lower(&s).unwrap().plan, &EvalSettings::default()).unwrap();
    /// assert!(!e.records().is_empty());
    /// ```
    pub fn records(&self) -> Vec<ResultRecord> {
        self.nodes
            .iter()
            .flat_map(|node| {
                let label = match node.step {
                    Some(k) => format!("{}@{k}", node.name),
                    None => node.name.clone(),
                };
                node.estimates.iter().map(move |e| {
                    let record = ResultRecord::new(&label, &e.result, e.error_vs_monte_carlo);
                    match &e.consistency {
                        Some(c) => record.with_consistency(
                            c.coverage.clone(),
                            c.anees.map(|a| (a.value, a.dof, a.band)),
                        ),
                        None => record,
                    }
                })
            })
            .collect()
    }

    /// The Monte Carlo statistics of every node where Monte Carlo ran (labels as in
    /// [`records`](Self::records)).
    ///
    /// ```
    /// use posecov::app::{Overrides, load, pipeline};
    /// let loaded = load("barfoot_compounding").unwrap();
    /// let (e, _) = pipeline(&loaded, &Overrides { samples: Some(64), ..Default::default() }, None).unwrap();
    /// let mc = e.monte_carlo_records();
    /// assert!(mc.iter().any(|r| r.uncentred_about_nominal_right.is_some()));
    /// ```
    pub fn monte_carlo_records(&self) -> Vec<MonteCarloRecord> {
        self.nodes
            .iter()
            .filter_map(|node| {
                let mc = node.monte_carlo.as_ref()?;
                let label = match node.step {
                    Some(k) => format!("{}@{k}", node.name),
                    None => node.name.clone(),
                };
                let to_right = node.nominal.inverse().adj();
                Some(MonteCarloRecord {
                    label,
                    samples: mc.stats.count,
                    nominal_matrix: node.nominal.to_matrix().to_rows(),
                    lie_mean_matrix: mc.stats.mean.to_matrix().to_rows(),
                    lie_mean_tangent: mc.stats.mean.log().iter().copied().collect(),
                    covariance_right: mc.stats.cov.to_rows(),
                    uncentred_about_nominal_left: mc.uncentred_left.map(|c| c.to_rows()),
                    uncentred_about_nominal_right: mc
                        .uncentred_left
                        .map(|c| (to_right * c * to_right.transpose()).to_rows()),
                    uncentred_about_nominal_left_stderr: mc
                        .uncentred_left_stderr
                        .map(|c| c.to_rows()),
                    cartesian_mean: mc.position_mean.map(|p| [p.x, p.y, p.z]),
                    cartesian_mean_stderr: mc.position_mean_stderr.map(|p| [p.x, p.y, p.z]),
                })
            })
            .collect()
    }
}

/// An evaluation of any group.
#[derive(Debug, Clone)]
pub enum AnyEvaluation {
    /// SO(2).
    So2(Evaluation<So2, 1>),
    /// SE(2).
    Se2(Evaluation<Se2, 3>),
    /// SO(3).
    So3(Evaluation<So3, 3>),
    /// SE(3).
    Se3(Evaluation<Se3, 6>),
}

/// Calls `$body` with `$e` bound to the group-typed evaluation inside an [`AnyEvaluation`].
#[macro_export]
#[doc(hidden)]
macro_rules! with_evaluation {
    ($any:expr, $e:ident => $body:expr) => {
        match $any {
            $crate::eval::AnyEvaluation::So2($e) => $body,
            $crate::eval::AnyEvaluation::Se2($e) => $body,
            $crate::eval::AnyEvaluation::So3($e) => $body,
            $crate::eval::AnyEvaluation::Se3($e) => $body,
        }
    };
}

impl AnyEvaluation {
    /// The group.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, lie::GroupKind, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert_eq!(e.group(), GroupKind::So3);
    /// ```
    pub fn group(&self) -> GroupKind {
        match self {
            AnyEvaluation::So2(_) => GroupKind::So2,
            AnyEvaluation::Se2(_) => GroupKind::Se2,
            AnyEvaluation::So3(_) => GroupKind::So3,
            AnyEvaluation::Se3(_) => GroupKind::Se3,
        }
    }

    /// Every estimate as a plain record.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert!(e.records().is_empty());
    /// ```
    pub fn records(&self) -> Vec<ResultRecord> {
        with_evaluation!(self, e => e.records())
    }

    /// The Monte Carlo statistics of every node where Monte Carlo ran.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert!(e.monte_carlo_records().is_empty());
    /// ```
    pub fn monte_carlo_records(&self) -> Vec<MonteCarloRecord> {
        with_evaluation!(self, e => e.monte_carlo_records())
    }

    /// The coverage of the last output's estimates against Monte Carlo (empty where Monte
    /// Carlo did not run): what a one-line status shows.
    ///
    /// ```
    /// use posecov::app::{Overrides, load, pipeline};
    /// let loaded = load("camera_on_robot").unwrap();
    /// let (e, _) = pipeline(&loaded, &Overrides { samples: Some(256), ..Default::default() }, None).unwrap();
    /// let summary = e.coverage_summary();
    /// assert_eq!(summary[0].output, "map_from_camera");
    /// assert_eq!(summary[0].method, "exact"); // a change of frame by a known mount
    /// ```
    pub fn coverage_summary(&self) -> Vec<super::consistency::CoverageSummary> {
        with_evaluation!(self, e => super::consistency::last_output_summary(&e.nodes))
    }

    /// The methods this evaluation computed an operation's result with, or tried and reported
    /// failing ([`Finding::MethodFailed`]), in [`Method::ALL`]'s order. Evaluated with every
    /// method asked for, these are the methods that apply to the plan: the evaluation is the
    /// one rule of which method works on which operation (a closed form only for a
    /// differential drive, fourth order only for compounding, …).
    ///
    /// ```
    /// use posecov::app::{load, resolve, evaluate};
    /// use posecov::uncertain::Method;
    /// let loaded = load("camera_on_robot").unwrap();
    /// let mut settings = resolve(&loaded.input, &Default::default(), None).unwrap();
    /// settings.eval.methods = Method::ALL.to_vec();
    /// settings.eval.samples = 16;
    /// let methods = evaluate(&loaded, &settings.eval).unwrap().methods_that_ran();
    /// assert!(methods.contains(&Method::SigmaPoints));
    /// assert!(!methods.contains(&Method::ClosedForm), "{methods:?}");
    /// ```
    pub fn methods_that_ran(&self) -> Vec<Method> {
        let mut seen: Vec<Method> = with_evaluation!(self, e => e
            .nodes
            .iter()
            .filter(|n| n.op.is_some())
            .flat_map(|n| n.estimates.iter().map(|x| x.result.method))
            .collect());
        seen.extend(self.findings().iter().filter_map(|f| match f {
            Finding::MethodFailed { method, .. } => Some(*method),
            _ => None,
        }));
        Method::ALL
            .into_iter()
            .filter(|m| seen.contains(m))
            .collect()
    }

    /// [`Evaluation::along_track`] of any group.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert!(e.along_track().is_empty());
    /// ```
    pub fn along_track(&self) -> Vec<AlongTrack> {
        with_evaluation!(self, e => e.along_track())
    }

    /// The findings.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert!(e.findings().is_empty());
    /// ```
    pub fn findings(&self) -> &[Finding] {
        with_evaluation!(self, e => &e.findings)
    }

    /// A pose graph's optimisation as `report --json`'s `optimized` object (None for other
    /// inputs).
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert!(e.optimized().is_none());
    /// ```
    pub fn optimized(&self) -> Option<super::graph::OptimizedReport> {
        with_evaluation!(self, e => e.graph.as_ref().map(|g| g.report()))
    }

    /// What the evaluation ran with: seed, samples, block size, methods.
    ///
    /// ```
    /// use posecov::{eval::{EvalSettings, evaluate}, plan::{AnyPlan, Plan}};
    /// let e = evaluate(&AnyPlan::So3(Plan::default()), &EvalSettings::default()).unwrap();
    /// assert_eq!(e.ran_with().seed, 0);
    /// ```
    pub fn ran_with(&self) -> RanWith<'_> {
        with_evaluation!(self, e => RanWith {
            seed: e.seed,
            samples: e.samples,
            block_samples: e.block_samples,
            methods: e.methods.as_slice(),
        })
    }
}
