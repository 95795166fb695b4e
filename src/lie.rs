//! Lie groups of rigid motion: the [`LieGroup`] trait, the operations written once over it,
//! and the four groups [`So2`], [`So3`], [`Se2`], [`Se3`].
//!
//! # Shape
//! Each group file (`so2.rs`, `so3.rs`, `se2.rs`, `se3.rs`) implements only the closed forms
//! that differ between groups: `identity, compose, inverse, exp, log, hat, vee, adj, ad, jr,
//! jr_inv, act, rotate` and the Jacobian of `act`. Everything that is the same for every group
//! — `between, rplus, lplus, rminus, lminus, interpolate, jl, jl_inv` and the Jacobians of
//! `compose, inverse, between, rplus, rminus, exp, log` — is a provided method of the trait,
//! written once here, with the formula and its source (Solà, Deray & Atchuthan 2018,
//! "A micro Lie theory for state estimation in robotics", arXiv:1812.01537; manif).
//!
//! # Conventions
//! See the [crate-level conventions](crate#conventions): tangent vectors are translation
//! first (`[ρ; θ]`), Jacobians are with respect to **right** perturbations of inputs and output
//! (X ⊕ δ = X · Exp(δ)), Ad_X τ = vee(X · hat(τ) · X⁻¹).
//!
//! ```
//! use posecov::lie::{LieGroup, Se3};
//! use nalgebra::Vector6;
//! let world_from_body = Se3::exp(&Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.3));
//! let body_from_cam = Se3::exp(&Vector6::new(0.1, 0.0, 0.2, 0.0, 0.1, 0.0));
//! let world_from_cam = world_from_body.compose(&body_from_cam);
//! let back = world_from_cam.between(&world_from_body); // cam_from_body
//! assert!(back.compose(&body_from_cam).rminus(&Se3::identity()).norm() < 1e-12);
//! ```
//!
//! # What this folder owns
//!
//! The groups SO(2), SE(2), SO(3), SE(3): closed forms per group file, everything generic written
//! once on `LieGroup`; group facts (`GroupKind`: DOF, rotation range, planar; `to_se3`).
//!
//! It does not know about files or drawing.

use std::fmt::{Debug, Display};
use std::ops::Range;

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

pub mod se2;
pub mod se3;
pub mod series;
pub mod so2;
pub mod so3;

pub use se2::Se2;
pub use se3::Se3;
pub use so2::So2;
pub use so3::So3;

/// A tangent vector (element of ℝᴺ ≅ the Lie algebra) of an N-DOF group, in the order of the
/// [conventions](crate#conventions) table.
pub type Tangent<const N: usize> = SVector<f64, N>;

/// An N×N matrix acting on tangent vectors: Jacobians, adjoints, covariances.
pub type TangentMatrix<const N: usize> = SMatrix<f64, N, N>;

/// Jacobians of a binary operation `Z = f(X, Y)` with respect to right perturbations of each
/// input, expressed at the output: Z ⊕ δZ ≈ f(X ⊕ δX, Y ⊕ δY) with δZ = `wrt_lhs`·δX + `wrt_rhs`·δY.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BinaryJacobians<const N: usize> {
    /// ∂Z/∂X (X = `self`, the left-hand operand).
    pub wrt_lhs: TangentMatrix<N>,
    /// ∂Z/∂Y (Y = the argument).
    pub wrt_rhs: TangentMatrix<N>,
}

/// Jacobians of `Y = X ⊕ τ = X · Exp(τ)` (Solà et al. 2018, eqs. 179a–b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RplusJacobians<const N: usize> {
    /// ∂Y/∂X = Ad_{Exp(τ)}⁻¹.
    pub wrt_group: TangentMatrix<N>,
    /// ∂Y/∂τ = Jr(τ).
    pub wrt_tangent: TangentMatrix<N>,
}

/// Jacobians of a group action `q = X · p` (or of `rotate`), with respect to a right
/// perturbation of X and to the point (Solà et al. 2018, eqs. 145, 153, 166, 181).
///
/// `G` is D×N (D = 2 or 3, the space dimension), `P` is D×D.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActJacobians<G, P> {
    /// ∂q/∂X, D×N.
    pub wrt_group: G,
    /// ∂q/∂p, D×D (the rotation matrix).
    pub wrt_point: P,
}

