//! TOML parse errors in the file's words: which key (`pose[2].mean`) and what was expected
//! ("a whole number ≥ 0"), never the names of Rust types.

/// The key path at byte `offset` of a scenario text: the table (`scenario`, `pose[2]`,
/// `operation[0].noise`, `draw`) and the key on that line, with the inner key of an inline
/// table (`pose[0].mean.xy_theta`); inside a value spanning several lines, the key it belongs
/// to. Where the text is too broken to say (a mangled header), `file`.
pub(crate) fn key_at(text: &str, offset: usize) -> String {
    let offset = offset.min(text.len());
    let mut table: Option<String> = Some(String::new());
    let mut last_key: Option<String> = None;
    let mut counts: Vec<(String, usize)> = Vec::new();
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let end = line_start + line.len();
        let trimmed = line.trim();
        let header = trimmed.starts_with('[');
        if header {
            table = header_path(trimmed, &mut counts);
            last_key = None;
        }
        let own_keys = if header {
            Vec::new()
        } else {
            keys_before(line, offset.saturating_sub(line_start).min(line.len()))
        };
        let at_target = offset < end || end == text.len();
        if at_target {
            let Some(table) = table else {
                return "file".to_owned();
            };
            let keys = match (own_keys.is_empty(), &last_key) {
                (false, _) => own_keys,
                (true, Some(k)) if !header && !starts_with_key(trimmed) => vec![k.clone()],
                _ => Vec::new(),
            };
            let mut parts: Vec<String> = Vec::new();
            if !table.is_empty() {
                parts.push(table);
            }
            parts.extend(keys);
            return if parts.is_empty() {
                "file".to_owned()
            } else {
                parts.join(".")
            };
        }
        if !header && starts_with_key(trimmed) {
            last_key = keys_before(line, line.len()).into_iter().next();
        }
        line_start = end;
    }
    "file".to_owned()
}

/// The table a header opens, `pose[2]` for the third `[[pose]]`, `pose[2].cov` for a
/// `[pose.cov]` below it; `None` for a header that is not a table name.
fn header_path(header: &str, counts: &mut Vec<(String, usize)>) -> Option<String> {
    let (array, inner) = match header.strip_prefix("[[") {
        Some(rest) => (true, rest.split_once("]]")?.0),
        None => (false, header.strip_prefix('[')?.split_once(']')?.0),
    };
    let segments: Vec<&str> = inner.split('.').map(str::trim).collect();
    let known = ["scenario", "pose", "operation", "draw"];
    if segments.iter().any(|s| !is_bare_key(s)) || !known.contains(&segments[0]) {
        return None;
    }
    let name = segments.join(".");
    if array {
        match counts.iter_mut().find(|(n, _)| *n == name) {
            Some((_, c)) => *c += 1,
            None => counts.push((name.clone(), 1)),
        }
    }
    let mut out: Vec<String> = Vec::new();
    for (k, seg) in segments.iter().enumerate() {
        let prefix = segments[..=k].join(".");
        match counts.iter().find(|(n, _)| *n == prefix) {
            Some((_, c)) => out.push(format!("{seg}[{}]", c - 1)),
            None => out.push((*seg).to_owned()),
        }
    }
    Some(out.join("."))
}

