//! Sampling and sample statistics ([CONVENTIONS §8]): drawn samples recover Σ on either side,
//! singular Σ is handled, results do not depend on the thread count, NEES detects a wrong
//! claimed covariance, and every degenerate input returns its typed error.
//!
//! Tolerances: for N Gaussian samples the sample covariance S has
//! E‖S − Σ‖²_F = (tr(Σ)² + ‖Σ‖²_F)/N (Wishart), so the relative Frobenius error has RMS
//! e(N) = √((tr(Σ)² + ‖Σ‖²_F)/N) / ‖Σ‖_F; tests allow 3 e(N).
//!
//! [CONVENTIONS §8]: posecov::conventions#8-sample-statistics

mod common;

use common::{evaluate_plan, mc_settings, nodes};
use nalgebra::{Matrix3, Matrix6, Vector6};
use posecov::Error;
use posecov::lie::{LieGroup, Se2, Se3, So2};
use posecov::plan::Plan;
use posecov::propagate::relative_frobenius_error;
use posecov::sample::{
    MeanError, Sampler, centred_covariance, covariance_square_root, lie_mean, nees,
    sample_statistics, tangent_about, uncentred_covariance, weighted_lie_mean,
};
use posecov::uncertain::{Side, UncertainPose};

/// RMS relative Frobenius error of a sample covariance of N Gaussian samples (module docs).
fn rms_relative_error<const D: usize>(cov: &nalgebra::SMatrix<f64, D, D>, n: usize) -> f64 {
    ((cov.trace().powi(2) + cov.norm_squared()) / n as f64).sqrt() / cov.norm()
}

/// A correlated SE(3) covariance: A Aᵀ with a fixed, well-conditioned A.
fn correlated_se3_cov() -> Matrix6<f64> {
    let a = Matrix6::from_fn(|i, j| {
        if i == j {
            0.1 + 0.02 * i as f64
        } else {
            0.01 * ((i + 2 * j) % 5) as f64 - 0.02
        }
    });
    a * a.transpose()
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

const N: usize = 50_000;

#[test]
fn samples_recover_the_covariance_on_both_sides() {
    let mean = Se3::from_xyz_rpy([1.0, -2.0, 0.5], [0.3, -0.2, 1.0]);
    let cov = correlated_se3_cov();
    let bound = 3.0 * rms_relative_error(&cov, N);
    for side in [Side::Right, Side::Left] {
        let pose = UncertainPose::try_new(mean, cov, side).unwrap();
        let samples = Sampler::new(&pose).unwrap().draw_par(N, 11);
        let stats = sample_statistics(&samples, side).unwrap();
        let centred = relative_frobenius_error(&stats.cov, &cov);
        let uncentred =
            relative_frobenius_error(&uncentred_covariance(&samples, &mean, side).unwrap(), &cov);
        println!(
            "{side:?}: centred {centred:.4}, uncentred {uncentred:.4}, bound {bound:.4}, {} iterations",
            stats.iterations
        );
        assert!(
            centred < bound && uncentred < bound,
            "{side:?}: {centred} / {uncentred} > {bound}"
        );
        // The Lie mean is the fixed point of its iteration: mean Log(μ̂⁻¹ Xᵢ) (right) or
        // mean Log(Xᵢ μ̂⁻¹) (left) vanishes to the stopping tolerance 1e-10.
        let residual = samples
            .iter()
            .map(|x| tangent_about(x, &stats.mean, side))
            .sum::<Vector6<f64>>()
            / N as f64;
        assert!(
            residual.norm() < 1e-10,
            "{side:?}: Lie mean residual {:e}",
            residual.norm()
        );
        assert!(stats.iterations >= 2);
        // The Lie mean is within a few standard errors √(tr Σ / N) of μ.
        let offset = stats.mean.rminus(&mean).norm();
        assert!(
            offset < 5.0 * (cov.trace() / N as f64).sqrt(),
            "Lie mean offset {offset}"
        );
        // Statistics taken on the wrong side see Ad-transformed covariances: clearly different.
        let other = if side == Side::Right {
            Side::Left
        } else {
            Side::Right
        };
        let wrong = sample_statistics(&samples, other).unwrap();
        assert!(relative_frobenius_error(&wrong.cov, &cov) > 10.0 * bound);
    }
}

#[test]
fn singular_covariance_samples_stay_in_the_subspace() {
    // R5-like: only yaw noise; Cholesky fails, the eigen square root is used.
    let cov = Matrix6::from_diagonal(&Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0009));
    let l = covariance_square_root(&cov).unwrap();
    assert!((l * l.transpose() - cov).norm() < 1e-15);
    let mean = Se3::exp(&Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0));
    let pose = UncertainPose::try_new(mean, cov, Side::Left).unwrap();
    let samples = Sampler::new(&pose).unwrap().draw_par(N, 5);
    let s = uncentred_covariance(&samples, &mean, Side::Left).unwrap();
    let off_block = (0..6)
        .flat_map(|i| (0..5).map(move |j| (i, j)))
        .map(|ij| s[ij].abs())
        .fold(0.0, f64::max);
    assert!(
        off_block < 1e-20,
        "noise leaked out of the yaw direction: {off_block:e}"
    );
    assert!((s[(5, 5)] / 0.0009 - 1.0).abs() < 3.0 * (2.0 / N as f64).sqrt());

    // A rank-2 correlated SE(2) covariance (perfectly correlated x and θ).
    let cov2 = Matrix3::new(0.04, 0.0, 0.02, 0.0, 0.01, 0.0, 0.02, 0.0, 0.01);
    let l2 = covariance_square_root(&cov2).unwrap();
    assert!((l2 * l2.transpose() - cov2).norm() < 1e-15);
}

