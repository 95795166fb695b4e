//! SE(3), rigid motions of 3D space.
//!
//! # Overview
//! | | |
//! |---|---|
//! | DOF | 6 |
//! | storage | rotation [`So3`] (unit quaternion) + translation t ∈ ℝ³ |
//! | tangent | ξ = [ρ; θ], translation part first (ROS, Solà, Barfoot & Furgale order) |
//! | matrix | 4×4 homogeneous [[R, t], [0, 1]] |
//!
//! Closed forms from Solà et al. 2018 §D and Barfoot & Furgale 2014 (IEEE T-RO 30(3)),
//! eqs. 100–102 for the Jacobians with Q(ρ, θ).

use std::fmt;

use nalgebra::{Isometry3, Matrix3, Matrix3x6, Matrix4, Matrix6, Translation3, Vector3, Vector6};

use super::series::{
    SMALL_ANGLE, jinv_coefficient, one_minus_cos_by_theta2_taylor, q_coefficient_2,
    q_coefficient_3, sinc_taylor, theta_minus_sin_by_theta3, theta_minus_sin_by_theta3_taylor,
};
use super::{ActJacobians, LieGroup, So3, Tangent, TangentMatrix};
use crate::error::{Error, Result, check_finite};

/// A 3D rigid transform, an element of SE(3): p ↦ R p + t.
///
/// ```
/// use posecov::lie::{LieGroup, Se3, So3};
/// use nalgebra::Vector3;
/// let world_from_body = Se3::from_parts(Vector3::new(1.0, 2.0, 0.0), So3::from_rpy(0.0, 0.0, 0.5));
/// let p_in_world = world_from_body.act(&Vector3::zeros());
/// assert_eq!(p_in_world, Vector3::new(1.0, 2.0, 0.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3 {
    rotation: So3,
    translation: Vector3<f64>,
}

/// Splits ξ = [ρ; θ] into (ρ, θ).
#[inline]
fn split(xi: &Tangent<6>) -> (Vector3<f64>, Vector3<f64>) {
    (
        xi.fixed_rows::<3>(0).into_owned(),
        xi.fixed_rows::<3>(3).into_owned(),
    )
}

/// Builds the block upper-triangular matrix [[a, b], [0, a]].
#[inline]
fn upper_block(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(a);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(b);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(a);
    m
}

