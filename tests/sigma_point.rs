//! The unscented transform on the manifold: exact where the map is linear in the tangent,
//! equal to first order for products of independent inputs, close to Monte Carlo for moderate
//! noise (R4's Exp(u + w) chain), tending to first order as α → 0, typed errors.
//!
//! Tolerance against MC: N = 1e5, relative Frobenius RMS sampling error
//! √((tr Σ)² + ‖Σ‖²_F)/N)/‖Σ‖_F ≈ 0.6 % for these Σ; 3 % leaves ≥ 4 RMS for sampling plus the
//! transform's own (fourth-order) truncation. Monte Carlo is the evaluation engine's
//! ([`posecov::eval::evaluate`] of a plan), summarised by the Lie mean and the centred
//! 1/(N−1) covariance, right side.

mod common;

use common::{evaluate_plan, mc_settings, mc_stats, nodes, odometry_plan, tangent_controls};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use posecov::Error;
use posecov::lie::{LieGroup, Se2, Se3, So3};
use posecov::plan::{OdometryModel, Op, Plan};
use posecov::propagate::first_order;
use posecov::propagate::odometry::{InputNoise, propagate_tangent_inputs};
use posecov::propagate::relative_frobenius_error;
use posecov::propagate::sigma_point::{Unscented, compose, map};
use posecov::uncertain::{Method, Side, UncertainPose};

fn moderate_pose(mean: Se3, side: Side) -> UncertainPose<Se3, 6> {
    let a = Matrix6::from_fn(|i, j| {
        if i == j {
            [0.1, 0.15, 0.05, 0.1, 0.08, 0.2][i]
        } else {
            0.01 * ((i * 3 + j) % 4) as f64 - 0.015
        }
    });
    UncertainPose::try_new(mean, a * a.transpose(), side).unwrap()
}

#[test]
fn exact_for_maps_linear_in_the_tangent() {
    let x = moderate_pose(
        Se3::from_xyz_rpy([1.0, 2.0, 3.0], [0.3, -0.2, 1.0]),
        Side::Right,
    );
    // Identity map: the input distribution, on the input's side.
    let same = map(&[x], |v: &[Se3]| v[0], &Unscented::default()).unwrap();
    assert_eq!(same.method, Method::SigmaPoints);
    assert!((same.pose.cov() - x.cov()).amax() < 1e-12);
    assert!(same.pose.mean().is_approx(x.mean(), 1e-12));
    // Left side in, left side out.
    let left = x.to_side(Side::Left);
    let same_left = map(
        &[left],
        |v: &[Se3]| v[0],
        &Unscented {
            side: Side::Left,
            ..Default::default()
        },
    )
    .unwrap();
    assert!((same_left.pose.cov() - left.cov()).amax() < 1e-12);
    // Another output group: the rotation of μ · Exp([ρ; θ]) is R_μ Exp(θ), so the rotation
    // block comes out exactly.
    let rotation = map(&[x], |v: &[Se3]| *v[0].rotation(), &Unscented::default()).unwrap();
    let block = x.cov().fixed_view::<3, 3>(3, 3).into_owned();
    assert!((rotation.pose.cov() - block).amax() < 1e-12);
    let _: &So3 = rotation.pose.mean();
}

