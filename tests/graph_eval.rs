//! A pose graph evaluated (`eval::graph::evaluate_graph`): loop-closure residuals at the chosen
//! confidence (not a fixed 95 %) in the findings and the text panel; the joint marginal of any
//! two poses against a dense inverse and against GTSAM's `jointMarginalCovariance`; the
//! relative pose's covariance against a numeric Jacobian; `--joint`, `--optimizer` and
//! `--graph-reading` refused by name where they do not apply; mutated GTSAM files refused or
//! drawn, never a panic; each pose's σ before (dead reckoning) and after the loop closures, never
//! larger after, in `report --json` and plotted in the figure; the vertex estimates drawn as one
//! batch of frames.

use nalgebra::{DMatrix, SVector};
use posecov::app::{Loaded, Overrides, pipeline};
use posecov::eval::Finding;
use posecov::eval::graph::{GraphEvaluation, GraphSettings, evaluate_graph};
use posecov::input::{Format, open, open_text};
use posecov::lie::LieGroup;
use posecov::plan::graph::PoseGraph;
use posecov::uncertain::Confidence;

#[path = "common/graph.rs"]
mod graph_common;
use graph_common::{
    block, dense_information, pose2_slam_example, pose2example_drawn, se2_graph, se3_graph,
};

const POSE2: &str = include_str!("data/gtsam/pose2example.txt");
const POSE3: &str = include_str!("data/gtsam/pose3example.txt");
const OFFDIAGONAL: &str = include_str!("data/gtsam/pose3example-offdiagonal.txt");
const TOY: &str = include_str!("data/gtsam/noisyToyGraph.txt");

fn evaluated<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    settings: GraphSettings,
) -> GraphEvaluation<G, N> {
    let confidence = Confidence::DEFAULT;
    evaluate_graph(graph, &settings, confidence, None, &mut |_, _| {}).expect("solvable")
}

/// The graph evaluated at confidence `p`.
fn at<G: LieGroup<N>, const N: usize>(graph: &PoseGraph<G, N>, p: f64) -> GraphEvaluation<G, N> {
    let confidence = Confidence::new(p).expect("a probability");
    evaluate_graph(
        graph,
        &GraphSettings::default(),
        confidence,
        None,
        &mut |_, _| {},
    )
    .expect("solvable")
}

#[test]
fn loop_closure_residuals_are_measured_at_the_chosen_confidence() {
    // Edge 0 → 2 says v2 = v0 · (2, 0, 0); v2's estimate is 0.1 m off in y, σ_y = 0.1 m: d = 1.
    let text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0.1 0\n\
                EDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\nEDGE_SE2 1 2 1 0.1 0 100 0 0 100 0 100\n\
                EDGE_SE2 0 2 2 0 0 1 0 0 100 0 1\n";
    let graph = se2_graph(text);
    let g = at(&graph, 0.95);
    assert_eq!(g.loop_closures.len(), 1);
    let l = &g.loop_closures[0];
    assert_eq!((l.from, l.to, l.line), (0, 2, 6));
    // r = Log(Z⁻¹ X_0⁻¹ X_2) = Log((0, 0.1, 0)) = (0, 0.1, 0) exactly (no rotation).
    assert!(
        (l.mahalanobis_before - 1.0).abs() < 1e-12,
        "{}",
        l.mahalanobis_before
    );
    assert!((g.radius - 2.795_483).abs() < 1e-6, "{}", g.radius);
    // At 10 % the radius is √χ²₃(0.1) = 0.7644: the same residual lies beyond it.
    let g10 = at(&graph, 0.1);
    assert!((g10.radius - 0.764_443).abs() < 1e-5, "{}", g10.radius);
    assert!(g10.loop_closures[0].mahalanobis_before > g10.radius);

    // GTSAM's pose3example: edge 3 → 0 (line 11) puts v0 about 1 m from v3, the estimates are
    // 2.24 m apart: hundreds of σ. Edge 1 → 4 agrees.
    let graph = se3_graph(POSE3);
    let g = at(&graph, 0.95);
    let mut worst: Vec<_> = g.loop_closures.iter().collect();
    worst.sort_by(|a, b| b.mahalanobis_before.total_cmp(&a.mahalanobis_before));
    assert_eq!((worst[0].from, worst[0].to, worst[0].line), (3, 0, 11));
    assert!(
        worst[0].mahalanobis_before > 100.0,
        "{}",
        worst[0].mahalanobis_before
    );
    assert!(worst[1].mahalanobis_before < g.radius);
    assert!(
        (g.radius - 3.548_2).abs() < 1e-3,
        "√χ²₆(0.95): {}",
        g.radius
    );
}

