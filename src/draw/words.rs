//! Numbers in a scenario's own words, filled from the run: a title or description never types
//! a number the evaluation computes; it names it with a placeholder, and drawing writes this
//! run's value in its place (the text panel, the figure's title). The one mechanism:
//!
//! | placeholder | becomes |
//! |---|---|
//! | `{{confidence}}` | the confidence the regions are drawn at: `95 %` |
//! | `{{samples}}` | the Monte Carlo samples: `4000` |
//! | `{{coverage OUTPUT METHOD REGION}}` | the share of OUTPUT's Monte Carlo samples inside METHOD's REGION (`tangent`, `tangent_position`, `cartesian`, `vector_space`) at its last step, with its binomial standard error: `70.1 ± 0.7 %` |
//! | `{{anees OUTPUT METHOD}}` | the ANEES of OUTPUT's samples under METHOD's Gaussian: `3.02` |
//! | `{{cartesian_mean OUTPUT}}` | the Cartesian mean of OUTPUT's Monte Carlo sample positions (where the operation computes it: `diff_drive`), each coordinate with its batch-means standard error: `(0.95 ± 0.003, 0.000 ± 0.004) m` |
//! | `{{along_track OUTPUT METHOD}}` | Σ_ρxρx (world, left form) of a compounding's last step; Monte Carlo's with its batch-means standard error: `1.88 ± 0.1 m²` |
//!
//! METHOD is a method's name as in `methods = [...]` (`first_order`, `monte_carlo`, …, and
//! `exact` for a result that needs no approximation). A value this run did not compute (Monte
//! Carlo off, another method list) reads "(not computed in this run)"; a placeholder that is
//! not one of these reads "(unknown placeholder …)", so the text never states a stale number.

use crate::eval::{Evaluation, Node};
use crate::lie::LieGroup;
use crate::uncertain::{Confidence, Method, Region};

/// What stands where a value this run did not compute would be.
pub const NOT_COMPUTED: &str = "(not computed in this run)";

/// `value ± stderr`: the standard error to one significant digit, the value to one decimal
/// beyond it (the reader sees how far the last digits are to be trusted); the value alone to
/// `digits` decimals when there is no standard error (1.883, 0.0987 → "1.88 ± 0.1").
pub(super) fn plus_minus(value: f64, stderr: Option<f64>, digits: usize) -> String {
    match stderr.filter(|s| s.is_finite() && *s > 0.0) {
        None => format!("{value:.digits$}"),
        Some(s) => {
            // Decimals that keep one significant digit of s (after rounding: 0.098 → 0.1).
            let mut decimals = (-s.log10().floor()).max(0.0) as usize;
            let rounded = (s * 10f64.powi(decimals as i32)).round();
            if rounded >= 10.0 && decimals > 0 {
                decimals -= 1;
            }
            let value_decimals = decimals + 1;
            format!("{value:.value_decimals$} ± {s:.decimals$}")
        }
    }
}

/// `text` with every placeholder replaced by this run's value.
pub(super) fn fill<G: LieGroup<N>, const N: usize>(
    text: &str,
    e: &Evaluation<G, N>,
    confidence: Confidence,
) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find("{{") {
        let Some(len) = rest[start..].find("}}") else {
            break;
        };
        out.push_str(&rest[..start]);
        let inner = &rest[start + 2..start + len];
        out.push_str(&value(inner, e, confidence));
        rest = &rest[start + len + 2..];
    }
    out.push_str(rest);
    out
}

/// The words of one placeholder's value.
fn value<G: LieGroup<N>, const N: usize>(
    placeholder: &str,
    e: &Evaluation<G, N>,
    confidence: Confidence,
) -> String {
    let words: Vec<&str> = placeholder.split_whitespace().collect();
    let method = |slug: &str| Method::ALL.iter().copied().find(|m| m.slug() == slug);
    let region = |name: &str| {
        [
            Region::Tangent,
            Region::TangentPosition,
            Region::Cartesian,
            Region::VectorSpace,
        ]
        .into_iter()
        .find(|r| r.name() == name)
    };
    let computed = match words.as_slice() {
        ["confidence"] => Some(confidence.to_string()),
        ["samples"] => (e.samples > 0).then(|| e.samples.to_string()),
        ["coverage", output, m, r] => match (method(m), region(r)) {
            (Some(m), Some(r)) => Some(
                last(e, output)
                    .and_then(|n| estimate_consistency(n, m))
                    .and_then(|c| c.region(r).copied())
                    .map_or(NOT_COMPUTED.to_owned(), |c| {
                        let inside = 100.0 * c.inside;
                        format!("{} %", plus_minus(inside, Some(100.0 * c.stderr), 1))
                    }),
            ),
            _ => None,
        },
        ["anees", output, m] => method(m).map(|m| {
            last(e, output)
                .and_then(|n| estimate_consistency(n, m))
                .and_then(|c| c.anees)
                .map_or(NOT_COMPUTED.to_owned(), |a| format!("{:.2}", a.value))
        }),
        ["along_track", output, m] => method(m).map(|m| {
            let values = e.along_track();
            let last_step = values
                .iter()
                .filter(|a| a.output == *output)
                .map(|a| a.step)
                .max();
            values
                .iter()
                .find(|a| a.output == *output && Some(a.step) == last_step && a.method == m)
                .map_or(NOT_COMPUTED.to_owned(), |a| {
                    format!("{} m²", plus_minus(a.variance_m2, a.stderr_m2, 4))
                })
        }),
        ["cartesian_mean", output] => Some(
            last(e, output)
                .and_then(|n| n.monte_carlo.as_ref())
                .and_then(|mc| Some((mc.position_mean?, mc.position_mean_stderr)))
                .map_or(NOT_COMPUTED.to_owned(), |(mean, stderr)| {
                    let dims = G::KIND.position_dims();
                    let coordinates: Vec<String> = (0..dims)
                        .map(|k| plus_minus(mean[k], stderr.map(|s| s[k]), 3))
                        .collect();
                    format!("({}) m", coordinates.join(", "))
                }),
        ),
        _ => None,
    };
    computed.unwrap_or_else(|| format!("(unknown placeholder {{{{{placeholder}}}}})"))
}

/// The last recorded node named `output`.
fn last<'e, G: LieGroup<N>, const N: usize>(
    e: &'e Evaluation<G, N>,
    output: &str,
) -> Option<&'e Node<G, N>> {
    e.nodes.iter().rev().find(|n| n.name == output)
}

fn estimate_consistency<G: LieGroup<N>, const N: usize>(
    node: &Node<G, N>,
    method: Method,
) -> Option<&crate::eval::Consistency> {
    node.estimates
        .iter()
        .find(|x| x.result.method == method)
        .and_then(|x| x.consistency.as_ref())
}

#[cfg(test)]
mod tests {
    use super::plus_minus;

    #[test]
    fn the_standard_error_sets_the_digits() {
        assert_eq!(plus_minus(1.8830, Some(0.0987), 4), "1.88 ± 0.1");
        assert_eq!(plus_minus(1.8830, Some(0.0234), 4), "1.883 ± 0.02");
        assert_eq!(plus_minus(70.06, Some(0.72), 1), "70.06 ± 0.7");
        assert_eq!(plus_minus(123.4, Some(12.0), 1), "123.4 ± 12");
        assert_eq!(plus_minus(1.8245, None, 4), "1.8245");
        assert_eq!(plus_minus(0.5, Some(0.0), 2), "0.50");
    }
}
