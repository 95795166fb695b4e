//! First-order operations (change of frame, inverse, compose, between — independent and
//! correlated —, points), fusion and the vector-space baseline: formulas against finite
//! differences and Monte Carlo, sides against each other, and every invalid input.

#[path = "../common/mod.rs"]
mod common;
mod fusion_and_ssc;

use common::{assert_close, gaussian_draws, numeric_jacobian, random_spd, uncentred_cov};
use nalgebra::{DMatrix, Matrix2, Matrix3, Matrix6, SMatrix, Vector2, Vector3, Vector6};
use posecov::Error;
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::propagate::first_order::{
    CorrelatedPair, act_point, between, between_correlated, change_frame_left, change_frame_right,
    compose, compose_correlated, inverse,
};
use posecov::propagate::odometry::{InputNoise, propagate_increments, propagate_tangent_inputs};
use posecov::propagate::{Propagated, relative_frobenius_error};
use posecov::uncertain::{Method, Side, UncertainPose, validate_covariance};

pub(crate) fn x_pose(side: Side) -> UncertainPose<Se3, 6> {
    let mean = Se3::from_xyz_rpy([1.0, -2.0, 0.5], [0.3, -0.2, 1.1]);
    UncertainPose::try_new(mean, random_spd::<6>(1, 0.01), Side::Right)
        .expect("valid")
        .to_side(side)
}

fn y_pose(side: Side) -> UncertainPose<Se3, 6> {
    let mean = Se3::from_xyz_rpy([2.0, 0.5, -1.0], [-0.4, 0.6, 2.0]);
    UncertainPose::try_new(mean, random_spd::<6>(2, 0.01), Side::Right)
        .expect("valid")
        .to_side(side)
}

#[track_caller]
pub(crate) fn assert_valid_covariance<const N: usize>(cov: &SMatrix<f64, N, N>) {
    assert_eq!(cov, &cov.transpose(), "exactly symmetric");
    validate_covariance("propagated", cov).expect("symmetric PSD");
}

/// Deterministic factors and inversion move a Gaussian ε through a linear map with no
/// truncation: for large perturbations (‖ε‖ ≈ 1) the output perturbation is exactly L ε,
/// and the reported Σ is L Σ Lᵀ.
#[test]
fn frame_changes_and_inverse_are_exact() {
    let a = Se3::from_xyz_rpy([10.0, 0.0, -3.0], [0.5, 0.1, -1.0]);
    let eps = Vector6::new(0.8, -0.5, 0.3, 0.6, -0.4, 0.7);
    for side in [Side::Right, Side::Left] {
        let x = x_pose(side);
        let perturbed = match side {
            Side::Right => x.mean().rplus(&eps),
            Side::Left => x.mean().lplus(&eps),
        };
        let cases: [(Propagated<Se3, 6>, Se3); 3] = [
            (change_frame_left(&a, &x), a.compose(&perturbed)),
            (change_frame_right(&x, &a), perturbed.compose(&a)),
            (inverse(&x), perturbed.inverse()),
        ];
        for (i, (out, sample)) in cases.iter().enumerate() {
            assert_eq!(out.method, Method::Exact);
            assert_eq!(out.pose.side(), side);
            assert_valid_covariance(out.pose.cov());
            // The linear map L, read off the output perturbation of unit tangents (exact
            // linearity checked with the large ε below).
            let l = numeric_jacobian(
                |e| {
                    let p = match side {
                        Side::Right => x.mean().rplus(e),
                        Side::Left => x.mean().lplus(e),
                    };
                    let s = match i {
                        0 => a.compose(&p),
                        1 => p.compose(&a),
                        _ => p.inverse(),
                    };
                    out.pose.perturbation_of(&s)
                },
                1e-6,
            );
            // 1e-8: the central-difference L carries ~1e-10 relative error, times |L ε| ≈ 10.
            assert_close(
                &out.pose.perturbation_of(sample),
                &(l * eps),
                1e-8,
                "exactly linear",
            );
            assert_close(
                out.pose.cov(),
                &(l * x.cov() * l.transpose()),
                1e-9,
                "L Σ Lᵀ",
            );
        }
    }
}

