//! End to end on every bundled scenario, through the library path the CLI uses (BENCHMARKS.md):
//! - `report`: parse + lower + evaluate + the JSON records (`posecov report <scenario> --json`);
//! - `save`: parse + lower + evaluate + draw + [`scene_to_rrd_bytes`]
//!   (`posecov <scenario> --save x.rrd`, less the file write).
//!
//! Run: `cargo bench --bench end_to_end -- --warm-up-time 1 --measurement-time 3`
//! (needs the `viewer` feature, on by default).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use posecov::app::{Overrides, evaluate, load_text, pipeline, resolve};
use posecov::input::scenario::bundled::BUNDLED;
use posecov::sink::{RecordingIds, scene_to_rrd_bytes};

fn report(name: &str, text: &str) -> String {
    let loaded = load_text(text, name).expect("bundled scenario loads");
    let settings = resolve(&loaded.input, &Overrides::default(), None).expect("settings");
    let evaluation = evaluate(&loaded, &settings.eval).expect("bundled scenario runs");
    serde_json::to_string_pretty(&evaluation.records()).expect("records serialise")
}

fn save(name: &str, text: &str) -> Vec<u8> {
    let loaded = load_text(text, name).expect("bundled scenario loads");
    let (_, scene) = pipeline(&loaded, &Overrides::default(), None).expect("bundled scenario runs");
    scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario(name, 0)).expect("scene encodes")
}

fn end_to_end(c: &mut Criterion) {
    for kind in ["report", "save"] {
        let mut g = c.benchmark_group(format!("e2e.{kind}"));
        g.sample_size(10);
        for b in BUNDLED {
            // Fail before timing if a scenario does not run.
            let size = if kind == "report" {
                report(b.name, b.text).len()
            } else {
                save(b.name, b.text).len()
            };
            eprintln!("{kind} {}: {size} bytes", b.name);
            g.bench_function(b.name, |bench| {
                bench.iter(|| {
                    if kind == "report" {
                        black_box(report(b.name, b.text).len())
                    } else {
                        black_box(save(b.name, b.text).len())
                    }
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, end_to_end);
criterion_main!(benches);