/// Which of the four groups an element belongs to: the facts code outside the group files may
/// need (degrees of freedom, where the rotation sits in the tangent, whether it is planar),
/// in one place instead of guessed from `N`.
///
/// ```
/// use posecov::lie::{GroupKind, LieGroup, Se2, Se3};
/// assert_eq!(Se3::KIND, GroupKind::Se3);
/// assert_eq!(GroupKind::Se3.rotation_range(), 3..6);
/// assert!(Se2::KIND.is_planar() && !Se2::KIND.is_rotation_only());
/// assert_eq!(GroupKind::Se2.position_dims(), 2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupKind {
    /// Planar rotations, tangent \[θ\].
    So2,
    /// Planar poses, tangent [ρx, ρy, θ].
    Se2,
    /// 3D rotations, tangent θ ∈ ℝ³.
    So3,
    /// 3D poses, tangent [ρ; θ].
    Se3,
}

impl GroupKind {
    /// Degrees of freedom N: 1, 3, 3, 6.
    ///
    /// ```
    /// assert_eq!(posecov::lie::GroupKind::So2.dof(), 1);
    /// ```
    pub fn dof(self) -> usize {
        match self {
            GroupKind::So2 => 1,
            GroupKind::Se2 | GroupKind::So3 => 3,
            GroupKind::Se3 => 6,
        }
    }

    /// The index range of the rotation part of the tangent (translation first, [ρ; θ]).
    ///
    /// ```
    /// assert_eq!(posecov::lie::GroupKind::Se2.rotation_range(), 2..3);
    /// ```
    pub fn rotation_range(self) -> Range<usize> {
        match self {
            GroupKind::So2 => 0..1,
            GroupKind::Se2 => 2..3,
            GroupKind::So3 => 0..3,
            GroupKind::Se3 => 3..6,
        }
    }

    /// Dimensions of the position part of the tangent (0 for rotation groups).
    ///
    /// ```
    /// assert_eq!(posecov::lie::GroupKind::So3.position_dims(), 0);
    /// ```
    pub fn position_dims(self) -> usize {
        self.rotation_range().start
    }

    /// Dimension of the space the group acts on (2 or 3).
    ///
    /// ```
    /// assert_eq!(posecov::lie::GroupKind::So2.space_dims(), 2);
    /// ```
    pub fn space_dims(self) -> usize {
        if self.is_planar() { 2 } else { 3 }
    }

    /// A rotation group (no translation): SO(2), SO(3).
    ///
    /// ```
    /// assert!(posecov::lie::GroupKind::So2.is_rotation_only());
    /// ```
    pub fn is_rotation_only(self) -> bool {
        matches!(self, GroupKind::So2 | GroupKind::So3)
    }

    /// A planar group: SO(2), SE(2).
    ///
    /// ```
    /// assert!(posecov::lie::GroupKind::Se2.is_planar());
    /// ```
    pub fn is_planar(self) -> bool {
        matches!(self, GroupKind::So2 | GroupKind::Se2)
    }

    /// Display name, "SE(3)" etc.
    ///
    /// ```
    /// assert_eq!(posecov::lie::GroupKind::Se3.name(), "SE(3)");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            GroupKind::So2 => "SO(2)",
            GroupKind::Se2 => "SE(2)",
            GroupKind::So3 => "SO(3)",
            GroupKind::Se3 => "SE(3)",
        }
    }
}

