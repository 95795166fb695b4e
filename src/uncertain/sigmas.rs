//! Uncertain poses from standard deviations, and the Mahalanobis distance: Σ⁻¹ of a valid,
//! non-singular covariance ([`Information`]), taken with the decomposition that validated it.

use super::{Side, UncertainPose, validate};
use crate::error::{Error, Result, check_finite};
use crate::lie::{LieGroup, Tangent, TangentMatrix};

impl<G: LieGroup<N>, const N: usize> UncertainPose<G, N> {
    /// A pose with independent tangent components: Σ = diag(σ₁², …, σ_N²), σ in the tangent
    /// order of the [conventions](crate#conventions) (SE(3): σ_ρx, σ_ρy, σ_ρz, σ_θx, σ_θy,
    /// σ_θz; SE(2): σ_ρx, σ_ρy, σ_θ), on `side`. Each σ must be finite and ≥ 0.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.2, 0.05], Side::Right).unwrap();
    /// assert!((p.cov()[(1, 1)] - 0.04).abs() < 1e-15);
    /// assert!(UncertainPose::try_from_std_devs(Se2::identity(), [0.1, -0.2, 0.05], Side::Right).is_err());
    /// ```
    pub fn try_from_std_devs(mean: G, std_devs: [f64; N], side: Side) -> Result<Self> {
        check_finite("standard deviations", std_devs)?;
        if let Some(&sigma) = std_devs.iter().find(|s| **s < 0.0) {
            return Err(Error::OutOfRange {
                what: "standard deviation",
                value: sigma,
                expected: "σ ≥ 0",
            });
        }
        let variances = nalgebra::SVector::<f64, N>::from_iterator(std_devs.iter().map(|s| s * s));
        Ok(Self::new_unchecked(
            mean,
            TangentMatrix::<N>::from_diagonal(&variances),
            side,
        ))
    }

    /// The tangent perturbation ε that takes the mean to `x` on this pose's side:
    /// right ε = Log(μ⁻¹ x) (x = μ · Exp ε), left ε = Log(x μ⁻¹) (x = Exp ε · μ).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::UncertainPose;
    /// use nalgebra::Vector3;
    /// let p = UncertainPose::certain(Se2::from_xy_theta(1.0, 0.0, 0.3));
    /// let eps = Vector3::new(0.1, -0.2, 0.05);
    /// assert!((p.perturbation_of(&p.mean().rplus(&eps)) - eps).norm() < 1e-14);
    /// ```
    pub fn perturbation_of(&self, x: &G) -> Tangent<N> {
        match self.side {
            Side::Right => x.rminus(&self.mean),
            Side::Left => x.lminus(&self.mean),
        }
    }

    /// Squared Mahalanobis distance of `x` from this distribution, d² = εᵀ Σ⁻¹ ε with ε from
    /// [`perturbation_of`](Self::perturbation_of) (N degrees of freedom: compare with
    /// [`chi2_radius`](super::chi2_radius)`(p, N)²`). The value is the same on either side (Ad is linear).
    /// Errors: [`Error::SingularCovariance`] when Σ is singular (see [`try_inverse_covariance`]).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// use nalgebra::Vector3;
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.1], Side::Right).unwrap();
    /// let x = Se2::exp(&Vector3::new(0.2, 0.0, 0.0));
    /// assert!((p.mahalanobis_squared(&x).unwrap() - 4.0).abs() < 1e-12);
    /// assert!(UncertainPose::certain(Se2::identity()).mahalanobis_squared(&x).is_err());
    /// ```
    pub fn mahalanobis_squared(&self, x: &G) -> Result<f64> {
        let info = try_inverse_covariance("pose covariance", &self.cov)?;
        let eps = self.perturbation_of(x);
        Ok((eps.transpose() * info * eps)[(0, 0)])
    }

    /// Mahalanobis distance d = √(εᵀ Σ⁻¹ ε), see [`mahalanobis_squared`](Self::mahalanobis_squared).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap();
    /// assert!((p.mahalanobis(&So2::from_angle(-0.3)).unwrap() - 3.0).abs() < 1e-12);
    /// ```
    pub fn mahalanobis(&self, x: &G) -> Result<f64> {
        self.mahalanobis_squared(x).map(f64::sqrt)
    }
}

