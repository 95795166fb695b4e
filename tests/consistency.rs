//! Is the drawn uncertainty honest? `results[].coverage`, `anees` and `anees_band` of
//! `report --json` against computations made here, independently of posecov: the camera on a
//! robot (the lecture's banana, whose Cartesian ellipse holds about 70 % of the cameras, not
//! 95 %), and linear-Gaussian cases in which every method is exact, so every tangent region
//! holds the confidence within Monte Carlo error.

use nalgebra::{Matrix2, Vector2};
use posecov::app::{Overrides, load, load_text, pipeline, report_json};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde_json::Value;

/// χ²₂(0.95) = −2 ln 0.05 (the 2-DOF χ² has a closed-form quantile).
const CHI2_2_95: f64 = 5.991_464_547_107_979;

fn report(loaded: &posecov::app::Loaded, samples: u64) -> Value {
    let overrides = Overrides {
        samples: Some(samples),
        ..Default::default()
    };
    let (evaluation, _) = pipeline(loaded, &overrides, None).expect("evaluates");
    report_json(
        "t",
        loaded,
        &evaluation,
        posecov::uncertain::Confidence::DEFAULT,
    )
}

/// The `results[]` entry of `label` and `method`.
fn result<'j>(json: &'j Value, label: &str, method: &str) -> &'j Value {
    json["results"]
        .as_array()
        .expect("results")
        .iter()
        .find(|r| r["label"] == label && r["method"] == method)
        .unwrap_or_else(|| panic!("no result {label} / {method}"))
}

/// (inside, stderr, dof) of `region` in a result's `coverage`.
fn coverage(result: &Value, region: &str) -> (f64, f64, u64) {
    let c = result["coverage"]
        .as_array()
        .expect("coverage")
        .iter()
        .find(|c| c["region"] == region)
        .unwrap_or_else(|| panic!("no {region} coverage in {result}"));
    (
        c["inside"].as_f64().expect("inside"),
        c["stderr"].as_f64().expect("stderr"),
        c["dof"].as_u64().expect("dof"),
    )
}

/// The camera-on-robot cloud drawn here with its own generator: the robot at
/// (2, 1, 30°) with σ = (5 cm, 5 cm, 20°) on the right, the camera 1.5 m ahead. Its
/// first-order Cartesian covariance is derived by hand: with X = μ Exp([ρ; φ]), the camera's
/// position is t + R V(φ) ρ + R(θ + φ) (1.5, 0), whose Jacobian at 0 is R on ρ and R (0, 1.5)
/// on φ, so Σ_p = R (σ_ρ² I + σ_φ² (0, 1.5)(0, 1.5)ᵀ) Rᵀ. Returns the share of n cameras inside
/// its 95 % ellipse.
fn camera_ellipse_coverage_by_hand(n: usize) -> f64 {
    let (x, y, theta) = (2.0, 1.0, 30f64.to_radians());
    let (s_rho, s_phi) = (0.05, 20f64.to_radians());
    let lever = 1.5;
    let rot = |a: f64| Matrix2::new(a.cos(), -a.sin(), a.sin(), a.cos());
    let r = rot(theta);
    let arm = Vector2::new(0.0, lever);
    let cov = r
        * (Matrix2::identity() * s_rho * s_rho + arm * arm.transpose() * s_phi * s_phi)
        * r.transpose();
    let info = cov.try_inverse().expect("regular");
    let centre = Vector2::new(x, y) + r * Vector2::new(lever, 0.0);
    let mut rng = rand::rngs::StdRng::seed_from_u64(20_261_202);
    let mut inside = 0usize;
    for _ in 0..n {
        let mut z = || -> f64 { StandardNormal.sample(&mut rng) };
        let (rho, phi) = (Vector2::new(z() * s_rho, z() * s_rho), z() * s_phi);
        // SE(2)'s V(φ) = (sin φ / φ) I + ((1 − cos φ) / φ) [[0, −1], [1, 0]].
        let (a, b) = if phi.abs() < 1e-9 {
            (1.0, 0.0)
        } else {
            (phi.sin() / phi, (1.0 - phi.cos()) / phi)
        };
        let v = Matrix2::new(a, -b, b, a);
        let camera = Vector2::new(x, y) + r * v * rho + rot(theta + phi) * Vector2::new(lever, 0.0);
        let d = camera - centre;
        inside += usize::from(d.dot(&(info * d)) <= CHI2_2_95);
    }
    inside as f64 / n as f64
}

#[test]
fn the_camera_scenarios_cartesian_ellipse_holds_about_70_percent_and_its_banana_95() {
    let loaded = load("camera_on_robot").expect("bundled");
    let json = report(&loaded, 20_000);
    let by_hand = camera_ellipse_coverage_by_hand(200_000);
    assert!((by_hand - 0.70).abs() < 0.02, "by hand: {by_hand}");
    // A change of frame by a known mount moves the Gaussian exactly (method `exact`).
    let first = result(&json, "map_from_camera", "exact");
    let (cartesian, stderr, dof) = coverage(first, "cartesian");
    assert_eq!(dof, 2);
    // Two independent Monte Carlo estimates: within 4 standard errors of their difference.
    let tolerance = 4.0 * (stderr.powi(2) + by_hand * (1.0 - by_hand) / 200_000.0).sqrt();
    assert!(
        (cartesian - by_hand).abs() < tolerance,
        "posecov {cartesian} ± {stderr}, by hand {by_hand}"
    );
    // The change of frame is exact on the tangent: the banana holds the confidence.
    let (tangent, stderr, dof) = coverage(first, "tangent");
    assert_eq!(dof, 3);
    assert!((tangent - 0.95).abs() < 4.0 * stderr, "tangent {tangent}");
    let band = first["anees_band"].as_array().expect("band");
    let anees = first["anees"].as_f64().expect("anees");
    assert!(band[0].as_f64().unwrap() < anees && anees < band[1].as_f64().unwrap());
    assert_eq!(first["anees_dof"], 3);
    // The vector-space ellipse is the same first-order ellipse: it misses the same cameras.
    let vector = result(&json, "map_from_camera", "vector_space");
    let (ellipse, stderr, _) = coverage(vector, "vector_space");
    assert!(
        (ellipse - cartesian).abs() < 4.0 * stderr,
        "{ellipse} vs {cartesian}"
    );
}

