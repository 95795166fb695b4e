//! Every way a scenario file can be wrong gets a message naming file:line:column, the field
//! and the offending value.

use posecov::app::{Overrides, load_text, pipeline};
use posecov::input::scenario::{Scenario, ScenarioError};

const GOOD: &str = r#"[scenario]
title = "t"
group = "se2"
methods = ["first_order"]

[[pose]]
name = "map_from_robot"
mean = { xy_theta = [1.0, 0.0, 0.0] }
cov = { std = [0.1, 0.1, 0.2] }

[[operation]]
kind = "inverse"
input = "map_from_robot"
output = "robot_from_map"
"#;

/// Few samples: errors come from reading, lowering and evaluating, not from the sample size.
fn small() -> Overrides {
    Overrides {
        samples: Some(50),
        ..Default::default()
    }
}

/// Parses and evaluates; returns the error's text (panics if there is none).
fn error_of(text: &str) -> String {
    let result = load_text(text, "bad.toml")
        .and_then(|loaded| pipeline(&loaded, &small(), None).map(|_| ()));
    match result {
        Ok(()) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{needle} not in text"))
}

#[test]
fn the_good_file_is_good() {
    let loaded = load_text(GOOD, "good.toml").unwrap();
    assert!(pipeline(&loaded, &small(), None).is_ok());
}

#[test]
fn missing_file() {
    let e = Scenario::load(std::path::Path::new("/definitely/not/here.toml")).unwrap_err();
    assert!(matches!(e, ScenarioError::Read { .. }));
    assert!(
        e.to_string()
            .starts_with("/definitely/not/here.toml: cannot read input:"),
        "{e}"
    );
}

#[test]
fn bad_toml_syntax() {
    let text = GOOD.replace("title = \"t\"", "title = \"t");
    let e = error_of(&text);
    assert!(e.starts_with("bad.toml:2:"), "{e}");
}

#[test]
fn unknown_key_lists_the_valid_ones() {
    let text = GOOD.replace("cov = {", "covariance = {");
    let e = error_of(&text);
    assert!(
        e.starts_with(&format!("bad.toml:{}:", line_of(&text, "covariance"))),
        "{e}"
    );
    assert!(
        e.contains("unknown field `covariance`") && e.contains("`cov`") && e.contains("`mean`"),
        "{e}"
    );
}

#[test]
fn non_psd_covariance() {
    let text = GOOD.replace(
        "cov = { std = [0.1, 0.1, 0.2] }",
        "cov = { matrix = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }",
    );
    let e = error_of(&text);
    assert!(
        e.starts_with(&format!("bad.toml:{}:", line_of(&text, "matrix ="))),
        "{e}"
    );
    assert!(
        e.contains("pose[0].cov") && e.contains("not positive semi-definite") && e.contains("-1.0"),
        "{e}"
    );
}

#[test]
fn asymmetric_covariance_names_the_entries() {
    let text = GOOD.replace(
        "cov = { std = [0.1, 0.1, 0.2] }",
        "cov = { matrix = [[1.0, 0.5, 0.0], [0.4, 1.0, 0.0], [0.0, 0.0, 1.0]] }",
    );
    let e = error_of(&text);
    assert!(
        e.contains("not symmetric") && e.contains("(0, 1) = 0.5") && e.contains("(1, 0) = 0.4"),
        "{e}"
    );
}

#[test]
fn wrong_length() {
    let e = error_of(&GOOD.replace("std = [0.1, 0.1, 0.2]", "std = [0.1, 0.1]"));
    assert!(
        e.contains("pose[0].cov") && e.contains("std needs 3 numbers") && e.contains("got 2"),
        "{e}"
    );
    let e = error_of(&GOOD.replace("xy_theta = [1.0, 0.0, 0.0]", "xy_theta = [1.0, 0.0]"));
    assert!(e.contains("bad.toml:8:"), "{e}");
}

#[test]
fn nan_is_rejected_with_its_place() {
    let text = GOOD.replace("std = [0.1, 0.1, 0.2]", "std = [0.1, nan, 0.2]");
    let e = error_of(&text);
    assert!(
        e.starts_with(&format!("bad.toml:{}:", line_of(&text, "nan"))),
        "{e}"
    );
    assert!(e.contains("std[1] is NaN"), "{e}");
}

#[test]
fn unknown_operation_lists_the_kinds() {
    let text = GOOD.replace("kind = \"inverse\"", "kind = \"invert\"");
    let e = error_of(&text);
    assert!(
        e.starts_with(&format!("bad.toml:{}:", line_of(&text, "invert"))),
        "{e}"
    );
    assert!(
        e.contains("unknown operation `invert`") && e.contains("inverse") && e.contains("compose"),
        "{e}"
    );
}

#[test]
fn unknown_pose_name_lists_the_known_ones() {
    let e = error_of(&GOOD.replace("input = \"map_from_robot\"", "input = \"map_from_robo\""));
    assert!(
        e.contains("no pose named `map_from_robo`") && e.contains("map_from_robot"),
        "{e}"
    );
}

#[test]
fn keys_that_do_not_belong_to_the_operation() {
    let e = error_of(&GOOD.replace(
        "output = \"robot_from_map\"",
        "output = \"robot_from_map\"\nsteps = 3",
    ));
    assert!(e.contains("`steps` does not apply to `inverse`"), "{e}");
}

#[test]
fn group_mismatched_mean_and_bad_values() {
    let e = error_of(&GOOD.replace("xy_theta = [1.0, 0.0, 0.0]", "xyz = [1.0, 0.0, 0.0]"));
    assert!(
        e.contains("`xyz` does not describe an element of SE(2)"),
        "{e}"
    );
    let e = error_of(&GOOD.replace(
        "methods = [\"first_order\"]",
        "methods = [\"first_order\"]\nconfidence = 1.5",
    ));
    assert!(
        e.contains("scenario.confidence") && e.contains("1.5"),
        "{e}"
    );
    let e = error_of(&GOOD.replace("methods = [\"first_order\"]", "methods = [\"fifth_order\"]"));
    assert!(e.contains("unknown variant `fifth_order`"), "{e}");
    let e = error_of(&GOOD.replace("std = [0.1, 0.1, 0.2]", "std = [0.1, -0.1, 0.2]"));
    assert!(e.contains("std[1] = -0.1 is negative"), "{e}");
}

#[test]
fn quaternions_and_matrices_are_validated_in_files() {
    let se3 = r#"[scenario]
title = "t"
group = "se3"
[[pose]]
name = "a"
mean = { xyz = [0, 0, 0], quaternion_xyzw = [0, 0, 0, 2] }
"#;
    let e = error_of(se3);
    assert!(
        e.starts_with("bad.toml:6:") && e.contains("norm 2.000000"),
        "{e}"
    );
    let e = error_of(&se3.replace(
        "mean = { xyz = [0, 0, 0], quaternion_xyzw = [0, 0, 0, 2] }",
        "mean = { matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]] }",
    ));
    assert!(e.contains("reflection"), "{e}");
}
