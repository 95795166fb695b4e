//! Statistics of sample sets: the one Lie mean ([`LieMeanAccumulator`], streaming over
//! blocks), covariances about it or about a given mean, and NEES
//! ([CONVENTIONS §8](crate::conventions#8-sample-statistics)).

use std::fmt::{Debug, Display};

use rayon::prelude::*;

use super::{CHUNK_SIZE, LIE_MEAN_MAX_ITERATIONS, LIE_MEAN_TOLERANCE, retract, tangent_about};
use crate::error::{Error, Result};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::uncertain::{Side, UncertainPose, try_inverse_covariance};

/// Why a Lie mean failed. Generic over the group so that a non-converged iteration hands back
/// its last estimate as a typed value; converts into [`crate::Error`] (the estimate then
/// travels formatted in [`Error::NotConverged`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeanError<G: Debug + Display> {
    /// The input was invalid (e.g. [`Error::TooFewSamples`], mismatched weights).
    #[error(transparent)]
    Invalid(#[from] Error),
    /// The iteration did not reach [`LIE_MEAN_TOLERANCE`] within [`LIE_MEAN_MAX_ITERATIONS`].
    #[error(
        "Lie mean: no convergence after {iterations} iterations (last step {last_step:.3e} > {tolerance:.1e}); \
         last estimate {last_estimate}"
    )]
    NotConverged {
        /// Where the iteration stopped.
        last_estimate: G,
        /// Iterations run.
        iterations: usize,
        /// Norm of the last tangent update.
        last_step: f64,
        /// The threshold it was held to.
        tolerance: f64,
    },
}

impl<G: Debug + Display> From<MeanError<G>> for Error {
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::MeanError;
    /// let e: posecov::Error = MeanError::NotConverged { last_estimate: So2::identity(), iterations: 100, last_step: 1.0, tolerance: 1e-10 }.into();
    /// assert!(matches!(e, posecov::Error::NotConverged { iterations: 100, .. }));
    /// ```
    fn from(e: MeanError<G>) -> Self {
        match e {
            MeanError::Invalid(e) => e,
            MeanError::NotConverged {
                last_estimate,
                iterations,
                last_step,
                tolerance,
            } => Error::NotConverged {
                what: "Lie mean",
                iterations,
                last_step,
                tolerance,
                last_estimate: last_estimate.to_string(),
            },
        }
    }
}

/// A converged Lie mean with its iteration count and final step norm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LieMean<G> {
    /// The mean μ.
    pub mean: G,
    /// Iterations run (1 when the initial guess already satisfied the tolerance).
    pub iterations: usize,
    /// Norm of the last tangent update (< [`LIE_MEAN_TOLERANCE`]).
    pub last_step: f64,
}

fn check_count(what: &'static str, got: usize, needed: usize) -> Result<()> {
    if got < needed {
        return Err(Error::TooFewSamples { what, needed, got });
    }
    Ok(())
}

/// The first two tangent moments of `samples` about `about`, weighted:
/// (Σᵢ wᵢ ξᵢ, Σᵢ wᵢ ξᵢ ξᵢᵀ) with ξᵢ = Log(about⁻¹ Xᵢ) (right) or Log(Xᵢ about⁻¹) (left), one
/// Log per sample, summed in chunk order (deterministic whatever the thread count).
/// `weights = None` means wᵢ = 1. Summed over the blocks of a sample too large to hold, they
/// give one iteration of the Lie mean and the covariance about `about`
/// ([`LieMeanAccumulator`]).
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::tangent_moments;
/// use posecov::uncertain::Side;
/// let (sum, outer) = tangent_moments(&[So2::from_angle(0.1), So2::from_angle(0.3)], None, &So2::identity(), Side::Right);
/// assert!((sum[0] - 0.4).abs() < 1e-15 && (outer[(0, 0)] - 0.1).abs() < 1e-15);
/// ```
pub fn tangent_moments<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    weights: Option<&[f64]>,
    about: &G,
    side: Side,
) -> (Tangent<N>, TangentMatrix<N>) {
    moments::<G, N, true>(samples, weights, about, side)
}

