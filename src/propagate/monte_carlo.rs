//! Monte Carlo propagation: sample the inputs, push every sample through the exact operation,
//! and summarise the outputs on the manifold (CONVENTIONS §8). The truth every other method is
//! judged by.
//!
//! # What is computed
//! - Inputs are drawn with [`Sampler`] (X = μ · Exp(L z) or Exp(L z) · μ) in parallel, with the
//!   [seeding scheme](crate::sample#seeding-scheme-identical-results-whatever-the-thread-count)
//!   of [`crate::sample`]: results are identical for a given seed whatever the thread count.
//! - The summary is either [`Centring::LieMean`] — the iterative Lie mean (started at the
//!   nominal output) and the centred 1/(N−1) covariance about it (ROB 530) — or
//!   [`Centring::Nominal`] — the uncentred E\[ξξᵀ\] about the nominal (noise-free) output, as in
//!   Barfoot & Furgale 2014's Monte Carlo comparisons (§III-A, Fig. 2).
//! - Covariances are on [`MonteCarlo::side`] (right / body by default).
//!
//! ```
//! use posecov::lie::{LieGroup, Se2};
//! use posecov::propagate::monte_carlo::{MonteCarlo, compose};
//! use posecov::uncertain::{Method, Side, UncertainPose};
//! let a = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 0.0, 0.0), [0.05, 0.05, 0.1], Side::Right).unwrap();
//! let mc = compose(&a, &a, &MonteCarlo::new(20_000, 1)).unwrap();
//! assert_eq!(mc.propagated.method, Method::MonteCarlo);
//! assert!(mc.propagated.pose.mean().is_approx(&Se2::from_xy_theta(2.0, 0.0, 0.0), 0.02));
//! ```

use crate::error::{Error, Result};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::propagate::Propagated;
use crate::sample::{
    Sampler, centred_covariance, covariance_square_root, fill_par, standard_normal,
    uncentred_covariance, weighted_lie_mean,
};
use crate::uncertain::{Method, Side, UncertainPose, validate_covariance};

/// Where the Monte Carlo covariance is centred.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Centring {
    /// The iterative Lie mean of the outputs and 1/(N−1) Σ ξᵢξᵢᵀ about it (ROB 530).
    #[default]
    LieMean,
    /// The nominal (noise-free) output and the uncentred 1/N Σ ξᵢξᵢᵀ about it, E\[ξξᵀ\]
    /// (Barfoot & Furgale 2014); the reported mean is the nominal output.
    Nominal,
}

/// Monte Carlo settings: sample count, seed, side and centring of the summary, and how many
/// output samples to hand back for drawing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MonteCarlo {
    /// Number of samples N (≥ 2).
    pub samples: usize,
    /// Seed of every random draw.
    pub seed: u64,
    /// Side of the output covariance (default right / body).
    pub side: Side,
    /// Where the covariance is centred (default the Lie mean).
    pub centring: Centring,
    /// How many output samples (the first ones) to return for drawing (default 0).
    pub keep_samples: usize,
}

impl MonteCarlo {
    /// N samples from `seed`; right side, Lie-mean centring, no samples kept.
    ///
    /// ```
    /// use posecov::propagate::monte_carlo::{Centring, MonteCarlo};
    /// let mc = MonteCarlo::new(1000, 3);
    /// assert_eq!((mc.samples, mc.seed, mc.centring), (1000, 3, Centring::LieMean));
    /// ```
    pub fn new(samples: usize, seed: u64) -> Self {
        Self {
            samples,
            seed,
            side: Side::Right,
            centring: Centring::LieMean,
            keep_samples: 0,
        }
    }

    /// The same settings with the output covariance on `side`.
    ///
    /// ```
    /// use posecov::propagate::monte_carlo::MonteCarlo;
    /// use posecov::uncertain::Side;
    /// assert_eq!(MonteCarlo::new(10, 0).with_side(Side::Left).side, Side::Left);
    /// ```
    pub fn with_side(self, side: Side) -> Self {
        Self { side, ..self }
    }

    /// The same settings with another [`Centring`].
    ///
    /// ```
    /// use posecov::propagate::monte_carlo::{Centring, MonteCarlo};
    /// assert_eq!(MonteCarlo::new(10, 0).with_centring(Centring::Nominal).centring, Centring::Nominal);
    /// ```
    pub fn with_centring(self, centring: Centring) -> Self {
        Self { centring, ..self }
    }

    /// The same settings, returning the first `keep` output samples (for drawing clouds).
    ///
    /// ```
    /// use posecov::propagate::monte_carlo::MonteCarlo;
    /// assert_eq!(MonteCarlo::new(10, 0).keeping(5).keep_samples, 5);
    /// ```
    pub fn keeping(self, keep: usize) -> Self {
        Self {
            keep_samples: keep,
            ..self
        }
    }