/// The text panel and the findings of a pose graph at `confidence`.
fn panel_and_findings(
    file: &str,
    confidence: f64,
    joints: Vec<(u64, u64)>,
) -> (String, Vec<Finding>) {
    let (source, input) = open(file).expect("readable");
    let loaded = Loaded { source, input };
    let overrides = Overrides {
        samples: Some(64),
        confidence: Some(Confidence::new(confidence).expect("a probability")),
        joints,
        ..Overrides::default()
    };
    let (evaluation, scene) = pipeline(&loaded, &overrides, None).expect("drawn");
    (scene.description_markdown, evaluation.findings().to_vec())
}

#[test]
fn the_text_panel_tells_the_residuals_at_the_confidence_and_the_input_no_longer_does() {
    let (panel, _) = panel_and_findings("tests/data/gtsam/pose3example.txt", 0.95, Vec::new());
    assert!(
        panel.contains("At the file's estimates 1 of 2 lie beyond it"),
        "{panel}"
    );
    assert!(panel.contains("v3 → v0 (line 11) d = "), "{panel}");
    assert!(
        !panel.contains("Loop closures against the estimates"),
        "{panel}"
    );
    let (panel, _) = panel_and_findings("tests/data/gtsam/pose3example.txt", 0.5, Vec::new());
    assert!(panel.contains("50 % radius"), "{panel}");
    // The findings list the outliers after the optimisation, at the confidence given: a
    // smaller confidence, a smaller radius, never fewer outliers.
    let count = |confidence| {
        panel_and_findings("tests/data/gtsam/pose2example.txt", confidence, Vec::new())
            .1
            .iter()
            .filter(|f| matches!(f, Finding::LoopClosureOutlier { .. }))
            .count()
    };
    assert!(count(0.01) >= count(0.99));
}

#[test]
fn joint_marginal_of_any_two_poses_equals_the_dense_inverse() {
    // pose2example (v0 holds the gauge): pairs joined by an edge, pairs that are not, and a
    // pair with the fixed vertex (its blocks are zero).
    let graph = se2_graph(POSE2);
    let pairs = vec![(1, 7), (3, 10), (2, 9), (0, 5), (6, 5)];
    let g = evaluated(
        &graph,
        GraphSettings {
            joints: pairs.clone(),
            ..GraphSettings::default()
        },
    );
    let unknown: Vec<usize> = (1..graph.vertices.len()).collect();
    let inverse = dense_information(&graph, &g.solution.poses, &unknown)
        .try_inverse()
        .expect("invertible");
    for (joint, &(a, b)) in g.joints.iter().zip(&pairs) {
        assert_eq!((joint.a, joint.b), (a, b));
        let [aa, ab, bb] = joint.blocks.expect("blocks");
        let dense = |v: u64, w: u64| match (v, w) {
            (0, _) | (_, 0) => nalgebra::Matrix3::zeros(),
            _ => block::<3>(&inverse, v as usize - 1, w as usize - 1),
        };
        for (ours, reference, name) in [
            (aa, dense(a, a), "aa"),
            (ab, dense(a, b), "ab"),
            (bb, dense(b, b), "bb"),
        ] {
            assert!(
                (ours - reference).amax() < 1e-12 * reference.amax().max(1e-300),
                "({a}, {b}) Σ_{name}: {ours} vs {reference}"
            );
        }
    }
}

