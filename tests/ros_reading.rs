//! The ROS reading of a `PoseWithCovariance` (CONVENTIONS §6) and the covariance inputs people
//! already have (`cov` keys `ros` for SE(2), `euler` with `euler_order`), each against a
//! computation made here: tf2_geometry_msgs' own test numbers, the sign pattern of a move by
//! Rx(π), planar readings that coincide, and Monte Carlo draws in each input's own
//! coordinates read back with nalgebra's rotations.

mod common;

use nalgebra::{Matrix2, Matrix3, Matrix6, Rotation3, Vector2, Vector3};
use posecov::app::load_text;
use posecov::interop::{RosReading, ros_cov_from_right, ros_cov_to_right};
use posecov::lie::{LieGroup, So3, TangentMatrix};
use posecov::plan::{AnyPlan, PoseValue};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// A pose's covariance in X = μ · Exp(ε) (right) form at `mean`, re-expressed in the ROS
/// reading after the pose moves into another frame by `target_from_source` (a known rotation,
/// X' = T X: the right-form Σ does not change): what `tf2::doTransform` computes.
fn moved(
    cov_ros: &Matrix6<f64>,
    mean: &So3,
    target_from_source: &So3,
    r: RosReading,
) -> Matrix6<f64> {
    let right = ros_cov_to_right(cov_ros, mean, r);
    ros_cov_from_right(&right, &target_from_source.compose(mean), r)
}

fn quaternion_about_x(angle: f64) -> So3 {
    let (s, c) = (angle / 2.0).sin_cos();
    So3::try_from_quaternion_xyzw([s, 0.0, 0.0, c]).expect("unit")
}

/// tf2_geometry_msgs' test (TfGeometry.PoseWithCovarianceStamped): a pose whose orientation is
/// the quaternion (1, 0, 0, 0), unit variances, and the entries [1], [6], [12] set to 1 (the
/// test sets [12] without [2]); moved into a frame "rotated" by π/2 about x, tf2 expects these
/// nine numbers of the position block.
#[test]
fn tf2_reading_reproduces_tf2_geometry_msgs_test_numbers() {
    let mut cov = Matrix6::identity();
    cov[(0, 1)] = 1.0;
    cov[(1, 0)] = 1.0;
    cov[(2, 0)] = 1.0;
    let mean = quaternion_about_x(std::f64::consts::PI);
    // The child "rotated" is A rotated by π/2 about x; moving into it applies the inverse.
    let rotated_from_a = quaternion_about_x(std::f64::consts::FRAC_PI_2).inverse();
    let expected = [
        (0, 1.0),
        (1, 0.0),
        (2, -1.0),
        (6, 1.0),
        (7, 1.0),
        (8, 0.0),
        (12, -1.0),
        (13, 0.0),
        (14, 1.0),
    ];
    for reading in [RosReading::Tf2, RosReading::Body] {
        let out = moved(&cov, &mean, &rotated_from_a, reading);
        for (index, value) in expected {
            let got = out[(index / 6, index % 6)];
            assert!(
                (got - value).abs() < 1e-12,
                "{reading:?}[{index}] = {got}, tf2 says {value}"
            );
        }
    }
    // The test's identity rotation block: tf2 rotates it too (R I Rᵀ = I); so does the tf2
    // reading, here and for any rotation.
    let out = moved(&cov, &mean, &rotated_from_a, RosReading::Tf2);
    assert!((out.fixed_view::<3, 3>(3, 3) - Matrix3::identity()).norm() < 1e-12);
}

