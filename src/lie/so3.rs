//! SO(3), rotations of 3D space.
//!
//! # Overview
//! | | |
//! |---|---|
//! | DOF | 3 |
//! | storage | unit quaternion (nalgebra `UnitQuaternion`, stored `[i, j, k, w]`) |
//! | tangent | θ ∈ ℝ³, axis · angle, in the body frame for right perturbations |
//! | matrix | 3×3 rotation matrix R |
//!
//! Closed forms from Solà et al. 2018 (arXiv:1812.01537) §B and Barfoot 2017 §7.1; with
//! A(θ) = (1 − cos θ)/θ², B(θ) = (θ − sin θ)/θ³, C(θ) = 1/θ² − cot(θ/2)/(2θ)
//! (see [`series`](crate::lie::series) for their small-angle branches).
//!
//! # Why the exponential map
//! Integrating a constant body rate ω by n Euler steps R ← R (I + ω̂ dt) leaves SO(3): every
//! step stretches the directions orthogonal to ω by √(1 + |ω|² dt²), so RᵀR drifts from I.
//! Stepping with Exp, R ← R · Exp(ω dt), stays on the group to round-off and lands exactly on
//! Exp(n ω dt).
//!
//! ```
//! use posecov::lie::{LieGroup, So3};
//! use nalgebra::{Matrix3, Vector3};
//! let (omega, dt, n) = (Vector3::new(0.3, -0.2, 1.0), 0.01, 1000);
//! let mut r_euler = Matrix3::identity();
//! let mut r_exp = So3::identity();
//! for _ in 0..n {
//!     r_euler *= Matrix3::identity() + So3::hat(&(omega * dt));
//!     r_exp = r_exp.rplus(&(omega * dt));
//! }
//! let drift = |r: &Matrix3<f64>| (r.transpose() * r - Matrix3::identity()).amax();
//! // (1 + 1.13e-4)^1000 ≈ 1.12: RᵀR is 12 % off the identity after 10 s.
//! assert!(drift(&r_euler) > 0.1);
//! assert!(drift(&r_exp.to_matrix()) < 1e-12);
//! assert!(r_exp.is_approx(&So3::exp(&(omega * dt * n as f64)), 1e-12));
//! ```

use std::fmt;

use nalgebra::{Matrix3, Quaternion, Rotation3, Unit, UnitQuaternion, Vector3};

use super::series::{
    SMALL_ANGLE, jinv_coefficient, one_minus_cos_by_theta2, sinc, theta_minus_sin_by_theta3,
};
use super::{
    ActJacobians, LieGroup, QUATERNION_NORM_TOLERANCE, ROTATION_MATRIX_TOLERANCE, Tangent,
    TangentMatrix,
};
use crate::error::{Error, Result, check_finite};

/// Below this norm of the quaternion's vector part |v| = sin(θ/2), [`So3::log`] uses the
/// series 2 atan(x)/x ≈ 2 (1 − x²/3), x = |v|/w, instead of dividing by |v| (exact to f64 there).
pub const LOG_SMALL_VECTOR_PART: f64 = 1e-6;

/// A 3D rotation, an element of SO(3).
///
/// ```
/// use posecov::lie::{LieGroup, So3};
/// use nalgebra::Vector3;
/// let world_from_body = So3::from_rpy(0.0, 0.0, std::f64::consts::FRAC_PI_2);
/// let x_in_world = world_from_body.act(&Vector3::x());
/// assert!((x_in_world - Vector3::y()).norm() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct So3 {
    quaternion: UnitQuaternion<f64>,
}

