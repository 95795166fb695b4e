//! Odometry: first-order covariance recursions along a chain of noisy motions
//! ([CONVENTIONS §5]), on either side.
//!
//! Two motion models:
//! - [`propagate_increments`]: X_{k+1} = X_k · U_k · Exp(w_k), w_k ~ N(0, Σ_w) (the NA 568 /
//!   ROB 530 SE(2) model, U_k a known increment);
//! - [`propagate_tangent_inputs`]: X_{k+1} = X_k · Exp(u_k + w_k) (the ROB 530 SE(3) script),
//!   with the noise entering through Jr(u_k) — or, labelled [`Method::LectureNoJr`], without
//!   it as in the script.
//!
//! Each returns the whole trajectory, one [`Propagated`] per pose, the start included
//! (entry 0 is the start unchanged). The covariance side is the start's: right form
//! Σ_{k+1} = Ad_{U_k⁻¹} Σ_k Ad_{U_k⁻¹}ᵀ + Q_k, left form Σ_{k+1} = Σ_k + Ad_{X_{k+1}} Q_k
//! Ad_{X_{k+1}}ᵀ, Q_k the body-frame noise at X_{k+1}. The two agree exactly after conversion
//! ([REFERENCE_CASES R3]): Ad_{X_{k+1}} Ad_{U_k⁻¹} = Ad_{X_k}.
//!
//! [CONVENTIONS §5]: crate::conventions#5-first-order-propagation
//! [REFERENCE_CASES R3]: crate::reference_cases#r3-right-form-against-left-form

use serde::{Deserialize, Serialize};

use crate::error::{Result, check_finite};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::uncertain::{Method, Side, UncertainPose, validate_covariance};

use super::Propagated;

/// How the noise of a tangent input u_k + w_k enters the covariance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InputNoise {
    /// Exp(u + w) ≈ Exp(u) Exp(Jr(u) w) (Solà et al. 2018 eq. 143): Q = Jr(u) Σ_w Jr(u)ᵀ.
    /// The correct first order; [`Method::FirstOrder`].
    RightJacobian,
    /// Q = Σ_w, as in the ROB 530 SE(3) script: 16–25 % low against Monte Carlo for large
    /// rotational inputs ([REFERENCE_CASES R4]). [`Method::LectureNoJr`].
    ///
    /// [REFERENCE_CASES R4]: crate::reference_cases#r4-se3-odometry-noise-inside-exp-rob-530
    LectureNoJr,
}

/// The noise covariance of each odometry step: one Σ_w for every step, or one per step (a
/// pose graph's odometry edges each carry their own).
///
/// ```
/// use posecov::propagate::odometry::StepNoise;
/// use nalgebra::Matrix3;
/// let each = StepNoise::PerStep(vec![Matrix3::identity(), Matrix3::identity() * 2.0]);
/// assert_eq!(each.at(1)[(0, 0)], 2.0);
/// assert_eq!(StepNoise::Same(Matrix3::<f64>::identity()).at(7)[(0, 0)], 1.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum StepNoise<const N: usize> {
    /// The same Σ_w at every step.
    Same(TangentMatrix<N>),
    /// Σ_w of step k at index k (one per step).
    PerStep(Vec<TangentMatrix<N>>),
}

impl<const N: usize> StepNoise<N> {
    /// Σ_w of step `k` (the last one given beyond the end; zero if none is).
    pub fn at(&self, k: usize) -> TangentMatrix<N> {
        match self {
            StepNoise::Same(m) => *m,
            StepNoise::PerStep(v) => v
                .get(k)
                .or(v.last())
                .copied()
                .unwrap_or_else(TangentMatrix::<N>::zeros),
        }
    }

    /// The covariances given: one for every step, or one per step.
    ///
    /// ```
    /// use posecov::propagate::odometry::StepNoise;
    /// assert_eq!(StepNoise::Same(nalgebra::Matrix3::<f64>::identity()).as_slice().len(), 1);
    /// ```
    pub fn as_slice(&self) -> &[TangentMatrix<N>] {
        match self {
            StepNoise::Same(m) => std::slice::from_ref(m),
            StepNoise::PerStep(v) => v,
        }
    }