impl Se3 {
    /// From a translation and a rotation: p ↦ R p + t.
    ///
    /// ```
    /// use posecov::lie::{Se3, So3};
    /// use nalgebra::Vector3;
    /// let x = Se3::from_parts(Vector3::new(1.0, 0.0, 0.0), So3::from_rpy(0.0, 0.0, 0.0));
    /// assert_eq!(x.translation(), &Vector3::new(1.0, 0.0, 0.0));
    /// ```
    #[inline]
    pub fn from_parts(translation: Vector3<f64>, rotation: So3) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// From position (x, y, z) and roll, pitch, yaw (radians; R = Rz(yaw) Ry(pitch) Rx(roll)).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// let x = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0, 0.0, 0.3]);
    /// assert!((x.rotation().to_rpy()[2] - 0.3).abs() < 1e-15);
    /// ```
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        Self::from_parts(Vector3::from(xyz), So3::from_rpy(rpy[0], rpy[1], rpy[2]))
    }

    /// From position (x, y, z) and a quaternion in ROS order (x, y, z, w); see
    /// [`So3::try_from_quaternion_xyzw`] for what is normalised and what is rejected.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// let x = Se3::try_from_xyz_quaternion_xyzw([1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0]).unwrap();
    /// assert_eq!(x.translation().x, 1.0);
    /// assert!(Se3::try_from_xyz_quaternion_xyzw([f64::NAN, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]).is_err());
    /// ```
    pub fn try_from_xyz_quaternion_xyzw(xyz: [f64; 3], xyzw: [f64; 4]) -> Result<Self> {
        check_finite("position (x, y, z)", xyz)?;
        Ok(Self::from_parts(
            Vector3::from(xyz),
            So3::try_from_quaternion_xyzw(xyzw)?,
        ))
    }

    /// From a 4×4 homogeneous matrix, validated: finite, last row exactly [0, 0, 0, 1], rotation
    /// block orthonormal with det +1 (see [`So3::try_from_matrix`]).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use nalgebra::Matrix4;
    /// let mut m = Matrix4::identity();
    /// m[(0, 3)] = 2.0;
    /// assert_eq!(Se3::try_from_matrix(&m).unwrap().translation().x, 2.0);
    /// m[(3, 0)] = 1e-3;
    /// assert!(Se3::try_from_matrix(&m).is_err());
    /// ```
    pub fn try_from_matrix(m: &Matrix4<f64>) -> Result<Self> {
        check_finite("homogeneous matrix", m.transpose().iter().copied())?;
        let last_row = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)]];
        if last_row != [0.0, 0.0, 0.0, 1.0] {
            return Err(Error::BadLastRow {
                what: "homogeneous matrix",
                row: last_row.to_vec(),
            });
        }
        let rotation = So3::try_from_matrix(&m.fixed_view::<3, 3>(0, 0).into_owned())?;
        Ok(Self::from_parts(
            m.fixed_view::<3, 1>(0, 3).into_owned(),
            rotation,
        ))
    }

    /// The rotation part R.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3, So3};
    /// assert_eq!(Se3::identity().rotation(), &So3::identity());
    /// ```
    #[inline]
    pub fn rotation(&self) -> &So3 {
        &self.rotation
    }

    /// The translation part t (the body origin in the parent frame).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se3};
    /// assert_eq!(Se3::identity().translation().norm(), 0.0);
    /// ```
    #[inline]
    pub fn translation(&self) -> &Vector3<f64> {
        &self.translation
    }

    /// Q(ρ, θ) of Barfoot & Furgale 2014, eq. 102: the off-diagonal block of the SE(3) left
    /// Jacobian, Jl([ρ; θ]) = [[Jl(θ), Q(ρ, θ)], [0, Jl(θ)]]:
    ///
    /// Q = ½ ρ^ + B (θ^ρ^ + ρ^θ^ + θ^ρ^θ^) + c₂ (θ^θ^ρ^ + ρ^θ^θ^ − 3 θ^ρ^θ^)
    ///     + c₃ (θ^ρ^θ^θ^ + θ^θ^ρ^θ^),
    /// with B = (φ − sin φ)/φ³, c₂ = (φ² + 2 cos φ − 2)/(2φ⁴), c₃ = (2φ − 3 sin φ + φ cos φ)/(2φ⁵), φ = |θ|.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use nalgebra::Vector3;
    /// // At θ = 0, Q = ½ ρ^.
    /// let q = Se3::q_matrix(&Vector3::new(1.0, 2.0, 3.0), &Vector3::zeros());
    /// assert!((q[(0, 1)] + 1.5).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn q_matrix(rho: &Vector3<f64>, theta: &Vector3<f64>) -> Matrix3<f64> {
        let angle = theta.norm();
        let (r, t) = (So3::skew(rho), So3::skew(theta));
        let (tr, rt, trt) = (t * r, r * t, t * r * t);
        r * 0.5
            + (tr + rt + trt) * theta_minus_sin_by_theta3(angle)
            + (t * tr + rt * t - trt * 3.0) * q_coefficient_2(angle)
            + (trt * t + t * trt) * q_coefficient_3(angle)
    }

    /// As a nalgebra isometry.
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// let x = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
    /// assert_eq!(Se3::from_isometry(&x.to_isometry()), x);
    /// ```
    #[inline]
    pub fn to_isometry(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::from(self.translation),
            *self.rotation.quaternion(),
        )
    }

    /// From a nalgebra isometry (its quaternion is unit by construction).
    ///
    /// ```
    /// use posecov::lie::Se3;
    /// use nalgebra::Isometry3;
    /// let iso = Isometry3::translation(1.0, 0.0, 0.0);
    /// assert_eq!(Se3::from_isometry(&iso).translation().x, 1.0);
    /// ```
    #[inline]
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        Self::from_parts(iso.translation.vector, So3::from_quaternion(iso.rotation))
    }
}

