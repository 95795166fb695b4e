//! Classification of one scenario run: where an error points and in whose words; what a
//! successful output contains (non-finite numbers, invalid scenes, indefinite covariances);
//! and what the input itself shows should have been refused (the oracles).

use std::collections::BTreeSet;

use nalgebra::SymmetricEigen;
use toml::{Table, Value};

use super::{Output, Reported, scene_nonfinite};
use crate::harness::{Finding, Limits, Run, finding, settle};
use posecov::eval::Finding as EvalFinding;

/// Words of an error message that speak Rust / serde rather than the file's vocabulary.
const RUST_SPEAK: &[&str] = &[
    "expected struct",
    "expected enum",
    "expected u64",
    "expected u32",
    "expected usize",
    "expected i64",
    "expected f64",
    "expected f32",
    "expected a sequence",
    "expected a map",
    "expected unit",
    "newtype",
    "Spanned",
    "tuple",
    "$__",
    "invalid type: map",
    "invalid type: sequence",
    "Option<",
    "Vec<",
];

/// Judges one run: the shared outcomes (panic, hang, slow, memory), then the error's place
/// and words, or the output's numbers and what the input should have been refused for.
pub fn classify(
    text: &str,
    origin: &str,
    run: Run<Result<Output, Reported>>,
    limits: &Limits,
) -> Vec<Finding> {
    let (result, mut findings) = match settle(run, limits) {
        Ok(x) => x,
        Err(ended) => return ended,
    };
    match result {
        Err(e) => findings.extend(check_error(text, origin, &e)),
        Ok(out) => findings.extend(check_output(text, &out)),
    }
    if findings.is_empty() {
        findings.push(finding("ok", String::new()));
    }
    findings
}

/// `origin:line:column: rest` → (line, column, rest).
fn split_location<'a>(first: &'a str, origin: &str) -> Option<(usize, usize, &'a str)> {
    let rest = first.strip_prefix(origin)?.strip_prefix(':')?;
    let (line, rest) = rest.split_once(':')?;
    let (column, rest) = rest.split_once(':')?;
    let rest = rest.strip_prefix(' ')?;
    Some((line.parse().ok()?, column.parse().ok()?, rest))
}

/// `scenario.x`, `pose[3].cov`, `operation[0].controls[2]`, `draw.axis_length`.
fn field_in_user_vocabulary(field: &str) -> bool {
    let seg_ok = |s: &str| {
        let (name, index) = match s.split_once('[') {
            Some((n, i)) => (n, Some(i)),
            None => (s, None),
        };
        !name.is_empty()
            // A key as the user typed it (bare-key characters), or one of ours.
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            && index.is_none_or(|i| {
                i.strip_suffix(']')
                    .is_some_and(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()))
            })
    };
    let mut segs = field.split('.');
    let head = segs.next().unwrap_or("");
    // `file`: the text is too broken to name a table (a mangled header, a bad top-level key).
    // A top-level key (where the text lost its table header) is named as the user wrote it.
    let head_ok = seg_ok(head);
    head_ok && segs.all(seg_ok)
}

fn check_error(text: &str, origin: &str, e: &Reported) -> Vec<Finding> {
    let f = finding;
    let first = e.text.lines().next().unwrap_or("");
    let mut out = Vec::new();
    let Some((line, column, rest)) = split_location(first, origin) else {
        return vec![f("error_unlocated", first.to_owned())];
    };
    let lines: Vec<&str> = text.split('\n').collect();
    let bad_location = line == 0
        || column == 0
        || line > lines.len()
        || column > lines[line - 1].chars().count() + 1;
    if bad_location {
        out.push(f("error_bad_location", first.to_owned()));
    }
    match e.field.as_deref() {
        Some("toml") => out.push(f("error_field_toml", rest.to_owned())),
        Some(field) if !field_in_user_vocabulary(field) => {
            out.push(f("error_field_unusual", rest.to_owned()))
        }
        _ => {}
    }
    if let Some(word) = RUST_SPEAK.iter().find(|w| rest.contains(*w)) {
        out.push(f("error_rust_speak", format!("[{word}] {rest}")));
    }
    if out.is_empty() {
        out.push(f("error_ok", first.to_owned()));
    }
    out
}