    /// Each covariance checked (finite, symmetric, PSD) and symmetrised; a per-step list
    /// must have one per step. Errors: the first bad covariance's, or the count.
    ///
    /// ```
    /// use posecov::propagate::odometry::StepNoise;
    /// use nalgebra::Matrix3;
    /// let bad = StepNoise::PerStep(vec![Matrix3::identity(), -Matrix3::identity()]);
    /// assert!(bad.validated(2).unwrap_err().to_string().contains("not positive semi-definite"));
    /// assert!(StepNoise::PerStep(vec![Matrix3::<f64>::identity()]).validated(2).is_err());
    /// ```
    pub fn validated(&self, steps: usize) -> Result<Self> {
        const WHAT: &str = "odometry noise covariance Σ_w";
        match self {
            StepNoise::Same(m) => Ok(StepNoise::Same(validate_covariance(WHAT, m)?)),
            StepNoise::PerStep(v) if v.len() != steps => Err(crate::Error::WrongLength {
                what: "odometry noise covariances Σ_w (one per step)",
                expected: steps,
                got: v.len(),
            }),
            StepNoise::PerStep(v) => v
                .iter()
                .map(|m| validate_covariance(WHAT, m))
                .collect::<Result<Vec<_>>>()
                .map(StepNoise::PerStep),
        }
    }
}

/// X_{k+1} = X_k · U_k · Exp(w_k), w_k ~ N(0, Σ_w) with Σ_w in the body frame at X_{k+1}
/// (NA 568): right form Σ_{k+1} = Ad_{U_k⁻¹} Σ_k Ad_{U_k⁻¹}ᵀ + Σ_w, left form
/// Σ_{k+1} = Σ_k + Ad_{X_{k+1}} Σ_w Ad_{X_{k+1}}ᵀ. First order (Exp(Ad ε) Exp(w) ≈ Exp(Ad ε + w)).
/// Returns `increments.len() + 1` results on the side of `start`. Errors: Σ_w not finite,
/// asymmetric or not PSD.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::odometry::propagate_increments;
/// use posecov::uncertain::UncertainPose;
/// use nalgebra::Matrix3;
/// let cov_w = Matrix3::from_diagonal(&nalgebra::Vector3::new(0.03f64.powi(2), 0.03f64.powi(2), 0.01));
/// let step = Se2::from_xy_theta(0.6, 0.043333, 0.072096);
/// let path = propagate_increments(&UncertainPose::certain(Se2::identity()), &[step, step], &cov_w).unwrap();
/// assert_eq!(path.len(), 3);
/// assert!((path[1].pose.cov() - cov_w).norm() < 1e-15);
/// ```
pub fn propagate_increments<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    increments: &[G],
    cov_noise: &TangentMatrix<N>,
) -> Result<Vec<Propagated<G, N>>> {
    propagate_increments_each(start, increments, &StepNoise::Same(*cov_noise))
}

/// [`propagate_increments`] with Σ_w given per step ([`StepNoise`]): X_{k+1} = X_k · U_k ·
/// Exp(w_k), w_k ~ N(0, Σ_{w,k}) — a pose graph's odometry chain, Σ_{w,k} the covariance of
/// edge k (k, k+1) in the body frame of vertex k+1 ([CONVENTIONS §10]).
///
/// [CONVENTIONS §10]: crate::conventions#10-pose-graphs-g2o-and-gtsam
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::odometry::{StepNoise, propagate_increments_each};
/// use posecov::uncertain::UncertainPose;
/// use nalgebra::Matrix3;
/// let (a, b) = (Matrix3::identity() * 0.01, Matrix3::identity() * 0.04);
/// let step = Se2::from_xy_theta(1.0, 0.0, 0.0);
/// let path = propagate_increments_each(&UncertainPose::certain(Se2::identity()), &[step, step], &StepNoise::PerStep(vec![a, b])).unwrap();
/// assert!((path[1].pose.cov() - a).norm() < 1e-15);
/// let ad = step.inverse().adj();
/// assert!((path[2].pose.cov() - (ad * a * ad.transpose() + b)).norm() < 1e-15);
/// ```
pub fn propagate_increments_each<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    increments: &[G],
    noise: &StepNoise<N>,
) -> Result<Vec<Propagated<G, N>>> {
    let noise = noise.validated(increments.len())?;
    Ok(recursion(
        start,
        increments
            .iter()
            .enumerate()
            .map(|(k, u)| (*u, noise.at(k))),
        Method::FirstOrder,
    ))
}

