//! Boundary conversions: ROS PoseWithCovariance, rotation-first sources, (x, y, θ) and
//! Euler-angle covariances — round trips, the Jacobians against finite differences, and every
//! invalid input's typed error.

mod common;

use common::{assert_close, numeric_jacobian, random_spd};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use posecov::Error;
use posecov::interop::{
    RosPoseWithCovariance, RosReading, RotationFirstSource, VectorChart, body_rates_to_euler_rates,
    from_rotation_first, ros_error_jacobian, se2_from_xytheta, se2_to_xytheta, se3_from_xyz_rpy,
    se3_to_xyz_rpy, to_rotation_first,
};
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::uncertain::{Side, UncertainPose};

fn poses() -> Vec<Se3> {
    vec![
        Se3::identity(),
        Se3::from_xyz_rpy([1.0, -2.0, 3.0], [0.3, -0.2, 1.1]),
        Se3::from_xyz_rpy([-4.0, 0.5, 0.0], [-2.5, 1.2, -3.0]),
        Se3::from_xyz_rpy([0.0, 0.0, 10.0], [3.0, -1.4, 0.2]),
    ]
}

fn ros_msg() -> RosPoseWithCovariance {
    let pose =
        UncertainPose::try_new(poses()[1], random_spd::<6>(5, 0.01), Side::Right).expect("valid");
    RosPoseWithCovariance::from_uncertain(&pose, RosReading::Tf2)
}

#[test]
fn ros_round_trips_both_ways() {
    for (i, mean) in poses().into_iter().enumerate() {
        for side in [Side::Right, Side::Left] {
            let pose = UncertainPose::try_new(mean, random_spd::<6>(i as u64, 0.01), Side::Right)
                .expect("valid")
                .to_side(side);
            let msg = RosPoseWithCovariance::from_uncertain(&pose, RosReading::Tf2);
            assert_eq!(msg.covariance.len(), 36);
            let back = msg.try_to_uncertain(RosReading::Tf2).expect("valid");
            assert_eq!(back.side(), Side::Right);
            assert!(back.mean().is_approx(&mean, 1e-14));
            assert_close(back.cov(), &pose.cov_right(), 1e-14, "Σ_right");
            // and message → pose → message
            assert_eq!(
                RosPoseWithCovariance::from_uncertain(&back, RosReading::Tf2)
                    .covariance
                    .len(),
                36
            );
            let again = RosPoseWithCovariance::from_uncertain(&back, RosReading::Tf2);
            let d = again
                .covariance
                .iter()
                .zip(&msg.covariance)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(d < 1e-14, "{d}");
        }
    }
}

/// B is the Jacobian of the ROS error with respect to the right-form tangent, by finite
/// differences: δp = p̃ − p in parent axes in both readings; δφ = Log(R̃ Rᵀ) (parent axes, tf2)
/// or δθ = Log(Rᵀ R̃) (body).
#[test]
fn ros_b_is_the_jacobian_of_the_ros_error() {
    for mean in poses() {
        for reading in [RosReading::Tf2, RosReading::Body] {
            let j: Matrix6<f64> = numeric_jacobian(
                |e| {
                    let x = mean.rplus(e);
                    let dp = x.translation() - mean.translation();
                    let dth = match reading {
                        RosReading::Tf2 => x.rotation().lminus(mean.rotation()),
                        RosReading::Body => x.rotation().rminus(mean.rotation()),
                    };
                    Vector6::new(dp.x, dp.y, dp.z, dth.x, dth.y, dth.z)
                },
                1e-6,
            );
            assert_close(&j, &ros_error_jacobian(mean.rotation(), reading), 1e-8, "B");
        }
    }
}