#[test]
fn compose_and_between_match_conventions_and_sides_agree() {
    let (xr, yr) = (x_pose(Side::Right), y_pose(Side::Right));
    let (xl, yl) = (x_pose(Side::Left), y_pose(Side::Left));
    // docs/CONVENTIONS.md §5 closed forms.
    let ad_y_inv = yr.mean().inverse().adj();
    let right = compose(&xr, &yr);
    assert_eq!(right.method, Method::FirstOrder);
    assert_close(
        right.pose.cov(),
        &(ad_y_inv * xr.cov() * ad_y_inv.transpose() + yr.cov()),
        1e-15,
        "compose right",
    );
    let ad_x = xl.mean().adj();
    let left = compose(&xl, &yl);
    assert_eq!(left.pose.side(), Side::Left);
    assert_close(
        left.pose.cov(),
        &(xl.cov() + ad_x * yl.cov() * ad_x.transpose()),
        1e-14,
        "compose left",
    );
    assert_close(
        &left.pose.cov_right(),
        right.pose.cov(),
        1e-13,
        "compose sides agree",
    );
    // Mixed sides: y is converted to x's side.
    assert_close(
        compose(&xr, &yl).pose.cov(),
        right.pose.cov(),
        1e-13,
        "mixed",
    );
    // between
    let b_right = between(&xr, &yr);
    let b_left = between(&xl, &yl);
    let ad_xi = xl.mean().inverse().adj();
    assert_close(
        b_left.pose.cov(),
        &(ad_xi * (xl.cov() + yl.cov()) * ad_xi.transpose()),
        1e-13,
        "between left",
    );
    assert_close(
        &b_left.pose.cov_right(),
        b_right.pose.cov(),
        1e-13,
        "between sides agree",
    );
    for p in [right, left, b_right, b_left] {
        assert_valid_covariance(p.pose.cov());
    }
}

/// Joint perturbation → output perturbation, by finite differences on both inputs at once:
/// the Jacobian the correlated formulas use, for each side.
#[test]
fn correlated_jacobians_match_finite_differences() {
    let (x, y) = (*x_pose(Side::Right).mean(), *y_pose(Side::Right).mean());
    let joint = DMatrix::from_fn(12, 12, |r, c| random_spd::<12>(4, 0.01)[(r, c)]);
    for side in [Side::Right, Side::Left] {
        let pair = CorrelatedPair::try_new(x, y, &joint, side).expect("valid");
        for (op, out) in [
            (0, compose_correlated(&pair)),
            (1, between_correlated(&pair)),
        ] {
            let j: SMatrix<f64, 6, 12> = numeric_jacobian(
                |e: &SMatrix<f64, 12, 1>| {
                    let (ex, ey) = (
                        e.fixed_rows::<6>(0).into_owned(),
                        e.fixed_rows::<6>(6).into_owned(),
                    );
                    let (xp, yp) = match side {
                        Side::Right => (x.rplus(&ex), y.rplus(&ey)),
                        Side::Left => (x.lplus(&ex), y.lplus(&ey)),
                    };
                    let z = if op == 0 {
                        xp.compose(&yp)
                    } else {
                        xp.between(&yp)
                    };
                    out.pose.perturbation_of(&z)
                },
                1e-6,
            );
            let js = SMatrix::<f64, 12, 12>::from_fn(|r, c| joint[(r, c)]);
            let expected = j * js * j.transpose();
            assert_close(
                out.pose.cov(),
                &expected,
                1e-9,
                &format!("op {op} {side:?}"),
            );
            assert_valid_covariance(out.pose.cov());
        }
        let back = pair.to_side(Side::Right);
        let right_pair = CorrelatedPair::try_new(x, y, &joint, side)
            .expect("valid")
            .to_side(Side::Right);
        assert_eq!(back, right_pair);
    }
}

