//! `report --json` carries every number the viewer shows, under stable keys, and each is
//! recomputed here from the evaluation's own particles or inputs:
//! `monte_carlo[*].uncentred_about_nominal_{left,right}`, `cartesian_mean`, `lie_mean_*`,
//! `covariance_right`; `results[*].relative_error_vs_monte_carlo`; the fusion cost V (with
//! Barfoot & Furgale's ½); `meta.sigma_points` and `[methods.sigma_points]` in files.

use nalgebra::{DMatrix, Matrix3};
use posecov::app::{Loaded, Overrides, load_text, pipeline, report_json};
use posecov::eval::AnyEvaluation;
use posecov::lie::{LieGroup, Se2};
use posecov::sample::uncentred_covariance;
use posecov::uncertain::Side;
use serde_json::Value;

fn run(text: &str, samples: u64) -> (Loaded, AnyEvaluation, Value) {
    let loaded = load_text(text, "t.toml").expect("loads");
    let overrides = Overrides {
        samples: Some(samples),
        ..Default::default()
    };
    let (evaluation, _) = pipeline(&loaded, &overrides, None).expect("evaluates");
    let json = report_json(
        "t",
        &loaded,
        &evaluation,
        posecov::uncertain::Confidence::DEFAULT,
    );
    (loaded, evaluation, json)
}

/// The last SE(2) node named `name` (its particles are kept: the plans here are short).
fn last_node<'e>(evaluation: &'e AnyEvaluation, name: &str) -> &'e posecov::eval::Node<Se2, 3> {
    let AnyEvaluation::Se2(e) = evaluation else {
        panic!("SE(2)")
    };
    e.nodes.iter().rfind(|n| n.name == name).expect("the node")
}

/// The entry of the array `json[key]` that `pick` selects.
fn entry<'j>(json: &'j Value, key: &str, pick: impl Fn(&Value) -> bool) -> &'j Value {
    json[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} is an array"))
        .iter()
        .find(|v| pick(v))
        .unwrap_or_else(|| panic!("no such entry in {key}"))
}

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("rows of numbers");
    DMatrix::from_fn(rows.len(), rows[0].len(), |r, c| rows[r][c])
}

fn close(a: &DMatrix<f64>, b: &DMatrix<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol * b.norm().max(1e-12)
}

const COMPOUND: &str = r#"[scenario]
title = "t"
group = "se2"
seed = 4
methods = ["first_order", "second_order", "monte_carlo"]
[[pose]]
name = "start"
mean = { xy_theta = [0.0, 0.0, 0.0] }
cov = { std = [0.0001, 0.0001, 0.0001], side = "left" }
[[pose]]
name = "step"
mean = { xy_theta = [1.0, 0.0, 0.0] }
[[operation]]
kind = "compound"
input = "start"
by = "step"
steps = 3
noise = { std = [0.0, 0.0, 0.1], side = "left" }
output = "robot"
"#;

#[test]
fn uncentred_monte_carlo_covariance_about_the_nominal_is_reported_on_both_sides() {
    let (_, evaluation, json) = run(COMPOUND, 500);
    let node = last_node(&evaluation, "robot");
    let particles = node
        .particles
        .as_ref()
        .expect("a short propagation keeps particles");
    let label = format!("robot@{}", node.step.expect("a step"));
    let record = entry(&json, "monte_carlo", |r| r["label"] == label.as_str());
    for (key, side) in [
        ("uncentred_about_nominal_left", Side::Left),
        ("uncentred_about_nominal_right", Side::Right),
    ] {
        let reported = matrix(&record[key]);
        let direct: Matrix3<f64> = uncentred_covariance(particles, &node.nominal, side).unwrap();
        let direct = DMatrix::from_column_slice(3, 3, direct.as_slice());
        assert!(
            close(&reported, &direct, 1e-9),
            "{key}: {reported} vs {direct}"
        );
    }
    // The two sides differ (the pose is 3 m out), so the right one is not a copy.
    assert!(!close(
        &matrix(&record["uncentred_about_nominal_left"]),
        &matrix(&record["uncentred_about_nominal_right"]),
        1e-3
    ));
    assert_eq!(record["samples"], 500);
    // The Lie mean and the centred covariance are the Monte Carlo estimate of `results`.
    let mc = entry(&json, "results", |r| {
        r["label"] == label.as_str() && r["method"] == "monte_carlo"
    });
    assert_eq!(record["lie_mean_tangent"], mc["mean_tangent"]);
    assert_eq!(record["lie_mean_matrix"], mc["mean_matrix"]);
    assert_eq!(record["covariance_right"], mc["covariance"]);
    // No Cartesian mean is asked for by compounding: the key is there, null.
    assert!(record["cartesian_mean"].is_null());
}

