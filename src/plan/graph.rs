//! A pose graph as the evaluation receives it: vertices with their initial estimates, relative
//! measurements (edges) and absolute ones (priors), each with its information matrix in
//! posecov's right form [ρ; θ], and the vertices the file holds fixed. Plain data: the reading
//! of a file's numbers (g2o's or GTSAM's, [CONVENTIONS §10]) is done by `input::graph`;
//! [`crate::eval::graph`] optimises it and computes the marginals.
//!
//! An edge i → j with measurement Z and information Λ says X_j = X_i · Z · Exp(ξ),
//! ξ ~ N(0, Λ⁻¹): its residual is r = Log(Z⁻¹ · X_i⁻¹ · X_j) and its cost rᵀ Λ r. A prior on
//! vertex i says X_i = Z · Exp(ξ): r = Log(Z⁻¹ · X_i).
//!
//! ```
//! use posecov::lie::{LieGroup, Se2};
//! use posecov::plan::graph::{GraphEdge, GraphReading, GraphVertex, PoseGraph};
//! let mut graph = PoseGraph::<Se2, 3>::default();
//! graph.vertices.push(GraphVertex { id: 0, estimate: Se2::identity(), line: 1 });
//! graph.vertices.push(GraphVertex { id: 1, estimate: Se2::from_xy_theta(1.0, 0.0, 0.0), line: 2 });
//! graph.edges.push(GraphEdge { from: 0, to: 1, measurement: Se2::from_xy_theta(1.0, 0.0, 0.0),
//!     information: nalgebra::Matrix3::identity() * 100.0, line: 3 });
//! let poses = [Se2::identity(), Se2::from_xy_theta(1.0, 0.0, 0.0)];
//! assert_eq!(graph.chi2(&poses, GraphReading::G2o), 0.0);
//! ```
//!
//! [CONVENTIONS §10]: crate::conventions#10-pose-graphs-g2o-and-gtsam
//!
//! # In the plan
//!
//! `plan/graph.rs`: `PoseGraph` (vertices, edges and priors with their information in g2o's reading
//! — GTSAM's is derived, `GraphReading`, one half-angle rule — fixed vertices; the residual r =
//! Log(Z⁻¹ X_i⁻¹ X_j) and χ²), carried by `Plan::graph`.

use super::{AnyPlan, Plan};
use crate::lie::{LieGroup, TangentMatrix};

/// How a file's information matrices are read ([CONVENTIONS §10]): the plan holds g2o's
/// reading; GTSAM's is derived from it ([`gtsam_information`]).
///
/// [CONVENTIONS §10]: crate::conventions#10-pose-graphs-g2o-and-gtsam
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GraphReading {
    /// As g2o defines them (`EDGE_SE3:QUAT`: over the quaternion's vector part, ≈ θ/2).
    #[default]
    G2o,
    /// As GTSAM's `readG2o` reads them (over the rotation vector, no half-angle factor).
    Gtsam,
}

impl GraphReading {
    /// The flag's value: `g2o` or `gtsam`.
    ///
    /// ```
    /// assert_eq!(posecov::plan::graph::GraphReading::Gtsam.name(), "gtsam");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            GraphReading::G2o => "g2o",
            GraphReading::Gtsam => "gtsam",
        }
    }
}

/// D's diagonal entry `axis` for a graph on N-dimensional tangents: 2 on SE(3)'s rotation
/// axes (g2o's `EDGE_SE3:QUAT` error uses the quaternion's vector part q.xyz ≈ θ/2, so
/// e = D⁻¹ ξ to first order), 1 everywhere else (SE(2): e = ξ).
///
/// ```
/// use posecov::plan::graph::half_angle_scale;
/// assert_eq!(half_angle_scale::<6>(3), 2.0);
/// assert_eq!(half_angle_scale::<6>(2), 1.0);
/// assert_eq!(half_angle_scale::<3>(2), 1.0);
/// ```
pub fn half_angle_scale<const N: usize>(axis: usize) -> f64 {
    if N == 6 && axis >= 3 { 2.0 } else { 1.0 }
}

