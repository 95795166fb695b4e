//! Pose-graph optimisation and marginals (`eval::graph`): every Jacobian against central
//! differences, the marginals against a dense inverse on small graphs, GTSAM's tutorial
//! numbers, a chain without loop closures against first-order propagation, the gauge of
//! unconnected parts, Gauss–Newton's divergence against Levenberg–Marquardt, and GTSAM's
//! example files.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use posecov::eval::graph::{
    Anchor, GraphReading, Optimizer, SolverSettings, Stop, edge_jacobians, optimize,
    relative_covariance,
};
use posecov::lie::{LieGroup, Se2, Se3, TangentMatrix};
use posecov::plan::StepNoise;
use posecov::plan::graph::{GraphEdge, GraphPrior, GraphVertex, PoseGraph};
use posecov::propagate::odometry::propagate_increments_each;
use posecov::uncertain::UncertainPose;
use rand::{Rng, SeedableRng};

#[path = "common/graph.rs"]
mod graph_common;
use graph_common::{
    block, dense_information, evaluate_default, manhattan_walk, pose2_slam_example, se2_graph,
    se3_graph,
};

const POSE2: &str = include_str!("data/gtsam/pose2example.txt");
const POSE3: &str = include_str!("data/gtsam/pose3example.txt");

fn random_tangent<const N: usize>(rng: &mut impl Rng, scale: f64) -> SVector<f64, N> {
    SVector::<f64, N>::from_fn(|_, _| rng.random_range(-scale..scale))
}

/// Central differences of r(X_i Exp(δ_i), X_j Exp(δ_j)) against the analytic Jacobians.
fn check_jacobians<G: LieGroup<N>, const N: usize>(seed: u64) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..50 {
        let poses = [
            G::exp(&random_tangent(&mut rng, 2.0)),
            G::exp(&random_tangent(&mut rng, 2.0)),
        ];
        let edge = GraphEdge {
            from: 0,
            to: 1,
            measurement: G::exp(&random_tangent(&mut rng, 2.0)),
            information: TangentMatrix::<N>::identity(),
            line: 1,
        };
        let (ji, jj) = edge_jacobians(&edge, &poses);
        let h = 1e-6;
        for (which, analytic) in [(0, ji), (1, jj)] {
            let mut numeric = TangentMatrix::<N>::zeros();
            for k in 0..N {
                let mut d = SVector::<f64, N>::zeros();
                d[k] = h;
                let mut plus = poses;
                plus[which] = poses[which].rplus(&d);
                let mut minus = poses;
                minus[which] = poses[which].rplus(&-d);
                let column = (edge.residual(&plus) - edge.residual(&minus)) / (2.0 * h);
                numeric.set_column(k, &column);
            }
            assert!(
                (numeric - analytic).amax() < 1e-6,
                "{} edge Jacobian {which}: numeric {numeric} analytic {analytic}",
                G::NAME
            );
        }
        // The prior's Jacobian J_r⁻¹(r), the same way.
        let prior = GraphPrior {
            vertex: 0,
            measurement: edge.measurement,
            information: TangentMatrix::<N>::identity(),
            line: 1,
        };
        let analytic = G::jr_inv(&prior.residual(&poses));
        let mut numeric = TangentMatrix::<N>::zeros();
        for k in 0..N {
            let mut d = SVector::<f64, N>::zeros();
            d[k] = h;
            let column = (prior.residual(&[poses[0].rplus(&d)])
                - prior.residual(&[poses[0].rplus(&-d)]))
                / (2.0 * h);
            numeric.set_column(k, &column);
        }
        assert!((numeric - analytic).amax() < 1e-6, "{} prior", G::NAME);
    }
}

#[test]
fn edge_and_prior_jacobians_match_central_differences() {
    check_jacobians::<Se2, 3>(1);
    check_jacobians::<Se3, 6>(2);
}

