//! Fusion (Barfoot & Furgale 2014 §IV) and the vector-space (Smith–Self–Cheeseman) baseline.

use crate::common::{assert_close, numeric_jacobian, random_spd};
use crate::{assert_valid_covariance, x_pose};
use nalgebra::{Matrix3, Matrix6, Vector1, Vector3, Vector6};
use posecov::Error;
use posecov::interop::VectorChart;
use posecov::lie::{LieGroup, Se2, Se3, So2};
use posecov::propagate::fusion::{FusionError, FusionOptions, fuse};
use posecov::propagate::vector_space::{VectorPose, ssc_compose, ssc_inverse, ssc_odometry};
use posecov::uncertain::{Method, Side, UncertainPose};

#[test]
fn fusion_of_identical_estimates_is_the_estimate_with_cov_over_n() {
    let x = x_pose(Side::Right);
    for n in 1..=5 {
        let estimates = vec![x; n];
        let fused = fuse(&estimates, FusionOptions::default()).expect("converges");
        assert!(fused.result.pose.mean().is_approx(x.mean(), 1e-14));
        assert_close(fused.result.pose.cov(), &(x.cov() / n as f64), 1e-14, "Σ/N");
        assert!(fused.cost.abs() < 1e-20);
        assert_eq!(fused.result.method, Method::FirstOrder);
    }
    // Left-form inputs are converted: the answer is the same.
    let xl = x.to_side(Side::Left);
    let fused = fuse(&[xl, xl, xl], FusionOptions::default()).expect("converges");
    assert_close(
        fused.result.pose.cov(),
        &(x.cov() / 3.0),
        1e-14,
        "left inputs",
    );
}

/// On SO(2) (commutative, Jr = 1) the fusion is exactly the information-weighted mean.
#[test]
fn fusion_on_so2_is_the_weighted_mean() {
    let a =
        UncertainPose::try_from_std_devs(So2::from_angle(0.2), [0.1], Side::Right).expect("valid");
    let b =
        UncertainPose::try_from_std_devs(So2::from_angle(0.5), [0.2], Side::Right).expect("valid");
    let fused = fuse(&[a, b], FusionOptions::default()).expect("converges");
    let (wa, wb) = (100.0, 25.0);
    let expected = (0.2 * wa + 0.5 * wb) / (wa + wb);
    assert!((fused.result.pose.mean().angle() - expected).abs() < 1e-12);
    assert!((fused.result.pose.cov()[(0, 0)] - 1.0 / (wa + wb)).abs() < 1e-15);
    let cost = wa * (expected - 0.2f64).powi(2) + wb * (expected - 0.5f64).powi(2);
    assert!((fused.cost - cost).abs() < 1e-12);
    let _ = Vector1::new(0.0);
}

