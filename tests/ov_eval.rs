//! OpenVINS `ov_eval` text trajectories with covariance (issue 32 item 3), on the files of
//! tests/data/ov_eval (written by its `make_ov_eval.py`: a TUM truth, and estimates whose
//! errors are drawn from each line's covariance in ov_eval's meaning): read as a log of one
//! topic — `report --json`, health, `check`, the view — with its NEES against a TUM reference
//! equal to ov_eval's own position and orientation NEES (computed here from the files with
//! ov_core's JPL formulas, independently of posecov's conventions); an ov_eval file as the
//! reference of a log topic; every line error located.

mod posecov_cli;
use posecov_cli::run;

mod common;

use std::path::PathBuf;

use nalgebra::{Matrix3, Rotation3, Vector3};
use posecov::app::Overrides;
use posecov::app::run::{Run, RunOptions, open};
use posecov::lie::{LieGroup, Se3};
use serde_json::Value;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ov_eval");

fn data(name: &str) -> String {
    format!("{DATA}/{name}")
}

fn report(args: &[&str]) -> Value {
    let mut all = vec!["report"];
    all.extend(args);
    all.push("--json");
    let (code, out, err) = run(&all);
    assert_eq!(code, Some(0), "{args:?}: {err}");
    serde_json::from_str(&out).expect("JSON")
}