impl So3 {
    /// Skew-symmetric (cross-product) matrix v^: `skew(v) * w == v.cross(w)`.
    ///
    /// ```
    /// use posecov::lie::So3;
    /// use nalgebra::Vector3;
    /// let (a, b) = (Vector3::new(1.0, 2.0, 3.0), Vector3::new(-1.0, 0.5, 2.0));
    /// assert_eq!(So3::skew(&a) * b, a.cross(&b));
    /// ```
    #[inline]
    pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
    }

    /// Wraps a nalgebra unit quaternion (already normalised by its type).
    ///
    /// ```
    /// use posecov::lie::So3;
    /// use nalgebra::UnitQuaternion;
    /// let r = So3::from_quaternion(UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3));
    /// assert!((r.to_rpy()[2] - 0.3).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn from_quaternion(quaternion: UnitQuaternion<f64>) -> Self {
        Self { quaternion }
    }

    /// From quaternion components in ROS order (x, y, z, w).
    ///
    /// Normalises a quaternion whose norm is within [`QUATERNION_NORM_TOLERANCE`] of 1
    /// (rounded input); rejects non-finite components and norms further from 1.
    ///
    /// ```
    /// use posecov::lie::So3;
    /// let r = So3::try_from_quaternion_xyzw([0.0, 0.0, 0.7071, 0.7071]).unwrap(); // normalised
    /// assert!((r.to_rpy()[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    /// assert!(So3::try_from_quaternion_xyzw([0.0, 0.0, 1.0, 1.0]).is_err()); // norm √2
    /// ```
    pub fn try_from_quaternion_xyzw(xyzw: [f64; 4]) -> Result<Self> {
        check_finite("quaternion (x, y, z, w)", xyzw)?;
        let [x, y, z, w] = xyzw;
        let q = Quaternion::new(w, x, y, z);
        let norm = q.norm();
        if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
            return Err(Error::QuaternionNotUnit {
                xyzw,
                norm,
                tolerance: QUATERNION_NORM_TOLERANCE,
            });
        }
        Ok(Self::from_quaternion(UnitQuaternion::new_normalize(q)))
    }

    /// Quaternion components in ROS order (x, y, z, w), with w ≥ 0.
    ///
    /// ```
    /// use posecov::lie::So3;
    /// assert_eq!(So3::from_rpy(0.0, 0.0, 0.0).to_quaternion_xyzw(), [0.0, 0.0, 0.0, 1.0]);
    /// ```
    #[inline]
    pub fn to_quaternion_xyzw(&self) -> [f64; 4] {
        let q = self.canonical_quaternion();
        [q.i, q.j, q.k, q.w]
    }

    /// The stored unit quaternion.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// assert_eq!(So3::identity().quaternion().w, 1.0);
    /// ```
    #[inline]
    pub fn quaternion(&self) -> &UnitQuaternion<f64> {
        &self.quaternion
    }

    /// From a rotation matrix, validated: finite, max |RᵀR − I| ≤ [`ROTATION_MATRIX_TOLERANCE`],
    /// det R = +1 within the same tolerance. Accepted matrices are re-orthonormalised.
    ///
    /// ```
    /// use posecov::lie::So3;
    /// use nalgebra::Matrix3;
    /// assert!(So3::try_from_matrix(&Matrix3::identity()).is_ok());
    /// let reflection = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, -1.0));
    /// assert!(So3::try_from_matrix(&reflection).is_err());
    /// ```
    pub fn try_from_matrix(r: &Matrix3<f64>) -> Result<Self> {
        super::check_rotation_matrix("rotation matrix", r, ROTATION_MATRIX_TOLERANCE)?;
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
        Ok(Self::from_quaternion(UnitQuaternion::new_normalize(
            q.into_inner(),
        )))
    }

    /// Rotation by `angle` radians about `axis` (any non-zero length; it is normalised).
    ///
    /// ```
    /// use posecov::lie::So3;
    /// use nalgebra::Vector3;
    /// let r = So3::try_from_axis_angle(&Vector3::new(0.0, 0.0, 2.0), 0.5).unwrap();
    /// assert!((r.to_rpy()[2] - 0.5).abs() < 1e-15);
    /// assert!(So3::try_from_axis_angle(&Vector3::zeros(), 0.5).is_err());
    /// ```
    pub fn try_from_axis_angle(axis: &Vector3<f64>, angle: f64) -> Result<Self> {
        check_finite("axis-angle", axis.iter().copied().chain([angle]))?;
        let norm = axis.norm();
        if norm == 0.0 {
            return Err(Error::ZeroAxis {
                axis: [axis.x, axis.y, axis.z],
            });
        }
        Ok(Self::exp(&(axis * (angle / norm))))
    }

    /// From roll, pitch, yaw (radians): R = Rz(yaw) · Ry(pitch) · Rx(roll), i.e. rotations
    /// about the fixed x, y, z axes in that order (ROS `setRPY`, the intrinsic Z-Y'-X'' sequence).
    ///
    /// ```
    /// use posecov::lie::So3;
    /// let r = So3::from_rpy(0.1, 0.2, 0.3);
    /// let [roll, pitch, yaw] = r.to_rpy();
    /// assert!((roll - 0.1).abs() < 1e-15 && (pitch - 0.2).abs() < 1e-15 && (yaw - 0.3).abs() < 1e-15);
    /// ```
    pub fn from_rpy(roll: f64, pitch: f64, yaw: f64) -> Self {
        Self::from_quaternion(UnitQuaternion::from_euler_angles(roll, pitch, yaw))
    }

    /// From ZYX Euler angles given yaw first: the same rotation as
    /// [`from_rpy(roll, pitch, yaw)`](Self::from_rpy), R = Rz(yaw) · Ry(pitch) · Rx(roll).
    ///
    /// ```
    /// use posecov::lie::So3;
    /// assert_eq!(So3::from_euler_zyx(0.3, 0.2, 0.1), So3::from_rpy(0.1, 0.2, 0.3));
    /// ```
    pub fn from_euler_zyx(yaw: f64, pitch: f64, roll: f64) -> Self {
        Self::from_rpy(roll, pitch, yaw)
    }

    /// [roll, pitch, yaw] with R = Rz(yaw) Ry(pitch) Rx(roll), pitch ∈ [−π/2, π/2].
    /// At gimbal lock (|pitch| = π/2) roll and yaw are not unique; one valid pair is returned.
    ///
    /// ```
    /// use posecov::lie::So3;
    /// let [r, p, y] = So3::from_rpy(-0.5, 1.0, 3.0).to_rpy();
    /// assert!((r + 0.5).abs() < 1e-12 && (p - 1.0).abs() < 1e-12 && (y - 3.0).abs() < 1e-12);
    /// ```
    pub fn to_rpy(&self) -> [f64; 3] {
        let (roll, pitch, yaw) = self.quaternion.euler_angles();
        [roll, pitch, yaw]
    }

    /// [yaw, pitch, roll], the ZYX Euler angles in yaw-first order (see [`to_rpy`](Self::to_rpy)).
    ///
    /// ```
    /// use posecov::lie::So3;
    /// let [y, p, r] = So3::from_euler_zyx(0.3, 0.2, 0.1).to_euler_zyx();
    /// assert!((y - 0.3).abs() < 1e-15 && (p - 0.2).abs() < 1e-15 && (r - 0.1).abs() < 1e-15);
    /// ```
    pub fn to_euler_zyx(&self) -> [f64; 3] {
        let [roll, pitch, yaw] = self.to_rpy();
        [yaw, pitch, roll]
    }

    /// The quaternion [cos(|θ|/2), k θ] of Exp(θ) (Solà eq. 101) from `cos_half` = cos(|θ|/2)
    /// and `k` = sin(|θ|/2)/|θ| = ½ sinc(|θ|/2), computed by the caller ([`So3::exp`],
    /// `Se3::exp`, which share one `sin_cos` of |θ|/2 with their other coefficients).
    #[inline]
    pub(crate) fn from_half_angle_terms(theta: &Vector3<f64>, cos_half: f64, k: f64) -> Self {
        let q = Quaternion::new(cos_half, k * theta.x, k * theta.y, k * theta.z);
        Self::from_quaternion(Unit::new_unchecked(q))
    }

    /// [`log`](LieGroup::log) with the canonical quaternion's scalar part w and the norm |v|
    /// of its vector part, from which it is read: cot(θ/2) = w/|v| (θ = |Log R| = 2 atan2(|v|,
    /// w)), what SE(3)'s Log needs for Jl(θ)⁻¹ without another trigonometric call.
    #[inline]
    pub(super) fn log_with_parts(&self) -> (Tangent<3>, f64, f64) {
        let q = self.canonical_quaternion();
        let v = Vector3::new(q.i, q.j, q.k);
        let n = v.norm();
        let factor = if n < LOG_SMALL_VECTOR_PART {
            let x2 = (n / q.w).powi(2);
            2.0 / q.w * (1.0 - x2 / 3.0)
        } else {
            2.0 * n.atan2(q.w) / n
        };
        (v * factor, q.w, n)
    }

    /// The quaternion with w ≥ 0; at w = 0 (θ = π exactly) the sign that makes the first
    /// non-zero vector component positive. q and −q are the same rotation: this picks the one
    /// whose Log has |θ| ≤ π and makes the result at θ = π defined.
    #[inline]
    fn canonical_quaternion(&self) -> Quaternion<f64> {
        let q = *self.quaternion.quaternion();
        let first_nonzero = [q.i, q.j, q.k]
            .into_iter()
            .find(|c| *c != 0.0)
            .unwrap_or(0.0);
        if q.w < 0.0 || (q.w == 0.0 && first_nonzero < 0.0) {
            -q
        } else {
            q
        }
    }
}

