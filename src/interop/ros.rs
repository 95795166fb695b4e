//! ROS `geometry_msgs/PoseWithCovariance` at the boundary ([CONVENTIONS §6]): the two
//! readings of its 6×6 covariance ([`RosReading`]), the one conversion to and from posecov's
//! right form, and the message as plain data.
//!
//! [CONVENTIONS §6]: crate::conventions#6-ros-posewithcovariance

use nalgebra::{Matrix6, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, check_finite};
use crate::lie::{LieGroup, Se3, So3};
use crate::uncertain::{Side, UncertainPose, validate_covariance};

/// Number of entries of a ROS `PoseWithCovariance.covariance` (6 × 6, row-major).
pub const ROS_COVARIANCE_LEN: usize = 36;

/// How the 6×6 covariance of a ROS `PoseWithCovariance` is read ([CONVENTIONS §6]). Both
/// readings add the position error in the parent frame's axes; they differ in the axes of the
/// rotation error.
///
/// [CONVENTIONS §6]: crate::conventions#6-ros-posewithcovariance
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RosReading {
    /// tf2's reading (the default): both errors in the parent axes, p̃ = p + δp,
    /// R̃ = Exp(δφ) · R, as `tf2_geometry_msgs`' `transformCovariance` moves them (it rotates
    /// both 3×3 blocks) and as the message's "fixed-axis representation" comment says.
    #[default]
    Tf2,
    /// The body-local reading some publishers use: p̃ = p + δp in the parent axes,
    /// R̃ = R · Exp(δθ) in the body.
    Body,
}

impl RosReading {
    /// The reading's name in flags, files and outputs: `tf2` or `body`.
    ///
    /// ```
    /// use posecov::interop::RosReading;
    /// assert_eq!(RosReading::default().name(), "tf2");
    /// assert_eq!("body".parse::<RosReading>().unwrap(), RosReading::Body);
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            RosReading::Tf2 => "tf2",
            RosReading::Body => "body",
        }
    }
}

impl std::str::FromStr for RosReading {
    type Err = String;

    /// `tf2` or `body`; anything else names the two.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "tf2" => Ok(RosReading::Tf2),
            "body" => Ok(RosReading::Body),
            other => Err(format!(
                "unknown ROS reading `{other}`: use `tf2` or `body`"
            )),
        }
    }
}

/// A ROS `geometry_msgs/PoseWithCovariance` as plain data (e.g. from rosbridge JSON):
/// position, orientation as a quaternion in ROS order (x, y, z, w), and 36 row-major covariance
/// entries in the order (x, y, z, rotX, rotY, rotZ).
///
/// Meaning ([CONVENTIONS §6]): the position error is additive in the **parent** frame's axes;
/// the rotation error too in tf2's reading (R̃ = Exp(δφ) · R, the default), or local in the
/// body reading (R̃ = R · Exp(δθ)): see [`RosReading`].
///
/// [CONVENTIONS §6]: crate::conventions#6-ros-posewithcovariance
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RosPoseWithCovariance {
    /// `pose.position` (x, y, z) in the parent frame.
    pub position: [f64; 3],
    /// `pose.orientation` as (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
    /// `covariance`, 36 numbers, row-major 6 × 6, (x, y, z, rotX, rotY, rotZ).
    pub covariance: Vec<f64>,
}

/// B, the first-order map from the right-form tangent [ρ; θ] to the ROS error [δp; δφ] in
/// `reading`: μ Exp([ρ; θ]) has position t + R Jl(θ) ρ ≈ t + R ρ (Solà et al. 2018 eq. 172) and
/// rotation R Exp(θ) = Exp(R θ) R. So δp = R ρ in both readings; δφ = R θ in tf2's (parent
/// axes), δθ = θ in the body reading. B = blkdiag(R, R) (tf2) or blkdiag(R, I₃) (body).
///
/// ```
/// use posecov::{interop::{RosReading, ros_error_jacobian}, lie::{LieGroup, So3}};
/// let r = So3::from_rpy(0.0, 0.0, 0.5);
/// let body = ros_error_jacobian(&r, RosReading::Body);
/// assert_eq!(body.fixed_view::<3, 3>(3, 3).into_owned(), nalgebra::Matrix3::identity());
/// let tf2 = ros_error_jacobian(&r, RosReading::Tf2);
/// assert_eq!(tf2.fixed_view::<3, 3>(3, 3).into_owned(), r.to_matrix());
/// ```
pub fn ros_error_jacobian(rotation: &So3, reading: RosReading) -> Matrix6<f64> {
    let r = rotation.to_matrix();
    let mut b = Matrix6::identity();
    b.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    if reading == RosReading::Tf2 {
        b.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    }
    b
}

