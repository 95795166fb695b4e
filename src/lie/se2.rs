//! SE(2), rigid motions of the plane.
//!
//! # Overview
//! | | |
//! |---|---|
//! | DOF | 3 |
//! | storage | rotation [`So2`] (unit complex) + translation t ∈ ℝ² |
//! | tangent | τ = [ρx, ρy, θ], translation part first |
//! | matrix | 3×3 homogeneous [[R, t], [0, 0, 1]] |
//!
//! Closed forms from Solà et al. 2018 §C (eqs. 156–166), with a = sin θ/θ and
//! b = (1 − cos θ)/θ = θ A(θ) on their small-angle branches.

use std::fmt;

use nalgebra::{Isometry2, Matrix2, Matrix2x3, Matrix3, Translation2, Vector2, Vector3};

use super::series::{
    half_theta_cot_half_theta, one_minus_cos_by_theta2, sinc, theta_minus_sin_by_theta3,
};
use super::{ActJacobians, LieGroup, So2, Tangent, TangentMatrix};
use crate::error::{Error, Result, check_finite};

/// A planar rigid transform, an element of SE(2): p ↦ R(θ) p + t.
///
/// ```
/// use posecov::lie::{LieGroup, Se2};
/// use nalgebra::Vector2;
/// let world_from_robot = Se2::from_xy_theta(1.0, 2.0, std::f64::consts::FRAC_PI_2);
/// let p_in_world = world_from_robot.act(&Vector2::new(1.0, 0.0));
/// assert!((p_in_world - Vector2::new(1.0, 3.0)).norm() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se2 {
    rotation: So2,
    translation: Vector2<f64>,
}

/// The SE(2) "V" block of Exp, V(θ) = [[a, −b], [b, a]] with a = sin θ/θ, b = (1 − cos θ)/θ,
/// from θ and its cos and sin (computed once by the caller); Taylor branches below
/// [`SMALL_ANGLE`](super::series::SMALL_ANGLE).
#[inline]
fn v_matrix(theta: f64, cos_theta: f64, sin_theta: f64) -> Matrix2<f64> {
    let (a, b) = if theta.abs() < super::series::SMALL_ANGLE {
        (sinc(theta), theta * one_minus_cos_by_theta2(theta))
    } else {
        (sin_theta / theta, (1.0 - cos_theta) / theta)
    };
    Matrix2::new(a, -b, b, a)
}

/// V(θ)⁻¹ = [[h, θ/2], [−θ/2, h]] with h = (θ/2) cot(θ/2): finite at θ = ±π.
#[inline]
fn v_inverse(theta: f64, cos_theta: f64, sin_theta: f64) -> Matrix2<f64> {
    let h = half_theta_cot_half_theta(theta, cos_theta, sin_theta);
    let half = 0.5 * theta;
    Matrix2::new(h, half, -half, h)
}

impl Se2 {
    /// From position (x, y) and heading θ (radians).
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// let x = Se2::from_xy_theta(1.0, 2.0, 0.5);
    /// assert_eq!((x.x(), x.y()), (1.0, 2.0));
    /// assert!((x.theta() - 0.5).abs() < 1e-16);
    /// ```
    #[inline]
    pub fn from_xy_theta(x: f64, y: f64, theta: f64) -> Self {
        Self::from_parts(Vector2::new(x, y), So2::from_angle(theta))
    }

    /// From a translation and a rotation.
    ///
    /// ```
    /// use posecov::lie::{Se2, So2};
    /// use nalgebra::Vector2;
    /// assert_eq!(Se2::from_parts(Vector2::new(1.0, 0.0), So2::from_angle(0.0)).x(), 1.0);
    /// ```
    #[inline]
    pub fn from_parts(translation: Vector2<f64>, rotation: So2) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// From a 3×3 homogeneous matrix, validated: finite, last row exactly [0, 0, 1],
    /// rotation block orthonormal with det +1.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use nalgebra::Matrix3;
    /// let m = Matrix3::new(0.0, -1.0, 1.0, 1.0, 0.0, 2.0, 0.0, 0.0, 1.0);
    /// assert!((Se2::try_from_matrix(&m).unwrap().theta() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    /// let bad = Matrix3::new(0.0, -1.0, 1.0, 1.0, 0.0, 2.0, 0.0, 0.0, 2.0);
    /// assert!(Se2::try_from_matrix(&bad).is_err());
    /// ```
    pub fn try_from_matrix(m: &Matrix3<f64>) -> Result<Self> {
        check_finite("homogeneous matrix", m.transpose().iter().copied())?;
        let last_row = [m[(2, 0)], m[(2, 1)], m[(2, 2)]];
        if last_row != [0.0, 0.0, 1.0] {
            return Err(Error::BadLastRow {
                what: "homogeneous matrix",
                row: last_row.to_vec(),
            });
        }
        let rotation = So2::try_from_matrix(&m.fixed_view::<2, 2>(0, 0).into_owned())?;
        Ok(Self::from_parts(
            m.fixed_view::<2, 1>(0, 2).into_owned(),
            rotation,
        ))
    }

