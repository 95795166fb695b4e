//! Topics in different frames joined by the log's own `/tf` (issue 19, item 2): an odometry
//! topic in `odom` and a localisation topic in `map`, with AMCL's map → odom in `/tf`, are
//! drawn in one view in `map` — the odometry's poses moved by map_from_odom interpolated on
//! SE(3) at each stamp, never extrapolated, the covariance moved with them — and the panel and
//! `report --json` say which transform joined which frames. A `/tf` with a cycle, a missing
//! link or a frame that never gets a transform keeps the frames apart and says why; a cycle is
//! a defect for `check`.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::logs::{McapLog, cdr, header};
use nalgebra::{Matrix3, Matrix6, Vector6};
use posecov::app::{
    Overrides, log,
    run::{Run, open},
};
use posecov::eval::log::frames::{FrameProblemKind, TopicFrame, join_plan};
use posecov::eval::log::{LogEvalSettings, PoseState, evaluate_log};
use posecov::input::log::decode::{
    Odometry, Pose, PoseWithCovariance, PoseWithCovarianceStamped, nested,
};
use posecov::input::log::reference::{TfMessage, Transform, TransformStamped};
use posecov::input::log::{LogOptions, read_log};
use posecov::interop::{RosReading, ros_cov_moved, ros_cov_to_right};
use posecov::lie::{LieGroup, Se3, So3};
use posecov::plan::log::{ReferenceSample, TfEdge, TfTree};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const BIN: &str = env!("CARGO_BIN_EXE_posecov");

/// map_from_odom at t seconds: AMCL's correction, drifting slowly and turning.
fn map_from_odom(t: f64) -> Se3 {
    Se3::from_xyz_rpy(
        [1.0 + 0.05 * t, -0.5 + 0.02 * t, 0.0],
        [0.0, 0.0, 0.3 + 0.01 * t],
    )
}

/// odom_from_base at t seconds: a robot driving a circle.
fn odom_from_base(t: f64) -> Se3 {
    Se3::from_xyz_rpy(
        [2.0 * (0.2 * t).sin(), 2.0 - 2.0 * (0.2 * t).cos(), 0.0],
        [0.0, 0.0, 0.2 * t],
    )
}

fn ns(t: f64) -> i64 {
    (t * 1e9).round() as i64
}

/// A planar Odometry covariance with an x–y correlation (so that rotating it shows).
fn planar_cov() -> [f64; 36] {
    let mut c = [0.0; 36];
    for (i, v) in [0.01, 0.004, 1e6, 1e6, 1e6, 0.002].iter().enumerate() {
        c[i * 7] = *v;
    }
    c[1] = 0.003;
    c[6] = 0.003;
    c
}

fn pose_of(x: &Se3) -> Pose {
    let p = x.translation();
    Pose {
        position: [p.x, p.y, p.z],
        orientation: x.rotation().to_quaternion_xyzw(),
    }
}

fn transform(x: &Se3) -> Transform {
    let p = x.translation();
    Transform {
        translation: [p.x, p.y, p.z],
        rotation: x.rotation().to_quaternion_xyzw(),
    }
}

fn tf(parent: &str, child: &str, t: f64, x: &Se3) -> TransformStamped {
    TransformStamped {
        header: header(ns(t), parent),
        child_frame_id: child.into(),
        transform: transform(x),
    }
}

/// `/odom` (Odometry in `odom_frame`, 20 Hz from 10 s to 30 s), `/amcl_pose` (in `map`, 2 Hz),
/// `/tf`: `map_edges` at 5 Hz from 11 s to 29 s (the odometry's first and last second fall
/// outside it) and odom → base_link at 20 Hz; `/tf_static` base_link → laser. Both pose
/// topics publish [`planar_cov`] throughout.
fn log(odom_frame: &str, map_edges: &[(&str, &str)]) -> Vec<u8> {
    log_with(odom_frame, map_edges, |_| planar_cov())
}

