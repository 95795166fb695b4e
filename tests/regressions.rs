//! Regression tests for the bugs the one-way pipeline fixed; each failed before its fix.

use posecov::app::{AppError, Overrides, load_text, pipeline, resolve};
use posecov::eval::{AnyEvaluation, Finding};
use posecov::uncertain::Method;

fn overrides(samples: u64) -> Overrides {
    Overrides {
        samples: Some(samples),
        ..Default::default()
    }
}

fn run(text: &str, samples: u64) -> Result<AnyEvaluation, AppError> {
    let loaded = load_text(text, "case.toml")?;
    pipeline(&loaded, &overrides(samples), None).map(|(e, _)| e)
}

fn error(text: &str) -> String {
    match run(text, 64) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

const POINT_OK: &str = r#"
[scenario]
title = "point"
group = "se2"
methods = ["first_order", "monte_carlo"]
[[pose]]
name = "world_from_robot"
mean = { xy_theta = [1.0, 0.0, 0.3] }
cov = { std = [0.1, 0.1, 0.1] }
[[operation]]
kind = "point_through_pose"
input = "world_from_robot"
point = [1.0, 0.0]
output = "landmark"
"#;

/// The point of [`POINT_OK`] used as a pose by a second operation (lines 15–18).
fn point_used_as_pose() -> String {
    format!(
        "{POINT_OK}[[operation]]\nkind = \"inverse\"\ninput = \"landmark\"\noutput = \"oops\"\n"
    )
}

/// A point used as a pose was silently the identity; now it is an error naming the operation
/// and the field.
#[test]
fn a_point_is_not_a_pose() {
    let e = error(&point_used_as_pose());
    assert!(
        e.starts_with("case.toml:17:9: operation[1].input: `landmark` is a point"),
        "{e}"
    );
}

/// `--samples 1` was reported at the file's `samples` line; a bad flag names the flag.
#[test]
fn a_bad_flag_names_the_flag_and_a_bad_file_value_its_line() {
    let text = POINT_OK.replace("methods =", "samples = 300\nmethods =");
    let loaded = load_text(&text, "case.toml").expect("valid");
    for n in [0, 1, 10_000_001] {
        let e = resolve(&loaded.input, &overrides(n), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("--samples {n}: out of range")),
            "{e}"
        );
    }
    let e = error(&POINT_OK.replace("methods =", "samples = 1\nmethods ="));
    assert!(
        e.starts_with("case.toml:5:11: scenario.samples: 1 is out of range"),
        "{e}"
    );
}

const ODOMETRY: &str = r#"
[scenario]
title = "long odometry"
group = "se2"
methods = ["first_order", "monte_carlo"]
[[pose]]
name = "world_from_robot"
mean = { xy_theta = [0.0, 0.0, 0.0] }
cov = { std = [0.01, 0.01, 0.01] }
[[operation]]
kind = "odometry"
input = "world_from_robot"
model = "increment"
controls = [[0.1, 0.0, 0.01]]
steps = STEPS
noise = { std = [0.01, 0.01, 0.005] }
output = "robot"
"#;

/// Odometry and compounding kept a particle copy per step; now at most the detailed steps
/// (and the last) keep particles and at most ~1000 steps are recorded, whatever `steps`.
#[test]
fn long_propagations_keep_a_bounded_number_of_particle_sets() {
    for steps in [10u64, 5000] {
        let e = run(&ODOMETRY.replace("STEPS", &steps.to_string()), 256).expect("runs");
        let AnyEvaluation::Se2(e) = e else {
            panic!("SE(2)")
        };
        let with_particles = e.nodes.iter().filter(|n| n.particles.is_some()).count();
        let recorded = e.nodes.iter().filter(|n| n.name == "robot").count();
        assert!(
            with_particles <= 22,
            "{steps} steps: {with_particles} particle sets"
        );
        assert_eq!(
            recorded as u64,
            steps.min(1000) + 1,
            "{steps} steps recorded"
        );
        let last = e
            .nodes
            .iter()
            .rev()
            .find(|n| n.name == "robot")
            .expect("last");
        assert_eq!(last.step, Some(steps), "the last step is always recorded");
        assert!(last.particles.is_some() && last.monte_carlo.is_some());
        if steps > 1000 {
            assert!(
                e.findings
                    .iter()
                    .any(|f| matches!(f, Finding::StepsThinned { .. }))
            );
        }
    }
}

/// `euler_vs_exp`'s `input` was never resolved: unknown names passed.
#[test]
fn euler_vs_exp_resolves_its_input() {
    let text = r#"
[scenario]
title = "e"
group = "so3"
[[pose]]
name = "start"
mean = { rpy = [0.0, 0.0, 0.0] }
[[operation]]
kind = "euler_vs_exp"
input = "nobody"
output = "spin"
rate = [0.0, 0.0, 1.0]
dt = 0.1
steps = 3
"#;
    let e = error(text);
    assert!(
        e.starts_with("case.toml:10:9: operation[0].input: no pose named `nobody`"),
        "{e}"
    );
}

const SE3: &str = r#"
[scenario]
title = "compose"
group = "se3"
methods = ["first_order", "fourth_order", "monte_carlo"]
[[pose]]
name = "world_from_a"
mean = { xyz = [1.0, 0.0, 0.0], rpy = [0.0, 0.0, 0.0] }
cov = { std = [SA, 0.1, 0.1, 1.5, 1.5, 1.5] }
[[pose]]
name = "world_from_b"
mean = { xyz = [XB, 0.0, 0.0], rpy = [0.0, 0.0, 0.0] }
cov = { std = [0.1, 0.1, 0.1, 1.5, 1.5, 1.5] }
[[operation]]
kind = "compose"
lhs = "world_from_a"
rhs = "world_from_b"
output = "ab"
"#;

