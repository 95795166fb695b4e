//! Uncertain poses: std-dev constructors, Mahalanobis distance, confidence helpers (χ²), and
//! marginals in body and world frames.

mod common;

use common::{assert_close, gaussian_draws, numeric_jacobian, random_spd};
use nalgebra::{Matrix2x3, Matrix3, Matrix3x6, Matrix6, Vector3, Vector6};
use posecov::Error;
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::uncertain::{
    Side, UncertainPose, chi2_probability, chi2_radius, sigma_probability, sigma_radius,
    try_inverse_covariance,
};

fn se3_pose(side: Side) -> UncertainPose<Se3, 6> {
    let mean = Se3::from_xyz_rpy([1.0, -2.0, 3.0], [0.3, -0.2, 1.1]);
    UncertainPose::try_new(mean, random_spd::<6>(7, 0.01), Side::Right)
        .expect("valid")
        .to_side(side)
}

#[test]
fn chi2_radii_match_the_tables() {
    // χ² quantiles from printed χ² tables, square-rooted.
    let cases = [
        (0.6827, 3, 1.8779),
        (0.95, 3, 2.7955),
        (0.95, 2, 2.4477),
        (0.99, 6, 4.1002), // χ²₆(0.99) = 16.812
        (0.95, 1, 1.9600),
    ];
    for (p, d, r) in cases {
        let got = chi2_radius(p, d).expect("valid");
        assert!((got - r).abs() < 1e-4, "p = {p}, d = {d}: {got} vs {r}");
    }
    assert!((sigma_radius(1.0, 3).expect("valid") - 1.8779).abs() < 1e-3);
    for (k, p) in [(1.0, 0.682689), (2.0, 0.954500), (3.0, 0.997300)] {
        assert!((sigma_probability(k).expect("valid") - p).abs() < 1e-6);
    }
}

#[test]
fn chi2_radius_and_probability_are_inverse() {
    for d in 1..=6 {
        for p in [0.01, 0.3, 0.6827, 0.95, 0.999] {
            let r = chi2_radius(p, d).expect("valid");
            let back = chi2_probability(r, d).expect("valid");
            assert!((back - p).abs() < 1e-9, "d = {d}, p = {p}: {back}");
        }
    }
}

#[test]
fn chi2_invalid_inputs_are_typed_errors() {
    for p in [0.0, 1.0, -0.1, 1.5, f64::NAN] {
        assert!(
            matches!(chi2_radius(p, 3), Err(Error::OutOfRange { .. })),
            "p = {p}"
        );
    }
    assert!(matches!(chi2_radius(0.5, 0), Err(Error::OutOfRange { .. })));
    assert!(matches!(
        chi2_probability(-1.0, 3),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        chi2_probability(f64::INFINITY, 3),
        Err(Error::OutOfRange { .. })
    ));
}

