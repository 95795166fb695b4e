//! Uncertain poses: a mean on a Lie group, a covariance in its tangent space, and the side
//! the covariance lives on.
//!
//! Right / body (default): X = μ · Exp(ε); left / world: X = Exp(ε) · μ; ε ~ N(0, Σ).
//! Σ_left = Ad_μ Σ_right Ad_μᵀ. See the [crate conventions](crate#conventions).
//!
//! Here: `UncertainPose` (mean, Σ, side) and side changes; `sigmas.rs` poses from standard
//! deviations and the Mahalanobis distance (Σ⁻¹, [`Information`]); `marginals.rs` marginals (the
//! one world-position covariance, `position_cov_in_world_3d`); `validate.rs` and `confidence.rs`.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::lie::{LieGroup, TangentMatrix};

mod confidence;
mod marginals;
mod sigmas;
mod validate;
pub use confidence::{
    Confidence, ConfidenceError, Coverage, Region, anees_band, chi2_probability, chi2_radius,
    sigma_probability, sigma_radius,
};
use sigmas::validated_information;
pub use sigmas::{Information, try_information, try_inverse_covariance};
pub use validate::{
    PSD_TOLERANCE, SYMMETRY_TOLERANCE, psd_tolerance, symmetry_tolerance, validate_covariance,
    validate_covariance_dyn,
};

/// Which side of the mean a covariance's perturbation multiplies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Right / local / body: X = μ · Exp(ε), Σ expressed in the body frame at μ (the default;
    /// NA 568's left-invariant error, SLAM 101's R̃ = R Exp(ε), ROS's rotation part).
    #[default]
    Right,
    /// Left / global / world: X = Exp(ε) · μ (EEME E6911, Barfoot & Furgale 2014).
    Left,
}

/// How a covariance was computed. Every propagated result names its method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Exact for deterministic operations (a change of frame moves the Gaussian exactly).
    Exact,
    /// First-order (Jacobian / adjoint) propagation on the manifold.
    FirstOrder,
    /// First-order odometry recursion without the Jr term on the noise (ROB 530 SE(3) script;
    /// kept only as a labelled, lecture-faithful comparison).
    LectureNoJr,
    /// Second-order compounding (Barfoot & Furgale 2014, eq. 38).
    SecondOrder,
    /// Fourth-order compounding (Barfoot & Furgale 2014, eq. 55).
    FourthOrder,
    /// Unscented transform with sigma points on the manifold.
    SigmaPoints,
    /// Monte Carlo sampling with the iterative Lie mean: the truth the others are judged by.
    MonteCarlo,
    /// Smith–Self–Cheeseman linearisation in (x, y, θ) / (x, y, z, roll, pitch, yaw): the
    /// vector-space baseline the lectures contrast with.
    VectorSpace,
    /// A closed form from the literature (e.g. Long et al. 2012 differential drive).
    ClosedForm,
    /// Numerical integration of a continuous-time covariance ODE.
    NumericIntegral,
}

/// A pose (or rotation) with a Gaussian uncertainty on the manifold: (μ, Σ, side).
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use posecov::uncertain::{Side, UncertainPose};
/// use nalgebra::Matrix3;
/// let world_from_robot = Se2::from_xy_theta(1.0, 0.0, 0.5);
/// let cov_in_body = Matrix3::from_diagonal(&nalgebra::Vector3::new(0.01, 0.01, 0.04));
/// let pose = UncertainPose::try_new(world_from_robot, cov_in_body, Side::Right).unwrap();
/// let in_world = pose.to_side(Side::Left);
/// let ad = world_from_robot.adj();
/// assert!((in_world.cov() - ad * cov_in_body * ad.transpose()).norm() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UncertainPose<G: LieGroup<N>, const N: usize> {
    mean: G,
    cov: TangentMatrix<N>,
    side: Side,
}

impl<G: LieGroup<N>, const N: usize> UncertainPose<G, N> {
    /// A validated uncertain pose (see [`validate_covariance`]); the stored Σ is symmetrised.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Matrix3;
    /// let bad = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
    /// assert!(UncertainPose::try_new(So3::identity(), bad, Side::Right).is_err());
    /// ```
    pub fn try_new(mean: G, cov: TangentMatrix<N>, side: Side) -> Result<Self> {
        let cov = validate_covariance("covariance", &cov)?;
        Ok(Self { mean, cov, side })
    }