/// A matrix Lie group of rigid motion with N degrees of freedom.
///
/// Implementors supply the closed forms; the trait supplies every operation that is the same
/// for all groups. The vocabulary follows Solà et al. 2018 and manif.
///
/// All formulas assume the [conventions](crate#conventions): right (body) perturbations,
/// translation-first tangents.
pub trait LieGroup<const N: usize>:
    Copy + Clone + Debug + Display + PartialEq + Send + Sync + 'static
{
    /// A point or direction of the space the group acts on (`Vector2` or `Vector3`).
    type Point: Copy + Debug + PartialEq;
    /// The group's matrix form (2×2, 3×3 or 4×4); also the type of `hat(τ)`.
    type Matrix: Copy + Debug + PartialEq;
    /// The D×N Jacobian of the action with respect to the group element.
    type ActJacobian: Copy + Debug + PartialEq;
    /// The D×D Jacobian of the action with respect to the point.
    type PointJacobian: Copy + Debug + PartialEq;

    /// Short name used in messages and reports ("SO(3)", …).
    const NAME: &'static str;
    /// Which group this is ([`GroupKind`]: DOF, rotation range, planar or not).
    const KIND: GroupKind;

    // ----------------------------------------------------------------------------------------
    // Closed forms each group provides.

    /// The identity element I.
    fn identity() -> Self;
    /// Group composition X · Y.
    fn compose(&self, other: &Self) -> Self;
    /// Group inverse X⁻¹.
    fn inverse(&self) -> Self;
    /// Exponential map Exp: ℝᴺ → G, Exp(τ) = exp(hat(τ)).
    fn exp(tau: &Tangent<N>) -> Self;
    /// Logarithmic map Log: G → ℝᴺ, the inverse of Exp with rotation angle |θ| ≤ π.
    fn log(&self) -> Tangent<N>;
    /// hat: ℝᴺ → 𝔤, the Lie-algebra matrix of a tangent vector.
    fn hat(tau: &Tangent<N>) -> Self::Matrix;
    /// vee: 𝔤 → ℝᴺ, the inverse of hat (reads only the entries hat writes).
    fn vee(algebra: &Self::Matrix) -> Tangent<N>;
    /// The adjoint matrix Ad_X, with Ad_X τ = vee(X · hat(τ) · X⁻¹).
    fn adj(&self) -> TangentMatrix<N>;
    /// The small adjoint ad_τ = d/dt Ad_{Exp(tτ)} at t = 0, so that ad_τ σ = vee([hat τ, hat σ]).
    fn ad(tau: &Tangent<N>) -> TangentMatrix<N>;
    /// Right Jacobian Jr(τ): Exp(τ + δ) ≈ Exp(τ) · Exp(Jr(τ) δ).
    fn jr(tau: &Tangent<N>) -> TangentMatrix<N>;
    /// Inverse of the right Jacobian, Jr(τ)⁻¹ (finite for rotation angles |θ| < 2π).
    fn jr_inv(tau: &Tangent<N>) -> TangentMatrix<N>;
    /// Group action on a point, X · p (rotation for SO(n), rotation then translation for SE(n)).
    fn act(&self, point: &Self::Point) -> Self::Point;
    /// Jacobians of [`act`](Self::act) at `point`.
    fn act_jacobians(
        &self,
        point: &Self::Point,
    ) -> ActJacobians<Self::ActJacobian, Self::PointJacobian>;
    /// Rotates a direction (no translation): R · v.
    fn rotate(&self, direction: &Self::Point) -> Self::Point;
    /// The group element as a matrix (rotation matrix, or homogeneous transform).
    fn to_matrix(&self) -> Self::Matrix;
    /// The element as a 3D pose, for drawing: planar groups at z = 0 rotating about z,
    /// rotation groups at the origin.
    fn to_se3(&self) -> Se3;

    /// The index range of the rotation part of the tangent, `Self::KIND.rotation_range()`.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// assert_eq!(Se3::rotation_range(), 3..6);
    /// ```
    fn rotation_range() -> Range<usize> {
        Self::KIND.rotation_range()
    }

    // ----------------------------------------------------------------------------------------
    // Operations written once for every group.

    /// Left Jacobian, Jl(τ) = Jr(−τ) (Solà et al. 2018, eq. 41).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use nalgebra::Vector3;
    /// let t = Vector3::new(0.1, 0.2, 0.3);
    /// // Jl(τ) = Ad_{Exp τ} Jr(τ)
    /// assert!((So3::jl(&t) - So3::exp(&t).adj() * So3::jr(&t)).norm() < 1e-14);
    /// ```
    fn jl(tau: &Tangent<N>) -> TangentMatrix<N> {
        Self::jr(&-tau)
    }

    /// Inverse left Jacobian, Jl(τ)⁻¹ = Jr(−τ)⁻¹.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use nalgebra::{Matrix3, Vector3};
    /// let t = Vector3::new(1.0, 2.0, 0.5);
    /// assert!((Se2::jl_inv(&t) * Se2::jl(&t) - Matrix3::identity()).norm() < 1e-14);
    /// ```
    fn jl_inv(tau: &Tangent<N>) -> TangentMatrix<N> {
        Self::jr_inv(&-tau)
    }

    /// Relative element X⁻¹ · Y ("Y seen from X"; `a_from_b = world_from_a.between(&world_from_b)`).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// let world_from_a = Se2::from_xy_theta(1.0, 0.0, 0.5);
    /// let world_from_b = Se2::from_xy_theta(2.0, 1.0, -0.2);
    /// let a_from_b = world_from_a.between(&world_from_b);
    /// assert!(world_from_a.compose(&a_from_b).rminus(&world_from_b).norm() < 1e-14);
    /// ```
    fn between(&self, other: &Self) -> Self {
        self.inverse().compose(other)
    }

    /// Right plus, X ⊕ τ = X · Exp(τ): τ is a perturbation in the body frame (Solà eq. 25).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use nalgebra::Vector1;
    /// let x = So2::from_angle(0.3).rplus(&Vector1::new(0.2));
    /// assert!((x.angle() - 0.5).abs() < 1e-15);
    /// ```
    #[inline]
    fn rplus(&self, tau: &Tangent<N>) -> Self {
        self.compose(&Self::exp(tau))
    }

    /// Left plus, τ ⊕ X = Exp(τ) · X: τ is a perturbation in the world frame (Solà eq. 27).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use nalgebra::Vector6;
    /// let x = Se3::exp(&Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3));
    /// let t = Vector6::new(0.01, 0.0, 0.0, 0.0, 0.02, 0.0);
    /// // τ ⊕ X = X ⊕ (Ad_X⁻¹ τ)
    /// let right = x.rplus(&(x.inverse().adj() * t));
    /// assert!(x.lplus(&t).rminus(&right).norm() < 1e-14);
    /// ```
    #[inline]
    fn lplus(&self, tau: &Tangent<N>) -> Self {
        Self::exp(tau).compose(self)
    }

    /// Right minus, Y ⊖ X = Log(X⁻¹ · Y), with `self` = Y and `other` = X (Solà eq. 26):
    /// the body-frame tangent that takes X to Y.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use nalgebra::Vector3;
    /// let x = So3::exp(&Vector3::new(0.1, 0.2, 0.3));
    /// let t = Vector3::new(-0.4, 0.5, 0.1);
    /// assert!((x.rplus(&t).rminus(&x) - t).norm() < 1e-14);
    /// ```
    fn rminus(&self, other: &Self) -> Tangent<N> {
        other.between(self).log()
    }

    /// Left minus, Y ⊖ˡ X = Log(Y · X⁻¹), with `self` = Y and `other` = X (Solà eq. 28):
    /// the world-frame tangent that takes X to Y.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use nalgebra::Vector3;
    /// let x = Se2::from_xy_theta(1.0, 2.0, 0.3);
    /// let t = Vector3::new(0.2, -0.1, 0.4);
    /// assert!((x.lplus(&t).lminus(&x) - t).norm() < 1e-14);
    /// ```
    fn lminus(&self, other: &Self) -> Tangent<N> {
        self.compose(&other.inverse()).log()
    }

    /// Geodesic interpolation X ⊕ t (Y ⊖ X), t ∈ [0, 1] (t = 0 gives X, t = 1 gives Y).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let mid = So2::from_angle(0.2).interpolate(&So2::from_angle(0.6), 0.5);
    /// assert!((mid.angle() - 0.4).abs() < 1e-15);
    /// ```
    fn interpolate(&self, other: &Self, t: f64) -> Self {
        self.rplus(&(other.rminus(self) * t))
    }

    /// Jacobians of Z = X · Y: ∂Z/∂X = Ad_Y⁻¹ = Ad_{Y⁻¹}, ∂Z/∂Y = I (Solà eqs. 170–171).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use nalgebra::{Matrix6, Vector6};
    /// let y = Se3::exp(&Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.5));
    /// let j = Se3::identity().compose_jacobians(&y);
    /// assert_eq!(j.wrt_rhs, Matrix6::identity());
    /// assert!((j.wrt_lhs - y.inverse().adj()).norm() < 1e-15);
    /// ```
    fn compose_jacobians(&self, other: &Self) -> BinaryJacobians<N> {
        BinaryJacobians {
            wrt_lhs: other.inverse().adj(),
            wrt_rhs: TangentMatrix::<N>::identity(),
        }
    }

    /// Jacobian of X⁻¹ with respect to X: −Ad_X (Solà eq. 160).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use nalgebra::Vector3;
    /// let x = So3::exp(&Vector3::new(0.1, 0.2, 0.3));
    /// assert!((x.inverse_jacobian() + x.adj()).norm() < 1e-15);
    /// ```
    fn inverse_jacobian(&self) -> TangentMatrix<N> {
        -self.adj()
    }

    /// Jacobians of Z = X⁻¹ · Y: ∂Z/∂X = −Ad_{Z⁻¹} = −Ad_{Y⁻¹X}, ∂Z/∂Y = I
    /// (from (X Exp δ)⁻¹ Y = Exp(−δ) Z = Z Exp(−Ad_{Z⁻¹} δ)).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// let x = Se2::from_xy_theta(1.0, 2.0, 0.3);
    /// let y = Se2::from_xy_theta(-1.0, 0.5, 1.3);
    /// let j = x.between_jacobians(&y);
    /// assert!((j.wrt_lhs + y.between(&x).adj()).norm() < 1e-14);
    /// ```
    fn between_jacobians(&self, other: &Self) -> BinaryJacobians<N> {
        BinaryJacobians {
            wrt_lhs: -other.between(self).adj(),
            wrt_rhs: TangentMatrix::<N>::identity(),
        }
    }

    /// Jacobians of Y = X ⊕ τ: ∂Y/∂X = Ad_{Exp τ}⁻¹, ∂Y/∂τ = Jr(τ) (Solà eqs. 179a–b).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use nalgebra::Vector3;
    /// let t = Vector3::new(0.3, 0.0, 0.1);
    /// let j = So3::identity().rplus_jacobians(&t);
    /// assert!((j.wrt_tangent - So3::jr(&t)).norm() < 1e-15);
    /// ```
    fn rplus_jacobians(&self, tau: &Tangent<N>) -> RplusJacobians<N> {
        RplusJacobians {
            wrt_group: Self::exp(&-tau).adj(),
            wrt_tangent: Self::jr(tau),
        }
    }

    /// Jacobians of τ = Y ⊖ X (`self` = Y, `other` = X): ∂τ/∂Y = Jr⁻¹(τ), ∂τ/∂X = −Jl⁻¹(τ)
    /// (Solà eqs. 180a–b). `wrt_lhs` is with respect to Y, `wrt_rhs` with respect to X.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// use nalgebra::Vector6;
    /// let x = Se3::identity();
    /// let y = Se3::exp(&Vector6::new(0.5, 0.0, 0.0, 0.0, 0.2, 0.0));
    /// let j = y.rminus_jacobians(&x);
    /// assert!((j.wrt_lhs - Se3::jr_inv(&y.log())).norm() < 1e-15);
    /// ```
    fn rminus_jacobians(&self, other: &Self) -> BinaryJacobians<N> {
        let tau = self.rminus(other);
        BinaryJacobians {
            wrt_lhs: Self::jr_inv(&tau),
            wrt_rhs: -Self::jl_inv(&tau),
        }
    }

    /// Jacobian of Exp at τ (right perturbation of the output): Jr(τ) (Solà eq. 41).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use nalgebra::Vector3;
    /// let t = Vector3::new(1.0, 2.0, 0.5);
    /// assert_eq!(Se2::exp_jacobian(&t), Se2::jr(&t));
    /// ```
    fn exp_jacobian(tau: &Tangent<N>) -> TangentMatrix<N> {
        Self::jr(tau)
    }

    /// Jacobian of Log at X (right perturbation of the input): Jr⁻¹(Log X) (Solà eq. 161).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use nalgebra::Vector3;
    /// let x = So3::exp(&Vector3::new(0.1, 0.2, 0.3));
    /// assert!((x.log_jacobian() * So3::jr(&x.log()) - nalgebra::Matrix3::identity()).norm() < 1e-14);
    /// ```
    fn log_jacobian(&self) -> TangentMatrix<N> {
        Self::jr_inv(&self.log())
    }

    /// True when `other ⊖ self` is shorter than `tolerance` (a metric comparison that does not
    /// depend on the storage, e.g. q and −q).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// assert!(So2::from_angle(1.0).is_approx(&So2::from_angle(1.0 + 1e-12), 1e-9));
    /// ```
    fn is_approx(&self, other: &Self, tolerance: f64) -> bool {
        other.rminus(self).norm() <= tolerance
    }
}