#[test]
fn every_methods_error_is_the_relative_frobenius_distance_to_monte_carlo() {
    let (_, _, json) = run(COMPOUND, 400);
    let results = json["results"].as_array().unwrap();
    let mut checked = 0;
    for r in results.iter().filter(|r| r["method"] != "monte_carlo") {
        let mc = results
            .iter()
            .find(|m| m["label"] == r["label"] && m["method"] == "monte_carlo")
            .expect("Monte Carlo ran at every step");
        let error = r["relative_error_vs_monte_carlo"]
            .as_f64()
            .expect("an error for every method where Monte Carlo ran");
        // Both on the right side: convert a left-form estimate with its own mean's adjoint.
        let mut cov = matrix(&r["covariance"]);
        if r["side"] == "left" {
            let t: Vec<f64> = serde_json::from_value(r["mean_tangent"].clone()).unwrap();
            let mean = Se2::exp(&nalgebra::Vector3::new(t[0], t[1], t[2]));
            let ad = mean.inverse().adj();
            let ad = DMatrix::from_column_slice(3, 3, ad.as_slice());
            cov = &ad * cov * ad.transpose();
        }
        let reference = matrix(&mc["covariance"]);
        let expected = (&cov - &reference).norm() / reference.norm();
        assert!(
            (error - expected).abs() < 1e-9 * expected.max(1.0),
            "{}: {error} vs {expected}",
            r["label"]
        );
        checked += 1;
    }
    assert!(checked >= 6, "first and second order at 3 steps: {checked}");
}

#[test]
fn the_differential_drive_reports_its_cartesian_and_lie_means() {
    let text = r#"[scenario]
title = "t"
group = "se2"
seed = 2
methods = ["closed_form", "monte_carlo"]
[[operation]]
kind = "diff_drive"
wheel_radius = 0.033
wheelbase = 0.2
duration = 1.0
diffusion = 2.0
speed = 1.0
turn_rate = 0.0
dt = 0.01
output = "end"
"#;
    let (_, evaluation, json) = run(text, 300);
    let node = last_node(&evaluation, "end");
    let particles = node.particles.as_ref().expect("particles");
    let direct = particles
        .iter()
        .map(|g| *g.to_se3().translation())
        .sum::<nalgebra::Vector3<f64>>()
        / particles.len() as f64;
    let record = entry(&json, "monte_carlo", |r| r["label"] == "end");
    let cartesian: Vec<f64> = serde_json::from_value(record["cartesian_mean"].clone()).unwrap();
    for k in 0..3 {
        assert!(
            (cartesian[k] - direct[k]).abs() < 1e-12,
            "{cartesian:?} vs {direct}"
        );
    }
    let lie = node.monte_carlo.as_ref().unwrap().stats.mean.log();
    let reported: Vec<f64> = serde_json::from_value(record["lie_mean_tangent"].clone()).unwrap();
    for k in 0..3 {
        assert!((reported[k] - lie[k]).abs() < 1e-12);
    }
    // The curved cloud's Cartesian mean lies behind its Lie mean (it retreats inside the banana).
    let finding = entry(&json, "findings", |f| f["kind"] == "diff_drive_means");
    assert_eq!(finding["cartesian_mean"][0].as_f64().unwrap(), cartesian[0]);
    assert!(finding["lie_mean"][0].as_f64().unwrap() > cartesian[0]);
}

