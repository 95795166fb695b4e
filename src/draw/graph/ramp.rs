//! The σ colour ramp of a pose graph's after picture: each pose's position σ = √tr Σ_ρρ of
//! its marginal ([`PoseSigma`](crate::eval::graph::PoseSigma)) picks one of five colours, so
//! that marginals too small to see at the map's scale still read along the trajectory. The
//! trajectory and the marginal ellipses are drawn one entity per colour (`…/sigma_<k>`), and
//! the legend names each colour's range of σ.

use crate::scene::{
    Color, Ellipsoid, Ellipsoids, FillMode, ItemKind, LineStrips, Swatch, Vec3, paths,
};

use super::super::Painter;

/// The ramp's colours, small σ to large: blue, teal, green, amber, red — ordered in hue and
/// readable on a white figure and on the viewer's dark background.
pub(super) const RAMP: [Color; 5] = [
    Color::rgb(44, 123, 182),
    Color::rgb(0, 166, 150),
    Color::rgb(120, 190, 60),
    Color::rgb(240, 170, 30),
    Color::rgb(215, 48, 39),
];

/// The σ that bound the ramp's colours: colour k holds `edges[k-1] ≤ σ < edges[k]` (the
/// first everything below `edges[0]`, the last everything from the last edge on).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Ramp {
    edges: [f64; RAMP.len() - 1],
}

impl Ramp {
    /// The ramp over the positive, finite `sigmas` (metres), `None` without one: five bins
    /// holding about a fifth of the σ each (the 20th, 40th, 60th and 80th percentiles), so
    /// that every colour marks a part of the trajectory; when those repeat (few or equal σ),
    /// five bins between the smallest and the largest, evenly spaced in log σ when they span
    /// more than 3× (evenly in σ otherwise). Each edge is rounded to two significant digits.
    pub(super) fn fitted(sigmas: impl IntoIterator<Item = f64>) -> Option<Self> {
        let mut sorted: Vec<f64> = sigmas
            .into_iter()
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect();
        sorted.sort_by(f64::total_cmp);
        let (mut lo, mut hi) = (*sorted.first()?, *sorted.last()?);
        let bins = RAMP.len();
        let quantiles: [f64; RAMP.len() - 1] =
            std::array::from_fn(|k| two_digits(sorted[(k + 1) * sorted.len() / bins]));
        if quantiles.windows(2).all(|w| w[0] < w[1]) && quantiles[0] > lo {
            return Some(Self { edges: quantiles });
        }
        if hi < 1.2 * lo {
            (lo, hi) = (lo / 1.1, lo * 1.1);
        }
        let log = hi > 3.0 * lo;
        let edges = std::array::from_fn(|k| {
            let t = (k + 1) as f64 / bins as f64;
            let edge = if log {
                lo * (hi / lo).powf(t)
            } else {
                lo + (hi - lo) * t
            };
            two_digits(edge)
        });
        Some(Self { edges })
    }

    /// A ramp of one colour, for a graph without marginals: every pose in the first.
    pub(super) fn flat() -> Self {
        Self {
            edges: [f64::INFINITY; RAMP.len() - 1],
        }
    }

    /// The bin of a σ (0 for a pose without one).
    pub(super) fn bin(&self, sigma: f64) -> usize {
        self.edges.iter().filter(|e| sigma >= **e).count()
    }

    /// Bin k's range in words: "< 20 mm", "20–50 mm", "≥ 0.5 m".
    pub(super) fn range_words(&self, k: usize) -> String {
        let last = RAMP.len() - 1;
        match k {
            0 => format!("< {}", length_words(self.edges[0])),
            k if k >= last => format!("≥ {}", length_words(self.edges[last - 1])),
            k => {
                let (a, b) = (self.edges[k - 1], self.edges[k]);
                if a < 0.1 && b < 0.1 {
                    format!("{}–{}", trimmed(a * 1e3), length_words(b))
                } else if a >= 0.1 && b >= 0.1 {
                    format!("{}–{}", trimmed(a), length_words(b))
                } else {
                    format!("{}–{}", length_words(a), length_words(b))
                }
            }
        }
    }

    /// The legend: one line entry per colour, "after: position σ √tr Σ_ρρ 20–50 mm" (the
    /// trajectory and the ellipses in that colour).
    pub(super) fn legend(&self, p: &mut Painter) {
        if self.edges[0].is_infinite() {
            let what = "after: optimised trajectory (no marginals, so no σ colours)";
            p.legend(what.to_owned(), RAMP[0], Swatch::Line);
            return;
        }
        for (k, color) in RAMP.iter().enumerate() {
            p.legend(
                format!("after: position σ √tr Σ_ρρ {}", self.range_words(k)),
                *color,
                Swatch::Line,
            );
        }
    }
}

/// `v` rounded to two significant digits.
fn two_digits(v: f64) -> f64 {
    let power = 10f64.powf(v.log10().floor() - 1.0);
    (v / power).round() * power
}