#[test]
fn joint_marginal_off_the_factor_pattern_comes_from_block_solves() {
    // A 40-pose chain with one loop closure: the ends' cross block is far outside L's
    // pattern for most orderings; it must still equal the dense inverse.
    let mut text = String::new();
    for k in 0..40 {
        text += &format!(
            "VERTEX_SE2 {k} {} {} {}\n",
            k as f64 * 0.9,
            0.05 * k as f64,
            0.01 * k as f64
        );
    }
    for k in 0..39 {
        text += &format!("EDGE_SE2 {k} {} 1 0 0.02 100 0 0 100 0 400\n", k + 1);
    }
    text += "EDGE_SE2 5 30 25 0 0 10 0 0 10 0 40\n";
    let graph = se2_graph(&text);
    let pairs = vec![(1, 39), (12, 27), (3, 33)];
    let g = evaluated(
        &graph,
        GraphSettings {
            joints: pairs.clone(),
            ..GraphSettings::default()
        },
    );
    let unknown: Vec<usize> = (1..40).collect();
    let inverse = dense_information(&graph, &g.solution.poses, &unknown)
        .try_inverse()
        .expect("invertible");
    for (joint, &(a, b)) in g.joints.iter().zip(&pairs) {
        let [_, ab, _] = joint.blocks.expect("blocks");
        let reference = block::<3>(&inverse, a as usize - 1, b as usize - 1);
        assert!(
            (ab - reference).amax() < 1e-10 * reference.amax(),
            "({a}, {b})"
        );
    }
}

#[test]
fn relative_covariance_is_the_joint_moved_by_a_numeric_jacobian() {
    // Cov(Log(T̂⁻¹ X_a⁻¹ X_b)) with X = X̂ Exp(δ): J Σ Jᵀ, J by central differences of the
    // relative pose in (δ_a, δ_b), against the adjoint formula the code uses.
    let graph = se2_graph(POSE2);
    let g = evaluated(
        &graph,
        GraphSettings {
            joints: vec![(2, 8), (0, 6)],
            ..GraphSettings::default()
        },
    );
    for joint in &g.joints {
        let (a, b) = (joint.a as usize, joint.b as usize);
        let (xa, xb) = (g.solution.poses[a], g.solution.poses[b]);
        let t = xa.inverse().compose(&xb);
        let f = |d: &SVector<f64, 6>| {
            let da = SVector::<f64, 3>::from_fn(|i, _| d[i]);
            let db = SVector::<f64, 3>::from_fn(|i, _| d[3 + i]);
            t.inverse()
                .compose(&xa.rplus(&da).inverse().compose(&xb.rplus(&db)))
                .log()
        };
        let h = 1e-6;
        let jac = DMatrix::from_fn(3, 6, |r, c| {
            let mut e = SVector::<f64, 6>::zeros();
            e[c] = h;
            (f(&e)[r] - f(&-e)[r]) / (2.0 * h)
        });
        let [aa, ab, bb] = joint.blocks.expect("blocks");
        let full = DMatrix::from_fn(6, 6, |r, c| match (r < 3, c < 3) {
            (true, true) => aa[(r, c)],
            (true, false) => ab[(r, c - 3)],
            (false, true) => ab[(c, r - 3)],
            (false, false) => bb[(r - 3, c - 3)],
        });
        let numeric = &jac * full * jac.transpose();
        let ours = joint.relative_cov.expect("same part");
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (ours[(r, c)] - numeric[(r, c)]).abs() < 1e-7 * numeric.amax(),
                    "({a}, {b}) [{r},{c}]: {} vs {}",
                    ours[(r, c)],
                    numeric[(r, c)]
                );
            }
        }
        assert!(joint.relative_pose.is_approx(&t, 1e-15));
    }
}