/// [`tangent_moments`]; without the outer products when `OUTER` is false (the second moment
/// then zero, the sum the same, bit for bit).
fn moments<G: LieGroup<N>, const N: usize, const OUTER: bool>(
    samples: &[G],
    weights: Option<&[f64]>,
    about: &G,
    side: Side,
) -> (Tangent<N>, TangentMatrix<N>) {
    // about⁻¹ once, not once a sample: the same operations as `tangent_about`'s rminus
    // (about⁻¹ · X, then Log) and lminus (X · about⁻¹, then Log), so the same bits.
    let about_inverse = about.inverse();
    let chunk_sums: Vec<(Tangent<N>, TangentMatrix<N>)> = samples
        .par_chunks(CHUNK_SIZE)
        .enumerate()
        .map(|(c, chunk)| {
            let mut sum = Tangent::<N>::zeros();
            let mut outer = TangentMatrix::<N>::zeros();
            for (i, x) in chunk.iter().enumerate() {
                let w = weights.map_or(1.0, |w| w[c * CHUNK_SIZE + i]);
                let xi = match side {
                    Side::Right => about_inverse.compose(x).log(),
                    Side::Left => x.compose(&about_inverse).log(),
                };
                sum += xi * w;
                if OUTER {
                    outer.ger(w, &xi, &xi, 1.0);
                }
            }
            (sum, outer)
        })
        .collect();
    let (sum, outer) = chunk_sums.iter().fold(
        (Tangent::<N>::zeros(), TangentMatrix::<N>::zeros()),
        |(s, o), (cs, co)| (s + cs, o + co),
    );
    (sum, (outer + outer.transpose()) * 0.5)
}

/// How close to the tolerance the foreseen next step of a Lie mean must be for its pass to sum
/// the outer products Σ wᵢ ξᵢξᵢᵀ ([`LieMeanAccumulator`]): 100×.
const OUTER_WITHIN: f64 = 100.0;

/// Where a [`LieMeanAccumulator`] stands after a pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeanPass {
    /// Another pass over the data is needed.
    Continue,
    /// Converged: [`LieMeanAccumulator::statistics`] has the result.
    Converged,
    /// Failed (non-finite step, or no convergence within [`LIE_MEAN_MAX_ITERATIONS`]).
    Failed,
}

/// The iterative Lie mean and the covariance about it, over data seen in passes: the one Lie
/// mean of the crate. Each pass [`add`](Self::add)s every sample (in one call, or block by
/// block for a sample too large to hold), then [`finish_pass`](Self::finish_pass) takes one
/// step μ ← μ ⊕ s, s = Σ wᵢ ξᵢ / Σ wᵢ (right: μ Exp(s); left: Exp(s) μ), until
/// ‖s‖ < [`LIE_MEAN_TOLERANCE`] ([CONVENTIONS §8]). On convergence the
/// covariance is the converged pass's Σ wᵢ ξᵢξᵢᵀ − W s sᵀ, divided by W − 1 for equal weights
/// (the unbiased sample covariance) — the ξᵢ are about the last μ, within 1e-10 of the final
/// one. Only that pass needs Σ wᵢ ξᵢξᵢᵀ: it is summed on the first pass and on those whose
/// step, foreseen from the last two (linear convergence), is within 100× of the tolerance; a
/// pass that converges without it is run once more about the same μ with it (the same ξᵢ: the
/// same step and numbers, bit for bit; not counted as an iteration). A wide cloud's mean takes
/// tens of passes, most without the outer products.
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::{LieMeanAccumulator, MeanPass};
/// use posecov::uncertain::Side;
/// let pts = [So2::from_angle(0.1), So2::from_angle(0.3)];
/// let mut acc = LieMeanAccumulator::new(pts[0], Side::Right);
/// let mut pass = MeanPass::Continue;
/// while pass == MeanPass::Continue {
///     acc.add(&pts[..1], None); // block by block
///     acc.add(&pts[1..], None);
///     pass = acc.finish_pass();
/// }
/// let stats = acc.statistics().unwrap();
/// assert!((stats.mean.angle() - 0.2).abs() < 1e-12 && (stats.cov[(0, 0)] - 0.02).abs() < 1e-12);
/// ```
///
/// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
#[derive(Clone, Debug)]
pub struct LieMeanAccumulator<G: LieGroup<N>, const N: usize> {
    mean: G,
    side: Side,
    sum: Tangent<N>,
    outer: TangentMatrix<N>,
    weight: f64,
    count: usize,
    weighted: bool,
    iterations: usize,
    last_step: f64,
    /// The step before the last (to foresee the next).
    step_before: f64,
    /// Whether this pass sums the outer products (only the pass that converges needs them).
    with_outer: bool,
    state: MeanPass,
    cov: Option<TangentMatrix<N>>,
}

