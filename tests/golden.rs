//! Golden recordings: every bundled scenario, recorded headless with a fixed seed and a small
//! sample count, must decode to the same content as its committed `tests/golden/<name>.rrd`,
//! and every recording must pass `rerun rrd verify`.
//!
//! After an intended change of what a scenario draws, regenerate with
//! `POSECOV_UPDATE_GOLDEN=1 cargo test --test golden`, look at the pictures, and commit.

mod rrd;

use std::path::PathBuf;
use std::process::Command;

use posecov::app::{Overrides, load, pipeline};
use posecov::input::scenario::bundled::BUNDLED;
use posecov::sink::{RecordingIds, scene_to_rrd_bytes};

/// Particles per input in golden recordings (small files, same code paths).
const GOLDEN_SAMPLES: u64 = 64;

fn golden_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.rrd"))
}

fn record(name: &str) -> Vec<u8> {
    let loaded = load(name).expect("bundled scenario loads");
    let overrides = Overrides {
        samples: Some(GOLDEN_SAMPLES),
        ..Default::default()
    };
    let (_, scene) = pipeline(&loaded, &overrides, None).expect("bundled scenario evaluates");
    let seed = loaded.input.defaults.seed.unwrap_or(0);
    scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario(name, seed)).expect("records")
}

#[test]
fn every_bundled_scenario_matches_its_golden_recording() {
    let update = std::env::var_os("POSECOV_UPDATE_GOLDEN").is_some();
    for b in BUNDLED {
        let bytes = record(b.name);
        let path = golden_path(b.name);
        if update {
            std::fs::create_dir_all(path.parent().expect("dir")).expect("mkdir");
            std::fs::write(&path, &bytes).expect("write golden");
            continue;
        }
        let golden = std::fs::read(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run POSECOV_UPDATE_GOLDEN=1 cargo test --test golden",
                path.display()
            )
        });
        rrd::assert_same_content(&golden, &bytes);
    }
}

#[test]
fn every_bundled_scenario_records_a_valid_rrd() {
    let Some(cli) = rrd::rerun_cli() else { return };
    let dir = std::env::temp_dir().join(format!("posecov-golden-verify-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("mkdir");
    let files: Vec<PathBuf> = BUNDLED
        .iter()
        .map(|b| {
            let file = dir.join(format!("{}.rrd", b.name));
            std::fs::write(&file, record(b.name)).expect("write");
            file
        })
        .collect();
    let out = Command::new(cli)
        .args(["rrd", "verify"])
        .args(&files)
        .output()
        .expect("run rerun rrd verify");
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        out.status.success(),
        "rerun rrd verify failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
