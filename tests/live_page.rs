//! The live page's choices and words (issue 22): it offers only the methods that apply to the
//! scenario, refuses a cleared field or NaN naming the field, and the scenario it downloads
//! (or saves) states the edited values in its own prose — no stale typed number.

use posecov::app::live::{ControlKind, Edit, EditError, EditValue, LiveDocument};
use posecov::app::load_text;
use posecov::input::scenario::bundled::BUNDLED;

fn methods(live: &LiveDocument) -> Vec<String> {
    live.controls()
        .into_iter()
        .filter_map(|c| c.id.strip_prefix("scenario.methods.").map(str::to_owned))
        .collect()
}

#[test]
fn only_the_methods_that_apply_are_offered() {
    let mut camera = LiveDocument::open("camera_on_robot").unwrap();
    let offered = methods(&camera);
    for m in ["sigma_points", "vector_space", "monte_carlo"] {
        assert!(offered.iter().any(|o| o == m), "{m} not in {offered:?}");
    }
    for m in [
        "closed_form",
        "numeric_integral",
        "second_order",
        "fourth_order",
        "lecture_no_jr",
    ] {
        assert!(!offered.iter().any(|o| o == m), "{m} in {offered:?}");
    }
    let e = camera
        .apply(&Edit {
            id: "scenario.methods.closed_form".into(),
            value: EditValue::Toggle(true),
        })
        .unwrap_err();
    assert!(matches!(e, EditError::Unknown { .. }), "{e}");

    let banana = methods(&LiveDocument::open("diff_drive_banana").unwrap());
    assert!(
        banana.contains(&"closed_form".into()) && banana.contains(&"numeric_integral".into()),
        "{banana:?}"
    );
    assert!(!banana.contains(&"fourth_order".into()), "{banana:?}");
    let barfoot = methods(&LiveDocument::open("barfoot_compounding").unwrap());
    assert!(
        barfoot.contains(&"second_order".into()) && barfoot.contains(&"fourth_order".into()),
        "{barfoot:?}"
    );
    assert!(!barfoot.contains(&"closed_form".into()), "{barfoot:?}");
}

#[test]
fn a_cleared_field_or_nan_is_refused_naming_the_field() {
    let mut live = LiveDocument::open("camera_on_robot").unwrap();
    let before = live.text();
    // As the page sends them: a cleared field is null, NaN a string (JSON has none).
    for (body, words) in [
        (
            r#"{"id": "pose[0].cov.std_deg[2]", "value": null}"#,
            "is empty: type a number",
        ),
        (
            r#"{"id": "pose[0].cov.std_deg[2]", "value": "NaN"}"#,
            "NaN is not a number",
        ),
        (
            r#"{"id": "pose[0].cov.std_deg[2]", "value": ""}"#,
            "is empty: type a number",
        ),
    ] {
        let edit: Edit = serde_json::from_str(body).unwrap();
        let e = live.apply(&edit).unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("pose[0].cov.std_deg[2]: pose map_from_robot σ θ")
                && text.contains(words),
            "{body}: {text}"
        );
        assert!(
            !text.contains("EditValue") && !text.contains("untagged"),
            "{text}"
        );
        assert_eq!(e.field().as_deref(), Some("pose[0].cov.std_deg[2]"));
    }
    assert_eq!(live.text(), before);
}

#[test]
fn the_downloaded_scenario_states_the_edited_heading_sigma() {
    let mut live = LiveDocument::open("camera_on_robot").unwrap();
    live.apply(&Edit {
        id: "pose[0].cov.std_deg[2]".into(),
        value: EditValue::Number(45.0),
    })
    .unwrap();
    let text = live.text();
    assert!(text.contains("(σθ = 45°)"), "{text}");
    assert!(!text.contains("20°"), "{text}");
    // Still the file's layout and comments, and a file `check` accepts.
    assert!(text.contains("std_deg = [0.05, 0.05, 45.0] }   # x, y in metres"));
    assert!(
        text.contains("description = \"\"\"\nThe robot's pose"),
        "{text}"
    );
    let loaded = load_text(&text, "download.toml").unwrap();
    assert!(loaded.input.about.description.contains("(σθ = 45°)"));
    // The viewer's text says it too.
    assert!(live.loaded().input.about.description.contains("(σθ = 45°)"));
    // Back to the file's value: the file's words again.
    live.apply(&Edit {
        id: "pose[0].cov.std_deg[2]".into(),
        value: EditValue::Number(20.0),
    })
    .unwrap();
    assert_eq!(
        live.text(),
        posecov::input::scenario::bundled::find("camera_on_robot")
            .unwrap()
            .text
    );
}

/// Whether `words` state `number` in `unit` (`20°`, `0.03 rad`) at a number's start.
fn states(words: &str, number: &str, unit: &str) -> bool {
    words.match_indices(number).any(|(k, _)| {
        let before = words[..k].chars().next_back();
        let after = words[k + number.len()..].trim_start_matches(' ');
        before.is_none_or(|c| !(c.is_alphanumeric() || matches!(c, '.' | '_' | '-')))
            && after.starts_with(unit)
            && after[unit.len()..]
                .chars()
                .next()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '/'))
    })
}

fn words(text: &str) -> String {
    let doc: toml::Table = toml::from_str(text).unwrap();
    let s = doc["scenario"].as_table().unwrap();
    let get = |k: &str| s.get(k).and_then(|v| v.as_str()).unwrap_or("").to_owned();
    format!("{}\n{}", get("title"), get("description"))
}

/// `x` as live mode writes it in words (six significant digits, no trailing zeros).
fn written(x: f64) -> String {
    let s = format!("{x:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

#[test]
fn every_value_a_bundled_description_states_is_restated_when_edited() {
    let mut restated = 0;
    for b in BUNDLED {
        let file_words = words(b.text);
        let mut live = LiveDocument::open(b.name).unwrap();
        let controls = live.controls();
        for c in &controls {
            let ControlKind::Number { value, integer, .. } = c.kind else {
                continue;
            };
            let shared = controls.iter().any(|o| {
                o.id != c.id
                    && o.unit == c.unit
                    && matches!(o.kind, ControlKind::Number { value: v, .. } if written(v) == written(value))
            });
            let leaf = c.id.starts_with("pose[") || c.id.starts_with("operation[");
            if !leaf || c.unit.is_empty() || shared || !states(&file_words, &written(value), c.unit)
            {
                continue;
            }
            let new = if integer {
                value + 1.0
            } else {
                value * 1.25 + 0.5
            };
            if live
                .apply(&Edit {
                    id: c.id.clone(),
                    value: EditValue::Number(new),
                })
                .is_err()
            {
                continue;
            }
            let now = words(&live.text());
            assert!(
                !states(&now, &written(value), c.unit) && states(&now, &written(new), c.unit),
                "{}: {} {} = {}{} edited to {}: the words still say\n{now}",
                b.name,
                c.section,
                c.label,
                written(value),
                c.unit,
                written(new)
            );
            restated += 1;
            live.apply(&Edit {
                id: c.id.clone(),
                value: EditValue::Number(value),
            })
            .unwrap();
            assert_eq!(
                words(&live.text()),
                file_words,
                "{}: back to the file's words",
                b.name
            );
        }
    }
    assert!(restated >= 5, "only {restated} stated values found");
}
