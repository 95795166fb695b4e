//! What one log message's covariance means in posecov's body-frame right form: the one ROS
//! conversion ([`ros_cov_to_right`], in the chosen [`RosReading`]) restricted to the plane for
//! an SE(2) topic, and how far the two ROS readings put it apart
//! ([CONVENTIONS §6](crate::conventions#6-ros-posewithcovariance)).

use nalgebra::{Matrix3, Matrix6, Vector2};

use super::PoseState;
use crate::interop::{RosReading, ros_cov_to_right};
use crate::lie::{Se2, Se3, So2, So3};
use crate::plan::log::Issue;
use crate::uncertain::{Side, UncertainPose};

/// The right-form Gaussian of a usable message. Planar: the unestimated z / roll / pitch rows
/// and columns are dropped (they are placeholders or zero, not variances), the pose is
/// projected to (x, y, yaw), and the one ROS conversion is applied at R = Rz(yaw); the
/// (ρx, ρy, θz) block is SE(2)'s tangent. A placeholder (≥ 1e6, "not estimated") on an axis
/// the motion uses — x, y or yaw when planar, any axis in 3-D — is no variance: such a message
/// cannot be drawn as a Gaussian (RViz's clipped picture and a cross say it instead).
pub(super) fn meaning(
    mean: &Se3,
    cov_ros: &Matrix6<f64>,
    unestimated: &[bool; 6],
    planar: bool,
    reading: RosReading,
) -> Result<PoseState, Vec<Issue>> {
    let invalid = |_| vec![Issue::NotPsd];
    match right_form(mean, cov_ros, unestimated, planar, reading)? {
        RightForm::Planar(mean, cov) => UncertainPose::try_new(mean, cov, Side::Right)
            .map(|pose| PoseState::Planar {
                pose,
                cloud: Vec::new(),
            })
            .map_err(invalid),
        RightForm::Spatial(mean, cov) => UncertainPose::try_new(mean, cov, Side::Right)
            .map(|pose| PoseState::Spatial {
                pose: Box::new(pose),
                cloud: Vec::new(),
            })
            .map_err(invalid),
    }
}

/// A message's mean and right-form covariance, not validated yet.
// Handed straight to its validation: boxing the 6 × 6 would allocate once per message.
#[allow(clippy::large_enum_variant)]
pub(super) enum RightForm {
    /// (x, y, yaw).
    Planar(Se2, Matrix3<f64>),
    /// SE(3).
    Spatial(Se3, Matrix6<f64>),
}

/// The conversion of [`meaning`], before Σ is validated (which the NEES does with the
/// decomposition that also inverts it).
pub(super) fn right_form(
    mean: &Se3,
    cov_ros: &Matrix6<f64>,
    unestimated: &[bool; 6],
    planar: bool,
    reading: RosReading,
) -> Result<RightForm, Vec<Issue>> {
    let used: &[usize] = if planar {
        &[0, 1, 5]
    } else {
        &[0, 1, 2, 3, 4, 5]
    };
    if used
        .iter()
        .any(|&i| unestimated[i] && cov_ros[(i, i)] != 0.0)
    {
        return Err(vec![Issue::PlaceholderUsedAxis]);
    }
    if !planar {
        let right = ros_cov_to_right(cov_ros, mean.rotation(), reading);
        return Ok(RightForm::Spatial(*mean, right));
    }
    let yaw = mean.rotation().to_rpy()[2];
    let mut cov = *cov_ros;
    for i in [2, 3, 4] {
        cov.row_mut(i).fill(0.0);
        cov.column_mut(i).fill(0.0);
    }
    let right = ros_cov_to_right(&cov, &So3::from_rpy(0.0, 0.0, yaw), reading);
    let keep = [0, 1, 5];
    let cov2 = Matrix3::from_fn(|r, c| right[(keep[r], keep[c])]);
    let t = mean.translation();
    let mean2 = Se2::from_parts(Vector2::new(t.x, t.y), So2::from_angle(yaw));
    Ok(RightForm::Planar(mean2, cov2))
}

/// ‖Σ_tf2 − Σ_body‖_F / ‖Σ_tf2‖_F of one message's right-form covariances (0 for Σ = 0).
pub(super) fn readings_apart(mean: &Se3, cov_ros: &Matrix6<f64>) -> f64 {
    let tf2 = ros_cov_to_right(cov_ros, mean.rotation(), RosReading::Tf2);
    let body = ros_cov_to_right(cov_ros, mean.rotation(), RosReading::Body);
    let scale = tf2.norm();
    if scale > 0.0 {
        (tf2 - body).norm() / scale
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interop::RosPoseWithCovariance;
    use crate::lie::LieGroup;

    #[test]
    fn planar_meaning_is_the_ros_conversion_restricted_to_the_plane() {
        let yaw: f64 = 0.7;
        let mean = Se3::from_xyz_rpy([1.0, 2.0, 0.0], [0.0, 0.0, yaw]);
        let mut cov = Matrix6::zeros();
        cov[(0, 0)] = 0.04;
        cov[(1, 1)] = 0.01;
        cov[(0, 1)] = 0.005;
        cov[(1, 0)] = 0.005;
        cov[(5, 5)] = 0.02;
        let mut with_placeholders = cov;
        for i in [2, 3, 4] {
            with_placeholders[(i, i)] = 1e6;
        }
        let un = [false, false, true, true, true, false];
        let PoseState::Planar { pose, .. } =
            meaning(&mean, &with_placeholders, &un, true, RosReading::Tf2).unwrap()
        else {
            panic!()
        };
        // The same numbers through the one public conversion of a full message.
        let mut full = cov;
        for i in [2, 3, 4] {
            full[(i, i)] = 1.0;
        }
        let msg = RosPoseWithCovariance {
            position: [1.0, 2.0, 0.0],
            orientation_xyzw: mean.rotation().to_quaternion_xyzw(),
            covariance: full.transpose().iter().copied().collect(),
        };
        let right = msg.try_to_uncertain(RosReading::Tf2).unwrap().cov_right();
        let keep = [0, 1, 5];
        for r in 0..3 {
            for c in 0..3 {
                assert!((pose.cov()[(r, c)] - right[(keep[r], keep[c])]).abs() < 1e-15);
            }
        }
        // Body x is the parent's direction at yaw: its variance mixes parent x and y.
        let (s, c) = yaw.sin_cos();
        let expect = c * c * 0.04 + s * s * 0.01 + 2.0 * s * c * 0.005;
        assert!((pose.cov()[(0, 0)] - expect).abs() < 1e-15);
        assert!((pose.mean().rotation().angle() - yaw).abs() < 1e-15);
    }

    #[test]
    fn a_placeholder_on_a_planar_axis_in_use_is_not_drawn() {
        // σ² = 4.5e153 on x: no variance (and its banana would overflow the viewer's f32).
        let mut cov = Matrix6::identity() * 0.01;
        cov[(0, 0)] = 4.5e153;
        let un = [true, false, true, true, true, false];
        assert_eq!(
            meaning(&Se3::identity(), &cov, &un, true, RosReading::Tf2).unwrap_err(),
            vec![Issue::PlaceholderUsedAxis]
        );
    }

    #[test]
    fn a_placeholder_in_3d_is_not_drawn() {
        let mean = Se3::identity();
        let mut cov = Matrix6::identity() * 0.01;
        cov[(3, 3)] = 1.79e308;
        let mut un = [false; 6];
        un[3] = true;
        assert_eq!(
            meaning(&mean, &cov, &un, false, RosReading::Tf2).unwrap_err(),
            vec![Issue::PlaceholderUsedAxis]
        );
    }
}
