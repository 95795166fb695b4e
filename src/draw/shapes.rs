//! The shapes of uncertainty: Cartesian ellipsoids, Exp-mapped banana surfaces and their
//! principal outlines.

use nalgebra::{DMatrix, Matrix3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};

use super::{Painter, v3};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::scene::{
    self, Color, Ellipsoid, Ellipsoids, FillMode, ItemKind, LineStrips, Surface, Vec3,
};
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

/// The world-frame Cartesian position region of a pose's first-order Gaussian, d = 2 for
/// planar groups and 3 otherwise, at `base/ellipsoid`.
pub(super) fn position_ellipsoid<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    base: &str,
    step: Option<u64>,
    pose: &UncertainPose<G, N>,
    color: Color,
) {
    let Some(cov) = pose.position_cov_in_world_3d() else {
        return;
    };
    let d = G::KIND.position_dims().max(1);
    let shape = ellipsoid_of(
        pose.mean().to_se3().translation(),
        &cov,
        p.confidence().radius(d),
    );
    p.push(
        format!("{base}/ellipsoid"),
        step,
        ItemKind::Ellipsoids(Ellipsoids {
            shapes: vec![shape],
            color,
            fill: FillMode::MajorWireframe,
            line_radius: 0.002 * p.axis_length / 0.15,
            label: None,
        }),
    );
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

/// The Exp-image surface and its principal outlines.
pub(super) fn banana<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    base: &str,
    step: Option<u64>,
    pose: &UncertainPose<G, N>,
    color: Color,
    point_of: impl Fn(&G) -> Vector3<f64> + Copy,
) {
    let frame = PrincipalFrame::of(pose, p.confidence());
    let (sphere, triangles) = scene::unit_sphere_mesh(BANANA_MESH.0, BANANA_MESH.1);
    let vertices: Vec<Vec3> = sphere
        .iter()
        .map(|u| v3(&point_of(&frame.apply(pose, [u[0], u[1], u[2]]))))
        .collect();
    let surface = Surface {
        vertices,
        triangles,
        normals: Vec::new(),
        color: color.with_alpha(70),
    }
    .with_computed_normals();
    p.push(format!("{base}/banana"), step, ItemKind::Surface(surface));
    outlines(
        p,
        &format!("{base}/banana_outline"),
        step,
        pose,
        color,
        point_of,
    );
}

/// Images of the three principal great circles of the tangent ellipsoid.
pub(super) fn outlines<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    path: &str,
    step: Option<u64>,
    pose: &UncertainPose<G, N>,
    color: Color,
    point_of: impl Fn(&G) -> Vector3<f64>,
) {
    let frame = PrincipalFrame::of(pose, p.confidence());
    let strips: Vec<Vec<Vec3>> = [(0, 1), (0, 2), (1, 2)]
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
        .collect();
    p.push(
        path.to_owned(),
        step,
        ItemKind::LineStrips(LineStrips {
            strips,
            color,
            // Thin: outlines sit on top of clouds and surfaces.
            radius: 0.004 * p.axis_length.min(0.5),
        }),
    );
}
