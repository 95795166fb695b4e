//! Running the `posecov` binary as a user does, for the command-line tests: its exit code,
//! standard output and standard error (one copy for every test file that runs the CLI).
#![allow(dead_code)]

use std::process::Command;

/// The binary Cargo built for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_posecov");

/// `posecov ARGS…`: (exit code, stdout, stderr).
pub fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(BIN).args(args).output().expect("run posecov");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `posecov ARGS…` that must exit 0, its stdout read as JSON.
pub fn json(args: &[&str]) -> serde_json::Value {
    let (code, out, err) = run(args);
    assert_eq!(code, Some(0), "{err}");
    serde_json::from_str(&out).expect("json")
}