#[test]
fn identical_results_for_one_and_two_threads() {
    let pose = UncertainPose::try_new(
        Se3::from_xyz_rpy([0.0, 1.0, 2.0], [0.1, 0.2, 0.3]),
        correlated_se3_cov(),
        Side::Right,
    )
    .unwrap();
    let sampler = Sampler::new(&pose).unwrap();
    // 10 000 samples = 10 chunks: enough for both threads to take chunks.
    let one = in_pool(1, || sampler.draw_par(10_000, 99));
    let two = in_pool(2, || sampler.draw_par(10_000, 99));
    assert_eq!(one, two);
    let other_seed = in_pool(2, || sampler.draw_par(10_000, 100));
    assert_ne!(one, other_seed);
    // Statistics (parallel chunked sums) and a whole Monte Carlo run are bit-identical too.
    let s1 = in_pool(1, || sample_statistics(&one, Side::Right).unwrap());
    let s2 = in_pool(2, || sample_statistics(&two, Side::Right).unwrap());
    assert_eq!(s1, s2);
    let mut plan = Plan::<Se3, 6>::default();
    let (x, y) = (plan.uncertain("x", pose), plan.uncertain("y", pose));
    plan.compose("xy", x, y);
    let settings = mc_settings(10_000, 3);
    let run = || {
        let e = evaluate_plan(plan.clone(), &settings);
        let xy = nodes(&e, "xy")[0];
        (xy.particles.clone(), xy.monte_carlo, xy.estimates.clone())
    };
    let m1 = in_pool(1, run);
    let m2 = in_pool(2, run);
    assert!(m1.0.as_ref().is_some_and(|p| p.len() == 10_000) && m1.1.is_some());
    assert_eq!(m1, m2);
}

