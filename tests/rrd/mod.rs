//! Helpers for tests that read .rrd recordings: decoding to chunks, comparing content, and
//! finding the Rerun CLI 0.36.3 for `rrd verify`.
#![allow(dead_code)]

use std::collections::BTreeMap;
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

/// The recording's rows as one-row chunks, by entity path: static rows first, then by time
/// (stream order among rows at the same time). How many rows a chunk holds is the sink's
/// choice, not content.
pub fn recording_rows(bytes: &[u8]) -> BTreeMap<String, Vec<Chunk>> {
    let mut rows: BTreeMap<String, Vec<Chunk>> = BTreeMap::new();
    for chunk in recording_chunks(bytes) {
        for i in 0..chunk.num_rows() {
            rows.entry(chunk.entity_path().to_string())
                .or_default()
                .push(chunk.row_sliced_deep(i, 1));
        }
    }
    for list in rows.values_mut() {
        list.sort_by_key(|row| {
            let mut times: Vec<(String, i64)> = row
                .timelines()
                .iter()
                .map(|(name, column)| (name.to_string(), column.times_raw()[0]))
                .collect();
            times.sort();
            (!row.is_static(), times)
        });
    }
    rows
}

/// Panics unless both recordings hold the same rows (entity paths, timelines, component
/// data; [`recording_rows`]), ignoring row and chunk ids, which Rerun randomises, and how the
/// rows are chunked.
pub fn assert_same_content(a: &[u8], b: &[u8]) {
    let (a, b) = (recording_rows(a), recording_rows(b));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "entity paths"
    );
    for (path, xs) in &a {
        let ys = &b[path];
        assert_eq!(xs.len(), ys.len(), "{path}: number of rows");
        for (x, y) in xs.iter().zip(ys) {
            if let Err(err) = Chunk::ensure_similar(x, y) {
                panic!("{path} differs: {err:#}");
            }
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
