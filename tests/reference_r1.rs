//! The closed-form fixtures of [REFERENCE_CASES R1], abs 1e-8.
//!
//! [REFERENCE_CASES R1]: posecov::reference_cases#r1-closed-form-fixtures

mod common;

use common::assert_close;
use nalgebra::{Matrix3, Vector3, Vector6};
use posecov::lie::{LieGroup, Se2, Se3, So3};

const TOL: f64 = 1e-8;

fn m3(rows: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| rows[r][c])
}

#[test]
fn r1_so3_exp_jl_jl_inv() {
    let phi = Vector3::new(0.1, 0.2, 0.3);
    let exp = m3([
        [0.935754803, -0.283164961, 0.210191706],
        [0.302932713, 0.950580618, -0.068031316],
        [-0.180540077, 0.127334575, 0.975290309],
    ]);
    let jl = m3([
        [0.978484495, -0.144948069, 0.103803881],
        [0.151568224, 0.983449612, -0.039489149],
        [-0.093873648, 0.059349615, 0.991724806],
    ]);
    let jl_inv = m3([
        [0.989141304, 0.151670569, -0.097494147],
        [-0.148329431, 0.991647157, 0.055011706],
        [0.102505853, -0.044988294, 0.995823579],
    ]);
    assert_close(&So3::exp(&phi).to_matrix(), &exp, TOL, "SO3 Exp");
    assert_close(&So3::jl(&phi), &jl, TOL, "SO3 Jl");
    assert_close(&So3::jl_inv(&phi), &jl_inv, TOL, "SO3 Jl⁻¹");
}

#[test]
fn r1_so3_jr() {
    let jr = m3([
        [0.455978492, -0.0979383, 0.696289814],
        [-0.414081942, 0.839993674, 0.188138581],
        [-0.568284754, -0.444148703, 0.359974696],
    ]);
    assert_close(&So3::jr(&Vector3::new(1.0, -2.0, 0.5)), &jr, TOL, "SO3 Jr");
}

#[test]
fn r1_se3_exp_q_adjoint() {
    let xi = Vector6::new(1.0, -0.5, 2.0, 0.1, 0.2, 0.3);
    let x = Se3::exp(&xi);
    assert_close(
        x.translation(),
        &Vector3::new(1.258566291, -0.41913488, 1.859901157),
        TOL,
        "SE3 Exp t",
    );
    let q = m3([
        [-0.164212523, -0.948900206, -0.174549992],
        [0.99815403, -0.230712081, -0.448460354],
        [0.339457861, 0.530020272, 0.000496676],
    ]);
    let q_ours = Se3::q_matrix(&Vector3::new(1.0, -0.5, 2.0), &Vector3::new(0.1, 0.2, 0.3));
    assert_close(&q_ours, &q, TOL, "SE3 Q(ρ, θ)");
    // Q is the upper-right block of Jl(ξ).
    assert_close(
        &Se3::jl(&xi).fixed_view::<3, 3>(0, 3).into_owned(),
        &q,
        TOL,
        "SE3 Jl block",
    );
    let ad_block = m3([
        [-0.487754261, -1.821356353, -0.282246663],
        [1.967633096, -0.686917841, -0.83653171],
        [0.773468379, 1.077684411, 0.002476754],
    ]);
    assert_close(
        &x.adj().fixed_view::<3, 3>(0, 3).into_owned(),
        &ad_block,
        TOL,
        "SE3 Ad block",
    );
}

#[test]
fn r1_se2_exp_jr_jl_adjoint() {
    let tau = Vector3::new(1.0, 2.0, 0.5);
    let x = Se2::exp(&tau);
    let exp = m3([
        [0.877582562, -0.479425539, 0.469181325],
        [0.479425539, 0.877582562, 2.162537031],
        [0.0, 0.0, 1.0],
    ]);
    let jr = m3([
        [0.958851077, 0.244834876, -0.897041659],
        [-0.244834876, 0.958851077, 0.654265444],
        [0.0, 0.0, 1.0],
    ]);
    let jl = m3([
        [0.958851077, -0.244834876, 1.06163735],
        [0.244834876, 0.958851077, -0.325074061],
        [0.0, 0.0, 1.0],
    ]);
    let ad = m3([
        [0.877582562, -0.479425539, 2.162537031],
        [0.479425539, 0.877582562, -0.469181325],
        [0.0, 0.0, 1.0],
    ]);
    assert_close(&x.to_matrix(), &exp, TOL, "SE2 Exp");
    assert_close(&Se2::jr(&tau), &jr, TOL, "SE2 Jr");
    assert_close(&Se2::jl(&tau), &jl, TOL, "SE2 Jl");
    assert_close(&x.adj(), &ad, TOL, "SE2 Ad");
}

/// Log(Exp(τ)) = τ at θ = 0, 1e-8 and π − 1e-6, and round trips ≤ 1e-9 at π − 1e-6.
#[test]
fn r1_log_exp_at_every_branch() {
    let axis = Vector3::new(0.6, -0.48, 0.64); // unit
    for angle in [0.0, 1e-8, 0.05, 0.1, 1.0, std::f64::consts::PI - 1e-6] {
        let phi = axis * angle;
        assert_close(
            &So3::exp(&phi).log(),
            &phi,
            1e-9,
            &format!("SO3 at {angle}"),
        );
        let xi = Vector6::new(1.0, -2.0, 0.5, phi.x, phi.y, phi.z);
        assert_close(&Se3::exp(&xi).log(), &xi, 1e-9, &format!("SE3 at {angle}"));
        let tau = Vector3::new(1.0, -2.0, angle);
        assert_close(
            &Se2::exp(&tau).log(),
            &tau,
            1e-9,
            &format!("SE2 at {angle}"),
        );
    }
}
