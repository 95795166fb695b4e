//! Uncertain poses at the boundary: ROS `PoseWithCovariance`, rotation-first tangent orders
//! (GTSAM Pose3, sophus-rs, EEME E6911), and vector-space coordinates (x, y, θ) and
//! (x, y, z, roll, pitch, yaw).
//!
//! Inside posecov every covariance follows the [conventions](crate#conventions): tangent
//! [ρ; θ] (translation first) on the side the [`UncertainPose`] names. Everything else is
//! converted here, on the way in (validated: every field finite, lengths right, Σ symmetric
//! PSD, each error naming the field and the value) and on the way out.
//!
//! | source | order | side | conversion | exact? |
//! |---|---|---|---|---|
//! | ROS `PoseWithCovariance`, tf2's reading (default) | x y z rotX rotY rotZ | both errors in parent axes: p̃ = p + δp, R̃ = Exp(δφ) R | Σ_ros = B Σ_right Bᵀ, B = blkdiag(R, R) | first order |
//! | ROS `PoseWithCovariance`, body reading | x y z rotX rotY rotZ | position in parent axes, rotation local: R̃ = R Exp(δθ) | Σ_ros = B Σ_right Bᵀ, B = blkdiag(R, I₃) | first order |
//! | GTSAM Pose3, sophus-rs | [θ; ρ] | right | Σ' = P Σ Pᵀ | exact |
//! | EEME E6911 slides | [ω; v] | left | Σ' = P Σ_left Pᵀ | exact |
//! | (x, y, θ) | x y θ | additive | Σ_xyθ = J Σ_right Jᵀ, J = blkdiag(R, 1) | first order |
//! | (x, y, z, roll, pitch, yaw) | x y z r p y | additive | Σ_e = J Σ_right Jᵀ, J = blkdiag(R, E_b⁻¹) | first order |
//!
//! ```
//! use posecov::interop::{RosPoseWithCovariance, RosReading};
//! let mut covariance = vec![0.0; 36];
//! for i in 0..6 { covariance[i * 7] = 0.01; }
//! let msg = RosPoseWithCovariance { position: [1.0, 2.0, 0.0], orientation_xyzw: [0.0, 0.0, 0.0, 1.0], covariance };
//! let pose = msg.try_to_uncertain(RosReading::Tf2).unwrap();
//! assert_eq!(RosPoseWithCovariance::from_uncertain(&pose, RosReading::Tf2), msg);
//! ```
//!
//! # What this module and `convert.rs` own
//!
//! The boundaries: ROS `PoseWithCovariance` (`ros.rs`: the one ROS conversion, in tf2's or the body
//! reading), rotation-first orders (the one permutation), Euler-angle charts; nalgebra/glam.

use nalgebra::{Matrix3, Matrix6, SVector, Vector3, Vector6};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, check_finite};
use crate::lie::{LieGroup, Se2, Se3, So3, TangentMatrix};
use crate::uncertain::{Side, UncertainPose, validate_covariance};

mod ros;
pub use ros::{
    ROS_COVARIANCE_LEN, RosPoseWithCovariance, RosReading, ros_cov_from_right, ros_cov_moved,
    ros_cov_to_right, ros_error_jacobian,
};

// --------------------------------------------------------------------------------------------
// Rotation-first tangent orders (docs/CONVENTIONS.md §2).

/// A library or text whose SE(3) tangent puts the rotation first, [θ; ρ].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RotationFirstSource {
    /// GTSAM `Pose3`: tangent [ω; v], retraction X · Exp(ξ), so its marginal covariances
    /// are right (body) form.
    GtsamPose3,
    /// sophus-rs `Isometry3`: tangent rotation first. It carries no covariance convention
    /// of its own; posecov assumes right (body) perturbations X · Exp(ξ) as in its optimiser.
    SophusRs,
    /// Columbia EEME E6911 slides: δ = [ω; v] with left perturbations T̃ = e^\[δ\] T.
    EemeE6911,
}

impl RotationFirstSource {
    /// The side this source's covariances live on.
    ///
    /// ```
    /// use posecov::{interop::RotationFirstSource, uncertain::Side};
    /// assert_eq!(RotationFirstSource::EemeE6911.side(), Side::Left);
    /// assert_eq!(RotationFirstSource::GtsamPose3.side(), Side::Right);
    /// ```
    pub fn side(self) -> Side {
        match self {
            RotationFirstSource::GtsamPose3 | RotationFirstSource::SophusRs => Side::Right,
            RotationFirstSource::EemeE6911 => Side::Left,
        }
    }
}