impl LieGroup<3> for So3 {
    type Point = Vector3<f64>;
    type Matrix = Matrix3<f64>;
    type ActJacobian = Matrix3<f64>;
    type PointJacobian = Matrix3<f64>;
    const NAME: &'static str = "SO(3)";
    const KIND: super::GroupKind = super::GroupKind::So3;

    #[inline]
    fn identity() -> Self {
        Self::from_quaternion(UnitQuaternion::identity())
    }

    #[inline]
    fn compose(&self, other: &Self) -> Self {
        Self::from_quaternion(self.quaternion * other.quaternion)
    }

    #[inline]
    fn inverse(&self) -> Self {
        Self::from_quaternion(self.quaternion.inverse())
    }

    /// Exp(θ) = [cos(|θ|/2), sin(|θ|/2) θ/|θ|] as a quaternion (Solà eq. 101), with
    /// sin(|θ|/2)/|θ| = ½ sinc(|θ|/2) on its Taylor branch near 0. Above that branch sin and
    /// cos of |θ|/2 come from one `sin_cos` in one basic block, which LLVM turns into a single
    /// `sincos` call (a `sin` used only inside the branch was sunk into it and called apart from
    /// `cos`: two libm calls). Same values as `sin()` / `cos()`: the result is unchanged.
    #[inline]
    fn exp(theta: &Tangent<3>) -> Self {
        let angle = theta.norm();
        let half = 0.5 * angle;
        if half < SMALL_ANGLE {
            // Taylor branch of sinc: no sine needed.
            Self::from_half_angle_terms(theta, half.cos(), 0.5 * sinc(half))
        } else {
            let (sin_half, cos_half) = half.sin_cos();
            Self::from_half_angle_terms(theta, cos_half, 0.5 * (sin_half / half))
        }
    }