impl LieGroup<6> for Se3 {
    type Point = Vector3<f64>;
    type Matrix = Matrix4<f64>;
    type ActJacobian = Matrix3x6<f64>;
    type PointJacobian = Matrix3<f64>;
    const NAME: &'static str = "SE(3)";
    const KIND: super::GroupKind = super::GroupKind::Se3;

    #[inline]
    fn identity() -> Self {
        Self::from_parts(Vector3::zeros(), So3::identity())
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

    /// Exp([ρ; θ]) = (Exp(θ), Jl(θ) ρ) (Solà eq. 172; V = Jl of SO(3)), with
    /// Jl(θ) ρ = ρ + A θ×ρ + B θ×(θ×ρ) (Solà eq. 174, Jl applied without building 3×3
    /// matrices), A = (1 − cos θ)/θ², B = (θ − sin θ)/θ³, θ = |θ|.
    ///
    /// One `sin_cos` of θ/2 serves the quaternion and both coefficients: 1 − cos θ = 2 sin²(θ/2)
    /// and sin θ = 2 sin(θ/2) cos(θ/2) (double-angle identities; see
    /// [`theta_minus_sin_by_theta3_from_sin`](super::series::theta_minus_sin_by_theta3_from_sin)
    /// for the error of B). Below [`SMALL_ANGLE`] A and B take their Taylor series (θ − sin θ
    /// cancels there), and so does the quaternion's sinc(θ/2) below θ/2 = [`SMALL_ANGLE`],
    /// exactly as in [`So3::exp`] (the rotation is bit-identical to it).
    #[inline]
    fn exp(xi: &Tangent<6>) -> Self {
        let (rho, theta) = split(xi);
        let angle = theta.norm();
        let half = 0.5 * angle;
        let (sin_half, cos_half) = half.sin_cos();
        // Both forms first, then the choice: written this way (not through the `_from_sin`
        // helpers, whose sine is used only on their closed-form side) LLVM keeps sin and cos
        // in one block and calls `sincos` once instead of `sin` and `cos` apart.
        let k_closed = sin_half / half;
        let a_closed = 2.0 * sin_half * sin_half / (angle * angle);
        let b_closed = (angle - 2.0 * sin_half * cos_half) / (angle * angle * angle);
        let k = 0.5
            * if half < SMALL_ANGLE {
                sinc_taylor(half)
            } else {
                k_closed
            };
        let (a, b) = if angle < SMALL_ANGLE {
            (
                one_minus_cos_by_theta2_taylor(angle),
                theta_minus_sin_by_theta3_taylor(angle),
            )
        } else {
            (a_closed, b_closed)
        };
        let theta_x_rho = theta.cross(&rho);
        let translation = rho + theta_x_rho * a + theta.cross(&theta_x_rho) * b;
        Self::from_parts(translation, So3::from_half_angle_terms(&theta, cos_half, k))
    }

    /// Log(R, t) = [Jl(θ)⁻¹ t; θ] with θ = Log(R) (Solà eq. 173), Jl⁻¹ applied without
    /// building 3×3 matrices: Jl(θ)⁻¹ t = t − ½ θ×t + c θ×(θ×t) (Solà eq. 146, as
    /// [`So3::jl_inv`]), c = 1/θ² − cot(θ/2)/(2θ) ([`jinv_coefficient`]). In closed form
    /// cot(θ/2) = w/|v| of the quaternion Log(R) read (θ = 2 atan2(|v|, w)), so Log takes one
    /// atan2 and no sine or cosine; below [`SMALL_ANGLE`] c takes its Taylor series.
    #[inline]
    fn log(&self) -> Tangent<6> {
        let (theta, w, n) = self.rotation.log_with_parts();
        let angle = theta.norm();
        let c = if angle < SMALL_ANGLE {
            jinv_coefficient(angle)
        } else {
            1.0 / (angle * angle) - w / (n * 2.0 * angle)
        };
        let t = self.translation;
        let theta_x_t = theta.cross(&t);
        let rho = t - theta_x_t * 0.5 + theta.cross(&theta_x_t) * c;
        Vector6::new(rho.x, rho.y, rho.z, theta.x, theta.y, theta.z)
    }

    #[inline]
    fn hat(xi: &Tangent<6>) -> Matrix4<f64> {
        let (rho, theta) = split(xi);
        let mut m = Matrix4::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&So3::skew(&theta));
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&rho);
        m
    }

    #[inline]
    fn vee(algebra: &Matrix4<f64>) -> Tangent<6> {
        let theta = So3::vee(&algebra.fixed_view::<3, 3>(0, 0).into_owned());
        Vector6::new(
            algebra[(0, 3)],
            algebra[(1, 3)],
            algebra[(2, 3)],
            theta.x,
            theta.y,
            theta.z,
        )
    }

    /// Ad = [[R, t^R], [0, R]] (Solà eq. 175).
    #[inline]
    fn adj(&self) -> TangentMatrix<6> {
        let r = self.rotation.to_matrix();
        upper_block(&r, &(So3::skew(&self.translation) * r))
    }

    /// ad_\[ρ;θ\] = [[θ^, ρ^], [0, θ^]] (Barfoot & Furgale 2014, eq. 12, translation first).
    #[inline]
    fn ad(xi: &Tangent<6>) -> TangentMatrix<6> {
        let (rho, theta) = split(xi);
        upper_block(&So3::skew(&theta), &So3::skew(&rho))
    }

    /// Jr([ρ; θ]) = Jl([−ρ; −θ]) = [[Jr(θ), Q(−ρ, −θ)], [0, Jr(θ)]] (Barfoot & Furgale 2014, eq. 100).
    #[inline]
    fn jr(xi: &Tangent<6>) -> TangentMatrix<6> {
        let (rho, theta) = split(xi);
        upper_block(&So3::jr(&theta), &Self::q_matrix(&-rho, &-theta))
    }

    /// Jr⁻¹ = [[Jr(θ)⁻¹, −Jr(θ)⁻¹ Q(−ρ, −θ) Jr(θ)⁻¹], [0, Jr(θ)⁻¹]] (block inverse; Barfoot & Furgale 2014, eq. 103).
    #[inline]
    fn jr_inv(xi: &Tangent<6>) -> TangentMatrix<6> {
        let (rho, theta) = split(xi);
        let jr_inv = So3::jr_inv(&theta);
        upper_block(
            &jr_inv,
            &(-jr_inv * Self::q_matrix(&-rho, &-theta) * jr_inv),
        )
    }

    #[inline]
    fn act(&self, point: &Vector3<f64>) -> Vector3<f64> {
        self.rotation.act(point) + self.translation
    }

    /// ∂(R p + t)/∂X = [R, −R p^], ∂(R p + t)/∂p = R (Solà eqs. 181–182).
    #[inline]
    fn act_jacobians(&self, point: &Vector3<f64>) -> ActJacobians<Matrix3x6<f64>, Matrix3<f64>> {
        let r = self.rotation.to_matrix();
        let mut wrt_group = Matrix3x6::zeros();
        wrt_group.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        wrt_group
            .fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-r * So3::skew(point)));
        ActJacobians {
            wrt_group,
            wrt_point: r,
        }
    }

    #[inline]
    fn rotate(&self, direction: &Vector3<f64>) -> Vector3<f64> {
        self.rotation.act(direction)
    }

    #[inline]
    fn to_matrix(&self) -> Matrix4<f64> {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&self.rotation.to_matrix());
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.translation);
        m
    }

    fn to_se3(&self) -> super::Se3 {
        *self
    }
}

