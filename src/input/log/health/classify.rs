//! One message's covariance health: what its 36 entries and its orientation say on their own
//! ([`classify`]), the words and thresholds of docs/guide/logs.md's "Covariance health". A topic's
//! running state (drops, growth, constant stretches, counts) is the parent module's.
//!
//! Most messages are decided by one pass ([`clean_full_block`]): an EKF's covariance, every
//! axis estimated, symmetric and not strongly correlated. The rest go through every check
//! ([`every_check`]), which says which issue and by how much.

use nalgebra::{DMatrix, SymmetricEigen};

use super::Issues;
use crate::plan::log::{COV_LEN, Issue, PLACEHOLDER};
use crate::uncertain::{psd_tolerance, symmetry_tolerance};

/// The axes planar motion uses (x, y, yaw), by ROS index.
const PLANAR_AXES: [usize; 3] = [0, 1, 5];

/// What one message's covariance is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MessageHealth {
    /// The issues of this message alone (drops and growth come from
    /// [`Trend`](super::Trend)).
    pub issues: Issues,
    /// Axes whose variance is ≥ [`PLACEHOLDER`] or exactly 0, per ROS axis.
    pub unestimated: [bool; 6],
    /// Smallest eigenvalue of the estimated block, computed when it is finite, symmetric and
    /// not positive definite; exactly 0 when it is positive definite but for axes whose row
    /// and column are zero (`None` otherwise: a positive definite block is PSD).
    pub min_eigenvalue: Option<f64>,
    /// Trace of the estimated position block, m² (usable messages only).
    pub position_trace: Option<f64>,
}

impl MessageHealth {
    /// A covariance with no issue, every axis estimated and positive definite (no smallest
    /// eigenvalue computed), before its orientation and position trace are added.
    pub const CLEAN: MessageHealth = MessageHealth {
        issues: Issues::EMPTY,
        unestimated: [false; 6],
        min_eigenvalue: None,
        position_trace: None,
    };

    /// Whether the covariance can be drawn as a Gaussian.
    pub fn usable(&self) -> bool {
        !self.issues.any_unusable()
    }
}

/// The entries of the `kept` axes' block of `cov`, gathered: `b[r][c] = cov[kept[r] · 6 + kept[c]]`
/// for `r, c < kept.len()`.
fn gather(cov: &[f64; COV_LEN], kept: &[usize]) -> [[f64; 6]; 6] {
    let mut b = [[0.0; 6]; 6];
    for (r, &i) in kept.iter().enumerate() {
        for (c, &j) in kept.iter().enumerate() {
            b[r][c] = cov[i * 6 + j];
        }
    }
    b
}

/// Whether the symmetrised N × N block `at(r, c)` (`r, c < N`) is positive definite: its
/// factorisation L D Lᵀ exists with D > 0, computed here on the stack, without square roots
/// (then its smallest eigenvalue is positive, above any −tolerance, and it is positive
/// semi-definite by the one rule without computing it). N is known at compile time, so the
/// loops unroll and the entries are read without index checks.
#[inline(always)]
fn positive_definite_block<const N: usize>(at: &impl Fn(usize, usize) -> f64) -> bool {
    // l[r][c] = L_rc · D_c (c < r), d_inv[c] = 1 / D_c.
    let mut ld = [[0.0f64; N]; N];
    let mut d_inv = [0.0f64; N];
    for r in 0..N {
        for c in 0..r + 1 {
            let mut v = 0.5 * (at(r, c) + at(c, r));
            for k in 0..c {
                v -= ld[r][k] * ld[c][k] * d_inv[k];
            }
            if r == c {
                if v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    return false;
                }
                // The last row's 1 / D is never used: one division fewer.
                if r + 1 < N {
                    d_inv[r] = 1.0 / v;
                }
            } else {
                ld[r][c] = v;
            }
        }
    }
    true
}

/// `f::<N>()` for `N = n` (0 ≤ n ≤ 6): the block functions above are generic in the size.
macro_rules! by_size {
    ($n:expr, $f:ident, $($arg:expr),*) => {
        match $n {
            0 => $f::<0>($($arg),*),
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            _ => $f::<6>($($arg),*),
        }
    };
}

/// Whether the symmetrised block of `cov` on the `kept` axes is positive definite
/// ([`positive_definite_block`]).
fn positive_definite(cov: &[f64; COV_LEN], kept: &[usize]) -> bool {
    let b = gather(cov, kept);
    by_size!(
        kept.len(),
        positive_definite_block,
        &|r: usize, c: usize| b[r][c]
    )
}

