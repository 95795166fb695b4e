//! Confidence regions ([CONVENTIONS §7]): how far out, in Mahalanobis radius, a region of a
//! d-dimensional Gaussian holds probability p (χ² with d degrees of freedom), and back.
//!
//! Here: `Confidence` (a probability in (0, 1), checked once; its χ² radius), χ² radii and
//! probabilities of confidence regions, the ANEES band, `Region` and `Coverage`.
//!
//! [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::error::{Error, Result};

fn chi_squared(dof: usize) -> Result<ChiSquared> {
    if dof == 0 {
        return Err(Error::OutOfRange {
            what: "degrees of freedom d",
            value: 0.0,
            expected: "d ≥ 1",
        });
    }
    ChiSquared::new(dof as f64).map_err(|_| Error::OutOfRange {
        what: "degrees of freedom d",
        value: dof as f64,
        expected: "a finite d ≥ 1",
    })
}

/// The Mahalanobis radius r of the p-probability region of a d-dimensional Gaussian:
/// P(εᵀ Σ⁻¹ ε ≤ r²) = p, i.e. r = √(χ²_d quantile(p)) ([CONVENTIONS §7]). d = 3 for an SE(3)
/// position marginal, 2 for SE(2), 6 / 3 for the full pose. Errors: p ∉ (0, 1), d = 0.
///
/// ```
/// use posecov::uncertain::chi2_radius;
/// assert!((chi2_radius(0.95, 3).unwrap() - 2.795).abs() < 1e-3);
/// assert!((chi2_radius(0.95, 2).unwrap() - 2.448).abs() < 1e-3);
/// assert!((chi2_radius(0.6827, 3).unwrap() - 1.878).abs() < 1e-3);
/// assert!(chi2_radius(1.0, 3).is_err());
/// ```
///
/// [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty
pub fn chi2_radius(probability: f64, dof: usize) -> Result<f64> {
    if !(probability > 0.0 && probability < 1.0) {
        return Err(Error::OutOfRange {
            what: "probability p",
            value: probability,
            expected: "0 < p < 1",
        });
    }
    Ok(chi_squared(dof)?.inverse_cdf(probability).sqrt())
}

/// The probability inside Mahalanobis radius r of a d-dimensional Gaussian,
/// P(εᵀ Σ⁻¹ ε ≤ r²) = F_χ²_d(r²): the inverse of [`chi2_radius`]. Errors: r < 0 or not
/// finite, d = 0.
///
/// ```
/// use posecov::uncertain::chi2_probability;
/// assert!((chi2_probability(1.0, 1).unwrap() - 0.682689).abs() < 1e-6); // 1σ in 1-D
/// assert!((chi2_probability(1.0, 3).unwrap() - 0.198748).abs() < 1e-6); // 1σ ellipsoid in 3-D
/// ```
pub fn chi2_probability(radius: f64, dof: usize) -> Result<f64> {
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(Error::OutOfRange {
            what: "Mahalanobis radius r",
            value: radius,
            expected: "a finite r ≥ 0",
        });
    }
    Ok(chi_squared(dof)?.cdf(radius * radius))
}

/// The probability of the 1-D k-σ interval, P(|z| ≤ k) = erf(k/√2) = F_χ²_1(k²)
/// (d = 1: 1σ → 68.27 %, 2σ → 95.45 %, 3σ → 99.73 %).
///
/// ```
/// use posecov::uncertain::sigma_probability;
/// assert!((sigma_probability(2.0).unwrap() - 0.954500).abs() < 1e-6);
/// ```
pub fn sigma_probability(k: f64) -> Result<f64> {
    chi2_probability(k, 1)
}

/// The d-dimensional Mahalanobis radius holding the same probability as the 1-D k-σ interval:
/// r = [`chi2_radius`]`(`[`sigma_probability`]`(k), d)`. E.g. "1σ" (68.27 %) in d = 3 is
/// r = 1.878, not 1: drawing the r = 1 ellipsoid of a 3-D position holds only 19.9 %.
///
/// ```
/// use posecov::uncertain::sigma_radius;
/// assert!((sigma_radius(1.0, 3).unwrap() - 1.878).abs() < 1e-3);
/// assert!((sigma_radius(2.0, 1).unwrap() - 2.0).abs() < 1e-9);
/// ```
pub fn sigma_radius(k: f64, dof: usize) -> Result<f64> {
    chi2_radius(sigma_probability(k)?, dof)
}

