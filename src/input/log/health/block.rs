//! The health of one 3 × 3 covariance block of a sensor message (`sensor_msgs/Imu`'s three):
//! the words of docs/guide/logs.md's "Covariance health", with REP 145's conventions — −1 in
//! element 0 is "not provided" (`unknown_marker`, and nothing else of the block is checked),
//! every entry 0 is "unknown" (`all_zero`).

use nalgebra::{Matrix3, SymmetricEigen};

use super::{Issues, PLACEHOLDER};
use crate::plan::log::Issue;
use crate::uncertain::{psd_tolerance, symmetry_tolerance};

/// What one message's block is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockHealth {
    /// The issues of this block in this message.
    pub issues: Issues,
    /// Axes whose variance is exactly 0 or ≥ [`PLACEHOLDER`] (not estimated).
    pub unestimated: [bool; 3],
    /// The smallest eigenvalue of the estimated block when it is not PSD.
    pub min_eigenvalue: Option<f64>,
    /// The sum of the estimated variances, when the block is usable and checked.
    pub trace: Option<f64>,
}

impl BlockHealth {
    /// Whether the block is provided and its σ's can be read: not "not provided" (−1) and no
    /// issue that makes a covariance unusable.
    pub fn usable(&self) -> bool {
        !self.issues.any_unusable()
    }
}

/// Classifies one row-major 3 × 3 block, in the order its issues are listed: not finite, ROS's
/// −1 ("not provided": the rest is not checked), all zero, placeholders, asymmetric, not PSD
/// (the tolerances are evaluation's: [`symmetry_tolerance`], [`psd_tolerance`]).
///
/// ```
/// use posecov::input::log::health::classify_block;
/// use posecov::plan::log::Issue;
/// let h = classify_block(&[0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.04]);
/// assert!(h.usable() && h.issues.is_empty());
/// assert_eq!(h.trace, Some(0.06));
/// let mut not_provided = [0.0; 9];
/// not_provided[0] = -1.0;
/// assert_eq!(classify_block(&not_provided).issues, vec![Issue::UnknownMarker]);
/// assert_eq!(classify_block(&[0.0; 9]).issues, vec![Issue::AllZero]);
/// let not_psd = classify_block(&[0.01, 0.05, 0.0, 0.05, 0.01, 0.0, 0.0, 0.0, 0.01]);
/// assert_eq!(not_psd.issues, vec![Issue::NotPsd]);
/// ```
pub fn classify_block(b: &[f64; 9]) -> BlockHealth {
    let mut h = BlockHealth {
        issues: Issues::default(),
        unestimated: [false; 3],
        min_eigenvalue: None,
        trace: None,
    };
    if !b.iter().all(|v| v.is_finite()) {
        h.issues.push(Issue::NonFinite);
        return h;
    }
    if b[0] == -1.0 {
        h.issues.push(Issue::UnknownMarker);
        return h;
    }
    if b.iter().all(|v| *v == 0.0) {
        h.issues.push(Issue::AllZero);
        h.unestimated = [true; 3];
        return h;
    }
    let diag = [b[0], b[4], b[8]];
    h.unestimated = diag.map(|v| v == 0.0 || v >= PLACEHOLDER);
    if diag.iter().any(|v| *v >= PLACEHOLDER) {
        h.issues.push(Issue::Placeholder);
    }
    // The block on the axes that are not placeholders (a huge row would swamp the rest).
    let kept: Vec<usize> = (0..3).filter(|&i| diag[i] < PLACEHOLDER).collect();
    let scale = kept.iter().map(|&i| diag[i].abs()).fold(0.0, f64::max);
    let tol = symmetry_tolerance(scale);
    let asymmetric = kept.iter().any(|&r| {
        kept.iter()
            .any(|&c| (b[r * 3 + c] - b[c * 3 + r]).abs() > tol)
    });
    if asymmetric {
        h.issues.push(Issue::Asymmetric);
        return h;
    }
    let m = Matrix3::from_fn(|r, c| {
        if kept.contains(&r) && kept.contains(&c) {
            0.5 * (b[r * 3 + c] + b[c * 3 + r])
        } else {
            0.0
        }
    });
    let eig = SymmetricEigen::new(m);
    let lo = eig.eigenvalues.min();
    let hi = eig.eigenvalues.max().max(0.0);
    if lo < -psd_tolerance(hi) {
        h.issues.push(Issue::NotPsd);
        h.min_eigenvalue = Some(lo);
        return h;
    }
    // The estimated variances' sum (placeholders and zeros left out).
    h.trace = Some((0..3).filter(|&i| !h.unestimated[i]).map(|i| diag[i]).sum());
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_case_has_its_word() {
        let d = |x: f64, y: f64, z: f64| [x, 0.0, 0.0, 0.0, y, 0.0, 0.0, 0.0, z];
        // A yaw without a magnetometer: a placeholder, a note, σ of x and y read.
        let h = classify_block(&d(0.01, 0.01, 1e6));
        assert_eq!(h.issues, vec![Issue::Placeholder]);
        assert!(h.usable() && h.unestimated == [false, false, true]);
        assert_eq!(h.trace, Some(0.02));
        let mut nan = d(0.01, 0.01, 0.01);
        nan[5] = f64::NAN;
        assert_eq!(classify_block(&nan).issues, vec![Issue::NonFinite]);
        let mut asym = d(0.01, 0.01, 0.01);
        asym[1] = 0.005;
        assert_eq!(classify_block(&asym).issues, vec![Issue::Asymmetric]);
        // −1 with garbage after it: not provided, nothing else checked.
        let mut marker = [f64::MAX; 9];
        marker[0] = -1.0;
        let h = classify_block(&marker);
        assert_eq!(h.issues, vec![Issue::UnknownMarker]);
        assert!(!h.usable() && h.trace.is_none());
        let h = classify_block(&d(-0.01, 0.01, 0.01));
        assert_eq!(h.issues, vec![Issue::NotPsd]);
        assert!((h.min_eigenvalue.unwrap() + 0.01).abs() < 1e-15);
    }
}