#[test]
fn ros_json_is_plain_data() {
    let msg = ros_msg();
    let json = serde_json::to_string(&msg).expect("serialisable");
    let back: RosPoseWithCovariance = serde_json::from_str(&json).expect("deserialisable");
    // serde_json without `float_roundtrip` may move the last bit.
    let close = |a: &[f64], b: &[f64]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-15 * x.abs().max(1.0))
    };
    assert!(close(&back.covariance, &msg.covariance));
    assert!(
        close(&back.position, &msg.position)
            && close(&back.orientation_xyzw, &msg.orientation_xyzw)
    );
    assert!(back.try_to_uncertain(RosReading::Tf2).is_ok());
}

#[test]
fn ros_invalid_inputs_name_the_field() {
    let good = ros_msg();
    for len in [0, 35, 37] {
        let mut m = good.clone();
        m.covariance.resize(len, 0.0);
        assert!(matches!(
            m.try_to_uncertain(RosReading::Tf2),
            Err(Error::WrongLength { what: "PoseWithCovariance.covariance", expected: 36, got }) if got == len
        ));
    }
    let mut m = good.clone();
    m.covariance[7] = f64::NAN;
    assert!(matches!(
        m.try_to_uncertain(RosReading::Tf2),
        Err(Error::NonFinite {
            what: "PoseWithCovariance.covariance",
            index: 7,
            ..
        })
    ));
    let mut m = good.clone();
    m.covariance[1] += 0.5; // (0, 1) ≠ (1, 0)
    assert!(matches!(
        m.try_to_uncertain(RosReading::Tf2),
        Err(Error::NotSymmetric {
            what: "PoseWithCovariance.covariance",
            row: 0,
            col: 1,
            ..
        })
    ));
    let mut m = good.clone();
    m.covariance[0] = -1.0; // ROS's "unknown" marker is not a covariance
    assert!(matches!(
        m.try_to_uncertain(RosReading::Tf2),
        Err(Error::NotPositiveSemiDefinite {
            what: "PoseWithCovariance.covariance",
            ..
        })
    ));
    let mut m = good.clone();
    m.position[2] = f64::INFINITY;
    assert!(matches!(
        m.try_to_uncertain(RosReading::Tf2),
        Err(Error::NonFinite {
            what: "PoseWithCovariance.pose.position",
            index: 2,
            ..
        })
    ));
    let mut m = good.clone();
    m.orientation_xyzw = [0.0, 0.0, 1.0, 1.0];
    assert!(matches!(
        m.try_to_uncertain(RosReading::Tf2),
        Err(Error::QuaternionNotUnit { .. })
    ));
}

#[test]
fn rotation_first_sources_round_trip_on_their_side() {
    let pose =
        UncertainPose::try_new(poses()[2], random_spd::<6>(9, 0.02), Side::Right).expect("valid");
    for source in [
        RotationFirstSource::GtsamPose3,
        RotationFirstSource::SophusRs,
        RotationFirstSource::EemeE6911,
    ] {
        let (mean, cov_rf) = to_rotation_first(source, &pose);
        // The rotation block comes first, on the source's side.
        let own_side = pose.to_side(source.side());
        assert_close(
            &cov_rf.fixed_view::<3, 3>(0, 0).into_owned(),
            &own_side.cov().fixed_view::<3, 3>(3, 3).into_owned(),
            0.0,
            "θθ first",
        );
        assert_close(
            &cov_rf.fixed_view::<3, 3>(0, 3).into_owned(),
            &own_side.cov().fixed_view::<3, 3>(3, 0).into_owned(),
            0.0,
            "θρ block",
        );
        let back = from_rotation_first(source, mean, &cov_rf).expect("valid");
        assert_eq!(back.side(), source.side());
        assert_close(&back.cov_right(), pose.cov(), 1e-14, "round trip");
    }
    let mut bad = Matrix6::identity();
    bad[(0, 5)] = 2.0;
    bad[(5, 0)] = 2.0;
    assert!(matches!(
        from_rotation_first(RotationFirstSource::GtsamPose3, Se3::identity(), &bad),
        Err(Error::NotPositiveSemiDefinite { .. })
    ));
}