/// What the checks over the estimated block find.
struct BlockChecks {
    /// Every entry is exactly 0.
    all_zero: bool,
    /// Some pair Σᵣ꜀, Σ꜀ᵣ differs by more than the symmetry tolerance at the block's scale
    /// (its largest |variance|).
    asymmetric: bool,
}

/// [`BlockChecks`] of the N × N block `at(r, c)`, every entry read once, without early exits
/// (the compiler compares in vectors).
#[inline(always)]
fn block_checks<const N: usize>(at: &impl Fn(usize, usize) -> f64) -> BlockChecks {
    let mut all_zero = true;
    let mut scale = 0.0f64;
    for r in 0..N {
        scale = scale.max(at(r, r).abs());
        for c in 0..N {
            all_zero &= at(r, c) == 0.0;
        }
    }
    // The symmetry rule is evaluation's (`uncertain`): what health calls symmetric,
    // evaluation accepts.
    let tol = symmetry_tolerance(scale);
    let mut asymmetric = false;
    // Each pair once (|Σᵢⱼ − Σⱼᵢ| is the same from either side; every entry is finite here).
    for r in 0..N {
        for c in r + 1..N {
            asymmetric |= (at(r, c) - at(c, r)).abs() > tol;
        }
    }
    BlockChecks {
        all_zero,
        asymmetric,
    }
}

/// [`block_checks`] and, when wanted (`pd_wanted(&checks)`), [`positive_definite_block`] of
/// the N × N block `at`: one function per size, so both unroll.
fn checks_and_pd<const N: usize>(
    at: &impl Fn(usize, usize) -> f64,
    pd_wanted: &impl Fn(&BlockChecks) -> bool,
) -> (BlockChecks, Option<bool>) {
    let checks = block_checks::<N>(at);
    let pd =
        pd_wanted(&checks).then(|| weakly_correlated::<N>(at) || positive_definite_block::<N>(at));
    (checks, pd)
}

/// Whether the symmetrised N × N block `at(r, c)` has a positive diagonal and correlations
/// ρᵣ꜀ = Σᵣ꜀ / √(Σᵣᵣ Σ꜀꜀) with Σ_{r<c} ρᵣ꜀² ≤ 0.45: then the correlation matrix is I + E with
/// ‖E‖₂ ≤ ‖E‖_F ≤ √0.9 < 0.95, so its eigenvalues are ≥ 0.05 and the block is positive definite
/// (by far: the rounding of this sum is 10¹³ times smaller than the margin; anything not
/// finite fails). A sufficient test without the L D Lᵀ's chain of dependent divisions (six
/// independent ones here); a block it does not decide goes to [`positive_definite_block`].
#[inline(always)]
fn weakly_correlated<const N: usize>(at: &impl Fn(usize, usize) -> f64) -> bool {
    let mut inv = [0.0f64; N];
    let mut positive = true;
    for (r, inv) in inv.iter_mut().enumerate() {
        let d = at(r, r);
        positive &= d > 0.0;
        *inv = 1.0 / d;
    }
    let mut sum = 0.0;
    for r in 0..N {
        for c in r + 1..N {
            let m = 0.5 * (at(r, c) + at(c, r));
            sum += (m * inv[r]) * (m * inv[c]);
        }
    }
    positive && sum <= 0.45
}

/// Whether the block of `cov` on the `kept` axes is positive definite once the axes whose row
/// and column are zero in it are left out (a variance of exactly 0 without correlation, "not
/// estimated", as some drivers publish z, roll and pitch): each such axis adds an eigenvalue
/// of exactly 0 and leaves the others to the rest, so the block is then PSD with smallest
/// eigenvalue 0, without an eigen-decomposition.
fn positive_definite_but_zero_axes(cov: &[f64; COV_LEN], kept: &[usize]) -> bool {
    let mut rest = [0usize; 6];
    let mut m = 0;
    for &i in kept {
        if kept
            .iter()
            .any(|&j| cov[i * 6 + j] != 0.0 || cov[j * 6 + i] != 0.0)
        {
            rest[m] = i;
            m += 1;
        }
    }
    m < kept.len() && positive_definite(cov, &rest[..m])
}

