//! Uncertain poses: a mean on a Lie group, a covariance in its tangent space, and the side
//! the covariance lives on.
//!
//! Right / body (default): X = μ · Exp(ε); left / world: X = Exp(ε) · μ; ε ~ N(0, Σ).
//! Σ_left = Ad_μ Σ_right Ad_μᵀ. See the [crate conventions](crate#conventions).
//!
//! Here: `UncertainPose` (mean, Σ, side), side changes, marginals (the one world-position
//! covariance, `position_cov_in_world_3d`); `validate.rs` and `confidence.rs` below.

use nalgebra::{Matrix2, Matrix3, SMatrix, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, check_finite};
use crate::lie::{LieGroup, Se2, Se3, So2, So3, Tangent, TangentMatrix};

mod confidence;
mod validate;
pub use confidence::{
    Confidence, ConfidenceError, Coverage, Region, anees_band, chi2_probability, chi2_radius,
    sigma_probability, sigma_radius,
};
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

// --------------------------------------------------------------------------------------------
// Constructors from standard deviations, Mahalanobis distance.

impl<G: LieGroup<N>, const N: usize> UncertainPose<G, N> {
    /// A pose with independent tangent components: Σ = diag(σ₁², …, σ_N²), σ in the tangent
    /// order of the [conventions](crate#conventions) (SE(3): σ_ρx, σ_ρy, σ_ρz, σ_θx, σ_θy,
    /// σ_θz; SE(2): σ_ρx, σ_ρy, σ_θ), on `side`. Each σ must be finite and ≥ 0.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.2, 0.05], Side::Right).unwrap();
    /// assert!((p.cov()[(1, 1)] - 0.04).abs() < 1e-15);
    /// assert!(UncertainPose::try_from_std_devs(Se2::identity(), [0.1, -0.2, 0.05], Side::Right).is_err());
    /// ```
    pub fn try_from_std_devs(mean: G, std_devs: [f64; N], side: Side) -> Result<Self> {
        check_finite("standard deviations", std_devs)?;
        if let Some(&sigma) = std_devs.iter().find(|s| **s < 0.0) {
            return Err(Error::OutOfRange {
                what: "standard deviation",
                value: sigma,
                expected: "σ ≥ 0",
            });
        }
        let variances = nalgebra::SVector::<f64, N>::from_iterator(std_devs.iter().map(|s| s * s));
        Ok(Self::new_unchecked(
            mean,
            TangentMatrix::<N>::from_diagonal(&variances),
            side,
        ))
    }

    /// The tangent perturbation ε that takes the mean to `x` on this pose's side:
    /// right ε = Log(μ⁻¹ x) (x = μ · Exp ε), left ε = Log(x μ⁻¹) (x = Exp ε · μ).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::UncertainPose;
    /// use nalgebra::Vector3;
    /// let p = UncertainPose::certain(Se2::from_xy_theta(1.0, 0.0, 0.3));
    /// let eps = Vector3::new(0.1, -0.2, 0.05);
    /// assert!((p.perturbation_of(&p.mean().rplus(&eps)) - eps).norm() < 1e-14);
    /// ```
    pub fn perturbation_of(&self, x: &G) -> Tangent<N> {
        match self.side {
            Side::Right => x.rminus(&self.mean),
            Side::Left => x.lminus(&self.mean),
        }
    }

    /// Squared Mahalanobis distance of `x` from this distribution, d² = εᵀ Σ⁻¹ ε with ε from
    /// [`perturbation_of`](Self::perturbation_of) (N degrees of freedom: compare with
    /// [`chi2_radius`]`(p, N)²`). The value is the same on either side (Ad is linear).
    /// Errors: [`Error::SingularCovariance`] when Σ is singular (see [`try_inverse_covariance`]).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Vector3;
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.1], Side::Right).unwrap();
    /// let x = Se2::exp(&Vector3::new(0.2, 0.0, 0.0));
    /// assert!((p.mahalanobis_squared(&x).unwrap() - 4.0).abs() < 1e-12);
    /// assert!(UncertainPose::certain(Se2::identity()).mahalanobis_squared(&x).is_err());
    /// ```
    pub fn mahalanobis_squared(&self, x: &G) -> Result<f64> {
        let info = try_inverse_covariance("pose covariance", &self.cov)?;
        let eps = self.perturbation_of(x);
        Ok((eps.transpose() * info * eps)[(0, 0)])
    }

    /// Mahalanobis distance d = √(εᵀ Σ⁻¹ ε), see [`mahalanobis_squared`](Self::mahalanobis_squared).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap();
    /// assert!((p.mahalanobis(&So2::from_angle(-0.3)).unwrap() - 3.0).abs() < 1e-12);
    /// ```
    pub fn mahalanobis(&self, x: &G) -> Result<f64> {
        self.mahalanobis_squared(x).map(f64::sqrt)
    }
}