#[test]
fn se2_xytheta_jacobian_and_round_trip() {
    for (i, mean) in [
        Se2::identity(),
        Se2::from_xy_theta(1.0, 2.0, 0.5),
        Se2::from_xy_theta(-3.0, 0.5, -2.9),
    ]
    .into_iter()
    .enumerate()
    {
        let v = mean.to_coordinates();
        let j: Matrix3<f64> = numeric_jacobian(|e| mean.rplus(e).to_coordinates() - v, 1e-6);
        assert_close(
            &j,
            &Se2::coordinates_jacobian(&v).expect("regular"),
            1e-8,
            "J(x,y,θ)",
        );
        let pose = UncertainPose::try_new(mean, random_spd::<3>(i as u64, 0.01), Side::Left)
            .expect("valid");
        let (v2, cov) = se2_to_xytheta(&pose);
        assert_close(&cov, &(j * pose.cov_right() * j.transpose()), 1e-9, "Σ_xyθ");
        let back = se2_from_xytheta(&v2, &cov).expect("valid");
        assert!(back.mean().is_approx(&mean, 1e-14));
        assert_close(back.cov(), &pose.cov_right(), 1e-14, "round trip");
    }
    assert!(matches!(
        se2_from_xytheta(&Vector3::new(0.0, f64::NAN, 0.0), &Matrix3::identity()),
        Err(Error::NonFinite { index: 1, .. })
    ));
    assert!(matches!(
        se2_from_xytheta(&Vector3::zeros(), &-Matrix3::identity()),
        Err(Error::NotPositiveSemiDefinite { .. })
    ));
}

/// The Euler-map Jacobian blkdiag(R, E_b⁻¹) against central differences of
/// (t, rpy)(μ Exp ε), at poses away from gimbal lock (|pitch| ≤ 1.4) and the yaw cut.
#[test]
fn euler_jacobian_matches_finite_differences() {
    for mean in poses() {
        let v = mean.to_coordinates();
        let j: Matrix6<f64> = numeric_jacobian(|e| mean.rplus(e).to_coordinates() - v, 1e-6);
        let analytic = Se3::coordinates_jacobian(&v).expect("not at gimbal lock");
        assert_close(&j, &analytic, 1e-7, "J(x,y,z,r,p,y)");
        assert_close(
            &(analytic * Se3::coordinates_jacobian_inverse(&v)),
            &Matrix6::identity(),
            1e-12,
            "J J⁻¹",
        );
    }
}

#[test]
fn euler_covariance_round_trips_and_rejects_gimbal_lock() {
    for (i, mean) in poses().into_iter().enumerate() {
        let pose = UncertainPose::try_new(mean, random_spd::<6>(20 + i as u64, 0.01), Side::Right)
            .expect("valid");
        let (v, cov) = se3_to_xyz_rpy(&pose).expect("not at gimbal lock");
        let back = se3_from_xyz_rpy(&v, &cov).expect("valid");
        assert!(back.mean().is_approx(&mean, 1e-13));
        assert_close(
            back.cov(),
            pose.cov(),
            1e-12 * pose.cov().amax().max(1.0),
            "round trip",
        );
    }
    let locked = Se3::from_xyz_rpy([0.0; 3], [0.1, std::f64::consts::FRAC_PI_2, 0.2]);
    let pose = UncertainPose::try_from_std_devs(locked, [0.1; 6], Side::Right).expect("valid");
    assert!(matches!(
        se3_to_xyz_rpy(&pose),
        Err(Error::OutOfRange {
            what: "pitch (rad)",
            ..
        })
    ));
    assert!(body_rates_to_euler_rates(0.0, f64::NAN).is_err());
    // From Euler coordinates at gimbal lock is fine: E_b is finite (Σ_right degenerate).
    let v = Vector6::new(0.0, 0.0, 0.0, 0.1, std::f64::consts::FRAC_PI_2, 0.2);
    assert!(se3_from_xyz_rpy(&v, &(Matrix6::identity() * 0.01)).is_ok());
}
