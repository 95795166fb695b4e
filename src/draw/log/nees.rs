//! A log's NEES against its reference (`--reference`): the plot over the stamp — each topic's
//! NEES per drawn message, its per-message 95 % bound and the ANEES band — and the paragraph
//! of the text panel, with the verdict in words.

use std::fmt::Write as _;

use crate::eval::log::LogEvaluation;
use crate::eval::log::nees::{Align, TopicConsistency, Verdict};
use crate::scene::{Color, Corner, Plot, PlotId, REFERENCE, ScalarSeries, Scene};

use crate::scene::paths::topic_segments;

/// The NEES line: first order's sky blue, the colour of what the numbers mean in the log's
/// view; the bounds are the reference yellow.
const NEES: Color = super::MEANING;

/// The verdict in words.
///
/// ```
/// use posecov::draw::log::verdict_word;
/// use posecov::eval::log::nees::Verdict;
/// assert_eq!(verdict_word(Verdict::Overconfident), "overconfident");
/// ```
pub fn verdict_word(verdict: Verdict) -> &'static str {
    match verdict {
        Verdict::Consistent => "consistent",
        Verdict::Overconfident => "overconfident",
        Verdict::Underconfident => "underconfident",
    }
}

/// What the verdict means for the published covariance.
fn verdict_meaning(verdict: Verdict) -> &'static str {
    match verdict {
        Verdict::Consistent => "the published covariance matches the errors",
        Verdict::Overconfident => {
            "the published covariance is too small for the errors against the reference"
        }
        Verdict::Underconfident => {
            "the published covariance is larger than the errors against the reference"
        }
    }
}

/// Adds one NEES plot per topic with a NEES series (each on its own scale: an overconfident
/// topic's NEES would flatten a consistent one's): its NEES at the drawn messages, the
/// per-message bound χ²_d(0.95), its ANEES and the ANEES band, flat over the topic's span.
pub(super) fn plots(scene: &mut Scene, e: &LogEvaluation) {
    let topics: Vec<(&str, &TopicConsistency)> = e
        .topics
        .iter()
        .filter_map(|t| Some((t.name.as_str(), t.consistency.as_ref()?)))
        .filter(|(_, c)| !c.series.is_empty())
        .collect();
    if topics.is_empty() {
        return;
    }
    for (name, c) in topics {
        let topic = topic_segments(name);
        let plot = PlotId::new(format!("nees_{}", topic.replace(['/', '-', '.'], "_")));
        let verdict = c.verdict.map_or("", verdict_word);
        // From 0 to the largest of the NEES, the bound and the band: all in view.
        let top = c
            .series
            .iter()
            .map(|p| p.1)
            .chain([c.bound_95])
            .chain(c.anees.map(|a| a.band[1]))
            .fold(0.0_f64, f64::max);
        scene.plots.push(Plot {
            id: plot.clone(),
            title: format!("NEES of {name} against {} — {verdict}", c.reference),
            unit: String::new(),
            range: (top.is_finite() && top > 0.0).then_some([0.0, 1.05 * top]),
            legend: Corner::LeftBottom,
        });
        let (first, last) = (c.series[0].0, c.series[c.series.len() - 1].0);
        let flat = |v: f64| vec![(first, v), (last, v)];
        let mut push = |segment: &str, label: String, color: Color, width: f64, points| {
            scene.series.push(ScalarSeries::new(
                plot.clone(),
                segment,
                label,
                color,
                width,
                points,
            ));
        };
        push(
            "nees",
            format!("NEES (d = {})", c.dof),
            NEES,
            1.5,
            c.series.clone(),
        );
        push(
            "bound_95",
            format!(
                "95 % of messages below: χ²_{}(0.95) = {:.2}",
                c.dof, c.bound_95
            ),
            REFERENCE,
            1.0,
            flat(c.bound_95),
        );
        if let Some(a) = c.anees {
            push(
                "anees",
                format!("ANEES {:.2}", a.value),
                NEES,
                3.0,
                flat(a.value),
            );
            for (segment, side, value) in [
                ("band_low", "low", a.band[0]),
                ("band_high", "high", a.band[1]),
            ] {
                let label = format!("ANEES 95 % band, {side} {value:.2}");
                push(segment, label, REFERENCE, 2.0, flat(value));
            }
        }
    }
}

/// The text panel's paragraph on a topic's NEES.
pub(super) fn paragraph(s: &mut String, c: &TopicConsistency) {
    let _ = write!(
        s,
        "\n**NEES against `{}`** ({} reading, e = Log(X̂⁻¹ X_ref), d = {}",
        c.reference,
        c.reading.name(),
        c.dof
    );
    if c.align != Align::None {
        let _ = write!(s, "; reference aligned: `--align {}`", c.align.name());
    }
    let _ = write!(s, "): ");
    match (c.anees, c.verdict) {
        (Some(a), Some(v)) => {
            let _ = writeln!(
                s,
                "ANEES **{:.2}** over {} messages, 95 % band [{:.2}, {:.2}] — **{}**: {}. \
                 {:.1} % of messages have NEES ≤ χ²_{}(0.95) = {:.2} (95 % when Σ is right).",
                a.value,
                c.messages,
                a.band[0],
                a.band[1],
                verdict_word(v),
                verdict_meaning(v),
                100.0 * c.inside_95.unwrap_or(0.0),
                c.dof,
                c.bound_95
            );
        }
        _ => {
            let _ = writeln!(s, "no message could be compared with the reference.");
        }
    }
    let part = |name: &str, a: &Option<crate::eval::Anees>| match a {
        Some(a) => format!(
            "{name} {:.2} (d = {}, band [{:.2}, {:.2}])",
            a.value, a.dof, a.band[0], a.band[1]
        ),
        None => format!("{name} –"),
    };
    let _ = writeln!(
        s,
        "\nANEES of position alone {}, of orientation alone {} (as ov_eval reports them).",
        part("", &c.position).trim_start(),
        part("", &c.orientation).trim_start()
    );
    let k = &c.skipped;
    let skipped: Vec<String> = [
        (k.before_reference, "before the reference's first stamp"),
        (k.after_reference, "after its last (never extrapolated)"),
        (k.unusable, "with an unusable covariance"),
        (k.singular, "with a singular covariance"),
        (k.other_dof, "planar in a 3-D topic or the other way"),
        (
            k.other_frame,
            "in another frame than the transform's parent",
        ),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, why)| format!("{n} {why}"))
    .collect();
    if !skipped.is_empty() {
        let _ = writeln!(s, "\nWithout NEES: {}.", skipped.join(", "));
    }
    if !c.reference_frame.is_empty() && c.reference_frame != c.estimate_frame {
        let _ = writeln!(
            s,
            "\nFrames differ: estimate in `{}`, reference in `{}`{}.",
            c.estimate_frame,
            c.reference_frame,
            if c.align == Align::None {
                " — if they are not the same frame, `--align se3` fits one to the other"
            } else {
                ""
            }
        );
    }
}