#[test]
fn the_fusion_cost_is_barfoot_and_furgales_v_with_the_half() {
    let text = r#"[scenario]
title = "t"
group = "se2"
methods = ["first_order"]
[[pose]]
name = "a"
mean = { xy_theta = [1.0, 0.0, 0.1] }
cov = { std = [0.1, 0.2, 0.05] }
[[pose]]
name = "b"
mean = { xy_theta = [1.2, 0.1, 0.0] }
cov = { std = [0.2, 0.1, 0.1] }
[[operation]]
kind = "fuse"
inputs = ["a", "b"]
output = "f"
"#;
    let (_, _, json) = run(text, 50);
    let fused = entry(&json, "results", |r| r["label"] == "f");
    let t: Vec<f64> = serde_json::from_value(fused["mean_tangent"].clone()).unwrap();
    let x = Se2::exp(&nalgebra::Vector3::new(t[0], t[1], t[2]));
    // V = ½ Σ eᵢᵀ Σᵢ⁻¹ eᵢ, eᵢ = Log(μᵢ⁻¹ X) (right form), from the inputs as written above.
    let inputs = [
        (Se2::from_xy_theta(1.0, 0.0, 0.1), [0.1, 0.2, 0.05]),
        (Se2::from_xy_theta(1.2, 0.1, 0.0), [0.2, 0.1, 0.1]),
    ];
    let v: f64 = 0.5
        * inputs
            .iter()
            .map(|(mu, std)| {
                let e = mu.inverse().compose(&x).log();
                (0..3).map(|k| e[k] * e[k] / (std[k] * std[k])).sum::<f64>()
            })
            .sum::<f64>();
    let finding = entry(&json, "findings", |f| f["kind"] == "fusion");
    let cost = finding["cost"].as_f64().unwrap();
    assert!(v > 0.1, "the estimates disagree: V = {v}");
    assert!((cost - v).abs() < 1e-9 * v, "reported {cost}, V = {v}");
}

/// A heading σ of 2 rad: at α = 1 (γ = √3) the inverse's sigma points turn 3.46 rad > π.
const SIGMA: &str = r#"[scenario]
title = "t"
group = "se2"
methods = ["first_order", "sigma_points"]
[[pose]]
name = "a"
mean = { xy_theta = [1.0, 0.0, 0.0] }
cov = { std = [0.1, 0.1, 2.0] }
[[operation]]
kind = "inverse"
input = "a"
output = "b"
"#;

fn covariance_of(json: &Value, method: &str) -> DMatrix<f64> {
    let r = entry(json, "results", |r| {
        r["label"] == "b" && r["method"] == method
    });
    matrix(&r["covariance"])
}

#[test]
fn sigma_point_parameters_come_from_the_file_and_reach_the_report() {
    let (_, _, default) = run(SIGMA, 50);
    assert_eq!(default["meta"]["sigma_points"]["alpha"], 1.0);
    assert_eq!(default["meta"]["sigma_points"]["beta"], 2.0);
    assert_eq!(default["meta"]["sigma_points"]["kappa"], 0.0);
    let text = format!("{SIGMA}[methods.sigma_points]\nalpha = 0.3\nkappa = 1.0\n");
    let (_, _, tuned) = run(&text, 50);
    assert_eq!(tuned["meta"]["sigma_points"]["alpha"], 0.3);
    assert_eq!(tuned["meta"]["sigma_points"]["beta"], 2.0);
    assert_eq!(tuned["meta"]["sigma_points"]["kappa"], 1.0);
    // The wrap-around caveat: inversion is linear in the tangent, so sigma points equal first
    // order — while every sigma point turns less than π. At α = 1 they turn 3.46 rad and wrap;
    // at α = 0.3 (γ = 0.6) they stay inside and agree to round-off.
    let first = covariance_of(&default, "exact"); // inversion moves a Gaussian exactly to first order
    assert!(!close(
        &covariance_of(&default, "sigma_points"),
        &first,
        0.05
    ));
    assert!(close(&covariance_of(&tuned, "sigma_points"), &first, 1e-9));
    // …and the report says where they wrap.
    let wrap = wrap_finding(&default).expect("a wrap-around finding at α = 1");
    assert!((wrap["largest_rotation_rad"].as_f64().unwrap() - 3f64.sqrt() * 2.0).abs() < 1e-12);
    assert!(wrap_finding(&tuned).is_none());
}

