//! Named small-angle thresholds and the Taylor-safe trigonometric coefficients every group uses.
//!
//! Each coefficient below is written once, in closed form above [`SMALL_ANGLE`] and as a
//! Taylor series through θ⁶ below it. Below θ = 0.1 the first omitted Taylor term is under
//! 1e-15 relative; above it the worst closed form, (θ² + 2 cos θ − 2)/(2θ⁴), loses at most
//! ~24 ε/θ⁴ ≈ 3e-11 relative to cancellation (and far less as θ grows).

/// Below this angle (radians) the coefficients switch from closed form to Taylor series.
pub const SMALL_ANGLE: f64 = 0.1;

/// sin θ / θ.
///
/// ```
/// use posecov::lie::series::sinc;
/// assert!((sinc(0.5) - 0.5f64.sin() / 0.5).abs() < 1e-15);
/// assert_eq!(sinc(0.0), 1.0);
/// ```
#[inline]
pub fn sinc(theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        sinc_taylor(theta)
    } else {
        theta.sin() / theta
    }
}

/// Taylor series of sin θ / θ through θ⁶ (nested form): the branch of [`sinc`] below
/// [`SMALL_ANGLE`].
#[inline]
pub(crate) fn sinc_taylor(theta: f64) -> f64 {
    let t2 = theta * theta;
    1.0 - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0))
}

/// sin θ / θ from θ and its already-computed `sin_theta` (no trigonometry here): the same
/// value as [`sinc`] when `sin_theta` is `theta.sin()`; Taylor branch below [`SMALL_ANGLE`].
///
/// ```
/// use posecov::lie::series::{sinc, sinc_from_sin};
/// for t in [0.0, 0.05, 0.1, 1.0, 3.0] {
///     assert_eq!(sinc_from_sin(t, t.sin()), sinc(t));
/// }
/// ```
#[inline]
pub fn sinc_from_sin(theta: f64, sin_theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        sinc_taylor(theta)
    } else {
        sin_theta / theta
    }
}

/// A(θ) = (1 − cos θ) / θ², the coefficient of φ^ in the SO(3) Jacobians (Solà et al. 2018, eq. 143).
///
/// ```
/// use posecov::lie::series::one_minus_cos_by_theta2 as a;
/// assert!((a(1.0) - (1.0 - 1f64.cos())).abs() < 1e-15);
/// assert_eq!(a(0.0), 0.5);
/// ```
#[inline]
pub fn one_minus_cos_by_theta2(theta: f64) -> f64 {
    one_minus_cos_by_theta2_from_half_sin(theta, (0.5 * theta).sin())
}

/// A(θ) = (1 − cos θ) / θ² from θ and its already-computed `sin_half_theta` = sin(θ/2), using
/// 1 − cos θ = 2 sin²(θ/2) (no cancellation; Solà et al. 2018, eq. 143 for A). The same value
/// as [`one_minus_cos_by_theta2`], which calls it; Taylor branch below [`SMALL_ANGLE`].
///
/// ```
/// use posecov::lie::series::{one_minus_cos_by_theta2, one_minus_cos_by_theta2_from_half_sin};
/// for t in [0.0, 0.05, 0.1, 1.0, 3.0] {
///     assert_eq!(one_minus_cos_by_theta2_from_half_sin(t, (0.5 * t).sin()), one_minus_cos_by_theta2(t));
/// }
/// ```
#[inline]
pub fn one_minus_cos_by_theta2_from_half_sin(theta: f64, sin_half_theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        one_minus_cos_by_theta2_taylor(theta)
    } else {
        2.0 * sin_half_theta * sin_half_theta / (theta * theta)
    }
}

/// Taylor series of (1 − cos θ) / θ² through θ⁶: the branch of [`one_minus_cos_by_theta2`]
/// below [`SMALL_ANGLE`].
#[inline]
pub(crate) fn one_minus_cos_by_theta2_taylor(theta: f64) -> f64 {
    let t2 = theta * theta;
    0.5 - t2 / 24.0 + t2 * t2 / 720.0 - t2 * t2 * t2 / 40320.0
}