/// With independent inputs each sigma point moves one input, and a product of group elements
/// is linear in one input's tangent: the unscented compose *is* first order (module docs).
#[test]
fn compose_equals_first_order_and_is_close_to_monte_carlo() {
    let a = moderate_pose(
        Se3::from_xyz_rpy([2.0, 0.0, 0.0], [0.0, 0.0, 0.5]),
        Side::Right,
    );
    let b = moderate_pose(
        Se3::from_xyz_rpy([3.0, 1.0, 0.0], [0.2, 0.0, -0.3]),
        Side::Right,
    );
    let ut = compose(&a, &b, &Unscented::default()).unwrap();
    let fo = first_order::compose(&a, &b);
    assert!(relative_frobenius_error(ut.pose.cov(), fo.pose.cov()) < 1e-12);
    let mut plan = Plan::<Se3, 6>::default();
    let (x, y) = (plan.uncertain("a", a), plan.uncertain("b", b));
    plan.compose("ab", x, y);
    let evaluation = evaluate_plan(plan, &mc_settings(100_000, 21));
    let truth = mc_stats(nodes(&evaluation, "ab")[0]);
    let e_ut = relative_frobenius_error(ut.pose.cov(), &truth.cov);
    let mean_offset = ut.pose.mean().rminus(&truth.mean).norm();
    println!(
        "SE(3) compose vs MC: sigma points {:.2} %, UT mean offset {mean_offset:.2e}",
        100.0 * e_ut
    );
    assert!(e_ut < 0.03, "sigma points {e_ut}");
    assert!(mean_offset < 0.01);

    // The same for a chain of three SE(2) inputs, X · Y⁻¹ · Z.
    let p = |x, y, t, s: [f64; 3]| {
        UncertainPose::try_from_std_devs(Se2::from_xy_theta(x, y, t), s, Side::Right).unwrap()
    };
    let inputs = [
        p(1.0, 0.0, 0.3, [0.1, 0.05, 0.15]),
        p(0.0, 2.0, -0.5, [0.05, 0.1, 0.1]),
        p(2.0, 1.0, 1.0, [0.2, 0.1, 0.05]),
    ];
    let f = |v: &[Se2]| v[0].compose(&v[1].inverse()).compose(&v[2]);
    let mut plan = Plan::<Se2, 3>::default();
    let x = plan.uncertain("x", inputs[0]);
    let y = plan.uncertain("y", inputs[1]);
    let z = plan.uncertain("z", inputs[2]);
    let y_inv = plan.operation("y_inv", Op::Inverse { input: y });
    let x_y_inv = plan.compose("x_y_inv", x, y_inv);
    plan.compose("x_y_inv_z", x_y_inv, z);
    let evaluation = evaluate_plan(plan, &mc_settings(100_000, 22));
    let truth = mc_stats(nodes(&evaluation, "x_y_inv_z")[0]);
    let ut = map(&inputs, f, &Unscented::default()).unwrap();
    let e = relative_frobenius_error(ut.pose.cov(), &truth.cov);
    println!("SE(2) X·Y⁻¹·Z vs MC: sigma points {:.2} %", 100.0 * e);
    assert!(e < 0.03, "{e}");
}

/// The inputs and noise of [REFERENCE_CASES R4]: X_{k+1} = X_k Exp(u_k + w_k), 4 steps.
///
/// [REFERENCE_CASES R4]: posecov::reference_cases#r4-se3-odometry-noise-inside-exp-rob-530
fn r4() -> (Vec<Vector6<f64>>, Matrix6<f64>) {
    let v1: [f64; 4] = [0.0, 4.0 / 3.0, 8.0 / 3.0, 4.0];
    let (w1, w2, w3) = (
        [0.0, 1.0 / 6.0, 1.0 / 3.0, 0.5],
        [0.0, 0.1, 0.2, 0.3],
        [0.0, 0.7 / 3.0, 1.4 / 3.0, 0.7],
    );
    let inputs = (0..4)
        .map(|k| {
            Vector6::new(
                v1[k],
                1.5 * v1[k],
                0.05 * (0.6 * v1[k]).exp() - 0.05,
                w1[k],
                w2[k],
                w3[k],
            )
        })
        .collect();
    let noise = Matrix6::from_diagonal(&Vector6::new(1e-4, 1e-4, 0.0025, 0.0025, 0.0025, 0.04));
    (inputs, noise)
}

