//! What a g2o edge's information matrix means in posecov's terms, and what GTSAM makes of
//! it ([CONVENTIONS §10]).
//!
//! An edge (i, j) with measurement Z and information Ω says X_j ≈ X_i · Z. g2o's error is
//! computed from Δ = Z⁻¹ · X_i⁻¹ · X_j:
//! - `EDGE_SE2`: e = (Δ.x, Δ.y, Δ.θ), the translation of Δ in the frame of X_i · Z and its
//!   angle;
//! - `EDGE_SE3:QUAT`: e = (Δ.t, Δ.q.xyz), the translation and the vector part of Δ's unit
//!   quaternion (w ≥ 0).
//!
//! posecov writes the same uncertainty as X_j = X_i · Z · Exp(ξ), ξ = [ρ; θ] (right
//! perturbation, body frame of X_j, [CONVENTIONS §1–2]). Then Δ = Exp(ξ), and to first order
//! e = J ξ with J = ∂e/∂ξ at ξ = 0:
//! - SE(2): J = I (Δ.t = V(θ) ρ ≈ ρ, Δ.θ = θ), so Σ_ξ = Ω⁻¹;
//! - SE(3): J = diag(I₃, ½ I₃) (Δ.t = V(θ) ρ ≈ ρ; Δ.q.xyz = sin(|θ|/2) θ/|θ| ≈ θ/2), so
//!   Σ_ξ = J⁻¹ Ω⁻¹ J⁻ᵀ = D Ω⁻¹ D with D = diag(1, 1, 1, 2, 2, 2): the rotation block ×4, the
//!   translation–rotation block ×2, the translation block as it is.
//!
//! GTSAM's `readG2o` (`gtsam/slam/dataset.cpp`, `ParseMeasurement<Pose3>`) reads the 21
//! numbers as the upper triangle of Ω (mirrored), swaps the blocks into its own rotation-first
//! order — Ω_gtsam = [[Ω_θθ, Ω_θt], [Ω_tθ, Ω_tt]] — and makes
//! `noiseModel::Gaussian::Information(Ω_gtsam)` for a `BetweenFactor<Pose3>`, whose error is
//! Log(Z⁻¹ X_i⁻¹ X_j) in [ω; v], right perturbation. It applies no factor: GTSAM reads the
//! quaternion block as information over the rotation vector itself, so its rotation σ is half
//! of g2o's (its Σ is Ω⁻¹ reordered, [`se3_cov_as_gtsam_reads`]). For `EDGE_SE2` both agree
//! (`NoiseFormatG2O`, order x, y, θ = GTSAM's Pose2 tangent order).
//!
//! [CONVENTIONS §10]: crate::conventions#10-pose-graphs-g2o-and-gtsam
//! [CONVENTIONS §1–2]: crate::conventions

use nalgebra::{Matrix6, SMatrix};

use crate::interop::cov_to_rotation_first;

/// The symmetric matrix whose upper triangle is `upper`, row by row
/// (m₀₀ m₀₁ … m₀ₙ m₁₁ … mₙₙ), as g2o and GTSAM store information matrices.
///
/// ```
/// use posecov::input::graph::convention::from_upper_triangle;
/// let m = from_upper_triangle::<3>(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
/// assert_eq!(m, nalgebra::Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 5.0, 3.0, 5.0, 6.0));
/// ```
pub fn from_upper_triangle<const N: usize>(upper: &[f64]) -> SMatrix<f64, N, N> {
    let mut m = SMatrix::<f64, N, N>::zeros();
    let mut values = upper.iter().copied();
    for row in 0..N {
        for col in row..N {
            let v = values.next().unwrap_or(0.0);
            m[(row, col)] = v;
            m[(col, row)] = v;
        }
    }
    m
}

/// The name of upper-triangle entry `k` of an information matrix over `axes`, e.g. `I(x,θ)`.
///
/// ```
/// use posecov::input::graph::convention::upper_triangle_name;
/// assert_eq!(upper_triangle_name(&["x", "y", "θ"], 2), "I(x,θ)");
/// assert_eq!(upper_triangle_name(&["x", "y", "θ"], 5), "I(θ,θ)");
/// ```
pub fn upper_triangle_name(axes: &[&str], k: usize) -> String {
    let n = axes.len();
    let mut index = 0;
    for row in 0..n {
        for col in row..n {
            if index == k {
                return format!("I({},{})", axes[row], axes[col]);
            }
            index += 1;
        }
    }
    format!("I[{k}]")
}