impl<G: LieGroup<N>, const N: usize> LieMeanAccumulator<G, N> {
    /// Starts the iteration at `initial`, tangents on `side`.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let acc = posecov::sample::LieMeanAccumulator::new(So2::identity(), posecov::uncertain::Side::Left);
    /// assert!(acc.is_iterating());
    /// ```
    pub fn new(initial: G, side: Side) -> Self {
        Self {
            mean: initial,
            side,
            sum: Tangent::<N>::zeros(),
            outer: TangentMatrix::<N>::zeros(),
            weight: 0.0,
            count: 0,
            weighted: false,
            iterations: 0,
            last_step: f64::INFINITY,
            step_before: f64::INFINITY,
            with_outer: true,
            state: MeanPass::Continue,
            cov: None,
        }
    }

    /// Whether more passes are needed.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let acc = posecov::sample::LieMeanAccumulator::new(So2::identity(), posecov::uncertain::Side::Right);
    /// assert!(acc.is_iterating());
    /// ```
    pub fn is_iterating(&self) -> bool {
        self.state == MeanPass::Continue
    }

    /// Adds samples (with weights, or 1 each) to the current pass; nothing once finished.
    /// Weights must have the samples' length (checked by the callers that take them).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let mut acc = posecov::sample::LieMeanAccumulator::new(So2::identity(), posecov::uncertain::Side::Right);
    /// acc.add(&[So2::from_angle(0.5)], Some(&[2.0]));
    /// ```
    pub fn add(&mut self, samples: &[G], weights: Option<&[f64]>) {
        if !self.is_iterating() {
            return;
        }
        let (sum, outer) = if self.with_outer {
            moments::<G, N, true>(samples, weights, &self.mean, self.side)
        } else {
            moments::<G, N, false>(samples, weights, &self.mean, self.side)
        };
        self.sum += sum;
        self.outer += outer;
        self.weight += weights.map_or(samples.len() as f64, |w| w.iter().sum());
        self.count += samples.len();
        self.weighted |= weights.is_some();
    }

    /// Ends a pass: one step of the mean, or convergence, or failure.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::{LieMeanAccumulator, MeanPass};
    /// let mut acc = LieMeanAccumulator::new(So2::identity(), posecov::uncertain::Side::Right);
    /// assert_eq!(acc.finish_pass(), MeanPass::Failed); // no samples
    /// ```
    pub fn finish_pass(&mut self) -> MeanPass {
        if !self.is_iterating() {
            return self.state;
        }
        let step = self.sum / self.weight;
        let norm = step.norm();
        let usable = norm.is_finite() && self.weight.is_finite() && self.weight != 0.0;
        if usable && norm < LIE_MEAN_TOLERANCE && !self.with_outer {
            // Converged on a pass without the outer products: the same pass again about the
            // same μ with them (the same ξᵢ, so the same step, bit for bit); not an iteration.
            self.with_outer = true;
            self.clear_pass();
            return self.state;
        }
        self.iterations += 1;
        self.step_before = self.last_step;
        self.last_step = norm;
        if !usable {
            self.state = MeanPass::Failed;
        } else if self.last_step < LIE_MEAN_TOLERANCE {
            let centred = self.outer - step * step.transpose() * self.weight;
            let divisor = if self.weighted {
                1.0
            } else {
                self.weight - 1.0
            };
            self.cov = Some((centred + centred.transpose()) * (0.5 / divisor));
            self.state = MeanPass::Converged;
        } else if self.iterations >= LIE_MEAN_MAX_ITERATIONS {
            self.state = MeanPass::Failed;
        }
        if self.last_step.is_finite() {
            self.mean = retract(&self.mean, &step, self.side);
        }
        if self.is_iterating() {
            self.clear_pass();
            // The iteration converges linearly: the next step is foreseen as the last times
            // their ratio, and the outer products summed once it may be within 100× of the
            // tolerance (a pass that converges sooner is run again with them, above).
            let ratio = if self.step_before.is_finite() {
                (self.last_step / self.step_before).min(1.0)
            } else {
                1.0
            };
            self.with_outer = self.last_step * ratio < OUTER_WITHIN * LIE_MEAN_TOLERANCE;
        }
        self.state
    }