/// The R4 chain as a map of the four noise "poses" Wₖ = Exp(wₖ) ~ (I, Σ_w): Log(Wₖ) = wₖ.
fn r4_unscented(params: &Unscented) -> posecov::propagate::Propagated<Se3, 6> {
    let (inputs, noise) = r4();
    let w = UncertainPose::try_new(Se3::identity(), noise, Side::Right).unwrap();
    let chain = |ws: &[Se3]| {
        ws.iter()
            .zip(&inputs)
            .fold(Se3::identity(), |x, (w, u)| x.rplus(&(u + w.log())))
    };
    map(&[w; 4], chain, params).unwrap()
}

/// Where the nonlinearity sits inside one input (Exp(u + w)), sigma points see it: R4's
/// chain against Monte Carlo, with first order (Jr) for comparison.
#[test]
fn close_to_monte_carlo_where_first_order_is_approximate() {
    let (inputs, noise) = r4();
    let start = UncertainPose::certain(Se3::identity());
    let plan = odometry_plan(
        Se3::identity(),
        OdometryModel::Exp,
        tangent_controls(&inputs),
        noise,
    );
    let evaluation = evaluate_plan(plan, &mc_settings(100_000, 530));
    let steps = nodes(&evaluation, "x");
    assert_eq!(steps[4].step, Some(4));
    let truth = mc_stats(steps[4]);
    let fo = propagate_tangent_inputs(&start, &inputs, &noise, InputNoise::RightJacobian).unwrap();
    let ut = r4_unscented(&Unscented::default());
    let mc = &truth.cov;
    let (e_ut, e_fo) = (
        relative_frobenius_error(ut.pose.cov(), mc),
        relative_frobenius_error(fo[4].pose.cov(), mc),
    );
    let offset = |m: &Se3| m.rminus(&truth.mean).norm();
    println!(
        "R4 step 4 vs MC: sigma points {:.2} % (mean offset {:.2e}), first order {:.2} % (mean offset {:.2e})",
        100.0 * e_ut,
        offset(ut.pose.mean()),
        100.0 * e_fo,
        offset(fo[4].pose.mean())
    );
    assert!(e_ut < 0.02, "sigma points {e_ut}");
    assert!(
        offset(ut.pose.mean()) < 0.5 * offset(fo[4].pose.mean()),
        "the UT mean should track the MC Lie mean"
    );
}

/// For a map linear in the tangent the transform returns Σ exactly whatever (α, β, κ): checks
/// that γ² · 2 · W = 1 and that the mean weights sum to 1. Breaking either (e.g. γ = √L + λ)
/// fails this.
#[test]
fn weights_and_scale_are_consistent_for_every_parameter_set() {
    let x = moderate_pose(
        Se3::from_xyz_rpy([1.0, -1.0, 0.5], [0.1, 0.2, 0.3]),
        Side::Right,
    );
    for (alpha, beta, kappa) in [
        (1.0, 2.0, 0.0),
        (0.5, 2.0, 0.0),
        (1e-2, 2.0, 1.0),
        (1.0, 0.0, 3.0),
        (0.3, 1.0, -3.0),
    ] {
        let params = Unscented {
            alpha,
            beta,
            kappa,
            side: Side::Right,
        };
        let w = params.weights(6).unwrap();
        assert!(
            (w.mean_centre + 12.0 * w.other - 1.0).abs() < 1e-9,
            "mean weights sum"
        );
        assert!(
            (2.0 * w.other * w.scale * w.scale - 1.0).abs() < 1e-12,
            "scale"
        );
        let y = map(&[x], |v: &[Se3]| v[0], &params).unwrap();
        let e = relative_frobenius_error(y.pose.cov(), x.cov());
        assert!(e < 1e-9, "α {alpha}, β {beta}, κ {kappa}: {e}");
    }
}