    /// x of the translation.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// assert_eq!(Se2::from_xy_theta(3.0, 0.0, 0.0).x(), 3.0);
    /// ```
    #[inline]
    pub fn x(&self) -> f64 {
        self.translation.x
    }

    /// y of the translation.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// assert_eq!(Se2::from_xy_theta(0.0, 3.0, 0.0).y(), 3.0);
    /// ```
    #[inline]
    pub fn y(&self) -> f64 {
        self.translation.y
    }

    /// Heading θ ∈ (−π, π].
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// assert!((Se2::from_xy_theta(0.0, 0.0, -0.5).theta() + 0.5).abs() < 1e-16);
    /// ```
    #[inline]
    pub fn theta(&self) -> f64 {
        self.rotation.angle()
    }

    /// The rotation part.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2, So2};
    /// assert_eq!(Se2::identity().rotation(), &So2::identity());
    /// ```
    #[inline]
    pub fn rotation(&self) -> &So2 {
        &self.rotation
    }

    /// The translation part t.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// assert_eq!(Se2::from_xy_theta(1.0, 2.0, 0.0).translation().y, 2.0);
    /// ```
    #[inline]
    pub fn translation(&self) -> &Vector2<f64> {
        &self.translation
    }

    /// As a nalgebra isometry.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// let x = Se2::from_xy_theta(1.0, 2.0, 0.3);
    /// assert_eq!(Se2::from_isometry(&x.to_isometry()), x);
    /// ```
    #[inline]
    pub fn to_isometry(&self) -> Isometry2<f64> {
        Isometry2::from_parts(
            Translation2::from(self.translation),
            *self.rotation.complex(),
        )
    }

    /// From a nalgebra isometry.
    ///
    /// ```
    /// use posecov::lie::Se2;
    /// use nalgebra::Isometry2;
    /// assert_eq!(Se2::from_isometry(&Isometry2::new(nalgebra::Vector2::new(1.0, 0.0), 0.0)).x(), 1.0);
    /// ```
    #[inline]
    pub fn from_isometry(iso: &Isometry2<f64>) -> Self {
        Self::from_parts(
            iso.translation.vector,
            So2::from_angle(iso.rotation.angle()),
        )
    }
}

impl LieGroup<3> for Se2 {
    type Point = Vector2<f64>;
    type Matrix = Matrix3<f64>;
    type ActJacobian = Matrix2x3<f64>;
    type PointJacobian = Matrix2<f64>;
    const NAME: &'static str = "SE(2)";
    const KIND: super::GroupKind = super::GroupKind::Se2;

    #[inline]
    fn identity() -> Self {
        Self::from_xy_theta(0.0, 0.0, 0.0)
    }

    /// (R₁, t₁)(R₂, t₂) = (R₁R₂, t₁ + R₁t₂).
    #[inline]
    fn compose(&self, other: &Self) -> Self {
        Self::from_parts(
            self.translation + self.rotation.act(&other.translation),
            self.rotation.compose(&other.rotation),
        )
    }

    /// (R, t)⁻¹ = (Rᵀ, −Rᵀt).
    #[inline]
    fn inverse(&self) -> Self {
        let r_inv = self.rotation.inverse();
        Self::from_parts(-r_inv.act(&self.translation), r_inv)
    }

    /// Exp([ρ; θ]) = (R(θ), V(θ) ρ), V = [[a, −b], [b, a]] (Solà eq. 156).
    #[inline]
    fn exp(tau: &Tangent<3>) -> Self {
        let rho = Vector2::new(tau.x, tau.y);
        let (sin_theta, cos_theta) = tau.z.sin_cos();
        let rotation = So2::from_cos_sin_unchecked(cos_theta, sin_theta);
        Self::from_parts(v_matrix(tau.z, cos_theta, sin_theta) * rho, rotation)
    }

    /// Log(R, t) = [V(θ)⁻¹ t; θ], θ = atan2 ∈ (−π, π] (Solà eq. 157).
    #[inline]
    fn log(&self) -> Tangent<3> {
        let theta = self.theta();
        let z = self.rotation.complex();
        let rho = v_inverse(theta, z.re, z.im) * self.translation;
        Vector3::new(rho.x, rho.y, theta)
    }

    #[inline]
    fn hat(tau: &Tangent<3>) -> Matrix3<f64> {
        Matrix3::new(0.0, -tau.z, tau.x, tau.z, 0.0, tau.y, 0.0, 0.0, 0.0)
    }