/// The two-sided `probability` band of the average NEES of `samples` independent d-dimensional
/// Gaussian errors, each NEES ε̃ᵀ Σ⁻¹ ε̃ ~ χ²_d when Σ is the errors' true covariance: n · ANEES
/// ~ χ²_{n·d}, so the band is \[χ²_{nd}((1 − p)/2), χ²_{nd}((1 + p)/2)\] / n, about the
/// expectation d (Bar-Shalom, Li & Kirubarajan 2001, *Estimation with Applications to
/// Tracking and Navigation*, §5.4.2). ANEES above the band: the covariance is too small
/// (overconfident); below: too large. Errors: p ∉ (0, 1), no samples, d = 0.
///
/// ```
/// use posecov::uncertain::anees_band;
/// let [low, high] = anees_band(1000, 3, 0.95).unwrap();
/// assert!((low - 2.8506).abs() < 1e-3 && (high - 3.1543).abs() < 1e-3);
/// let [low, high] = anees_band(1, 2, 0.95).unwrap(); // one sample: χ²_2's own 95 % interval
/// assert!((low - 0.0506).abs() < 1e-3 && (high - 7.3778).abs() < 1e-3);
/// ```
pub fn anees_band(samples: usize, dof: usize, probability: f64) -> Result<[f64; 2]> {
    if samples == 0 {
        return Err(Error::OutOfRange {
            what: "samples n",
            value: 0.0,
            expected: "n ≥ 1",
        });
    }
    let total = dof.saturating_mul(samples);
    let tail = (1.0 - probability) / 2.0;
    let low = chi2_radius(tail, total)?;
    let high = chi2_radius(1.0 - tail, total)?;
    let n = samples as f64;
    Ok([low * low / n, high * high / n])
}

/// A confidence region whose coverage is measured against Monte Carlo samples (the
/// `region` of a [`Coverage`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Region {
    /// The full tangent ellipsoid of a Gaussian on the group, on its own side:
    /// Log(μ⁻¹X)ᵀ Σ⁻¹ Log(μ⁻¹X) ≤ χ²_d(p), d the group's degrees of freedom. The banana is its
    /// picture.
    Tangent,
    /// The position block of the right-form tangent: ρᵀ Σ_ρρ⁻¹ ρ ≤ χ²_k(p), ρ the first k = 2
    /// or 3 entries of Log(μ⁻¹X).
    TangentPosition,
    /// The world-frame Cartesian ellipse (ellipsoid) of a tangent Gaussian's position:
    /// (p − p̄)ᵀ Σ_p⁻¹ (p − p̄) ≤ χ²_k(p), Σ_p = R Σ_ρρ Rᵀ, p̄ the mean's position.
    Cartesian,
    /// The vector-space (Smith–Self–Cheeseman) method's position ellipse: the same test with
    /// the position block of its Gaussian in (x, y, θ) / (x, y, z, roll, pitch, yaw).
    VectorSpace,
}

impl Region {
    /// The region's name in `report --json` and in the text (`tangent`, `tangent_position`,
    /// `cartesian`, `vector_space`).
    ///
    /// ```
    /// use posecov::uncertain::Region;
    /// assert_eq!(Region::TangentPosition.name(), "tangent_position");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Region::Tangent => "tangent",
            Region::TangentPosition => "tangent_position",
            Region::Cartesian => "cartesian",
            Region::VectorSpace => "vector_space",
        }
    }
}

/// The fraction of samples inside a confidence region, with its binomial standard error
/// √(q (1 − q) / n) (q the fraction, n the samples): a region drawn at confidence p is honest
/// when q is within a few standard errors of p.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Coverage {
    /// Which region.
    pub region: Region,
    /// Its degrees of freedom: the χ² that sets its radius.
    pub dof: usize,
    /// The fraction of the samples inside, q.
    pub inside: f64,
    /// The binomial standard error of q.
    pub stderr: f64,
}