/// A ROS covariance in posecov's right form at a pose with rotation R:
/// Σ_right = B⁻¹ Σ_ros B⁻ᵀ, B = [`ros_error_jacobian`] for `reading` (first order;
/// [CONVENTIONS §6]). The one conversion every ROS input uses.
///
/// ```
/// use posecov::{interop::{RosReading, ros_cov_to_right}, lie::So3};
/// use nalgebra::Matrix6;
/// let yaw90 = So3::from_rpy(0.0, 0.0, std::f64::consts::FRAC_PI_2);
/// let mut ros = Matrix6::zeros();
/// ros[(1, 1)] = 0.01; // parent y
/// ros[(3, 3)] = 0.04; // about parent x
/// let right = ros_cov_to_right(&ros, &yaw90, RosReading::Tf2);
/// assert!((right[(0, 0)] - 0.01).abs() < 1e-15); // body x
/// assert!((right[(4, 4)] - 0.04).abs() < 1e-15); // parent x is body −y
/// let body = ros_cov_to_right(&ros, &yaw90, RosReading::Body);
/// assert!((body[(3, 3)] - 0.04).abs() < 1e-15); // read as about body x
/// ```
///
/// [CONVENTIONS §6]: crate::conventions#6-ros-posewithcovariance
pub fn ros_cov_to_right(
    cov_ros: &Matrix6<f64>,
    rotation: &So3,
    reading: RosReading,
) -> Matrix6<f64> {
    let b_inv = ros_error_jacobian(&rotation.inverse(), reading);
    b_inv * cov_ros * b_inv.transpose()
}

/// The right-form covariance at a pose with rotation R as a ROS covariance in `reading`:
/// Σ_ros = B Σ_right Bᵀ ([`ros_error_jacobian`]), the inverse of [`ros_cov_to_right`].
///
/// ```
/// use posecov::{interop::{RosReading, ros_cov_from_right, ros_cov_to_right}, lie::So3};
/// use nalgebra::Matrix6;
/// let r = So3::from_rpy(0.3, -0.2, 1.0);
/// let ros = Matrix6::from_diagonal(&nalgebra::Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3));
/// let back = ros_cov_from_right(&ros_cov_to_right(&ros, &r, RosReading::Tf2), &r, RosReading::Tf2);
/// assert!((back - ros).norm() < 1e-12);
/// ```
pub fn ros_cov_from_right(
    cov_right: &Matrix6<f64>,
    rotation: &So3,
    reading: RosReading,
) -> Matrix6<f64> {
    let b = ros_error_jacobian(rotation, reading);
    b * cov_right * b.transpose()
}

/// A ROS covariance moved with its pose by a known transform T = parent_from_child (frames
/// joined through `/tf`, [CONVENTIONS §6]): the message's pose X becomes T · X, and its error
/// [δp; δφ] becomes B_T [δp; δφ] with B_T = [`ros_error_jacobian`] of T's rotation R_T, so
/// **Σ' = B_T Σ B_T^T** — blkdiag(R_T, R_T) in tf2's reading (both blocks in the parent's axes:
/// T · (Exp(δφ) R, p + δp) = (Exp(R_T δφ) R_T R, R_T p + t + R_T δp), exactly), blkdiag(R_T, I₃)
/// in the body reading (the rotation error is local and does not move). This is what
/// `tf2_geometry_msgs`' `doTransform` applies to a `PoseWithCovarianceStamped`. In posecov's
/// right form nothing changes: T · X̂ · Exp(ξ) = (T X̂) · Exp(ξ), and B of R_T R is B_T B.
///
/// ```
/// use posecov::{interop::{RosReading, ros_cov_moved, ros_cov_to_right}, lie::{LieGroup, So3}};
/// use nalgebra::{Matrix6, Vector6};
/// let r = So3::from_rpy(0.0, 0.0, 0.4); // the pose's rotation
/// let r_t = So3::from_rpy(0.1, 0.0, 1.2); // map_from_odom's rotation
/// let ros = Matrix6::from_diagonal(&Vector6::new(0.04, 0.01, 0.02, 0.003, 0.002, 0.001));
/// let moved = ros_cov_moved(&ros, &r_t, RosReading::Tf2);
/// let before = ros_cov_to_right(&ros, &r, RosReading::Tf2);
/// let after = ros_cov_to_right(&moved, &r_t.compose(&r), RosReading::Tf2);
/// assert!((before - after).norm() < 1e-15); // the right form does not move
/// ```
///
/// [CONVENTIONS §6]: crate::conventions#6-ros-posewithcovariance
pub fn ros_cov_moved(cov_ros: &Matrix6<f64>, rotation: &So3, reading: RosReading) -> Matrix6<f64> {
    // The same map as a right-form covariance at R_T read out: B_T Σ B_Tᵀ.
    ros_cov_from_right(cov_ros, rotation, reading)
}

