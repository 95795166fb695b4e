//! Inputs that were once cut short, refused without a place, refused too late or accepted
//! silently: each is refused where it is read, with `file:line:column`, the key and what is
//! expected.

use posecov::app::live::{Edit, EditValue, LiveDocument};
use posecov::app::{Overrides, load_text, pipeline};
use posecov::input::scenario::Scenario;

const SE2: &str = r#"[scenario]
title = "t"
group = "se2"
methods = ["first_order", "monte_carlo"]
samples = 50

[[pose]]
name = "map_from_robot"
mean = { xy_theta = [1.0, 0.0, 0.3] }
cov = { std = [0.1, 0.1, 0.2] }

[[pose]]
name = "robot_from_camera"
mean = { xy_theta = [0.2, 0.0, 0.0] }

[[operation]]
kind = "between"
lhs = "map_from_robot"
rhs = "robot_from_camera"
output = "x"
"#;

const SE3: &str = r#"[scenario]
title = "t"
group = "se3"
methods = ["first_order"]

[[pose]]
name = "map_from_robot"
mean = { xyz = [1.0, 0.0, 0.0], rpy_deg = [0.0, 0.0, 30.0] }
cov = { std = [0.1, 0.1, 0.1, 0.05, 0.05, 0.05] }

[draw]
camera = { direction = [1.0, 1.0, 1.0] }
"#;