#[test]
fn nees_matches_the_dimension_only_for_the_true_covariance() {
    let pose = UncertainPose::try_new(
        Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.0, 0.5, 0.0]),
        correlated_se3_cov(),
        Side::Right,
    )
    .unwrap();
    let samples = Sampler::new(&pose).unwrap().draw_par(N, 8);
    let consistent = nees(&samples, &pose).unwrap();
    // Mean of N χ²₆ values: mean 6, standard error √(2·6/N).
    let se = (12.0 / N as f64).sqrt();
    println!("NEES true Σ: {:.4} (6 ± {se:.4})", consistent.mean);
    assert_eq!((consistent.dof, consistent.values.len()), (6, N));
    assert!((consistent.mean - 6.0).abs() < 4.0 * se);
    let overconfident =
        UncertainPose::try_new(*pose.mean(), pose.cov() * 0.8, Side::Right).unwrap();
    let n = nees(&samples, &overconfident).unwrap().mean;
    assert!(
        (n - 7.5).abs() < 4.0 * se * 1.25 && (n - 6.0).abs() > 10.0 * se,
        "overconfident NEES {n}"
    );
    // The claimed side matters: the same Σ on the left is another distribution.
    let left = UncertainPose::try_new(*pose.mean(), *pose.cov(), Side::Left).unwrap();
    assert!((nees(&samples, &left).unwrap().mean - 6.0).abs() > 10.0 * se);
}

#[test]
fn typed_errors_for_empty_and_small_sample_sets() {
    let none: [Se2; 0] = [];
    let one = [Se2::identity()];
    assert!(matches!(
        lie_mean(&none, Side::Right),
        Err(MeanError::Invalid(Error::TooFewSamples {
            needed: 1,
            got: 0,
            ..
        }))
    ));
    assert!(matches!(
        uncentred_covariance(&none, &one[0], Side::Right),
        Err(Error::TooFewSamples { got: 0, .. })
    ));
    assert!(matches!(
        centred_covariance(&one, &one[0], Side::Right),
        Err(Error::TooFewSamples {
            needed: 2,
            got: 1,
            ..
        })
    ));
    assert!(matches!(
        sample_statistics(&one, Side::Left),
        Err(MeanError::Invalid(Error::TooFewSamples { .. }))
    ));
    let pose = UncertainPose::try_from_std_devs(Se2::identity(), [0.1; 3], Side::Right).unwrap();
    assert!(matches!(
        nees(&none, &pose),
        Err(Error::TooFewSamples { .. })
    ));
    assert!(matches!(
        nees(&one, &UncertainPose::certain(Se2::identity())),
        Err(Error::SingularCovariance { .. })
    ));
    assert!(matches!(
        weighted_lie_mean(&one, Some(&[1.0, 2.0]), &one[0], Side::Right),
        Err(MeanError::Invalid(Error::WrongLength {
            expected: 1,
            got: 2,
            ..
        }))
    ));
    assert!(matches!(
        weighted_lie_mean(&[one[0], one[0]], Some(&[1.0, -1.0]), &one[0], Side::Right),
        Err(MeanError::Invalid(Error::OutOfRange { .. }))
    ));
    let bad = Matrix3::new(f64::NAN, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert!(matches!(
        covariance_square_root(&bad),
        Err(Error::NonFinite { .. })
    ));
}

#[test]
fn non_convergence_carries_the_last_estimate() {
    // Negative weights (as unscented weights can be) make the step wrap around the circle:
    // from 0 the iteration moves by ≈ 2π every time and never settles.
    let points = [So2::from_angle(0.0), So2::from_angle(3.0)];
    let result = weighted_lie_mean(&points, Some(&[2.0, -1.0]), &points[0], Side::Right);
    let Err(MeanError::NotConverged {
        last_estimate,
        iterations,
        last_step,
        tolerance,
    }) = result
    else {
        panic!("expected NotConverged, got {result:?}");
    };
    assert_eq!(iterations, 100);
    assert!(last_step > 1.0 && tolerance == 1e-10);
    assert!(last_estimate.angle().is_finite());
    let as_crate_error: Error = MeanError::NotConverged {
        last_estimate,
        iterations,
        last_step,
        tolerance,
    }
    .into();
    let Error::NotConverged {
        what,
        last_estimate: text,
        ..
    } = as_crate_error
    else {
        panic!()
    };
    assert_eq!(what, "Lie mean");
    assert_eq!(text, last_estimate.to_string());
}