impl RosPoseWithCovariance {
    /// The message as a right-form uncertain pose in `reading`: Σ_right = B⁻¹ Σ_ros B⁻ᵀ with
    /// B = [`ros_error_jacobian`] (first order: the ROS position error is additive, posecov's
    /// is R Jl(θ) ρ; the two agree to first order in the perturbation).
    ///
    /// Errors, each naming the field: position or orientation not finite, quaternion norm not
    /// within 1e-3 of 1, covariance length ≠ 36, an entry NaN/∞ (with its row-major index),
    /// asymmetric, or not positive semi-definite.
    ///
    /// ```
    /// use posecov::{Error, interop::{RosPoseWithCovariance, RosReading}};
    /// let msg = RosPoseWithCovariance { position: [0.0; 3], orientation_xyzw: [0.0, 0.0, 0.0, 1.0], covariance: vec![0.0; 35] };
    /// assert!(matches!(msg.try_to_uncertain(RosReading::Tf2), Err(Error::WrongLength { expected: 36, got: 35, .. })));
    /// ```
    pub fn try_to_uncertain(&self, reading: RosReading) -> Result<UncertainPose<Se3, 6>> {
        check_finite("PoseWithCovariance.pose.position", self.position)?;
        let rotation = So3::try_from_quaternion_xyzw(self.orientation_xyzw)?;
        if self.covariance.len() != ROS_COVARIANCE_LEN {
            return Err(Error::WrongLength {
                what: "PoseWithCovariance.covariance",
                expected: ROS_COVARIANCE_LEN,
                got: self.covariance.len(),
            });
        }
        let cov_ros = Matrix6::from_row_slice(&self.covariance);
        let cov_ros = validate_covariance("PoseWithCovariance.covariance", &cov_ros)?;
        let mean = Se3::from_parts(Vector3::from(self.position), rotation);
        Ok(UncertainPose::new_unchecked(
            mean,
            ros_cov_to_right(&cov_ros, &rotation, reading),
            Side::Right,
        ))
    }

    /// An uncertain pose as a ROS message in `reading`: Σ_ros = B Σ_right Bᵀ
    /// ([`ros_cov_from_right`], converting to the right side first; first order, see
    /// [`try_to_uncertain`](Self::try_to_uncertain)). The quaternion has w ≥ 0.
    ///
    /// ```
    /// use posecov::{interop::{RosPoseWithCovariance, RosReading}, lie::Se3, uncertain::{Side, UncertainPose}};
    /// let yaw90 = Se3::from_xyz_rpy([0.0; 3], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
    /// let p = UncertainPose::try_from_std_devs(yaw90, [0.1, 0.0, 0.0, 0.0, 0.0, 0.0], Side::Right).unwrap();
    /// let msg = RosPoseWithCovariance::from_uncertain(&p, RosReading::Tf2);
    /// assert!((msg.covariance[7] - 0.01).abs() < 1e-15); // body x is parent y
    /// ```
    pub fn from_uncertain(pose: &UncertainPose<Se3, 6>, reading: RosReading) -> Self {
        let mean = pose.mean();
        let cov = ros_cov_from_right(&pose.cov_right(), mean.rotation(), reading);
        let cov = (cov + cov.transpose()) * 0.5;
        let t = mean.translation();
        Self {
            position: [t.x, t.y, t.z],
            orientation_xyzw: mean.rotation().to_quaternion_xyzw(),
            covariance: cov.transpose().iter().copied().collect(),
        }
    }
}