/// GTSAM's Pose2 SLAM tutorial graph (`examples/Pose2SLAMExample`: a prior on x1 with
/// σ = (0.3, 0.3, 0.1), four odometry edges with σ = (0.2, 0.2, 0.1), the loop closure 5 → 2):
/// the joint marginals as PyPI gtsam 4.3.0 prints them (`Marginals(graph, result)
/// .jointMarginalCovariance([a, b]).fullMatrix()`, numpy's default precision). GTSAM's Pose2
/// tangent is (x, y, θ), right perturbation: posecov's order, so the numbers compare as they are.
#[test]
fn gtsam_joint_marginal_covariance_of_the_pose2_slam_example() {
    let graph = se2_graph(&pose2_slam_example());
    let g = evaluated(
        &graph,
        GraphSettings {
            joints: vec![(2, 5), (1, 4), (3, 5)],
            ..GraphSettings::default()
        },
    );
    let printed: [[[f64; 6]; 6]; 3] = [
        [
            [0.13, 0.0, 0.0, 0.0, 0.13, 0.0],
            [0.0, 0.17, 0.02, -0.17, -0.04, 0.02],
            [0.0, 0.02, 0.02, -0.02, -0.04, 0.02],
            [0.0, -0.17, -0.02, 0.202, 0.036, -0.018],
            [0.13, -0.04, -0.04, 0.036, 0.26, -0.051],
            [0.0, 0.02, 0.02, -0.018, -0.051, 0.0265],
        ],
        [
            [0.09, 0.0, 0.0, -0.09, 0.0, 0.0],
            [0.0, 0.09, 0.0, 0.0, -0.09, 0.0],
            [0.0, 0.0, 0.01, 0.02, -0.04, 0.01],
            [-0.09, 0.0, 0.02, 0.268, -0.128, 0.048],
            [0.0, -0.09, -0.04, -0.128, 0.378, -0.068],
            [0.0, 0.0, 0.01, 0.048, -0.068, 0.028],
        ],
        [
            [0.362, 0.0, 0.062, -0.218, -0.124, 0.062],
            [0.0, 0.162, -0.002, 0.0, -0.142, 0.002],
            [0.062, -0.002, 0.0265, -0.018, -0.047, 0.0225],
            [-0.218, 0.0, -0.018, 0.202, 0.036, -0.018],
            [-0.124, -0.142, -0.047, 0.036, 0.26, -0.051],
            [0.062, 0.002, 0.0225, -0.018, -0.051, 0.0265],
        ],
    ];
    for (joint, expected) in g.joints.iter().zip(&printed) {
        let [aa, ab, bb] = joint.blocks.expect("blocks");
        for r in 0..6 {
            for c in 0..6 {
                let ours = match (r < 3, c < 3) {
                    (true, true) => aa[(r, c)],
                    (true, false) => ab[(r, c - 3)],
                    (false, true) => ab[(c, r - 3)],
                    (false, false) => bb[(r - 3, c - 3)],
                };
                // numpy prints at most 8 significant digits, trailing zeros dropped: these
                // are exact to 1e-6.
                assert!(
                    (ours - expected[r][c]).abs() <= 1e-6,
                    "x{} x{} [{r},{c}]: {ours} vs printed {}",
                    joint.a,
                    joint.b,
                    expected[r][c]
                );
            }
        }
    }
}

#[test]
fn the_vertex_estimates_are_one_batch_of_frames_at_the_files_estimates() {
    let (_, evaluation, scene) = pose2example_drawn(Vec::new());
    let posecov::eval::AnyEvaluation::Se2(e) = &evaluation else {
        panic!("pose2example is SE(2)")
    };
    let vertices: Vec<_> = scene
        .items
        .iter()
        .filter(|i| i.path == posecov::scene::paths::vertices())
        .collect();
    let [item] = vertices[..] else {
        panic!("one vertices item, got {}", vertices.len())
    };
    let posecov::scene::ItemKind::Triads(t) = &item.kind else {
        panic!("triads, got {:?}", item.kind)
    };
    // All 11 vertices are drawn, each at the file's estimate (x of VERTEX_SE2 1 is 1.03039).
    assert_eq!(t.translations.len(), 11);
    let v1 = e
        .nodes
        .iter()
        .find(|n| n.name == "v1")
        .expect("v1 is a node");
    assert_eq!(t.translations[1][0], v1.nominal.x());
    assert!((t.translations[1][0] - 1.03039).abs() < 1e-12);
    let own_entity = |path: &str| {
        let name = path
            .strip_prefix("world/v")
            .and_then(|p| p.strip_suffix("/frame"));
        name.is_some_and(|id| id.chars().all(|c| c.is_ascii_digit()))
    };
    assert!(
        !scene.items.iter().any(|i| own_entity(&i.path)),
        "no vertex has an entity of its own"
    );
}