/// Below this ratio λ_min / λ_max a covariance counts as singular and is not inverted.
pub const SINGULAR_TOLERANCE: f64 = 1e-12;

/// The information matrix Σ⁻¹ of a covariance, through its eigen-decomposition
/// Σ = V diag(λ) Vᵀ → Σ⁻¹ = V diag(1/λ) Vᵀ. Σ is validated first
/// ([`validate_covariance`](super::validate_covariance)); [`Error::SingularCovariance`] when λ_min ≤
/// `SINGULAR_TOLERANCE` · λ_max (including Σ = 0).
///
/// ```
/// use posecov::uncertain::try_inverse_covariance;
/// use nalgebra::Matrix2;
/// let info = try_inverse_covariance("Σ", &Matrix2::new(4.0, 0.0, 0.0, 0.25)).unwrap();
/// assert!((info - Matrix2::new(0.25, 0.0, 0.0, 4.0)).norm() < 1e-14);
/// assert!(try_inverse_covariance("Σ", &Matrix2::new(1.0, 1.0, 1.0, 1.0)).is_err());
/// ```
pub fn try_inverse_covariance<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<TangentMatrix<N>> {
    // The decomposition that validated ½(Σ + Σᵀ) is the one inverted (one, not two).
    let (_, eigen) = validate::validated_eigen(what, cov, true)?;
    information(what, eigen)
}

/// Σ⁻¹ of a valid, non-singular covariance, as a quadratic form εᵀ Σ⁻¹ ε is taken with it
/// ([`try_information`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Information<const N: usize> {
    /// Σ = L Lᵀ (L lower triangular), for a well-conditioned Σ: εᵀ Σ⁻¹ ε = ‖L⁻¹ ε‖².
    Cholesky(TangentMatrix<N>),
    /// Σ⁻¹ = V diag(1/λ) Vᵀ from the eigen-decomposition that validated Σ.
    Inverse(TangentMatrix<N>),
}

impl<const N: usize> Information<N> {
    /// εᵀ Σ⁻¹ ε (a squared Mahalanobis distance, an NEES).
    ///
    /// ```
    /// use posecov::uncertain::try_information;
    /// use nalgebra::{Matrix2, Vector2};
    /// let info = try_information("Σ", &Matrix2::new(4.0, 0.0, 0.0, 0.25)).unwrap();
    /// assert_eq!(info.quadratic(&Vector2::new(2.0, 1.0)), 5.0);
    /// ```
    pub fn quadratic(&self, e: &Tangent<N>) -> f64 {
        match self {
            Information::Cholesky(l) => l.solve_lower_triangular_unchecked(e).norm_squared(),
            Information::Inverse(info) => (e.transpose() * info * e)[0],
        }
    }

    /// Σ⁻¹ as a matrix.
    pub fn matrix(&self) -> TangentMatrix<N> {
        match self {
            Information::Cholesky(l) => {
                let l_inverse = l.solve_lower_triangular_unchecked(&TangentMatrix::<N>::identity());
                l_inverse.transpose() * l_inverse
            }
            Information::Inverse(info) => *info,
        }
    }
}

/// Σ⁻¹ of a covariance, validated first ([`validate_covariance`](super::validate_covariance)), as a quadratic form is
/// taken with it: for a well-conditioned Σ (tr Σ · tr Σ⁻¹ ≤ 10⁸, which bounds λ_max / λ_min)
/// its Cholesky factor, which proves Σ positive definite and far from singular without its
/// eigenvalues; otherwise [`try_inverse_covariance`]'s, which decides through them (the same
/// decisions either way: 10⁸ is four orders of magnitude inside `SINGULAR_TOLERANCE`).
///
/// ```
/// use posecov::uncertain::{Information, try_information};
/// use nalgebra::Matrix2;
/// let info = try_information("Σ", &Matrix2::new(4.0, 1.0, 1.0, 2.0)).unwrap();
/// assert!(matches!(info, Information::Cholesky(_)));
/// assert!((info.matrix() * Matrix2::new(4.0, 1.0, 1.0, 2.0) - Matrix2::identity()).norm() < 1e-15);
/// // λ_max / λ_min = 1e10: decided by the eigenvalues (not singular: 1e10 < 1e12).
/// assert!(matches!(try_information("Σ", &Matrix2::new(1.0, 0.0, 0.0, 1e-10)), Ok(Information::Inverse(_))));
/// assert!(try_information("Σ", &Matrix2::new(1.0, 1.0, 1.0, 1.0)).is_err());
/// ```
pub fn try_information<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<Information<N>> {
    validated_information(what, cov).and_then(|(_, information)| information)
}

