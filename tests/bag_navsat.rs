//! `sensor_msgs/NavSatFix` (issue 32): its position covariance and `position_covariance_type`
//! checked on a ROS 1 bag and an MCAP (CDR) of the same messages written by PyPI `rosbags`
//! (tests/data/navsat), `report --json`'s `sensors` and `fixes`, `check`'s lines and exit
//! codes, and what is drawn: the fixes and their regions in the local East-North plane, and an
//! IMU's orientation spray.

use posecov::draw::log::{LogDrawSettings, description, draw_log};
use posecov::eval::log::{LogEvalSettings, evaluate_log};
use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Class, Issue, LogSummary, SensorKind};
use posecov::scene::{ItemKind, Scene, Timing, paths};
use posecov::uncertain::Confidence;

mod posecov_cli;
use posecov_cli::run;

const BAG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/navsat/navsat.bag");
const MCAP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/navsat/navsat.mcap");
const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);

fn read(path: &str) -> LogSummary {
    read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap()
}

fn scene_of(path: &str) -> (Scene, String) {
    let mut plan = read(path);
    let e = evaluate_log(&mut plan, &LogEvalSettings::default());
    let confidence = Confidence::DEFAULT;
    let text = description(&plan, "ROS 1 bag", &e, confidence);
    let about = posecov::input::About {
        title: "navsat".into(),
        description: String::new(),
        source: String::new(),
    };
    let settings = LogDrawSettings {
        about,
        confidence,
        axis_length: None,
    };
    (draw_log(&e, &settings, &text), text)
}

#[test]
fn each_covariance_type_has_its_class_in_both_codecs() {
    for path in [BAG, MCAP] {
        let plan = read(path);
        assert!(plan.topics.is_empty(), "{path}");
        let names: Vec<&str> = plan.sensors.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "/gps/approximated",
                "/gps/diagonal_bad",
                "/gps/fix",
                "/gps/unknown"
            ],
            "{path}"
        );
        let [approximated, diagonal_bad, fix, unknown] = &plan.sensors[..] else {
            unreachable!()
        };
        for t in &plan.sensors {
            assert_eq!(t.kind, SensorKind::NavSatFix);
            assert_eq!(t.frame_id, "gps_antenna");
            assert_eq!(t.blocks[0].spec.axes, ["east", "north", "up"]);
        }
        // The honest topic: no finding at all, σ east 1.0…1.6 m, σ up 3 m.
        assert_eq!(fix.count, 30);
        let found: Vec<_> = fix.findings().map(|f| f.1).collect();
        assert!(found.is_empty(), "{path}: {found:?}");
        let east = fix.blocks[0].sigma_stats[0].unwrap();
        assert!((east.min - 1.0).abs() < 1e-12 && east.max > 1.59 && east.max <= 1.6);
        assert_eq!(fix.blocks[0].sigma_stats[2].unwrap().max, 3.0);
        assert_eq!(fix.drawn.fixes.len(), 30);
        // Unknown: a note, the block not checked (its zeros are no `all_zero`), no σ; the
        // NO_FIX message a note and not drawn.
        let b = &unknown.blocks[0];
        assert_eq!(b.health.count(Issue::CovarianceTypeUnknown), 20);
        assert_eq!(b.health.issues.len(), 1, "{:?}", b.health);
        assert_eq!(b.sigma_stats, [None; 3]);
        assert_eq!(unknown.health.count(Issue::NoFix), 1);
        assert_eq!(unknown.health.issues[&Issue::NoFix].first_index, 5);
        assert!(unknown.findings().all(|f| f.3 == Class::Note));
        assert_eq!(unknown.drawn.fixes.len(), 19);
        assert!(
            unknown
                .drawn
                .fixes
                .iter()
                .all(|f| f.covariance_enu.is_none())
        );
        // Approximated: a note beside the numbers' own (constant).
        let b = &approximated.blocks[0];
        assert_eq!(b.health.count(Issue::CovarianceApproximated), 10);
        assert_eq!(b.health.count(Issue::Constant), 10);
        assert_eq!(b.sigma_stats[0].unwrap().max, 3.0);
        // Diagonal known with off-diagonal entries: a defect; σ still read.
        let b = &diagonal_bad.blocks[0];
        assert_eq!(b.health.count(Issue::DiagonalKnownOffDiagonal), 10);
        assert_eq!(
            SensorKind::class(Issue::DiagonalKnownOffDiagonal),
            Class::Defect
        );
        assert_eq!(b.sigma_stats[0].unwrap().max, 2f64.sqrt());
    }
}