/// Validates a rotation matrix of any size: finite, orthonormal within `tolerance`
/// (max |RᵀR − I|), determinant +1 within `tolerance`.
pub(crate) fn check_rotation_matrix<const D: usize>(
    what: &'static str,
    r: &SMatrix<f64, D, D>,
    tolerance: f64,
) -> crate::Result<()>
where
    nalgebra::Const<D>: nalgebra::DimMin<nalgebra::Const<D>, Output = nalgebra::Const<D>>,
{
    crate::error::check_finite(what, r.transpose().iter().copied())?;
    let deviation = (r.transpose() * r - SMatrix::<f64, D, D>::identity()).amax();
    let determinant = r.determinant();
    if determinant < 0.0 {
        return Err(crate::Error::NotRightHanded { what, determinant });
    }
    if deviation > tolerance {
        return Err(crate::Error::NotOrthonormal {
            what,
            deviation,
            tolerance,
        });
    }
    if (determinant - 1.0).abs() > tolerance {
        return Err(crate::Error::NotRightHanded { what, determinant });
    }
    Ok(())
}

/// The tolerance on orthonormality (max |RᵀR − I|) and on det R = 1 that matrix constructors
/// accept; within it the rotation is re-orthonormalised, beyond it the matrix is rejected.
pub const ROTATION_MATRIX_TOLERANCE: f64 = 1e-6;

/// How far from 1 a quaternion's norm may be and still be normalised (rounded inputs such as
/// four-decimal values); beyond it the quaternion is rejected.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;