    /// Log(q) = 2 atan2(|v|, w) v/|v| with q canonicalised to w ≥ 0 (Solà eq. 105), so
    /// |θ| ≤ π and the result stays accurate as θ → π (no arccos of a trace). At θ = π exactly
    /// the axis sign follows [`to_quaternion_xyzw`](So3::to_quaternion_xyzw): first non-zero
    /// component positive.
    #[inline]
    fn log(&self) -> Tangent<3> {
        self.log_with_parts().0
    }

    #[inline]
    fn hat(theta: &Tangent<3>) -> Matrix3<f64> {
        Self::skew(theta)
    }

    #[inline]
    fn vee(algebra: &Matrix3<f64>) -> Tangent<3> {
        Vector3::new(algebra[(2, 1)], algebra[(0, 2)], algebra[(1, 0)])
    }

    /// Ad_R = R (Solà eq. 127).
    #[inline]
    fn adj(&self) -> TangentMatrix<3> {
        self.to_matrix()
    }

    /// ad_θ = θ^.
    #[inline]
    fn ad(theta: &Tangent<3>) -> TangentMatrix<3> {
        Self::skew(theta)
    }

    /// Jr(θ) = I − A θ^ + B θ^² (Solà eq. 143).
    #[inline]
    fn jr(theta: &Tangent<3>) -> TangentMatrix<3> {
        let angle = theta.norm();
        let h = Self::skew(theta);
        Matrix3::identity() - h * one_minus_cos_by_theta2(angle)
            + h * h * theta_minus_sin_by_theta3(angle)
    }