fn is_bare_key(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// Whether a line starts with `key =` (not the continuation of a value).
fn starts_with_key(line: &str) -> bool {
    line.split_once('=').is_some_and(|(k, _)| {
        k.trim()
            .split('.')
            .all(|s| is_bare_key(s.trim().trim_matches('"')))
    })
}

/// Keys assigned on `line` before byte `column`: the first one, and the last one inside an
/// inline table opened after it.
fn keys_before(line: &str, column: usize) -> Vec<String> {
    let before = line.get(..column).unwrap_or(line);
    let mut keys = Vec::new();
    let mut depth = 0usize;
    let mut current = String::new();
    let mut in_string: Option<char> = None;
    for c in before.chars() {
        match in_string {
            Some(q) if c == q => in_string = None,
            Some(_) => {}
            None => match c {
                '"' | '\'' => in_string = Some(c),
                '{' => {
                    depth += 1;
                    current.clear();
                }
                '}' => {
                    depth = depth.saturating_sub(1);
                    current.clear();
                }
                '=' => {
                    let key = current.trim().trim_matches('"').to_owned();
                    if key.split('.').all(is_bare_key) {
                        if keys.len() > depth {
                            keys.truncate(depth);
                        }
                        keys.push(key);
                    }
                    current.clear();
                }
                ',' | '[' | ']' => current.clear(),
                '#' => break,
                _ => current.push(c),
            },
        }
    }
    keys.truncate(2);
    keys
}

/// A toml/serde message with Rust type names replaced by what the file should contain.
pub(crate) fn in_file_words(message: &str) -> String {
    let suggested = with_suggestion(message.trim());
    let message = suggested.as_deref().unwrap_or(message.trim());
    // "invalid value: integer `-5`, expected u64" → "-5 is not a whole number ≥ 0"
    if let Some(rest) = message.strip_prefix("invalid value: integer `")
        && let Some((value, expected)) = rest.split_once("`, expected ")
    {
        return format!("{value} is not {}", type_words(expected));
    }
    if let Some(rest) = message.strip_prefix("invalid type: ")
        && let Some((found, expected)) = rest.split_once(", expected ")
    {
        return format!(
            "expected {}, found {}",
            type_words(expected),
            type_words(found)
        );
    }
    let mut out = message.to_owned();
    for (rust, words) in WORDS {
        out = out.replace(rust, words);
    }
    out
}

/// serde's "unknown field `stdd`, expected one of `std`, …" (or variant: a method, a group)
/// with the nearest accepted name: "unknown field `stdd`; did you mean `std`? expected one
/// of …". `None` when the message is not of that kind or no name is near.
fn with_suggestion(message: &str) -> Option<String> {
    let (what, rest) = ["unknown field `", "unknown variant `"]
        .iter()
        .find_map(|p| message.strip_prefix(p).map(|rest| (*p, rest)))?;
    let (word, rest) = rest.split_once('`')?;
    let expected = rest.split_once("expected")?.1;
    let candidates = expected.split('`').skip(1).step_by(2);
    let guess = crate::input::suggest::did_you_mean(word, candidates);
    (!guess.is_empty()).then(|| {
        format!(
            "{what}{word}`; {guess}{}",
            rest.trim_start_matches(',').trim_start()
        )
    })
}

/// Rust and serde type names, as a scenario file's author says them.
const WORDS: &[(&str, &str)] = &[
    (
        "struct MeanSpec",
        "a mean table such as { xy_theta = [x, y, θ] }",
    ),
    (
        "struct CovSpec",
        "a covariance table such as { std = [σ, …] }",
    ),
    ("struct PoseSpec", "a [[pose]] table"),
    ("struct OperationSpec", "an [[operation]] table"),
    ("struct DrawSpec", "a [draw] table"),
    ("struct Header", "a [scenario] table"),
    ("struct ScenarioFile", "a scenario file"),
    (
        "struct MethodsSpec",
        "a [methods] table of method parameters (the methods compared go in [scenario]: methods = [\"first_order\", …])",
    ),
    (
        "struct SigmaPointsSpec",
        "a [methods.sigma_points] table such as { alpha = 1, beta = 2, kappa = 0 }",
    ),
    (
        "struct CameraSpec",
        "a camera table such as { direction = [x, y, z] }",
    ),
    ("u64", "a whole number ≥ 0"),
    ("i64", "a whole number"),
    ("f64", "a number"),
    ("a sequence", "an array"),
    ("sequence", "array"),
    ("map", "table"),
    ("a boolean", "true or false"),
];

fn type_words(s: &str) -> String {
    let mut out = s.trim().to_owned();
    for (rust, words) in WORDS {
        if out == *rust {
            return (*words).to_owned();
        }
    }
    for (rust, words) in WORDS {
        out = out.replace(rust, words);
    }
    // A structure not listed above is still a table to the file, never a Rust type name.
    if let Some(rest) = out.strip_prefix("struct ")
        && rest.chars().all(|c| c.is_ascii_alphanumeric())
    {
        return "a table".to_owned();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_name_tables_and_inline_keys() {
        let text = "[scenario]\nsamples = -5\n[[pose]]\nname = 'a'\n[[pose]]\nmean = { xy_theta = [1, 2] }\n[pose.cov]\nstd = [\n 1,\n x]\n[[/bad]]\nk = 1\n";
        assert_eq!(key_at(text, text.find("-5").unwrap()), "scenario.samples");
        let at = text.find("[1, 2]").unwrap();
        assert_eq!(key_at(text, at), "pose[1].mean.xy_theta");
        assert_eq!(key_at(text, text.find("[[pose]]").unwrap()), "pose[0]");
        assert_eq!(key_at(text, text.find(" x]").unwrap()), "pose[1].cov.std");
        assert_eq!(key_at(text, text.find("k = 1").unwrap()), "file");
    }

    #[test]
    fn messages_speak_the_files_language() {
        assert_eq!(
            in_file_words("invalid value: integer `-5`, expected u64"),
            "-5 is not a whole number ≥ 0"
        );
        assert_eq!(
            in_file_words("invalid type: string \"x\", expected f64"),
            "expected a number, found string \"x\""
        );
        assert!(
            !in_file_words("invalid type: integer `3`, expected struct MeanSpec")
                .contains("struct")
        );
        // Found by the fuzz harness: `methods = [...]` above `[scenario]`.
        let e =
            in_file_words("invalid type: string \"first_order\", expected struct SigmaPointsSpec");
        assert!(
            e.starts_with("expected a [methods.sigma_points] table"),
            "{e}"
        );
        assert_eq!(
            in_file_words("invalid type: integer `3`, expected struct SomethingNew"),
            "expected a table, found integer `3`"
        );
    }

    #[test]
    fn unknown_names_get_the_nearest() {
        assert_eq!(
            in_file_words("unknown field `stdd`, expected one of `std`, `std_deg`, `matrix`"),
            "unknown field `stdd`; did you mean `std`? expected one of `std`, `std_deg`, `matrix`"
        );
        assert_eq!(
            in_file_words("unknown variant `first_ordr`, expected one of `exact`, `first_order`"),
            "unknown variant `first_ordr`; did you mean `first_order`? expected one of `exact`, `first_order`"
        );
        assert_eq!(
            in_file_words("unknown field `zzz`, expected `std`"),
            "unknown field `zzz`, expected `std`"
        );
    }
}