/// ½(Σ + Σᵀ) validated and [`try_information`]'s Σ⁻¹ (`Err` inside: Σ is singular).
pub(super) fn validated_information<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<(TangentMatrix<N>, Result<Information<N>>)> {
    if let Some((sym, l)) = validate::well_conditioned_factor(what, cov) {
        return Ok((sym, Ok(Information::Cholesky(l))));
    }
    let (sym, eigen) = validate::validated_eigen(what, cov, true)?;
    Ok((sym, information(what, eigen).map(Information::Inverse)))
}

/// Σ⁻¹ = V diag(1/λ) Vᵀ from the decomposition that validated Σ (`None`: a 0 × 0 Σ), or
/// [`Error::SingularCovariance`].
fn information<const N: usize>(
    what: &'static str,
    eigen: Option<validate::Eigen<N>>,
) -> Result<TangentMatrix<N>> {
    let singular = |min_eigenvalue| Error::SingularCovariance {
        what,
        min_eigenvalue,
    };
    // Only a 0 × 0 Σ has no decomposition: nothing to invert.
    let eigen = eigen.ok_or_else(|| singular(0.0))?;
    let (min_eigenvalue, max_eigenvalue) = (eigen.values.min(), eigen.values.max());
    if max_eigenvalue <= 0.0 || min_eigenvalue <= SINGULAR_TOLERANCE * max_eigenvalue {
        return Err(singular(min_eigenvalue));
    }
    let v = &eigen.vectors;
    let inverse_values = eigen.values.map(|l| 1.0 / l);
    let info = v * TangentMatrix::<N>::from_diagonal(&inverse_values) * v.transpose();
    Ok((info + info.transpose()) * 0.5)
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix6, Vector6};
    use rand::{Rng, SeedableRng};

    use super::*;

    /// The Cholesky path decides as the eigenvalues do (valid, singular or not) and gives the
    /// same quadratic forms, for condition numbers from 1 to 10¹⁶ and for matrices with a
    /// slightly negative eigenvalue; it is taken for the well-conditioned ones only.
    #[test]
    fn information_decides_as_the_eigenvalues_do() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let (mut factored, mut decomposed) = (0, 0);
        for k in 0..2000 {
            let q = Matrix6::from_fn(|_, _| rng.random_range(-1.0..1.0))
                .qr()
                .q();
            let log_kappa = f64::from(k % 17);
            let mut values = Vector6::from_fn(|i, _| {
                let t = if i == 0 {
                    0.0
                } else {
                    rng.random_range(0.0..1.0)
                };
                10f64.powf(-log_kappa * t)
            });
            values[5] = 10f64.powf(-log_kappa);
            if k % 23 == 0 {
                values[5] = -1e-11;
            }
            let scale = 10f64.powf(rng.random_range(-6.0..6.0));
            let cov = q * Matrix6::from_diagonal(&values) * q.transpose() * scale;
            let e = Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let by_eigen = try_inverse_covariance("Σ", &cov);
            let by_factor = try_information("Σ", &cov);
            assert_eq!(by_factor.is_ok(), by_eigen.is_ok(), "{k}: {by_eigen:?}");
            let (Ok(info), Ok(inverse)) = (by_factor, by_eigen) else {
                continue;
            };
            match info {
                Information::Cholesky(_) => factored += 1,
                Information::Inverse(_) => decomposed += 1,
            }
            if log_kappa <= 8.0 {
                let (a, b) = (info.quadratic(&e), (e.transpose() * inverse * e)[0]);
                assert!((a - b).abs() <= 1e-6 * b, "{k}: {a} vs {b}");
            }
        }
        assert!(
            factored > 500 && decomposed > 500,
            "{factored} {decomposed}"
        );
    }
}
