//! The log's drawing on real logs under `tests/data/`: read, evaluated and drawn through the
//! library's stages (a cross-stage test, so it lives here and not in `draw`).

use std::collections::BTreeMap;

use nalgebra::Vector3;
use posecov::draw::log::{LogDrawSettings, draw_log};
use posecov::eval::log::{LogEvalSettings, evaluate_log};
use posecov::input::About;
use posecov::input::log::{LogOptions, read_log};
use posecov::scene::{Ellipsoid, ItemKind, Scene, View3d};
use posecov::uncertain::Confidence;

/// The scene's whole-log views (one per frame; the robot views left out).
fn whole_log_views(scene: &Scene) -> Vec<&View3d> {
    scene
        .views
        .iter()
        .filter(|v| v.name.starts_with("frame "))
        .collect()
}

/// The scene of a log under `tests/data/`, drawn with the defaults.
fn scene_of(file: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    let mut plan = read_log(&path, &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    let e = evaluate_log(&mut plan, &LogEvalSettings::default());
    let settings = LogDrawSettings {
        about: About {
            title: "t".into(),
            description: String::new(),
            source: String::new(),
        },
        confidence: Confidence::DEFAULT,
        axis_length: None,
    };
    let scene = draw_log(&e, &settings, "");
    scene.validate().unwrap();
    scene
}

fn eye_distance(view: &View3d) -> f64 {
    let c = view.camera.expect("a camera");
    let d: Vector3<f64> = Vector3::from(c.position) - Vector3::from(c.target);
    d.norm()
}

#[test]
fn the_robot_view_is_at_the_scale_of_the_covariance() {
    // test2.bag: 84 m of driving, σx = σy = 31.6 mm, Σzz = 1e6 (a placeholder).
    let scene = scene_of("robot_localization/test2.bag");
    // The whole log, the robot view, and /imu/data's orientation spray (a view of its own).
    let [whole, robot, spray] = scene.views.as_slice() else {
        panic!("{:?}", scene.views);
    };
    assert!(
        spray.name.starts_with("/imu/data: orientation"),
        "{}",
        spray.name
    );
    assert_eq!(whole.name, "frame odom: the whole log");
    // The 95 % position region is r σ = 2.448 × 31.6 mm = 77 mm wide each way: the robot
    // view's eye stands well under a metre away, the whole log's tens of metres.
    assert!(eye_distance(robot) < 1.0, "{:?}", robot.camera);
    assert!(eye_distance(whole) > 20.0, "{:?}", whole.camera);
    // RViz's ellipse is its 7.7 cm, not the 10–24 m an eigen solver gives with the 1e6 in
    // place; the clipped z placeholder is 3 × that, and labelled in the whole-log view.
    let rviz: Vec<&Ellipsoid> = scene
        .items
        .iter()
        .filter(|i| i.path.ends_with("/rviz/position"))
        .flat_map(|i| match &i.kind {
            ItemKind::Ellipsoids(e) => e.shapes.iter().collect(),
            _ => Vec::new(),
        })
        .collect();
    assert!(!rviz.is_empty());
    let xy = 2.4477 * 0.001f64.sqrt();
    for shape in rviz {
        let mut h = shape.half_sizes;
        h.sort_by(f64::total_cmp);
        assert!(
            (h[0] - xy).abs() < 1e-3 && (h[1] - xy).abs() < 1e-3,
            "{h:?}"
        );
        assert!((h[2] - 3.0 * h[1]).abs() < 1e-9, "{h:?}");
    }
    let labelled = scene.items.iter().any(|i| {
        !i.path.contains("/robot/")
            && matches!(&i.kind, ItemKind::Ellipsoids(e)
                if e.label.as_deref() == Some("RViz: z placeholder (σ² ≥ 1e6), clipped"))
    });
    assert!(labelled);
    // The robot view's pose says the message's σ.
    let label = scene.items.iter().rev().find_map(|i| match &i.kind {
        ItemKind::Frame(f) if i.path.ends_with("/robot/pose") => f.label.clone(),
        _ => None,
    });
    let label = label.expect("a labelled robot pose");
    assert!(
        label.ends_with(": σx 31.6 mm, σy 31.6 mm, σyaw 9.92°"),
        "{label}"
    );
    // Plots in mm and degrees, fitted from 0 to just above the constant σ.
    let plot = &scene.plots[0];
    assert_eq!(plot.label(), "σ xy (mm)");
    let [low, high] = plot.range.unwrap();
    assert!(low == 0.0 && (high - 1.15 * 31.623).abs() < 0.01, "{high}");
    assert_eq!(scene.plots[1].label(), "σ yaw (°)");
}

#[test]
fn topics_in_different_frames_are_never_overlaid() {
    // The health-case MCAP: /planar/odom in `odom`, /amcl_pose in `map`, /bare without a
    // header (no frame_id).
    let scene = scene_of("mcap/health_cases.mcap");
    let whole = whole_log_views(&scene);
    assert_eq!(whole.len(), 3, "{:?}", scene.views);
    for view in &whole {
        // Each frame's view shows its own topics only, their robot views left out.
        assert_eq!(view.include.len(), 1, "{view:?}");
        assert_eq!(view.exclude, vec![format!("{}/robot", view.include[0])]);
        assert!(view.camera.is_some());
    }
    let robot = scene.views.len() - whole.len();
    assert_eq!(robot, 3, "one robot view per topic with a drawn pose");
    // The robot view's items sit at the origin: its frame at each stamp.
    let frames = scene.items.iter().filter(|i| {
        i.path.ends_with("/robot/pose")
            && matches!(&i.kind, ItemKind::Frame(f) if f.translation[..2] == [0.0, 0.0])
    });
    assert!(frames.count() > 0);
}

#[test]
fn rviz_s_placeholder_note_is_said_once_per_view() {
    // amcl_tf.mcap: /amcl_pose and /odom (joined into `map` through /tf), one view, both
    // with RViz's z placeholder, drawn at much the same place. The note is on one topic's
    // shapes only; both shapes are still drawn clipped.
    let scene = scene_of("mcap/amcl_tf.mcap");
    let whole = whole_log_views(&scene);
    assert_eq!(whole.len(), 1, "{:?}", scene.views);
    assert_eq!(whole[0].include.len(), 2, "{:?}", whole[0]);
    let shapes = |labelled: bool| -> BTreeMap<String, usize> {
        let mut by_topic = BTreeMap::new();
        for i in &scene.items {
            if let ItemKind::Ellipsoids(e) = &i.kind
                && i.path.ends_with("/rviz/position")
                && !i.path.contains("/robot/")
                && e.label.is_some() == labelled
            {
                *by_topic.entry(i.path.clone()).or_insert(0) += 1;
            }
        }
        by_topic
    };
    let labelled = shapes(true);
    assert_eq!(labelled.len(), 1, "{labelled:?}");
    let (path, count) = labelled.iter().next().unwrap();
    assert!(*count > 1, "{labelled:?}");
    // The other topic's shapes are drawn, unlabelled.
    let unlabelled = shapes(false);
    assert!(unlabelled.keys().any(|p| p != path), "{unlabelled:?}");
    let note = scene.items.iter().find_map(|i| match &i.kind {
        ItemKind::Ellipsoids(e) if i.path == *path => e.label.clone(),
        _ => None,
    });
    assert_eq!(
        note.as_deref(),
        Some("RViz: z placeholder (σ² ≥ 1e6), clipped")
    );
}