#[test]
fn typed_errors_for_bad_parameters() {
    let x = moderate_pose(Se3::identity(), Side::Right);
    let bad = |params: Unscented| matches!(compose(&x, &x, &params), Err(Error::OutOfRange { .. }));
    assert!(bad(Unscented {
        alpha: 0.0,
        ..Default::default()
    }));
    assert!(bad(Unscented {
        alpha: f64::NAN,
        ..Default::default()
    }));
    assert!(bad(Unscented {
        kappa: -12.0,
        ..Default::default()
    })); // L + κ = 0
    assert!(bad(Unscented {
        beta: f64::INFINITY,
        ..Default::default()
    }));
    let none: [UncertainPose<Se3, 6>; 0] = [];
    assert!(matches!(
        map(&none, |_: &[Se3]| Se3::identity(), &Unscented::default()),
        Err(Error::TooFewSamples { .. })
    ));
}

/// The estimate of `method` at the node `name` of `e` (right side).
fn estimate_of<G: LieGroup<N>, const N: usize>(
    e: &posecov::eval::Evaluation<G, N>,
    name: &str,
    method: Method,
) -> UncertainPose<G, N> {
    let node = nodes(e, name)[0];
    let found = node.estimates.iter().find(|x| x.result.method == method);
    found
        .unwrap_or_else(|| panic!("{name}: no {method:?}"))
        .result
        .pose
        .to_side(Side::Right)
}

/// Two SE(2) poses of one odometry chain: Y = X · U · Exp(η), so εY = Ad_{U⁻¹} εX + η and
/// Σ_XY = Σ_X Ad_{U⁻¹}ᵀ (strongly correlated), all scaled by `scale`.
fn chain_pair(scale: f64) -> (UncertainPose<Se2, 3>, UncertainPose<Se2, 3>, Matrix3<f64>) {
    let x_mean = Se2::from_xy_theta(2.0, 1.0, 0.4);
    let step = Se2::from_xy_theta(1.5, 0.2, 0.3);
    let l = Matrix3::new(0.1, 0.0, 0.0, 0.02, 0.08, 0.0, 0.01, -0.02, 0.1) * scale;
    let cov_x = l * l.transpose();
    let ad = step.inverse().adj();
    let cov_y = ad * cov_x * ad.transpose()
        + Matrix3::from_diagonal(&Vector3::new(0.02, 0.01, 0.03)) * scale * scale;
    let x = UncertainPose::try_new(x_mean, cov_x, Side::Right).unwrap();
    let y = UncertainPose::try_new(x_mean.compose(&step), cov_y, Side::Right).unwrap();
    (x, y, cov_x * ad.transpose())
}

/// A plan with `X`, `Y` and their correlated between and compose (Σ_XY = `cross`).
fn correlated_plan(
    x: UncertainPose<Se2, 3>,
    y: UncertainPose<Se2, 3>,
    cross: Matrix3<f64>,
) -> Plan<Se2, 3> {
    let mut plan = Plan::<Se2, 3>::default();
    let (a, b) = (plan.uncertain("x", x), plan.uncertain("y", y));
    let cross_cov = Some(cross);
    plan.operation(
        "between",
        Op::Between {
            lhs: a,
            rhs: b,
            cross_cov,
        },
    );
    plan.operation(
        "compose",
        Op::Compose {
            lhs: a,
            rhs: b,
            cross_cov,
        },
    );
    plan
}

