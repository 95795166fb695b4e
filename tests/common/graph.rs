//! Pose-graph test helpers: a graph from g2o text, and H and its blocks as dense matrices
//! (tiny graphs only: the code under test never forms them).
#![allow(dead_code)]

use std::f64::consts::FRAC_PI_2;

use nalgebra::{DMatrix, SMatrix, SVector};
use posecov::eval::graph::{GraphEvaluation, GraphSettings, edge_jacobians, evaluate_graph};
use posecov::input::graph::read_text;
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::plan::AnyPlan;
use posecov::plan::graph::{GraphEdge, GraphVertex, PoseGraph};
use posecov::uncertain::Confidence;
use rand::{Rng, SeedableRng};

/// `tests/data/gtsam/pose2example.txt` opened, evaluated with 64 samples and the joint
/// marginals of `joints`, and drawn, as the CLI does: the input, its evaluation and its scene.
pub fn pose2example_drawn(
    joints: Vec<(u64, u64)>,
) -> (
    posecov::app::Loaded,
    posecov::eval::AnyEvaluation,
    posecov::scene::Scene,
) {
    let (source, input) =
        posecov::input::open("tests/data/gtsam/pose2example.txt").expect("readable");
    let loaded = posecov::app::Loaded { source, input };
    let overrides = posecov::app::Overrides {
        samples: Some(64),
        joints,
        ..posecov::app::Overrides::default()
    };
    let (evaluation, scene) = posecov::app::pipeline(&loaded, &overrides, None).expect("drawn");
    (loaded, evaluation, scene)
}

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

/// The graph evaluated with the default settings at the default confidence.
pub fn evaluate_default<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
) -> GraphEvaluation<G, N> {
    let settings = GraphSettings::default();
    evaluate_graph(graph, &settings, Confidence::DEFAULT, None, &mut |_, _| {}).expect("solvable")
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

/// A seeded Manhattan-world walk in the plane with loop closures: unit steps, a quarter turn
/// left or right 2 times in 5, noisy odometry (σ = 0.05, 0.05, 0.02) chained into the
/// initial guess, and a loop closure (same noise) with probability ½ between poses at most
/// 1.1 apart and more than 5 steps apart.
pub fn manhattan_walk(poses: usize, seed: u64) -> PoseGraph<Se2, 3> {
    let turns = [0.0, 0.0, 0.0, FRAC_PI_2, -FRAC_PI_2];
    let steps = turns.map(|turn| Se2::from_xy_theta(1.0, 0.0, turn));
    walk(poses, seed, &steps, [0.05, 0.05, 0.02], |d| {
        d.translation().norm()
    })
}

/// The same walk in space: unit steps, a quarter turn about z (left, right) 4 times in 9 and
/// about y (up, down) 2 times in 9, σ = 0.05 (translation) and 0.02 (rotation).
pub fn manhattan_walk_3d(poses: usize, seed: u64) -> PoseGraph<Se3, 6> {
    let turns = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, FRAC_PI_2],
        [0.0, 0.0, -FRAC_PI_2],
        [0.0, 0.0, FRAC_PI_2],
        [0.0, 0.0, -FRAC_PI_2],
        [0.0, FRAC_PI_2, 0.0],
        [0.0, -FRAC_PI_2, 0.0],
    ];
    let steps = turns.map(|rpy| Se3::from_xyz_rpy([1.0, 0.0, 0.0], rpy));
    let sigma = [0.05, 0.05, 0.05, 0.02, 0.02, 0.02];
    walk(poses, seed, &steps, sigma, |d| d.translation().norm())
}

fn walk<G: LieGroup<N>, const N: usize>(
    poses: usize,
    seed: u64,
    steps: &[G],
    sigma: [f64; N],
    distance: impl Fn(&G) -> f64,
) -> PoseGraph<G, N> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut truth = vec![G::identity()];
    for _ in 1..poses {
        let step = steps[rng.random_range(0..steps.len())];
        let last = *truth.last().unwrap();
        truth.push(last.compose(&step));
    }
    graph_of(&truth, &mut rng, sigma, |rng, _, _, d| {
        distance(d) < 1.1 && rng.random_bool(0.5)
    })
}