#[test]
fn the_report_gives_sigmas_in_metres_and_the_tangent_plane() {
    let (code, out, err) = run(&["report", "--json", BAG]);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["schema_version"], 2);
    let fix = &v["sensors"][2];
    assert_eq!(fix["name"], "/gps/fix");
    assert_eq!(fix["type"], "sensor_msgs/NavSatFix");
    assert_eq!(fix["kind"], "nav_sat_fix");
    let position = &fix["blocks"]["position"];
    assert_eq!(position["unit"], "m");
    assert_eq!(position["sigma"]["east"]["unit"], "m");
    assert_eq!(position["sigma"]["up"]["max"], 3.0);
    assert_eq!(position["health"], serde_json::json!({}));
    let plane = &fix["fixes"];
    assert_eq!(plane["projection"], "local_tangent_wgs84");
    assert_eq!(plane["drawn"], 30);
    assert_eq!(plane["with_region"], 30);
    assert_eq!(plane["origin"]["message"], 0);
    let lat = plane["origin"]["latitude_deg"].as_f64().unwrap();
    assert!((lat - 48.137).abs() < 1e-4, "{lat}");
    let unknown = &v["sensors"][3];
    let note = &unknown["blocks"]["position"]["health"]["covariance_type_unknown"];
    assert_eq!(note["class"], "note");
    assert_eq!(note["count"], 20);
    assert_eq!(unknown["health"]["no_fix"]["first_message"], 5);
    assert_eq!(
        unknown["blocks"]["position"]["sigma"],
        serde_json::json!({})
    );
    assert_eq!(unknown["fixes"]["with_region"], 0);
    let defect = &v["sensors"][1]["blocks"]["position"]["health"]["diagonal_known_off_diagonal"];
    assert_eq!(defect["class"], "defect");
    // The MCAP of the same messages gives the same sensors.
    let (_, mcap, _) = run(&["report", "--json", MCAP]);
    let w: serde_json::Value = serde_json::from_str(&mcap).unwrap();
    assert_eq!(v["sensors"], w["sensors"]);
}

#[test]
fn check_names_the_topic_and_block_of_a_defect() {
    let (code, out, err) = run(&["check", BAG]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(
        err.contains(
            "navsat.bag: topic /gps/diagonal_bad, message 0 (stamp 1700000000.000 s): \
             diagonal_known_off_diagonal on position_covariance — position_covariance_type = \
             COVARIANCE_TYPE_DIAGONAL_KNOWN (2)"
        ),
        "{err}"
    );
    assert!(!err.contains("covariance_type_unknown"), "a note: {err}");
    let (code, out, err) = run(&["check", BAG, "--allow", "diagonal_known_off_diagonal"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains("4 sensor topic(s)"), "{out}");
    // Only the unknown topic: notes only, exit 0.
    let (code, out, err) = run(&["check", BAG, "--topic", "/gps/unknown"]);
    assert_eq!(code, Some(0), "{out}{err}");
}

#[test]
fn fixes_are_drawn_in_the_east_north_plane_of_the_first() {
    let (scene, text) = scene_of(BAG);
    scene.validate().unwrap();
    let base = paths::fixes("/gps/fix");
    let points = scene
        .items
        .iter()
        .find(|i| i.path == paths::child(&base, "points"))
        .expect("points");
    let ItemKind::Points(p) = &points.kind else {
        panic!("{:?}", points.kind)
    };
    assert_eq!(p.positions.len(), 30);
    assert_eq!(p.positions[0], [0.0, 0.0, 0.0]);
    // The walk goes about 2 m north a second: the last fix ~58 m north of the first.
    let north = p.positions[29][1];
    assert!((50.0..66.0).contains(&north), "{north}");
    // One region per fix at its stamp, and all of them faint and static.
    let regions: Vec<_> = scene
        .items
        .iter()
        .filter(|i| i.path == paths::child(&base, "region"))
        .collect();
    assert_eq!(regions.len(), 30);
    assert!(regions.iter().all(|i| matches!(i.timing, Timing::Stamp(_))));
    // The unknown topic: dots, no region.
    let unknown = paths::fixes("/gps/unknown");
    assert!(
        !scene
            .items
            .iter()
            .any(|i| i.path == paths::child(&unknown, "region"))
    );
    // Its own view, which says the projection and its origin.
    let view = scene
        .views
        .iter()
        .find(|v| v.include == vec![base.clone()])
        .expect("view");
    assert!(
        view.name
            .contains("East-North (m) of the first fix 48.1370")
            && view.name.contains("local tangent plane, WGS84"),
        "{}",
        view.name
    );
    assert!(view.camera.is_some());
    assert!(
        scene
            .plots
            .iter()
            .any(|p| p.id.as_str() == "sigma_fix_position"),
        "{:?}",
        scene.plots
    );
    assert!(text.contains("**/gps/fix** drawn: 30 fixes"), "{text}");
    assert!(text.contains("covariance_type_unknown"), "{text}");
}

#[test]
fn an_imus_orientation_is_sprayed_at_its_newest_message() {
    let (scene, text) = scene_of(TEST2);
    scene.validate().unwrap();
    let base = paths::orientation_spray("/imu/data");
    let tips: Vec<_> = scene
        .items
        .iter()
        .filter(|i| paths::is_under(&i.path, &base) && i.path.contains("tips_"))
        .collect();
    assert_eq!(tips.len(), 3);
    for t in &tips {
        let ItemKind::Points(p) = &t.kind else {
            panic!()
        };
        assert_eq!(p.positions.len(), 100);
        // Axis tips of rotations: on the unit sphere.
        assert!(p.positions.iter().all(|q| {
            let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            (n - 1.0).abs() < 1e-9
        }));
    }
    let view = scene
        .views
        .iter()
        .find(|v| v.include == vec![base.clone()])
        .expect("spray view");
    assert!(
        view.name
            .contains("/imu/data: orientation at message 3060, 100 samples")
            && view.name.contains("tf2's reading"),
        "{}",
        view.name
    );
    assert!(text.contains("**/imu/data** drawn: its orientation at message 3060"));
    // The same seed, the same spray.
    let (again, _) = scene_of(TEST2);
    let a: Vec<_> = scene
        .items
        .iter()
        .filter(|i| i.path.starts_with(&base))
        .collect();
    let b: Vec<_> = again
        .items
        .iter()
        .filter(|i| i.path.starts_with(&base))
        .collect();
    assert_eq!(a, b);
}