    /// Empties the sums for the next pass.
    fn clear_pass(&mut self) {
        self.sum = Tangent::<N>::zeros();
        self.outer = TangentMatrix::<N>::zeros();
        self.weight = 0.0;
        self.count = 0;
    }

    /// The converged mean, or why there is none ([`MeanError::NotConverged`] with the last
    /// estimate).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let acc = posecov::sample::LieMeanAccumulator::new(So2::identity(), posecov::uncertain::Side::Right);
    /// assert!(acc.mean().is_err()); // no pass finished
    /// ```
    pub fn mean(&self) -> Result<LieMean<G>, MeanError<G>> {
        match self.state {
            MeanPass::Converged => Ok(LieMean {
                mean: self.mean,
                iterations: self.iterations,
                last_step: self.last_step,
            }),
            _ => Err(MeanError::NotConverged {
                last_estimate: self.mean,
                iterations: self.iterations,
                last_step: self.last_step,
                tolerance: LIE_MEAN_TOLERANCE,
            }),
        }
    }

    /// The Lie mean and the covariance about it (1/(N−1) for equal weights, Σ wᵢ ξᵢξᵢᵀ for
    /// weights), once converged.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let acc = posecov::sample::LieMeanAccumulator::new(So2::identity(), posecov::uncertain::Side::Right);
    /// assert!(acc.statistics().is_err());
    /// ```
    pub fn statistics(&self) -> Result<SampleStatistics<G, N>, MeanError<G>> {
        let mean = self.mean()?;
        Ok(SampleStatistics {
            mean: mean.mean,
            cov: self.cov.unwrap_or_else(TangentMatrix::<N>::zeros),
            side: self.side,
            count: self.count,
            iterations: mean.iterations,
        })
    }
}

/// The Lie (Fréchet / Karcher) mean of weighted points from the initial guess `initial`:
/// μ ← μ · Exp(Σ wᵢ Log(μ⁻¹ Xᵢ) / Σ wᵢ) (right), μ ← Exp(Σ wᵢ Log(Xᵢ μ⁻¹) / Σ wᵢ) · μ (left),
/// until ‖step‖ < [`LIE_MEAN_TOLERANCE`] ([CONVENTIONS §8]; unscented weights may be negative
/// as long as their sum is not 0). `weights = None` means equal weights.
///
/// Errors: [`Error::TooFewSamples`] for no points, [`Error::WrongLength`] for a weight vector
/// of the wrong length, [`Error::OutOfRange`] for a zero or non-finite weight sum,
/// [`MeanError::NotConverged`] (with the last estimate) after [`LIE_MEAN_MAX_ITERATIONS`].
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::weighted_lie_mean;
/// use posecov::uncertain::Side;
/// let pts = [So2::from_angle(0.1), So2::from_angle(0.4)];
/// let m = weighted_lie_mean(&pts, Some(&[2.0, 1.0]), &pts[0], Side::Right).unwrap();
/// assert!((m.mean.angle() - 0.2).abs() < 1e-12);
/// ```
///
/// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
pub fn weighted_lie_mean<G: LieGroup<N>, const N: usize>(
    points: &[G],
    weights: Option<&[f64]>,
    initial: &G,
    side: Side,
) -> Result<LieMean<G>, MeanError<G>> {
    check_count("Lie mean", points.len(), 1)?;
    let total = match weights {
        None => points.len() as f64,
        Some(w) if w.len() != points.len() => {
            return Err(Error::WrongLength {
                what: "Lie mean weights",
                expected: points.len(),
                got: w.len(),
            }
            .into());
        }
        Some(w) => w.iter().sum(),
    };
    if !(total.is_finite() && total != 0.0) {
        return Err(Error::OutOfRange {
            what: "sum of Lie mean weights",
            value: total,
            expected: "a finite, non-zero sum",
        }
        .into());
    }
    let mut acc = LieMeanAccumulator::new(*initial, side);
    while acc.is_iterating() {
        acc.add(points, weights);
        acc.finish_pass();
    }
    acc.mean()
}

