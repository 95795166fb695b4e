//! The words come from the run: a bundled scenario's title and description state no number
//! that the run computes. Every decimal number and every percentage they contain must be an
//! input written elsewhere in the same file (a σ, a step length); anything the evaluation
//! produces is shown by the text panel from the evaluation itself, never typed by hand.

use posecov::input::scenario::bundled::BUNDLED;

/// The numbers of `text` a reader takes as results: decimals ("1.69") and percentages ("70 %").
fn stated_numbers(text: &str) -> Vec<String> {
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
        if number.contains('.') || rest.trim_start().starts_with('%') {
            out.push(number);
        }
        i = j;
    }
    out
}

#[test]
fn finds_decimals_and_percentages() {
    assert_eq!(
        stated_numbers("σ = 0.03 rad, 100 steps, ≈ 1.69 and 70 % (eq. 55), x_1.5"),
        vec!["0.03", "1.69", "70"]
    );
}

#[test]
fn bundled_descriptions_state_only_their_inputs() {
    let mut typed = Vec::new();
    for b in BUNDLED {
        let doc: toml::Table = toml::from_str(b.text).expect("bundled TOML parses");
        let scenario = doc["scenario"].as_table().expect("[scenario]");
        let words: String = ["title", "description"]
            .iter()
            .filter_map(|k| scenario.get(*k).and_then(|v| v.as_str()))
            .collect::<Vec<_>>()
            .join("\n");
        let description = scenario
            .get("description")
            .and_then(|v| v.as_str())
            .unwrap_or("");
        let title = scenario.get("title").and_then(|v| v.as_str()).unwrap_or("");
        let inputs = b.text.replace(description, "").replace(title, "");
        for number in stated_numbers(&words) {
            if !inputs.contains(&number) {
                typed.push(format!("{}: {number}", b.name));
            }
        }
    }
    assert!(
        typed.is_empty(),
        "bundled titles or descriptions state numbers that are not inputs of the file (the run \
         computes them: let the text panel show them from the evaluation): {typed:?}"
    );
}
