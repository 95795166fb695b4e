//! Errors of the command line in the user's words: one plain sentence, no Rust paths, no
//! clap "subcommand", and for `report --json` the same error as a JSON object on stdout.

use std::path::PathBuf;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_posecov");
const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);

fn posecov(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .env("PATH", "") // never a native viewer
        .output()
        .expect("posecov runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout_json(o: &Output) -> serde_json::Value {
    let text = String::from_utf8_lossy(&o.stdout);
    serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("stdout is not JSON ({e}): {text}"))
}

/// A file of its own for this test.
fn temp_file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("posecov-words-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn assert_plain(text: &str) {
    for rust in ["::", "subcommand", "unexpected argument", "panicked"] {
        assert!(!text.contains(rust), "{rust:?} in {text}");
    }
}

#[test]
fn two_inputs_to_the_viewer_get_a_sentence() {
    let o = posecov(&["so3_sampling", "camera_on_robot", "--save", "/dev/null"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("shows one input at a time, and was given 2: `so3_sampling`, `camera_on_robot`"),
        "{e}"
    );
    assert_plain(&e);
}

#[test]
fn a_mistyped_command_is_named() {
    let o = posecov(&["lve", "so3_sampling"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("`lve` is not a command; did you mean `posecov live so3_sampling`?"),
        "{e}"
    );
    assert_plain(&e);
}

#[test]
fn live_on_a_log_says_what_live_mode_edits() {
    let o = posecov(&["live", TEST2, "--bind", "127.0.0.1:0"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("live mode edits scenario files"), "{e}");
    assert!(e.contains(&format!("`posecov {TEST2}`")), "{e}");
    assert_plain(&e);
}

#[test]
fn a_failed_json_report_answers_in_json() {
    let bad = temp_file(
        "bad.toml",
        b"[scenario]\ntitle = \"t\"\ngroup = \"se2\"\nsamples = 1\n",
    );
    let o = posecov(&["report", "--json", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let json = stdout_json(&o);
    let error = &json["error"];
    assert_eq!(error["file"], bad.to_str().unwrap());
    assert_eq!(error["line"], 4);
    assert_eq!(error["column"], 11);
    assert_eq!(error["key"], "scenario.samples");
    assert_eq!(error["exit_code"], 1);
    let message = error["message"].as_str().unwrap();
    assert!(stderr(&o).contains(message), "{message} / {}", stderr(&o));
    // Without --json: text only.
    let o = posecov(&["report", bad.to_str().unwrap()]);
    assert!(o.stdout.is_empty());
}

#[test]
fn a_usage_error_of_a_json_report_answers_in_json() {
    let o = posecov(&["report", "--json", "so3_sampling", "--confidence", "95"]);
    assert_eq!(o.status.code(), Some(2));
    let json = stdout_json(&o);
    let message = json["error"]["message"].as_str().unwrap();
    assert!(message.contains("did you mean 0.95?"), "{message}");
    assert_eq!(json["error"]["exit_code"], 2);
    assert!(stderr(&o).contains("did you mean 0.95?"));
}

#[test]
fn a_damaged_bag_record_is_said_in_the_bags_words() {
    // Four zero bytes in a record header of the third chunk (found by the fuzz harness).
    let mut bytes = std::fs::read(TEST2).unwrap();
    bytes[433_157..433_161].fill(0);
    let bag = temp_file("damaged.bag", &bytes);
    let o = posecov(&["check", bag.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains(bag.to_str().unwrap()), "{e}");
    assert!(e.contains("chunk"), "{e}");
    assert!(!e.contains("rosbag"), "{e}");
    assert_plain(&e);
}

#[test]
fn near_misses_get_the_nearest_name() {
    // A bundled example.
    let e = stderr(&posecov(&["check", "camera_on_robt"]));
    assert!(e.contains("did you mean `camera_on_robot`?"), "{e}");
    // A topic of a log.
    let e = stderr(&posecov(&[
        "check",
        TEST2,
        "--topic",
        "/jackal_velocity_controller/odm",
    ]));
    assert!(
        e.contains("did you mean `/jackal_velocity_controller/odom`?"),
        "{e}"
    );
    // A key and a method of a scenario file.
    let toml = temp_file(
        "near.toml",
        b"[scenario]\ntitle = \"t\"\ngroup = \"se2\"\nmethods = [\"first_ordr\"]\n",
    );
    let e = stderr(&posecov(&["check", toml.to_str().unwrap()]));
    assert!(e.contains("did you mean `first_order`?"), "{e}");
}

#[test]
fn a_missing_path_is_one_line_and_a_damaged_db3_is_named() {
    let o = posecov(&["check", "no/such/dir/run.mcap"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(e.contains("no such file"), "{e}");
    assert!(
        !e.contains("camera_on_robot"),
        "the bundled list is for bare names: {e}"
    );
    let db3 = temp_file("run_0.db3", b"SQLite format 3\0rest of the file");
    let o = posecov(&["check", db3.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("run_0.db3: ") && e.contains("SQLite"), "{e}");
}