#[test]
fn joint_pairs_are_in_report_json_and_drawn() {
    let (loaded, evaluation, scene) = pose2example_drawn(vec![(5, 9)]);
    let json = posecov::app::report_json("p", &loaded, &evaluation, Confidence::DEFAULT);
    let joint = &json["optimized"]["joints"][0];
    assert_eq!(
        (joint["a"].as_u64(), joint["b"].as_u64()),
        (Some(5), Some(9))
    );
    assert_eq!(joint["covariance"].as_array().expect("6 rows").len(), 6);
    assert_eq!(joint["relative_pose"].as_array().expect("x y θ").len(), 3);
    assert!(joint["relative_covariance"][2][2].as_f64().expect("σ²_θ") > 0.0);
    assert!(
        json["input"].get("worst_loop_closures").is_none(),
        "{}",
        json["input"]
    );
    assert!(
        scene
            .items
            .iter()
            .any(|i| i.path == "world/optimized/relative/v5_v9/banana"),
        "the pair's relative banana"
    );
    assert!(
        scene
            .description_markdown
            .contains("**Joint marginal of v5 and v9**")
    );
}

#[test]
fn graph_flags_are_refused_by_name_where_they_do_not_apply() {
    use posecov::app::resolve;
    let graph = open("tests/data/gtsam/pose2example.txt")
        .expect("readable")
        .1;
    let scenario = open("camera_on_robot").expect("bundled").1;
    let refused =
        |input, overrides: Overrides| resolve(input, &overrides, None).unwrap_err().to_string();
    let e = refused(
        &scenario,
        Overrides {
            optimizer: Some(posecov::eval::graph::Optimizer::GaussNewton),
            ..Overrides::default()
        },
    );
    assert_eq!(
        e,
        "--optimizer gn: applies to pose graphs (g2o / GTSAM files) only (it picks the optimiser of a pose graph, Levenberg–Marquardt or Gauss–Newton); this input is a scenario"
    );
    let e = refused(
        &scenario,
        Overrides {
            graph_reading: Some(posecov::plan::graph::GraphReading::Gtsam),
            ..Overrides::default()
        },
    );
    assert!(
        e.starts_with("--graph-reading gtsam: applies to pose graphs"),
        "{e}"
    );
    let e = refused(
        &scenario,
        Overrides {
            joints: vec![(1, 2)],
            ..Overrides::default()
        },
    );
    assert!(e.starts_with("--joint 1,2: applies to pose graphs"), "{e}");
    let e = resolve(
        posecov::app::RobotLog,
        &Overrides {
            joints: vec![(1, 2)],
            ..Overrides::default()
        },
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(e.ends_with("this input is a robot log"), "{e}");
    // On a graph: unknown vertex ids and a pair of one vertex are named.
    let e = refused(
        &graph,
        Overrides {
            joints: vec![(3, 4), (3, 99)],
            ..Overrides::default()
        },
    );
    assert_eq!(
        e,
        "--joint 3,99: this pose graph has no vertex 99 (11 vertices, ids 0 ..= 10)"
    );
    let e = refused(
        &graph,
        Overrides {
            joints: vec![(4, 4)],
            ..Overrides::default()
        },
    );
    assert!(
        e.starts_with("--joint 4,4: name two different vertices"),
        "{e}"
    );
    assert!(
        resolve(
            &graph,
            &Overrides {
                joints: vec![(0, 10)],
                ..Overrides::default()
            },
            None
        )
        .is_ok()
    );
    // Text read as a graph takes the same checks.
    let text = open_text(POSE2, "p.g2o", Format::Graph).expect("valid").1;
    assert!(
        refused(
            &text,
            Overrides {
                joints: vec![(11, 0)],
                ..Overrides::default()
            }
        )
        .contains("no vertex 11")
    );
}

#[test]
fn mutated_graphs_are_refused_or_drawn_never_a_panic_or_a_bad_scene() {
    // Replace each number of the GTSAM files, one at a time, by awkward values; every result
    // is a located error or a valid scene.
    use posecov::app::{AppError, Overrides};
    let awkward = [
        "0",
        "-0",
        "1e308",
        "-1e308",
        "1e-308",
        "nan",
        "-inf",
        "18446744073709551616",
        "",
        "1e6",
        "-1",
    ];
    let overrides = Overrides {
        samples: Some(16),
        ..Default::default()
    };
    let (mut drawn, mut refused) = (0, 0);
    for text in [POSE2, OFFDIAGONAL, TOY] {
        let tokens: Vec<&str> = text.split_whitespace().collect();
        for (k, _) in tokens.iter().enumerate().skip(1).step_by(3) {
            for value in awkward {
                let mut mutated = tokens.clone();
                mutated[k] = value;
                let mutated = mutated
                    .join(" ")
                    .replace(" VERTEX", "\nVERTEX")
                    .replace(" EDGE", "\nEDGE");
                let Ok((source, input)) = open_text(&mutated, "m.g2o", Format::Graph) else {
                    refused += 1;
                    continue;
                };
                let loaded = posecov::app::Loaded { source, input };
                match posecov::app::pipeline(&loaded, &overrides, None) {
                    Ok(_) => drawn += 1,
                    Err(AppError::Input(_)) => refused += 1,
                    Err(e) => panic!("token {k} = {value:?}: {e}\n{mutated}"),
                }
            }
        }
    }
    println!("{drawn} drawn, {refused} refused");
    assert!(
        drawn > 100 && refused > 100,
        "{drawn} drawn, {refused} refused"
    );
}

/// Every pose's σ after is at most its σ before, position and rotation, and both are the
/// roots of the marginals' block traces.
fn check_sigmas<G: LieGroup<N>, const N: usize>(g: &GraphEvaluation<G, N>, what: &str) {
    let sigmas = g.sigmas();
    assert_eq!(sigmas.len(), g.ids.len());
    let rot = G::KIND.rotation_range();
    let mut compared = 0;
    for (k, s) in sigmas.iter().enumerate() {
        let (Some(before), Some(after)) = (s.before, s.after) else {
            assert!(g.solution.covariances[k].is_none(), "{what}: v{}", g.ids[k]);
            continue;
        };
        let cov = g.solution.covariances[k].expect("a marginal");
        let position: f64 = (0..rot.start).map(|i| cov[(i, i)]).sum();
        let rotation: f64 = rot.clone().map(|i| cov[(i, i)]).sum();
        assert!((after.position - position.sqrt()).abs() <= 1e-12 * position.sqrt());
        assert!((after.rotation - rotation.sqrt()).abs() <= 1e-12 * rotation.sqrt());
        let dr = g.dead_reckoning[k].expect("a dead-reckoning marginal");
        let before_position: f64 = (0..rot.start).map(|i| dr[(i, i)]).sum();
        assert!((before.position - before_position.sqrt()).abs() <= 1e-12 * before.position);
        for (b, a, name) in [
            (before.position, after.position, "position"),
            (before.rotation, after.rotation, "rotation"),
        ] {
            assert!(
                a <= b * (1.0 + 1e-9),
                "{what}: v{} {name} σ after {a} > before {b}",
                g.ids[k]
            );
        }
        compared += 1;
    }
    assert!(
        compared + 1 >= g.ids.len(),
        "{what}: {compared} poses compared"
    );
    // Somewhere the loop closures made a difference.
    assert!(
        sigmas.iter().any(|s| match (s.before, s.after) {
            (Some(b), Some(a)) => a.position < 0.9 * b.position,
            _ => false,
        }),
        "{what}: no pose's σ shrank"
    );
}

#[test]
fn sigma_after_the_loop_closures_is_at_most_dead_reckonings_at_every_pose() {
    check_sigmas(
        &evaluated(&se2_graph(POSE2), GraphSettings::default()),
        "pose2example",
    );
    check_sigmas(
        &evaluated(&se3_graph(POSE3), GraphSettings::default()),
        "pose3example",
    );
    check_sigmas(
        &evaluated(
            &graph_common::manhattan_walk(400, 7),
            GraphSettings::default(),
        ),
        "manhattan walk",
    );
    check_sigmas(
        &evaluated(
            &graph_common::manhattan_walk_3d(200, 7),
            GraphSettings::default(),
        ),
        "3-D manhattan walk",
    );
    // Without loop closures, before is after.
    let chain = evaluated(
        &se2_graph(
            "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\n\
             EDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\nEDGE_SE2 1 2 1 0 0 100 0 0 100 0 400\n",
        ),
        GraphSettings::default(),
    );
    assert!(chain.sigmas().iter().all(|s| s.before == s.after));
}

#[test]
fn sigma_before_and_after_are_in_report_json_and_the_figure_plots_them() {
    let (loaded, evaluation, scene) = pose2example_drawn(Vec::new());
    let json = posecov::app::report_json("p", &loaded, &evaluation, Confidence::DEFAULT);
    let poses = json["optimized"]["poses"].as_array().expect("poses");
    let mut with_sigma = 0;
    for p in poses {
        let Some(cov) = p["covariance"].as_array() else {
            assert!(p["sigma"].is_null() && p["sigma_before"].is_null(), "{p}");
            continue;
        };
        let at = |r: usize| cov[r][r].as_f64().expect("a number");
        let after = &p["sigma"];
        let position = after["position"].as_f64().expect("m");
        assert!((position - (at(0) + at(1)).sqrt()).abs() < 1e-12, "{p}");
        let heading = after["rotation"].as_f64().expect("rad");
        assert!((heading - at(2).sqrt()).abs() < 1e-12, "{p}");
        let before = p["sigma_before"]["position"].as_f64().expect("m");
        assert!(position <= before * (1.0 + 1e-9), "{p}");
        with_sigma += 1;
    }
    assert_eq!(with_sigma, poses.len() - 1, "all but the anchor");

    // The plot: first, four lines over the poses with a marginal and the loop closures' ends.
    let plot = &scene.plots[0];
    assert_eq!(plot.id.as_str(), "graph_sigma");
    assert_eq!(
        plot.label(),
        "σ by pose, before/after loop closures (m, rad)"
    );
    let series: Vec<_> = scene.series.iter().filter(|s| s.plot == plot.id).collect();
    assert_eq!(series.len(), 5);
    assert!(
        series[..4]
            .iter()
            .all(|s| s.points.len() == with_sigma && !s.marks)
    );
    let ends = series[4];
    assert!(ends.marks);
    // v5 → v9 and v3 → v10 (pose2example's loop closures): four ends, a rug below the lines.
    let xs: Vec<i64> = ends.points.iter().map(|p| p.0).collect();
    assert_eq!(xs, vec![3, 5, 9, 10]);
    let lowest = series[..4]
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(f64::INFINITY, f64::min);
    assert!(ends.points.iter().all(|p| p.1 <= lowest));
    let svg = posecov::sink::figure::svg(&scene, &posecov::sink::figure::FigureOptions::default());
    for s in &series {
        assert!(svg.contains(&s.name), "the figure names {}", s.name);
    }
    assert!(svg.contains(&plot.label()));
    assert!(
        series[2].name.starts_with("heading σ"),
        "{}",
        series[2].name
    );
}