/// A number with at most two significant digits and no trailing zeros ("20", "0.25", "1.2").
fn trimmed(v: f64) -> String {
    let decimals = (1.0 - v.log10().floor()).max(0.0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    }
}

/// A length in mm below 0.1 m, else in m, to two significant digits.
pub(super) fn length_words(metres: f64) -> String {
    if metres < 0.1 {
        format!("{} mm", trimmed(metres * 1e3))
    } else {
        format!("{} m", trimmed(metres))
    }
}

/// The trajectory through `points` in the ramp's colours at `base/sigma_<k>`, one entity per
/// colour (every colour logged, an empty one too, so that a later state of the timeline
/// replaces an earlier one whole): the segments `a → a + 1` for each `a` of `segments`
/// (ascending), each coloured by the larger σ of its two ends, consecutive segments of one
/// colour joined into one polyline.
pub(super) fn trajectory(
    p: &mut Painter,
    base: &str,
    step: Option<u64>,
    (points, sigma): (&[Vec3], &[f64]),
    segments: impl IntoIterator<Item = usize>,
    (ramp, radius): (&Ramp, f64),
) {
    let mut strips: [Vec<Vec<Vec3>>; RAMP.len()] = Default::default();
    let mut last: Option<(usize, usize)> = None;
    for a in segments {
        if a + 1 >= points.len() {
            continue;
        }
        let k = ramp.bin(sigma[a].max(sigma[a + 1]));
        match last {
            Some((prev, bin)) if prev + 1 == a && bin == k => {
                if let Some(strip) = strips[k].last_mut() {
                    strip.push(points[a + 1]);
                }
            }
            _ => strips[k].push(vec![points[a], points[a + 1]]),
        }
        last = Some((a, k));
    }
    for (k, strips) in strips.into_iter().enumerate() {
        p.push(
            paths::child(base, &format!("sigma_{k}")),
            step,
            ItemKind::LineStrips(LineStrips {
                strips,
                color: RAMP[k],
                radius,
            }),
        );
    }
}

/// Ellipses (each with its pose's σ) in the ramp's colours at `base/sigma_<k>`, one entity
/// per colour, every colour logged (see [`trajectory`]).
pub(super) fn ellipses(
    p: &mut Painter,
    base: &str,
    step: Option<u64>,
    shapes: Vec<(Ellipsoid, f64)>,
    (ramp, line_radius): (&Ramp, f64),
) {
    let mut binned: [Vec<Ellipsoid>; RAMP.len()] = Default::default();
    for (shape, sigma) in shapes {
        binned[ramp.bin(sigma)].push(shape);
    }
    for (k, shapes) in binned.into_iter().enumerate() {
        p.push(
            paths::child(base, &format!("sigma_{k}")),
            step,
            ItemKind::Ellipsoids(Ellipsoids {
                shapes,
                color: RAMP[k],
                fill: FillMode::MajorWireframe,
                line_radius,
                label: None,
            }),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(edges: [f64; 4], expected: [f64; 4]) {
        for (a, b) in edges.iter().zip(expected) {
            assert!((a - b).abs() <= 1e-12 * b, "{edges:?} against {expected:?}");
        }
    }

    #[test]
    fn many_sigmas_are_binned_by_fifths() {
        let ramp = Ramp::fitted((1..=10).map(|k| 0.01 * k as f64)).unwrap();
        close(ramp.edges, [0.03, 0.05, 0.07, 0.09]);
        assert_eq!(ramp.bin(0.02), 0);
        assert_eq!(ramp.bin(0.1), 4);
    }

    #[test]
    fn a_wide_span_is_binned_in_log_sigma_and_named_in_words() {
        let ramp = Ramp::fitted([0.01, 0.02, 1.0]).unwrap();
        close(ramp.edges, [0.025, 0.063, 0.16, 0.4]);
        assert_eq!(ramp.bin(0.0), 0);
        assert_eq!(ramp.bin(0.05), 1);
        assert_eq!(ramp.bin(5.0), 4);
        assert_eq!(ramp.range_words(0), "< 25 mm");
        assert_eq!(ramp.range_words(1), "25–63 mm");
        assert_eq!(ramp.range_words(2), "63 mm–0.16 m");
        assert_eq!(ramp.range_words(3), "0.16–0.4 m");
        assert_eq!(ramp.range_words(4), "≥ 0.4 m");
    }

    #[test]
    fn a_narrow_span_is_binned_evenly_and_one_value_gets_a_range() {
        let ramp = Ramp::fitted([1.0, 2.0]).unwrap();
        close(ramp.edges, [1.2, 1.4, 1.6, 1.8]);
        let one = Ramp::fitted([0.5, f64::NAN, 0.0]).unwrap();
        assert!(one.edges.windows(2).all(|w| w[0] < w[1]), "{:?}", one.edges);
        assert!(Ramp::fitted([0.0, f64::INFINITY]).is_none());
    }
}