/// The odometry's covariance at t seconds as dead reckoning makes it: [`planar_cov`] growing
/// linearly from 10 s (× 6 by 30 s), while AMCL's stays bounded.
fn growing_cov(t: f64) -> [f64; 36] {
    let mut c = planar_cov();
    for i in [0, 1, 6, 7, 35] {
        c[i] *= 1.0 + 0.25 * (t - 10.0);
    }
    c
}

/// [`log`] with the odometry's covariance at t seconds `odom_cov(t)`.
fn log_with(
    odom_frame: &str,
    map_edges: &[(&str, &str)],
    odom_cov: fn(f64) -> [f64; 36],
) -> Vec<u8> {
    let mut log = McapLog::new();
    let laser = Se3::from_xyz_rpy([0.2, 0.0, 0.3], [0.0; 3]);
    let static_tf = TfMessage {
        transforms: vec![tf("base_link", "laser", 10.0, &laser)],
    };
    log.put(
        "/tf_static",
        "tf2_msgs/msg/TFMessage",
        ns(10.0),
        &cdr(&static_tf),
    );
    for k in 0..=400 {
        let t = 10.0 + 0.05 * k as f64;
        let odom = Odometry {
            header: header(ns(t), odom_frame),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: pose_of(&odom_from_base(t)),
                covariance: nested(&odom_cov(t)),
            },
            twist: Default::default(),
        };
        log.put("/odom", "nav_msgs/msg/Odometry", ns(t), &cdr(&odom));
        let mut transforms = vec![tf("odom", "base_link", t, &odom_from_base(t))];
        if k % 4 == 0 && (20..=380).contains(&k) {
            for (parent, child) in map_edges {
                transforms.push(tf(parent, child, t, &map_from_odom(t)));
            }
        }
        log.put(
            "/tf",
            "tf2_msgs/msg/TFMessage",
            ns(t),
            &cdr(&TfMessage { transforms }),
        );
        if k % 10 == 5 {
            let amcl = PoseWithCovarianceStamped {
                header: header(ns(t), "map"),
                pose: PoseWithCovariance {
                    pose: pose_of(&map_from_odom(t).compose(&odom_from_base(t))),
                    covariance: nested(&planar_cov()),
                },
            };
            log.put(
                "/amcl_pose",
                "geometry_msgs/msg/PoseWithCovarianceStamped",
                ns(t),
                &cdr(&amcl),
            );
        }
    }
    log.finish()
}

/// The committed AMCL-like log (the guide's picture of a join, docs/guide/logs.md): this file's [`log_with`] with
/// AMCL's map → odom and the odometry's covariance growing as dead reckoning's does
/// ([`growing_cov`]). `POSECOV_UPDATE_GOLDEN=1 cargo test --test bag_frames` rewrites it.
const AMCL_EXAMPLE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mcap/amcl_tf.mcap");

#[test]
fn committed_amcl_log_is_the_generators_output() {
    let bytes = log_with("odom", &[("map", "odom")], growing_cov);
    if std::env::var_os("POSECOV_UPDATE_GOLDEN").is_some() {
        std::fs::write(AMCL_EXAMPLE, &bytes).expect("write the example");
    }
    // The writer's summary order is not byte-stable; what reading it gives must be the same.
    let options = LogOptions {
        every: Some(1),
        ..Default::default()
    };
    let generated = file("amcl_generated.mcap", &bytes);
    let read = |path: &Path| read_log(path, &options, &mut |_, _| {}, None).expect("read");
    assert!(
        read(Path::new(AMCL_EXAMPLE)) == read(&generated),
        "tests/data/mcap/amcl_tf.mcap is not this generator's output: rerun with POSECOV_UPDATE_GOLDEN=1"
    );
    // What the guide (docs/guide/logs.md) shows: /odom (in odom) drawn in map beside /amcl_pose.
    let run = log_run(Path::new(AMCL_EXAMPLE));
    let odom = run.evaluation.topics.iter().find(|t| t.name == "/odom");
    let join = odom.and_then(|t| t.joined.as_ref()).expect("joined");
    assert_eq!((join.from.as_str(), join.to.as_str()), ("odom", "map"));
    assert!(run.evaluation.frames.problems.is_empty());
    // The odometry's covariance grows: no defect, so `check` passes with nothing allowed.
    let out = Command::new(BIN)
        .args(["check", AMCL_EXAMPLE])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
}