/// GTSAM's reading Ω of the information that g2o's reading makes Λ = D⁻¹ Ω D⁻¹ over
/// [ρ; θ]: Ω = D Λ D (GTSAM's `readG2o` takes the file's numbers as information over the
/// rotation vector, [`half_angle_scale`]).
///
/// ```
/// use posecov::plan::graph::gtsam_information;
/// let lambda = nalgebra::Matrix6::identity() * 2.5e3;
/// let omega = gtsam_information(&lambda);
/// assert_eq!((omega[(0, 0)], omega[(3, 3)], omega[(3, 4)]), (2.5e3, 1e4, 0.0));
/// ```
pub fn gtsam_information<const N: usize>(information: &TangentMatrix<N>) -> TangentMatrix<N> {
    TangentMatrix::<N>::from_fn(|r, c| {
        information[(r, c)] * half_angle_scale::<N>(r) * half_angle_scale::<N>(c)
    })
}

/// A vertex: its id in the file and the file's estimate (the optimiser's initial guess).
#[derive(Debug, Clone, PartialEq)]
pub struct GraphVertex<G> {
    /// The file's vertex id.
    pub id: u64,
    /// The initial estimate (the file's, or chained from the edges when the file has none).
    pub estimate: G,
    /// The vertex's line (0 when the estimate was chained from the edges).
    pub line: usize,
}

/// A relative measurement between two vertices (indices into [`PoseGraph::vertices`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GraphEdge<G: LieGroup<N>, const N: usize> {
    /// Index of vertex i.
    pub from: usize,
    /// Index of vertex j.
    pub to: usize,
    /// Z, with X_j ≈ X_i · Z.
    pub measurement: G,
    /// Λ over [ρ; θ] as g2o defines the file's numbers (for `EDGE_SE3:QUAT`, the half-angle
    /// factor applied: Λ = D⁻¹ Ω D⁻¹, D = diag(1, 1, 1, 2, 2, 2)); GTSAM's reading is
    /// [`information_in`](Self::information_in).
    pub information: TangentMatrix<N>,
    /// The edge's line.
    pub line: usize,
}

/// An absolute measurement of one vertex (g2o's `EDGE_PRIOR_SE2`, `EDGE_SE3_PRIOR`).
#[derive(Debug, Clone, PartialEq)]
pub struct GraphPrior<G: LieGroup<N>, const N: usize> {
    /// Index of the vertex.
    pub vertex: usize,
    /// Z, with X ≈ Z.
    pub measurement: G,
    /// Λ over [ρ; θ], g2o's reading (see [`GraphEdge::information`]).
    pub information: TangentMatrix<N>,
    /// The prior's line.
    pub line: usize,
}

/// A vertex the file holds fixed (g2o's `FIX id`): not optimised, its marginal zero.
///
/// ```
/// use posecov::plan::graph::FixedVertex;
/// let f = FixedVertex { index: 0, line: 2 };
/// assert_eq!(f.line, 2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixedVertex {
    /// Index of the vertex.
    pub index: usize,
    /// The `FIX` record's line.
    pub line: usize,
}

/// A pose graph (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct PoseGraph<G: LieGroup<N>, const N: usize> {
    /// Vertices, in increasing id order.
    pub vertices: Vec<GraphVertex<G>>,
    /// Edges in file order.
    pub edges: Vec<GraphEdge<G, N>>,
    /// Priors in file order.
    pub priors: Vec<GraphPrior<G, N>>,
    /// Vertices the file holds fixed (g2o's `FIX id`).
    pub fixed: Vec<FixedVertex>,
}

impl<G: LieGroup<N>, const N: usize> Default for PoseGraph<G, N> {
    fn default() -> Self {
        Self {
            vertices: Vec::new(),
            edges: Vec::new(),
            priors: Vec::new(),
            fixed: Vec::new(),
        }
    }
}

/// Λ (g2o's reading) in `reading`.
fn reading_of<const N: usize>(
    information: &TangentMatrix<N>,
    reading: GraphReading,
) -> TangentMatrix<N> {
    match reading {
        GraphReading::G2o => *information,
        GraphReading::Gtsam => gtsam_information(information),
    }
}

impl<G: LieGroup<N>, const N: usize> GraphEdge<G, N> {
    /// r = Log(Z⁻¹ · X_i⁻¹ · X_j), the edge's residual at `poses` ([ρ; θ]).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::plan::graph::GraphEdge;
    /// let z = Se2::from_xy_theta(1.0, 0.0, 0.0);
    /// let e = GraphEdge { from: 0, to: 1, measurement: z, information: nalgebra::Matrix3::identity(), line: 1 };
    /// let r = e.residual(&[Se2::identity(), Se2::from_xy_theta(1.0, 0.5, 0.0)]);
    /// assert!((r - nalgebra::Vector3::new(0.0, 0.5, 0.0)).norm() < 1e-12);
    /// ```
    pub fn residual(&self, poses: &[G]) -> crate::lie::Tangent<N> {
        self.measurement
            .inverse()
            .compose(&poses[self.from].inverse().compose(&poses[self.to]))
            .log()
    }

