//! Facts an evaluation found that are not estimates (typed, numbers only): the text panel
//! words them (`draw/`), `report --json` writes them as they are.

use serde::Serialize;

use crate::uncertain::{Confidence, Method};

/// Why a method gave no estimate ([`Finding::MethodFailed`]); `report --json` writes it as
/// `{"kind": "not_finite"}` or `{"kind": "refused", "message": …}`, the text panel in words.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FailureReason {
    /// The result overflowed: a number not finite or beyond the overflow limits.
    NotFinite,
    /// The Monte Carlo sample statistics overflowed.
    StatisticsNotFinite,
    /// The vector-space baseline needs one noise covariance shared by every step.
    NeedsOneNoise,
    /// The method refused its inputs (a sigma-point spread, a singular matrix, …).
    Refused {
        /// The method's own message.
        message: String,
    },
}

/// A fact the evaluation found that is not an estimate: something to tell the user in the
/// text panel and in `report --json`. Failures that let the run finish are findings too;
/// nothing is swallowed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Finding {
    /// The Monte Carlo sample was simulated in blocks to bound memory.
    Blocked {
        /// Samples in all.
        samples: usize,
        /// Blocks.
        blocks: usize,
        /// Samples per block.
        block_samples: usize,
        /// Lie-mean passes over all blocks.
        passes: usize,
    },
    /// Gauss–Newton fusion result.
    Fusion {
        /// The output.
        output: String,
        /// How many estimates were fused.
        inputs: usize,
        /// Final cost V = ½ Σ eᵢᵀ Σᵢ⁻¹ eᵢ (Barfoot & Furgale 2014, §IV).
        cost: f64,
        /// Iterations.
        iterations: usize,
    },
    /// A differential drive's nominal end, the samples' Lie mean and their Cartesian mean.
    DiffDriveMeans {
        /// The output.
        output: String,
        /// Wheel noise intensity D.
        diffusion: f64,
        /// Nominal end (x, y).
        nominal_end: [f64; 2],
        /// Lie mean of the samples (x, y).
        lie_mean: [f64; 2],
        /// Cartesian mean of the samples' positions (x, y).
        cartesian_mean: [f64; 2],
        /// Its standard error by batch means (x, y; [`batch_means`](super::batch_means));
        /// absent with fewer than two samples per batch.
        #[serde(skip_serializing_if = "Option::is_none")]
        cartesian_mean_stderr: Option<[f64; 2]>,
    },
    /// Euler integration's drift off SO(3) against the exponential map's.
    EulerDrift {
        /// The output.
        output: String,
        /// Steps.
        steps: u64,
        /// dt (s).
        dt: f64,
        /// max |RᵀR − I| after Euler steps.
        euler: f64,
        /// max |RᵀR − I| after Exp steps.
        exp: f64,
    },
    /// A method could not produce an estimate for an output; the others stand.
    MethodFailed {
        /// The output.
        output: String,
        /// Step, for propagations.
        step: Option<u64>,
        /// The method.
        method: Method,
        /// Why.
        reason: FailureReason,
        /// How many later recorded steps of the same output failed the same way.
        later_steps: u64,
    },
    /// An estimate's covariance is not positive semi-definite (it is reported and drawn
    /// clamped to its PSD part, never hidden).
    NotPositiveSemiDefinite {
        /// The output.
        output: String,
        /// Step, for propagations.
        step: Option<u64>,
        /// The method.
        method: Method,
        /// Smallest eigenvalue (at `step`, the first such step).
        smallest_eigenvalue: f64,
        /// Largest eigenvalue (at `step`).
        largest_eigenvalue: f64,
        /// How many later recorded steps of the same output and method are indefinite too.
        later_steps: u64,
    },
    /// A sigma point of an operation's inputs turns further than π: Log wraps it to the other
    /// side, so the unscented estimate departs from first order even where the operation is
    /// linear in each input's tangent ([`JointInputs::wrap_around`](crate::propagate::sigma_point::JointInputs::wrap_around)).
    SigmaPointsWrap {
        /// The output.
        output: String,
        /// The largest rotation angle |θ| (rad) of any sigma point's tangent offset.
        largest_rotation_rad: f64,
        /// The α used.
        alpha: f64,
        /// Every α below this keeps all sigma points within π (α · π / largest rotation).
        alpha_below_pi: f64,
    },
    /// Recorded steps of a long propagation were thinned ([`StepPolicy`](crate::plan::StepPolicy)).
    StepsThinned {
        /// The output.
        output: String,
        /// Steps in all.
        steps: u64,
        /// Steps recorded.
        recorded: u64,
        /// Recorded steps with Monte Carlo statistics (all recorded ones without Monte Carlo).
        sampled: u64,
    },
    /// Ctrl-C stopped the evaluation: later operations or steps are missing.
    Interrupted,
    /// A pose graph's optimiser stopped without meeting its stop criteria: the iteration log,
    /// and the estimate kept (the last that lowered χ²).
    GraphNotConverged {
        /// Why it stopped.
        stop: super::graph::Stop,
        /// The optimiser.
        optimizer: super::graph::Optimizer,
        /// Accepted steps.
        iterations: usize,
        /// χ² of the initial guess.
        chi2_before: f64,
        /// χ² of the estimate kept.
        chi2_after: f64,
        /// Every step tried (the last 50).
        log: Vec<super::graph::Iteration>,
    },
    /// A loop closure whose residual after the optimisation lies outside its edge's own region
    /// at the confidence: d = √(rᵀ Λ r) beyond √χ²_N(confidence).
    LoopClosureOutlier {
        /// Vertex i.
        from: u64,
        /// Vertex j.
        to: u64,
        /// The edge's line.
        line: usize,
        /// d after the optimisation.
        mahalanobis: f64,
        /// d at the file's estimates.
        mahalanobis_before: f64,
        /// √χ²_N(confidence).
        radius: f64,
        /// The confidence.
        confidence: Confidence,
    },
    /// More loop-closure outliers than are listed one by one.
    MoreLoopClosureOutliers {
        /// Outliers not listed.
        more: usize,
        /// Outliers in all.
        outliers: usize,
        /// Loop closures in all.
        loop_closures: usize,
    },
    /// The graph falls into several unconnected parts (or has vertices no edge reaches): each
    /// is anchored on its own.
    GraphParts {
        /// Every part with its anchor.
        parts: Vec<super::graph::Part>,
    },
    /// Edges joining the same two vertices more than once: all kept and counted.
    DuplicateEdges {
        /// How many edges repeat an earlier pair.
        count: usize,
        /// (line, line of the first edge of the pair), the first 10.
        lines: Vec<(usize, usize)>,
    },
    /// The marginals could not be computed (the estimate stands).
    GraphMarginalsFailed {
        /// Why.
        reason: String,
    },
}