fn file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-frames-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn log_run(path: &Path) -> log::LogRun {
    let overrides = Overrides {
        every: Some(1),
        ..Default::default()
    };
    match Run::start(
        open(path.to_str().unwrap()).unwrap(),
        &overrides,
        posecov::app::run::RunOptions::shown(),
    )
    .unwrap()
    {
        Run::Log(run) => *run,
        _ => panic!("a log"),
    }
}

fn check_code(path: &Path) -> (Option<i32>, String) {
    let (code, _, stderr) = check_allowing(path, &[]);
    (code, stderr)
}

/// `posecov check PATH --allow constant --allow NAME…`: the exit code, stdout and stderr.
fn check_allowing(path: &Path, names: &[&str]) -> (Option<i32>, String, String) {
    let mut command = Command::new(BIN);
    // The odometry's covariance is constant on purpose (a defect of its own): allowed.
    command.args(["check", path.to_str().unwrap(), "--allow", "constant"]);
    for name in names {
        command.args(["--allow", name]);
    }
    let out = command.output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn amcl_map_to_odom_joins_the_odometry_to_the_map() {
    let path = file("amcl.mcap", &log("odom", &[("map", "odom")]));
    let options = LogOptions {
        every: Some(1),
        ..Default::default()
    };
    let mut plan = read_log(&path, &options, &mut |_, _| {}, None).unwrap();
    let without_tf = posecov::plan::log::LogSummary {
        tf: TfTree::default(),
        ..plan.clone()
    };
    let names: Vec<String> = plan.tf.edges.iter().map(|e| e.name()).collect();
    assert_eq!(names, ["base_link→laser", "odom→base_link", "map→odom"]);
    let map_odom = plan.tf.edge("map", "odom").unwrap();
    assert_eq!((map_odom.messages, map_odom.samples.len()), (91, 91));
    let e = evaluate_log(&mut plan, &LogEvalSettings::default());
    assert!(e.frames.problems.is_empty(), "{:?}", e.frames);
    let odom = e.topics.iter().find(|t| t.name == "/odom").unwrap();
    let join = odom.joined.as_ref().expect("joined");
    assert_eq!((join.from.as_str(), join.to.as_str()), ("odom", "map"));
    // 10.00–10.95 s and 29.05–30.00 s lie outside map → odom's samples: never extrapolated.
    assert_eq!((join.left_out, join.moved), (20 + 20, 401 - 40));
    assert_eq!(join.first_left_out_ns, Some(ns(10.0)));
    assert_eq!(odom.frame_id, "map");
    let amcl = e.topics.iter().find(|t| t.name == "/amcl_pose").unwrap();
    assert!(amcl.joined.is_none() && amcl.frame_id == "map");
    let unmoved = evaluate_log(&mut { without_tf }, &LogEvalSettings::default());
    let unmoved = unmoved.topics.iter().find(|t| t.name == "/odom").unwrap();
    assert_eq!(unmoved.frame_id, "odom");
    let mut on_sample = 0;
    for p in &odom.poses {
        let t = p.stamp_ns as f64 * 1e-9;
        // The transform at t, interpolated here by hand on SE(3) between the 5 Hz samples.
        let k = ((t - 10.0) / 0.2).floor();
        let (ta, tb) = (10.0 + 0.2 * k, 10.0 + 0.2 * (k + 1.0));
        let (a, b) = (map_from_odom(ta), map_from_odom(tb));
        let s = (t - ta) / (tb - ta);
        let at = a.compose(&Se3::exp(&(s * a.inverse().compose(&b).log())));
        let expected = at.compose(&odom_from_base(t));
        let got = p.mean.unwrap();
        assert!(
            got.rminus(&expected).norm() < 1e-9,
            "{t}: {:?}",
            got.rminus(&expected)
        );
        // …and where AMCL says the robot is (the drift is linear, the turn rate constant).
        let truth = map_from_odom(t).compose(&odom_from_base(t));
        assert!(got.rminus(&truth).norm() < 1e-3);
        // The covariance: the right-form Gaussian is unchanged by the move…
        let before = unmoved.poses.iter().find(|q| q.index == p.index).unwrap();
        let (PoseState::Planar { pose, .. }, PoseState::Planar { pose: pose0, .. }) =
            (&p.state, &before.state)
        else {
            panic!("planar")
        };
        assert!((pose.cov() - pose0.cov()).norm() < 1e-12);
        // σ per axis stays as published, in `odom`'s axes.
        assert_eq!(p.sigma, before.sigma);
        // …and RViz's position block, in the parent's axes, is rotated by hand: R Σ Rᵀ.
        if (t * 5.0 - (t * 5.0).round()).abs() < 1e-9 {
            on_sample += 1;
            let yaw: f64 = 0.3 + 0.01 * t;
            let (c, s) = (yaw.cos(), yaw.sin());
            let r = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
            let sigma = Matrix3::new(0.01, 0.003, 0.0, 0.003, 0.004, 0.0, 0.0, 0.0, 1e6);
            let hand = r * sigma * r.transpose();
            let rviz = p.rviz.unwrap().position_cov;
            let xy = (rviz - hand).fixed_view::<2, 2>(0, 0).norm();
            assert!(
                xy < 1e-12 && (rviz[(2, 2)] - 1e6).abs() < 1e-6,
                "{rviz} vs {hand}"
            );
        }
    }
    assert_eq!(on_sample, 91);
    // Trajectory points are moved too.
    let point = odom.trajectory[odom.trajectory.len() / 2];
    let t = point.stamp_ns as f64 * 1e-9;
    let truth = map_from_odom(t).compose(&odom_from_base(t));
    assert!((truth.translation() - nalgebra::Vector3::from(point.position)).norm() < 1e-3);

    // The app: one whole-log view for both topics, the panel and the JSON say the join.
    let run = log_run(&path);
    let whole: Vec<&str> = run
        .scene
        .views
        .iter()
        .map(|v| v.name.as_str())
        .filter(|n| n.starts_with("frame "))
        .collect();
    assert_eq!(whole, ["frame map (+ /tf: /odom from odom): the whole log"]);
    let text = &run.scene.description_markdown;
    assert!(
        text.contains(
            "**Joined through the log's /tf**: /odom (in `odom`) drawn in `map`, moved by \
             map→odom at each stamp (interpolated on SE(3)): 361 drawn message(s); 40 stamped \
             outside the transforms' span (first at 10.000 s) left out, never extrapolated."
        ),
        "{text}"
    );
    assert!(
        text.contains("both blocks rotated by the transform (tf2's reading)"),
        "{text}"
    );
    let json = log::report_json("amcl", &run);
    let odom = &json["topics"][1];
    assert_eq!(odom["name"], "/odom");
    assert_eq!(odom["frame_id"], "odom");
    assert_eq!(odom["frame_join"]["to"], "map");
    assert_eq!(odom["frame_join"]["left_out"], 40);
    assert_eq!(json["frames"]["has_tf"], true);
    assert_eq!(json["frames"]["tf_edges"][2]["parent"], "map");
    assert_eq!(json["frames"]["tf_edges"][2]["messages"], 91);
    assert_eq!(json["frames"]["tf_edges"][0]["static"], true);
    assert_eq!(json["frames"]["problems"], serde_json::json!([]));
    assert_eq!(check_code(&path).0, Some(0));
}

/// The tf2 reading's rule Σ' = blkdiag(R, R) Σ blkdiag(R, R)ᵀ against Monte Carlo: errors
/// drawn in the parent's axes (p + δp, Exp(δφ) R), the pose moved by T, the errors of the
/// moved samples measured in the new parent's axes.
#[test]
fn the_moved_covariance_matches_monte_carlo() {
    let x = Se3::from_xyz_rpy([1.0, -2.0, 0.5], [0.4, -0.3, 1.1]);
    let t = Se3::from_xyz_rpy([3.0, 1.0, -0.2], [0.2, 0.5, -0.7]);
    let l = Matrix6::new(
        0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.05, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.02, 0.15, 0.0, 0.0,
        0.0, 0.01, 0.0, 0.0, 0.05, 0.0, 0.0, 0.0, 0.01, 0.0, 0.02, 0.08, 0.0, 0.0, 0.0, 0.03, 0.0,
        0.01, 0.06,
    );
    let sigma = l * l.transpose();
    let moved_mean = t.compose(&x);
    let mut rng = ChaCha8Rng::seed_from_u64(19);
    let n = 100_000;
    let mut sum = Matrix6::zeros();
    for _ in 0..n {
        let z = Vector6::from_fn(|_, _| StandardNormal.sample(&mut rng));
        let d = l * z;
        let p = x.translation() + d.fixed_rows::<3>(0);
        let r = So3::exp(&d.fixed_rows::<3>(3).into_owned()).compose(x.rotation());
        let y = t.compose(&Se3::from_parts(p, r));
        let dp = y.translation() - moved_mean.translation();
        let dphi = y.rotation().compose(&moved_mean.rotation().inverse()).log();
        let e = Vector6::new(dp.x, dp.y, dp.z, dphi.x, dphi.y, dphi.z);
        sum += e * e.transpose();
    }
    let empirical = sum / n as f64;
    let formula = ros_cov_moved(&sigma, t.rotation(), RosReading::Tf2);
    let rel = (empirical - formula).norm() / formula.norm();
    eprintln!("Monte Carlo ({n} samples) vs blkdiag(R, R) Σ blkdiag(R, R)ᵀ: {rel:.4} relative");
    assert!(rel < 0.02, "relative difference {rel}");
    // In the right form, nothing moves.
    let before = ros_cov_to_right(&sigma, x.rotation(), RosReading::Tf2);
    let after = ros_cov_to_right(&formula, moved_mean.rotation(), RosReading::Tf2);
    assert!((before - after).norm() < 1e-12 * before.norm());
}

#[test]
fn a_cycle_is_a_defect_said_and_nothing_is_joined() {
    // map → odom and odom → map: a cycle.
    let path = file(
        "cycle.mcap",
        &log("odom", &[("map", "odom"), ("odom", "map")]),
    );
    let run = log_run(&path);
    assert!(run.evaluation.topics.iter().all(|t| t.joined.is_none()));
    let json = log::report_json("cycle", &run);
    let kinds: Vec<&str> = json["frames"]["problems"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["tf_cycle"]);
    let cycle = json["frames"]["problems"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["kind"] == "tf_cycle")
        .unwrap();
    assert_eq!(cycle["class"], "defect");
    assert_eq!(cycle["source"], "/tf");
    assert_eq!(cycle["first_stamp_s"], 11.0);
    let sentence = cycle["sentence"].as_str().unwrap();
    assert!(sentence.starts_with("/tf has a cycle `"), "{sentence}");
    assert!(sentence.contains("(closed at 11.000 s)"), "{sentence}");
    assert!(
        run.scene
            .description_markdown
            .contains("**defect** `tf_cycle`")
    );
    let (code, stderr) = check_code(&path);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("cycle.mcap: tf_cycle — /tf has a cycle"),
        "{stderr}"
    );
    assert!(
        stderr.contains("(`--allow tf_cycle` accepts it)"),
        "{stderr}"
    );
    // Accepted on purpose: check passes, and says which defects it allowed.
    let (code, stdout, stderr) = check_allowing(&path, &["tf_cycle"]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(!stderr.contains("tf_cycle"), "{stderr}");
    assert!(
        stdout.contains(": ok (2 pose topic(s), ")
            && stdout.contains(", defects allowed: constant, tf_cycle)"),
        "{stdout}"
    );
    // The report still says it, as a defect.
    assert_eq!(cycle["class"], "defect");
    // Allowing another /tf defect does not accept this one.
    let (code, _, stderr) = check_allowing(&path, &["tf_several_parents"]);
    assert_eq!(code, Some(1), "{stderr}");
}

#[test]
fn a_missing_link_and_a_frame_never_transformed_are_said() {
    // /odom in `odom` under `world` (world → odom), /amcl_pose in `map`, which is in no
    // transform at all.
    let path = file("missing.mcap", &log("odom", &[("world", "odom")]));
    let run = log_run(&path);
    let json = log::report_json("missing", &run);
    let problem = &json["frames"]["problems"][0];
    assert_eq!(problem["kind"], "tf_no_transform");
    assert_eq!(problem["class"], "note");
    assert_eq!(problem["frames"], serde_json::json!(["map"]));
    assert_eq!(problem["topics"], serde_json::json!(["/amcl_pose"]));
    assert_eq!(problem["first_stamp_s"], 10.25);
    let whole = run
        .scene
        .views
        .iter()
        .filter(|v| v.name.starts_with("frame "))
        .count();
    assert_eq!(whole, 2, "one view per frame");
    assert_eq!(check_code(&path).0, Some(0));

    // Two trees: map → utm_link and world → odom: `map` and `odom` are in /tf, nothing joins.
    let path = file(
        "apart.mcap",
        &log("odom", &[("world", "odom"), ("map", "utm")]),
    );
    let run = log_run(&path);
    let json = log::report_json("apart", &run);
    let problem = &json["frames"]["problems"][0];
    assert_eq!(problem["kind"], "tf_missing_link");
    assert_eq!(problem["roots"], serde_json::json!(["map", "world"]));
    let sentence = problem["sentence"].as_str().unwrap();
    assert!(
        sentence.contains("the missing link is a transform between `map` and `world`"),
        "{sentence}"
    );
    assert!(
        run.scene
            .description_markdown
            .contains("note `tf_missing_link`")
    );
}

fn sample() -> ReferenceSample {
    ReferenceSample {
        stamp_ns: 0,
        position: [0.0; 3],
        orientation_xyzw: [0.0, 0.0, 0.0, 1.0],
    }
}

fn tree(edges: &[(&str, &str)]) -> TfTree {
    TfTree {
        edges: edges
            .iter()
            .map(|(p, c)| TfEdge {
                samples: vec![sample()],
                messages: 1,
                ..TfEdge::new(p, c, "/tf", 0)
            })
            .collect(),
        ..Default::default()
    }
}

#[test]
fn tree_problems_by_kind() {
    let topics = |frames: &[&'static str]| -> Vec<TopicFrame<'static>> {
        frames
            .iter()
            .map(|f| TopicFrame {
                topic: f,
                frame_id: f,
                first_stamp_ns: Some(0),
            })
            .collect()
    };
    // map → odom → base_link → map: a cycle.
    let plan = join_plan(
        &tree(&[("map", "odom"), ("odom", "base_link"), ("base_link", "map")]),
        &topics(&["map", "odom"]),
    );
    assert!(plan.chains.iter().all(Option::is_none));
    assert_eq!(plan.problems.len(), 1, "{:?}", plan.problems);
    assert_eq!(plan.problems[0].kind, FrameProblemKind::Cycle);
    assert_eq!(plan.problems[0].topics, ["map", "odom"]);
    // Two parents for one child: tf allows one.
    let plan = join_plan(
        &tree(&[("map", "odom"), ("world", "odom")]),
        &topics(&["odom", "map"]),
    );
    assert!(plan.chains.iter().all(Option::is_none));
    assert_eq!(plan.problems[0].kind, FrameProblemKind::SeveralParents);
    assert_eq!(plan.problems[0].frames, ["odom", "map", "world"]);
    // The common frame is the lowest common ancestor: earth → map → odom, map → gps.
    let plan = join_plan(
        &tree(&[("earth", "map"), ("map", "odom"), ("map", "gps")]),
        &topics(&["odom", "gps"]),
    );
    assert_eq!(
        plan.chains[0].as_deref(),
        Some(&["odom".to_owned(), "map".to_owned()][..])
    );
    assert_eq!(
        plan.chains[1].as_deref(),
        Some(&["gps".to_owned(), "map".to_owned()][..])
    );
    assert!(plan.problems.is_empty());
}
