//! Each method's words, slug and colour in one place: one fixed colour per method, so a
//! method looks the same in every scenario, plot and legend.
//!
//! Colours follow the Okabe–Ito palette (distinguishable with the common colour-vision
//! deficiencies), lightened where needed to read on the viewer's dark background. Monte Carlo
//! (the reference) is neutral grey; the nominal pose or path is [`NOMINAL`].

use super::Color;
use crate::uncertain::Method;

/// Colour of nominal (noise-free) poses and paths: Okabe–Ito blue, readable on the viewer's
/// dark and light themes.
pub const NOMINAL: Color = Color::rgb(0, 114, 178);
/// Colours of the x, y and z axes of every drawn frame, triad and axis-tip spray: red, green,
/// blue (the light shades that read on the viewer's dark background and on paper).
pub const AXIS_COLORS: [Color; 3] = [
    Color::rgb(255, 90, 90),
    Color::rgb(90, 220, 90),
    Color::rgb(100, 140, 255),
];
/// Lines between poses (a pose graph's loop closures): neutral grey.
pub const LINK: Color = Color::rgb(110, 110, 110);
/// What a plot's lines are judged against (the confidence claimed, a χ² band): Okabe–Ito
/// yellow, apart from every method's colour.
pub const REFERENCE: Color = Color::rgb(240, 228, 66);

/// The name of a palette colour, whatever its alpha ("sky blue", "yellow"; the axis colours
/// "red", "green", "blue"); `None` for a colour outside the palette.
///
/// ```
/// use posecov::scene::{REFERENCE, color_name};
/// use posecov::uncertain::Method;
/// assert_eq!(color_name(Method::FirstOrder.color().with_alpha(90)), Some("sky blue"));
/// assert_eq!(color_name(REFERENCE), Some("yellow"));
/// ```
pub fn color_name(color: Color) -> Option<&'static str> {
    let opaque = color.with_alpha(255);
    let named = [
        (NOMINAL, "blue"),
        (LINK, "dark grey"),
        (REFERENCE, "yellow"),
        (AXIS_COLORS[0], "red"),
        (AXIS_COLORS[1], "green"),
        (AXIS_COLORS[2], "blue"),
    ];
    Method::ALL
        .iter()
        .map(|m| (m.color(), m.color_name()))
        .chain(named)
        .find(|(c, _)| *c == opaque)
        .map(|(_, name)| name)
}

impl Method {
    /// Every method, in legend order.
    pub const ALL: [Self; 10] = [
        Self::Exact,
        Self::FirstOrder,
        Self::LectureNoJr,
        Self::SecondOrder,
        Self::FourthOrder,
        Self::SigmaPoints,
        Self::MonteCarlo,
        Self::VectorSpace,
        Self::ClosedForm,
        Self::NumericIntegral,
    ];

    /// The method's colour (opaque). `Exact` shares first order's colour: a deterministic
    /// operation's result is what first order gives there, and the two never meet on one pose.
    ///
    /// ```
    /// use posecov::uncertain::Method;
    /// assert_ne!(Method::FirstOrder.color(), Method::MonteCarlo.color());
    /// ```
    pub const fn color(self) -> Color {
        match self {
            Self::Exact | Self::FirstOrder => Color::rgb(86, 180, 233), // sky blue
            Self::ClosedForm => Color::rgb(120, 200, 255),              // light sky blue
            Self::SecondOrder => Color::rgb(0, 158, 115),               // bluish green
            Self::NumericIntegral => Color::rgb(0, 200, 150),           // light bluish green
            Self::FourthOrder => Color::rgb(230, 159, 0),               // orange
            Self::SigmaPoints => Color::rgb(204, 121, 167),             // reddish purple
            Self::MonteCarlo => Color::rgb(175, 175, 175),              // grey
            Self::VectorSpace => Color::rgb(213, 94, 0),                // vermillion
            Self::LectureNoJr => Color::rgb(240, 200, 40),              // gold
        }
    }

    /// The colour's name, for the text panel ("first order is drawn in sky blue").
    ///
    /// ```
    /// assert_eq!(posecov::uncertain::Method::MonteCarlo.color_name(), "grey");
    /// ```
    pub const fn color_name(self) -> &'static str {
        match self {
            Self::Exact | Self::FirstOrder => "sky blue",
            Self::ClosedForm => "light sky blue",
            Self::SecondOrder => "bluish green",
            Self::NumericIntegral => "light bluish green",
            Self::FourthOrder => "orange",
            Self::SigmaPoints => "reddish purple",
            Self::MonteCarlo => "grey",
            Self::VectorSpace => "vermillion",
            Self::LectureNoJr => "gold",
        }
    }

    /// A short human-readable label ("first order", "Monte Carlo", …).
    ///
    /// ```
    /// use posecov::uncertain::Method;
    /// assert_eq!(Method::MonteCarlo.label(), "Monte Carlo");
    /// ```
    pub fn label(self) -> &'static str {
        match self {
            Self::Exact => "exact",
            Self::FirstOrder => "first order",
            Self::LectureNoJr => "first order without Jr (lecture)",
            Self::SecondOrder => "second order",
            Self::FourthOrder => "fourth order",
            Self::SigmaPoints => "sigma points",
            Self::MonteCarlo => "Monte Carlo",
            Self::VectorSpace => "vector space (SSC)",
            Self::ClosedForm => "closed form",
            Self::NumericIntegral => "numeric integral",
        }
    }

    /// Identifier used in entity paths and scenario files (`first_order`, `monte_carlo`, …):
    /// the serde name.
    ///
    /// ```
    /// use posecov::uncertain::Method;
    /// assert_eq!(Method::SigmaPoints.slug(), "sigma_points");
    /// ```
    pub const fn slug(self) -> &'static str {
        match self {
            Self::Exact => "exact",
            Self::FirstOrder => "first_order",
            Self::LectureNoJr => "lecture_no_jr",
            Self::SecondOrder => "second_order",
            Self::FourthOrder => "fourth_order",
            Self::SigmaPoints => "sigma_points",
            Self::MonteCarlo => "monte_carlo",
            Self::VectorSpace => "vector_space",
            Self::ClosedForm => "closed_form",
            Self::NumericIntegral => "numeric_integral",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_names_and_slugs_are_distinct() {
        let drawn: Vec<Method> = Method::ALL
            .into_iter()
            .filter(|m| *m != Method::Exact)
            .collect();
        for (i, a) in drawn.iter().enumerate() {
            for b in &drawn[i + 1..] {
                assert_ne!(a.color(), b.color(), "{a:?} {b:?}");
                assert_ne!(a.color_name(), b.color_name());
            }
            assert_ne!(a.color(), NOMINAL);
        }
        for m in Method::ALL {
            // The slug is the serde name, so scenario files and entity paths agree.
            assert_eq!(
                serde_json::to_value(m).unwrap(),
                serde_json::Value::from(m.slug())
            );
        }
    }
}
