//! Confidence regions ([CONVENTIONS §7]): how far out, in Mahalanobis radius, a region of a
//! d-dimensional Gaussian holds probability p (χ² with d degrees of freedom), and back.
//!
//! [CONVENTIONS §7]: crate::conventions#7-drawing-uncertainty

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