/// Below this ratio λ_min / λ_max a covariance counts as singular and is not inverted.
pub const SINGULAR_TOLERANCE: f64 = 1e-12;

/// The information matrix Σ⁻¹ of a covariance, through its eigen-decomposition
/// Σ = V diag(λ) Vᵀ → Σ⁻¹ = V diag(1/λ) Vᵀ. Σ is validated first
/// ([`validate_covariance`]); [`Error::SingularCovariance`] when λ_min ≤
/// [`SINGULAR_TOLERANCE`] · λ_max (including Σ = 0).
///
/// ```
/// use posecov::uncertain::try_inverse_covariance;
/// use nalgebra::Matrix2;
/// let info = try_inverse_covariance("Σ", &Matrix2::new(4.0, 0.0, 0.0, 0.25)).unwrap();
/// assert!((info - Matrix2::new(0.25, 0.0, 0.0, 4.0)).norm() < 1e-14);
/// assert!(try_inverse_covariance("Σ", &Matrix2::new(1.0, 1.0, 1.0, 1.0)).is_err());
/// ```
pub fn try_inverse_covariance<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<TangentMatrix<N>> {
    // The decomposition that validated ½(Σ + Σᵀ) is the one inverted (one, not two).
    let (_, eigen) = validate::validated_eigen(what, cov, true)?;
    information(what, eigen)
}

/// Σ⁻¹ of a valid, non-singular covariance, as a quadratic form εᵀ Σ⁻¹ ε is taken with it
/// ([`try_information`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Information<const N: usize> {
    /// Σ = L Lᵀ (L lower triangular), for a well-conditioned Σ: εᵀ Σ⁻¹ ε = ‖L⁻¹ ε‖².
    Cholesky(TangentMatrix<N>),
    /// Σ⁻¹ = V diag(1/λ) Vᵀ from the eigen-decomposition that validated Σ.
    Inverse(TangentMatrix<N>),
}

impl<const N: usize> Information<N> {
    /// εᵀ Σ⁻¹ ε (a squared Mahalanobis distance, an NEES).
    ///
    /// ```
    /// use posecov::uncertain::try_information;
    /// use nalgebra::{Matrix2, Vector2};
    /// let info = try_information("Σ", &Matrix2::new(4.0, 0.0, 0.0, 0.25)).unwrap();
    /// assert_eq!(info.quadratic(&Vector2::new(2.0, 1.0)), 5.0);
    /// ```
    pub fn quadratic(&self, e: &Tangent<N>) -> f64 {
        match self {
            Information::Cholesky(l) => l.solve_lower_triangular_unchecked(e).norm_squared(),
            Information::Inverse(info) => (e.transpose() * info * e)[0],
        }
    }

    /// Σ⁻¹ as a matrix.
    pub fn matrix(&self) -> TangentMatrix<N> {
        match self {
            Information::Cholesky(l) => {
                let l_inverse = l.solve_lower_triangular_unchecked(&TangentMatrix::<N>::identity());
                l_inverse.transpose() * l_inverse
            }
            Information::Inverse(info) => *info,
        }
    }
}