#[test]
fn marginals_equal_the_dense_inverse_of_the_undamped_information() {
    // pose2example: vertex 0 holds the gauge; every other block of H⁻¹, and the joint block
    // of every edge, against a dense inverse.
    let graph = se2_graph(POSE2);
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(s.converged(), "{:?} {:?}", s.stop, s.log);
    let unknown: Vec<usize> = (1..graph.vertices.len()).collect();
    let h = dense_information(&graph, &s.poses, &unknown);
    let inverse = h.try_inverse().expect("invertible");
    for (k, &v) in unknown.iter().enumerate() {
        let cov = s.covariances[v].expect("a marginal");
        assert!(
            (cov - block::<3>(&inverse, k, k)).amax() < 1e-12,
            "vertex {v}"
        );
    }
    for (e, joint) in graph.edges.iter().zip(&s.edge_joints) {
        let (Some(a), Some(b)) = (
            unknown.iter().position(|&u| u == e.from),
            unknown.iter().position(|&u| u == e.to),
        ) else {
            continue;
        };
        let [ii, ij, jj] = joint.expect("joint");
        assert!((ii - block::<3>(&inverse, a, a)).amax() < 1e-12);
        assert!((ij - block::<3>(&inverse, a, b)).amax() < 1e-12);
        assert!((jj - block::<3>(&inverse, b, b)).amax() < 1e-12);
    }
    // The same in 3-D.
    let graph = se3_graph(POSE3);
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(s.converged(), "{:?}", s.stop);
    let unknown: Vec<usize> = (1..graph.vertices.len()).collect();
    let inverse = dense_information(&graph, &s.poses, &unknown)
        .try_inverse()
        .expect("invertible");
    for (k, &v) in unknown.iter().enumerate() {
        let cov = s.covariances[v].expect("a marginal");
        let reference = block::<6>(&inverse, k, k);
        assert!(
            (cov - reference).amax() < 1e-9 * reference.amax(),
            "vertex {v}"
        );
    }
}

/// GTSAM's tutorial (Dellaert, "Factor Graphs and GTSAM: A Hands-on Introduction", §2.5,
/// `examples/OdometryExample.cpp`): a prior on x1 with σ = (0.3, 0.3, 0.1), two odometry
/// steps (2, 0, 0) with σ = (0.2, 0.2, 0.1); printed with `cout.precision(2)`.
#[test]
fn gtsam_tutorial_odometry_marginals() {
    let text = "VERTEX_SE2 1 0.5 0.0 0.2\nVERTEX_SE2 2 2.3 0.1 -0.2\nVERTEX_SE2 3 4.1 0.1 0.1\n\
                EDGE_PRIOR_SE2 1 0 0 0 11.111111111111 0 0 11.111111111111 0 100\n\
                EDGE_SE2 1 2 2 0 0 25 0 0 25 0 100\nEDGE_SE2 2 3 2 0 0 25 0 0 25 0 100\n";
    let graph = se2_graph(text);
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(s.converged());
    assert_eq!(s.parts[0].anchor, Anchor::Priors { count: 1 });
    // x1: 0.09 0.09 0.01; x2: 0.13, 0.17, 0.02 | 0.02, 0.02; x3: 0.17, 0.37, 0.06 | 0.06, 0.03.
    let printed: [[[f64; 3]; 3]; 3] = [
        [[0.09, 0.0, 0.0], [0.0, 0.09, 0.0], [0.0, 0.0, 0.01]],
        [[0.13, 0.0, 0.0], [0.0, 0.17, 0.02], [0.0, 0.02, 0.02]],
        [[0.17, 0.0, 0.0], [0.0, 0.37, 0.06], [0.0, 0.06, 0.03]],
    ];
    for (v, expected) in printed.iter().enumerate() {
        let cov = s.covariances[v].unwrap();
        for p in 0..3 {
            for q in 0..3 {
                // Two significant digits, as printed.
                let tolerance = 0.005 + 0.05 * expected[p][q].abs();
                assert!(
                    (cov[(p, q)] - expected[p][q]).abs() <= tolerance,
                    "x{} ({p},{q}): {} vs printed {}",
                    v + 1,
                    cov[(p, q)],
                    expected[p][q]
                );
            }
        }
    }
    // The optimum is the odometry itself.
    assert!((s.poses[2].x() - 4.0).abs() < 1e-6 && s.poses[2].theta().abs() < 1e-6);
}

