//! [REFERENCE_CASES R2] (NA 568 SE(2) odometry table, 1e-6) and [R3] (right vs left form:
//! the two recursions agree to 1e-12; the table's 6 decimals to 1e-6).
//!
//! [REFERENCE_CASES R2]: posecov::reference_cases#r2-se2-odometry-na-568
//! [R3]: posecov::reference_cases#r3-right-form-against-left-form

mod common;

use common::assert_close;
use nalgebra::{Matrix3, Vector3};
use posecov::lie::{LieGroup, Se2};
use posecov::propagate::odometry::propagate_increments;
use posecov::propagate::vector_space::{VectorPose, ssc_odometry};
use posecov::uncertain::{Method, Side, UncertainPose};

/// The table has 6 decimals (rounding leaves ≤ 5e-7) and was computed from unrounded inputs,
/// while the inputs above are rounded to 6 decimals: e.g. θ₄ = Σ u3 = 0.209548 here, 0.209547
/// in the table — exactly 1e-6 in decimal, 1.00000000003e-6 in f64. Hence 1e-6 plus f64 slack.
const TABLE_TOL: f64 = 1e-6 + 1e-12;

const U2: [f64; 7] = [
    0.043333, 0.062110, 0.089025, 0.127602, 0.182895, 0.262149, 0.375746,
];
const U3: [f64; 7] = [
    0.072096, 0.031054, 0.044150, 0.062248, 0.086330, 0.116042, 0.147573,
];

/// The nominal path integrates the rounded inputs, so its error against the table grows with
/// the step k: the table's own rounding (5e-7), plus per step 5e-7 on (u1, u2) and a heading
/// off by ≤ (j − 1)·5e-7 swinging the 0.6 m step j. Measured: ≤ 1e-6 up to step 6, 1.26e-6 at
/// step 7 (bound 1.19e-5); the covariances stay within 5e-7 at every step (TABLE_TOL).
fn nominal_tolerance(k: usize) -> f64 {
    let rounding = 5e-7;
    let kf = k as f64;
    TABLE_TOL.max(rounding + kf * rounding + 0.61 * rounding * kf * (kf - 1.0) / 2.0)
}

fn increments() -> Vec<Se2> {
    // U_i = [[R(u3), (u1, u2)ᵀ], [0 0, 1]]: the translation is (u1, u2) itself.
    (0..7)
        .map(|i| Se2::from_xy_theta(0.6, U2[i], U3[i]))
        .collect()
}

fn cov_w() -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(
        0.03f64.powi(2),
        0.03f64.powi(2),
        0.1f64.powi(2),
    ))
}

fn upper(rows: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| if r <= c { rows[r][c] } else { rows[c][r] })
}

fn table() -> Vec<(Vector3<f64>, Matrix3<f64>)> {
    vec![
        (
            Vector3::new(0.600000, 0.043333, 0.072096),
            upper([[0.0009, 0.0, 0.0], [0.0, 0.0009, 0.0], [0.0, 0.0, 0.01]]),
        ),
        (
            Vector3::new(1.193967, 0.148502, 0.103150),
            upper([
                [0.001819, -0.000261, -0.000435],
                [0.0, 0.005420, 0.006016],
                [0.0, 0.0, 0.02],
            ]),
        ),
        (
            Vector3::new(1.781612, 0.298834, 0.147300),
            upper([
                [0.002802, -0.001334, -0.001418],
                [0.0, 0.020892, 0.018097],
                [0.0, 0.0, 0.03],
            ]),
        ),
        (
            Vector3::new(2.356386, 0.513114, 0.209547),
            upper([
                [0.003902, -0.003648, -0.002990],
                [0.0, 0.054959, 0.036353],
                [0.0, 0.0, 0.04],
            ]),
        ),
        (
            Vector3::new(2.905216, 0.816819, 0.295878),
            upper([
                [0.005195, -0.007074, -0.005064],
                [0.0, 0.115921, 0.061017],
                [0.0, 0.0, 0.05],
            ]),
        ),
        (
            Vector3::new(3.402707, 1.242525, 0.411919),
            upper([
                [0.006997, -0.010538, -0.007511],
                [0.0, 0.213230, 0.092509],
                [0.0, 0.0, 0.06],
            ]),
        ),
        (
            Vector3::new(3.802082, 1.827062, 0.559493),
            upper([
                [0.010612, -0.013364, -0.010833],
                [0.0, 0.358141, 0.131531],
                [0.0, 0.0, 0.07],
            ]),
        ),
    ]
}

fn right_path() -> Vec<posecov::propagate::Propagated<Se2, 3>> {
    propagate_increments(
        &UncertainPose::certain(Se2::identity()),
        &increments(),
        &cov_w(),
    )
    .expect("valid R2 inputs")
}