/// B(θ) = (θ − sin θ) / θ³, the coefficient of φ^² in the SO(3) Jacobians (Solà et al. 2018, eq. 143).
///
/// ```
/// use posecov::lie::series::theta_minus_sin_by_theta3 as b;
/// assert!((b(1.0) - (1.0 - 1f64.sin())).abs() < 1e-15);
/// assert!((b(0.0) - 1.0 / 6.0).abs() < 1e-16);
/// ```
#[inline]
pub fn theta_minus_sin_by_theta3(theta: f64) -> f64 {
    theta_minus_sin_by_theta3_from_sin(theta, theta.sin())
}

/// B(θ) = (θ − sin θ) / θ³ from θ and its already-computed `sin_theta` (Solà et al. 2018,
/// eq. 143 for B); the same value as [`theta_minus_sin_by_theta3`], which calls it. Taylor
/// branch below [`SMALL_ANGLE`], where θ − sin θ ≈ θ³/6 cancels; above it an absolute error δ
/// in `sin_theta` becomes a relative error ≈ 6δ/θ³ in B. [`Se3::exp`](crate::lie::Se3) uses
/// sin θ = 2 sin(θ/2) cos(θ/2) (δ ≲ 2 ulp(sin θ), against ½ ulp for `theta.sin()`): ≲ 2e-13
/// relative in B at θ = 0.1 and less above; B multiplies θ×(θ×ρ), |θ×(θ×ρ)| ≤ θ²|ρ|, so the
/// translation moves by ≲ 4e-16 |ρ| (B θ² ≈ 1.7e-3 at θ = 0.1), a few ulps of ρ.
///
/// ```
/// use posecov::lie::series::{theta_minus_sin_by_theta3, theta_minus_sin_by_theta3_from_sin};
/// for t in [0.0, 0.05, 0.1, 1.0, 3.0] {
///     assert_eq!(theta_minus_sin_by_theta3_from_sin(t, t.sin()), theta_minus_sin_by_theta3(t));
/// }
/// ```
#[inline]
pub fn theta_minus_sin_by_theta3_from_sin(theta: f64, sin_theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        theta_minus_sin_by_theta3_taylor(theta)
    } else {
        (theta - sin_theta) / (theta * theta * theta)
    }
}

/// Taylor series of (θ − sin θ) / θ³ through θ⁶: the branch of [`theta_minus_sin_by_theta3`]
/// below [`SMALL_ANGLE`].
#[inline]
pub(crate) fn theta_minus_sin_by_theta3_taylor(theta: f64) -> f64 {
    let t2 = theta * theta;
    1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0 - t2 * t2 * t2 / 362_880.0
}

/// C(θ) = 1/θ² − cot(θ/2) / (2θ), the coefficient of φ^² in Jr⁻¹ and Jl⁻¹ of SO(3)
/// (Solà et al. 2018, eq. 144; Barfoot 2017 eq. 7.77 writes it with (1 + cos θ) / (2θ sin θ),
/// which is 0/0 at θ = π; the half-angle form is finite there).
///
/// ```
/// use posecov::lie::series::jinv_coefficient as c;
/// let t: f64 = 1.0;
/// assert!((c(t) - (1.0 / (t * t) - (1.0 + t.cos()) / (2.0 * t * t.sin()))).abs() < 1e-15);
/// assert!((c(0.0) - 1.0 / 12.0).abs() < 1e-16);
/// assert!((c(std::f64::consts::PI) - 1.0 / (std::f64::consts::PI.powi(2))).abs() < 1e-15);
/// ```
#[inline]
pub fn jinv_coefficient(theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        let t2 = theta * theta;
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2 * t2 * t2 / 1_209_600.0
    } else {
        let half = 0.5 * theta;
        1.0 / (theta * theta) - half.cos() / (half.sin() * 2.0 * theta)
    }
}