#[test]
fn a_chain_without_loop_closures_equals_first_order_propagation() {
    // A seeded random walk: the optimum is the chain itself (χ² = 0) and every marginal is
    // exactly the first-order propagated covariance from the anchored first vertex.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut graph = PoseGraph::<Se3, 6>::default();
    let mut pose = Se3::identity();
    let mut increments = Vec::new();
    let mut covs = Vec::new();
    graph.vertices.push(GraphVertex {
        id: 0,
        estimate: pose,
        line: 0,
    });
    for k in 0..40 {
        let z = Se3::exp(&random_tangent(&mut rng, 0.8));
        let a = SMatrix::<f64, 6, 6>::from_fn(|_, _| rng.random_range(-0.1..0.1));
        let cov = a * a.transpose() + SMatrix::<f64, 6, 6>::identity() * 1e-3;
        pose = pose.compose(&z);
        graph.vertices.push(GraphVertex {
            id: k + 1,
            estimate: pose,
            line: 0,
        });
        let information = cov.try_inverse().unwrap();
        graph.edges.push(GraphEdge {
            from: k as usize,
            to: k as usize + 1,
            measurement: z,
            information,
            line: 0,
        });
        increments.push(z);
        covs.push(cov);
    }
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert_eq!(s.stop, Stop::Converged);
    assert!(s.chi2_before < 1e-20, "the initial guess is the optimum");
    let propagated = propagate_increments_each(
        &UncertainPose::certain(Se3::identity()),
        &increments,
        &StepNoise::PerStep(covs),
    )
    .unwrap();
    // propagated[k] is vertex k (0: the start, held).
    assert_eq!(propagated.len(), 41);
    for (k, p) in propagated.iter().enumerate().skip(1) {
        let cov = s.covariances[k].unwrap();
        let reference = p.pose.cov();
        assert!(
            (cov - reference).amax() <= 1e-9 * reference.amax(),
            "vertex {k}: {cov} vs {reference}"
        );
    }
}

#[test]
fn unconnected_parts_are_each_anchored_and_an_isolated_vertex_is_kept() {
    let text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 5 5 5 0\nVERTEX_SE2 6 6 5 0.1\n\
                VERTEX_SE2 9 9 9 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\n\
                EDGE_SE2 5 6 1 0 0 100 0 0 100 0 100\nFIX 6\n";
    let graph = se2_graph(text);
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert_eq!(
        s.parts.iter().map(|p| p.anchor.clone()).collect::<Vec<_>>(),
        vec![
            Anchor::FirstVertex { id: 0 },
            Anchor::Fixed { ids: vec![6] },
            Anchor::Isolated { id: 9 },
        ]
    );
    // Held vertices keep their estimates and have no marginal.
    assert_eq!(s.poses[3], graph.vertices[3].estimate);
    assert_eq!(s.poses[4], graph.vertices[4].estimate);
    assert!(s.covariances[0].is_none() && s.covariances[3].is_none() && s.covariances[4].is_none());
    // Vertex 5 moved to 6 · Z⁻¹ and carries the edge's covariance, moved to its frame.
    assert!((s.poses[2].theta() - 0.1).abs() < 1e-9);
    let cov = s.covariances[2].unwrap();
    assert!((cov[(2, 2)] - 0.01).abs() < 1e-12);
}

#[test]
fn levenberg_marquardt_converges_where_gauss_newton_is_stopped_as_diverged() {
    let mut graph = manhattan_walk(300, 3);
    assert!(
        graph.edges.len() > 330,
        "loop closures: {}",
        graph.edges.len()
    );
    // A poor initial guess: every estimate rotated about the origin by its index.
    for (k, v) in graph.vertices.iter_mut().enumerate() {
        v.estimate = Se2::from_xy_theta(0.0, 0.0, 0.02 * k as f64).compose(&v.estimate);
    }
    let lm = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(lm.converged(), "{:?}", lm.stop);
    assert!(lm.chi2_after < lm.chi2_before);
    // χ² at the optimum is about its degrees of freedom (3 per edge less 3 per free pose).
    let dof = 3.0 * (graph.edges.len() as f64 - (graph.vertices.len() - 1) as f64);
    assert!(lm.chi2_after < 2.0 * dof, "χ² {} dof {dof}", lm.chi2_after);
    let gn = optimize(
        &graph,
        &SolverSettings {
            optimizer: Optimizer::GaussNewton,
            ..Default::default()
        },
        &mut |_| {},
    )
    .unwrap();
    // Gauss–Newton either reaches the same optimum or stops with its log and its last good
    // estimate, never a worse one.
    match gn.stop {
        Stop::Converged => assert!((gn.chi2_after - lm.chi2_after).abs() < 1e-3 * lm.chi2_after),
        Stop::Diverged => {
            assert!(gn.chi2_after <= gn.chi2_before);
            assert!(!gn.log.last().unwrap().accepted);
            assert!(
                (graph.chi2(&gn.poses, GraphReading::G2o) - gn.chi2_after).abs()
                    < 1e-9 * gn.chi2_after
            );
        }
        other => panic!("Gauss–Newton stopped as {other:?}"),
    }
}

