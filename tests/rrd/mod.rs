//! Helpers for tests that read .rrd recordings: decoding to chunks, comparing content, and
//! finding the Rerun CLI 0.36.3 for `rrd verify`.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Stdio};

use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

/// The recording's (not the blueprint's) chunks, in stream order.
pub fn recording_chunks(bytes: &[u8]) -> Vec<Chunk> {
    store_chunks(bytes, rerun::StoreKind::Recording)
}

/// The chunks of one kind of store (recording or blueprint), in stream order.
pub fn store_chunks(bytes: &[u8], kind: rerun::StoreKind) -> Vec<Chunk> {
    let decoder = DecoderApp::decode_eager(std::io::Cursor::new(bytes)).expect("an .rrd stream");
    decoder
        .map(|msg| msg.expect("decodable message"))
        .filter_map(|msg| match msg {
            LogMsg::ArrowMsg(store, arrow) if store.kind() == kind => {
                Some(Chunk::from_arrow_msg(&arrow).expect("a chunk"))
            }
            _ => None,
        })
        .collect()
}

/// Panics unless both recordings hold the same chunks (entity paths, timelines, component
/// data), ignoring row and chunk ids, which Rerun randomises.
pub fn assert_same_content(a: &[u8], b: &[u8]) {
    let (a, b) = (recording_chunks(a), recording_chunks(b));
    assert_eq!(a.len(), b.len(), "number of chunks");
    for (x, y) in a.iter().zip(&b) {
        if let Err(err) = Chunk::ensure_similar(x, y) {
            panic!("{} differs: {err:#}", x.entity_path());
        }
    }
}

/// The Rerun CLI: `$POSECOV_RERUN_CLI` (set by `.ci/run`), and nothing else. Under CI (`CI`
/// set) a missing CLI is a failure, not a skip.
pub fn rerun_cli() -> Option<PathBuf> {
    let found = std::env::var_os("POSECOV_RERUN_CLI")
        .map(PathBuf::from)
        .filter(|cli| {
            cli.is_file()
                && Command::new(cli)
                    .arg("--version")
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .status()
                    .is_ok_and(|s| s.success())
        });
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must provide the Rerun CLI (POSECOV_RERUN_CLI)"
        );
        eprintln!("skipping `rerun rrd` checks: no Rerun CLI 0.36.3 found (set POSECOV_RERUN_CLI)");
    }
    found
}