fn check_output(text: &str, out: &Output) -> Vec<Finding> {
    let f = finding;
    let mut found = Vec::new();
    // Numbers of the records (and what serde_json makes of them: NaN/inf become null).
    for (r, j) in out
        .records
        .iter()
        .zip(out.records_json.as_array().into_iter().flatten())
    {
        let mut nulls = Vec::new();
        for key in ["mean_matrix", "mean_tangent", "covariance"] {
            let mut stack = vec![&j[key]];
            while let Some(v) = stack.pop() {
                match v {
                    serde_json::Value::Array(a) => stack.extend(a),
                    serde_json::Value::Number(_) => {}
                    _ => {
                        nulls.push(key);
                        break;
                    }
                }
            }
        }
        if r.relative_error_vs_monte_carlo
            .is_some_and(|x| !x.is_finite())
        {
            nulls.push("relative_error_vs_monte_carlo");
        }
        if !nulls.is_empty() {
            found.push(f(
                "nonfinite_record",
                format!(
                    "{:?} record: {} non-finite (JSON null) — `{}`",
                    r.method,
                    nulls.join(", "),
                    r.label
                ),
            ));
        }
    }
    // Where Monte Carlo ran for a label, every other estimate of it has a relative error.
    for r in &out.records {
        let ran = out
            .records
            .iter()
            .any(|m| m.label == r.label && m.method == posecov::uncertain::Method::MonteCarlo);
        if ran && r.relative_error_vs_monte_carlo.is_none() {
            found.push(f(
                "nonfinite_record",
                format!(
                    "{:?} record: relative_error_vs_monte_carlo null where Monte Carlo ran",
                    r.method
                ),
            ));
        }
    }
    let mut stack = vec![&out.findings_json];
    while let Some(v) = stack.pop() {
        match v {
            serde_json::Value::Array(a) => stack.extend(a),
            // `step` is null for a result that is not per step; numbers are never null.
            serde_json::Value::Object(o) => {
                stack.extend(o.iter().filter(|(k, _)| *k != "step").map(|(_, v)| v))
            }
            serde_json::Value::Null => {
                found.push(f(
                    "nonfinite_record",
                    "a finding has a non-finite number (JSON null)".to_owned(),
                ));
                break;
            }
            _ => {}
        }
    }
    for (path, field, v) in scene_nonfinite(&out.scene).into_iter().take(3) {
        found.push(f(
            "nonfinite_scene",
            format!("{} {field} = {v}", normalise_path(&path)),
        ));
    }
    if let Err(e) = &out.scene_valid {
        found.push(f("scene_invalid", e.clone()));
    }
    // Covariances: symmetric and positive semi-definite.
    for (label, m) in &out.covariances {
        if m.iter().any(|v| !v.is_finite()) {
            continue; // reported as non-finite
        }
        let scale = m.amax();
        let asym = (m - m.transpose()).amax();
        if asym > 1e-9 * scale.max(1e-300) {
            found.push(f(
                "asymmetric_cov",
                format!(
                    "{}: |Σ − Σᵀ| = {asym:.3e} of max |Σ| = {scale:.3e}",
                    method_of(label)
                ),
            ));
        }
        let eig = SymmetricEigen::new((m + m.transpose()) * 0.5);
        let max = eig.eigenvalues.amax();
        let min = eig.eigenvalues.min();
        if min < -1e-9 * max && !reported_indefinite(&out.findings, label) {
            found.push(f(
                "non_psd",
                format!(
                    "{} covariance is indefinite: λmin = {min:.3e}, max |λ| = {max:.3e} — `{label}`",
                    method_of(label)
                ),
            ));
        }
    }
    found.extend(input_oracles(text));
    found
}

/// Whether the evaluation reported the covariance labelled `name[@step] (Method)` as not
/// positive semi-definite (reported, not hidden, is what is required).
fn reported_indefinite(findings: &[EvalFinding], label: &str) -> bool {
    let (name_step, _) = label.rsplit_once(" (").unwrap_or((label, ""));
    let (name, step) = match name_step.split_once('@') {
        Some((n, k)) => (n, k.parse::<u64>().ok()),
        None => (name_step, None),
    };
    findings.iter().any(|f| {
        // One finding per output and method: its first step, and a count of later ones.
        matches!(f, EvalFinding::NotPositiveSemiDefinite { output, step: s, method, later_steps, .. }
            if output == name
                && (*s == step || (*later_steps > 0 && *s < step))
                && format!("{method:?}") == method_of(label))
    })
}

/// The `(Method)` part of a covariance label.
fn method_of(label: &str) -> &str {
    label
        .rsplit_once('(')
        .map_or(label, |(_, m)| m.trim_end_matches(')'))
}

/// `world/robot/first_order/banana` → `world/*/first_order/banana` (dedup by what, not where).
fn normalise_path(p: &str) -> String {
    let segs: Vec<&str> = p.split('/').collect();
    if segs.len() > 2 {
        let mut s = segs.clone();
        s[1] = "*";
        s.join("/")
    } else {
        p.to_owned()
    }
}