/// X_{k+1} = X_k · Exp(u_k + w_k), w_k ~ N(0, Σ_w), u_k a body-frame tangent (ROB 530 SE(3)
/// odometry): with U_k = Exp(u_k), right form Σ_{k+1} = Ad_{Exp(−u_k)} Σ_k Ad_{Exp(−u_k)}ᵀ + Q_k,
/// left form Σ_{k+1} = Σ_k + Ad_{X_{k+1}} Q_k Ad_{X_{k+1}}ᵀ, with Q_k = Jr(u_k) Σ_w Jr(u_k)ᵀ
/// ([`InputNoise::RightJacobian`], Solà et al. 2018 eq. 143) or Σ_w
/// ([`InputNoise::LectureNoJr`]). Errors: a non-finite input (with its index in the
/// flattened inputs), Σ_w invalid.
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::propagate::odometry::{propagate_tangent_inputs, InputNoise};
/// use posecov::uncertain::{Method, UncertainPose};
/// use nalgebra::{Matrix6, Vector6};
/// let u = Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
/// let cov_w = Matrix6::identity() * 1e-4;
/// let start = UncertainPose::certain(Se3::identity());
/// let with_jr = propagate_tangent_inputs(&start, &[u], &cov_w, InputNoise::RightJacobian).unwrap();
/// let lecture = propagate_tangent_inputs(&start, &[u], &cov_w, InputNoise::LectureNoJr).unwrap();
/// assert_eq!(lecture[1].method, Method::LectureNoJr);
/// let jr = Se3::jr(&u);
/// assert!((with_jr[1].pose.cov() - jr * cov_w * jr.transpose()).norm() < 1e-15);
/// ```
pub fn propagate_tangent_inputs<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    inputs: &[Tangent<N>],
    cov_noise: &TangentMatrix<N>,
    noise: InputNoise,
) -> Result<Vec<Propagated<G, N>>> {
    propagate_tangent_inputs_each(start, inputs, &StepNoise::Same(*cov_noise), noise)
}

/// [`propagate_tangent_inputs`] with Σ_w given per step ([`StepNoise`]).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::propagate::odometry::{InputNoise, StepNoise, propagate_tangent_inputs_each};
/// use posecov::uncertain::UncertainPose;
/// use nalgebra::{Matrix3, Vector3};
/// let u = Vector3::new(1.0, 0.0, 0.0);
/// let noise = StepNoise::PerStep(vec![Matrix3::identity() * 1e-4]);
/// let path = propagate_tangent_inputs_each(&UncertainPose::certain(Se2::identity()), &[u], &noise, InputNoise::LectureNoJr).unwrap();
/// assert!((path[1].pose.cov() - Matrix3::identity() * 1e-4).norm() < 1e-18);
/// ```
pub fn propagate_tangent_inputs_each<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    inputs: &[Tangent<N>],
    step_noise: &StepNoise<N>,
    noise: InputNoise,
) -> Result<Vec<Propagated<G, N>>> {
    check_finite(
        "odometry inputs u_k",
        inputs.iter().flat_map(|u| u.iter().copied()),
    )?;
    let step_noise = step_noise.validated(inputs.len())?;
    let method = match noise {
        InputNoise::RightJacobian => Method::FirstOrder,
        InputNoise::LectureNoJr => Method::LectureNoJr,
    };
    let steps = inputs.iter().enumerate().map(|(k, u)| {
        let cov_noise = step_noise.at(k);
        let q = match noise {
            InputNoise::RightJacobian => {
                let jr = G::jr(u);
                jr * cov_noise * jr.transpose()
            }
            InputNoise::LectureNoJr => cov_noise,
        };
        (G::exp(u), q)
    });
    Ok(recursion(start, steps, method))
}

/// The shared recursion over (U_k, Q_k), Q_k the body-frame noise covariance at X_{k+1}.
fn recursion<G: LieGroup<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    steps: impl Iterator<Item = (G, TangentMatrix<N>)>,
    method: Method,
) -> Vec<Propagated<G, N>> {
    let mut out = vec![Propagated {
        pose: *start,
        method,
    }];
    let (mut mean, mut cov) = (*start.mean(), *start.cov());
    for (u, q) in steps {
        mean = mean.compose(&u);
        let next = match start.side() {
            Side::Right => {
                let ad = u.inverse().adj();
                ad * cov * ad.transpose() + q
            }
            Side::Left => {
                let ad = mean.adj();
                cov + ad * q * ad.transpose()
            }
        };
        cov = (next + next.transpose()) * 0.5;
        out.push(Propagated {
            pose: UncertainPose::new_unchecked(mean, cov, start.side()),
            method,
        });
    }
    out
}