/// Huge values overflowed into NaN/inf that reached the report as `null` (and hung the
/// drawing); now an overflow is an error at the operation, and an input too large is refused
/// where it is written.
#[test]
fn overflow_is_an_error_with_a_location_not_a_nan() {
    let e = error(&SE3.replace("SA", "1e150").replace("XB", "1.0"));
    assert!(
        e.starts_with("case.toml:9:7: pose[0].cov: a covariance entry"),
        "{e}"
    );
    assert!(e.contains("too large"), "{e}");
    let e = error(&SE3.replace("SA", "0.1").replace("XB", "1e300"));
    assert!(
        e.starts_with("case.toml:12:8: pose[1].mean: a coordinate"),
        "{e}"
    );
    // Within the input limits, a long propagation overflows: an error at the operation.
    let bundled = posecov::input::scenario::bundled::find("barfoot_compounding").expect("bundled");
    let text = bundled
        .text
        .replace(
            "mean = { xyz = [1.0, 0.0, 0.0] }",
            "mean = { xyz = [1e12, 0.0, 0.0] }",
        )
        .replace("steps = 100", "steps = 100000");
    assert_ne!(text, bundled.text);
    let e = match run(&text, 16) {
        Ok(_) => panic!("expected an overflow error"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("operation[0]: (`robot`, step ") && e.contains("result is not finite"),
        "{e}"
    );
}

/// Fourth-order compounding with large noise returned indefinite covariances that the
/// drawing silently clamped; now each is reported as a finding.
#[test]
fn an_indefinite_covariance_is_reported() {
    let bundled = posecov::input::scenario::bundled::find("se3_global_vs_local").expect("bundled");
    let text = bundled
        .text
        .replace(
            "[0.02, 0.02, 0.02, 0.15, 0.15, 0.25]",
            "[0.2, 0.2, 0.2, 1.5, 1.5, 2.5]",
        )
        .replace(
            "[0.05, 0.05, 0.05, 0.05, 0.05, 0.1]",
            "[0.5, 0.5, 0.5, 0.5, 0.5, 1.0]",
        );
    assert_ne!(text, bundled.text, "the noise was raised");
    let e = run(&text, 64).expect("runs");
    let indefinite: Vec<_> = e
        .findings()
        .iter()
        .filter_map(|f| match f {
            Finding::NotPositiveSemiDefinite {
                method,
                smallest_eigenvalue,
                ..
            } => Some((*method, *smallest_eigenvalue)),
            _ => None,
        })
        .collect();
    assert!(
        indefinite
            .iter()
            .any(|(m, l)| *m == Method::FourthOrder && *l < 0.0),
        "{indefinite:?}"
    );
    let json = serde_json::to_value(e.findings()).expect("serialises");
    assert!(
        json.to_string().contains("not_positive_semi_definite"),
        "{json}"
    );
}

/// `draw.axis_length` accepted 0, negative and NaN and failed late at the scene; now it is
/// refused where it is written.
#[test]
fn axis_length_is_checked_where_it_is_written() {
    for bad in ["0.0", "-1.0", "nan", "1e300"] {
        let e = error(&format!("{POINT_OK}\n[draw]\naxis_length = {bad}\n"));
        assert!(
            e.starts_with("case.toml:17:15: draw.axis_length: "),
            "{bad}: {e}"
        );
    }
}

/// Parse errors named the field `toml` and spoke Rust.
#[test]
fn parse_errors_speak_the_files_language() {
    let e = error(&POINT_OK.replace("methods =", "samples = -5\nmethods ="));
    assert!(
        e.starts_with("case.toml:5:11: scenario.samples: -5 is not a whole number ≥ 0"),
        "{e}"
    );
    let e = error(&POINT_OK.replace("mean = { xy_theta = [1.0, 0.0, 0.3] }", "mean = 3"));
    assert!(e.contains("pose[0].mean") && !e.contains("struct"), "{e}");
}

const DIFF_DRIVE: &str = r#"
[scenario]
title = "dd"
group = "se2"
methods = ["closed_form", "numeric_integral", "monte_carlo"]
[[operation]]
kind = "diff_drive"
output = "robot"
wheel_radius = 0.033
wheelbase = 0.16
duration = DURATION
diffusion = 1.0
speed = 1.0
turn_rate = TURN
dt = DT
"#;

/// The differential-drive integral took seconds to minutes at huge turn rates and
/// `duration/dt` up to 1e9 was accepted; both are refused up front with the limit.
#[test]
fn differential_drive_work_is_bounded_up_front() {
    let e = error(
        &DIFF_DRIVE
            .replace("DURATION", "1.0")
            .replace("TURN", "1e6")
            .replace("DT", "0.01"),
    );
    assert!(
        e.contains("operation[0].turn_rate") && e.contains("at most 1000 rad"),
        "{e}"
    );
    let e = error(
        &DIFF_DRIVE
            .replace("DURATION", "1000.0")
            .replace("TURN", "0.0")
            .replace("DT", "1e-6"),
    );
    assert!(
        e.contains("operation[0].dt") && e.contains("at most 100000"),
        "{e}"
    );
}

/// A covariance entry near f64::MAX became inf in ½(Σ + Σᵀ) and hung the drawing; now it is
/// an error at its line.
#[test]
fn a_covariance_near_the_largest_float_is_refused() {
    let text = POINT_OK.replace(
        "cov = { std = [0.1, 0.1, 0.1] }",
        "cov = { matrix = [[1.7e308, 0, 0], [0, 1.7e308, 0], [0, 0, 1]] }",
    );
    let e = error(&text);
    assert!(e.starts_with("case.toml:9:7: pose[0].cov:"), "{e}");
}
