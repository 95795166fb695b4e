//! The 3-D views of the bundled scenarios: every view has a camera that holds everything it
//! draws, planar scenes are seen from above with x to the right, crowded scenes are split, and
//! the blueprint carries each camera (`EyeControls3D`) and each hidden entity
//! (`EntityBehavior`) where the viewer reads them.

#[cfg(feature = "viewer")]
mod rrd;

use nalgebra::Vector3;
use posecov::app::{Overrides, load, pipeline};
use posecov::input::scenario::bundled::BUNDLED;
use posecov::scene::{ItemKind, Scene, View3d};

fn scene_of(name: &str) -> Scene {
    let loaded = load(name).expect("bundled");
    let overrides = Overrides {
        samples: Some(200),
        ..Default::default()
    };
    pipeline(&loaded, &overrides, None).expect("evaluates").1
}

/// Positions an item draws (enough for a framing check: clouds, meshes, frames, strips).
fn positions(kind: &ItemKind) -> Vec<[f64; 3]> {
    match kind {
        ItemKind::Points(p) => p.positions.clone(),
        ItemKind::Surface(s) => s.vertices.clone(),
        ItemKind::Frame(f) => vec![f.translation],
        ItemKind::LineStrips(l) => l.strips.iter().flatten().copied().collect(),
        ItemKind::Ellipsoids(e) => e.shapes.iter().map(|s| s.center).collect(),
        _ => Vec::new(),
    }
}

/// Every drawn point of `view` lies inside its camera's 55° field of view, at the view's shape
/// in a 1024 × 640 window (its cell of the left column, above the legend view).
fn assert_in_view(name: &str, scene: &Scene, view: &View3d) {
    let camera = view
        .camera
        .unwrap_or_else(|| panic!("{name}/{}: no camera", view.name));
    let eye = Vector3::from(camera.position);
    let forward = (Vector3::from(camera.target) - eye).normalize();
    let right = forward.cross(&Vector3::from(camera.up)).normalize();
    let up = right.cross(&forward);
    let tan_y = (55.0f64.to_radians() / 2.0).tan();
    let tan_x = tan_y * posecov::scene::layout::views_aspect(scene, scene.views.len());
    let mut count = 0;
    for item in scene.items.iter().filter(|i| view.shows(&i.path)) {
        for p in positions(&item.kind) {
            let d = Vector3::from(p) - eye;
            let depth = d.dot(&forward);
            assert!(
                depth > 0.0,
                "{name}/{}: {} behind the eye",
                view.name,
                item.path
            );
            let (x, y) = (d.dot(&right) / depth, d.dot(&up) / depth);
            assert!(
                x.abs() <= tan_x * 1.001 && y.abs() <= tan_y * 1.001,
                "{name}/{}: {} at ({x:.3}, {y:.3}) outside ±({tan_x:.3}, {tan_y:.3})",
                view.name,
                item.path
            );
            count += 1;
        }
    }
    assert!(count > 0, "{name}/{}: draws nothing", view.name);
}

#[test]
fn every_view_of_every_bundled_scenario_holds_everything_it_draws() {
    for b in BUNDLED {
        let scene = scene_of(b.name);
        assert!(!scene.views.is_empty(), "{}", b.name);
        for view in &scene.views {
            assert_in_view(b.name, &scene, view);
        }
    }
}

#[test]
fn planar_scenes_are_seen_from_above_with_x_to_the_right() {
    for name in [
        "camera_on_robot",
        "diff_drive_banana",
        "na568_se2_odometry",
        "vector_space_vs_lie",
        "barfoot_compounding", // SE(3), planar motion: the file asks for the top view
    ] {
        let scene = scene_of(name);
        let camera = scene.views[0].camera.expect("a camera");
        let sight = (Vector3::from(camera.target) - Vector3::from(camera.position)).normalize();
        assert!(sight.z < -0.99, "{name}: looks along {sight}");
        let right = sight.cross(&Vector3::from(camera.up)).normalize();
        assert!(
            (right - Vector3::x()).norm() < 1e-6,
            "{name}: screen right is {right}"
        );
    }
}