/// The iterative Lie mean of samples ([CONVENTIONS §8]), starting from the first sample; see
/// [`weighted_lie_mean`] for the iteration, the errors and the left-side form.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::sample::{MeanError, lie_mean};
/// use posecov::uncertain::Side;
/// let pts = [Se2::from_xy_theta(0.0, 0.0, 0.2), Se2::from_xy_theta(0.0, 0.0, -0.2)];
/// assert!(lie_mean(&pts, Side::Right).unwrap().mean.theta().abs() < 1e-12);
/// assert!(matches!(lie_mean::<Se2, 3>(&[], Side::Right), Err(MeanError::Invalid(_))));
/// ```
///
/// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
pub fn lie_mean<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    side: Side,
) -> Result<LieMean<G>, MeanError<G>> {
    let first = samples.first().ok_or(Error::TooFewSamples {
        what: "Lie mean",
        needed: 1,
        got: 0,
    })?;
    weighted_lie_mean(samples, None, first, side)
}

/// Weighted second moment Σᵢ wᵢ ξᵢ ξᵢᵀ about `mean` on `side` (ξ from [`tangent_about`]); the
/// unscented transform's covariance with its weights W⁽ᶜ⁾ (Julier & Uhlmann 2004, eq. 12).
/// Errors: [`Error::WrongLength`] when the lengths differ, [`Error::TooFewSamples`] for none.
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::weighted_covariance;
/// use posecov::uncertain::Side;
/// let pts = [So2::from_angle(0.1), So2::from_angle(-0.1)];
/// let c = weighted_covariance(&pts, &[0.5, 0.5], &So2::identity(), Side::Right).unwrap();
/// assert!((c[(0, 0)] - 0.01).abs() < 1e-15);
/// ```
pub fn weighted_covariance<G: LieGroup<N>, const N: usize>(
    points: &[G],
    weights: &[f64],
    mean: &G,
    side: Side,
) -> Result<TangentMatrix<N>> {
    check_count("weighted covariance", points.len(), 1)?;
    if weights.len() != points.len() {
        return Err(Error::WrongLength {
            what: "covariance weights",
            expected: points.len(),
            got: weights.len(),
        });
    }
    Ok(tangent_moments(points, Some(weights), mean, side).1)
}

/// The uncentred covariance E\[ξξᵀ\] ≈ 1/N Σ ξᵢ ξᵢᵀ of samples about a *given* mean (e.g. the
/// propagated nominal pose), as in Barfoot & Furgale 2014's Monte Carlo comparisons (§IV-A,
/// Fig. 2). Right: ξ = Log(μ⁻¹ X); left: ξ = Log(X μ⁻¹). Errors: [`Error::TooFewSamples`] for
/// an empty set.
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::uncentred_covariance;
/// use posecov::uncertain::Side;
/// let pts = [So2::from_angle(0.3), So2::from_angle(0.1)];
/// let c = uncentred_covariance(&pts, &So2::identity(), Side::Right).unwrap();
/// assert!((c[(0, 0)] - 0.05).abs() < 1e-15); // (0.09 + 0.01) / 2, not about the mean 0.2
/// ```
pub fn uncentred_covariance<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    about: &G,
    side: Side,
) -> Result<TangentMatrix<N>> {
    check_count("uncentred covariance", samples.len(), 1)?;
    Ok(tangent_moments(samples, None, about, side).1 / samples.len() as f64)
}