/// The smallest eigenvalue and the largest (at least 0) of the symmetrised block of `cov` on
/// the `kept` axes, by nalgebra's symmetric eigen-decomposition: the numbers a covariance
/// that is not positive definite reports.
fn eigenvalue_range(cov: &[f64; COV_LEN], kept: &[usize]) -> (f64, f64) {
    let block = DMatrix::from_fn(kept.len(), kept.len(), |r, c| {
        0.5 * (cov[kept[r] * 6 + kept[c]] + cov[kept[c] * 6 + kept[r]])
    });
    let eig = SymmetricEigen::new(block);
    let lo = eig
        .eigenvalues
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let hi = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    (lo, hi)
}

/// Classifies one covariance (ROS layout) and its orientation quaternion.
///
/// ```
/// use posecov::input::log::health::classify;
/// use posecov::plan::log::Issue;
/// let mut cov = [0.0; 36];
/// for (i, v) in [0.001, 0.001, 1e6, 1e6, 1e6, 0.03].iter().enumerate() { cov[i * 7] = *v; }
/// let h = classify(&cov, [0.0, 0.0, 0.0, 1.0]);
/// assert_eq!(h.issues, vec![Issue::Placeholder]);
/// assert!(h.usable());
/// assert_eq!(h.unestimated, [false, false, true, true, true, false]);
/// ```
pub fn classify(cov: &[f64; COV_LEN], orientation_xyzw: [f64; 4]) -> MessageHealth {
    with_orientation(orientation_xyzw, classify_covariance(cov), cov)
}

/// The message's health from its orientation and its covariance's classification
/// ([`classify_covariance`]): a bad orientation first, then the covariance's issues, and the
/// position trace if the message is usable.
#[inline]
pub(super) fn with_orientation(
    orientation_xyzw: [f64; 4],
    covariance: MessageHealth,
    cov: &[f64; COV_LEN],
) -> MessageHealth {
    let [x, y, z, w] = orientation_xyzw;
    // The sum as `Iterator::sum` makes it (from −0), term by term.
    let squared = -0.0 + x * x + y * y + z * z + w * w;
    let mut issues = covariance.issues;
    // Unit within 1e-3. A squared norm in [0.9981, 1.0019] is, without its root: √ is
    // monotone and correctly rounded, and √0.9981 > 0.99904, √1.0019 < 1.00095.
    let unit = (0.9981..=1.0019).contains(&squared) || {
        let norm = squared.sqrt();
        norm.is_finite() && (norm - 1.0).abs() <= 1e-3
    };
    if !unit {
        issues.push(Issue::BadOrientation);
    }
    let u = covariance.unestimated;
    // The estimated position variances' sum, from −0 as `Iterator::sum` makes it (adding −0
    // for an axis not estimated changes nothing, to the bit).
    let pick = |i: usize| if u[i] { -0.0 } else { cov[i * 7] };
    let position_trace = (!issues.any_unusable()).then(|| -0.0 + pick(0) + pick(1) + pick(2));
    MessageHealth {
        issues,
        position_trace,
        ..covariance
    }
}

/// What the covariance alone says (no orientation, no position trace): a function of its 36
/// entries, so a topic whose covariance repeats classifies it once
/// ([`TopicHealth::add`](super::TopicHealth::add)). [`clean_full_block`] decides the common
/// case in one pass, [`every_check`] the rest: the same answer either way.
#[inline]
pub(super) fn classify_covariance(cov: &[f64; COV_LEN]) -> MessageHealth {
    if clean_full_block(cov) {
        MessageHealth::CLEAN
    } else {
        every_check(cov)
    }
}

