//! Validation of covariances: finite, symmetric and positive semi-definite within the one
//! pair of tolerances every stage uses (files, evaluation, the health of robot logs).
//!
//! The one symmetry and PSD rule (`symmetry_tolerance`, `psd_tolerance`) that files,
//! evaluation and the health of robot logs share.

use nalgebra::allocator::Allocator;
use nalgebra::{
    Const, DMatrix, DefaultAllocator, DimDiff, DimSub, Dyn, OMatrix, SVector, SymmetricEigen, U1,
};

use crate::error::{Error, Result, check_finite};
use crate::lie::TangentMatrix;

/// Tolerance on |Σᵢⱼ − Σⱼᵢ|, relative to max(1, max |Σ|): inputs typed with a few decimals or
/// produced by f64 arithmetic pass; a transposed entry does not.
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// Allowance for round-off in the positive-semi-definite check: the smallest eigenvalue of Σ
/// may be as low as −`PSD_TOLERANCE` · max(1, λ_max) and still be accepted (as 0).
pub const PSD_TOLERANCE: f64 = 1e-12;

/// The asymmetry |Σᵢⱼ − Σⱼᵢ| accepted in a covariance whose largest magnitude is `scale`:
/// [`SYMMETRY_TOLERANCE`] · max(1, scale). The one rule for files, evaluation and the health
/// of robot logs.
///
/// ```
/// use posecov::uncertain::symmetry_tolerance;
/// assert_eq!(symmetry_tolerance(0.01), 1e-9);
/// assert!((symmetry_tolerance(100.0) - 1e-7).abs() < 1e-20);
/// ```
pub fn symmetry_tolerance(scale: f64) -> f64 {
    SYMMETRY_TOLERANCE * scale.max(1.0)
}

/// How far below zero the smallest eigenvalue of a symmetric matrix whose largest eigenvalue
/// is `largest` may lie and the matrix still count as positive semi-definite:
/// [`PSD_TOLERANCE`] · max(1, λ_max). The one rule for files, evaluation and the health of
/// robot logs.
///
/// ```
/// use posecov::uncertain::psd_tolerance;
/// assert_eq!(psd_tolerance(0.5), 1e-12);
/// assert_eq!(psd_tolerance(1e6), 1e-6);
/// ```
pub fn psd_tolerance(largest: f64) -> f64 {
    PSD_TOLERANCE * largest.max(1.0)
}

/// Validates a covariance: finite, symmetric within [`SYMMETRY_TOLERANCE`], positive
/// semi-definite by its eigenvalues within [`PSD_TOLERANCE`]. Returns the symmetrised matrix
/// ½(Σ + Σᵀ).
///
/// ```
/// use posecov::uncertain::validate_covariance;
/// use nalgebra::Matrix2;
/// assert!(validate_covariance("Σ", &Matrix2::new(1.0, 0.5, 0.5, 1.0)).is_ok());
/// assert!(validate_covariance("Σ", &Matrix2::new(1.0, 2.0, 2.0, 1.0)).is_err()); // eigenvalue −1
/// assert!(validate_covariance("Σ", &Matrix2::new(1.0, 0.5, 0.4, 1.0)).is_err()); // asymmetric
/// ```
pub fn validate_covariance<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Result<TangentMatrix<N>> {
    validated_eigen(what, cov, false).map(|(sym, _)| sym)
}

/// [`validate_covariance`] for a matrix whose size is known only at run time (a joint
/// covariance of several poses): square, finite, symmetric within [`SYMMETRY_TOLERANCE`],
/// positive semi-definite within [`PSD_TOLERANCE`]. Returns ½(Σ + Σᵀ).
///
/// ```
/// use posecov::uncertain::validate_covariance_dyn;
/// use nalgebra::DMatrix;
/// assert!(validate_covariance_dyn("joint", &DMatrix::<f64>::identity(4, 4)).is_ok());
/// assert!(validate_covariance_dyn("joint", &DMatrix::<f64>::identity(4, 3)).is_err()); // not square
/// ```
pub fn validate_covariance_dyn(what: &'static str, cov: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    decomposed(what, cov, false).map(|(sym, _)| sym)
}

/// The eigen-decomposition ½(Σ + Σᵀ) = V diag(λ) Vᵀ of a validated N × N covariance.
pub(super) struct Eigen<const N: usize> {
    /// λ, in nalgebra's order.
    pub(super) values: SVector<f64, N>,
    /// V, one eigenvector per column.
    pub(super) vectors: TangentMatrix<N>,
}

/// ½(Σ + Σᵀ) and, when asked for, its eigen-decomposition.
pub(super) type Validated<const N: usize> = (TangentMatrix<N>, Option<Eigen<N>>);

/// [`validate_covariance`]; with `vectors`, also handing back the eigen-decomposition of
/// ½(Σ + Σᵀ) that decided positive semi-definiteness (`None` for a 0 × 0 matrix, or without
/// `vectors`), so that [`try_inverse_covariance`](super::try_inverse_covariance) inverts
/// through it instead of decomposing the same matrix again. Without `vectors` only the
/// eigenvalues are computed (the same values: nalgebra's QR sweeps do not depend on the
/// eigenvectors they accumulate).
///
/// nalgebra's decompositions take their size as a type: the sizes of the groups (1, 2, 3, 6)
/// run as that fixed size, on the stack (the same operations in the same order as at run-time
/// size, so the same bits, without a heap matrix per call); any other N at run-time size.
pub(super) fn validated_eigen<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
    vectors: bool,
) -> Result<Validated<N>> {
    match N {
        1 => in_size(what, cov, vectors, Const::<1>),
        2 => in_size(what, cov, vectors, Const::<2>),
        3 => in_size(what, cov, vectors, Const::<3>),
        6 => in_size(what, cov, vectors, Const::<6>),
        _ => in_size(what, cov, vectors, Dyn(N)),
    }
}

