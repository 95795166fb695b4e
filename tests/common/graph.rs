//! Pose-graph test helpers: a graph from g2o text, and H and its blocks as dense matrices
//! (tiny graphs only: the code under test never forms them).
#![allow(dead_code)]

use nalgebra::{DMatrix, SMatrix};
use posecov::eval::graph::edge_jacobians;
use posecov::input::graph::read_text;
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::plan::AnyPlan;
use posecov::plan::graph::PoseGraph;

/// The SE(2) pose graph of g2o text.
pub fn se2_graph(text: &str) -> PoseGraph<Se2, 3> {
    match read_text(text, "g.g2o").expect("valid").1.plan {
        AnyPlan::Se2(p) => p.graph.expect("a graph"),
        _ => panic!("planar"),
    }
}

/// GTSAM's Pose2 SLAM tutorial graph (`examples/Pose2SLAMExample`) as g2o text: a prior on
/// x1 with σ = (0.3, 0.3, 0.1), four odometry edges with σ = (0.2, 0.2, 0.1) and the loop
/// closure 5 → 2, from GTSAM's initial estimate.
pub fn pose2_slam_example() -> String {
    let info = "25 0 0 25 0 100";
    format!(
        "VERTEX_SE2 1 0.5 0.0 0.2\nVERTEX_SE2 2 2.3 0.1 -0.2\nVERTEX_SE2 3 4.1 0.1 1.5707963267948966\n\
         VERTEX_SE2 4 4.0 2.0 3.141592653589793\nVERTEX_SE2 5 2.1 2.1 -1.5707963267948966\n\
         EDGE_PRIOR_SE2 1 0 0 0 11.111111111111111 0 0 11.111111111111111 0 100\n\
         EDGE_SE2 1 2 2 0 0 {info}\nEDGE_SE2 2 3 2 0 1.5707963267948966 {info}\n\
         EDGE_SE2 3 4 2 0 1.5707963267948966 {info}\nEDGE_SE2 4 5 2 0 1.5707963267948966 {info}\n\
         EDGE_SE2 5 2 2 0 1.5707963267948966 {info}\n"
    )
}

/// The SE(3) pose graph of g2o text.
pub fn se3_graph(text: &str) -> PoseGraph<Se3, 6> {
    match read_text(text, "g.g2o").expect("valid").1.plan {
        AnyPlan::Se3(p) => p.graph.expect("a graph"),
        _ => panic!("spatial"),
    }
}

/// H at `poses` as a dense matrix over the unknown vertices (tests only: tiny graphs).
pub fn dense_information<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    poses: &[G],
    unknown: &[usize],
) -> DMatrix<f64> {
    let n = unknown.len() * N;
    let at = |v: usize| unknown.iter().position(|&u| u == v);
    let mut h = DMatrix::<f64>::zeros(n, n);
    let mut add = |a: Option<usize>, b: Option<usize>, m: SMatrix<f64, N, N>| {
        if let (Some(a), Some(b)) = (a, b) {
            let mut view = h.view_mut((a * N, b * N), (N, N));
            view += m;
        }
    };
    for e in &graph.edges {
        let (ji, jj) = edge_jacobians(e, poses);
        let l = e.information;
        let (a, b) = (at(e.from), at(e.to));
        add(a, a, ji.transpose() * l * ji);
        add(b, b, jj.transpose() * l * jj);
        add(a, b, ji.transpose() * l * jj);
        add(b, a, jj.transpose() * l * ji);
    }
    for p in &graph.priors {
        let j = G::jr_inv(&p.residual(poses));
        let a = at(p.vertex);
        add(a, a, j.transpose() * p.information * j);
    }
    h
}

/// Block (a, b) of a dense matrix over N-blocks.
pub fn block<const N: usize>(m: &DMatrix<f64>, a: usize, b: usize) -> SMatrix<f64, N, N> {
    SMatrix::<f64, N, N>::from_fn(|p, q| m[(a * N + p, b * N + q)])
}