    /// [`try_new`](Self::try_new) and Σ⁻¹ as [`try_information`] gives it (`Err` when Σ is
    /// singular), from the one factorisation that validates Σ: what a consumer of every
    /// message of a log (the NEES) needs, without factorising Σ twice.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Matrix3;
    /// let (pose, info) = UncertainPose::try_new_with_information(Se2::identity(), Matrix3::identity() * 4.0, Side::Right).unwrap();
    /// assert_eq!(pose.cov()[(2, 2)], 4.0);
    /// assert!((info.unwrap().matrix() - Matrix3::identity() * 0.25).norm() < 1e-15);
    /// let (_, info) = UncertainPose::try_new_with_information(Se2::identity(), Matrix3::zeros(), Side::Right).unwrap();
    /// assert!(info.is_err()); // valid (PSD) but singular
    /// ```
    pub fn try_new_with_information(
        mean: G,
        cov: TangentMatrix<N>,
        side: Side,
    ) -> Result<(Self, Result<Information<N>>)> {
        let (cov, information) = validated_information("covariance", &cov)?;
        Ok((Self { mean, cov, side }, information))
    }

    /// Wraps an already-valid (symmetric PSD) covariance without checking it; for results
    /// the library computes itself, e.g. Ad Σ Adᵀ of a valid Σ. The result is symmetrised.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::new_unchecked(So2::identity(), nalgebra::Matrix1::new(0.1), Side::Right);
    /// assert_eq!(p.cov()[(0, 0)], 0.1);
    /// ```
    pub fn new_unchecked(mean: G, cov: TangentMatrix<N>, side: Side) -> Self {
        Self {
            mean,
            cov: (cov + cov.transpose()) * 0.5,
            side,
        }
    }

    /// A pose known exactly (Σ = 0, right side).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::uncertain::UncertainPose;
    /// assert_eq!(UncertainPose::certain(Se3::identity()).cov().norm(), 0.0);
    /// ```
    pub fn certain(mean: G) -> Self {
        Self::new_unchecked(mean, TangentMatrix::<N>::zeros(), Side::Right)
    }

    /// The mean μ.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::uncertain::UncertainPose;
    /// assert_eq!(UncertainPose::certain(So2::identity()).mean(), &So2::identity());
    /// ```
    pub fn mean(&self) -> &G {
        &self.mean
    }

    /// The covariance Σ, on [`side`](Self::side).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::uncertain::UncertainPose;
    /// assert_eq!(UncertainPose::certain(So2::identity()).cov()[(0, 0)], 0.0);
    /// ```
    pub fn cov(&self) -> &TangentMatrix<N> {
        &self.cov
    }

    /// The side Σ lives on.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// assert_eq!(UncertainPose::certain(So2::identity()).side(), Side::Right);
    /// ```
    pub fn side(&self) -> Side {
        self.side
    }

    /// The same distribution with Σ expressed on `side` (to first order, exact for the
    /// linear map Ad): Σ_left = Ad_μ Σ_right Ad_μᵀ, Σ_right = Ad_μ⁻¹ Σ_left Ad_μ⁻ᵀ.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Matrix6;
    /// let p = UncertainPose::try_new(Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.1, 0.2, 0.3]), Matrix6::identity() * 0.01, Side::Right).unwrap();
    /// let back = p.to_side(Side::Left).to_side(Side::Right);
    /// assert!((back.cov() - p.cov()).norm() < 1e-14);
    /// ```
    pub fn to_side(&self, side: Side) -> Self {
        if side == self.side {
            return *self;
        }
        let ad = match side {
            Side::Left => self.mean.adj(),
            Side::Right => self.mean.inverse().adj(),
        };
        Self::new_unchecked(self.mean, ad * self.cov * ad.transpose(), side)
    }

    /// Σ in the body frame (right side), converting if needed.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_new(So3::identity(), nalgebra::Matrix3::identity(), Side::Left).unwrap();
    /// assert_eq!(p.cov_right(), nalgebra::Matrix3::identity());
    /// ```
    pub fn cov_right(&self) -> TangentMatrix<N> {
        self.to_side(Side::Right).cov
    }

    /// Σ in the world frame (left side), converting if needed.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(So3::identity());
    /// assert_eq!(p.cov_left(), nalgebra::Matrix3::zeros());
    /// ```
    pub fn cov_left(&self) -> TangentMatrix<N> {
        self.to_side(Side::Left).cov
    }
}