/// The centred sample covariance 1/(N−1) Σ ξᵢ ξᵢᵀ about the sample's own Lie mean `mean`
/// (ROB 530; pass the result of [`lie_mean`]). Right: ξ = Log(μ⁻¹ X); left: ξ = Log(X μ⁻¹).
/// At the Lie mean Σ ξᵢ = 0, so this is the unbiased covariance of the ξᵢ. Errors:
/// [`Error::TooFewSamples`] for fewer than 2 samples.
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::centred_covariance;
/// use posecov::uncertain::Side;
/// let pts = [So2::from_angle(0.3), So2::from_angle(0.1)];
/// let c = centred_covariance(&pts, &So2::from_angle(0.2), Side::Right).unwrap();
/// assert!((c[(0, 0)] - 0.02).abs() < 1e-15); // (0.01 + 0.01) / (2 − 1)
/// ```
pub fn centred_covariance<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    mean: &G,
    side: Side,
) -> Result<TangentMatrix<N>> {
    check_count("centred covariance", samples.len(), 2)?;
    Ok(tangent_moments(samples, None, mean, side).1 / (samples.len() - 1) as f64)
}

/// Sample statistics: the Lie mean and the centred 1/(N−1) covariance about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleStatistics<G: LieGroup<N>, const N: usize> {
    /// The iterative Lie mean.
    pub mean: G,
    /// The centred covariance about it, on `side`.
    pub cov: TangentMatrix<N>,
    /// The side of the tangents (and of the mean iteration).
    pub side: Side,
    /// Number of samples.
    pub count: usize,
    /// Lie mean iterations.
    pub iterations: usize,
}

impl<G: LieGroup<N>, const N: usize> SampleStatistics<G, N> {
    /// As an uncertain pose (μ, Σ, side).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::sample_statistics;
    /// use posecov::uncertain::Side;
    /// let s = sample_statistics(&[So2::from_angle(0.1), So2::from_angle(0.3)], Side::Right).unwrap();
    /// assert!((s.to_pose().cov()[(0, 0)] - 0.02).abs() < 1e-15);
    /// ```
    pub fn to_pose(&self) -> UncertainPose<G, N> {
        UncertainPose::new_unchecked(self.mean, self.cov, self.side)
    }
}

/// The Lie mean ([`lie_mean`]) and centred covariance ([`centred_covariance`]) of samples,
/// on `side` ([CONVENTIONS §8]). Errors: [`Error::TooFewSamples`] below 2 samples,
/// [`MeanError::NotConverged`].
///
/// ```
/// use posecov::lie::{LieGroup, So3};
/// use posecov::sample::sample_statistics;
/// use posecov::uncertain::Side;
/// assert!(sample_statistics(&[So3::identity()], Side::Left).is_err()); // one sample
/// ```
///
/// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
pub fn sample_statistics<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    side: Side,
) -> Result<SampleStatistics<G, N>, MeanError<G>> {
    check_count("sample statistics", samples.len(), 2)?;
    let mut acc = LieMeanAccumulator::new(samples[0], side);
    while acc.is_iterating() {
        acc.add(samples, None);
        acc.finish_pass();
    }
    acc.statistics()
}

/// Normalised estimation error squared of samples against a claimed distribution.
#[derive(Clone, Debug, PartialEq)]
pub struct Nees {
    /// εᵢᵀ Σ⁻¹ εᵢ per sample.
    pub values: Vec<f64>,
    /// Their average; ≈ `dof` when the claimed Σ is consistent with the samples.
    pub mean: f64,
    /// Degrees of freedom N of the group.
    pub dof: usize,
}