#[test]
fn crowded_scenes_get_one_view_per_pose_or_per_method() {
    let names = |s: &Scene| s.views.iter().map(|v| v.name.clone()).collect::<Vec<_>>();
    let rotations = scene_of("rotation_global_vs_local");
    assert_eq!(
        names(&rotations),
        [
            "world_from_body",
            "global_rotation",
            "local_rotation",
            "inverse"
        ]
    );
    let se3 = scene_of("se3_global_vs_local");
    assert_eq!(
        names(&se3),
        [
            "first order",
            "second order",
            "fourth order",
            "sigma points",
            // The inversion, b_from_world (drawn from world_from_b's mean): exact, the inverse
            // of μ·Exp(ε) is Exp(−ε)·μ⁻¹.
            "exact"
        ]
    );
    // Each method's view shows its own banana surface and the Monte Carlo cloud, no other method.
    for view in &se3.views {
        let paths: Vec<&str> = se3
            .items
            .iter()
            .filter(|i| view.shows(&i.path))
            .map(|i| i.path.as_str())
            .collect();
        let slug = view.name.replace(' ', "_");
        // The composition's methods, or the inversion's (exact).
        let pose = if slug == "exact" {
            "b_from_world"
        } else {
            "world_from_b"
        };
        assert!(paths.contains(&format!("world/{pose}/{slug}/banana").as_str()));
        assert!(paths.contains(&format!("world/{pose}/monte_carlo/cloud").as_str()));
        for other in [
            "exact",
            "first_order",
            "second_order",
            "fourth_order",
            "sigma_points",
        ] {
            if other != slug {
                assert!(
                    !paths.iter().any(|p| p.contains(&format!("/{other}/"))),
                    "{}: shows {other}",
                    view.name
                );
            }
        }
    }
    // One view with the main method: the others start hidden, the vector-space ellipse stays.
    let robot = scene_of("camera_on_robot");
    assert_eq!(robot.views.len(), 1);
    assert_eq!(
        robot.views[0].hidden,
        ["world/map_from_camera/sigma_points"]
    );
    assert!(robot.description_markdown.contains("Hidden at first"));
}

#[cfg(feature = "viewer")]
#[test]
fn the_blueprint_carries_each_camera_and_each_hidden_entity() {
    use posecov::sink::{RecordingIds, scene_to_rrd_bytes};
    let scene = scene_of("camera_on_robot");
    let bytes = scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("c", 0)).unwrap();
    let paths: Vec<String> = rrd::store_chunks(&bytes, rerun::StoreKind::Blueprint)
        .iter()
        .map(|c| c.entity_path().to_string())
        .collect();
    let eye = paths
        .iter()
        .find(|p| p.ends_with("/EyeControls3D"))
        .expect("an eye for the 3-D view");
    let view = eye.trim_end_matches("/EyeControls3D");
    assert!(paths.iter().any(|p| p == view), "{paths:?}");
    let hidden =
        format!("{view}/ViewContents/overrides/world/map_from_camera/sigma_points/visualizers");
    assert!(paths.contains(&hidden), "{paths:?}");
    // The layout is deterministic: the same scene gives the same blueprint paths.
    let again = scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("c", 0)).unwrap();
    let mut a = paths.clone();
    let mut b: Vec<String> = rrd::store_chunks(&again, rerun::StoreKind::Blueprint)
        .iter()
        .map(|c| c.entity_path().to_string())
        .collect();
    a.sort();
    b.sort();
    assert_eq!(a, b);
}

/// Every bundled scenario's legend tiles fit their view at 1024 × 640 unscaled: a legend
/// taller than its view is scaled down, its words keep their size and overlap.
#[test]
fn legends_fit_their_view() {
    use posecov::scene::layout::{VIEW_CHROME, has_legend_view, legend_share, tiles};
    for bundled in BUNDLED {
        let scene = scene_of(bundled.name);
        if !has_legend_view(&scene) {
            continue;
        }
        let height = tiles(&scene.legend).height;
        assert!(
            height + VIEW_CHROME <= legend_share(height),
            "{}: the legend needs {height:.0} points, its view has {:.0}",
            bundled.name,
            legend_share(height) - VIEW_CHROME
        );
    }
}
