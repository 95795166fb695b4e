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
