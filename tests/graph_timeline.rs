//! What the loop closures did, one by one (`eval::graph` timeline): step 0 is the graph
//! without loop closures, each later step adds the next ones in file order and re-optimises,
//! the last is the full solution; the marginals never grow as closures arrive; the after view
//! follows the steps on the `step` timeline after the chain's, and leaves out (and says so)
//! marginals wider than the map; a graph beyond the size limit gets no timeline and says so.

use posecov::app::{Loaded, Overrides, pipeline};
use posecov::eval::graph::{MAX_TIMELINE_POSES, SolverSettings, optimize};
use posecov::input::open;
use posecov::scene::Timing;

#[path = "common/graph.rs"]
mod graph_common;
use graph_common::{evaluate_default, pose2example_drawn, se2_graph};

const POSE2: &str = include_str!("data/gtsam/pose2example.txt");

#[test]
fn each_step_adds_loop_closures_and_no_marginal_grows() {
    let graph = se2_graph(POSE2);
    let g = evaluate_default(&graph);
    let t = &g.timeline;
    let ks: Vec<usize> = t.steps.iter().map(|s| s.closures).collect();
    assert_eq!(ks, vec![0, 1, 2], "pose2example has 2 loop closures");
    // The last step is the full solution.
    let last = t.steps.last().expect("steps");
    assert_eq!(last.poses, g.solution.poses);
    assert_eq!(last.covariances, g.solution.covariances);
    // Step 0 is the graph without its loop closures, solved on its own.
    let lines: Vec<&str> = POSE2.lines().collect();
    let chain_only: String = lines
        .iter()
        .enumerate()
        .filter(|(k, _)| !g.loop_closures.iter().any(|l| l.line == k + 1))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let alone = optimize(
        &se2_graph(&chain_only),
        &SolverSettings::default(),
        &mut |_| {},
    )
    .expect("solved");
    for (v, (a, b)) in t.steps[0]
        .covariances
        .iter()
        .zip(&alone.covariances)
        .enumerate()
    {
        match (a, b) {
            (Some(a), Some(b)) => assert!((a - b).amax() < 1e-9 * b.amax(), "v{v}"),
            (None, None) => {}
            _ => panic!("v{v}: {a:?} vs {b:?}"),
        }
    }
    // Information only adds: no marginal grows from one step to the next (to rounding and
    // the relinearisation at each step's optimum).
    for pair in t.steps.windows(2) {
        for (v, (a, b)) in pair[0]
            .covariances
            .iter()
            .zip(&pair[1].covariances)
            .enumerate()
        {
            if let (Some(a), Some(b)) = (a, b) {
                assert!(
                    b.trace() <= a.trace() * (1.0 + 1e-3),
                    "v{v} grew from k = {} to {}: {} → {}",
                    pair[0].closures,
                    pair[1].closures,
                    a.trace(),
                    b.trace()
                );
            }
        }
    }
    // The last pose is the chain's end: the first closure (5 → 9) already shrinks it.
    let end = |k: usize| t.steps[k].covariances[10].expect("a marginal").trace();
    assert!(end(1) < 0.9 * end(0), "{} {}", end(0), end(1));
}

#[test]
fn the_after_view_follows_the_steps_after_the_chain() {
    let (loaded, evaluation, scene) = pose2example_drawn(Vec::new());
    let steps_of = |path: &str| -> Vec<i64> {
        scene
            .items
            .iter()
            .filter(|i| i.path == path)
            .filter_map(|i| match i.timing {
                Timing::Step(k) => Some(k),
                _ => None,
            })
            .collect()
    };
    // The chain has 10 steps: k = 0 from step 0, k = 1 at step 11, k = 2 at step 12.
    assert_eq!(
        steps_of("world/optimized/marginals/sigma_0"),
        vec![0, 11, 12]
    );
    assert_eq!(steps_of("world/optimized/closed"), vec![11, 12]);
    assert!(
        scene
            .description_markdown
            .contains("**Loop closures one by one**")
    );
    let json = posecov::app::report_json(
        "p",
        &loaded,
        &evaluation,
        posecov::uncertain::Confidence::DEFAULT,
    );
    let timeline = json["optimized"]["timeline"].as_array().expect("timeline");
    assert_eq!(timeline.len(), 3);
    assert_eq!(timeline[2]["chi2"], json["optimized"]["chi2_after"]);
}

#[test]
fn a_graph_beyond_the_limit_gets_no_timeline_and_says_so() {
    let n = MAX_TIMELINE_POSES + 1;
    let mut text = String::new();
    for k in 0..n {
        text += &format!("VERTEX_SE2 {k} {k} 0 0\n");
    }
    for k in 0..n - 1 {
        text += &format!("EDGE_SE2 {k} {} 1 0 0 100 0 0 100 0 100\n", k + 1);
    }
    text += "EDGE_SE2 0 20 20 0 0 100 0 0 100 0 100\n";
    let graph = se2_graph(&text);
    let g = evaluate_default(&graph);
    assert!(g.timeline.steps.is_empty());
    assert_eq!(g.timeline.too_large, Some(n));
}

/// The after view's final state on a graph whose information is weak (pose2example's divided by
/// 10⁴: σ of metres per edge on a map a few metres wide): its marginal ellipses would cover the
/// map many times over, so none is drawn and the legend says so; with the file's own
/// information every drawn ellipse is there and the legend says nothing of the kind.
#[test]
fn marginals_wider_than_the_map_are_left_out_of_the_final_state_and_said() {
    let weak: String = POSE2
        .lines()
        .map(|line| {
            let mut fields: Vec<String> = line.split_whitespace().map(str::to_owned).collect();
            if fields.first().is_some_and(|f| f == "EDGE_SE2") {
                for f in &mut fields[6..] {
                    *f = (f.parse::<f64>().expect("a number") * 1e-4).to_string();
                }
            }
            fields.join(" ") + "\n"
        })
        .collect();
    let dir = std::env::temp_dir().join(format!("posecov-weak-graph-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let final_ellipses_and_note = |text: &str| {
        let file = dir.join("g.g2o");
        std::fs::write(&file, text).unwrap();
        let (source, input) = open(file.to_str().unwrap()).expect("readable");
        let overrides = Overrides {
            samples: Some(64),
            ..Overrides::default()
        };
        let (_, scene) = pipeline(&Loaded { source, input }, &overrides, None).expect("drawn");
        let last = scene
            .items
            .iter()
            .filter_map(|i| match i.timing {
                Timing::Step(k) if i.path.starts_with("world/optimized/marginals/") => Some(k),
                _ => None,
            })
            .max()
            .expect("the after view's states");
        let ellipses: usize = scene
            .items
            .iter()
            .filter(|i| i.path.starts_with("world/optimized/marginals/"))
            .filter(|i| i.timing == Timing::Step(last))
            .map(|i| match &i.kind {
                posecov::scene::ItemKind::Ellipsoids(e) => e.shapes.len(),
                _ => 0,
            })
            .sum();
        let said = scene.legend.iter().any(|e| {
            e.label
                .starts_with("after: marginals wider than the map not drawn")
        });
        (ellipses, said)
    };
    let (weak_ellipses, weak_said) = final_ellipses_and_note(&weak);
    assert_eq!((weak_ellipses, weak_said), (0, true));
    let (ellipses, said) = final_ellipses_and_note(POSE2);
    assert!(ellipses > 0 && !said, "{ellipses} ellipses, said: {said}");
    std::fs::remove_dir_all(&dir).ok();
}
