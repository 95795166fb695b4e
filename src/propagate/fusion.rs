//! Fusion of N independent estimates of one pose by iterated Gauss–Newton in the tangent
//! space (Barfoot & Furgale 2014, "Associating uncertainty with three-dimensional poses for
//! use in estimation problems", IEEE T-RO 30(3), §IV "Fusing poses"; here in the right form).
//!
//! Estimates (μ_i, Σ_i) describe X = μ_i Exp(e_i), e_i ~ N(0, Σ_i) (left-form inputs are
//! converted). The fused pose minimises
//!
//! J(X) = Σ_i e_iᵀ Σ_i⁻¹ e_i,  e_i = X ⊖ μ_i = Log(μ_i⁻¹ X).
//!
//! With X ← X Exp(δ), e_i ≈ e_i + Jr⁻¹(e_i) δ (Solà et al. 2018 eq. 180a), so each step solves
//! (Σ_i J_iᵀ Σ_i⁻¹ J_i) δ = −Σ_i J_iᵀ Σ_i⁻¹ e_i with J_i = Jr⁻¹(e_i), until ‖δ‖ <
//! tolerance. The fused covariance is the inverse of that information matrix at the optimum
//! (right form, first order — the Laplace approximation).

use thiserror::Error;

use crate::error::Error;
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::uncertain::{Method, Side, UncertainPose, try_inverse_covariance};

use super::Propagated;

/// When the Gauss–Newton iteration stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FusionOptions {
    /// Iteration cap ([CONVENTIONS §8]: 100).
    ///
    /// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
    pub max_iterations: usize,
    /// Converged when the step norm ‖δ‖ falls below this ([CONVENTIONS §8]: 1e-10).
    ///
    /// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
    pub tolerance: f64,
}

impl Default for FusionOptions {
    /// 100 iterations, ‖δ‖ < 1e-10.
    fn default() -> Self {
        Self {
            max_iterations: 100,
            tolerance: 1e-10,
        }
    }
}

/// The fused estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fused<G: LieGroup<N>, const N: usize> {
    /// Mean and covariance (right form), [`Method::FirstOrder`].
    pub result: Propagated<G, N>,
    /// J at the returned mean, Σ_i e_iᵀ Σ_i⁻¹ e_i (no ½; χ² with N·(n − 1) degrees of freedom
    /// when the estimates are consistent).
    pub cost: f64,
    /// Gauss–Newton iterations run.
    pub iterations: usize,
}

/// Why [`fuse`] failed.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum FusionError<G: LieGroup<N>, const N: usize> {
    /// Bad input as a whole: no estimates, or invalid options.
    #[error(transparent)]
    Input(Error),
    /// Estimate `index` cannot be used (its covariance is singular, …).
    #[error("estimate {index}: {source}")]
    Estimate {
        /// Position of the estimate in the input slice.
        index: usize,
        /// What is wrong with it.
        source: Error,
    },
    /// The information matrix at an iterate is singular.
    #[error("fused information matrix: {0}")]
    Information(Error),
    /// No convergence within the cap; `last` is where the iteration stopped.
    #[error("{source}")]
    NotConverged {
        /// [`Error::NotConverged`] with the numbers.
        source: Error,
        /// The last estimate (mean, covariance, cost).
        last: Box<Fused<G, N>>,
    },
}

/// Fuses independent estimates of one pose (see the [module docs](self)), starting from the
/// first estimate's mean. Errors: no estimates ([`Error::TooFewSamples`]), invalid options,
/// a singular Σ_i ([`Error::SingularCovariance`], with its index), no convergence
/// ([`FusionError::NotConverged`], carrying the last estimate).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::fusion::{fuse, FusionOptions};
/// use posecov::uncertain::{Side, UncertainPose};
/// let a = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 0.0, 0.1), [0.1; 3], Side::Right).unwrap();
/// let fused = fuse(&[a, a], FusionOptions::default()).unwrap();
/// assert!((fused.result.pose.cov() - a.cov() / 2.0).norm() < 1e-12);
/// assert!(fused.cost < 1e-20);
/// ```
pub fn fuse<G: LieGroup<N>, const N: usize>(
    estimates: &[UncertainPose<G, N>],
    options: FusionOptions,
) -> Result<Fused<G, N>, FusionError<G, N>> {
    check_options(&options).map_err(FusionError::Input)?;
    let first = estimates
        .first()
        .ok_or(FusionError::Input(Error::TooFewSamples {
            what: "pose fusion",
            needed: 1,
            got: 0,
        }))?;
    let terms = estimates
        .iter()
        .enumerate()
        .map(|(index, e)| {
            try_inverse_covariance("estimate covariance", &e.cov_right())
                .map(|info| (*e.mean(), info))
                .map_err(|source| FusionError::Estimate { index, source })
        })
        .collect::<Result<Vec<_>, _>>()?;

    let mut mean = *first.mean();
    let mut last_step = f64::INFINITY;
    for iteration in 1..=options.max_iterations {
        let (information, gradient, _) = normal_equations(&terms, &mean);
        let cov = try_inverse_covariance("fused information", &information)
            .map_err(FusionError::Information)?;
        let step: Tangent<N> = -(cov * gradient);
        mean = mean.rplus(&step);
        last_step = step.norm();
        if last_step < options.tolerance {
            return finish(&terms, mean, iteration);
        }
    }
    let last = finish(&terms, mean, options.max_iterations)?;
    Err(FusionError::NotConverged {
        source: Error::NotConverged {
            what: "pose fusion (Gauss–Newton)",
            iterations: options.max_iterations,
            last_step,
            tolerance: options.tolerance,
            last_estimate: last.result.pose.mean().to_string(),
        },
        last: Box::new(last),
    })
}

fn check_options(options: &FusionOptions) -> Result<(), Error> {
    if options.max_iterations == 0 {
        return Err(Error::OutOfRange {
            what: "fusion max_iterations",
            value: 0.0,
            expected: "at least 1",
        });
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(Error::OutOfRange {
            what: "fusion tolerance",
            value: options.tolerance,
            expected: "a finite tolerance > 0",
        });
    }
    Ok(())
}

/// (H, g, J) at `mean`: H = Σ J_iᵀ W_i J_i, g = Σ J_iᵀ W_i e_i, J = Σ e_iᵀ W_i e_i.
fn normal_equations<G: LieGroup<N>, const N: usize>(
    terms: &[(G, TangentMatrix<N>)],
    mean: &G,
) -> (TangentMatrix<N>, Tangent<N>, f64) {
    let mut information = TangentMatrix::<N>::zeros();
    let mut gradient = Tangent::<N>::zeros();
    let mut cost = 0.0;
    for (mu, weight) in terms {
        let e = mean.rminus(mu);
        let j = G::jr_inv(&e);
        information += j.transpose() * weight * j;
        gradient += j.transpose() * (weight * e);
        cost += (e.transpose() * weight * e)[(0, 0)];
    }
    (
        (information + information.transpose()) * 0.5,
        gradient,
        cost,
    )
}

fn finish<G: LieGroup<N>, const N: usize>(
    terms: &[(G, TangentMatrix<N>)],
    mean: G,
    iterations: usize,
) -> Result<Fused<G, N>, FusionError<G, N>> {
    let (information, _, cost) = normal_equations(terms, &mean);
    let cov = try_inverse_covariance("fused information", &information)
        .map_err(FusionError::Information)?;
    Ok(Fused {
        result: Propagated {
            pose: UncertainPose::new_unchecked(mean, cov, Side::Right),
            method: Method::FirstOrder,
        },
        cost,
        iterations,
    })
}