/// (θ² + 2 cos θ − 2) / (2θ⁴), the second coefficient of Q(ρ, θ) (Barfoot & Furgale 2014, eq. 102).
///
/// ```
/// use posecov::lie::series::q_coefficient_2 as c2;
/// let t: f64 = 1.0;
/// assert!((c2(t) - (t * t + 2.0 * t.cos() - 2.0) / 2.0).abs() < 1e-15);
/// assert!((c2(0.0) - 1.0 / 24.0).abs() < 1e-16);
/// ```
#[inline]
pub fn q_coefficient_2(theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        let t2 = theta * theta;
        1.0 / 24.0 - t2 / 720.0 + t2 * t2 / 40320.0 - t2 * t2 * t2 / 3_628_800.0
    } else {
        let t2 = theta * theta;
        (t2 + 2.0 * theta.cos() - 2.0) / (2.0 * t2 * t2)
    }
}

/// (2θ − 3 sin θ + θ cos θ) / (2θ⁵), the third coefficient of Q(ρ, θ) (Barfoot & Furgale 2014, eq. 102).
///
/// ```
/// use posecov::lie::series::q_coefficient_3 as c3;
/// let t: f64 = 1.0;
/// assert!((c3(t) - (2.0 * t - 3.0 * t.sin() + t * t.cos()) / 2.0).abs() < 1e-15);
/// assert!((c3(0.0) - 1.0 / 120.0).abs() < 1e-16);
/// ```
#[inline]
pub fn q_coefficient_3(theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        let t2 = theta * theta;
        1.0 / 120.0 - t2 / 2520.0 + t2 * t2 / 120_960.0 - t2 * t2 * t2 / 9_979_200.0
    } else {
        let t2 = theta * theta;
        (2.0 * theta - 3.0 * theta.sin() + theta * theta.cos()) / (2.0 * t2 * t2 * theta)
    }
}

/// h(θ) = (θ/2) cot(θ/2), the diagonal of the SE(2) V(θ)⁻¹ (Solà et al. 2018, eq. 158),
/// from θ and its already-computed cos θ and sin θ: (θ/2) sin θ / (1 − cos θ) above
/// [`SMALL_ANGLE`] (0 at θ = ±π, no 0/0 there), 1 − θ²/12 − θ⁴/720 − θ⁶/30240 below.
///
/// ```
/// use posecov::lie::series::half_theta_cot_half_theta as h;
/// let t: f64 = 1.0;
/// assert!((h(t, t.cos(), t.sin()) - 0.5 / (0.5f64).tan()).abs() < 1e-15);
/// assert_eq!(h(0.0, 1.0, 0.0), 1.0);
/// assert_eq!(h(std::f64::consts::PI, -1.0, 0.0), 0.0);
/// ```
#[inline]
pub fn half_theta_cot_half_theta(theta: f64, cos_theta: f64, sin_theta: f64) -> f64 {
    if theta.abs() < SMALL_ANGLE {
        let t2 = theta * theta;
        1.0 - t2 / 12.0 - t2 * t2 / 720.0 - t2 * t2 * t2 / 30240.0
    } else {
        0.5 * theta * sin_theta / (1.0 - cos_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both branches agree at the switch point, so no coefficient jumps there.
    #[test]
    fn branches_meet_at_the_threshold() {
        let below = SMALL_ANGLE * (1.0 - 1e-12);
        let above = SMALL_ANGLE * (1.0 + 1e-12);
        let h = |t: f64| half_theta_cot_half_theta(t, t.cos(), t.sin());
        for f in [
            h,
            sinc,
            one_minus_cos_by_theta2,
            theta_minus_sin_by_theta3,
            jinv_coefficient,
            q_coefficient_2,
            q_coefficient_3,
        ] {
            let (a, b) = (f(below), f(above));
            assert!((a - b).abs() < 1e-9 * a.abs(), "{a} vs {b}");
        }
    }
}
