//! Running the posecov binary in the live-stream tests (tests/live_ws.rs, tests/live_ws_network.rs):
//! its output, and what it said in one string for assertion messages.
#![allow(dead_code)]

use std::process::{Command, Output};

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_posecov");

/// Runs posecov with `args` to its end.
pub fn posecov(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run posecov")
}

/// Its exit code, stdout and stderr, in one string.
pub fn text(o: &Output) -> String {
    format!(
        "exit {:?}\nstdout: {}\nstderr: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