/// Whether `cov` is the common case, decided in one pass over its diagonal and upper
/// triangle: every axis estimated (0 < Σᵢᵢ < [`PLACEHOLDER`]), exactly symmetric (Σᵣ꜀ = Σ꜀ᵣ,
/// compared with `==`) and weakly correlated (Σ_{r<c} ρᵣ꜀² ≤ [`ONE_PASS_BOUND`]). Then
/// [`every_check`] finds nothing:
/// - every entry is finite: the diagonal by its range; a NaN off the diagonal is unequal to
///   its mirror, and an infinite one makes its term, so the sum, +∞;
/// - no ROS −1 marker, not all zero, no placeholder: the diagonal is positive and below
///   [`PLACEHOLDER`];
/// - symmetric: every difference is 0, below any tolerance;
/// - positive definite by [`weakly_correlated`]: ½(Σᵣ꜀ + Σ꜀ᵣ) = Σᵣ꜀ exactly, so its 15 terms
///   are these, to the bit (unless Σᵣ꜀ + Σ꜀ᵣ overflows: then |Σᵣ꜀| > 8.9e307 and its term
///   here, over variances below 1e6, is +∞). Here they are added in three chains (shorter
///   dependent chains than its one); sums of the same 15 non-negative terms in two orders
///   differ by at most 28 ε of their size, so a sum ≤ 0.449 here is < 0.45 there.
///
/// So a `true` here is [`MessageHealth::CLEAN`], and a `false` only sends the covariance to
/// every check (a unit test compares both paths on covariances of every kind).
#[inline(always)]
fn clean_full_block(cov: &[f64; COV_LEN]) -> bool {
    let diag: [f64; 6] = std::array::from_fn(|i| cov[i * 7]);
    let mut clean = diag
        .iter()
        .fold(true, |c, d| c & (*d > 0.0) & (*d < PLACEHOLDER));
    let inv = diag.map(|d| 1.0 / d);
    // Term k of the 15 goes to chain k mod 3.
    let mut sums = [0.0f64; 3];
    let mut k = 0;
    for r in 0..6 {
        for c in r + 1..6 {
            let m = cov[r * 6 + c];
            clean &= m == cov[c * 6 + r];
            sums[k % 3] += (m * inv[r]) * (m * inv[c]);
            k += 1;
        }
    }
    clean && (sums[0] + sums[1]) + sums[2] <= ONE_PASS_BOUND
}

/// The one pass's bound on Σ ρ²: below [`weakly_correlated`]'s 0.45 by far more than the
/// rounding of either sum ([`clean_full_block`]).
const ONE_PASS_BOUND: f64 = 0.449;