#[test]
fn std_dev_constructor_validates() {
    let p = UncertainPose::try_from_std_devs(
        Se3::identity(),
        [0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
        Side::Left,
    )
    .expect("valid");
    assert_close(
        &p.cov().diagonal(),
        &Vector6::new(0.01, 0.04, 0.09, 0.16, 0.25, 0.36),
        1e-15,
        "diag",
    );
    assert_eq!(p.side(), Side::Left);
    assert!(matches!(
        UncertainPose::try_from_std_devs(Se2::identity(), [0.1, -0.1, 0.0], Side::Right),
        Err(Error::OutOfRange { value, .. }) if value == -0.1
    ));
    assert!(matches!(
        UncertainPose::try_from_std_devs(Se2::identity(), [0.1, f64::NAN, 0.0], Side::Right),
        Err(Error::NonFinite { index: 1, .. })
    ));
}

#[test]
fn mahalanobis_is_side_independent_and_matches_the_definition() {
    let right = se3_pose(Side::Right);
    let left = right.to_side(Side::Left);
    let eps = Vector6::new(0.05, -0.02, 0.1, 0.01, 0.03, -0.02);
    let x = right.mean().rplus(&eps);
    let info = right.cov().try_inverse().expect("SPD");
    let expected = (eps.transpose() * info * eps)[(0, 0)];
    let d2_right = right.mahalanobis_squared(&x).expect("regular");
    let d2_left = left.mahalanobis_squared(&x).expect("regular");
    assert!((d2_right - expected).abs() < 1e-9 * expected);
    assert!(
        (d2_left - expected).abs() < 1e-9 * expected,
        "{d2_left} vs {expected}"
    );
    assert!((right.mahalanobis(&x).expect("regular") - expected.sqrt()).abs() < 1e-9);
}

/// E[d²] = N and Var[d²] = 2N for samples of the distribution itself: with n draws the mean
/// d² has standard error √(2N/n); 5 standard errors.
#[test]
fn mahalanobis_of_samples_is_chi2_distributed() {
    let pose = se3_pose(Side::Right);
    let n = 20_000;
    let draws = gaussian_draws(pose.cov(), n, 11);
    let mean_d2: f64 = draws
        .iter()
        .map(|e| {
            pose.mahalanobis_squared(&pose.mean().rplus(e))
                .expect("regular")
        })
        .sum::<f64>()
        / n as f64;
    let tolerance = 5.0 * (2.0 * 6.0 / n as f64).sqrt();
    assert!((mean_d2 - 6.0).abs() < tolerance, "mean d² = {mean_d2}");
    // The fraction inside the 95 % radius (d = 6) is 0.95 within 5 binomial standard errors.
    let r = chi2_radius(0.95, 6).expect("valid");
    let inside = draws
        .iter()
        .filter(|e| pose.mahalanobis(&pose.mean().rplus(e)).expect("regular") <= r)
        .count() as f64
        / n as f64;
    assert!(
        (inside - 0.95).abs() < 5.0 * (0.95 * 0.05 / n as f64).sqrt(),
        "{inside}"
    );
}

#[test]
fn singular_covariance_is_a_typed_error() {
    let mut cov = Matrix6::identity() * 0.01;
    cov[(5, 5)] = 0.0;
    let pose = UncertainPose::try_new(Se3::identity(), cov, Side::Right).expect("PSD is valid");
    assert!(matches!(
        pose.mahalanobis(&Se3::identity()),
        Err(Error::SingularCovariance { .. })
    ));
    assert!(matches!(
        try_inverse_covariance("Σ", &Matrix3::zeros()),
        Err(Error::SingularCovariance { .. })
    ));
    assert!(matches!(
        try_inverse_covariance(
            "Σ",
            &Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0)
        ),
        Err(Error::NotPositiveSemiDefinite { .. })
    ));
}

/// Position marginals against the first-order map of the position itself: ∂t(μ Exp ε)/∂ε
/// by finite differences, J Σ Jᵀ. Same answer from a right- or left-form input.
#[test]
fn se3_position_marginals_are_the_first_order_position_covariance() {
    for side in [Side::Right, Side::Left] {
        let pose = se3_pose(side);
        let mean = *pose.mean();
        let j: Matrix3x6<f64> =
            numeric_jacobian(|e| mean.rplus(e).translation() - mean.translation(), 1e-6);
        let expected = j * pose.cov_right() * j.transpose();
        assert_close(
            &pose.position_cov_in_world(),
            &expected,
            1e-9,
            "world position",
        );
        let r = mean.rotation().to_matrix();
        assert_close(
            &pose.position_cov_in_body(),
            &(r.transpose() * expected * r),
            1e-9,
            "body position",
        );
        // Not the left form's ρρ block (t ≠ 0): a left perturbation moves t by ρ + θ × t.
        let left_rho = pose.cov_left().fixed_view::<3, 3>(0, 0).into_owned();
        assert!((left_rho - expected).norm() > 1e-3);
        // Rotation: world = left θθ block, body = right θθ block.
        assert_close(
            &pose.rotation_cov_in_world(),
            &pose.cov_left().fixed_view::<3, 3>(3, 3).into_owned(),
            1e-15,
            "world rotation",
        );
        assert_close(
            pose.rotation_marginal().cov(),
            &pose.cov_right().fixed_view::<3, 3>(3, 3).into_owned(),
            1e-15,
            "rotation marginal",
        );
    }
}

#[test]
fn se2_position_marginals_are_the_first_order_position_covariance() {
    let mean = Se2::from_xy_theta(2.0, -1.0, 2.3);
    let pose = UncertainPose::try_new(mean, random_spd::<3>(3, 0.02), Side::Left).expect("valid");
    let j: Matrix2x3<f64> =
        numeric_jacobian(|e| mean.rplus(e).translation() - mean.translation(), 1e-6);
    assert_close(
        &pose.position_cov_in_world(),
        &(j * pose.cov_right() * j.transpose()),
        1e-9,
        "world position",
    );
    assert!((pose.heading_variance() - pose.cov_right()[(2, 2)]).abs() < 1e-15);
    assert!((pose.rotation_marginal().cov()[(0, 0)] - pose.heading_variance()).abs() < 1e-15);
    assert_eq!(pose.position(), Vector3::new(2.0, -1.0, 0.0).xy());
}