/// Y = X · D with Y's error mostly X's error carried along (εY = Ad_{D⁻¹} εX + ν), the
/// situation of two poses of one odometry chain. Monte Carlo over the joint 12-D Gaussian
/// (Cholesky), n = 40 000 draws, uncentred covariance of the output perturbation about the
/// propagated mean.
///
/// Tolerance: for Gaussian ε, E‖S − Σ‖²_F = (‖Σ‖²_F + (tr Σ)²)/n, so the RMS relative
/// Frobenius sampling error is s = √((1 + (tr Σ)²/‖Σ‖²_F)/n) (≤ √(7/n) for d = 6). We
/// allow 4 s plus 2 % for the linearisation (σ_θ ≈ 0.05 rad: second-order terms
/// ~σ² relative). The independent formula must miss by more than 3× that tolerance
/// (measured: between 52.5 vs tolerance 0.062, compose 0.44 vs 0.058).
#[test]
fn correlated_relative_pose_matches_monte_carlo_where_independent_fails() {
    let x = Se3::from_xyz_rpy([1.0, -2.0, 0.5], [0.3, -0.2, 1.1]);
    let d = Se3::from_xyz_rpy([2.0, 0.5, 0.3], [0.1, -0.2, 0.4]);
    let y = x.compose(&d);
    let sxx = random_spd::<6>(8, 0.002);
    let nu = random_spd::<6>(9, 0.0002);
    let ad = d.inverse().adj();
    let mut joint = SMatrix::<f64, 12, 12>::zeros();
    joint.fixed_view_mut::<6, 6>(0, 0).copy_from(&sxx);
    joint
        .fixed_view_mut::<6, 6>(0, 6)
        .copy_from(&(sxx * ad.transpose()));
    joint.fixed_view_mut::<6, 6>(6, 0).copy_from(&(ad * sxx));
    joint
        .fixed_view_mut::<6, 6>(6, 6)
        .copy_from(&(ad * sxx * ad.transpose() + nu));
    let joint_dyn = DMatrix::from_fn(12, 12, |r, c| joint[(r, c)]);
    let pair = CorrelatedPair::try_new(x, y, &joint_dyn, Side::Right).expect("valid joint");
    let px = UncertainPose::try_new(x, sxx, Side::Right).expect("valid");
    let py = UncertainPose::try_new(y, joint.fixed_view::<6, 6>(6, 6).into_owned(), Side::Right)
        .expect("valid");

    let n = 40_000;
    let draws = gaussian_draws(&joint, n, 2020);
    for (name, correlated, independent, op) in [
        ("between", between_correlated(&pair), between(&px, &py), 1),
        ("compose", compose_correlated(&pair), compose(&px, &py), 0),
    ] {
        let errors: Vec<Vector6<f64>> = draws
            .iter()
            .map(|e| {
                let xs = x.rplus(&e.fixed_rows::<6>(0).into_owned());
                let ys = y.rplus(&e.fixed_rows::<6>(6).into_owned());
                let z = if op == 1 {
                    xs.between(&ys)
                } else {
                    xs.compose(&ys)
                };
                correlated.pose.perturbation_of(&z)
            })
            .collect();
        let mc = uncentred_cov(&errors);
        let reference = correlated.pose.cov();
        let ratio = reference.trace().powi(2) / reference.norm_squared();
        let tolerance = 4.0 * ((1.0 + ratio) / n as f64).sqrt() + 0.02;
        let e_corr = relative_frobenius_error(reference, &mc);
        let e_ind = relative_frobenius_error(independent.pose.cov(), &mc);
        eprintln!(
            "{name}: correlated vs MC {e_corr:.4}, independent vs MC {e_ind:.4}, tolerance {tolerance:.4} (n = {n})"
        );
        assert!(
            e_corr < tolerance,
            "{name}: correlated formula off by {e_corr}"
        );
        assert!(
            e_ind > 3.0 * tolerance,
            "{name}: independent formula should fail, {e_ind}"
        );
    }
}

#[test]
fn correlated_pair_rejects_bad_joints() {
    let x = Se2::identity();
    assert!(matches!(
        CorrelatedPair::try_new(x, x, &DMatrix::identity(6, 5), Side::Right),
        Err(Error::WrongShape {
            expected_rows: 6,
            expected_cols: 6,
            rows: 6,
            cols: 5,
            ..
        })
    ));
    assert!(matches!(
        CorrelatedPair::try_new(x, x, &DMatrix::identity(4, 4), Side::Right),
        Err(Error::WrongShape { rows: 4, .. })
    ));
    let mut j = DMatrix::identity(6, 6);
    j[(0, 3)] = 1.5;
    j[(3, 0)] = 1.5;
    assert!(matches!(
        CorrelatedPair::try_new(x, x, &j, Side::Right),
        Err(Error::NotPositiveSemiDefinite {
            what: "joint covariance",
            ..
        })
    ));
    j[(3, 0)] = 0.0;
    assert!(matches!(
        CorrelatedPair::try_new(x, x, &j, Side::Right),
        Err(Error::NotSymmetric { .. })
    ));
    j[(3, 0)] = f64::NAN;
    assert!(matches!(
        CorrelatedPair::try_new(x, x, &j, Side::Right),
        Err(Error::NonFinite { .. })
    ));
}

