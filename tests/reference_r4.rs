//! [REFERENCE_CASES R4], deterministic part: ROB 530 SE(3) odometry with the noise inside
//! the exponential, X_{k+1} = X_k Exp(u_k + w_k), with and without the Jr term. (The Monte
//! Carlo comparison belongs to the sampling suite.)
//!
//! [REFERENCE_CASES R4]: posecov::reference_cases#r4-se3-odometry-noise-inside-exp-rob-530

mod common;

use common::{assert_close, r4_inputs, r4_noise};
use nalgebra::{Vector3, Vector6};
use posecov::lie::{LieGroup, Se3};
use posecov::propagate::Propagated;
use posecov::propagate::odometry::{InputNoise, propagate_tangent_inputs};
use posecov::uncertain::{Method, Side, UncertainPose};

/// The table's 6 decimals.
const TABLE_TOL: f64 = 1e-6;

fn run(noise: InputNoise, side: Side) -> Vec<Propagated<Se3, 6>> {
    let start = UncertainPose::certain(Se3::identity()).to_side(side);
    propagate_tangent_inputs(&start, &r4_inputs(), &r4_noise(), noise).expect("valid R4 inputs")
}

#[test]
fn r4_nominal_positions() {
    let path = run(InputNoise::RightJacobian, Side::Right);
    let expected = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.096498, 2.125939, 0.176471),
        Vector3::new(1.870219, 6.635629, 1.507789),
        Vector3::new(0.460708, 11.663701, 6.289424),
    ];
    assert_eq!(path.len(), 5, "start + 4 steps");
    for (k, p) in expected.iter().enumerate() {
        assert_close(
            path[k + 1].pose.mean().translation(),
            p,
            TABLE_TOL,
            &format!("step {}", k + 1),
        );
    }
}

#[test]
fn r4_step4_diagonals_with_and_without_jr() {
    let lecture = [0.852095, 4.488039, 7.399204, 0.012156, 0.070807, 0.097036];
    let with_jr = [0.867324, 5.207498, 9.044747, 0.012427, 0.081679, 0.083749];
    for (noise, table, method) in [
        (InputNoise::LectureNoJr, lecture, Method::LectureNoJr),
        (InputNoise::RightJacobian, with_jr, Method::FirstOrder),
    ] {
        let path = run(noise, Side::Right);
        let last = &path[4];
        assert_eq!(last.method, method);
        let diag = last.pose.cov().diagonal();
        eprintln!("R4 {noise:?} step-4 diagonal: {:?}", diag.as_slice());
        assert_close(
            &diag,
            &Vector6::from(table),
            TABLE_TOL,
            &format!("{noise:?}"),
        );
    }
}

/// The left-form recursion agrees with the right form after conversion, both noise models.
#[test]
fn r4_left_form_agrees() {
    for noise in [InputNoise::RightJacobian, InputNoise::LectureNoJr] {
        let right = run(noise, Side::Right);
        let left = run(noise, Side::Left);
        for (k, (r, l)) in right.iter().zip(&left).enumerate() {
            let scale = r.pose.cov().amax().max(1.0);
            assert_close(
                &l.pose.cov_right(),
                r.pose.cov(),
                1e-12 * scale,
                &format!("{noise:?} step {k}"),
            );
        }
    }
}