/// The permutation P with v_rotation_first = P v_translation_first for any group: the
/// rotation coordinates first, then the translation ([θ; ρ] = P [ρ; θ]). For SE(3) a swap of
/// the two 3-blocks (P = Pᵀ = P⁻¹); for rotation groups the identity.
///
/// ```
/// use posecov::interop::rotation_first_permutation;
/// use posecov::lie::{Se2, Se3};
/// use nalgebra::{Matrix6, Vector3, Vector6};
/// let p = rotation_first_permutation::<Se3, 6>();
/// assert_eq!(p * Vector6::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0), Vector6::new(4.0, 5.0, 6.0, 1.0, 2.0, 3.0));
/// assert_eq!(p * p, Matrix6::identity());
/// assert_eq!(rotation_first_permutation::<Se2, 3>() * Vector3::new(1.0, 2.0, 3.0), Vector3::new(3.0, 1.0, 2.0));
/// ```
pub fn rotation_first_permutation<G: LieGroup<N>, const N: usize>() -> TangentMatrix<N> {
    let rot = G::rotation_range();
    let order: Vec<usize> = rot
        .clone()
        .chain((0..N).filter(|i| !rot.contains(i)))
        .collect();
    TangentMatrix::<N>::from_fn(|r, c| if order[r] == c { 1.0 } else { 0.0 })
}

/// A translation-first covariance in rotation-first order: Σ' = P Σ Pᵀ (exact).
///
/// ```
/// use posecov::interop::cov_to_rotation_first;
/// use nalgebra::{Matrix6, Vector6};
/// let s = Matrix6::from_diagonal(&Vector6::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0));
/// assert_eq!(cov_to_rotation_first(&s)[(0, 0)], 4.0);
/// ```
pub fn cov_to_rotation_first(cov: &Matrix6<f64>) -> Matrix6<f64> {
    let p = rotation_first_permutation::<Se3, 6>();
    p * cov * p.transpose()
}

/// A rotation-first covariance in posecov's translation-first order: Σ = Pᵀ Σ' P (exact).
///
/// ```
/// use posecov::interop::{cov_from_rotation_first, cov_to_rotation_first};
/// use nalgebra::Matrix6;
/// let s = Matrix6::from_fn(|r, c| (r * 6 + c) as f64);
/// assert_eq!(cov_from_rotation_first(&cov_to_rotation_first(&s)), s);
/// ```
pub fn cov_from_rotation_first(cov: &Matrix6<f64>) -> Matrix6<f64> {
    let p = rotation_first_permutation::<Se3, 6>();
    p.transpose() * cov * p
}

/// An uncertain pose from a rotation-first source: Σ = Pᵀ Σ' P on the source's
/// [side](RotationFirstSource::side). Errors: Σ' not finite, asymmetric or not PSD.
///
/// ```
/// use posecov::interop::{from_rotation_first, RotationFirstSource};
/// use posecov::{lie::{LieGroup, Se3}, uncertain::Side};
/// use nalgebra::{Matrix6, Vector6};
/// let cov_gtsam = Matrix6::from_diagonal(&Vector6::new(0.01, 0.01, 0.01, 0.1, 0.1, 0.1)); // [ω; v]
/// let p = from_rotation_first(RotationFirstSource::GtsamPose3, Se3::identity(), &cov_gtsam).unwrap();
/// assert_eq!(p.side(), Side::Right);
/// assert_eq!(p.cov()[(0, 0)], 0.1); // ρx
/// ```
pub fn from_rotation_first(
    source: RotationFirstSource,
    mean: Se3,
    cov_rotation_first: &Matrix6<f64>,
) -> Result<UncertainPose<Se3, 6>> {
    let cov = validate_covariance("rotation-first covariance [θ; ρ]", cov_rotation_first)?;
    Ok(UncertainPose::new_unchecked(
        mean,
        cov_from_rotation_first(&cov),
        source.side(),
    ))
}

