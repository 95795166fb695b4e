//! Pose graphs at the edges of what is drawn: a graph whose optimised extent is a millionth of
//! its dead reckoning's still gets two views, each fitted to what it shows (issue 33, "Bad
//! input and limits").

use nalgebra::Vector3;
use posecov::app::{Overrides, load, pipeline};
use posecov::eval::AnyEvaluation;
use posecov::scene::View3d;

/// A chain of `n` poses 1 km apart by odometry (σ 100 m) whose loop closures k → k+2 and
/// k → k+3 (σ 1 mm) say they are 1 mm apart: optimised, the graph is about n mm long; dead
/// reckoning (and the file's estimates) n km.
fn collapsing_graph(n: usize) -> String {
    let mut text = String::new();
    for k in 0..n {
        text += &format!("VERTEX_SE2 {k} {} 0 0\n", k as f64 * 1000.0);
    }
    for k in 0..n - 1 {
        text += &format!("EDGE_SE2 {k} {} 1000 0 0 1e-4 0 0 1e-4 0 1e4\n", k + 1);
    }
    for gap in [2, 3] {
        for k in 0..n - gap {
            text += &format!(
                "EDGE_SE2 {k} {} {} 0 0 1e6 0 0 1e6 0 1e4\n",
                k + gap,
                gap as f64 * 1e-3
            );
        }
    }
    text
}

/// How far `view`'s eye is from what it looks at.
fn sight(view: &View3d) -> f64 {
    let camera = view.camera.expect("a camera");
    (Vector3::from(camera.position) - Vector3::from(camera.target)).norm()
}

#[test]
fn extents_a_million_apart_get_two_views_each_fitted_on_its_own() {
    let n = 20;
    let path = std::env::temp_dir().join(format!("posecov-collapsing-{}.g2o", std::process::id()));
    std::fs::write(&path, collapsing_graph(n)).expect("write");
    let loaded = load(path.to_str().expect("utf-8")).expect("valid");
    let overrides = Overrides {
        samples: Some(200),
        ..Default::default()
    };
    let (evaluation, scene) = pipeline(&loaded, &overrides, None).expect("evaluates");
    std::fs::remove_file(&path).ok();
    let AnyEvaluation::Se2(evaluation) = evaluation else {
        panic!("planar")
    };
    let g = evaluation.graph.as_ref().expect("a graph");
    let positions: Vec<Vector3<f64>> = g
        .solution
        .poses
        .iter()
        .map(|x| Vector3::new(x.x(), x.y(), 0.0))
        .collect();
    let optimised = positions.iter().map(|p| p.norm()).fold(0.0, f64::max);
    let dead_reckoning = (n - 1) as f64 * 1000.0;
    assert!(
        optimised > 0.01 && optimised < 0.03 && dead_reckoning / optimised > 5e5,
        "optimised extent {optimised} m against {dead_reckoning} m"
    );
    // The before and after views first (the close-ups, fitted on their own regions, follow).
    assert!(scene.views.len() >= 2, "{:?}", scene.views);
    let (before, after) = (&scene.views[0], &scene.views[1]);
    assert!(
        before.name.starts_with("before") && after.name.starts_with("after"),
        "{} / {}",
        before.name,
        after.name
    );
    assert!(
        scene.views[2..]
            .iter()
            .all(|v| v.name.starts_with("close-up")),
        "{:?}",
        scene.views
    );
    // Each eye is as far as its own content is wide (within a few times), not the other's.
    let (b, a) = (sight(before), sight(after));
    assert!(
        b > 0.3 * dead_reckoning && b < 20.0 * dead_reckoning,
        "before: eye {b} m for {dead_reckoning} m"
    );
    assert!(
        a > 0.3 * optimised && a < 20.0 * optimised,
        "after: eye {a} m for {optimised} m"
    );
    // The after view looks at the optimised poses, and its grid is on their scale.
    let target = Vector3::from(after.camera.expect("a camera").target);
    let centre = positions.iter().sum::<Vector3<f64>>() / n as f64;
    assert!(
        (target.xy() - centre.xy()).norm() < optimised,
        "after looks at {target:?}, the poses are about {centre:?}"
    );
    let grid = after.grid_spacing.expect("a grid");
    assert!(
        grid < 2.0 * optimised,
        "after: grid {grid} m for {optimised} m"
    );
}