fn error_of(text: &str) -> String {
    let overrides = Overrides {
        samples: Some(50),
        ..Default::default()
    };
    match load_text(text, "bad.toml").and_then(|l| pipeline(&l, &overrides, None).map(drop)) {
        Ok(()) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .expect("needle")
        + 1
}

#[test]
fn the_seeds_are_good() {
    for text in [SE2, SE3] {
        let loaded = load_text(text, "good.toml").unwrap();
        pipeline(&loaded, &Overrides::default(), None).unwrap();
    }
}

/// Too many numbers for a fixed-length array: refused at the array, as too few are.
#[test]
fn too_many_numbers_are_refused_at_their_place() {
    let cases = [
        (
            SE2,
            "xy_theta = [1.0, 0.0, 0.3]",
            "xy_theta = [1, 2, 0.3, 99]",
            3,
            4,
        ),
        (
            SE2,
            "xy_theta = [1.0, 0.0, 0.3]",
            "xy_theta_deg = [1, 2, 3, 4]",
            3,
            4,
        ),
        (SE3, "xyz = [1.0, 0.0, 0.0]", "xyz = [1, 0, 0, 4]", 3, 4),
        (
            SE3,
            "rpy_deg = [0.0, 0.0, 30.0]",
            "rpy_deg = [0, 0, 30, 4]",
            3,
            4,
        ),
        (
            SE3,
            "rpy_deg = [0.0, 0.0, 30.0]",
            "quaternion_xyzw = [0, 0, 0, 1, 5]",
            4,
            5,
        ),
        (
            SE3,
            "rpy_deg = [0.0, 0.0, 30.0]",
            "axis_angle = [0, 0, 1, 0.5, 1]",
            4,
            5,
        ),
        (
            SE3,
            "direction = [1.0, 1.0, 1.0]",
            "direction = [1, 1, 1, 4]",
            3,
            4,
        ),
        (
            SE3,
            "direction = [1.0, 1.0, 1.0]",
            "direction = [1, 1]",
            3,
            2,
        ),
    ];
    for (seed, from, to, expected, found) in cases {
        let text = seed.replace(from, to);
        let e = error_of(&text);
        let line = line_of(&text, to);
        assert!(e.starts_with(&format!("bad.toml:{line}:")), "{to}: {e}");
        assert!(
            e.contains(&format!(
                "expected an array of {expected} numbers, found {found}"
            )),
            "{to}: {e}"
        );
    }
}

/// A byte that is not text is named at its line and column, in a file and by `check`.
#[test]
fn bytes_that_are_not_text_are_located() {
    let dir = std::env::temp_dir().join(format!("posecov-bad-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &[u8], &str); 3] = [
        (
            "invalid.toml",
            b"[scenario]\ntitle = \"a\xffb\"\n",
            "bad.toml:2:11: file: byte 0xFF is not UTF-8 text",
        ),
        (
            "nul.toml",
            b"[scenario]\ntitle = 'x'\ngr\x00oup = 'se2'\n",
            "bad.toml:3:3: file: a NUL byte is not text",
        ),
        (
            "cut.toml",
            b"[scenario]\ntitle = '\xc3",
            "bad.toml:2:10: file: a UTF-8 sequence cut short at the end of the file is not UTF-8 text",
        ),
    ];
    for (name, bytes, expected) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = posecov::input::open(path.to_str().unwrap())
            .err()
            .unwrap()
            .to_string();
        let expected = expected.replace("bad.toml", &path.display().to_string());
        assert!(
            e.starts_with(&expected),
            "{name}: {e}\nexpected: {expected}"
        );
        let e = Scenario::load(&path).unwrap_err().to_string();
        assert!(e.starts_with(&expected), "{name}: {e}");
    }
    let graph = dir.join("bad.g2o");
    std::fs::write(&graph, b"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 \xfe\n").unwrap();
    let e = posecov::input::graph::read_file(&graph)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("bad.g2o:2:18: file: byte 0xFE is not UTF-8 text; a g2o / GTSAM graph is text"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A camera whose numbers overflow once squared is refused where the file gives it.
#[test]
fn a_camera_too_far_is_refused_when_read() {
    let text = SE3.replace("direction = [1.0, 1.0, 1.0]", "direction = [1e155, 0, 1]");
    let e = load_text(&text, "bad.toml").err().unwrap().to_string();
    let line = line_of(&text, "1e155");
    assert!(e.starts_with(&format!("bad.toml:{line}:")), "{e}");
    assert!(
        e.contains("draw.camera") && e.contains("beyond ±1e9 m"),
        "{e}"
    );
    assert_eq!(e.matches("beyond").count(), 1, "said once: {e}");
}

/// One uncertain pose on both sides of `between` is one draw, not two independent ones.
#[test]
fn between_a_pose_and_itself_is_refused() {
    for kind in ["between", "compose"] {
        let text = SE2
            .replace("kind = \"between\"", &format!("kind = \"{kind}\""))
            .replace("rhs = \"robot_from_camera\"", "rhs = \"map_from_robot\"");
        let e = error_of(&text);
        let line = line_of(&text, "rhs = \"map_from_robot\"");
        assert!(e.starts_with(&format!("bad.toml:{line}:")), "{e}");
        assert!(
            e.contains("operation[0].rhs")
                && e.contains("the same uncertain pose `map_from_robot`"),
            "{e}"
        );
        assert!(e.contains(&format!("{kind}_correlated")), "{e}");
    }
    // A known transform on both sides is exact: nothing to refuse.
    let text = SE2.replace("lhs = \"map_from_robot\"", "lhs = \"robot_from_camera\"");
    load_text(&text, "ok.toml").unwrap();
}

/// A live edit whose file reads but does not evaluate (an odometry control of 1e16
/// overflows) is refused, naming the control, and the document is unchanged.
#[test]
fn a_live_edit_that_does_not_evaluate_is_refused() {
    let mut live = LiveDocument::open("na568_se3_odometry").unwrap();
    let before = live.text();
    let id = live
        .controls()
        .into_iter()
        .map(|c| c.id)
        .find(|id| id == "operation[0].controls[0][0]")
        .expect("an odometry control");
    let e = live
        .apply(&Edit {
            id: id.clone(),
            value: EditValue::Number(1e16),
        })
        .unwrap_err();
    assert_eq!(e.field().as_deref(), Some(id.as_str()), "{e}");
    assert!(e.to_string().contains("does not evaluate"), "{e}");
    assert_eq!(live.text(), before);
    // What the page offers for download still passes `check`.
    let loaded = load_text(&live.text(), "download.toml").unwrap();
    pipeline(
        &loaded,
        &Overrides {
            samples: Some(16),
            ..Default::default()
        },
        None,
    )
    .unwrap();
}

/// A key is named as the file writes it: `std_deg[2]`, not `std[2]`.
#[test]
fn a_negative_std_deg_is_named_as_typed() {
    let text = SE2.replace(
        "cov = { std = [0.1, 0.1, 0.2] }",
        "cov = { std_deg = [0.1, 0.1, -2] }",
    );
    let e = error_of(&text);
    assert!(e.contains("std_deg[2] = -2 is negative"), "{e}");
}