/// An uncertain pose for a rotation-first consumer: the mean and P Σ Pᵀ, with Σ first moved
/// to the source's side (Ad).
///
/// ```
/// use posecov::interop::{from_rotation_first, to_rotation_first, RotationFirstSource};
/// use posecov::{lie::Se3, uncertain::{Side, UncertainPose}};
/// let x = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
/// let p = UncertainPose::try_from_std_devs(x, [0.1, 0.2, 0.3, 0.01, 0.02, 0.03], Side::Right).unwrap();
/// let (mean, cov) = to_rotation_first(RotationFirstSource::EemeE6911, &p);
/// let back = from_rotation_first(RotationFirstSource::EemeE6911, mean, &cov).unwrap();
/// assert!((back.cov_right() - p.cov()).norm() < 1e-14);
/// ```
pub fn to_rotation_first(
    source: RotationFirstSource,
    pose: &UncertainPose<Se3, 6>,
) -> (Se3, Matrix6<f64>) {
    (
        *pose.mean(),
        cov_to_rotation_first(pose.to_side(source.side()).cov()),
    )
}

// --------------------------------------------------------------------------------------------
// Vector-space coordinates: (x, y, θ) and (x, y, z, roll, pitch, yaw).

/// Below this |cos(pitch)| the roll–pitch–yaw chart is at gimbal lock: roll and yaw are not
/// separable and the Euler-angle covariance is undefined (E_b⁻¹ has 1/cos(pitch) entries).
pub const GIMBAL_LOCK_COS_PITCH: f64 = 1e-6;

/// A vector-space chart of a pose group: coordinates v = φ(X) in which the Smith–Self–Cheeseman
/// baseline and many tools write covariances, with the Jacobian of φ with respect to a right
/// perturbation, J(v) = ∂φ(X · Exp ε)/∂ε at ε = 0.
///
/// Covariances map to first order as Σ_v = J Σ_right Jᵀ and Σ_right = J⁻¹ Σ_v J⁻ᵀ: a Gaussian
/// in v and a Gaussian in the tangent are different distributions (ellipse vs. "banana") that
/// agree only to first order.
///
/// ```
/// use posecov::interop::VectorChart;
/// use posecov::lie::{LieGroup, Se3};
/// use nalgebra::Vector6;
/// let v = Vector6::new(1.0, 2.0, 3.0, 0.1, -0.2, 0.3);
/// let x = Se3::try_from_coordinates(&v).unwrap();
/// assert!((x.to_coordinates() - v).norm() < 1e-14);
/// // first order: φ(X Exp ε) ≈ φ(X) + J ε
/// let eps = Vector6::new(1e-6, 0.0, 0.0, 0.0, 2e-6, 0.0);
/// let j = Se3::coordinates_jacobian(&v).unwrap();
/// assert!((x.rplus(&eps).to_coordinates() - v - j * eps).norm() < 1e-11);
/// assert!((j * Se3::coordinates_jacobian_inverse(&v) - nalgebra::Matrix6::identity()).norm() < 1e-12);
/// ```
pub trait VectorChart<const N: usize>: LieGroup<N> {
    /// Names of the coordinates, in order, e.g. "(x, y, θ)".
    const COORDINATES: &'static str;
    /// φ(X).
    fn to_coordinates(&self) -> SVector<f64, N>;
    /// φ⁻¹(v); errors when v is not finite.
    fn try_from_coordinates(v: &SVector<f64, N>) -> Result<Self>;
    /// J(v) = ∂φ(X · Exp ε)/∂ε at ε = 0, X = φ⁻¹(v); errors where the chart is singular.
    fn coordinates_jacobian(v: &SVector<f64, N>) -> Result<TangentMatrix<N>>;
    /// J(v)⁻¹ = ∂ε/∂v (finite everywhere, also where J is not).
    fn coordinates_jacobian_inverse(v: &SVector<f64, N>) -> TangentMatrix<N>;
}

impl VectorChart<3> for Se2 {
    const COORDINATES: &'static str = "(x, y, θ)";

    /// (x, y, θ), θ ∈ (−π, π].
    fn to_coordinates(&self) -> SVector<f64, 3> {
        Vector3::new(self.x(), self.y(), self.theta())
    }

    fn try_from_coordinates(v: &SVector<f64, 3>) -> Result<Self> {
        check_finite("(x, y, θ)", v.iter().copied())?;
        Ok(Se2::from_xy_theta(v.x, v.y, v.z))
    }

    /// J = blkdiag(R(θ), 1): μ Exp([ρ; θ_ε]) = (t + R V(θ_ε) ρ, θ + θ_ε), and V(0) = I
    /// (Solà et al. 2018 eq. 156).
    fn coordinates_jacobian(v: &SVector<f64, 3>) -> Result<TangentMatrix<3>> {
        Ok(se2_jacobian(v.z))
    }