/// Moving a dense covariance by Rx(π): tf2 multiplies entry (i, j) by sᵢ sⱼ with
/// s = (1, −1, −1, 1, −1, −1), since it rotates both blocks; the body reading rotates only the
/// position block (s = (1, −1, −1, 1, 1, 1)), so the two disagree in sign in the 16 entries
/// with exactly one index on rotY or rotZ.
#[test]
fn a_move_by_rx_pi_flips_16_of_36_signs_between_the_readings() {
    let cov: Matrix6<f64> = common::random_spd::<6>(7, 1.0); // dense
    assert!(cov.iter().all(|v| v.abs() > 1e-9), "every entry non-zero");
    let mean = So3::from_rpy(0.4, -0.7, 1.9); // a 3-D attitude
    let rx_pi = quaternion_about_x(std::f64::consts::PI);
    let tf2 = moved(&cov, &mean, &rx_pi, RosReading::Tf2);
    let body = moved(&cov, &mean, &rx_pi, RosReading::Body);
    let s = [1.0, -1.0, -1.0, 1.0, -1.0, -1.0];
    for r in 0..6 {
        for c in 0..6 {
            assert!(
                (tf2[(r, c)] - s[r] * s[c] * cov[(r, c)]).abs() < 1e-12,
                "tf2 ({r}, {c})"
            );
        }
    }
    let flipped = (0..36)
        .filter(|i| (tf2[(i / 6, i % 6)] + body[(i / 6, i % 6)]).abs() < 1e-12)
        .count();
    let same = (0..36)
        .filter(|i| (tf2[(i / 6, i % 6)] - body[(i / 6, i % 6)]).abs() < 1e-12)
        .count();
    assert_eq!((flipped, same), (16, 20));
}

/// A planar covariance (yaw-only rotation; x, y, yaw and their cross terms; equal roll and pitch
/// variances) at a yaw-only pose reads the same in both.
#[test]
fn planar_readings_coincide_and_3d_attitudes_do_not() {
    let mut cov = Matrix6::zeros();
    cov.fixed_view_mut::<2, 2>(0, 0)
        .copy_from(&Matrix2::new(0.04, 0.01, 0.01, 0.09));
    cov[(2, 2)] = 0.01;
    cov[(3, 3)] = 0.0025;
    cov[(4, 4)] = 0.0025;
    cov[(5, 5)] = 0.07;
    cov[(0, 5)] = 0.012;
    cov[(5, 0)] = 0.012;
    cov[(1, 5)] = -0.008;
    cov[(5, 1)] = -0.008;
    for yaw in [0.0, 0.5, 2.0, -3.0] {
        let r = So3::from_rpy(0.0, 0.0, yaw);
        let tf2 = ros_cov_to_right(&cov, &r, RosReading::Tf2);
        let body = ros_cov_to_right(&cov, &r, RosReading::Body);
        assert!((tf2 - body).norm() < 1e-14, "yaw {yaw}");
    }
    let tilted = So3::from_rpy(0.6, -0.5, 1.0);
    let tf2 = ros_cov_to_right(&cov, &tilted, RosReading::Tf2);
    let body = ros_cov_to_right(&cov, &tilted, RosReading::Body);
    assert!((tf2 - body).norm() > 0.1 * tf2.norm());
}

/// The right-form covariance of the first pose of a scenario.
fn first_pose_cov<const N: usize>(text: &str) -> TangentMatrix<N> {
    let loaded = load_text(text, "t.toml").unwrap_or_else(|e| panic!("{e}"));
    let cov = match &loaded.input.plan {
        AnyPlan::Se2(p) => match &p.poses[0].value {
            PoseValue::Uncertain(pose) => pose.cov_right().iter().copied().collect::<Vec<_>>(),
            PoseValue::Known(_) => panic!("uncertain"),
        },
        AnyPlan::Se3(p) => match &p.poses[0].value {
            PoseValue::Uncertain(pose) => pose.cov_right().iter().copied().collect::<Vec<_>>(),
            PoseValue::Known(_) => panic!("uncertain"),
        },
        _ => panic!("a pose group"),
    };
    TangentMatrix::<N>::from_iterator(cov)
}

