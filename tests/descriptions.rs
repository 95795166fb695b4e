//! The words come from the run: a bundled scenario's title and description state no number
//! that the run computes. Every decimal number and every percentage they type must be an
//! input written elsewhere in the same file (a σ, a step length); anything the evaluation
//! produces is named by a placeholder (`{{coverage map_from_camera exact cartesian}}`, see
//! `draw::words`) and written from this run's evaluation. The filled numbers are the ones
//! `report --json` gives.

use posecov::app::{Overrides, load, pipeline, report_json};
use posecov::input::scenario::bundled::BUNDLED;
use serde_json::Value;

/// The numbers of `text` a reader takes as results: decimals ("1.69"), percentages ("70 %")
/// and anything said to be approximate ("≈ 2", "about 3"). Placeholders are not numbers.
fn stated_numbers(text: &str) -> Vec<String> {
    let text = without_placeholders(text);
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit()
            && (i == 0
                || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_' || chars[i - 1] == '.'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
            j += 1;
        }
        let number: String = chars[i..j]
            .iter()
            .collect::<String>()
            .trim_end_matches('.')
            .to_owned();
        let rest: String = chars[j..chars.len().min(j + 2)].iter().collect();
        let before: String = chars[i.saturating_sub(6)..i].iter().collect();
        let approximate = before.trim_end().ends_with('≈') || before.trim_end().ends_with("about");
        if number.contains('.') || rest.trim_start().starts_with('%') || approximate {
            out.push(number);
        }
        i = j;
    }
    out
}

/// `text` without its `{{…}}` placeholders.
fn without_placeholders(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let (Some(a), Some(b)) = (rest.find("{{"), rest.find("}}")) {
        if b < a {
            break;
        }
        out.push_str(&rest[..a]);
        rest = &rest[b + 2..];
    }
    out.push_str(rest);
    out
}

#[test]
fn finds_decimals_percentages_and_approximations() {
    assert_eq!(
        stated_numbers(
            "σ = 0.03 rad, 100 steps, ≈ 1.69 and 70 % (eq. 55), x_1.5, ≈ 2, about 3, {{coverage a exact tangent}}"
        ),
        vec!["0.03", "1.69", "70", "2", "3"]
    );
}

/// A bundled scenario's title and description, joined.
fn words(text: &str) -> (String, String, String) {
    let doc: toml::Table = toml::from_str(text).expect("bundled TOML parses");
    let scenario = doc["scenario"].as_table().expect("[scenario]");
    let get = |k: &str| {
        scenario
            .get(k)
            .and_then(|v| v.as_str())
            .unwrap_or("")
            .to_owned()
    };
    let (title, description) = (get("title"), get("description"));
    (format!("{title}\n{description}"), title, description)
}

#[test]
fn bundled_descriptions_state_only_their_inputs() {
    let mut typed = Vec::new();
    for b in BUNDLED {
        let (words, title, description) = words(b.text);
        let inputs = b.text.replace(&description, "").replace(&title, "");
        for number in stated_numbers(&words) {
            if !inputs.contains(&number) {
                typed.push(format!("{}: {number}", b.name));
            }
        }
    }
    assert!(
        typed.is_empty(),
        "bundled titles or descriptions state numbers that are not inputs of the file (the run \
         computes them: name them with a placeholder, which the run fills): {typed:?}"
    );
}

/// `value ± stderr` as the text writes it: the standard error to one significant digit, the
/// value to one decimal beyond it (written independently of the crate's formatter).
fn plus_minus(value: f64, stderr: f64) -> String {
    // The fewest decimals at which the error shows a non-zero digit once rounded (0.0987 → 0.1).
    let decimals = (0..12)
        .find(|&d| stderr * 10f64.powi(d) >= 0.95)
        .unwrap_or(12) as usize;
    format!("{value:.0$} ± {stderr:.1$}", decimals + 1, decimals)
}

/// The scene's text panel and the report of a bundled scenario at `samples`.
fn run(name: &str, samples: u64) -> (String, Value) {
    let loaded = load(name).unwrap();
    let overrides = Overrides {
        samples: Some(samples),
        ..Default::default()
    };
    let (evaluation, scene) = pipeline(&loaded, &overrides, None).unwrap();
    let report = report_json(
        name,
        &loaded,
        &evaluation,
        posecov::uncertain::Confidence::DEFAULT,
    );
    (scene.description_markdown, report)
}

#[test]
fn every_placeholder_of_a_bundled_scenario_is_filled_by_its_run() {
    for b in BUNDLED {
        let (words, ..) = words(b.text);
        if !words.contains("{{") {
            continue;
        }
        let (text, _) = run(b.name, 400);
        for unfilled in [
            "{{",
            "}}",
            "(unknown placeholder",
            "(not computed in this run)",
        ] {
            assert!(
                !text.contains(unfilled),
                "{}: {unfilled} in\n{text}",
                b.name
            );
        }
    }
}

#[test]
fn camera_on_robot_states_the_coverage_report_json_gives() {
    let (text, report) = run("camera_on_robot", 4000);
    let result = report["results"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["label"] == "map_from_camera" && r["method"] == "exact")
        .expect("map_from_camera's exact result");
    let coverage = |region: &str| {
        let c = result["coverage"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["region"] == region)
            .unwrap();
        let (inside, stderr) = (c["inside"].as_f64().unwrap(), c["stderr"].as_f64().unwrap());
        format!("{} %", plus_minus(100.0 * inside, 100.0 * stderr))
    };
    let (banana, ellipse) = (coverage("tangent"), coverage("cartesian"));
    let sentence = format!(
        "holds\n{banana} of this run's 4000 cameras, the Cartesian\nellipse only {ellipse},"
    );
    assert!(text.contains(&sentence), "{sentence:?} not in\n{text}");
    // The lecture's point, as numbers: the banana holds about what it claims, the ellipse far less.
    assert!(
        ellipse.starts_with('6') || ellipse.starts_with('7'),
        "{ellipse}"
    );
}

#[test]
fn barfoot_states_the_along_track_variances_report_json_gives() {
    let (text, report) = run("barfoot_compounding", 2000);
    let last: Vec<&Value> = report["along_track"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["step"] == 100)
        .collect();
    let of = |method: &str| *last.iter().find(|a| a["method"] == method).unwrap();
    let mc = of("monte_carlo");
    let stderr = mc["stderr_m2"]
        .as_f64()
        .expect("Monte Carlo's standard error");
    assert!(stderr > 0.0 && stderr < 0.5 * mc["variance_m2"].as_f64().unwrap());
    let monte_carlo = format!(
        "{} m²",
        plus_minus(mc["variance_m2"].as_f64().unwrap(), stderr)
    );
    assert!(
        text.contains(&format!("Monte Carlo\n{monte_carlo}")),
        "{monte_carlo} not in\n{text}"
    );
    for method in ["second_order", "fourth_order"] {
        let v = format!("{:.4} m²", of(method)["variance_m2"].as_f64().unwrap());
        assert!(text.contains(&v), "{method}: {v} not in\n{text}");
        assert!(
            of(method).get("stderr_m2").is_none(),
            "an analytic value has no standard error"
        );
    }
}