    fn coordinates_jacobian_inverse(v: &SVector<f64, 3>) -> TangentMatrix<3> {
        se2_jacobian(-v.z)
    }
}

/// blkdiag(R(θ), 1).
fn se2_jacobian(theta: f64) -> TangentMatrix<3> {
    let (s, c) = theta.sin_cos();
    nalgebra::Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// E_b(roll, pitch): body angular velocity from Euler-angle rates, ω_b = E_b (ṙ, ṗ, ẏ)ᵀ for
/// R = Rz(yaw) Ry(pitch) Rx(roll). Derivation: ω_b = vee(Rᵀ Ṙ) = ṙ e_x + Rxᵀ ṗ e_y +
/// Rxᵀ Ryᵀ ẏ e_z, so E_b = [[1, 0, −sin p], [0, cos r, sin r cos p], [0, −sin r, cos r cos p]].
///
/// ```
/// use posecov::interop::euler_rates_to_body_rates;
/// assert_eq!(euler_rates_to_body_rates(0.0, 0.0), nalgebra::Matrix3::identity());
/// ```
pub fn euler_rates_to_body_rates(roll: f64, pitch: f64) -> Matrix3<f64> {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    Matrix3::new(1.0, 0.0, -sp, 0.0, cr, sr * cp, 0.0, -sr, cr * cp)
}

/// E_b⁻¹(roll, pitch) = [[1, sin r tan p, cos r tan p], [0, cos r, −sin r],
/// [0, sin r / cos p, cos r / cos p]]: Euler-angle rates from body rates, i.e. the Jacobian of
/// rpy(R Exp(θ)) with respect to θ at 0. Errors at gimbal lock (|cos p| <
/// [`GIMBAL_LOCK_COS_PITCH`]).
///
/// ```
/// use posecov::interop::{body_rates_to_euler_rates, euler_rates_to_body_rates};
/// let e = euler_rates_to_body_rates(0.3, -0.7);
/// assert!((body_rates_to_euler_rates(0.3, -0.7).unwrap() * e - nalgebra::Matrix3::identity()).norm() < 1e-14);
/// assert!(body_rates_to_euler_rates(0.0, std::f64::consts::FRAC_PI_2).is_err());
/// ```
pub fn body_rates_to_euler_rates(roll: f64, pitch: f64) -> Result<Matrix3<f64>> {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    if cp.is_nan() || cp.abs() < GIMBAL_LOCK_COS_PITCH {
        return Err(Error::OutOfRange {
            what: "pitch (rad)",
            value: pitch,
            expected: "|cos pitch| ≥ 1e-6: the roll-pitch-yaw covariance is undefined at gimbal lock",
        });
    }
    Ok(Matrix3::new(
        1.0,
        sr * sp / cp,
        cr * sp / cp,
        0.0,
        cr,
        -sr,
        0.0,
        sr / cp,
        cr / cp,
    ))
}

/// blkdiag(a, b) of two 3×3 blocks.
fn block_diag3(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(a);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(b);
    m
}

impl VectorChart<6> for Se3 {
    const COORDINATES: &'static str = "(x, y, z, roll, pitch, yaw)";

    /// (x, y, z, roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll), pitch ∈ [−π/2, π/2].
    fn to_coordinates(&self) -> SVector<f64, 6> {
        let t = self.translation();
        let [r, p, y] = self.rotation().to_rpy();
        Vector6::new(t.x, t.y, t.z, r, p, y)
    }

    fn try_from_coordinates(v: &SVector<f64, 6>) -> Result<Self> {
        check_finite("(x, y, z, roll, pitch, yaw)", v.iter().copied())?;
        Ok(Se3::from_xyz_rpy([v[0], v[1], v[2]], [v[3], v[4], v[5]]))
    }

    /// J = blkdiag(R, E_b⁻¹(roll, pitch)): the position of μ Exp([ρ; θ]) is t + R Jl(θ) ρ
    /// (derivative R at 0), its rotation R Exp(θ) has Euler rates E_b⁻¹ θ
    /// ([`body_rates_to_euler_rates`]).
    fn coordinates_jacobian(v: &SVector<f64, 6>) -> Result<TangentMatrix<6>> {
        let r = So3::from_rpy(v[3], v[4], v[5]).to_matrix();
        Ok(block_diag3(&r, &body_rates_to_euler_rates(v[3], v[4])?))
    }

    /// J⁻¹ = blkdiag(Rᵀ, E_b(roll, pitch)).
    fn coordinates_jacobian_inverse(v: &SVector<f64, 6>) -> TangentMatrix<6> {
        let r = So3::from_rpy(v[3], v[4], v[5]).to_matrix();
        block_diag3(&r.transpose(), &euler_rates_to_body_rates(v[3], v[4]))
    }
}

/// The order of the six coordinates of an Euler-angle pose covariance. Both libraries build
/// the rotation as R = Rz(yaw) Ry(pitch) Rx(roll) with positions in the parent axes; they list
/// the angles in opposite orders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EulerOrder {
    /// (x, y, z, roll, pitch, yaw): robot_localization's state.
    XyzRpy,
    /// (x, y, z, yaw, pitch, roll): MRPT's `CPose3D` / `CPose3DPDFGaussian`.
    XyzYpr,
}