/// A scratch file of its own per test.
fn scratch(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-ov-eval-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The numbers of a trajectory file's pose lines.
fn lines(name: &str) -> Vec<Vec<f64>> {
    std::fs::read_to_string(data(name))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// ov_core's `quat_2_Rot`: the four numbers (x, y, z, w) read as a JPL quaternion,
/// (2w² − 1) I − 2w ⌊q×⌋ + 2 q qᵀ.
fn quat_2_rot(q: &[f64]) -> Matrix3<f64> {
    let v = Vector3::new(q[0], q[1], q[2]);
    (2.0 * q[3] * q[3] - 1.0) * Matrix3::identity() - 2.0 * q[3] * v.cross_matrix()
        + 2.0 * v * v.transpose()
}

/// The upper triangle (11 12 13 22 23 33) as a symmetric matrix, as `Loader::load_data`.
fn upper(c: &[f64]) -> Matrix3<f64> {
    Matrix3::new(c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5])
}

/// ov_eval's `ResultTrajectory::calculate_nees`, on an estimate file against gt.txt (every
/// estimate stamp is a truth stamp): the mean position and orientation NEES.
fn ov_eval_nees(estimate: &str) -> (f64, f64) {
    let truth = lines("gt.txt");
    let (mut position, mut orientation, mut n) = (0.0, 0.0, 0.0);
    for e in lines(estimate) {
        let gt = truth
            .iter()
            .find(|g| (g[0] - e[0]).abs() < 1e-6)
            .expect("a truth line at the estimate's stamp");
        // e_R = quat_2_Rot(q_gt) quat_2_Rot(q_est)ᵀ, errori = −log_so3(e_R)
        let e_r = quat_2_rot(&gt[4..8]) * quat_2_rot(&e[4..8]).transpose();
        let errori = -Rotation3::from_matrix_unchecked(e_r).scaled_axis();
        orientation += (errori.transpose() * upper(&e[8..14]).try_inverse().unwrap() * errori)[0];
        let errpos = Vector3::new(gt[1] - e[1], gt[2] - e[2], gt[3] - e[3]);
        position += (errpos.transpose() * upper(&e[14..20]).try_inverse().unwrap() * errpos)[0];
        n += 1.0;
    }
    (position / n, orientation / n)
}

#[test]
fn an_ov_eval_estimate_has_ov_evals_own_nees_against_its_tum_truth() {
    let v = report(&[&data("estimate.txt"), "--reference", &data("gt.txt")]);
    assert_eq!(v["format"], "ov_eval");
    let t = &v["topics"][0];
    assert_eq!(t["name"], "/estimate");
    assert_eq!(t["messages"], 200);
    assert_eq!(t["type"], "ov_eval trajectory line");
    assert_eq!(t["planar"], false);
    assert_eq!(t["health"], serde_json::json!({}), "{}", t["health"]);
    // σ of the first line: Pt11 = 0.0408 m², in the parent's axes as written.
    let x = t["sigma"]["x"]["first"].as_f64().unwrap();
    assert!((x - 0.0408f64.sqrt()).abs() < 1e-12, "{x}");
    let c = &t["consistency"];
    assert_eq!(c["messages"], 200, "{c}");
    assert_eq!(c["verdict"], "consistent", "{c}");
    // posecov's position and orientation NEES are ov_eval's, computed from the files.
    let (position, orientation) = ov_eval_nees("estimate.txt");
    for (part, expected) in [("position", position), ("orientation", orientation)] {
        let value = c[part]["value"].as_f64().unwrap();
        assert!(
            (value / expected - 1.0).abs() < 1e-9,
            "{part}: {value} vs {expected}"
        );
        let band = &c[part]["band"];
        assert!(band[0].as_f64().unwrap() < value && value < band[1].as_f64().unwrap());
    }
    // The joint NEES (error on SE(3)) is their sum to first order.
    let anees = c["anees"].as_f64().unwrap();
    assert!(
        (anees / (position + orientation) - 1.0).abs() < 0.01,
        "{anees}"
    );

    // A tenth of each covariance: ten times every NEES, overconfident.
    let over = report(&[&data("overconfident.txt"), "--reference", &data("gt.txt")]);
    let c = &over["topics"][0]["consistency"];
    assert_eq!(c["verdict"], "overconfident", "{c}");
    assert!(
        (c["anees"].as_f64().unwrap() / anees - 10.0).abs() < 1e-6,
        "{c}"
    );
    let (position, orientation) = ov_eval_nees("overconfident.txt");
    for (part, expected) in [("position", position), ("orientation", orientation)] {
        let value = c[part]["value"].as_f64().unwrap();
        assert!(
            (value / expected - 1.0).abs() < 1e-9,
            "{part}: {value} vs {expected}"
        );
    }
}

#[test]
fn an_ov_eval_file_is_the_reference_of_a_log_topic_as_a_tum_file_is() {
    // The NEES log of tests/nees.rs (an MCAP with /ekf and its truth /ground_truth), its
    // truth as a TUM file and as an ov_eval file (the same poses, a covariance added).
    let log = scratch("nees.mcap", "");
    std::fs::write(&log, common::logs::nees_log(7)).unwrap();
    let tum = common::logs::truth_tum(&Se3::identity());
    let ov_eval: String = tum
        .lines()
        .map(|l| match l.starts_with('#') {
            true => format!("{l} Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23 Pt33\n"),
            false => format!("{l} 1e-4 0 0 1e-4 0 1e-4 0.01 0 0 0.01 0 0.01\n"),
        })
        .collect();
    let tum = scratch("truth.tum", &tum);
    let ov_eval = scratch("truth_ov_eval.txt", &ov_eval);
    let log = log.to_str().unwrap();
    let ekf = |reference: &str| {
        let v = report(&[log, "--reference", reference]);
        let t = v["topics"].as_array().unwrap().iter();
        let ekf = t.clone().find(|t| t["name"] == "/ekf").unwrap();
        ekf["consistency"].clone()
    };
    let (by_tum, by_ov_eval, by_topic) = (
        ekf(tum.to_str().unwrap()),
        ekf(ov_eval.to_str().unwrap()),
        ekf("/ground_truth"),
    );
    for key in ["messages", "anees", "verdict", "position", "orientation"] {
        assert_eq!(by_tum[key], by_ov_eval[key], "{key}");
    }
    let (a, b) = (
        by_ov_eval["anees"].as_f64().unwrap(),
        by_topic["anees"].as_f64().unwrap(),
    );
    assert!((a / b - 1.0).abs() < 1e-6, "{a} vs {b}");
    assert_eq!(by_ov_eval["verdict"], "consistent");
}

#[test]
fn check_view_and_health_work_as_for_a_log_topic() {
    let (code, out, err) = run(&["check", &data("estimate.txt")]);
    assert_eq!(code, Some(0), "{out}{err}");
    // An all-zero covariance: the all_zero defect, exit 1, allowed by name.
    let zero = scratch(
        "zero.txt",
        "1 0 0 0 0 0 0 1 0.01 0 0 0.01 0 0.01 1 0 0 1 0 1\n\
         2 1 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 0 0 0\n",
    );
    let zero = zero.to_str().unwrap();
    let (code, out, err) = run(&["check", zero]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(format!("{out}{err}").contains("all_zero"), "{out}{err}");
    let (code, _, err) = run(&["check", zero, "--allow", "all_zero"]);
    assert_eq!(code, Some(0), "{err}");
    // Lines of 8 columns (after ov_eval's header) carry no covariance: ROS's "unknown".
    let mixed = scratch(
        "mixed.txt",
        "# timestamp(s) tx ty tz qx qy qz qw Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23 Pt33\n\
         1 0 0 0 0 0 0 1\n\
         2 1 0 0 0 0 0 1 0.01 0 0 0.01 0 0.01 1 0 0 1 0 1\n\
         3 2 0 0 0 0 0 1\n",
    );
    let v = report(&[mixed.to_str().unwrap()]);
    let health = &v["topics"][0]["health"];
    assert_eq!(health["unknown_marker"]["count"], 2, "{health}");
    assert_eq!(v["topics"][0]["messages"], 3);
    // The view: a scene drawn and valid.
    let opened = open(&data("estimate.txt")).unwrap();
    let Run::Log(run) = Run::start(opened, &Overrides::default(), RunOptions::shown()).unwrap()
    else {
        panic!("not a log run")
    };
    assert_eq!(run.summary.topics[0].name, "/estimate");
    assert!(run.scene.validate().is_ok());
    let drawn = run
        .scene
        .items
        .iter()
        .filter(|i| i.path.contains("estimate"));
    assert!(drawn.count() > 10);
}

#[test]
fn every_line_error_is_located() {
    let good = "1 0 0 0 0 0 0 1 0.01 0 0 0.01 0 0.01 1 0 0 1 0 1";
    let cases = [
        ("1 0 0 0 0 0 0 1 0.01", ":2:1: line: 9 values"),
        (
            "2 0 0 0 0 0 0 1 0.01 0 0 0.01 0 0.01 1 0 0 1 0 1 7",
            ":2:1: line: 21 values",
        ),
        ("nan 0 0 0 0 0 0 1", ":2:1: timestamp: `nan` is not finite"),
        ("2 0 0 0 0.5 0 0 1", ":2:9: quaternion (qx qy qz qw)"),
        ("2 0 0 zero 0 0 0 1", ":2:7: tz: `zero` is not a number"),
        (
            "2 0 0 2e12 0 0 0 1",
            ":2:7: tz: 2000000000000 m lies beyond",
        ),
        (
            "2 0 0 0 0 0 0 1 0.01 0 0 0.01 0 0.01 1 3 0 1 0 1",
            ":2:38: Pt (Pt11…Pt33)",
        ),
        (
            "2 0 0 0 0 0 0 1 -0.01 0 0 0.01 0 0.01 1 0 0 1 0 1",
            ":2:17: Pr (Pr11…Pr33)",
        ),
    ];
    for (i, (line, expected)) in cases.iter().enumerate() {
        let path = scratch(&format!("bad{i}.txt"), &format!("{good}\n{line}\n"));
        let path = path.to_str().unwrap();
        for command in ["report", "check"] {
            // Exit 1: a located error, as a scenario's or a graph's.
            let (code, _, err) = run(&[command, path]);
            assert_eq!(code, Some(1), "{line}: {err}");
            assert!(err.contains(&format!("{path}{expected}")), "{line}: {err}");
        }
    }
    // ov_eval's frames are its own: the ROS reading does not apply.
    let (code, _, err) = run(&["report", &data("estimate.txt"), "--ros-reading", "body"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--ros-reading applies to ROS messages"),
        "{err}"
    );
}
