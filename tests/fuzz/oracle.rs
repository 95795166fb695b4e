//! Oracles on a run's JSON report: no `null` where a number belongs, none where Monte Carlo
//! ran.

/// The first non-finite number of a JSON document, as serde_json writes it (`null`) where a
/// number belongs: any `null`, except under the keys in `optional` (values that may be
/// absent by design, such as a finding's `step` or a topic's stamps when it has no message;
/// their subtree is not looked at), and except at the whole paths in `optional` written with
/// `[#]` for indices (`.optimized.poses[#].covariance`: null there by design, checked when not).
pub fn json_null(v: &serde_json::Value, optional: &[&str]) -> Option<String> {
    let mut stack = vec![("".to_owned(), v)];
    while let Some((path, v)) = stack.pop() {
        match v {
            serde_json::Value::Null => return Some(path),
            serde_json::Value::Array(a) => stack.extend(
                a.iter()
                    .enumerate()
                    .map(|(i, x)| (format!("{path}[{i}]"), x)),
            ),
            serde_json::Value::Object(o) => stack.extend(
                o.iter()
                    .filter(|(k, _)| !optional.contains(&k.as_str()))
                    .map(|(k, x)| (format!("{path}.{k}"), x))
                    // A whole path (indices as `[#]`) may be null by design; its value is
                    // still checked when it is not.
                    .filter(|(p, x)| {
                        !(x.is_null() && optional.contains(&indices_hidden(p).as_str()))
                    }),
            ),
            _ => {}
        }
    }
    None
}

/// A JSON path with its array indices written `[#]`: `.a[3].b` → `.a[#].b`.
fn indices_hidden(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    let mut in_index = false;
    for c in path.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push_str("[#");
            }
            ']' => {
                in_index = false;
                out.push(']');
            }
            _ if in_index => {}
            _ => out.push(c),
        }
    }
    out
}

/// Results compared with a Monte Carlo run of the same label whose relative error is `null`
/// (where Monte Carlo ran, the error is a number).
pub fn null_error_where_monte_carlo_ran(report: &serde_json::Value) -> Option<String> {
    let ran: Vec<&str> = report["monte_carlo"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|r| r["label"].as_str())
        .collect();
    report["results"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|r| {
            r["relative_error_vs_monte_carlo"].is_null()
                && r["label"].as_str().is_some_and(|l| ran.contains(&l))
        })
        .map(|r| format!("{} ({})", r["label"], r["method"]))
}

// =========================================================================================
// The campaign: generate, run, classify, count, keep failing inputs.
// =========================================================================================