/// An Euler-angle covariance at `mean` in posecov's right form, to first order: the angles are
/// put in (roll, pitch, yaw) order (a swap of yaw and roll for [`EulerOrder::XyzYpr`]), then
/// Σ_right = J⁻¹ Σ_e J⁻ᵀ with J = blkdiag(R, E_b⁻¹) the chart Jacobian of
/// (x, y, z, roll, pitch, yaw) at the mean ([`VectorChart`], [`from_coordinates`]). Valid also
/// at gimbal lock (J⁻¹ is finite there).
///
/// ```
/// use posecov::interop::{EulerOrder, se3_cov_from_euler};
/// use posecov::lie::Se3;
/// use nalgebra::{Matrix6, Vector6};
/// let mean = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0; 3]);
/// let ypr = Matrix6::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, 0.09, 0.04, 0.01));
/// let right = se3_cov_from_euler(&mean, &ypr, EulerOrder::XyzYpr);
/// assert!((right[(3, 3)] - 0.01).abs() < 1e-15 && (right[(5, 5)] - 0.09).abs() < 1e-15); // roll, yaw
/// ```
pub fn se3_cov_from_euler(mean: &Se3, cov: &Matrix6<f64>, order: EulerOrder) -> Matrix6<f64> {
    let mut rpy = *cov;
    if order == EulerOrder::XyzYpr {
        rpy.swap_rows(3, 5);
        rpy.swap_columns(3, 5);
    }
    let j_inv = Se3::coordinates_jacobian_inverse(&mean.to_coordinates());
    let right = j_inv * rpy * j_inv.transpose();
    (right + right.transpose()) * 0.5
}

/// An uncertain pose in vector-space coordinates (first order): v = φ(μ),
/// Σ_v = J(v) Σ_right J(v)ᵀ ([`VectorChart`]). Errors where the chart is singular.
///
/// ```
/// use posecov::interop::to_coordinates;
/// use posecov::{lie::Se2, uncertain::{Side, UncertainPose}};
/// let p = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 2.0, 0.5), [0.1, 0.2, 0.3], Side::Right).unwrap();
/// let (v, cov) = to_coordinates(&p).unwrap();
/// assert!((v.z - 0.5).abs() < 1e-15 && (cov[(2, 2)] - 0.09).abs() < 1e-15);
/// ```
pub fn to_coordinates<G: VectorChart<N>, const N: usize>(
    pose: &UncertainPose<G, N>,
) -> Result<(SVector<f64, N>, TangentMatrix<N>)> {
    let v = pose.mean().to_coordinates();
    let j = G::coordinates_jacobian(&v)?;
    let cov = j * pose.cov_right() * j.transpose();
    Ok((v, (cov + cov.transpose()) * 0.5))
}

/// An uncertain pose (right side) from vector-space coordinates and their covariance
/// (first order): μ = φ⁻¹(v), Σ_right = J(v)⁻¹ Σ_v J(v)⁻ᵀ. Errors: v not finite, Σ_v not
/// finite, asymmetric or not PSD.
///
/// ```
/// use posecov::interop::{from_coordinates, to_coordinates};
/// use posecov::lie::Se3;
/// use nalgebra::{Matrix6, Vector6};
/// let v = Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3);
/// let cov = Matrix6::identity() * 0.01;
/// let p = from_coordinates::<Se3, 6>(&v, &cov).unwrap();
/// let (v2, cov2) = to_coordinates(&p).unwrap();
/// assert!((v2 - v).norm() < 1e-12 && (cov2 - cov).norm() < 1e-12);
/// ```
pub fn from_coordinates<G: VectorChart<N>, const N: usize>(
    v: &SVector<f64, N>,
    cov: &TangentMatrix<N>,
) -> Result<UncertainPose<G, N>> {
    let mean = G::try_from_coordinates(v)?;
    let cov = validate_covariance("vector-space covariance", cov)?;
    let j_inv = G::coordinates_jacobian_inverse(v);
    Ok(UncertainPose::new_unchecked(
        mean,
        j_inv * cov * j_inv.transpose(),
        Side::Right,
    ))
}

