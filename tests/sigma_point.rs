//! The unscented transform on the manifold: exact where the map is linear in the tangent,
//! close to Monte Carlo for moderate noise (closer than first order here), tending to first
//! order as α → 0, and typed errors for bad parameters.
//!
//! Tolerance against MC: N = 1e5, relative Frobenius RMS sampling error
//! √((tr Σ)² + ‖Σ‖²_F)/N)/‖Σ‖_F ≈ 0.6 % for these Σ; 3 % leaves ≥ 4 RMS for sampling plus the
//! transform's own (fourth-order) truncation.

use nalgebra::{Matrix6, Vector6};
use posecov::Error;
use posecov::lie::{LieGroup, Se2, Se3, So3};
use posecov::propagate::first_order;
use posecov::propagate::monte_carlo::{MonteCarlo, compose as mc_compose, map as mc_map};
use posecov::propagate::relative_frobenius_error;
use posecov::propagate::sigma_point::{Unscented, compose, map};
use posecov::uncertain::{Method, Side, UncertainPose};

fn moderate_pose(mean: Se3, side: Side) -> UncertainPose<Se3, 6> {
    let a = Matrix6::from_fn(|i, j| if i == j { [0.1, 0.15, 0.05, 0.1, 0.08, 0.2][i] } else { 0.01 * ((i * 3 + j) % 4) as f64 - 0.015 });
    UncertainPose::try_new(mean, a * a.transpose(), side).unwrap()
}

#[test]
fn exact_for_maps_linear_in_the_tangent() {
    let x = moderate_pose(Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.3, -0.2, 1.0]), Side::Right);
    // Identity map: the input distribution, on the input's side.
    let same = map(&[x], |v: &[Se3]| v[0], &Unscented::default()).unwrap();
    assert_eq!(same.method, Method::SigmaPoints);
    assert!((same.pose.cov() - x.cov()).amax() < 1e-12);
    assert!(same.pose.mean().is_approx(x.mean(), 1e-12));
    // Left side in, left side out.
    let left = x.to_side(Side::Left);
    let same_left = map(&[left], |v: &[Se3]| v[0], &Unscented { side: Side::Left, ..Default::default() }).unwrap();
    assert!((same_left.pose.cov() - left.cov()).amax() < 1e-12);
    // Another output group: the rotation of μ · Exp([ρ; θ]) is R_μ Exp(θ), so the rotation
    // block comes out exactly.
    let rotation = map(&[x], |v: &[Se3]| *v[0].rotation(), &Unscented::default()).unwrap();
    let block = x.cov().fixed_view::<3, 3>(3, 3).into_owned();
    assert!((rotation.pose.cov() - block).amax() < 1e-12);
    let _: &So3 = rotation.pose.mean();
}

#[test]
fn close_to_monte_carlo_for_moderate_noise() {
    let a = moderate_pose(Se3::from_xyz_rpy([2.0, 0.0, 0.0], [0.0, 0.0, 0.5]), Side::Right);
    let b = moderate_pose(Se3::from_xyz_rpy([3.0, 1.0, 0.0], [0.2, 0.0, -0.3]), Side::Right);
    let truth = mc_compose(&a, &b, &MonteCarlo::new(100_000, 21)).unwrap();
    let ut = compose(&a, &b, &Unscented::default()).unwrap();
    let fo = first_order::compose(&a, &b);
    let e_ut = relative_frobenius_error(ut.pose.cov(), truth.propagated.pose.cov());
    let e_fo = relative_frobenius_error(fo.pose.cov(), truth.propagated.pose.cov());
    let mean_offset = ut.pose.mean().rminus(truth.propagated.pose.mean()).norm();
    println!("SE(3) compose vs MC: sigma points {:.2} %, first order {:.2} %, UT mean offset {mean_offset:.2e}", 100.0 * e_ut, 100.0 * e_fo);
    assert!(e_ut < 0.03, "sigma points {e_ut}");
    assert!(e_ut < e_fo, "sigma points {e_ut} should beat first order {e_fo} at this noise");
    assert!(mean_offset < 0.01);

    // A generic map of three SE(2) inputs (X · Y⁻¹ · Z), against MC.
    let p = |x, y, t, s: [f64; 3]| UncertainPose::try_from_std_devs(Se2::from_xy_theta(x, y, t), s, Side::Right).unwrap();
    let inputs = [p(1.0, 0.0, 0.3, [0.1, 0.05, 0.15]), p(0.0, 2.0, -0.5, [0.05, 0.1, 0.1]), p(2.0, 1.0, 1.0, [0.2, 0.1, 0.05])];
    let f = |v: &[Se2]| v[0].compose(&v[1].inverse()).compose(&v[2]);
    let truth = mc_map(&inputs, f, &MonteCarlo::new(100_000, 22)).unwrap();
    let ut = map(&inputs, f, &Unscented::default()).unwrap();
    let e = relative_frobenius_error(ut.pose.cov(), truth.propagated.pose.cov());
    println!("SE(2) X·Y⁻¹·Z vs MC: sigma points {:.2} %", 100.0 * e);
    assert!(e < 0.03, "{e}");
}

#[test]
fn small_alpha_tends_to_first_order() {
    let a = moderate_pose(Se3::from_xyz_rpy([2.0, 0.0, 0.0], [0.0, 0.0, 0.5]), Side::Right);
    let b = moderate_pose(Se3::from_xyz_rpy([3.0, 1.0, 0.0], [0.2, 0.0, -0.3]), Side::Right);
    let fo = first_order::compose(&a, &b);
    let error = |alpha| {
        let ut = compose(&a, &b, &Unscented { alpha, ..Default::default() }).unwrap();
        relative_frobenius_error(ut.pose.cov(), fo.pose.cov())
    };
    let (coarse, fine) = (error(0.1), error(0.01));
    println!("UT vs first order: α = 0.1 → {coarse:.2e}, α = 0.01 → {fine:.2e}");
    // The difference is O(α² Σ): ×100 smaller per ×10 in α.
    assert!(fine < 1e-3 && fine < coarse / 20.0, "{coarse} → {fine}");
}

#[test]
fn typed_errors_for_bad_parameters() {
    let x = moderate_pose(Se3::identity(), Side::Right);
    let bad = |params: Unscented| matches!(compose(&x, &x, &params), Err(Error::OutOfRange { .. }));
    assert!(bad(Unscented { alpha: 0.0, ..Default::default() }));
    assert!(bad(Unscented { alpha: f64::NAN, ..Default::default() }));
    assert!(bad(Unscented { kappa: -12.0, ..Default::default() })); // L + κ = 0
    assert!(bad(Unscented { beta: f64::INFINITY, ..Default::default() }));
    let none: [UncertainPose<Se3, 6>; 0] = [];
    assert!(matches!(map(&none, |_: &[Se3]| Se3::identity(), &Unscented::default()), Err(Error::TooFewSamples { .. })));
    let _ = Vector6::<f64>::zeros();
}
