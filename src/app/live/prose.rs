//! The file's own words about its values, kept true while they are edited live. A title or
//! description types the inputs it speaks of ("σθ = 20°", "1.5 m ahead", "100 times"); the
//! numbers the run computes are placeholders already (`draw::words`). When a value is edited,
//! every number of the file's words that states it is restated with the new value: the page's
//! download and save, and the viewer's text, never keep a stale typed number.
//!
//! A number states a value when it is that value as [`trim`](super::document) writes it and is
//! followed by the value's unit (`20°`, `0.03 rad`, `1 ms` for 0.001 s), or, for a value
//! without a unit, stands after `=` or before a word (`D = 4`, `100 times`). When several
//! values of the file share that number and not all changed alike (roll and pitch σ = 2°, roll
//! now 3°), the number stays and the change is said beside it.

use super::controls::{Control, ControlKind};
use super::document::trim;

/// `raw`, the file's text of a title or description, with every number that states a value
/// edited from `file` to `now` restated (see the module docs).
///
/// ```ignore
/// restate("heading (σθ = 20°)", &file, &now) == "heading (σθ = 45°)"
/// ```
pub(super) fn restate(raw: &str, file: &[Control], now: &[Control]) -> String {
    let values: Vec<(&Control, f64, Option<f64>)> = file
        .iter()
        .filter(|c| c.id.starts_with("pose[") || c.id.starts_with("operation["))
        .filter_map(|c| {
            let ControlKind::Number { value, .. } = c.kind else {
                return None;
            };
            let new = now
                .iter()
                .find(|n| n.id == c.id)
                .and_then(|n| match n.kind {
                    ControlKind::Number { value: v, .. } if v != value => Some(v),
                    _ => None,
                });
            Some((c, value, new))
        })
        .collect();
    if values.iter().all(|(.., new)| new.is_none()) {
        return raw.to_owned();
    }
    let chars: Vec<char> = raw.chars().collect();
    let mut out = String::with_capacity(raw.len());
    let mut i = 0;
    let mut placeholder = false;
    while i < chars.len() {
        if chars[i..].starts_with(&['{', '{']) {
            placeholder = true;
        } else if chars[i..].starts_with(&['}', '}']) {
            placeholder = false;
        }
        let Some(end) = (!placeholder).then(|| number_at(&chars, i)).flatten() else {
            out.push(chars[i]);
            i += 1;
            continue;
        };
        let token: String = chars[i..end].iter().collect();
        let before: String = chars[i.saturating_sub(3)..i].iter().collect();
        let after: String = chars[end..chars.len().min(end + 8)].iter().collect();
        // Every value of the file this number may state, with the scale the words use.
        let stated: Vec<(&Control, f64, Option<f64>, f64, usize)> = values
            .iter()
            .filter_map(|&(c, value, new)| {
                let (scale, unit_len) = states(&token, &before, &after, value, c.unit)?;
                Some((c, value, new, scale, unit_len))
            })
            .collect();
        let unit_len = stated.first().map_or(0, |s| s.4);
        let news: Vec<Option<f64>> = stated.iter().map(|s| s.2.map(|v| v * s.3)).collect();
        let same_new = news.first().copied().flatten().filter(|first| {
            news.iter()
                .all(|n| n.is_some_and(|v| trim(v) == trim(*first)))
        });
        out.push_str(&match same_new {
            Some(v) => trim(v),
            None => token.clone(),
        });
        out.extend(&chars[end..end + unit_len]);
        if same_new.is_none() {
            let said: Vec<String> = stated
                .iter()
                .filter_map(|(c, _, new, ..)| {
                    new.map(|v| format!("{} {} = {}", c.section, c.label, with_unit(v, c.unit)))
                })
                .collect();
            if !said.is_empty() {
                out.push_str(&format!(" (changed live: {})", said.join("; ")));
            }
        }
        i = end + unit_len;
    }
    out
}

/// `v` and its unit as the words write them: `45°`, `1.75 m/s`, `4`.
fn with_unit(v: f64, unit: &str) -> String {
    match unit {
        "" | "°" => format!("{}{unit}", trim(v)),
        unit => format!("{} {unit}", trim(v)),
    }
}