/// NEES of each sample against `claimed` (Bar-Shalom, Li & Kirubarajan 2001, §5.4.2):
/// NEESᵢ = εᵢᵀ Σ⁻¹ εᵢ with εᵢ = Log(μ⁻¹ Xᵢ) (right) or Log(Xᵢ μ⁻¹) (left). For a consistent Σ
/// the mean NEES is ≈ N (χ²_N), with standard error √(2N / count). Errors:
/// [`Error::TooFewSamples`] for none, [`Error::SingularCovariance`] when Σ is singular.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::sample::{Sampler, nees};
/// use posecov::uncertain::{Side, UncertainPose};
/// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.2, 0.05], Side::Right).unwrap();
/// let samples = Sampler::new(&p).unwrap().draw_par(20_000, 3);
/// let n = nees(&samples, &p).unwrap();
/// assert!((n.mean - 3.0).abs() < 5.0 * (6.0f64 / 20_000.0).sqrt());
/// ```
pub fn nees<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    claimed: &UncertainPose<G, N>,
) -> Result<Nees> {
    check_count("NEES", samples.len(), 1)?;
    let info = try_inverse_covariance("claimed covariance", claimed.cov())?;
    let (mean, side) = (claimed.mean(), claimed.side());
    let values: Vec<f64> = samples
        .par_iter()
        .map(|x| {
            let eps = tangent_about(x, mean, side);
            eps.dot(&(info * eps))
        })
        .collect();
    // Sequential sum: deterministic whatever the thread count.
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    Ok(Nees {
        values,
        mean,
        dof: N,
    })
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};

    use super::*;
    use crate::lie::Se3;

    /// CONVENTIONS §8 as written: every pass sums Σ ξᵢ and Σ ξᵢξᵢᵀ (in two blocks, split at
    /// a third), the step from the first, the covariance from the pass that converges (about
    /// the μ before its step; the mean returned is after it).
    fn reference(samples: &[Se3], initial: Se3) -> (Se3, TangentMatrix<6>, usize) {
        let mut mean = initial;
        let (a, b) = samples.split_at(samples.len() / 3);
        for iteration in 1..=LIE_MEAN_MAX_ITERATIONS {
            let (sa, oa) = tangent_moments(a, None, &mean, Side::Right);
            let (sb, ob) = tangent_moments(b, None, &mean, Side::Right);
            let (sum, outer) = (
                Tangent::<6>::zeros() + sa + sb,
                TangentMatrix::<6>::zeros() + oa + ob,
            );
            let w = samples.len() as f64;
            let step = sum / w;
            if step.norm() < LIE_MEAN_TOLERANCE {
                let centred = outer - step * step.transpose() * w;
                let cov = (centred + centred.transpose()) * (0.5 / (w - 1.0));
                return (retract(&mean, &step, Side::Right), cov, iteration);
            }
            mean = retract(&mean, &step, Side::Right);
        }
        panic!("the reference did not converge");
    }

    fn cloud(rotation_sigma: f64, n: usize, seed: u64) -> Vec<Se3> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let centre = Se3::exp(&Tangent::<6>::from_fn(|i, _| 0.3 * i as f64 - 0.7));
        (0..n)
            .map(|_| {
                let xi = Tangent::<6>::from_fn(|i, _| {
                    let s = if i < 3 { 2.0 } else { rotation_sigma };
                    s * (rng.random::<f64>() * 2.0 - 1.0)
                });
                centre.compose(&Se3::exp(&xi))
            })
            .collect()
    }

    #[test]
    fn the_outer_products_of_the_converging_pass_alone_give_the_same_bits() {
        // Wide (tens of passes, most without the outer products), narrow (a few, fast
        // convergence: the converging pass may be run again) and a cloud of one pose repeated
        // (converged on the first pass).
        let one = Se3::exp(&Tangent::<6>::from_fn(|i, _| 0.1 * i as f64));
        let mut seen = Vec::new();
        for (samples, start) in [
            (cloud(1.6, 2000, 1), 0),
            (cloud(0.9, 500, 2), 7),
            (cloud(1e-3, 300, 3), 0),
            (cloud(1e-6, 300, 4), 5),
            (vec![one; 50], 0),
        ] {
            let (mean, cov, passes) = reference(&samples, samples[start]);
            let mut acc = LieMeanAccumulator::new(samples[start], Side::Right);
            let mut runs = 0;
            while acc.is_iterating() {
                acc.add(&samples[..samples.len() / 3], None);
                acc.add(&samples[samples.len() / 3..], None);
                acc.finish_pass();
                runs += 1;
            }
            let stats = acc.statistics().expect("converged");
            assert_eq!(stats.mean, mean);
            assert_eq!(stats.cov, cov);
            assert_eq!(stats.iterations, passes);
            // At most one pass more than the iterations (the converging one, again).
            assert!(
                runs == passes || runs == passes + 1,
                "{runs} runs, {passes} passes"
            );
            seen.push((passes, runs));
        }
        // Both ways to converge were taken: with the outer products foreseen, and again.
        assert!(seen.iter().any(|(p, r)| r == p), "{seen:?}");
        assert!(seen.iter().any(|(p, r)| *r == p + 1), "{seen:?}");
        assert!(seen.iter().any(|(p, _)| *p >= 10), "{seen:?}");
    }
}