/// Every check of the covariance, in the order its issues are listed: not finite, ROS's −1,
/// all zero, placeholders, asymmetric, not PSD (with the smallest eigenvalue). Kept out of
/// line: most messages never come here, and the one pass stays a short function of its own.
#[cold]
#[inline(never)]
fn every_check(cov: &[f64; COV_LEN]) -> MessageHealth {
    let mut issues = Issues::default();
    // Every entry read once, without an early exit: in vectors.
    if !cov.iter().fold(true, |finite, v| finite & v.is_finite()) {
        issues.push(Issue::NonFinite);
        return MessageHealth {
            issues,
            unestimated: [false; 6],
            min_eigenvalue: None,
            position_trace: None,
        };
    }
    let diag: [f64; 6] = std::array::from_fn(|i| cov[i * 7]);
    let unestimated = diag.map(|v| v == 0.0 || v >= PLACEHOLDER);
    // The estimated axes: not a placeholder (a huge row would swamp the rounding of the rest).
    let mut axes = [0, 1, 2, 3, 4, 5];
    let mut n = 6;
    let unknown_marker = cov[0] == -1.0;
    // Positive definiteness is only asked of a symmetric block (not the −1 marker's).
    let pd_wanted = |checks: &BlockChecks| !checks.asymmetric && !unknown_marker;
    let (checks, positive_definite) = if diag.iter().all(|v| *v < PLACEHOLDER) {
        // Every axis estimated (an EKF's covariance): the block is `cov` itself, read in place.
        checks_and_pd::<6>(&|r: usize, c: usize| cov[r * 6 + c], &pd_wanted)
    } else {
        n = 0;
        for i in (0..6).filter(|&i| diag[i] < PLACEHOLDER) {
            axes[n] = i;
            n += 1;
        }
        let b = gather(cov, &axes[..n]);
        by_size!(n, checks_and_pd, &|r: usize, c: usize| b[r][c], &pd_wanted)
    };
    let kept = &axes[..n];
    if unknown_marker {
        issues.push(Issue::UnknownMarker);
    } else if n > 0 && checks.all_zero {
        issues.push(Issue::AllZero);
    }
    if PLANAR_AXES.iter().any(|&i| diag[i] >= PLACEHOLDER) {
        issues.push(Issue::PlaceholderUsedAxis);
    } else if diag.iter().any(|v| *v >= PLACEHOLDER) {
        // z, roll or pitch only: a note if the topic turns out planar, else a defect (the
        // topic's collector decides when it has seen every message).
        issues.push(Issue::Placeholder);
    }
    let mut min_eigenvalue = None;
    if checks.asymmetric {
        issues.push(Issue::Asymmetric);
    } else if n > 0 && positive_definite == Some(false) {
        // Only a block that is not positive definite needs more (most messages' are: one
        // factorisation on the stack decides; the eigen-decomposition was most of the health
        // classes' time).
        min_eigenvalue = Some(match positive_definite_but_zero_axes(cov, kept) {
            // Positive definite but for axes whose row and column are zero: their
            // eigenvalue, exactly 0, is the smallest; PSD.
            true => 0.0,
            false => {
                let (lo, hi) = eigenvalue_range(cov, kept);
                if lo < -psd_tolerance(hi) {
                    issues.push(Issue::NotPsd);
                }
                lo
            }
        });
    }
    MessageHealth {
        issues,
        unestimated,
        min_eigenvalue,
        position_trace: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diag(d: [f64; 6]) -> [f64; 36] {
        let mut c = [0.0; 36];
        for i in 0..6 {
            c[i * 7] = d[i];
        }
        c
    }
    const Q: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

    /// The one-pass decision never disagrees with every check: on random covariances of every
    /// kind (an EKF's, strongly correlated, with a NaN, an infinity, a huge entry, a mirror one
    /// bit off, a zero, negative, placeholder or just-below-placeholder variance, ROS's −1), whenever
    /// [`clean_full_block`] says clean, [`every_check`] finds exactly that; and it does decide
    /// most EKF-like ones and none of the spoilt ones.
    #[test]
    fn the_one_pass_agrees_with_every_check() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(19);
        let (mut clean, mut spoilt_clean) = (0, 0);
        for k in 0..20_000 {
            // Σ = D R D with R = I + symmetric off-diagonal of size `strength`.
            let strength = [0.05, 0.2, 0.35, 0.6][k % 4];
            let sigma: [f64; 6] = std::array::from_fn(|_| 10f64.powf(rng.random_range(-4.0..1.0)));
            let mut cov = [0.0; 36];
            for r in 0..6 {
                cov[r * 7] = sigma[r] * sigma[r];
                for c in r + 1..6 {
                    let v = rng.random_range(-strength..strength) * sigma[r] * sigma[c];
                    cov[r * 6 + c] = v;
                    cov[c * 6 + r] = v;
                }
            }
            let spoil = k % 13;
            let (r, c) = (rng.random_range(0..6), rng.random_range(0..6));
            match spoil {
                0 => cov[r * 6 + c] = f64::NAN,
                1 => cov[r * 6 + c] = f64::INFINITY,
                2 => cov[r * 6 + c] = f64::NEG_INFINITY,
                3 => cov[r * 6 + c] = 1.7e308,
                // The mirror one bit off (symmetric within the tolerance), or well off.
                4 if r != c && k % 2 == 0 => {
                    cov[r * 6 + c] = f64::from_bits(cov[r * 6 + c].to_bits() + 1)
                }
                4 if r != c => cov[r * 6 + c] += 0.1 * sigma[r] * sigma[c],
                5 => cov[r * 7] = 0.0,
                6 => cov[r * 7] = -cov[r * 7],
                7 => cov[r * 7] = [PLACEHOLDER, 1.79e308][k % 2],
                // Just below the placeholder: estimated, not spoilt.
                10 => cov[r * 7] = PLACEHOLDER * (1.0 - 1e-16),
                8 => cov[0] = -1.0,
                9 => {
                    // Two axes fully correlated: singular.
                    cov[r * 6 + (r + 1) % 6] = sigma[r] * sigma[(r + 1) % 6];
                    cov[((r + 1) % 6) * 6 + r] = sigma[r] * sigma[(r + 1) % 6];
                }
                _ => {}
            }
            if clean_full_block(&cov) {
                assert_eq!(every_check(&cov), MessageHealth::CLEAN, "{cov:?}");
                clean += 1;
                if matches!(spoil, 0..=3 | 5..=8) {
                    spoilt_clean += 1;
                }
            }
        }
        // The weakly correlated ones left unspoilt are decided in one pass (half the strengths,
        // 3/13 of the spoils: about 2 300 of the 20 000); no spoilt one is.
        assert!(clean > 2_000, "{clean}");
        assert_eq!(spoilt_clean, 0);
        // One correlation each side of the bound (ρ² = 0.4489, 0.450241): the second goes
        // to every check, which finds it positive definite by its L D Lᵀ, clean too.
        const { assert!(0.67f64 * 0.67 <= ONE_PASS_BOUND) };
        let mut c = [0.0; 36];
        for i in 0..6 {
            c[i * 7] = 1.0;
        }
        assert!(clean_full_block(&c));
        for (rho, one_pass) in [(0.67, true), (0.671, false)] {
            c[1] = rho;
            c[6] = rho;
            assert_eq!(clean_full_block(&c), one_pass);
            assert_eq!(every_check(&c), MessageHealth::CLEAN);
        }
    }

    #[test]
    fn each_case_has_its_word() {
        assert!(classify(&diag([0.1; 6]), Q).issues.is_empty());
        assert_eq!(classify(&[0.0; 36], Q).issues, vec![Issue::AllZero]);
        let mut m = diag([0.1; 6]);
        m[0] = -1.0;
        assert_eq!(classify(&m, Q).issues, vec![Issue::UnknownMarker]);
        assert_eq!(
            classify(&diag([0.1, 0.1, 1.79e308, 0.1, 0.1, 0.1]), Q).issues,
            vec![Issue::Placeholder]
        );
        assert_eq!(
            classify(&diag([1e6, 0.1, 0.1, 0.1, 0.1, 0.1]), Q).issues,
            vec![Issue::PlaceholderUsedAxis]
        );
        // Zeros on x, y, yaw with placeholders elsewhere: nothing is estimated.
        assert_eq!(
            classify(&diag([0.0, 0.0, 1e6, 1e6, 1e6, 0.0]), Q).issues,
            vec![Issue::AllZero, Issue::Placeholder]
        );
        let mut n = diag([0.1; 6]);
        n[3] = f64::NAN;
        assert_eq!(classify(&n, Q).issues, vec![Issue::NonFinite]);
        let mut a = diag([0.1; 6]);
        a[1] = 0.05;
        assert_eq!(classify(&a, Q).issues, vec![Issue::Asymmetric]);
        let mut p = diag([0.1; 6]);
        p[1] = 0.5;
        p[6] = 0.5;
        let h = classify(&p, Q);
        assert_eq!(h.issues, vec![Issue::NotPsd]);
        assert!((h.min_eigenvalue.unwrap() - (0.1 - 0.5)).abs() < 1e-12);
        assert_eq!(
            classify(&diag([0.1; 6]), [0.0, 0.0, 0.0, 2.0]).issues,
            vec![Issue::BadOrientation]
        );
    }

    #[test]
    fn zero_axes_are_psd_without_an_eigen_decomposition() {
        // z, roll and pitch published as exact zeros: positive definite on x, y and yaw, and
        // the smallest eigenvalue is the zero axes' 0 (what the eigen-decomposition gives).
        let h = classify(&diag([1e-3, 1e-3, 0.0, 0.0, 0.0, 0.03]), Q);
        assert!(h.usable() && h.issues.is_empty(), "{:?}", h.issues);
        assert_eq!(h.min_eigenvalue, Some(0.0));
        assert_eq!(h.unestimated, [false, false, true, true, true, false]);
        assert_eq!(
            eigenvalue_range(
                &diag([1e-3, 1e-3, 0.0, 0.0, 0.0, 0.03]),
                &[0, 1, 2, 3, 4, 5]
            )
            .0,
            0.0
        );
        // A zero variance correlated with another axis is no zero axis: not PSD.
        let mut c = diag([1e-3, 1e-3, 0.0, 0.0, 0.0, 0.03]);
        c[2] = 1e-4;
        c[12] = 1e-4;
        let h = classify(&c, Q);
        assert!(h.issues.contains(Issue::NotPsd), "{:?}", h.issues);
        assert!(h.min_eigenvalue.unwrap() < -1e-6);
    }

    #[test]
    fn placeholders_do_not_spoil_the_psd_check() {
        // 1.79e308 next to 1e-3: eigenvalues of the whole matrix would be rounding noise.
        let h = classify(&diag([1e-3, 1e-3, 1.79e308, 1e6, 1e6, 0.03]), Q);
        assert!(h.usable());
        // Positive definite: decided by Cholesky, no eigenvalue computed.
        assert_eq!(h.min_eigenvalue, None);
        assert_eq!(h.position_trace, Some(2e-3));
        // Singular but PSD (x and y fully correlated): the eigenvalues decide, within the
        // tolerance.
        let mut s = diag([1e-3, 1e-3, 1e6, 1e6, 1e6, 0.03]);
        s[1] = 1e-3;
        s[6] = 1e-3;
        let h = classify(&s, Q);
        assert!(!h.issues.contains(Issue::NotPsd), "{:?}", h.issues);
        assert!(h.min_eigenvalue.unwrap().abs() < 1e-15);
    }
}