impl fmt::Display for Se3 {
    /// `SE(3) t = [x, y, z], rpy = [roll, pitch, yaw] deg`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = &self.translation;
        let [r, p, y] = self.rotation.to_rpy().map(f64::to_degrees);
        write!(
            f,
            "SE(3) t = [{:.6}, {:.6}, {:.6}], rpy = [{r:.3}, {p:.3}, {y:.3}] deg",
            t.x, t.y, t.z
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Se3::exp` (one `sin_cos` of θ/2, sin θ = 2 sin(θ/2) cos(θ/2), V·ρ by cross products)
    /// agrees with the matrix form (So3::exp(θ), Jl(θ) ρ), Jl = I + A θ^ + B θ^² with A, B from
    /// their own `sin` calls, within 1e-12 in every regime: θ = 0, 1e-8, the Taylor branch, both
    /// sides of the switch at 0.1, 1 and π − 1e-6. The rotation is bit-identical to `So3::exp`.
    #[test]
    fn exp_agrees_with_the_matrix_jl_form() {
        let axes = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, -0.5, 0.8),
            Vector3::new(-0.2, 0.9, 0.1),
            Vector3::new(0.0, 0.0, -1.0),
        ];
        let rhos = [
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(-0.5, 0.1, 0.0),
            Vector3::new(100.0, -40.0, 7.0),
        ];
        let switch = crate::lie::series::SMALL_ANGLE;
        let angles = [
            0.0,
            1e-8,
            0.05,
            switch * (1.0 - 1e-15),
            switch,
            switch * (1.0 + 1e-15),
            0.15,
            1.0,
            std::f64::consts::PI - 1e-6,
        ];
        let mut worst: f64 = 0.0;
        for axis in axes {
            for angle in angles {
                let theta = axis.normalize() * angle;
                for rho in rhos {
                    let xi = Vector6::new(rho.x, rho.y, rho.z, theta.x, theta.y, theta.z);
                    let x = Se3::exp(&xi);
                    let expected = So3::jl(&theta) * rho;
                    let err = (x.translation() - expected).amax() / rho.amax();
                    worst = worst.max(err);
                    assert!(err <= 1e-12, "θ = {angle}: relative error {err:e}");
                    assert_eq!(x.rotation(), &So3::exp(&theta));
                }
            }
        }
        eprintln!("Se3::exp vs the matrix Jl form: worst error {worst:e} × max|ρ|");
    }

    #[test]
    fn log_agrees_with_the_matrix_jl_inverse_form() {
        // Log reads cot(θ/2) off the quaternion instead of calling cos and sin: the same
        // numbers as Jl(θ)⁻¹ t with So3::jl_inv, on both sides of the series switch and
        // towards π, and Exp undoes it.
        let switch = crate::lie::series::SMALL_ANGLE;
        let angles = [
            0.0,
            1e-9,
            1e-6,
            0.05,
            switch * (1.0 - 1e-15),
            switch,
            switch * (1.0 + 1e-15),
            0.7,
            2.0,
            std::f64::consts::PI - 1e-6,
        ];
        let axes = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, -0.5, 0.8),
            Vector3::new(0.0, 0.0, -1.0),
        ];
        let ts = [
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(-0.5, 0.1, 0.0),
            Vector3::new(100.0, -40.0, 7.0),
        ];
        for axis in axes {
            for angle in angles {
                let rotation = So3::exp(&(axis.normalize() * angle));
                for t in ts {
                    let x = Se3::from_parts(t, rotation);
                    let xi = x.log();
                    let theta = rotation.log();
                    let expected = So3::jl_inv(&theta) * t;
                    let rho = Vector3::new(xi[0], xi[1], xi[2]);
                    let err = (rho - expected).amax() / t.amax();
                    assert!(err <= 1e-12, "θ = {angle}: relative error {err:e}");
                    assert_eq!(Vector3::new(xi[3], xi[4], xi[5]), theta);
                    let back = Se3::exp(&xi);
                    assert!(
                        (back.translation() - t).amax() <= 1e-12 * t.amax(),
                        "θ = {angle}"
                    );
                }
            }
        }
    }
}