/// SE(2) in (x, y, θ): the named form of [`to_coordinates`], Σ_xyθ = blkdiag(R, 1) Σ_right
/// blkdiag(R, 1)ᵀ (first order).
///
/// ```
/// use posecov::interop::se2_to_xytheta;
/// use posecov::{lie::Se2, uncertain::{Side, UncertainPose}};
/// let p = UncertainPose::try_from_std_devs(Se2::from_xy_theta(0.0, 0.0, std::f64::consts::FRAC_PI_2), [0.1, 0.0, 0.0], Side::Right).unwrap();
/// let (_, cov) = se2_to_xytheta(&p);
/// assert!((cov[(1, 1)] - 0.01).abs() < 1e-15); // body x is world y
/// ```
pub fn se2_to_xytheta(pose: &UncertainPose<Se2, 3>) -> (Vector3<f64>, Matrix3<f64>) {
    let v = pose.mean().to_coordinates();
    let j = se2_jacobian(v.z);
    let cov = j * pose.cov_right() * j.transpose();
    (v, (cov + cov.transpose()) * 0.5)
}

/// SE(2) from (x, y, θ) and its covariance: the named form of [`from_coordinates`].
///
/// ```
/// use posecov::interop::{se2_from_xytheta, se2_to_xytheta};
/// use nalgebra::{Matrix3, Vector3};
/// let cov = Matrix3::new(0.02, 0.01, 0.0, 0.01, 0.03, 0.005, 0.0, 0.005, 0.01);
/// let p = se2_from_xytheta(&Vector3::new(1.0, 2.0, 0.7), &cov).unwrap();
/// assert!((se2_to_xytheta(&p).1 - cov).norm() < 1e-15);
/// ```
pub fn se2_from_xytheta(v: &Vector3<f64>, cov: &Matrix3<f64>) -> Result<UncertainPose<Se2, 3>> {
    from_coordinates::<Se2, 3>(v, cov)
}

/// SE(3) in (x, y, z, roll, pitch, yaw): the named form of [`to_coordinates`],
/// Σ_e = blkdiag(R, E_b⁻¹) Σ_right blkdiag(R, E_b⁻¹)ᵀ (first order). Errors at gimbal lock.
///
/// ```
/// use posecov::interop::se3_to_xyz_rpy;
/// use posecov::{lie::{LieGroup, Se3}, uncertain::{Side, UncertainPose}};
/// let p = UncertainPose::try_from_std_devs(Se3::identity(), [0.0, 0.0, 0.0, 0.1, 0.0, 0.0], Side::Right).unwrap();
/// let (_, cov) = se3_to_xyz_rpy(&p).unwrap();
/// assert!((cov[(3, 3)] - 0.01).abs() < 1e-15); // roll
/// ```
pub fn se3_to_xyz_rpy(pose: &UncertainPose<Se3, 6>) -> Result<(Vector6<f64>, Matrix6<f64>)> {
    to_coordinates(pose)
}

/// SE(3) from (x, y, z, roll, pitch, yaw) and its covariance: the named form of
/// [`from_coordinates`] (first order; valid also at gimbal lock, where Σ_right comes out
/// degenerate).
///
/// ```
/// use posecov::interop::se3_from_xyz_rpy;
/// use nalgebra::{Matrix6, Vector6};
/// let p = se3_from_xyz_rpy(&Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3), &(Matrix6::identity() * 0.01)).unwrap();
/// assert!((p.mean().translation().x - 1.0).abs() < 1e-15);
/// assert!(se3_from_xyz_rpy(&Vector6::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0), &Matrix6::identity()).is_err());
/// ```
pub fn se3_from_xyz_rpy(v: &Vector6<f64>, cov: &Matrix6<f64>) -> Result<UncertainPose<Se3, 6>> {
    from_coordinates::<Se3, 6>(v, cov)
}