/// A seeded sphere of poses like the benchmark's sphere2500: `rings` × `per_ring` poses on a
/// sphere of radius 50 m, ring after ring from the south pole's side, each heading along its
/// ring; odometry between consecutive poses and a loop closure from each pose to the one
/// below it in the ring before; σ = 0.05 (translation) and 0.02 (rotation).
pub fn sphere(rings: usize, per_ring: usize, seed: u64) -> PoseGraph<Se3, 6> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let truth: Vec<Se3> = (0..rings * per_ring)
        .map(|k| {
            let (r, c) = (k / per_ring, k % per_ring);
            let latitude = -FRAC_PI_2 + std::f64::consts::PI * (r + 1) as f64 / (rings + 1) as f64;
            let longitude = std::f64::consts::TAU * c as f64 / per_ring as f64;
            let at = [
                50.0 * latitude.cos() * longitude.cos(),
                50.0 * latitude.cos() * longitude.sin(),
                50.0 * latitude.sin(),
            ];
            Se3::from_xyz_rpy(at, [0.0, 0.0, longitude + FRAC_PI_2])
        })
        .collect();
    let sigma = [0.05, 0.05, 0.05, 0.02, 0.02, 0.02];
    graph_of(&truth, &mut rng, sigma, |_, i, j, _| j - i == per_ring)
}

/// The graph of a true trajectory: odometry between consecutive poses, chained into the
/// initial guess, and a loop closure i → j (j more than 5 after i) wherever `closes` says so
/// (given the rng, i, j and the true relative pose), every measurement with noise σ.
fn graph_of<G: LieGroup<N>, const N: usize>(
    truth: &[G],
    rng: &mut rand_chacha::ChaCha8Rng,
    sigma: [f64; N],
    mut closes: impl FnMut(&mut rand_chacha::ChaCha8Rng, usize, usize, &G) -> bool,
) -> PoseGraph<G, N> {
    let poses = truth.len();
    let info = SMatrix::<f64, N, N>::from_diagonal(&SVector::<f64, N>::from_fn(|k, _| {
        1.0 / (sigma[k] * sigma[k])
    }));
    let noisy = |rng: &mut rand_chacha::ChaCha8Rng, z: G| {
        let n = SVector::<f64, N>::from_fn(|k, _| {
            sigma[k] * rand_distr::Distribution::<f64>::sample(&rand_distr::StandardNormal, rng)
        });
        z.rplus(&n)
    };
    let mut graph = PoseGraph::<G, N>::default();
    let mut guess = truth.first().copied().unwrap_or_else(G::identity);
    for k in 0..poses {
        if k > 0 {
            let z = noisy(rng, truth[k - 1].between(&truth[k]));
            graph.edges.push(GraphEdge {
                from: k - 1,
                to: k,
                measurement: z,
                information: info,
                line: 0,
            });
            guess = guess.compose(&z);
        }
        graph.vertices.push(GraphVertex {
            id: k as u64,
            estimate: guess,
            line: 0,
        });
    }
    for j in 0..poses {
        for i in 0..j.saturating_sub(5) {
            let d = truth[i].between(&truth[j]);
            if closes(rng, i, j, &d) {
                let z = noisy(rng, d);
                graph.edges.push(GraphEdge {
                    from: i,
                    to: j,
                    measurement: z,
                    information: info,
                    line: 0,
                });
            }
        }
    }
    graph
}

/// A pose graph as g2o text: `VERTEX_SE2` / `EDGE_SE2` for a planar group (x, y, θ), else
/// `VERTEX_SE3:QUAT` / `EDGE_SE3:QUAT` (x, y, z, qx, qy, qz, qw), each edge with the upper
/// triangle of its information matrix as stored (for SE(3) not converted to g2o's quaternion
/// error: a picture's test, not a numbers' one).
pub fn to_g2o<G: LieGroup<N>, const N: usize>(graph: &PoseGraph<G, N>) -> String {
    let planar = G::KIND.is_planar();
    let values = |x: &G| -> String {
        let se3 = x.to_se3();
        let t = se3.translation();
        let q = se3.rotation().to_quaternion_xyzw();
        let numbers: Vec<f64> = if planar {
            vec![t.x, t.y, 2.0 * q[2].atan2(q[3])]
        } else {
            vec![t.x, t.y, t.z, q[0], q[1], q[2], q[3]]
        };
        numbers
            .iter()
            .map(|v| format!("{v:.9}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let (vertex, edge) = if planar {
        ("VERTEX_SE2", "EDGE_SE2")
    } else {
        ("VERTEX_SE3:QUAT", "EDGE_SE3:QUAT")
    };
    let mut text = String::new();
    for v in &graph.vertices {
        text += &format!("{vertex} {} {}\n", v.id, values(&v.estimate));
    }
    for e in &graph.edges {
        let info: Vec<String> = (0..N)
            .flat_map(|r| (r..N).map(move |c| (r, c)))
            .map(|(r, c)| format!("{}", e.information[(r, c)]))
            .collect();
        text += &format!(
            "{edge} {} {} {} {}\n",
            graph.vertices[e.from].id,
            graph.vertices[e.to].id,
            values(&e.measurement),
            info.join(" ")
        );
    }
    text
}