/// Σ⁻¹ of a covariance, validated first ([`validate_covariance`]), as a quadratic form is
/// taken with it: for a well-conditioned Σ (tr Σ · tr Σ⁻¹ ≤ 10⁸, which bounds λ_max / λ_min)
/// its Cholesky factor, which proves Σ positive definite and far from singular without its
/// eigenvalues; otherwise [`try_inverse_covariance`]'s, which decides through them (the same
/// decisions either way: 10⁸ is four orders of magnitude inside [`SINGULAR_TOLERANCE`]).
///
/// ```
/// use posecov::uncertain::{Information, try_information};
/// use nalgebra::Matrix2;
/// let info = try_information("Σ", &Matrix2::new(4.0, 1.0, 1.0, 2.0)).unwrap();
/// assert!(matches!(info, Information::Cholesky(_)));
/// assert!((info.matrix() * Matrix2::new(4.0, 1.0, 1.0, 2.0) - Matrix2::identity()).norm() < 1e-15);
/// // λ_max / λ_min = 1e10: decided by the eigenvalues (not singular: 1e10 < 1e12).
/// assert!(matches!(try_information("Σ", &Matrix2::new(1.0, 0.0, 0.0, 1e-10)), Ok(Information::Inverse(_))));
/// assert!(try_information("Σ", &Matrix2::new(1.0, 1.0, 1.0, 1.0)).is_err());
/// ```
pub fn try_information<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<Information<N>> {
    validated_information(what, cov).and_then(|(_, information)| information)
}

/// ½(Σ + Σᵀ) validated and [`try_information`]'s Σ⁻¹ (`Err` inside: Σ is singular).
fn validated_information<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<(TangentMatrix<N>, Result<Information<N>>)> {
    if let Some((sym, l)) = validate::well_conditioned_factor(what, cov) {
        return Ok((sym, Ok(Information::Cholesky(l))));
    }
    let (sym, eigen) = validate::validated_eigen(what, cov, true)?;
    Ok((sym, information(what, eigen).map(Information::Inverse)))
}

/// Σ⁻¹ = V diag(1/λ) Vᵀ from the decomposition that validated Σ (`None`: a 0 × 0 Σ), or
/// [`Error::SingularCovariance`].
fn information<const N: usize>(
    what: &'static str,
    eigen: Option<validate::Eigen<N>>,
) -> Result<TangentMatrix<N>> {
    let singular = |min_eigenvalue| Error::SingularCovariance {
        what,
        min_eigenvalue,
    };
    // Only a 0 × 0 Σ has no decomposition: nothing to invert.
    let eigen = eigen.ok_or_else(|| singular(0.0))?;
    let (min_eigenvalue, max_eigenvalue) = (eigen.values.min(), eigen.values.max());
    if max_eigenvalue <= 0.0 || min_eigenvalue <= SINGULAR_TOLERANCE * max_eigenvalue {
        return Err(singular(min_eigenvalue));
    }
    let v = &eigen.vectors;
    let inverse_values = eigen.values.map(|l| 1.0 / l);
    let info = v * TangentMatrix::<N>::from_diagonal(&inverse_values) * v.transpose();
    Ok((info + info.transpose()) * 0.5)
}

// --------------------------------------------------------------------------------------------
// Marginals (docs/CONVENTIONS.md §7), first order in the position, exact in the rotation.

/// R Σ Rᵀ.
fn rotate_cov<const D: usize>(
    r: &SMatrix<f64, D, D>,
    cov: &SMatrix<f64, D, D>,
) -> SMatrix<f64, D, D> {
    let out = r * cov * r.transpose();
    (out + out.transpose()) * 0.5
}

impl<G: LieGroup<N>, const N: usize> UncertainPose<G, N> {
    /// Position covariance in the **world** axes, first order, lifted into 3D for any group:
    /// R Σ_ρρ Rᵀ from the right form (planar groups: z row and column zero; rotation groups:
    /// `None`, they have no position). The one world-position covariance of the crate; the
    /// per-group [`position_cov_in_world`](UncertainPose::position_cov_in_world) are views of it.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2, So3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let yaw90 = Se2::from_xy_theta(5.0, 0.0, std::f64::consts::FRAC_PI_2);
    /// let p = UncertainPose::try_from_std_devs(yaw90, [0.1, 0.0, 0.0], Side::Right).unwrap();
    /// let c = p.position_cov_in_world_3d().unwrap();
    /// assert!((c[(1, 1)] - 0.01).abs() < 1e-15 && c[(2, 2)] == 0.0); // body x is world y
    /// assert!(UncertainPose::certain(So3::identity()).position_cov_in_world_3d().is_none());
    /// ```
    pub fn position_cov_in_world_3d(&self) -> Option<Matrix3<f64>> {
        let d = G::KIND.position_dims();
        if d == 0 {
            return None;
        }
        let cov = self.cov_right();
        let block = Matrix3::from_fn(|r, c| if r < d && c < d { cov[(r, c)] } else { 0.0 });
        Some(rotate_cov(
            &self.mean.to_se3().rotation().to_matrix(),
            &block,
        ))
    }
}