fn numbers(m: &[f64]) -> String {
    m.iter()
        .map(|v| format!("{v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The sample covariance of zero-mean vectors.
fn second_moment<const N: usize>(v: &[nalgebra::SVector<f64, N>]) -> TangentMatrix<N> {
    v.iter()
        .map(|x| x * x.transpose())
        .sum::<TangentMatrix<N>>()
        / v.len() as f64
}

fn rng(seed: u64) -> rand::rngs::StdRng {
    rand::rngs::StdRng::seed_from_u64(seed)
}

/// `ros` for SE(2): 3×3 over (x, y, yaw) in the parent axes. Drawn here as the message means it
/// (p̃ = p + δp, ψ̃ = ψ + δψ) and read back as X̄⁻¹X̃ by hand: its tangent (ρ, θ) with
/// θ = δψ and ρ = V(θ)⁻¹ R(ψ)ᵀ δp.
#[test]
fn se2_ros_key_matches_draws_in_parent_axes() {
    let sigma = Matrix3::new(
        4e-4, 1e-4, 2e-5, //
        1e-4, 9e-4, -3e-5, //
        2e-5, -3e-5, 1e-4,
    );
    let (x, y, psi) = (2.0, -1.0, 2.3f64);
    let text = format!(
        "[scenario]\ntitle='t'\ngroup='se2'\n[[pose]]\nname='a'\nmean={{xy_theta=[{x}, {y}, {psi}]}}\n\
         cov={{ros=[{}]}}\n",
        numbers(sigma.transpose().as_slice())
    );
    let right = first_pose_cov::<3>(&text);
    let l = sigma.cholesky().expect("SPD").l();
    let mut g = rng(1);
    let (c, s) = (psi.cos(), psi.sin());
    let rt = Matrix2::new(c, s, -s, c); // R(ψ)ᵀ
    let draws: Vec<Vector3<f64>> = (0..200_000)
        .map(|_| {
            let z = Vector3::from_fn(|_, _| StandardNormal.sample(&mut g));
            let d = l * z;
            let th: f64 = d.z;
            let (a, b) = if th.abs() < 1e-12 {
                (1.0, 0.0)
            } else {
                (th.sin() / th, (1.0 - th.cos()) / th)
            };
            let v_inv = Matrix2::new(a, -b, b, a).try_inverse().expect("V");
            let rho = v_inv * rt * Vector2::new(d.x, d.y);
            Vector3::new(rho.x, rho.y, th)
        })
        .collect();
    let mc = second_moment(&draws);
    assert!(
        (right - mc).norm() < 0.02 * mc.norm(),
        "posecov\n{right}\nby hand\n{mc}"
    );
    // And `reading = "body"` is the same in the plane.
    let body = first_pose_cov::<3>(&text.replace("cov={ros=", "cov={reading='body', ros="));
    assert!((body - right).norm() < 1e-15);
}

/// `euler` in both orders: drawn as (x, y, z, roll, pitch, yaw) (or MRPT's yaw-pitch-roll)
/// additive in the parent axes and the angles, R = Rz(yaw) Ry(pitch) Rx(roll) built by
/// nalgebra, read back as ρ ≈ R̄ᵀ δp, θ = the scaled axis of R̄ᵀ R̃.
#[test]
fn euler_keys_match_draws_in_both_orders() {
    let mut sigma =
        Matrix6::from_diagonal(&nalgebra::Vector6::new(4e-4, 9e-4, 1e-4, 3e-4, 1e-4, 6e-4));
    sigma[(0, 3)] = 1e-4;
    sigma[(3, 0)] = 1e-4;
    sigma[(4, 5)] = -5e-5;
    sigma[(5, 4)] = -5e-5;
    let (rpy, xyz) = ([0.7, -0.6, 1.3], [1.0, 2.0, -0.5]);
    let mean_r = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
    let l = sigma.cholesky().expect("SPD").l();
    let mut g = rng(2);
    let draws: Vec<nalgebra::Vector6<f64>> = (0..200_000)
        .map(|_| {
            let z = nalgebra::Vector6::from_fn(|_, _| StandardNormal.sample(&mut g));
            let d = l * z; // (x, y, z, roll, pitch, yaw)
            let r = Rotation3::from_euler_angles(rpy[0] + d[3], rpy[1] + d[4], rpy[2] + d[5]);
            let rho = mean_r.inverse() * Vector3::new(d[0], d[1], d[2]);
            let theta = (mean_r.inverse() * r).scaled_axis();
            nalgebra::Vector6::new(rho.x, rho.y, rho.z, theta.x, theta.y, theta.z)
        })
        .collect();
    let mc = second_moment(&draws);
    let mean = format!("mean={{xyz=[{}], rpy=[{}]}}", numbers(&xyz), numbers(&rpy));
    let scenario = |cov: &str| {
        format!("[scenario]\ntitle='t'\ngroup='se3'\n[[pose]]\nname='a'\n{mean}\ncov={{{cov}}}\n")
    };
    let rpy_cov = first_pose_cov::<6>(&scenario(&format!(
        "euler=[{}], euler_order='xyz_rpy'",
        numbers(sigma.transpose().as_slice())
    )));
    assert!(
        (rpy_cov - mc).norm() < 0.03 * mc.norm(),
        "posecov\n{rpy_cov}\nby hand\n{mc}"
    );
    // MRPT lists the same angles as (yaw, pitch, roll).
    let p = [0, 1, 2, 5, 4, 3];
    let ypr = Matrix6::from_fn(|r, c| sigma[(p[r], p[c])]);
    let ypr_cov = first_pose_cov::<6>(&scenario(&format!(
        "euler=[{}], euler_order='xyz_ypr'",
        numbers(ypr.transpose().as_slice())
    )));
    assert!((ypr_cov - rpy_cov).norm() < 1e-12 * rpy_cov.norm());
}

/// The keys' modifiers are refused where they do not apply, each naming why.
#[test]
fn cov_key_modifiers_are_refused_where_they_do_not_apply() {
    let pose = |cov: &str, group: &str, mean: &str| {
        format!(
            "[scenario]\ntitle='t'\ngroup='{group}'\n[[pose]]\nname='a'\nmean={{{mean}}}\ncov={{{cov}}}\n"
        )
    };
    let ros36 = numbers(Matrix6::<f64>::identity().as_slice());
    for (text, says) in [
        (
            pose(&format!("euler=[{ros36}]"), "se3", "xyz=[0,0,0]"),
            "needs `euler_order`",
        ),
        (
            pose("std=[1,1,1,1,1,1], reading='body'", "se3", "xyz=[0,0,0]"),
            "`reading` applies to `ros` only",
        ),
        (
            pose(&format!("ros=[{ros36}], side='left'"), "se3", "xyz=[0,0,0]"),
            "`side` applies to",
        ),
        (
            pose(
                "ros=[1,0,0,0,1,0,0,0,1], reading='sideways'",
                "se2",
                "xy_theta=[0,0,0]",
            ),
            "sideways",
        ),
        (
            pose(
                "euler=[1,0,0,0,1,0,0,0,1], euler_order='xyz_rpy'",
                "se2",
                "xy_theta=[0,0,0]",
            ),
            "`euler` covariances are for SE(3)",
        ),
        (
            pose("ros=[1]", "so3", "rpy=[0,0,0]"),
            "`ros` covariances are for SE(2)",
        ),
    ] {
        let e = load_text(&text, "t.toml").expect_err("refused").to_string();
        assert!(e.contains(says), "{e}");
        assert!(e.starts_with("t.toml:"), "located: {e}");
    }
}

/// `--ros-reading` on a log: every JSON says which reading it used; the planar log's readings
/// coincide (0 apart); a scenario refuses the flag and says where its reading goes instead.
#[test]
fn every_log_report_says_which_reading_and_scenarios_refuse_the_flag() {
    let bin = env!("CARGO_BIN_EXE_posecov");
    let log = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/robot_localization/test2.bag"
    );
    for (flag, expected) in [(None, "tf2"), (Some("body"), "body"), (Some("tf2"), "tf2")] {
        let mut args = vec!["report", "--json", log];
        if let Some(reading) = flag {
            args.extend(["--ros-reading", reading]);
        }
        let out = std::process::Command::new(bin)
            .args(&args)
            .output()
            .expect("runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
        assert_eq!(v["meta"]["ros_reading"], expected);
        let topic = &v["topics"][0];
        assert_eq!(topic["ros_reading"], expected);
        assert_eq!(
            topic["ros_readings_apart"], 0.0,
            "planar: the readings coincide"
        );
    }
    let out = std::process::Command::new(bin)
        .args([
            "report",
            "ros_pose_with_covariance",
            "--ros-reading",
            "body",
        ])
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("--ros-reading body: applies to robot logs") && err.contains("`reading`"),
        "{err}"
    );
    let out = std::process::Command::new(bin)
        .args(["report", log, "--ros-reading", "sideways"])
        .output()
        .expect("runs");
    assert!(String::from_utf8_lossy(&out.stderr).contains("use `tf2` or `body`"));
}