impl Coverage {
    /// The coverage of `inside` samples out of `samples` (`samples` ≥ 1).
    ///
    /// ```
    /// use posecov::uncertain::{Coverage, Region};
    /// let c = Coverage::from_counts(Region::Tangent, 3, 950, 1000);
    /// assert!((c.inside - 0.95).abs() < 1e-15 && (c.stderr - 0.0068920).abs() < 1e-6);
    /// ```
    pub fn from_counts(region: Region, dof: usize, inside: usize, samples: usize) -> Self {
        let n = samples.max(1) as f64;
        let q = inside as f64 / n;
        Self {
            region,
            dof,
            inside: q,
            stderr: (q * (1.0 - q) / n).sqrt(),
        }
    }
}

/// A confidence: the probability p ∈ (0, 1) a drawn region holds (`--confidence`,
/// `[scenario] confidence`). Checked once, here, wherever it is given.
///
/// ```
/// use posecov::uncertain::Confidence;
/// assert_eq!(Confidence::new(0.95).unwrap().get(), 0.95);
/// assert_eq!(Confidence::new(95.0).unwrap_err().to_string(), "95 is not a probability in (0, 1); did you mean 0.95?");
/// assert_eq!(Confidence::new(1.0).unwrap_err().to_string(), "1 is not a probability in (0, 1), e.g. 0.95");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, serde::Serialize)]
#[serde(transparent)]
pub struct Confidence(f64);

/// A number that is not a probability in (0, 1).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{value} is not a probability in (0, 1){}", hint(*.value))]
pub struct ConfidenceError {
    /// The number given.
    pub value: f64,
}

/// A percentage (1 < v < 100) was probably meant as a fraction.
fn hint(value: f64) -> String {
    if value > 1.0 && value < 100.0 {
        format!("; did you mean {}?", value / 100.0)
    } else {
        ", e.g. 0.95".to_owned()
    }
}

impl Confidence {
    /// The 95 % regions drawn by default.
    pub const DEFAULT: Confidence = Confidence(0.95);

    /// `p` if it lies strictly between 0 and 1.
    ///
    /// # Errors
    /// [`ConfidenceError`] otherwise (NaN too), suggesting `p / 100` for a percentage.
    ///
    /// ```
    /// assert!(posecov::uncertain::Confidence::new(f64::NAN).is_err());
    /// ```
    pub fn new(p: f64) -> std::result::Result<Self, ConfidenceError> {
        if p > 0.0 && p < 1.0 {
            Ok(Self(p))
        } else {
            Err(ConfidenceError { value: p })
        }
    }

    /// The Mahalanobis radius of this confidence's region in `dof` ≥ 1 dimensions,
    /// [`chi2_radius`] (which cannot fail for a valid confidence; `dof` 0 is taken as 1).
    ///
    /// ```
    /// use posecov::uncertain::Confidence;
    /// assert!((Confidence::DEFAULT.radius(3) - 2.795).abs() < 1e-3);
    /// ```
    pub fn radius(self, dof: usize) -> f64 {
        chi2_radius(self.0, dof.max(1)).unwrap_or(f64::NAN)
    }

    /// The probability.
    ///
    /// ```
    /// assert_eq!(posecov::uncertain::Confidence::DEFAULT.get(), 0.95);
    /// ```
    pub const fn get(self) -> f64 {
        self.0
    }
}

/// The probability as people write it: "95 %", "99.7 %" (at most two decimals, no trailing
/// zeros; a thin space would not survive every font, so a plain one).
///
/// ```
/// use posecov::uncertain::Confidence;
/// assert_eq!(Confidence::DEFAULT.to_string(), "95 %");
/// assert_eq!(Confidence::new(0.997).unwrap().to_string(), "99.7 %");
/// assert_eq!(Confidence::new(0.5).unwrap().to_string(), "50 %");
/// ```
impl std::fmt::Display for Confidence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = format!("{:.2}", 100.0 * self.0);
        write!(f, "{} %", text.trim_end_matches('0').trim_end_matches('.'))
    }
}