    /// Checks N ≥ 2 ([`Error::OutOfRange`] otherwise).
    ///
    /// ```
    /// use posecov::propagate::monte_carlo::MonteCarlo;
    /// assert!(MonteCarlo::new(1, 0).validate().is_err());
    /// assert!(MonteCarlo::new(2, 0).validate().is_ok());
    /// ```
    pub fn validate(&self) -> Result<()> {
        if self.samples < 2 {
            return Err(Error::OutOfRange {
                what: "Monte Carlo sample count",
                value: self.samples as f64,
                expected: "at least 2 samples (the covariance divides by N − 1)",
            });
        }
        Ok(())
    }
}

/// A Monte Carlo result: the summary as a [`Propagated`] (method [`Method::MonteCarlo`]),
/// the nominal output, the kept samples and the Lie mean's iteration count.
#[derive(Clone, Debug, PartialEq)]
pub struct MonteCarloOutput<G: LieGroup<N>, const N: usize> {
    /// Mean and covariance (see [`Centring`]), method `MonteCarlo`.
    pub propagated: Propagated<G, N>,
    /// The noise-free output (the operation applied to the input means).
    pub nominal: G,
    /// The first [`MonteCarlo::keep_samples`] output samples.
    pub samples: Vec<G>,
    /// Lie mean iterations (0 for [`Centring::Nominal`]).
    pub iterations: usize,
}

/// Summarises output samples according to `mc` (see [`Centring`]).
fn summarise<G: LieGroup<N>, const N: usize>(
    samples: &[G],
    nominal: G,
    mc: &MonteCarlo,
) -> Result<MonteCarloOutput<G, N>> {
    let (mean, cov, iterations) = match mc.centring {
        Centring::LieMean => {
            let mean = weighted_lie_mean(samples, None, &nominal, mc.side)?;
            let cov = centred_covariance(samples, &mean.mean, mc.side)?;
            (mean.mean, cov, mean.iterations)
        }
        Centring::Nominal => (
            nominal,
            uncentred_covariance(samples, &nominal, mc.side)?,
            0,
        ),
    };
    Ok(MonteCarloOutput {
        propagated: Propagated {
            pose: UncertainPose::new_unchecked(mean, cov, mc.side),
            method: Method::MonteCarlo,
        },
        nominal,
        samples: samples.iter().take(mc.keep_samples).copied().collect(),
        iterations,
    })
}

/// Monte Carlo through any map Y = f(X₁, …, X_k) of independent uncertain inputs (one group):
/// each sample draws every input once (in input order, from random family 0) and evaluates
/// `f`; the nominal output is f(μ₁, …, μ_k). The output group may differ from the inputs'.
///
/// Errors: [`Error::OutOfRange`] for N < 2, [`Error::TooFewSamples`] for no inputs, a
/// non-finite input covariance, a non-converging Lie mean ([`Error::NotConverged`]).
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::monte_carlo::{MonteCarlo, map};
/// use posecov::uncertain::{Side, UncertainPose};
/// let x = UncertainPose::try_from_std_devs(Se3::from_xyz_rpy([1.0, 2.0, 0.0], [0.0, 0.0, 0.5]), [0.1; 6], Side::Right).unwrap();
/// // The inverse: Σ_right(X⁻¹) ≈ Ad_μ Σ Ad_μᵀ.
/// let inv = map(&[x], |v: &[Se3]| v[0].inverse(), &MonteCarlo::new(4000, 9)).unwrap();
/// assert!(inv.nominal.is_approx(&x.mean().inverse(), 1e-15));
/// ```
pub fn map<G, const N: usize, H, const M: usize, F>(
    inputs: &[UncertainPose<G, N>],
    f: F,
    mc: &MonteCarlo,
) -> Result<MonteCarloOutput<H, M>>
where
    G: LieGroup<N>,
    H: LieGroup<M>,
    F: Fn(&[G]) -> H + Sync,
{
    mc.validate()?;
    if inputs.is_empty() {
        return Err(Error::TooFewSamples {
            what: "Monte Carlo inputs",
            needed: 1,
            got: 0,
        });
    }
    let samplers = inputs
        .iter()
        .map(Sampler::new)
        .collect::<Result<Vec<_>>>()?;
    let means: Vec<G> = inputs.iter().map(|p| *p.mean()).collect();
    let nominal = f(&means);
    let mut outputs = vec![nominal; mc.samples];
    fill_par(&mut outputs, mc.seed, 0, |rng, chunk| {
        let mut drawn = means.clone(); // one buffer per chunk, reused for every sample
        for y in chunk {
            for (x, sampler) in drawn.iter_mut().zip(&samplers) {
                *x = sampler.draw(rng);
            }
            *y = f(&drawn);
        }
    });
    summarise(&outputs, nominal, mc)
}

/// Monte Carlo of the composition Z = X · Y of independent uncertain poses (the reference for
/// first-order Σ_Z = Ad_{μY⁻¹} Σ_X Ad_{μY⁻¹}ᵀ + Σ_Y and for 2nd / 4th-order compounding). See
/// [`map`].
///
/// ```
/// use posecov::lie::{LieGroup, So3};
/// use posecov::propagate::monte_carlo::{MonteCarlo, compose};
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(So3::identity(), [0.05; 3], Side::Right).unwrap();
/// let z = compose(&a, &a, &MonteCarlo::new(20_000, 2)).unwrap();
/// // Two independent small rotations: variances add.
/// assert!((z.propagated.pose.cov()[(0, 0)] / 0.005 - 1.0).abs() < 0.05);
/// ```
pub fn compose<G: LieGroup<N>, const N: usize>(
    a: &UncertainPose<G, N>,
    b: &UncertainPose<G, N>,
    mc: &MonteCarlo,
) -> Result<MonteCarloOutput<G, N>> {
    map(&[*a, *b], |x: &[G]| x[0].compose(&x[1]), mc)
}

