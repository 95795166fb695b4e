//! Construction, conversion and validation: every constructor round-trips and every invalid
//! input returns its typed error; the exactly-π Log is defined.

mod common;

use std::f64::consts::PI;

use common::assert_close;
use nalgebra::{
    Isometry2, Isometry3, Matrix2, Matrix3, Matrix4, UnitQuaternion, Vector2, Vector3, Vector6,
};
use posecov::Error;
use posecov::convert::{se2_to_se3, se3_to_glam, se3_to_glam_affine, so3_to_glam};
use posecov::lie::{LieGroup, Se2, Se3, So2, So3};

#[test]
fn matrices_round_trip() {
    let x = Se3::from_xyz_rpy([1.0, -2.0, 3.0], [0.3, -0.2, 2.5]);
    assert!(
        Se3::try_from_matrix(&x.to_matrix())
            .unwrap()
            .is_approx(&x, 1e-14)
    );
    assert!(
        So3::try_from_matrix(&x.rotation().to_matrix())
            .unwrap()
            .is_approx(x.rotation(), 1e-14)
    );
    let y = Se2::from_xy_theta(1.0, -2.0, 2.9);
    assert!(
        Se2::try_from_matrix(&y.to_matrix())
            .unwrap()
            .is_approx(&y, 1e-14)
    );
    assert!(
        So2::try_from_matrix(&y.rotation().to_matrix())
            .unwrap()
            .is_approx(y.rotation(), 1e-14)
    );
}

#[test]
fn nalgebra_and_glam_round_trip() {
    let x = Se3::from_xyz_rpy([1.0, -2.0, 3.0], [0.3, -0.2, 2.5]);
    let iso: Isometry3<f64> = x.into();
    assert_eq!(Se3::from(iso), x);
    let q: UnitQuaternion<f64> = (*x.rotation()).into();
    assert_eq!(So3::from(q), *x.rotation());
    let y = Se2::from_xy_theta(1.0, -2.0, 2.9);
    let iso2: Isometry2<f64> = y.into();
    assert!(Se2::from(iso2).is_approx(&y, 1e-15));
    // glam (f32): same action on a point to f32 precision.
    let p = Vector3::new(0.5, -1.0, 2.0);
    let expect = x.act(&p);
    let got = se3_to_glam_affine(&x).transform_point3(glam::Vec3::new(0.5, -1.0, 2.0));
    assert!(
        (got - glam::Vec3::new(expect.x as f32, expect.y as f32, expect.z as f32)).length() < 1e-5
    );
    let (t, r) = se3_to_glam(&x);
    assert!((r - so3_to_glam(x.rotation())).length() < 1e-7 && t.x == 1.0);
    // SE(2) lifted to SE(3) acts the same in the plane.
    let y3 = se2_to_se3(&y);
    let p2 = y.act(&Vector2::new(0.3, 0.4));
    assert_close(
        &y3.act(&Vector3::new(0.3, 0.4, 0.0)),
        &Vector3::new(p2.x, p2.y, 0.0),
        1e-14,
        "lift",
    );
}

#[test]
#[allow(clippy::approx_constant)] // 0.7071 is deliberately a rounded 1/√2
fn quaternions_euler_axis_angle_round_trip() {
    let r = So3::from_rpy(0.3, -0.2, 2.5);
    let back = So3::try_from_quaternion_xyzw(r.to_quaternion_xyzw()).unwrap();
    assert!(back.is_approx(&r, 1e-15));
    let [roll, pitch, yaw] = r.to_rpy();
    assert_close(
        &Vector3::new(roll, pitch, yaw),
        &Vector3::new(0.3, -0.2, 2.5),
        1e-14,
        "rpy",
    );
    let [yaw2, pitch2, roll2] = So3::from_euler_zyx(2.5, -0.2, 0.3).to_euler_zyx();
    assert_close(
        &Vector3::new(yaw2, pitch2, roll2),
        &Vector3::new(2.5, -0.2, 0.3),
        1e-14,
        "zyx",
    );
    // R = Rz(yaw) Ry(pitch) Rx(roll), checked by matrices.
    let rz = So3::try_from_axis_angle(&Vector3::z(), 2.5)
        .unwrap()
        .to_matrix();
    let ry = So3::try_from_axis_angle(&Vector3::y(), -0.2)
        .unwrap()
        .to_matrix();
    let rx = So3::try_from_axis_angle(&Vector3::x(), 0.3)
        .unwrap()
        .to_matrix();
    assert_close(&r.to_matrix(), &(rz * ry * rx), 1e-14, "rpy order");
    // Rounded quaternions are normalised; the result is unit.
    let q = So3::try_from_quaternion_xyzw([0.0, 0.0, 0.7071, 0.7071]).unwrap();
    assert!((q.quaternion().norm() - 1.0).abs() < 1e-15);
}

#[test]
fn log_at_exactly_pi_is_defined() {
    // Both q and −q at θ = π give the same, documented answer: π · axis, first non-zero
    // component positive.
    for xyzw in [[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -1.0, 0.0]] {
        let r = So3::try_from_quaternion_xyzw(xyzw).unwrap();
        assert_close(&r.log(), &Vector3::new(0.0, 0.0, PI), 0.0, "SO3 Log at π");
    }
    let r = So3::try_from_matrix(&Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, -1.0))).unwrap();
    assert_close(
        &r.log(),
        &Vector3::new(0.0, PI, 0.0),
        1e-15,
        "SO3 Log at π from matrix",
    );
    let x = Se3::from_parts(Vector3::new(1.0, 2.0, 3.0), r);
    assert!(Se3::exp(&x.log()).is_approx(&x, 1e-12));
    assert!(x.log().iter().all(|v| v.is_finite()));
    let y = Se2::from_xy_theta(1.0, 2.0, PI);
    assert!((y.log().z - PI).abs() < 1e-15 && Se2::exp(&y.log()).is_approx(&y, 1e-12));
    assert!(
        So3::jr_inv(&Vector3::new(0.0, 0.0, PI))
            .iter()
            .all(|v| v.is_finite())
    );
    assert!(
        Se3::jr_inv(&Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, PI))
            .iter()
            .all(|v| v.is_finite())
    );
}