/// The `sigma_points_wrap` finding of `json`, if any.
fn wrap_finding(json: &Value) -> Option<&Value> {
    json["findings"]
        .as_array()
        .expect("findings")
        .iter()
        .find(|f| f["kind"] == "sigma_points_wrap")
}

/// A compose of two uncertain SE(2) poses, `a` with a heading σ of √2 rad: L = 6, γ = √6 at
/// α = 1, so its heading sigma points turn √12 = 3.46 rad.
const WRAP: &str = r#"[scenario]
title = "t"
group = "se2"
methods = ["first_order", "sigma_points"]
[[pose]]
name = "a"
mean = { xy_theta = [2.0, 1.0, 0.5] }
cov = { std = [0.05, 0.05, 1.4142135623730951] }
[[pose]]
name = "m"
mean = { xy_theta = [1.5, 0.0, 0.0] }
cov = { std = [0.05, 0.05, 0.05] }
[[operation]]
kind = "compose"
lhs = "a"
rhs = "m"
output = "b"
"#;

#[test]
fn sigma_points_beyond_pi_are_a_finding_with_the_angle_and_the_alpha_that_avoids_it() {
    let (_, _, wide) = run(WRAP, 50);
    let wrap = wrap_finding(&wide).expect("a wrap-around finding at α = 1");
    let turn = 12f64.sqrt();
    assert_eq!(wrap["output"], "b");
    assert_eq!(wrap["alpha"], 1.0);
    assert!((wrap["largest_rotation_rad"].as_f64().unwrap() - turn).abs() < 1e-12);
    let below = wrap["alpha_below_pi"].as_f64().unwrap();
    assert!((below - std::f64::consts::PI / turn).abs() < 1e-12);
    // The wrapped points lose (1 − ((2π − √12)/√12)²) of the heading's share: 34 % off.
    let first = covariance_of(&wide, "first_order");
    let sigma = covariance_of(&wide, "sigma_points");
    let off = (&sigma - &first).norm() / first.norm();
    assert!((off - 0.3375).abs() < 1e-3, "{off}");

    // Just below that α every point stays within π: no finding, first order to 1e-9.
    let text = format!("{WRAP}[methods.sigma_points]\nalpha = {}\n", below * 0.99);
    let (loaded, _, inside) = run(&text, 50);
    assert!(wrap_finding(&inside).is_none());
    assert!(close(
        &covariance_of(&inside, "sigma_points"),
        &covariance_of(&inside, "first_order"),
        1e-9
    ));
    // The text panel says it where it applies, and only there.
    let (_, scene) = pipeline(&loaded, &Overrides::default(), None).unwrap();
    assert!(!scene.description_markdown.contains("wrap"));
    let (_, scene) = pipeline(
        &load_text(WRAP, "t.toml").unwrap(),
        &Overrides::default(),
        None,
    )
    .unwrap();
    let md = &scene.description_markdown;
    assert!(
        md.contains("**Sigma points wrap around** for `b`: one turns 3.46 rad"),
        "{md}"
    );
    assert!(md.contains("a turn of -2.82 rad"), "{md}");
    assert!(
        md.contains("any α below 0.907 (now 1), e.g. `[methods.sigma_points] alpha = 0.9`"),
        "{md}"
    );
}

#[test]
fn no_bundled_scenario_wraps_its_sigma_points_until_alpha_pushes_them_past_pi() {
    let mut with_sigma_points = Vec::new();
    for b in posecov::input::scenario::bundled::BUNDLED {
        let (_, evaluation, json) = run(b.text, 16);
        assert!(wrap_finding(&json).is_none(), "{}", b.name);
        if evaluation
            .ran_with()
            .methods
            .contains(&posecov::uncertain::Method::SigmaPoints)
        {
            with_sigma_points.push(b.name);
        }
    }
    assert_eq!(
        with_sigma_points,
        ["camera_on_robot", "se3_global_vs_local"]
    );
    // camera_on_robot: heading σ 20°, L = 3, so its points turn α√3 · 20° — past π at α = 6.
    let mut loaded = posecov::app::load("camera_on_robot").unwrap();
    loaded.input.defaults.sigma_points = Some(posecov::propagate::sigma_point::Unscented {
        alpha: 6.0,
        ..Default::default()
    });
    let overrides = Overrides {
        samples: Some(16),
        ..Default::default()
    };
    let (evaluation, _) = pipeline(&loaded, &overrides, None).unwrap();
    let json = report_json(
        "t",
        &loaded,
        &evaluation,
        posecov::uncertain::Confidence::DEFAULT,
    );
    let wrap = wrap_finding(&json).expect("α = 6 pushes them past π");
    let turn = 6.0 * 3f64.sqrt() * 20f64.to_radians();
    assert!((wrap["largest_rotation_rad"].as_f64().unwrap() - turn).abs() < 1e-12);
}