/// q = X · p with X and p uncertain: J Σ Jᵀ against central differences in (ε, δp), for SE(3)
/// and SE(2), from right- and left-form poses.
#[test]
fn uncertain_point_from_uncertain_pose() {
    let p = Vector3::new(4.0, -1.0, 2.0);
    let cov_p = random_spd::<3>(3, 0.001);
    for side in [Side::Right, Side::Left] {
        let x = x_pose(side);
        let mean = *x.mean();
        let q = act_point(&x, &p, &cov_p).expect("valid");
        assert_eq!(q.method, Method::FirstOrder);
        let jx: SMatrix<f64, 3, 6> =
            numeric_jacobian(|e| mean.rplus(e).act(&p) - mean.act(&p), 1e-6);
        let jp: Matrix3<f64> = numeric_jacobian(|d| mean.act(&(p + d)) - mean.act(&p), 1e-6);
        let expected = jx * x.cov_right() * jx.transpose() + jp * cov_p * jp.transpose();
        assert_close(&q.cov, &expected, 1e-9, "SE(3) point");
        assert_close(&q.mean, &mean.act(&p), 1e-14, "mean");
        assert_valid_covariance(&q.cov);
    }
    let x2 = UncertainPose::try_new(
        Se2::from_xy_theta(1.0, 2.0, 0.7),
        random_spd::<3>(5, 0.01),
        Side::Right,
    )
    .expect("valid");
    let p2 = Vector2::new(3.0, -1.0);
    let q2 = act_point(&x2, &p2, &Matrix2::zeros()).expect("valid");
    let m2 = *x2.mean();
    let j2: SMatrix<f64, 2, 3> = numeric_jacobian(|e| m2.rplus(e).act(&p2) - m2.act(&p2), 1e-6);
    assert_close(
        &q2.cov,
        &(j2 * x2.cov() * j2.transpose()),
        1e-9,
        "SE(2) point",
    );
    // invalid inputs
    let x = x_pose(Side::Right);
    assert!(matches!(
        act_point(&x, &Vector3::new(0.0, f64::NAN, 0.0), &cov_p),
        Err(Error::NonFinite {
            what: "point",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        act_point(&x, &p, &-Matrix3::identity()),
        Err(Error::NotPositiveSemiDefinite {
            what: "point covariance",
            ..
        })
    ));
}

#[test]
fn odometry_rejects_invalid_inputs_and_stays_psd() {
    let start = UncertainPose::certain(Se3::identity());
    let bad = -Matrix6::identity();
    assert!(matches!(
        propagate_increments(&start, &[Se3::identity()], &bad),
        Err(Error::NotPositiveSemiDefinite { .. })
    ));
    let u = Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, f64::NAN);
    assert!(matches!(
        propagate_tangent_inputs(
            &start,
            &[Vector6::zeros(), u],
            &Matrix6::identity(),
            InputNoise::RightJacobian
        ),
        Err(Error::NonFinite { index: 11, .. })
    ));
    let inputs: Vec<Vector6<f64>> = (0..20)
        .map(|k| Vector6::new(1.0, 0.1, 0.0, 0.1, -0.2, 0.3 * k as f64))
        .collect();
    for side in [Side::Right, Side::Left] {
        let path = propagate_tangent_inputs(
            &start.to_side(side),
            &inputs,
            &random_spd::<6>(6, 0.01),
            InputNoise::RightJacobian,
        )
        .expect("valid");
        assert_eq!(path.len(), 21);
        for p in &path {
            assert_valid_covariance(p.pose.cov());
        }
    }
}
