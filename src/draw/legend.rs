//! The legend: one entry per colour and mark a scene draws, worded as the text panel words
//! them, so a figure or a view explains itself without the description.

use super::views::Estimate;
use crate::scene::{Color, LegendEntry, Swatch};

/// What a pose's Gaussian is called: the method's label, or "given" for an input's own.
pub(super) fn who(estimate: Estimate, label: &str) -> String {
    match estimate {
        Estimate::Given => "given (input)".to_owned(),
        Estimate::Method(_) => label.to_owned(),
    }
}

/// An entry with what the run measured about it (`detail`, possibly empty).
pub(super) fn entry(label: String, detail: String, color: Color, swatch: Swatch) -> LegendEntry {
    LegendEntry {
        label,
        detail,
        color: color.with_alpha(255),
        swatch,
    }
}

/// The axis triad's entry (frames, sample triads, Euler frames): red x, green y, blue z.
pub(super) fn axes(what: &str) -> LegendEntry {
    entry(
        format!("{what}: x red, y green, z blue"),
        String::new(),
        Color::rgb(0, 0, 0),
        Swatch::Axes,
    )
}