#[test]
fn bad_sigma_point_parameters_and_cameras_are_named_where_they_are_written() {
    for (extra, expected) in [
        (
            "[methods.sigma_points]\nalpha = 0.0\n",
            "methods.sigma_points.alpha: 0 is out of range",
        ),
        (
            "[methods.sigma_points]\nkappa = -3.0\n",
            "methods.sigma_points.kappa: -3 is out of range: a finite κ > −3",
        ),
        (
            "[methods.sigma_points]\ngamma = 1.0\n",
            "unknown field `gamma`",
        ),
        (
            "[draw]\ncamera = { position = [0.0, 0.0, 5.0], direction = [0.0, 0.0, 1.0] }\n",
            "draw.camera: give `position` or `direction`, not both",
        ),
        (
            "[draw]\ncamera = { direction = [0.0, 0.0, 1.0] }\n",
            "draw.camera: up = [0.0, 0.0, 1.0] lies along the line of sight",
        ),
        (
            "[draw]\ncamera = { position = [1.0, 1.0, 1.0], target = [1.0, 1.0, 1.0] }\n",
            "draw.camera: the eye `position` is at its `target`",
        ),
        ("[draw]\nlayout = \"grid\"\n", "unknown variant `grid`"),
    ] {
        let text = format!("{SIGMA}{extra}");
        let err = load_text(&text, "t.toml").unwrap_err().to_string();
        assert!(err.starts_with("t.toml:"), "{err}");
        assert!(err.contains(expected), "{extra}: {err}");
    }
}

#[test]
fn a_file_camera_is_the_views_camera() {
    let text = format!(
        "{SIGMA}[draw]\ncamera = {{ position = [1.0, -4.0, 3.0], target = [1.0, 0.0, 0.0] }}\n"
    );
    let loaded = load_text(&text, "t.toml").unwrap();
    let (_, scene) = pipeline(&loaded, &Overrides::default(), None).unwrap();
    assert!(!scene.views.is_empty());
    for view in &scene.views {
        let camera = view.camera.expect("a camera");
        assert_eq!(camera.position, [1.0, -4.0, 3.0]);
        assert_eq!(camera.target, [1.0, 0.0, 0.0]);
        assert_eq!(camera.up, [0.0, 0.0, 1.0]);
    }
}

/// The text panel lists the Monte Carlo cloud only where Monte Carlo ran.
#[test]
fn the_text_panel_names_the_monte_carlo_cloud_only_where_monte_carlo_ran() {
    let without = WRAP.replace(
        "methods = [\"first_order\", \"sigma_points\"]",
        "methods = [\"first_order\"]",
    );
    let with = WRAP.replace(
        "methods = [\"first_order\", \"sigma_points\"]",
        "methods = [\"first_order\", \"monte_carlo\"]",
    );
    let overrides = Overrides {
        samples: Some(50),
        ..Default::default()
    };
    let text = |toml: &str| {
        let loaded = load_text(toml, "t.toml").unwrap();
        pipeline(&loaded, &overrides, None)
            .unwrap()
            .1
            .description_markdown
    };
    let md = text(&without);
    assert!(md.contains("| first order |"), "{md}");
    assert!(!md.contains("Monte Carlo"), "{md}");
    assert!(!md.contains("grey cloud"), "{md}");
    let md = text(&with);
    assert!(
        md.contains("| Monte Carlo samples | grey cloud (50 samples, seed 0) |\n\n"),
        "{md}"
    );
}