impl<G: crate::lie::LieGroup<N>, const N: usize> super::Node<G, N> {
    /// The methods whose Cartesian position ellipse is the vector-space one exactly: the same
    /// centre and first-order world position covariance R Σ_ρρ Rᵀ
    /// ([`position_cov_in_world_3d`](crate::uncertain::UncertainPose::position_cov_in_world_3d))
    /// to 1e-9 relative (to the largest entry of the vector-space matrix; centres to
    /// 1e-9 · (1 + |c|)). Drawn, one hides the other; the text panel says so. Empty without a
    /// vector-space estimate or without positions.
    ///
    /// ```
    /// use posecov::eval::{Estimate, Node, Role};
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::Propagated;
    /// use posecov::uncertain::{Method, Side, UncertainPose};
    /// let pose = UncertainPose::<Se2, 3>::try_from_std_devs(Se2::identity(), [0.1, 0.2, 0.05], Side::Right).unwrap();
    /// let estimate = |method, pose| Estimate { result: Propagated { pose, method }, error_vs_monte_carlo: None, consistency: None };
    /// let mut node = Node { name: "X".into(), role: Role::Output, op: None, step: None, last_step: None,
    ///     nominal: Se2::identity(), estimates: vec![estimate(Method::VectorSpace, pose), estimate(Method::FirstOrder, pose)],
    ///     monte_carlo: None, particles: None };
    /// assert_eq!(node.coinciding_ellipses(), vec![Method::FirstOrder]);
    /// node.estimates[1].result.pose = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.3, 0.05], Side::Right).unwrap();
    /// assert!(node.coinciding_ellipses().is_empty());
    /// ```
    pub fn coinciding_ellipses(&self) -> Vec<Method> {
        let ellipse = |method: Method| {
            let e = self.estimates.iter().find(|e| e.result.method == method)?;
            let cov = e.result.pose.position_cov_in_world_3d()?;
            let centre = e.result.pose.mean().to_se3().translation().to_owned();
            Some((centre, cov))
        };
        let Some((c0, m0)) = ellipse(Method::VectorSpace) else {
            return Vec::new();
        };
        let scale = m0.amax().max(f64::MIN_POSITIVE);
        self.estimates
            .iter()
            .map(|e| e.result.method)
            .filter(|m| *m != Method::VectorSpace)
            .filter(|m| {
                ellipse(*m).is_some_and(|(c, m)| {
                    (m - m0).amax() <= 1e-9 * scale
                        && (0..3).all(|k| (c[k] - c0[k]).abs() <= 1e-9 * (1.0 + c0[k].abs()))
                })
            })
            .collect()
    }
}