/// Sigma points of a correlated pair run over the joint 2N-dimensional tangent [εX; εY] with
/// the joint covariance: with small noise they equal Mangelson et al.'s correlated first
/// order (not the independent formula), with large noise they sit at Monte Carlo.
#[test]
fn correlated_pairs_move_both_inputs_in_every_sigma_point() {
    let mut settings = mc_settings(2, 5);
    settings.methods = vec![Method::FirstOrder, Method::SigmaPoints];
    let (x, y, cross) = chain_pair(1e-3);
    let e = evaluate_plan(correlated_plan(x, y, cross), &settings);
    for (name, independent) in [
        ("between", first_order::between(&x, &y)),
        ("compose", first_order::compose(&x, &y)),
    ] {
        let sigma = estimate_of(&e, name, Method::SigmaPoints);
        let first = estimate_of(&e, name, Method::FirstOrder);
        let to_first = relative_frobenius_error(sigma.cov(), first.cov());
        let to_independent = relative_frobenius_error(sigma.cov(), independent.pose.cov());
        println!(
            "{name}, σ ~ 1e-4: sigma points vs correlated first order {to_first:.1e}, vs independent {to_independent:.2}"
        );
        assert!(to_first < 1e-6, "{name}: {to_first}");
        assert!(to_independent > 0.3, "{name}: {to_independent}");
    }

    let (x, y, cross) = chain_pair(2.0);
    let mut settings = mc_settings(100_000, 23);
    settings.methods = vec![Method::FirstOrder, Method::SigmaPoints, Method::MonteCarlo];
    let e = evaluate_plan(correlated_plan(x, y, cross), &settings);
    for (name, f) in [
        (
            "between",
            (|g: &[Se2]| g[0].between(&g[1])) as fn(&[Se2]) -> Se2,
        ),
        ("compose", |g: &[Se2]| g[0].compose(&g[1])),
    ] {
        let truth = mc_stats(nodes(&e, name)[0]);
        let sigma = estimate_of(&e, name, Method::SigmaPoints);
        let first = estimate_of(&e, name, Method::FirstOrder);
        // What the sigma points gave before they saw Σ_XY: the inputs as independent.
        let blind = map(&[x, y], f, &Unscented::default()).unwrap();
        let err = |c: &Matrix3<f64>| relative_frobenius_error(c, &truth.cov);
        println!(
            "{name}, σ ~ 0.2: vs Monte Carlo sigma points {:.2} %, first order {:.2} %, independent sigma points {:.1} %",
            100.0 * err(sigma.cov()),
            100.0 * err(first.cov()),
            100.0 * err(blind.pose.cov())
        );
        assert!(err(sigma.cov()) < 0.03, "{name}");
        assert!(err(blind.pose.cov()) > 0.3, "{name}");
    }
}

/// The wrap-around finding measures the joint sigma points: SO(2) inputs with σ = s rad and
/// ρ = 0.5 have joint principal axes (1, 1) (σ² · 1.5) and (1, −1) (σ² · 0.5), so with γ = √2
/// each input turns at most √0.75 · √2 · s = √1.5 · s, not the independent √2 · s.
#[test]
fn the_wrap_around_finding_measures_the_joint_sigma_points() {
    use posecov::eval::Finding;
    use posecov::lie::So2;
    let mut settings = mc_settings(2, 5);
    settings.methods = vec![Method::FirstOrder, Method::SigmaPoints];
    let turns = |s: f64| {
        let p = UncertainPose::try_from_std_devs(So2::from_angle(0.2), [s], Side::Right).unwrap();
        let mut plan = Plan::<So2, 1>::default();
        let (a, b) = (plan.uncertain("a", p), plan.uncertain("b", p));
        let cross_cov = Some(nalgebra::Matrix1::new(0.5 * s * s));
        plan.operation(
            "ab",
            Op::Compose {
                lhs: a,
                rhs: b,
                cross_cov,
            },
        );
        let e = evaluate_plan(plan, &settings);
        e.findings
            .iter()
            .filter_map(|f| match f {
                Finding::SigmaPointsWrap {
                    largest_rotation_rad,
                    ..
                } => Some(*largest_rotation_rad),
                _ => None,
            })
            .collect::<Vec<f64>>()
    };
    // s = 2.4: independent points would turn 3.39 rad (beyond π), the joint ones 2.94.
    assert!(2.4 * 2f64.sqrt() > std::f64::consts::PI);
    assert_eq!(turns(2.4), Vec::<f64>::new());
    let found = turns(3.0);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!((found[0] - 1.5f64.sqrt() * 3.0).abs() < 1e-12, "{found:?}");
}