/// Every method is exact: a change of frame and an inverse on SE(2) (linear in the tangent:
/// Ad), and angles added on SO(2).
#[test]
fn where_every_method_is_exact_every_tangent_region_holds_the_confidence() {
    let se2 = r#"[scenario]
title = "t"
group = "se2"
seed = 5
confidence = 0.9
methods = ["first_order", "sigma_points", "monte_carlo"]
[[pose]]
name = "a"
mean = { xy_theta = [1.0, -2.0, 0.4] }
cov = { std = [0.3, 0.2, 0.25] }
[[pose]]
name = "mount"
mean = { xy_theta = [0.5, 0.2, 1.0] }
[[operation]]
kind = "change_frame_right"
input = "a"
by = "mount"
output = "a_mount"
[[operation]]
kind = "inverse"
input = "a"
output = "a_inv"
"#;
    let so2 = r#"[scenario]
title = "t"
group = "so2"
seed = 6
confidence = 0.9
methods = ["first_order", "sigma_points", "monte_carlo"]
[[pose]]
name = "a"
mean = { angle_deg = 30.0 }
cov = { std_deg = [10.0] }
[[pose]]
name = "b"
mean = { angle_deg = -50.0 }
cov = { std_deg = [15.0] }
[[operation]]
kind = "compose"
lhs = "a"
rhs = "b"
output = "ab"
"#;
    let samples = 20_000;
    let mut checked = 0;
    // A change of frame and an inverse are `exact`; SO(2) compose is first order.
    for (text, outputs, first) in [
        (se2, &["a_mount", "a_inv"][..], "exact"),
        (so2, &["ab"][..], "first_order"),
    ] {
        let loaded = load_text(text, "t.toml").expect("loads");
        let json = report(&loaded, samples);
        for output in outputs {
            for method in [first, "sigma_points", "monte_carlo"] {
                let r = result(&json, output, method);
                let (inside, stderr, _) = coverage(r, "tangent");
                // The binomial error of p itself at this sample size.
                let sigma = (0.9f64 * 0.1 / samples as f64).sqrt();
                assert!((stderr - sigma).abs() < 0.2 * sigma, "{stderr} vs {sigma}");
                assert!(
                    (inside - 0.9).abs() < 4.0 * sigma,
                    "{output} {method}: {inside} inside, not 0.9"
                );
                let anees = r["anees"].as_f64().expect("anees");
                let dof = r["anees_dof"].as_f64().expect("dof");
                assert!(
                    (anees - dof).abs() < 0.05 * dof,
                    "{output} {method}: {anees}"
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 9);
}

/// Without Monte Carlo there is nothing to count: empty coverage, no ANEES.
#[test]
fn without_monte_carlo_no_coverage_is_claimed() {
    let text = "[scenario]\ntitle='t'\ngroup='se2'\nmethods=['first_order']\n[[pose]]\nname='a'\n\
                mean={xy_theta=[1,2,0]}\ncov={std=[0.1,0.1,0.1]}\n[[operation]]\nkind='inverse'\n\
                input='a'\noutput='b'\n";
    let loaded = load_text(text, "t.toml").expect("loads");
    let json = report(&loaded, 100);
    let r = result(&json, "b", "exact");
    assert_eq!(r["coverage"], Value::Array(Vec::new()));
    assert!(r["anees"].is_null() && r["anees_band"].is_null());
}

/// A sample simulated in blocks counts every block: the analytic estimates' coverage and ANEES
/// equal the whole sample's; Monte Carlo's own Gaussian, known only after every block, has none.
#[test]
fn a_blocked_sample_counts_the_same_as_a_whole_one() {
    let loaded = load("camera_on_robot").expect("bundled");
    let run = |block_samples| {
        let overrides = Overrides {
            samples: Some(9000),
            block_samples,
            ..Default::default()
        };
        let (evaluation, _) = pipeline(&loaded, &overrides, None).expect("evaluates");
        report_json(
            "t",
            &loaded,
            &evaluation,
            posecov::uncertain::Confidence::DEFAULT,
        )
    };
    let (whole, blocked) = (run(None), run(Some(2048)));
    for method in ["exact", "sigma_points", "vector_space"] {
        let (a, b) = (
            result(&whole, "map_from_camera", method),
            result(&blocked, "map_from_camera", method),
        );
        assert_eq!(a["coverage"], b["coverage"], "{method}");
        let (x, y) = (a["anees"].as_f64().unwrap(), b["anees"].as_f64().unwrap());
        assert!((x - y).abs() < 1e-9 * x, "{method}: {x} vs {y}");
    }
    let mc = result(&blocked, "map_from_camera", "monte_carlo");
    assert_eq!(mc["coverage"], Value::Array(Vec::new()));
}
