//! SO(2), rotations of the plane.
//!
//! # Overview
//! | | |
//! |---|---|
//! | DOF | 1 |
//! | storage | unit complex number (nalgebra `UnitComplex`: cos θ + i sin θ) |
//! | tangent | θ (radians) |
//! | matrix | 2×2 rotation matrix |
//!
//! SO(2) is commutative: Ad = 1, ad = 0, Jr = Jl = 1 (Solà et al. 2018 §A).

use std::fmt;

use nalgebra::{Matrix1, Matrix2, Matrix2x1, Rotation2, UnitComplex, Vector1, Vector2};

use super::{ActJacobians, LieGroup, ROTATION_MATRIX_TOLERANCE, Tangent, TangentMatrix};
use crate::error::Result;

/// A planar rotation, an element of SO(2).
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use nalgebra::Vector2;
/// let r = So2::from_angle(std::f64::consts::FRAC_PI_2);
/// assert!((r.act(&Vector2::x()) - Vector2::y()).norm() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct So2 {
    complex: UnitComplex<f64>,
}

/// The 90° rotation [[0, −1], [1, 0]] = hat(1): hat(θ) p = θ · (−p_y, p_x).
#[inline]
fn perp(p: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-p.y, p.x)
}

impl So2 {
    /// Rotation by `angle` radians (counter-clockwise).
    ///
    /// ```
    /// use posecov::lie::So2;
    /// assert!((So2::from_angle(0.25).angle() - 0.25).abs() < 1e-16);
    /// ```
    #[inline]
    pub fn from_angle(angle: f64) -> Self {
        Self {
            complex: UnitComplex::new(angle),
        }
    }

    /// From cos θ and sin θ already computed (and of unit norm): saves the trigonometry when a
    /// caller needs both anyway (SE(2) Exp).
    #[inline]
    pub(crate) fn from_cos_sin_unchecked(cos_theta: f64, sin_theta: f64) -> Self {
        Self {
            complex: UnitComplex::from_cos_sin_unchecked(cos_theta, sin_theta),
        }
    }

    /// The angle in (−π, π].
    ///
    /// ```
    /// use posecov::lie::So2;
    /// assert!((So2::from_angle(3.0 * std::f64::consts::PI).angle() - std::f64::consts::PI).abs() < 1e-12);
    /// ```
    #[inline]
    pub fn angle(&self) -> f64 {
        self.complex.angle()
    }

    /// The stored unit complex number.
    ///
    /// ```
    /// use posecov::lie::So2;
    /// assert_eq!(So2::from_angle(0.0).complex().re, 1.0);
    /// ```
    #[inline]
    pub fn complex(&self) -> &UnitComplex<f64> {
        &self.complex
    }

    /// From a 2×2 rotation matrix, validated like [`So3::try_from_matrix`](super::So3::try_from_matrix).
    ///
    /// ```
    /// use posecov::lie::So2;
    /// use nalgebra::Matrix2;
    /// assert!(So2::try_from_matrix(&Matrix2::new(0.0, -1.0, 1.0, 0.0)).is_ok());
    /// assert!(So2::try_from_matrix(&Matrix2::new(1.0, 0.0, 0.0, -1.0)).is_err());
    /// ```
    pub fn try_from_matrix(r: &Matrix2<f64>) -> Result<Self> {
        super::check_rotation_matrix("rotation matrix", r, ROTATION_MATRIX_TOLERANCE)?;
        Ok(Self::from_angle(r[(1, 0)].atan2(r[(0, 0)])))
    }

    /// As a nalgebra `Rotation2`.
    ///
    /// ```
    /// use posecov::lie::So2;
    /// assert!((So2::from_angle(0.5).to_rotation2().angle() - 0.5).abs() < 1e-16);
    /// ```
    #[inline]
    pub fn to_rotation2(&self) -> Rotation2<f64> {
        self.complex.to_rotation_matrix()
    }
}

impl LieGroup<1> for So2 {
    type Point = Vector2<f64>;
    type Matrix = Matrix2<f64>;
    type ActJacobian = Matrix2x1<f64>;
    type PointJacobian = Matrix2<f64>;
    const NAME: &'static str = "SO(2)";
    const KIND: super::GroupKind = super::GroupKind::So2;

    #[inline]
    fn identity() -> Self {
        Self::from_angle(0.0)
    }

    #[inline]
    fn compose(&self, other: &Self) -> Self {
        Self {
            complex: self.complex * other.complex,
        }
    }

    #[inline]
    fn inverse(&self) -> Self {
        Self {
            complex: self.complex.inverse(),
        }
    }

    /// Exp(θ) = cos θ + i sin θ (Solà eq. 81).
    #[inline]
    fn exp(theta: &Tangent<1>) -> Self {
        Self::from_angle(theta.x)
    }

    /// Log(z) = atan2(Im z, Re z) ∈ (−π, π] (Solà eq. 82).
    #[inline]
    fn log(&self) -> Tangent<1> {
        Vector1::new(self.angle())
    }

    #[inline]
    fn hat(theta: &Tangent<1>) -> Matrix2<f64> {
        Matrix2::new(0.0, -theta.x, theta.x, 0.0)
    }

    #[inline]
    fn vee(algebra: &Matrix2<f64>) -> Tangent<1> {
        Vector1::new(algebra[(1, 0)])
    }

    /// Ad = 1 (SO(2) is commutative).
    #[inline]
    fn adj(&self) -> TangentMatrix<1> {
        Matrix1::identity()
    }

    /// ad = 0.
    #[inline]
    fn ad(_theta: &Tangent<1>) -> TangentMatrix<1> {
        Matrix1::zeros()
    }

    /// Jr = 1.
    #[inline]
    fn jr(_theta: &Tangent<1>) -> TangentMatrix<1> {
        Matrix1::identity()
    }

    /// Jr⁻¹ = 1.
    #[inline]
    fn jr_inv(_theta: &Tangent<1>) -> TangentMatrix<1> {
        Matrix1::identity()
    }

    #[inline]
    fn act(&self, point: &Vector2<f64>) -> Vector2<f64> {
        self.complex * point
    }

    /// ∂(R p)/∂θ = R · (−p_y, p_x)ᵀ, ∂(R p)/∂p = R (Solà eq. 153).
    #[inline]
    fn act_jacobians(&self, point: &Vector2<f64>) -> ActJacobians<Matrix2x1<f64>, Matrix2<f64>> {
        ActJacobians {
            wrt_group: self.complex * perp(point),
            wrt_point: self.to_matrix(),
        }
    }

    #[inline]
    fn rotate(&self, direction: &Vector2<f64>) -> Vector2<f64> {
        self.complex * direction
    }

    #[inline]
    fn to_matrix(&self) -> Matrix2<f64> {
        self.to_rotation2().into_inner()
    }

    fn to_se3(&self) -> super::Se3 {
        super::Se3::from_parts(
            nalgebra::Vector3::zeros(),
            super::So3::from_rpy(0.0, 0.0, self.angle()),
        )
    }
}

impl fmt::Display for So2 {
    /// `SO(2) θ = … deg`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SO(2) θ = {:.3} deg", self.angle().to_degrees())
    }
}
