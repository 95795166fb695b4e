//! The shapes of uncertainty as geometry (the caller places them): Cartesian ellipsoids,
//! Exp-mapped banana surfaces and their principal outlines.

use nalgebra::{DMatrix, Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};

use super::v3;
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::scene::{self, Ellipsoid, Vec3};
use crate::uncertain::{Confidence, UncertainPose};

/// Sphere-mesh resolution of banana surfaces (latitude bands, meridians).
const BANANA_MESH: (u32, u32) = (16, 32);
/// Points per principal-ellipse outline.
const OUTLINE_POINTS: usize = 96;
/// Eigenvalues below this fraction of the largest count as zero when choosing the χ² degrees
/// of freedom of a drawn region.
const RANK_TOLERANCE: f64 = 1e-9;

/// Colours of the x, y, z axes ([`scene::AXIS_COLORS`]).
pub(super) use crate::scene::AXIS_COLORS;

/// An ellipsoid from a 3×3 covariance: half sizes r√λ along the eigenvectors (a flat one for
/// a planar covariance gets a small thickness so it stays visible). The orientation comes from
/// the closed-form rotation-matrix conversion (no iteration, whatever the input).
pub(super) fn ellipsoid_of(center: &Vector3<f64>, cov: &Matrix3<f64>, radius: f64) -> Ellipsoid {
    let eig = SymmetricEigen::new(*cov);
    let mut axes = eig.eigenvectors;
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    let half: Vec<f64> = eig
        .eigenvalues
        .iter()
        .map(|l| radius * l.max(0.0).sqrt())
        .collect();
    let floor = half.iter().copied().fold(0.0, f64::max) * 0.01;
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(axes));
    Ellipsoid {
        center: v3(center),
        half_sizes: [half[0].max(floor), half[1].max(floor), half[2].max(floor)],
        rotation: [rotation.i, rotation.j, rotation.k, rotation.w],
    }
}

/// The world-frame Cartesian position region of a pose's first-order Gaussian at
/// `confidence`: half sizes √χ²_d(p)·√λ along the eigenvectors of the world-frame position
/// covariance, d = 2 for planar groups and 3 otherwise; `None` for a rotation-only pose.
pub(super) fn position_region<G: LieGroup<N>, const N: usize>(
    pose: &UncertainPose<G, N>,
    confidence: Confidence,
) -> Option<Ellipsoid> {
    let cov = pose.position_cov_in_world_3d()?;
    let d = G::KIND.position_dims().max(1);
    Some(ellipsoid_of(
        pose.mean().to_se3().translation(),
        &cov,
        confidence.radius(d),
    ))
}

/// Principal axes of a symmetric matrix: (eigenvalues ≥ 0, eigenvectors), sorted by
/// decreasing eigenvalue.
fn principal_axes<const N: usize>(cov: &TangentMatrix<N>) -> (Vec<f64>, Vec<Tangent<N>>) {
    let eig = SymmetricEigen::new(DMatrix::from_iterator(N, N, cov.iter().copied()));
    let mut order: Vec<usize> = (0..N).collect();
    order.sort_by(|a, b| eig.eigenvalues[*b].total_cmp(&eig.eigenvalues[*a]));
    let values = order.iter().map(|&i| eig.eigenvalues[i].max(0.0)).collect();
    let vectors = order
        .iter()
        .map(|&i| Tangent::<N>::from_iterator(eig.eigenvectors.column(i).iter().copied()))
        .collect();
    (values, vectors)
}

/// The three largest principal directions of Σ scaled by r√λ: u ∈ S² ↦ Σᵢ uᵢ r√λᵢ eᵢ.
struct PrincipalFrame<const N: usize> {
    columns: [Tangent<N>; 3],
}

impl<const N: usize> PrincipalFrame<N> {
    fn of<G: LieGroup<N>>(pose: &UncertainPose<G, N>, confidence: Confidence) -> Self {
        let (values, vectors) = principal_axes(pose.cov());
        // A Gaussian of rank k < N lives in a k-dimensional subspace: its p-region has the χ²_k
        // radius, not χ²_N (a yaw-only noise would otherwise be drawn far too wide).
        let largest = values.first().copied().unwrap_or(0.0);
        let rank = values
            .iter()
            .filter(|l| **l > RANK_TOLERANCE * largest)
            .count()
            .max(1);
        let r = confidence.radius(rank);
        let column = |i: usize| match (values.get(i), vectors.get(i)) {
            (Some(l), Some(v)) => v * (r * l.sqrt()),
            _ => Tangent::<N>::zeros(),
        };
        PrincipalFrame {
            columns: [column(0), column(1), column(2)],
        }
    }

    /// μ · Exp(τ) (right) or Exp(τ) · μ (left) for τ = Σ uᵢ cᵢ.
    fn apply<G: LieGroup<N>>(&self, pose: &UncertainPose<G, N>, u: [f64; 3]) -> G {
        let tau = self.columns[0] * u[0] + self.columns[1] * u[1] + self.columns[2] * u[2];
        crate::sample::retract(pose.mean(), &tau, pose.side())
    }
}

/// The Exp-image of the tangent ellipsoid's principal 3-D slice at `confidence`: the unit
/// sphere's mesh mapped by u ↦ point_of(μ · Exp(Σᵢ uᵢ r√λᵢ eᵢ)) (right; Exp(·) · μ left), as
/// (vertices, triangles).
pub(super) fn banana_surface<G: LieGroup<N>, const N: usize>(
    pose: &UncertainPose<G, N>,
    confidence: Confidence,
    point_of: impl Fn(&G) -> Vector3<f64>,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let frame = PrincipalFrame::of(pose, confidence);
    let (sphere, triangles) = scene::unit_sphere_mesh(BANANA_MESH.0, BANANA_MESH.1);
    let vertices = sphere
        .iter()
        .map(|u| v3(&point_of(&frame.apply(pose, [u[0], u[1], u[2]]))))
        .collect();
    (vertices, triangles)
}

/// Images of the three principal great circles of the tangent ellipsoid at `confidence`
/// (one strip each, [`OUTLINE_POINTS`] + 1 points).
pub(super) fn outline_strips<G: LieGroup<N>, const N: usize>(
    pose: &UncertainPose<G, N>,
    confidence: Confidence,
    point_of: impl Fn(&G) -> Vector3<f64>,
) -> Vec<Vec<Vec3>> {
    let frame = PrincipalFrame::of(pose, confidence);
    [(0, 1), (0, 2), (1, 2)]
        .iter()
        .map(|&(a, b)| {
            (0..=OUTLINE_POINTS)
                .map(|i| {
                    let s = std::f64::consts::TAU * i as f64 / OUTLINE_POINTS as f64;
                    let mut u = [0.0; 3];
                    u[a] = s.cos();
                    u[b] = s.sin();
                    v3(&point_of(&frame.apply(pose, u)))
                })
                .collect()
        })
        .collect()
}
