//! Propagating uncertainty through what a robot does to its poses.
//!
//! Every operation returns a [`Propagated`]: the resulting [`UncertainPose`] and the
//! [`Method`] that produced it. [`ResultRecord`] is the same result as plain serialisable
//! data (for the JSON report and the viewer), with the relative Frobenius error against
//! Monte Carlo where Monte Carlo ran. Monte Carlo itself is the evaluation engine's
//! ([`crate::eval`]): particles flow through the operations of a [`crate::plan::Plan`].
//!
//! # What this folder owns
//!
//! The analytic methods (first order, 2nd/4th order, sigma points, vector space, odometry,
//! differential drive, fusion); not Monte Carlo (that is `eval/`).

pub mod diff_drive;
pub mod first_order;
pub mod fourth_order;
pub mod fusion;
pub mod odometry;
pub mod sigma_point;
pub mod vector_space;

use serde::{Deserialize, Serialize};

use crate::lie::{LieGroup, TangentMatrix};
use crate::uncertain::{Coverage, Method, Side, UncertainPose};

/// An uncertain pose together with the method that computed it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Propagated<G: LieGroup<N>, const N: usize> {
    /// The resulting mean and covariance.
    pub pose: UncertainPose<G, N>,
    /// How the covariance was computed.
    pub method: Method,
}

/// Relative Frobenius error ‖Σ − Σ_ref‖_F / ‖Σ_ref‖_F (0 when both are zero).
///
/// ```
/// use posecov::propagate::relative_frobenius_error;
/// use nalgebra::Matrix2;
/// let e = relative_frobenius_error(&(Matrix2::identity() * 1.1), &Matrix2::identity());
/// assert!((e - 0.1).abs() < 1e-12);
/// ```
pub fn relative_frobenius_error<const N: usize>(
    cov: &TangentMatrix<N>,
    reference: &TangentMatrix<N>,
) -> f64 {
    let denominator = reference.norm();
    let numerator = (cov - reference).norm();
    if denominator == 0.0 {
        if numerator == 0.0 { 0.0 } else { f64::INFINITY }
    } else {
        numerator / denominator
    }
}

/// A propagated result as plain data: what the JSON report prints and the viewer draws.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultRecord {
    /// What this result is (e.g. "world_from_cam", "step 3").
    pub label: String,
    /// The group ("SE(2)", "SE(3)", …).
    pub group: String,
    /// How it was computed.
    pub method: Method,
    /// The side of the covariance.
    pub side: Side,
    /// The mean as a matrix, row-major rows.
    pub mean_matrix: Vec<Vec<f64>>,
    /// The mean as a tangent vector Log(μ), in the conventions' order.
    pub mean_tangent: Vec<f64>,
    /// The covariance, row-major rows.
    pub covariance: Vec<Vec<f64>>,
    /// ‖Σ − Σ_MC‖_F / ‖Σ_MC‖_F against the Monte Carlo result of the same quantity, on the
    /// same side, where Monte Carlo ran.
    pub relative_error_vs_monte_carlo: Option<f64>,
    /// Per region this result draws (`tangent`, `tangent_position`, `cartesian`,
    /// `vector_space`), the fraction of the Monte Carlo samples inside it at the run's
    /// confidence, with its binomial standard error; empty where Monte Carlo did not run.
    #[serde(default)]
    pub coverage: Vec<Coverage>,
    /// The average NEES of the Monte Carlo samples under this result's Gaussian (expectation
    /// `anees_dof`), where Monte Carlo ran and Σ is regular.
    #[serde(default)]
    pub anees: Option<f64>,
    /// The dimension d of the NEES: the ANEES's expectation.
    #[serde(default)]
    pub anees_dof: Option<usize>,
    /// The 95 % band of the ANEES for the sample size: outside it, Σ is too small (above) or
    /// too large (below).
    #[serde(default)]
    pub anees_band: Option<[f64; 2]>,
}

impl ResultRecord {
    /// Plain-data record of a propagated result.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::{Propagated, ResultRecord};
    /// use posecov::uncertain::{Method, UncertainPose};
    /// let p = Propagated { pose: UncertainPose::certain(Se2::identity()), method: Method::Exact };
    /// let r = ResultRecord::new("start", &p, None);
    /// assert_eq!(r.group, "SE(2)");
    /// assert_eq!(r.mean_matrix.len(), 3);
    /// ```
    pub fn new<G, const N: usize>(
        label: &str,
        result: &Propagated<G, N>,
        relative_error_vs_monte_carlo: Option<f64>,
    ) -> Self
    where
        G: LieGroup<N>,
        G::Matrix: MatrixRows,
    {
        let pose = &result.pose;
        Self {
            label: label.to_owned(),
            group: G::NAME.to_owned(),
            method: result.method,
            side: pose.side(),
            mean_matrix: pose.mean().to_matrix().to_rows(),
            mean_tangent: pose.mean().log().iter().copied().collect(),
            covariance: pose.cov().to_rows(),
            relative_error_vs_monte_carlo,
            coverage: Vec::new(),
            anees: None,
            anees_dof: None,
            anees_band: None,
        }
    }

    /// The record with the coverage of its regions and its ANEES (value, d, band) against
    /// Monte Carlo.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::propagate::{Propagated, ResultRecord};
    /// use posecov::uncertain::{Coverage, Method, Region, UncertainPose};
    /// let p = Propagated { pose: UncertainPose::certain(Se2::identity()), method: Method::Exact };
    /// let r = ResultRecord::new("a", &p, None)
    ///     .with_consistency(vec![Coverage::from_counts(Region::Tangent, 3, 95, 100)], Some((3.1, 3, [2.4, 3.7])));
    /// assert_eq!((r.coverage[0].inside, r.anees, r.anees_dof), (0.95, Some(3.1), Some(3)));
    /// ```
    pub fn with_consistency(
        mut self,
        coverage: Vec<Coverage>,
        anees: Option<(f64, usize, [f64; 2])>,
    ) -> Self {
        self.coverage = coverage;
        if let Some((value, dof, band)) = anees {
            self.anees = Some(value);
            self.anees_dof = Some(dof);
            self.anees_band = Some(band);
        }
        self
    }
}

/// Row-major rows of a fixed-size matrix, for plain-data output.
pub trait MatrixRows {
    /// The rows, each as a `Vec<f64>`.
    fn to_rows(&self) -> Vec<Vec<f64>>;
}

impl<const R: usize, const C: usize> MatrixRows for nalgebra::SMatrix<f64, R, C> {
    /// ```
    /// use posecov::propagate::MatrixRows;
    /// assert_eq!(nalgebra::Matrix2::new(1.0, 2.0, 3.0, 4.0).to_rows(), vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
    /// ```
    fn to_rows(&self) -> Vec<Vec<f64>> {
        (0..R)
            .map(|r| (0..C).map(|c| self[(r, c)]).collect())
            .collect()
    }
}