impl UncertainPose<Se3, 6> {
    /// The mean position t (the body origin in the world frame).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0; 3]));
    /// assert_eq!(p.position().x, 1.0);
    /// ```
    pub fn position(&self) -> Vector3<f64> {
        *self.mean.translation()
    }

    /// Position covariance in the **body** axes, first order: the ρρ block of the right-form
    /// Σ (X = μ Exp([ρ; θ]) moves the position by R Jl(θ) ρ ≈ R ρ; Solà et al. 2018 eq. 172).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se3::identity(), [0.1, 0.2, 0.3, 0.0, 0.0, 0.0], Side::Right).unwrap();
    /// assert!((p.position_cov_in_body()[(2, 2)] - 0.09).abs() < 1e-15);
    /// ```
    pub fn position_cov_in_body(&self) -> Matrix3<f64> {
        self.cov_right().fixed_view::<3, 3>(0, 0).into_owned()
    }

    /// Position covariance in the **world** axes, first order: R Σ_ρρ Rᵀ from the right form
    /// ([CONVENTIONS §7]). Note: this is *not* the ρρ block of the left form unless t = 0 — a
    /// left perturbation moves the position by ρ + θ × t.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let yaw90 = Se3::from_xyz_rpy([5.0, 0.0, 0.0], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
    /// let p = UncertainPose::try_from_std_devs(yaw90, [0.1, 0.0, 0.0, 0.0, 0.0, 0.0], Side::Right).unwrap();
    /// // body x is world y
    /// assert!((p.position_cov_in_world()[(1, 1)] - 0.01).abs() < 1e-15);
    /// ```
    ///
    /// [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty
    pub fn position_cov_in_world(&self) -> Matrix3<f64> {
        self.position_cov_in_world_3d()
            .unwrap_or_else(Matrix3::zeros)
    }

    /// Rotation covariance in the body frame: the θθ block of the right-form Σ (exact: the
    /// rotation of μ Exp([ρ; θ]) is R Exp(θ)).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se3::identity(), [0.0, 0.0, 0.0, 0.1, 0.0, 0.0], Side::Right).unwrap();
    /// assert!((p.rotation_cov_in_body()[(0, 0)] - 0.01).abs() < 1e-15);
    /// ```
    pub fn rotation_cov_in_body(&self) -> Matrix3<f64> {
        self.cov_right().fixed_view::<3, 3>(3, 3).into_owned()
    }

    /// Rotation covariance in the world frame: R Σ_θθ Rᵀ (exact: R Exp(θ) = Exp(R θ) R), equal
    /// to the θθ block of the left form.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let x = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
    /// let p = UncertainPose::try_from_std_devs(x, [0.1, 0.2, 0.3, 0.01, 0.02, 0.03], Side::Right).unwrap();
    /// let left = p.cov_left();
    /// assert!((p.rotation_cov_in_world() - left.fixed_view::<3, 3>(3, 3)).norm() < 1e-15);
    /// ```
    pub fn rotation_cov_in_world(&self) -> Matrix3<f64> {
        rotate_cov(
            &self.mean.rotation().to_matrix(),
            &self.rotation_cov_in_body(),
        )
    }

    /// The rotation marginal as an uncertain SO(3) element (right side, Σ = Σ_θθ; exact).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(Se3::from_xyz_rpy([1.0, 0.0, 0.0], [0.0, 0.0, 0.5]));
    /// assert!((p.rotation_marginal().mean().to_rpy()[2] - 0.5).abs() < 1e-15);
    /// ```
    pub fn rotation_marginal(&self) -> UncertainPose<So3, 3> {
        UncertainPose::new_unchecked(
            *self.mean.rotation(),
            self.rotation_cov_in_body(),
            Side::Right,
        )
    }
}

impl UncertainPose<Se2, 3> {
    /// The mean position (x, y).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::UncertainPose;
    /// assert_eq!(UncertainPose::certain(Se2::from_xy_theta(1.0, 2.0, 0.0)).position().y, 2.0);
    /// ```
    pub fn position(&self) -> Vector2<f64> {
        *self.mean.translation()
    }