/// What a successful evaluation should have rejected, judged from the TOML itself.
fn input_oracles(text: &str) -> Vec<Finding> {
    let f = finding;
    let Ok(doc) = toml::from_str::<Table>(text) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    let mut defined: BTreeSet<String> = BTreeSet::new();
    let mut points: BTreeSet<String> = BTreeSet::new();
    for p in doc
        .get("pose")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        if let Some(n) = p.get("name").and_then(Value::as_str) {
            defined.insert(n.to_owned());
        }
    }
    for op in doc
        .get("operation")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        let kind = op.get("kind").and_then(Value::as_str).unwrap_or("?");
        let mut refs: Vec<(&str, &str)> = Vec::new();
        for key in ["input", "lhs", "rhs", "by"] {
            if let Some(s) = op.get(key).and_then(Value::as_str) {
                refs.push((key, s));
            }
        }
        for v in op
            .get("inputs")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if let Some(s) = v.as_str() {
                refs.push(("inputs", s));
            }
        }
        for (key, name) in refs {
            if points.contains(name) {
                found.push(f(
                    "accepted_point_as_pose",
                    format!("`{kind}`.{key} names a point_through_pose output; accepted as a pose"),
                ));
            } else if !defined.contains(name) {
                found.push(f(
                    "accepted_unknown_name",
                    format!("`{kind}`.{key} names an undefined pose; accepted"),
                ));
            }
        }
        if let Some(o) = op.get("output").and_then(Value::as_str) {
            defined.insert(o.to_owned());
            if kind == "point_through_pose" {
                points.insert(o.to_owned());
            }
        }
    }
    found.extend(length_oracles(&doc));
    // One uncertain pose on both sides of `compose` / `between` is one draw, not two.
    let known: BTreeSet<&str> = doc
        .get("pose")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter(|p| p.get("cov").is_none())
        .filter_map(|p| p.get("name").and_then(Value::as_str))
        .collect();
    for op in doc
        .get("operation")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        let kind = op.get("kind").and_then(Value::as_str).unwrap_or("?");
        let (lhs, rhs) = (op.get("lhs"), op.get("rhs"));
        if ["compose", "between"].contains(&kind)
            && op.get("cross_cov").is_none()
            && let (Some(Value::String(a)), Some(Value::String(b))) = (lhs, rhs)
            && a == b
            && !known.contains(a.as_str())
        {
            found.push(f(
                "accepted_invalid_value",
                format!("`{kind}` of one uncertain pose with itself accepted as independent"),
            ));
        }
    }
    if let Some(v) = doc.get("draw").and_then(|d| d.get("axis_length")) {
        let x = v.as_float().or(v.as_integer().map(|i| i as f64));
        if x.is_some_and(|x| !(x.is_finite() && x > 0.0)) {
            found.push(f(
                "accepted_invalid_value",
                format!("draw.axis_length = {} accepted", x.unwrap()),
            ));
        }
    }
    found
}

/// Fixed-length arrays given another length (more numbers were once cut short without a
/// word), and camera coordinates beyond ±1e9 m, must be refused.
fn length_oracles(doc: &Table) -> Vec<Finding> {
    const FIXED: [(&str, usize); 7] = [
        ("xy_theta", 3),
        ("xy_theta_deg", 3),
        ("xyz", 3),
        ("rpy", 3),
        ("rpy_deg", 3),
        ("quaternion_xyzw", 4),
        ("axis_angle", 4),
    ];
    let mut found = Vec::new();
    let mut check = |table: Option<&Value>, keys: &[(&str, usize)], bound: Option<f64>| {
        for (key, len) in keys {
            let Some(Value::Array(a)) = table.and_then(|t| t.get(*key)) else {
                continue;
            };
            if a.len() != *len {
                found.push(finding(
                    "accepted_invalid_value",
                    format!("{key} of {} numbers accepted (expects {len})", a.len()),
                ));
            }
            let number = |v: &Value| v.as_float().or(v.as_integer().map(|i| i as f64));
            if let Some(bound) = bound
                && a.iter().filter_map(number).any(|x| x.abs() > bound)
            {
                found.push(finding(
                    "accepted_invalid_value",
                    format!("camera {key} beyond ±{bound:e} accepted"),
                ));
            }
        }
    };
    for p in doc
        .get("pose")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        check(p.get("mean"), &FIXED, None);
    }
    let camera = doc.get("draw").and_then(|d| d.get("camera"));
    let camera_keys = [("position", 3), ("direction", 3), ("target", 3), ("up", 3)];
    check(camera, &camera_keys, Some(1e9));
    found
}
