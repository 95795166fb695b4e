//! The library's typed errors: each names what is wrong, where, and by how much.

use thiserror::Error;

/// Everything the posecov library can reject.
///
/// Each variant names the offending quantity and its value, so a caller (the CLI, a test, a
/// script) can tell the user exactly what to fix. Library code never panics on user data; it
/// returns one of these.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// An input contained NaN or ±∞.
    #[error("{what}: element {index} is {value}, but every element must be finite")]
    NonFinite {
        /// Which input (e.g. "rotation matrix", "covariance").
        what: &'static str,
        /// Position of the first non-finite element (row-major for matrices).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A rotation matrix whose columns are not orthonormal within the tolerance.
    #[error(
        "{what}: not orthonormal, max |RᵀR − I| = {deviation:.3e} exceeds the tolerance {tolerance:.1e}"
    )]
    NotOrthonormal {
        /// Which input.
        what: &'static str,
        /// Largest absolute entry of RᵀR − I.
        deviation: f64,
        /// The tolerance it was held to.
        tolerance: f64,
    },
    /// A matrix with determinant −1 (a reflection) or otherwise far from +1.
    #[error("{what}: determinant is {determinant:.6}, a rotation needs +1 (−1 is a reflection)")]
    NotRightHanded {
        /// Which input.
        what: &'static str,
        /// The determinant found.
        determinant: f64,
    },
    /// A homogeneous transform whose last row is not exactly `[0, …, 0, 1]`.
    #[error("{what}: last row is {row:?}, a homogeneous transform needs exactly [0, …, 0, 1]")]
    BadLastRow {
        /// Which input.
        what: &'static str,
        /// The last row found.
        row: Vec<f64>,
    },
    /// A quaternion whose norm is too far from 1 to be a rotation that was merely rounded.
    #[error(
        "quaternion (x, y, z, w) = {xyzw:?} has norm {norm:.6}; it must be within {tolerance:.0e} of 1 \
         (small rounding is normalised away, larger errors are rejected)"
    )]
    QuaternionNotUnit {
        /// The components in ROS order (x, y, z, w).
        xyzw: [f64; 4],
        /// Its Euclidean norm.
        norm: f64,
        /// The accepted deviation from 1.
        tolerance: f64,
    },
    /// A rotation axis of zero length.
    #[error("rotation axis {axis:?} has zero length, so it names no direction")]
    ZeroAxis {
        /// The axis given.
        axis: [f64; 3],
    },
    /// A slice or vector of the wrong length.
    #[error("{what}: expected {expected} numbers, got {got}")]
    WrongLength {
        /// Which input.
        what: &'static str,
        /// Length required.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// A matrix of the wrong shape (e.g. a joint covariance that is not 2N × 2N).
    #[error("{what}: expected a {expected_rows} × {expected_cols} matrix, got {rows} × {cols}")]
    WrongShape {
        /// Which input.
        what: &'static str,
        /// Rows required.
        expected_rows: usize,
        /// Columns required.
        expected_cols: usize,
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
    },
    /// A covariance that is not symmetric within the tolerance.
    #[error(
        "{what}: not symmetric, entry ({row}, {col}) = {upper} but ({col}, {row}) = {lower} \
         (difference {difference:.3e} exceeds the tolerance {tolerance:.1e})"
    )]
    NotSymmetric {
        /// Which input.
        what: &'static str,
        /// Row of the worst pair.
        row: usize,
        /// Column of the worst pair.
        col: usize,
        /// Σ[row, col].
        upper: f64,
        /// Σ[col, row].
        lower: f64,
        /// |upper − lower|.
        difference: f64,
        /// The tolerance it was held to.
        tolerance: f64,
    },
    /// A covariance with a negative eigenvalue beyond round-off.
    #[error(
        "{what}: not positive semi-definite, smallest eigenvalue {min_eigenvalue:.6e} < −{tolerance:.1e} \
         (a covariance's variances along every direction must be ≥ 0)"
    )]
    NotPositiveSemiDefinite {
        /// Which input.
        what: &'static str,
        /// The most negative eigenvalue.
        min_eigenvalue: f64,
        /// The allowance for round-off it was held to.
        tolerance: f64,
    },
    /// A covariance that must be inverted (Mahalanobis distance, fusion) but is singular.
    #[error(
        "{what}: singular covariance (smallest eigenvalue {min_eigenvalue:.3e}) cannot be inverted"
    )]
    SingularCovariance {
        /// Which input.
        what: &'static str,
        /// The smallest eigenvalue.
        min_eigenvalue: f64,
    },
    /// A value outside its allowed range (a probability, a sample count, a step size, …).
    #[error("{what} = {value} is out of range: {expected}")]
    OutOfRange {
        /// Which input.
        what: &'static str,
        /// The value given.
        value: f64,
        /// What is allowed, in words.
        expected: &'static str,
    },
    /// A statistic asked of an empty set.
    #[error("{what}: needs at least {needed} samples, got {got}")]
    TooFewSamples {
        /// Which statistic.
        what: &'static str,
        /// Minimum count.
        needed: usize,
        /// Count given.
        got: usize,
    },
    /// An iteration that did not converge; `last_estimate` is a human-readable rendering of
    /// where it stopped (the typed estimate travels in the operation's own error type).
    #[error(
        "{what}: no convergence after {iterations} iterations (last step {last_step:.3e} > {tolerance:.1e}); \
         last estimate {last_estimate}"
    )]
    NotConverged {
        /// Which iteration.
        what: &'static str,
        /// Iterations run.
        iterations: usize,
        /// Norm of the last update step.
        last_step: f64,
        /// The convergence threshold.
        tolerance: f64,
        /// The last estimate, formatted.
        last_estimate: String,
    },
}

/// Result alias used across the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Returns [`Error::NonFinite`] for the first non-finite value of `values`.
///
/// ```
/// use posecov::error::{check_finite, Error};
/// assert!(check_finite("v", [1.0, 2.0]).is_ok());
/// assert!(matches!(check_finite("v", [1.0, f64::NAN]), Err(Error::NonFinite { index: 1, .. })));
/// ```
pub fn check_finite<I: IntoIterator<Item = f64>>(what: &'static str, values: I) -> Result<()> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((index, value)) => Err(Error::NonFinite { what, index, value }),
        None => Ok(()),
    }
}
