//! One number per pose and part of the pose for "what did the loop closures do?": the σ of
//! its marginal before the loop closures (dead reckoning) and after (optimised).

use crate::lie::{LieGroup, TangentMatrix};

/// A pose's σ from its right-form marginal Σ over [ρ; θ]: `position` = √tr Σ_ρρ (m), the
/// root of the summed position variances, and `rotation` = √tr Σ_θθ (rad) — for a 2-D pose
/// the heading σ √Σ_θθ, for a 3-D pose the root of the three rotation variances.
///
/// ```
/// use posecov::eval::graph::PoseSigma;
/// use posecov::lie::Se2;
/// let cov = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(0.09, 0.16, 0.0004));
/// let s = PoseSigma::of::<Se2, 3>(&cov);
/// assert!((s.position - 0.5).abs() < 1e-12 && (s.rotation - 0.02).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PoseSigma {
    /// √ of the trace of the position block (m).
    pub position: f64,
    /// √ of the trace of the rotation block (rad): the heading σ of a 2-D pose.
    pub rotation: f64,
}

impl PoseSigma {
    /// The σ of the marginal `cov` of a pose of group `G` (a negative rounding-level trace
    /// counts as 0).
    pub fn of<G: LieGroup<N>, const N: usize>(cov: &TangentMatrix<N>) -> Self {
        let rotation = G::KIND.rotation_range();
        let trace = |r: std::ops::Range<usize>| r.map(|k| cov[(k, k)]).sum::<f64>().max(0.0);
        Self {
            position: trace(0..rotation.start).sqrt(),
            rotation: trace(rotation).sqrt(),
        }
    }
}

/// A pose's σ before and after the loop closures (None: held fixed, isolated, or no
/// marginals).
///
/// ```
/// use posecov::eval::graph::{PoseSigma, SigmaBeforeAfter};
/// let s = SigmaBeforeAfter { before: Some(PoseSigma { position: 2.0, rotation: 0.1 }), after: None };
/// assert!(s.after.is_none());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SigmaBeforeAfter {
    /// Dead reckoning: the marginal of the graph without its loop closures.
    pub before: Option<PoseSigma>,
    /// The optimised marginal.
    pub after: Option<PoseSigma>,
}
