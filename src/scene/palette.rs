//! One fixed colour per method, so a method looks the same in every scenario, plot and legend.
//!
//! Colours follow the Okabe–Ito palette (distinguishable with the common colour-vision
//! deficiencies), all of middle lightness so they read on both the native viewer's dark
//! theme and the web viewer's light one (so no white, black or pale yellow). Monte Carlo (the
//! reference) is neutral grey.

use super::Color;

/// A way of computing (or showing) an uncertain pose; each has a fixed colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    /// First-order (linearised, Jacobian / adjoint) propagation.
    FirstOrder,
    /// Second-order propagation.
    SecondOrder,
    /// Fourth-order compounding (Barfoot & Furgale 2014).
    FourthOrder,
    /// Sigma points (unscented transform on the manifold).
    SigmaPoints,
    /// Monte-Carlo sampling: the reference.
    MonteCarlo,
    /// Vector-space propagation (Smith–Self–Cheeseman), no Lie algebra.
    VectorSpace,
    /// The lecture's formula as written (e.g. SE(3) odometry without Jr).
    LectureFaithful,
    /// The noise-free (mean) pose or path.
    Nominal,
}

impl Method {
    /// Every method, in legend order.
    pub const ALL: [Self; 8] = [
        Self::FirstOrder,
        Self::SecondOrder,
        Self::FourthOrder,
        Self::SigmaPoints,
        Self::MonteCarlo,
        Self::VectorSpace,
        Self::LectureFaithful,
        Self::Nominal,
    ];

    /// The method's colour (opaque).
    ///
    /// ```
    /// use posecov::scene::Method;
    /// assert_ne!(Method::FirstOrder.color(), Method::MonteCarlo.color());
    /// ```
    pub const fn color(self) -> Color {
        match self {
            Self::FirstOrder => Color::rgb(86, 180, 233), // sky blue
            Self::SecondOrder => Color::rgb(0, 158, 115), // bluish green
            Self::FourthOrder => Color::rgb(230, 159, 0), // orange
            Self::SigmaPoints => Color::rgb(204, 121, 167), // reddish purple
            Self::MonteCarlo => Color::rgb(175, 175, 175), // grey
            Self::VectorSpace => Color::rgb(213, 94, 0),  // vermillion
            Self::LectureFaithful => Color::rgb(204, 170, 0), // gold
            Self::Nominal => Color::rgb(0, 114, 178),     // blue
        }
    }

    /// The colour's name, for the text panel ("first order is drawn in sky blue").
    ///
    /// ```
    /// assert_eq!(posecov::scene::Method::MonteCarlo.color_name(), "grey");
    /// ```
    pub const fn color_name(self) -> &'static str {
        match self {
            Self::FirstOrder => "sky blue",
            Self::SecondOrder => "bluish green",
            Self::FourthOrder => "orange",
            Self::SigmaPoints => "reddish purple",
            Self::MonteCarlo => "grey",
            Self::VectorSpace => "vermillion",
            Self::LectureFaithful => "gold",
            Self::Nominal => "blue",
        }
    }

    /// Human-readable name, for legends.
    ///
    /// ```
    /// assert_eq!(posecov::scene::Method::VectorSpace.label(), "vector space (SSC)");
    /// ```
    pub const fn label(self) -> &'static str {
        match self {
            Self::FirstOrder => "first order",
            Self::SecondOrder => "second order",
            Self::FourthOrder => "fourth order",
            Self::SigmaPoints => "sigma points",
            Self::MonteCarlo => "Monte Carlo",
            Self::VectorSpace => "vector space (SSC)",
            Self::LectureFaithful => "lecture-faithful (no Jr)",
            Self::Nominal => "nominal",
        }
    }

    /// Identifier used in entity paths and scenario files (`first_order`, `monte_carlo`, …).
    ///
    /// ```
    /// use posecov::scene::Method;
    /// assert_eq!(Method::from_slug(Method::SigmaPoints.slug()), Some(Method::SigmaPoints));
    /// ```
    pub const fn slug(self) -> &'static str {
        match self {
            Self::FirstOrder => "first_order",
            Self::SecondOrder => "second_order",
            Self::FourthOrder => "fourth_order",
            Self::SigmaPoints => "sigma_points",
            Self::MonteCarlo => "monte_carlo",
            Self::VectorSpace => "vector_space",
            Self::LectureFaithful => "lecture_faithful",
            Self::Nominal => "nominal",
        }
    }

    /// The method with this [`slug`](Self::slug), if any.
    pub fn from_slug(slug: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.slug() == slug)
    }

    /// A markdown legend line per method: `- **first order**: sky blue`.
    ///
    /// ```
    /// use posecov::scene::Method;
    /// let md = Method::legend_markdown(&[Method::MonteCarlo]);
    /// assert_eq!(md, "- **Monte Carlo**: grey\n");
    /// ```
    pub fn legend_markdown(methods: &[Self]) -> String {
        methods
            .iter()
            .map(|m| format!("- **{}**: {}\n", m.label(), m.color_name()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_names_and_slugs_are_distinct() {
        for (i, a) in Method::ALL.iter().enumerate() {
            for b in &Method::ALL[i + 1..] {
                assert_ne!(a.color(), b.color(), "{a:?} {b:?}");
                assert_ne!(a.color_name(), b.color_name());
                assert_ne!(a.slug(), b.slug());
            }
            assert_eq!(Method::from_slug(a.slug()), Some(*a));
        }
    }
}
