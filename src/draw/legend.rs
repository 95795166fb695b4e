//! The legend: one entry per colour and mark a scene draws, worded as the text panel words
//! them, so a figure or a view explains itself without the description.

use super::views::Estimate;
use crate::scene::{Color, LegendEntry, Swatch};
use crate::uncertain::Confidence;

/// A probability as the legend writes it: "95 %", "99.7 %" (at most two decimals, no
/// trailing zeros).
pub(super) fn percent(p: Confidence) -> String {
    let text = format!("{:.2}", 100.0 * p.get());
    let text = text.trim_end_matches('0').trim_end_matches('.');
    format!("{text} %")
}

/// What a pose's Gaussian is called: the method's label, or "given" for an input's own.
pub(super) fn who(estimate: Estimate, label: &str) -> String {
    match estimate {
        Estimate::Given => "given (input)".to_owned(),
        Estimate::Method(_) => label.to_owned(),
    }
}

/// An entry.
pub(super) fn entry(label: String, color: Color, swatch: Swatch) -> LegendEntry {
    LegendEntry {
        label,
        color: color.with_alpha(255),
        swatch,
    }
}

/// The axis triad's entry (frames, sample triads, Euler frames): red x, green y, blue z.
pub(super) fn axes(what: &str) -> LegendEntry {
    entry(
        format!("{what}: x red, y green, z blue"),
        Color::rgb(0, 0, 0),
        Swatch::Axes,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_keeps_what_matters() {
        let percent = |p| percent(Confidence::new(p).unwrap());
        assert_eq!(percent(0.95), "95 %");
        assert_eq!(percent(0.997), "99.7 %");
        assert_eq!(percent(0.5), "50 %");
    }
}