#[test]
fn no_nan_for_finite_extremes() {
    for angle in [
        0.0,
        1e-300,
        1e-12,
        1e-8,
        0.1,
        PI - 1e-12,
        PI,
        2.0 * PI - 1e-3,
        10.0,
        1e6,
    ] {
        let phi = Vector3::new(angle, 0.0, 0.0);
        let xi = Vector6::new(1e3, -1e3, 5.0, 0.0, angle, 0.0);
        let tau = Vector3::new(1e3, -2.0, angle);
        for m in [So3::exp(&phi).log(), So3::jr(&phi).column(0).into_owned()] {
            assert!(m.iter().all(|v| v.is_finite()), "SO3 at {angle}");
        }
        assert!(
            Se3::exp(&xi).log().iter().all(|v| v.is_finite()),
            "SE3 at {angle}"
        );
        assert!(
            Se3::jr(&xi).iter().all(|v| v.is_finite()),
            "SE3 Jr at {angle}"
        );
        assert!(
            Se2::exp(&tau).log().iter().all(|v| v.is_finite()),
            "SE2 at {angle}"
        );
        assert!(
            Se2::jr_inv(&tau).iter().all(|v| v.is_finite()),
            "SE2 Jr⁻¹ at {angle}"
        );
    }
}

#[test]
fn invalid_matrices_are_rejected_with_what_and_how_much() {
    // Not orthonormal: scaled rotation.
    let err = So3::try_from_matrix(&(Matrix3::identity() * 1.01)).unwrap_err();
    match err {
        Error::NotOrthonormal {
            deviation,
            tolerance,
            ..
        } => {
            assert!((deviation - 0.0201).abs() < 1e-12 && tolerance == 1e-6)
        }
        other => panic!("unexpected {other}"),
    }
    // Reflection.
    let err =
        So3::try_from_matrix(&Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0))).unwrap_err();
    assert!(
        matches!(err, Error::NotRightHanded { determinant, .. } if determinant == -1.0),
        "{err}"
    );
    assert!(err.to_string().contains("reflection"));
    // Non-finite, with its index (row-major).
    let mut m = Matrix4::identity();
    m[(1, 2)] = f64::NAN;
    let err = Se3::try_from_matrix(&m).unwrap_err();
    assert!(matches!(err, Error::NonFinite { index: 6, .. }), "{err}");
    // Last row not exact.
    let mut m = Matrix4::identity();
    m[(3, 3)] = 1.0 + 1e-12;
    assert!(matches!(
        Se3::try_from_matrix(&m),
        Err(Error::BadLastRow { .. })
    ));
    let mut m3 = Matrix3::identity();
    m3[(2, 0)] = 0.5;
    assert!(matches!(
        Se2::try_from_matrix(&m3),
        Err(Error::BadLastRow { .. })
    ));
    assert!(matches!(
        So2::try_from_matrix(&Matrix2::new(1.0, 0.1, 0.0, 1.0)),
        Err(Error::NotOrthonormal { .. })
    ));
}

#[test]
fn invalid_quaternions_and_axes_are_rejected() {
    let err = So3::try_from_quaternion_xyzw([0.0, 0.0, 0.0, 2.0]).unwrap_err();
    assert!(
        matches!(err, Error::QuaternionNotUnit { norm, .. } if norm == 2.0),
        "{err}"
    );
    assert!(matches!(
        So3::try_from_quaternion_xyzw([0.0, 0.0, 0.0, 0.0]),
        Err(Error::QuaternionNotUnit { .. })
    ));
    assert!(matches!(
        So3::try_from_quaternion_xyzw([0.0, f64::INFINITY, 0.0, 1.0]),
        Err(Error::NonFinite { index: 1, .. })
    ));
    assert!(matches!(
        So3::try_from_axis_angle(&Vector3::zeros(), 1.0),
        Err(Error::ZeroAxis { .. })
    ));
    assert!(matches!(
        So3::try_from_axis_angle(&Vector3::x(), f64::NAN),
        Err(Error::NonFinite { index: 3, .. })
    ));
    assert!(matches!(
        Se3::try_from_xyz_quaternion_xyzw([0.0, 0.0, f64::NAN], [0.0, 0.0, 0.0, 1.0]),
        Err(Error::NonFinite { index: 2, .. })
    ));
}

#[test]
fn display_is_readable() {
    let x = Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0, 0.0, PI / 2.0]);
    assert_eq!(
        x.to_string(),
        "SE(3) t = [1.000000, 2.000000, 3.000000], rpy = [0.000, -0.000, 90.000] deg"
    );
    assert_eq!(
        Se2::from_xy_theta(1.0, 2.0, PI).to_string(),
        "SE(2) x = 1.000000, y = 2.000000, θ = 180.000 deg"
    );
    assert_eq!(
        So2::from_angle(-PI / 4.0).to_string(),
        "SO(2) θ = -45.000 deg"
    );
}