/// [`validated_eigen`] run in the size `dim` (= N).
fn in_size<D, const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
    vectors: bool,
    dim: D,
) -> Result<Validated<N>>
where
    D: DimSub<U1>,
    DefaultAllocator: Allocator<D, D> + Allocator<D> + Allocator<DimDiff<D, U1>>,
{
    let m = OMatrix::<f64, D, D>::from_iterator_generic(dim, dim, cov.iter().copied());
    let (sym, eigen) = decomposed(what, &m, vectors)?;
    Ok((
        TangentMatrix::<N>::from_iterator(sym.iter().copied()),
        eigen.map(|e| Eigen {
            values: SVector::from_iterator(e.eigenvalues.iter().copied()),
            vectors: TangentMatrix::<N>::from_iterator(e.eigenvectors.iter().copied()),
        }),
    ))
}

/// ½(Σ + Σᵀ) and, when asked for, its eigen-decomposition, in any size.
type Decomposed<D> = (OMatrix<f64, D, D>, Option<SymmetricEigen<f64, D>>);

/// The one validation: square, finite, symmetric within [`SYMMETRY_TOLERANCE`], positive
/// semi-definite within [`PSD_TOLERANCE`] (see [`validated_eigen`] for `vectors`).
fn decomposed<D>(
    what: &'static str,
    cov: &OMatrix<f64, D, D>,
    vectors: bool,
) -> Result<Decomposed<D>>
where
    D: DimSub<U1>,
    DefaultAllocator: Allocator<D, D> + Allocator<D> + Allocator<DimDiff<D, U1>>,
{
    let sym = symmetrised(what, cov)?;
    if sym.nrows() == 0 {
        return Ok((sym, None));
    }
    let (eigenvalues, eigen) = if vectors {
        let eigen = SymmetricEigen::new(sym.clone());
        (eigen.eigenvalues.clone(), Some(eigen))
    } else {
        (sym.symmetric_eigenvalues(), None)
    };
    let min_eigenvalue = eigenvalues.min();
    let tolerance = psd_tolerance(eigenvalues.max());
    if min_eigenvalue < -tolerance {
        return Err(Error::NotPositiveSemiDefinite {
            what,
            min_eigenvalue,
            tolerance,
        });
    }
    Ok((sym, eigen))
}

/// The bound on tr Σ · tr Σ⁻¹ under which [`well_conditioned_factor`] hands back a Cholesky
/// factor: κ(Σ) = λ_max / λ_min ≤ tr Σ · tr Σ⁻¹ ≤ 10⁸, four orders of magnitude inside the
/// singular ratio (`SINGULAR_TOLERANCE` = 10⁻¹²), so that the eigenvalues' round-off (≈ 10⁻¹⁵
/// λ_max) cannot change what they decide.
pub(super) const FACTOR_CONDITION_BOUND: f64 = 1e8;

/// ½(Σ + Σᵀ) validated, with the Cholesky factor L (L Lᵀ = ½(Σ + Σᵀ)) when it proves what the
/// eigenvalues would decide, without computing them: Σ is positive definite (the factor
/// exists) and tr Σ · tr Σ⁻¹ (tr Σ⁻¹ = ‖L⁻¹‖²_F) ≤ [`FACTOR_CONDITION_BOUND`], so λ_min > 0
/// passes the PSD rule and λ_min / λ_max ≥ 10⁻⁸ is far from singular. Otherwise (`None`: a
/// 0 × 0, ill-conditioned, singular or invalid Σ) the caller decomposes Σ as
/// [`validated_eigen`] does, which decides and words every error.
pub(super) fn well_conditioned_factor<const N: usize>(
    what: &'static str,
    cov: &TangentMatrix<N>,
) -> Option<(TangentMatrix<N>, TangentMatrix<N>)> {
    let sym = symmetrised(what, cov).ok()?;
    if N == 0 {
        return None;
    }
    let l = sym.cholesky()?.unpack();
    let l_inverse = l.solve_lower_triangular(&TangentMatrix::<N>::identity())?;
    let bound = sym.trace() * l_inverse.norm_squared();
    (bound <= FACTOR_CONDITION_BOUND).then_some((sym, l))
}

/// Square, finite and symmetric within [`SYMMETRY_TOLERANCE`]: ½(Σ + Σᵀ).
fn symmetrised<D>(what: &'static str, cov: &OMatrix<f64, D, D>) -> Result<OMatrix<f64, D, D>>
where
    D: nalgebra::Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let (n, cols) = cov.shape();
    if n != cols {
        return Err(Error::WrongShape {
            what,
            expected_rows: n.max(cols),
            expected_cols: n.max(cols),
            rows: n,
            cols,
        });
    }
    check_finite(what, cov.transpose().iter().copied())?;
    let tolerance = symmetry_tolerance(cov.amax());
    let mut worst = (0, 0, 0.0);
    for row in 0..n {
        for col in row + 1..n {
            let difference = (cov[(row, col)] - cov[(col, row)]).abs();
            if difference > worst.2 {
                worst = (row, col, difference);
            }
        }
    }
    let (row, col, difference) = worst;
    if difference > tolerance {
        return Err(Error::NotSymmetric {
            what,
            row,
            col,
            upper: cov[(row, col)],
            lower: cov[(col, row)],
            difference,
            tolerance,
        });
    }
    Ok((cov + cov.transpose()) * 0.5)
}