#[test]
fn r2_every_step_nominal_and_covariance() {
    let path = right_path();
    assert_eq!(path.len(), 8, "start + 7 steps");
    assert_eq!(path[0].pose.cov(), &Matrix3::zeros());
    for (k, (nominal, cov)) in table().iter().enumerate() {
        let step = &path[k + 1];
        assert_eq!(step.method, Method::FirstOrder);
        assert_eq!(step.pose.side(), Side::Right);
        let m = step.pose.mean();
        let got = Vector3::new(m.x(), m.y(), m.theta());
        eprintln!(
            "R2 step {}: nominal max err {:.3e}, Σ max err {:.3e}",
            k + 1,
            (got - nominal).amax(),
            (step.pose.cov() - cov).amax()
        );
        assert_close(
            &got,
            nominal,
            nominal_tolerance(k + 1),
            &format!("R2 nominal step {}", k + 1),
        );
        assert_close(
            step.pose.cov(),
            cov,
            TABLE_TOL,
            &format!("R2 Σ step {}", k + 1),
        );
    }
}

#[test]
fn r3_right_and_left_recursions_agree() {
    let right = right_path();
    let start_left = UncertainPose::certain(Se2::identity()).to_side(Side::Left);
    let left = propagate_increments(&start_left, &increments(), &cov_w()).expect("valid");
    // Every step, both ways, 1e-12.
    for (k, (r, l)) in right.iter().zip(&left).enumerate() {
        assert_eq!(l.pose.side(), Side::Left);
        assert!(r.pose.mean().is_approx(l.pose.mean(), 1e-15));
        assert_close(
            &r.pose.cov_left(),
            l.pose.cov(),
            1e-12,
            &format!("R3 step {k}"),
        );
        assert_close(
            r.pose.cov(),
            &l.pose.cov_right(),
            1e-12,
            &format!("R3 step {k} back"),
        );
    }
    // The table after 6 steps, 6 decimals.
    let x6 = Matrix3::new(
        0.916354, -0.400369, 3.402707, 0.400369, 0.916354, 1.242525, 0.0, 0.0, 1.0,
    );
    let sigma_l6 = Matrix3::new(
        0.031276, -0.085458, 0.030631, -0.085458, 0.310709, -0.122399, 0.030631, -0.122399, 0.06,
    );
    assert_close(&left[6].pose.mean().to_matrix(), &x6, TABLE_TOL, "R3 X6");
    assert_close(left[6].pose.cov(), &sigma_l6, TABLE_TOL, "R3 Σ^L_6");
    let ad = right[6].pose.mean().adj();
    assert_close(
        &(ad * right[6].pose.cov() * ad.transpose()),
        &sigma_l6,
        TABLE_TOL,
        "R3 Ad Σ6 Adᵀ",
    );
}

/// The vector-space baseline on the same inputs, noise added to (dx, dy, dθ). To first order
/// SSC and the Lie recursion are one linearisation in two charts; here the two noise models
/// coincide too (Σ_w is isotropic in (x, y), so R(u3) Σ_w R(u3)ᵀ = Σ_w), hence after the
/// first-order chart conversion they agree to round-off at every step. With an anisotropic
/// Σ_w the noise models differ by R(u3) and so do the results.
#[test]
fn r2_vector_space_baseline_matches_in_its_chart() {
    let start = VectorPose::<Se2, 3>::try_new(Vector3::zeros(), Matrix3::zeros()).expect("valid");
    let u: Vec<Vector3<f64>> = (0..7).map(|i| Vector3::new(0.6, U2[i], U3[i])).collect();
    let ssc = ssc_odometry(&start, &u, &cov_w()).expect("valid");
    let lie = right_path();
    let anisotropic = Matrix3::from_diagonal(&Vector3::new(0.05f64.powi(2), 0.01f64.powi(2), 0.01));
    let ssc_aniso = ssc_odometry(&start, &u, &anisotropic).expect("valid");
    let lie_aniso = propagate_increments(
        &UncertainPose::certain(Se2::identity()),
        &increments(),
        &anisotropic,
    )
    .expect("valid");
    for k in 1..=7 {
        let m = lie[k].pose.mean();
        assert_close(
            ssc[k].mean(),
            &Vector3::new(m.x(), m.y(), m.theta()),
            1e-12,
            "nominal",
        );
        let as_pose = ssc[k].to_uncertain().expect("no gimbal lock in SE(2)");
        assert_eq!(as_pose.method, Method::VectorSpace);
        assert_close(
            as_pose.pose.cov(),
            lie[k].pose.cov(),
            1e-15,
            &format!("isotropic step {k}"),
        );
        let e = posecov::propagate::relative_frobenius_error(
            ssc_aniso[k].to_uncertain().expect("valid").pose.cov(),
            lie_aniso[k].pose.cov(),
        );
        eprintln!("R2 inputs, anisotropic Σ_w, step {k}: SSC vs Lie relative Frobenius {e:.3e}");
        assert!(e > 1e-4 && e < 0.2, "step {k}: {e:.3e}");
    }
}