/// Runs N particles from `start` through `steps` noisy transitions and summarises every step.
/// Particles are drawn from random family 0; step k's noise from family k + 1. Entry 0 of the
/// result summarises the start samples.
fn odometry_run<G, const N: usize, S>(
    start: &UncertainPose<G, N>,
    steps: usize,
    noise: &TangentMatrix<N>,
    mc: &MonteCarlo,
    step: S,
) -> Result<Vec<MonteCarloOutput<G, N>>>
where
    G: LieGroup<N>,
    S: Fn(&G, usize, &Tangent<N>) -> G + Sync,
{
    mc.validate()?;
    let noise_root =
        covariance_square_root(&validate_covariance("odometry noise covariance", noise)?)?;
    let mut particles = Sampler::new(start)?.draw_par(mc.samples, mc.seed);
    let mut nominal = *start.mean();
    let mut results = Vec::with_capacity(steps + 1);
    results.push(summarise(&particles, nominal, mc)?);
    for k in 0..steps {
        nominal = step(&nominal, k, &Tangent::<N>::zeros());
        fill_par(&mut particles, mc.seed, k as u64 + 1, |rng, chunk| {
            for x in chunk {
                *x = step(x, k, &(noise_root * standard_normal::<N, _>(rng)));
            }
        });
        results.push(summarise(&particles, nominal, mc)?);
    }
    Ok(results)
}

/// Monte Carlo of the odometry model X_{k+1} = X_k · U_k · Exp(w_k), w_k ~ N(0, Σ_w)
/// (NA 568; first order: Σ_{k+1} = Ad_{U_k⁻¹} Σ_k Ad_{U_k⁻¹}ᵀ + Σ_w), from the uncertain
/// `start`. Returns `increments.len() + 1` results: entry 0 summarises the start samples,
/// entry k the poses after U_{k−1} (index by index with
/// [`odometry::propagate_increments`](super::odometry::propagate_increments)).
///
/// Errors: as [`map`], plus an invalid Σ_w (non-symmetric, non-PSD, non-finite).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::monte_carlo::{MonteCarlo, odometry_increments};
/// use posecov::uncertain::UncertainPose;
/// use nalgebra::{Matrix3, Vector3};
/// let u = Se2::from_xy_theta(0.6, 0.0, 0.1);
/// let noise = Matrix3::from_diagonal(&Vector3::new(0.03f64.powi(2), 0.03f64.powi(2), 0.01));
/// let steps = odometry_increments(&UncertainPose::certain(Se2::identity()), &[u, u], &noise, &MonteCarlo::new(5000, 1)).unwrap();
/// assert_eq!(steps.len(), 3); // the start, then one per increment
/// assert!((steps[1].propagated.pose.cov()[(2, 2)] / 0.01 - 1.0).abs() < 0.1);
/// ```
pub fn odometry_increments<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    increments: &[G],
    noise: &TangentMatrix<N>,
    mc: &MonteCarlo,
) -> Result<Vec<MonteCarloOutput<G, N>>> {
    odometry_run(start, increments.len(), noise, mc, |x, k, w| {
        x.compose(&increments[k]).rplus(w)
    })
}

/// Monte Carlo of the odometry model with the noise inside the exponential,
/// X_{k+1} = X_k · Exp(u_k + w_k), w_k ~ N(0, Σ_w) (ROB 530 SE(3); first order:
/// Σ_{k+1} = Ad_{Exp(−u_k)} Σ_k Ad_{Exp(−u_k)}ᵀ + Jr(u_k) Σ_w Jr(u_k)ᵀ). Returns
/// `inputs.len() + 1` results, entry 0 the start (as
/// [`odometry::propagate_tangent_inputs`](super::odometry::propagate_tangent_inputs)).
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::monte_carlo::{MonteCarlo, odometry_tangent_inputs};
/// use posecov::uncertain::UncertainPose;
/// use nalgebra::{Matrix6, Vector6};
/// let u = Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.2);
/// let steps = odometry_tangent_inputs(&UncertainPose::certain(Se3::identity()), &[u], &(Matrix6::identity() * 1e-4), &MonteCarlo::new(2000, 5)).unwrap();
/// assert!(steps[1].nominal.is_approx(&Se3::exp(&u), 1e-14));
/// ```
pub fn odometry_tangent_inputs<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    inputs: &[Tangent<N>],
    noise: &TangentMatrix<N>,
    mc: &MonteCarlo,
) -> Result<Vec<MonteCarloOutput<G, N>>> {
    odometry_run(start, inputs.len(), noise, mc, |x, k, w| {
        x.rplus(&(inputs[k] + w))
    })
}