    /// Position covariance in the **body** axes, first order: the ρρ block of the right-form Σ
    /// (μ Exp([ρ; θ]) moves the position by R V(θ) ρ ≈ R ρ; Solà et al. 2018 eq. 156).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.2, 0.3], Side::Right).unwrap();
    /// assert!((p.position_cov_in_body()[(1, 1)] - 0.04).abs() < 1e-15);
    /// ```
    pub fn position_cov_in_body(&self) -> Matrix2<f64> {
        self.cov_right().fixed_view::<2, 2>(0, 0).into_owned()
    }

    /// Position covariance in the **world** axes, first order: R Σ_ρρ Rᵀ from the right form
    /// ([CONVENTIONS §7]; the left form's ρρ block differs unless t = 0).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let x = Se2::from_xy_theta(3.0, 0.0, std::f64::consts::FRAC_PI_2);
    /// let p = UncertainPose::try_from_std_devs(x, [0.1, 0.0, 0.0], Side::Right).unwrap();
    /// assert!((p.position_cov_in_world()[(1, 1)] - 0.01).abs() < 1e-15);
    /// ```
    ///
    /// [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty
    pub fn position_cov_in_world(&self) -> Matrix2<f64> {
        self.position_cov_in_world_3d()
            .map_or_else(Matrix2::zeros, |c| c.fixed_view::<2, 2>(0, 0).into_owned())
    }

    /// Heading variance σ_θ² (the same in body and world frames: SO(2) is commutative; exact).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 2.0, 0.3), [0.1, 0.1, 0.2], Side::Left).unwrap();
    /// assert!((p.heading_variance() - 0.04).abs() < 1e-15);
    /// ```
    pub fn heading_variance(&self) -> f64 {
        self.cov[(2, 2)]
    }

    /// The rotation marginal as an uncertain SO(2) element (right side, Σ = σ_θ²; exact).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use posecov::uncertain::UncertainPose;
    /// let p = UncertainPose::certain(Se2::from_xy_theta(0.0, 0.0, 0.4));
    /// assert!((p.rotation_marginal().mean().angle() - 0.4).abs() < 1e-15);
    /// ```
    pub fn rotation_marginal(&self) -> UncertainPose<So2, 1> {
        UncertainPose::new_unchecked(
            *self.mean.rotation(),
            nalgebra::Matrix1::new(self.heading_variance()),
            Side::Right,
        )
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix6, Vector6};
    use rand::{Rng, SeedableRng};

    use super::*;

    /// The Cholesky path decides as the eigenvalues do (valid, singular or not) and gives the
    /// same quadratic forms, for condition numbers from 1 to 10¹⁶ and for matrices with a
    /// slightly negative eigenvalue; it is taken for the well-conditioned ones only.
    #[test]
    fn information_decides_as_the_eigenvalues_do() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let (mut factored, mut decomposed) = (0, 0);
        for k in 0..2000 {
            let q = Matrix6::from_fn(|_, _| rng.random_range(-1.0..1.0))
                .qr()
                .q();
            let log_kappa = f64::from(k % 17);
            let mut values = Vector6::from_fn(|i, _| {
                let t = if i == 0 {
                    0.0
                } else {
                    rng.random_range(0.0..1.0)
                };
                10f64.powf(-log_kappa * t)
            });
            values[5] = 10f64.powf(-log_kappa);
            if k % 23 == 0 {
                values[5] = -1e-11;
            }
            let scale = 10f64.powf(rng.random_range(-6.0..6.0));
            let cov = q * Matrix6::from_diagonal(&values) * q.transpose() * scale;
            let e = Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let by_eigen = try_inverse_covariance("Σ", &cov);
            let by_factor = try_information("Σ", &cov);
            assert_eq!(by_factor.is_ok(), by_eigen.is_ok(), "{k}: {by_eigen:?}");
            let (Ok(info), Ok(inverse)) = (by_factor, by_eigen) else {
                continue;
            };
            match info {
                Information::Cholesky(_) => factored += 1,
                Information::Inverse(_) => decomposed += 1,
            }
            if log_kappa <= 8.0 {
                let (a, b) = (info.quadratic(&e), (e.transpose() * inverse * e)[0]);
                assert!((a - b).abs() <= 1e-6 * b, "{k}: {a} vs {b}");
            }
        }
        assert!(
            factored > 500 && decomposed > 500,
            "{factored} {decomposed}"
        );
    }
}