#[test]
fn progress_sees_every_step_and_cancel_stops_between_iterations() {
    let graph = manhattan_walk(120, 5);
    let mut seen = 0;
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| seen += 1).unwrap();
    assert_eq!(seen, s.log.len());
    let cancel = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let s = optimize(
        &graph,
        &SolverSettings {
            cancel: Some(cancel),
            ..Default::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(s.stop, Stop::Interrupted);
    assert_eq!(s.poses, graph.estimates());
}

#[test]
fn loop_closure_relative_covariance_is_the_joint_marginal_moved() {
    let graph = se2_graph(POSE2);
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    // Edge 5 → 9 (a loop closure): its relative covariance against sampling the joint.
    let k = graph
        .edges
        .iter()
        .position(|e| e.from == 5 && e.to == 9)
        .unwrap();
    let joint = s.edge_joints[k].unwrap();
    let rel = relative_covariance(&s.poses[5], &s.poses[9], &joint);
    let full = DMatrix::from_fn(6, 6, |p, q| match (p < 3, q < 3) {
        (true, true) => joint[0][(p, q)],
        (true, false) => joint[1][(p, q - 3)],
        (false, true) => joint[1][(q, p - 3)],
        (false, false) => joint[2][(p - 3, q - 3)],
    });
    // Sampled at 1 % of the marginal's σ: the first-order map is what is checked (at full
    // size, the second-order terms of two far-from-anchor poses are as large as the result).
    let scale = 1e-4;
    let chol = (full * scale).cholesky().expect("a covariance");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let n = 40_000;
    let mut acc = SMatrix::<f64, 3, 3>::zeros();
    for _ in 0..n {
        let z = DVector::from_fn(6, |_, _| {
            rand_distr::Distribution::<f64>::sample(&rand_distr::StandardNormal, &mut rng)
        });
        let d = chol.l() * z;
        let xi = s.poses[5].rplus(&SVector::<f64, 3>::from_fn(|p, _| d[p]));
        let xj = s.poses[9].rplus(&SVector::<f64, 3>::from_fn(|p, _| d[p + 3]));
        let e = s.poses[5]
            .between(&s.poses[9])
            .inverse()
            .compose(&xi.between(&xj))
            .log();
        acc += e * e.transpose();
    }
    let sampled = acc / (n as f64 * scale);
    assert!(
        (sampled - rel).amax() < 0.03 * rel.amax(),
        "{sampled} vs {rel}"
    );
}

#[test]
fn gtsam_reading_changes_only_the_rotation_weight_in_3d() {
    let graph = se3_graph(POSE3);
    let g2o = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    let gtsam = optimize(
        &graph,
        &SolverSettings {
            reading: GraphReading::Gtsam,
            ..Default::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert!(g2o.converged() && gtsam.converged());
    // The same information over translation; 4× over rotation: rotation variances smaller.
    let (a, b) = (g2o.covariances[4].unwrap(), gtsam.covariances[4].unwrap());
    assert!(b[(5, 5)] < a[(5, 5)]);
    let graph2 = se2_graph(POSE2);
    let a = optimize(&graph2, &SolverSettings::default(), &mut |_| {}).unwrap();
    let b = optimize(
        &graph2,
        &SolverSettings {
            reading: GraphReading::Gtsam,
            ..Default::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(a.covariances, b.covariances, "2-D readings agree");
}

/// GTSAM's Pose2 SLAM tutorial graph (`examples/Pose2SLAMExample`: a prior on x1 with
/// σ = (0.3, 0.3, 0.1), four odometry edges with σ = (0.2, 0.2, 0.1) and the loop closure
/// 5 → 2), its marginals as GTSAM prints them (PyPI gtsam 4.3.0, `Marginals(graph,
/// result).marginalCovariance(i)`, numpy's 5 significant digits).
#[test]
fn gtsam_tutorial_pose2_slam_marginals() {
    let graph = se2_graph(&pose2_slam_example());
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(s.converged());
    let printed: [[[f64; 3]; 3]; 5] = [
        [[0.09, 0.0, 0.0], [0.0, 0.09, 0.0], [0.0, 0.0, 0.01]],
        [[0.13, 0.0, 0.0], [0.0, 0.17, 0.02], [0.0, 0.02, 0.02]],
        [
            [0.362, 0.0, 0.062],
            [0.0, 0.162, -0.002],
            [0.062, -0.002, 0.0265],
        ],
        [
            [0.268, -0.128, 0.048],
            [-0.128, 0.378, -0.068],
            [0.048, -0.068, 0.028],
        ],
        [
            [0.202, 0.036, -0.018],
            [0.036, 0.26, -0.051],
            [-0.018, -0.051, 0.0265],
        ],
    ];
    for (v, expected) in printed.iter().enumerate() {
        let cov = s.covariances[v].unwrap();
        for p in 0..3 {
            for q in 0..3 {
                assert!(
                    (cov[(p, q)] - expected[p][q]).abs() <= 1e-6 + 5e-5 * expected[p][q].abs(),
                    "x{} ({p},{q}): {} vs printed {}",
                    v + 1,
                    cov[(p, q)],
                    expected[p][q]
                );
            }
        }
    }
    // The optimum: x3 = (4, 0, π/2), x5 = (2, 2, −π/2).
    assert!((s.poses[4].x() - 2.0).abs() < 1e-6 && (s.poses[4].y() - 2.0).abs() < 1e-6);
}

#[test]
fn a_file_without_vertices_is_chained_from_its_edges_odometry_first() {
    // The loop closure 0 → 2 comes first in the file; the odometry edges place the vertices.
    let text = "EDGE_SE2 0 2 2.2 0 0 100 0 0 100 0 100\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\n\
                EDGE_SE2 1 2 1 0 0.5 100 0 0 100 0 100\nEDGE_SE2 3 2 1 0 0 100 0 0 100 0 100\n";
    let graph = se2_graph(text);
    let x: Vec<(f64, f64, f64)> = graph
        .vertices
        .iter()
        .map(|v| (v.estimate.x(), v.estimate.y(), v.estimate.theta()))
        .collect();
    assert_eq!(x[1], (1.0, 0.0, 0.0));
    assert_eq!(x[2], (2.0, 0.0, 0.5));
    // Vertex 3 only appears as the start of an edge to 2: X_3 = X_2 · Z⁻¹.
    let expected = graph.vertices[2]
        .estimate
        .compose(&Se2::from_xy_theta(1.0, 0.0, 0.0).inverse());
    assert!(graph.vertices[3].estimate.is_approx(&expected, 1e-12));
    assert!(graph.vertices.iter().all(|v| v.line == 0));
    let s = optimize(&graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(s.converged());
}

#[test]
fn duplicated_edges_are_kept_counted_and_noted() {
    let text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\n\
                EDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\nEDGE_SE2 1 2 1 0 0 100 0 0 100 0 100\n\
                EDGE_SE2 0 2 2 0 0 100 0 0 100 0 100\nEDGE_SE2 0 2 2.5 0 0 100 0 0 100 0 100\n";
    let graph = se2_graph(text);
    let g = evaluate_default(&graph);
    assert_eq!(g.duplicates, vec![(7, 6)]);
    assert_eq!(g.loop_closures.len(), 2, "both copies are loop closures");
    assert_eq!(g.edge_chi2.len(), 4);
    // Both pull: the optimum sits between 2 and 2.5 for vertex 2.
    let x2 = g.solution.poses[2].x();
    assert!(x2 > 2.0 && x2 < 2.5, "{x2}");
}