    #[inline]
    fn vee(algebra: &Matrix3<f64>) -> Tangent<3> {
        Vector3::new(algebra[(0, 2)], algebra[(1, 2)], algebra[(1, 0)])
    }

    /// Ad = [[R, (t_y, −t_x)ᵀ], [0, 0, 1]] (Solà eq. 159).
    #[inline]
    fn adj(&self) -> TangentMatrix<3> {
        let r = self.rotation.to_matrix();
        let t = &self.translation;
        Matrix3::new(
            r[(0, 0)],
            r[(0, 1)],
            t.y,
            r[(1, 0)],
            r[(1, 1)],
            -t.x,
            0.0,
            0.0,
            1.0,
        )
    }

    /// ad_\[ρ;θ\] = [[0, −θ, ρy], [θ, 0, −ρx], [0, 0, 0]] (derivative of Ad at the identity).
    #[inline]
    fn ad(tau: &Tangent<3>) -> TangentMatrix<3> {
        Matrix3::new(0.0, -tau.z, tau.y, tau.z, 0.0, -tau.x, 0.0, 0.0, 0.0)
    }

    /// Jr = [[a, b, ρx θB − ρy A], [−b, a, ρx A + ρy θB], [0, 0, 1]] (Solà eq. 163, with
    /// (θρx − ρy + ρy cos θ − ρx sin θ)/θ² written as ρx θB − ρy A so it is finite at θ = 0).
    #[inline]
    fn jr(tau: &Tangent<3>) -> TangentMatrix<3> {
        let (x, y, th) = (tau.x, tau.y, tau.z);
        let (a, big_a, th_b) = (
            sinc(th),
            one_minus_cos_by_theta2(th),
            th * theta_minus_sin_by_theta3(th),
        );
        let b = th * big_a;
        Matrix3::new(
            a,
            b,
            x * th_b - y * big_a,
            -b,
            a,
            x * big_a + y * th_b,
            0.0,
            0.0,
            1.0,
        )
    }

    /// Jr⁻¹ = [[M⁻¹, −M⁻¹ m], [0, 1]] for Jr = [[M, m], [0, 1]], M⁻¹ = [[a, −b], [b, a]]/(a² + b²)
    /// (a² + b² = sinc²(θ/2) > 0 for |θ| < 2π).
    #[inline]
    fn jr_inv(tau: &Tangent<3>) -> TangentMatrix<3> {
        let jr = Self::jr(tau);
        let (a, b) = (jr[(0, 0)], jr[(0, 1)]);
        let m_inv = Matrix2::new(a, -b, b, a) / (a * a + b * b);
        let col = -m_inv * Vector2::new(jr[(0, 2)], jr[(1, 2)]);
        Matrix3::new(
            m_inv[(0, 0)],
            m_inv[(0, 1)],
            col.x,
            m_inv[(1, 0)],
            m_inv[(1, 1)],
            col.y,
            0.0,
            0.0,
            1.0,
        )
    }

    #[inline]
    fn act(&self, point: &Vector2<f64>) -> Vector2<f64> {
        self.rotation.act(point) + self.translation
    }

    /// ∂(R p + t)/∂X = [R, R (−p_y, p_x)ᵀ], ∂(R p + t)/∂p = R (Solà eq. 166).
    #[inline]
    fn act_jacobians(&self, point: &Vector2<f64>) -> ActJacobians<Matrix2x3<f64>, Matrix2<f64>> {
        let r = self.rotation.to_matrix();
        let col = r * Vector2::new(-point.y, point.x);
        ActJacobians {
            wrt_group: Matrix2x3::new(r[(0, 0)], r[(0, 1)], col.x, r[(1, 0)], r[(1, 1)], col.y),
            wrt_point: r,
        }
    }

    #[inline]
    fn rotate(&self, direction: &Vector2<f64>) -> Vector2<f64> {
        self.rotation.act(direction)
    }

    #[inline]
    fn to_matrix(&self) -> Matrix3<f64> {
        let r = self.rotation.to_matrix();
        let t = &self.translation;
        Matrix3::new(
            r[(0, 0)],
            r[(0, 1)],
            t.x,
            r[(1, 0)],
            r[(1, 1)],
            t.y,
            0.0,
            0.0,
            1.0,
        )
    }

    fn to_se3(&self) -> super::Se3 {
        let t = self.translation();
        super::Se3::from_parts(
            nalgebra::Vector3::new(t.x, t.y, 0.0),
            super::So3::from_rpy(0.0, 0.0, self.theta()),
        )
    }
}

impl fmt::Display for Se2 {
    /// `SE(2) x = …, y = …, θ = … deg`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "SE(2) x = {:.6}, y = {:.6}, θ = {:.3} deg",
            self.x(),
            self.y(),
            self.theta().to_degrees()
        )
    }
}