/// D = diag(1, 1, 1, 2, 2, 2) = J⁻¹ for J = ∂(t, q.xyz)/∂[ρ; θ] at 0 (see the module docs;
/// the one rule is [`half_angle_scale`](crate::plan::graph::half_angle_scale)).
fn half_angle_scale() -> Matrix6<f64> {
    Matrix6::from_fn(|r, c| {
        if r == c {
            crate::plan::graph::half_angle_scale::<6>(r)
        } else {
            0.0
        }
    })
}

/// posecov's right-perturbation covariance Σ_ξ over [ρ; θ] of an `EDGE_SE3:QUAT` whose error
/// covariance (over g2o's (t, q.xyz)) is `cov_error` = Ω⁻¹: Σ_ξ = D Ω⁻¹ D,
/// D = diag(1, 1, 1, 2, 2, 2).
///
/// ```
/// use posecov::input::graph::convention::se3_cov_from_g2o_error_cov;
/// use nalgebra::Matrix6;
/// let cov = se3_cov_from_g2o_error_cov(&(Matrix6::identity() * 1e-4));
/// assert_eq!(cov[(0, 0)], 1e-4);
/// assert_eq!(cov[(3, 3)], 4e-4); // σ_θ = 2 σ_q
/// ```
pub fn se3_cov_from_g2o_error_cov(cov_error: &Matrix6<f64>) -> Matrix6<f64> {
    let d = half_angle_scale();
    d * cov_error * d
}

/// The information over posecov's [ρ; θ] of an `EDGE_SE3:QUAT` whose information over g2o's
/// (t, q.xyz) is `information` = Ω: Λ = (D Ω⁻¹ D)⁻¹ = D⁻¹ Ω D⁻¹, D = diag(1, 1, 1, 2, 2, 2)
/// (the inverse of [`se3_cov_from_g2o_error_cov`] of Ω⁻¹).
///
/// ```
/// use posecov::input::graph::convention::se3_information_from_g2o;
/// use nalgebra::Matrix6;
/// let lambda = se3_information_from_g2o(&(Matrix6::identity() * 1e4));
/// assert_eq!(lambda[(0, 0)], 1e4);
/// assert_eq!(lambda[(3, 3)], 2.5e3); // σ_θ = 2 σ_q: a quarter of the information
/// ```
pub fn se3_information_from_g2o(information: &Matrix6<f64>) -> Matrix6<f64> {
    let d = half_angle_scale();
    Matrix6::from_fn(|r, c| information[(r, c)] / (d[(r, r)] * d[(c, c)]))
}

/// The covariance GTSAM's `readG2o` gives an `EDGE_SE3:QUAT` of information `information`
/// (g2o order), in GTSAM's own order [ω; v]: (P Ω Pᵀ)⁻¹ with P swapping the translation and
/// rotation blocks, no half-angle factor. `None` if Ω is not invertible.
///
/// ```
/// use posecov::input::graph::convention::se3_cov_as_gtsam_reads;
/// use nalgebra::Matrix6;
/// let info = Matrix6::from_diagonal(&nalgebra::Vector6::new(1.0, 1.0, 1.0, 4.0, 4.0, 4.0));
/// let cov = se3_cov_as_gtsam_reads(&info).unwrap();
/// assert!((cov[(0, 0)] - 0.25).abs() < 1e-15); // rotation first
/// assert!((cov[(3, 3)] - 1.0).abs() < 1e-15);
/// ```
pub fn se3_cov_as_gtsam_reads(information: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    // Ω_gtsam = [[Ω_θθ, Ω_θt], [Ω_tθ, Ω_tt]] (dataset.cpp, ParseMeasurement<Pose3>): the one
    // rotation-first permutation, applied to the information.
    cov_to_rotation_first(information)
        .cholesky()
        .map(|c| c.inverse())
}