    /// Jr⁻¹(θ) = I + ½ θ^ + C θ^² (Solà eq. 144, half-angle form of C).
    #[inline]
    fn jr_inv(theta: &Tangent<3>) -> TangentMatrix<3> {
        let h = Self::skew(theta);
        Matrix3::identity() + h * 0.5 + h * h * jinv_coefficient(theta.norm())
    }

    #[inline]
    fn act(&self, point: &Vector3<f64>) -> Vector3<f64> {
        self.quaternion * point
    }

    /// ∂(R p)/∂R = −R p^, ∂(R p)/∂p = R (Solà eqs. 145–146).
    #[inline]
    fn act_jacobians(&self, point: &Vector3<f64>) -> ActJacobians<Matrix3<f64>, Matrix3<f64>> {
        let r = self.to_matrix();
        ActJacobians {
            wrt_group: -r * Self::skew(point),
            wrt_point: r,
        }
    }

    #[inline]
    fn rotate(&self, direction: &Vector3<f64>) -> Vector3<f64> {
        self.quaternion * direction
    }

    #[inline]
    fn to_matrix(&self) -> Matrix3<f64> {
        self.quaternion.to_rotation_matrix().into_inner()
    }

    fn to_se3(&self) -> super::Se3 {
        super::Se3::from_parts(nalgebra::Vector3::zeros(), *self)
    }
}

impl fmt::Display for So3 {
    /// `SO(3) rpy = [roll, pitch, yaw] deg, q_xyzw = [x, y, z, w]`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [r, p, y] = self.to_rpy().map(f64::to_degrees);
        let [qx, qy, qz, qw] = self.to_quaternion_xyzw();
        write!(
            f,
            "SO(3) rpy = [{r:.3}, {p:.3}, {y:.3}] deg, q_xyzw = [{qx:.6}, {qy:.6}, {qz:.6}, {qw:.6}]"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lie::series::sinc;

    /// `So3::exp` with one `sin_cos` of |θ|/2 gives bit for bit the quaternion of the former
    /// form, cos(|θ|/2) and ½ sinc(|θ|/2) θ from separate `cos` and `sin` calls, on both sides of
    /// the Taylor switch and up to π.
    #[test]
    fn exp_is_bit_identical_to_separate_sin_and_cos() {
        let axes = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, -0.5, 0.8),
            Vector3::new(-0.2, 0.9, 0.1),
        ];
        let mut angles = vec![
            0.0,
            1e-12,
            1e-8,
            0.05,
            0.1,
            0.2,
            1.0,
            3.0,
            std::f64::consts::PI,
        ];
        angles.extend((0..2000).map(|i| i as f64 * 1.6e-3)); // 0 … 3.2 rad
        angles.extend([0.2 * (1.0 - 1e-15), 0.2 * (1.0 + 1e-15)]);
        for axis in axes {
            for &angle in &angles {
                let theta = axis.normalize() * angle;
                let half = 0.5 * theta.norm();
                let k = 0.5 * sinc(half);
                let old = Quaternion::new(half.cos(), k * theta.x, k * theta.y, k * theta.z);
                let new = *So3::exp(&theta).quaternion().quaternion();
                assert_eq!(new, old, "θ = {theta:?}");
            }
        }
    }
}
