//! NEES of a log against its ground truth, the Rust side of `benches/run_nees.sh`
//! (BENCHMARKS.md §8). No Rerun: `cargo build --release --no-default-features --example
//! nees_bench`.
//!
//! - `nees_bench write FILE [SECONDS]` writes the NEES test log of `tests/common/logs.rs` (the
//!   same generator as the tests, seed 7) with its truth spanning SECONDS (default 3600: the
//!   one-hour log — `/ground_truth` and `/tf` at 100 Hz, `/ekf` and `/ekf_overconfident` at
//!   10 Hz).
//! - `nees_bench report FILE` runs what `posecov report FILE --reference /ground_truth --json`
//!   runs (the library call the binary makes: the log read and streamed, every estimate's NEES,
//!   the health and the drawn messages; `report` draws no scene) and prints one JSON line per estimate
//!   topic — messages, ANEES, position and orientation ANEES, inside_95 — for
//!   `benches/nees_rosbags.py` to be compared with, plus the seconds it took.

#[allow(dead_code)]
#[path = "../tests/common/logs.rs"]
mod logs;

use std::time::Instant;

use posecov::app::Overrides;
use posecov::app::commands::report;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: nees_bench write FILE [SECONDS] | nees_bench report FILE";
    match (
        args.first().map(String::as_str),
        args.get(1),
        args.get(2).map(|s| s.parse::<f64>()),
    ) {
        (Some("write"), Some(file), seconds) => {
            let seconds = seconds.transpose()?.unwrap_or(3600.0);
            std::fs::write(file, logs::nees_log_spanning(7, "/ground_truth", seconds))?;
            Ok(())
        }
        (Some("report"), Some(file), None) => {
            let clock = Instant::now();
            let overrides = Overrides {
                reference: Some("/ground_truth".to_owned()),
                ..Overrides::default()
            };
            let text = report(file, &overrides, true)?;
            let seconds = clock.elapsed().as_secs_f64();
            let json: serde_json::Value = serde_json::from_str(&text)?;
            for topic in json["topics"].as_array().ok_or("no topics")? {
                let c = &topic["consistency"];
                if c.is_null() {
                    continue;
                }
                println!(
                    "{}",
                    serde_json::json!({
                        "side": "posecov",
                        "topic": topic["name"],
                        "messages": c["messages"],
                        "anees": c["anees"],
                        "anees_position": c["position"]["value"],
                        "anees_orientation": c["orientation"]["value"],
                        "inside_95": c["inside_95"],
                        "seconds": seconds,
                    })
                );
            }
            Ok(())
        }
        _ => Err(usage.into()),
    }
}