/// Disagreeing SE(3) estimates: the fused mean is a stationary point of the cost (no small
/// step lowers it), and capping the iterations returns NotConverged with the last estimate.
#[test]
fn fusion_of_disagreeing_estimates_and_its_errors() {
    let a = x_pose(Side::Right);
    let shifted = a
        .mean()
        .rplus(&Vector6::new(0.3, -0.2, 0.1, 0.2, 0.1, -0.3));
    let b = UncertainPose::try_new(shifted, random_spd::<6>(12, 0.02), Side::Left).expect("valid");
    let fused = fuse(&[a, b], FusionOptions::default()).expect("converges");
    let cost_at = |m: &Se3| {
        [a, b]
            .iter()
            .map(|e| {
                let r = e.to_side(Side::Right);
                let eps = m.rminus(r.mean());
                (eps.transpose() * r.cov().try_inverse().expect("SPD") * eps)[(0, 0)]
            })
            .sum::<f64>()
    };
    let m = *fused.result.pose.mean();
    assert!((cost_at(&m) - fused.cost).abs() < 1e-9);
    for i in 0..6 {
        for s in [-1e-4, 1e-4] {
            let mut d = Vector6::zeros();
            d[i] = s;
            assert!(
                cost_at(&m.rplus(&d)) >= fused.cost - 1e-12,
                "not a minimum along {i}"
            );
        }
    }
    assert!(fused.iterations > 1);
    assert_valid_covariance(fused.result.pose.cov());

    match fuse(
        &[a, b],
        FusionOptions {
            max_iterations: 1,
            tolerance: 1e-10,
        },
    ) {
        Err(FusionError::NotConverged {
            source: Error::NotConverged { iterations: 1, .. },
            last,
        }) => {
            assert!(
                !last.result.pose.mean().is_approx(a.mean(), 1e-6),
                "the last estimate moved"
            );
            assert!(last.cost < cost_at(a.mean()));
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    assert!(matches!(
        fuse::<Se3, 6>(&[], FusionOptions::default()),
        Err(FusionError::Input(Error::TooFewSamples { got: 0, .. }))
    ));
    let mut singular = Matrix6::identity() * 0.01;
    singular[(2, 2)] = 0.0;
    let s = UncertainPose::try_new(*a.mean(), singular, Side::Right).expect("PSD");
    assert!(matches!(
        fuse(&[a, s], FusionOptions::default()),
        Err(FusionError::Estimate {
            index: 1,
            source: Error::SingularCovariance { .. }
        })
    ));
    assert!(matches!(
        fuse(
            &[a],
            FusionOptions {
                max_iterations: 0,
                tolerance: 1e-10
            }
        ),
        Err(FusionError::Input(Error::OutOfRange { .. }))
    ));
}

/// The generic chain-rule Jacobians equal Smith–Self–Cheeseman's closed forms in SE(2).
#[test]
fn ssc_se2_matches_the_closed_forms() {
    let (v1, v2) = (Vector3::new(1.0, 2.0, 0.7), Vector3::new(0.5, -0.3, -1.2));
    let (s1, s2) = (random_spd::<3>(30, 0.01), random_spd::<3>(31, 0.02));
    let a = VectorPose::<Se2, 3>::try_new(v1, s1).expect("valid");
    let b = VectorPose::<Se2, 3>::try_new(v2, s2).expect("valid");
    let c = ssc_compose(&a, &b).expect("valid");
    let (s, co) = v1.z.sin_cos();
    let v3 = Vector3::new(
        v1.x + v2.x * co - v2.y * s,
        v1.y + v2.x * s + v2.y * co,
        v1.z + v2.z,
    );
    let j1 = Matrix3::new(
        1.0,
        0.0,
        -(v3.y - v1.y),
        0.0,
        1.0,
        v3.x - v1.x,
        0.0,
        0.0,
        1.0,
    );
    let j2 = Matrix3::new(co, -s, 0.0, s, co, 0.0, 0.0, 0.0, 1.0);
    assert_close(c.mean(), &v3, 1e-14, "v3");
    assert_close(
        c.cov(),
        &(j1 * s1 * j1.transpose() + j2 * s2 * j2.transpose()),
        1e-14,
        "Σ3",
    );
    // SSC inverse: J = [[−c, −s, y′], [s, −c, −x′], [0, 0, −1]] with (x′, y′) = ⊖ position.
    let inv = ssc_inverse(&a).expect("valid");
    let (s, co) = v1.z.sin_cos();
    let (xi, yi) = (-v1.x * co - v1.y * s, v1.x * s - v1.y * co);
    let j = Matrix3::new(-co, -s, yi, s, -co, -xi, 0.0, 0.0, -1.0);
    assert_close(inv.mean(), &Vector3::new(xi, yi, -v1.z), 1e-14, "⊖ mean");
    assert_close(inv.cov(), &(j * s1 * j.transpose()), 1e-14, "⊖ Σ");
}

/// SE(3) SSC Jacobians against central differences of the Euler-coordinate compounding.
#[test]
fn ssc_se3_jacobians_match_finite_differences() {
    let v1 = Vector6::new(1.0, -2.0, 0.5, 0.3, -0.2, 1.1);
    let v2 = Vector6::new(2.0, 0.5, -1.0, -0.4, 0.6, 0.5);
    let (s1, s2) = (random_spd::<6>(40, 0.01), random_spd::<6>(41, 0.01));
    let f = |a: &Vector6<f64>, b: &Vector6<f64>| {
        let x = Se3::try_from_coordinates(a).expect("finite");
        let y = Se3::try_from_coordinates(b).expect("finite");
        x.compose(&y).to_coordinates()
    };
    let v3 = f(&v1, &v2);
    let j1: Matrix6<f64> = numeric_jacobian(|d| f(&(v1 + d), &v2) - v3, 1e-6);
    let j2: Matrix6<f64> = numeric_jacobian(|d| f(&v1, &(v2 + d)) - v3, 1e-6);
    let a = VectorPose::<Se3, 6>::try_new(v1, s1).expect("valid");
    let b = VectorPose::<Se3, 6>::try_new(v2, s2).expect("valid");
    let c = ssc_compose(&a, &b).expect("valid");
    assert_close(c.mean(), &v3, 1e-12, "mean");
    assert_close(
        c.cov(),
        &(j1 * s1 * j1.transpose() + j2 * s2 * j2.transpose()),
        1e-8,
        "Σ3",
    );
    assert_valid_covariance(c.cov());
    // Gimbal lock is a typed error, not a NaN.
    let locked = VectorPose::<Se3, 6>::try_new(
        Vector6::new(0.0, 0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0),
        Matrix6::identity() * 0.01,
    )
    .expect("valid");
    let still = VectorPose::<Se3, 6>::try_new(Vector6::zeros(), Matrix6::zeros()).expect("valid");
    assert!(matches!(
        ssc_compose(&locked, &still),
        Err(Error::OutOfRange {
            what: "pitch (rad)",
            ..
        })
    ));
    assert!(matches!(
        ssc_odometry(&still, &[Vector6::zeros()], &-Matrix6::identity()),
        Err(Error::NotPositiveSemiDefinite { .. })
    ));
}