    /// Λ in the chosen reading ([`gtsam_information`] for GTSAM's).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::plan::graph::{GraphEdge, GraphReading};
    /// let e = GraphEdge { from: 0, to: 1, measurement: Se2::identity(), information: nalgebra::Matrix3::identity(), line: 1 };
    /// assert_eq!(e.information_in(GraphReading::Gtsam), e.information); // SE(2): the same
    /// ```
    pub fn information_in(&self, reading: GraphReading) -> TangentMatrix<N> {
        reading_of(&self.information, reading)
    }
}

impl<G: LieGroup<N>, const N: usize> GraphPrior<G, N> {
    /// r = Log(Z⁻¹ · X), the prior's residual at `poses`.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::plan::graph::GraphPrior;
    /// let p = GraphPrior { vertex: 0, measurement: Se2::identity(), information: nalgebra::Matrix3::identity(), line: 1 };
    /// assert!((p.residual(&[Se2::from_xy_theta(0.0, 0.0, 0.1)])[2] - 0.1).abs() < 1e-15);
    /// ```
    pub fn residual(&self, poses: &[G]) -> crate::lie::Tangent<N> {
        self.measurement
            .inverse()
            .compose(&poses[self.vertex])
            .log()
    }

    /// Λ in the chosen reading ([`gtsam_information`] for GTSAM's).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::plan::graph::{GraphPrior, GraphReading};
    /// let e = GraphPrior { vertex: 0, measurement: Se2::identity(), information: nalgebra::Matrix3::identity(), line: 1 };
    /// assert_eq!(e.information_in(GraphReading::Gtsam), e.information); // SE(2): the same
    /// ```
    pub fn information_in(&self, reading: GraphReading) -> TangentMatrix<N> {
        reading_of(&self.information, reading)
    }
}

impl<G: LieGroup<N>, const N: usize> PoseGraph<G, N> {
    /// χ² = Σ rᵀ Λ r over the edges and priors at `poses` (one per vertex); GTSAM's
    /// `graph.error(values)` is half of it, in `reading` of Λ.
    ///
    /// See the [module docs](self) for an example.
    pub fn chi2(&self, poses: &[G], reading: GraphReading) -> f64 {
        let edges: f64 = self
            .edges
            .iter()
            .map(|e| {
                let r = e.residual(poses);
                (r.transpose() * e.information_in(reading) * r)[(0, 0)]
            })
            .sum();
        let priors: f64 = self
            .priors
            .iter()
            .map(|p| {
                let r = p.residual(poses);
                (r.transpose() * p.information_in(reading) * r)[(0, 0)]
            })
            .sum();
        edges + priors
    }

    /// The initial estimates, one per vertex.
    ///
    /// ```
    /// let g = posecov::plan::graph::PoseGraph::<posecov::lie::Se2, 3>::default();
    /// assert!(g.estimates().is_empty());
    /// ```
    pub fn estimates(&self) -> Vec<G> {
        self.vertices.iter().map(|v| v.estimate).collect()
    }
}

impl AnyPlan {
    /// The vertex ids of the plan's pose graph, ascending (None: the plan has no graph).
    ///
    /// ```
    /// use posecov::plan::{AnyPlan, Plan};
    /// use posecov::plan::graph::{GraphVertex, PoseGraph};
    /// use posecov::lie::{LieGroup, Se2};
    /// let mut graph = PoseGraph::<Se2, 3>::default();
    /// graph.vertices.push(GraphVertex { id: 4, estimate: Se2::identity(), line: 1 });
    /// let plan = AnyPlan::Se2(Plan { graph: Some(graph), ..Plan::default() });
    /// assert_eq!(plan.graph_vertex_ids(), Some(vec![4]));
    /// assert_eq!(AnyPlan::Se2(Plan::default()).graph_vertex_ids(), None);
    /// ```
    pub fn graph_vertex_ids(&self) -> Option<Vec<u64>> {
        fn ids<G: LieGroup<N>, const N: usize>(p: &Plan<G, N>) -> Option<Vec<u64>> {
            p.graph
                .as_ref()
                .map(|g| g.vertices.iter().map(|v| v.id).collect())
        }
        match self {
            AnyPlan::So2(p) => ids(p),
            AnyPlan::Se2(p) => ids(p),
            AnyPlan::So3(p) => ids(p),
            AnyPlan::Se3(p) => ids(p),
        }
    }
}