/// The end of a number that starts at `i` (`20`, `0.033`, `-3`), if one does: not inside a
/// name (`x_1`, `T_MC`) nor a longer number.
fn number_at(chars: &[char], i: usize) -> Option<usize> {
    let boundary = |k: usize| {
        k == 0 || !(chars[k - 1].is_alphanumeric() || matches!(chars[k - 1], '_' | '.' | '-'))
    };
    let start_digit = match chars.get(i) {
        Some('-') => chars.get(i + 1).is_some_and(char::is_ascii_digit),
        Some(c) => c.is_ascii_digit(),
        None => false,
    };
    if !start_digit || !boundary(i) {
        return None;
    }
    let mut j = i + 1;
    while j < chars.len()
        && (chars[j].is_ascii_digit()
            || chars[j] == '.' && chars.get(j + 1).is_some_and(char::is_ascii_digit))
    {
        j += 1;
    }
    Some(j)
}

/// Whether `token` (with the text `before` and `after` it) states `value` in `unit`: the scale
/// the words use (1, or 1000 for seconds written in ms) and how many characters of `after` are
/// its unit (to keep them).
fn states(token: &str, before: &str, after: &str, value: f64, unit: &str) -> Option<(f64, usize)> {
    let gap = usize::from(after.starts_with([' ', '\u{a0}']));
    let rest = &after[after
        .char_indices()
        .nth(gap)
        .map_or(after.len(), |(k, _)| k)..];
    let ends_word = |s: &str| {
        s.chars()
            .next()
            .is_none_or(|c| !(c.is_alphanumeric() || matches!(c, '/' | '²' | '³')))
    };
    let with_unit = |unit: &str, scale: f64| {
        (trim(value * scale) == token && rest.starts_with(unit) && ends_word(&rest[unit.len()..]))
            .then(|| (scale, gap + unit.chars().count()))
    };
    match unit {
        "" => {
            // The word after it: a unit (`1 m/s`, `1 s`) means another value's number.
            let word: String = after
                .strip_prefix(' ')
                .map(|r| r.chars().take_while(|c| c.is_alphabetic()).collect())
                .unwrap_or_default();
            let words = word.chars().count();
            let unit_like = words > 0 && (words < 3 || word == "rad");
            let bare = !unit_like && (before.trim_end().ends_with('=') || words >= 3);
            (bare && trim(value) == token).then_some((1.0, 0))
        }
        "s" => with_unit("s", 1.0).or_else(|| with_unit("ms", 1000.0)),
        unit => with_unit(unit, 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn number(id: &str, section: &str, label: &str, unit: &'static str, value: f64) -> Control {
        Control {
            id: id.into(),
            section: section.into(),
            label: label.into(),
            unit,
            kind: ControlKind::Number {
                value,
                min: 0.0,
                max: 1.0,
                step: 0.1,
                integer: false,
            },
        }
    }

    #[test]
    fn an_edited_value_is_restated_where_the_words_type_it() {
        let file = [
            number("pose[0].cov.std_deg[2]", "pose r", "σ θ", "°", 20.0),
            number("operation[0].dt", "operation[0]", "dt", "s", 0.001),
            number("operation[0].steps", "operation[0]", "steps", "", 100.0),
        ];
        let mut now = file.clone();
        for (c, v) in now.iter_mut().zip([45.0, 0.002, 50.0]) {
            if let ControlKind::Number { value, .. } = &mut c.kind {
                *value = v;
            }
        }
        let raw = "heading (σθ = 20°), dt = 1 ms, 100 times, 20 m, Fig. 20, x_20°, {{coverage a 20°}}, 100 s";
        assert_eq!(
            restate(raw, &file, &now),
            "heading (σθ = 45°), dt = 2 ms, 50 times, 20 m, Fig. 20, x_20°, {{coverage a 20°}}, 100 s"
        );
        assert_eq!(restate(raw, &file, &file), raw);
    }

    #[test]
    fn a_number_two_values_share_says_the_change_beside_it() {
        let file = [
            number("pose[0].cov.std_deg[0]", "pose d", "σ roll", "°", 2.0),
            number("pose[0].cov.std_deg[1]", "pose d", "σ pitch", "°", 2.0),
        ];
        let mut now = file.clone();
        if let ControlKind::Number { value, .. } = &mut now[0].kind {
            *value = 3.0;
        }
        assert_eq!(
            restate("roll and pitch σ = 2°.", &file, &now),
            "roll and pitch σ = 2° (changed live: pose d σ roll = 3°)."
        );
    }
}
