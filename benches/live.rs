//! Live mode's latency (BENCHMARKS.md): from a control change to the first new picture
//! handed to the viewer, per bundled scenario, the way the live thread does it — apply the
//! edit to the document (parse + lower: the file's validation), evaluate, draw, re-stream in
//! place ([`Restream`], with its clears) and encode what was logged (the bytes a viewer
//! receives). `preview`: the first picture, the first of live mode's own [`passes`] (one
//! random chunk of samples when the Monte Carlo work is large, fewer steps kept when a
//! propagation is long; the whole picture for small scenes); `full`: the scenario's own.
//!
//! Run (release, the numbers in BENCHMARKS.md; a cold release build of Rerun is ~20 min):
//! `cargo bench --bench live -- --warm-up-time 1 --measurement-time 3`; with the test build's
//! dependencies: `cargo bench --profile dev --bench live -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;
use std::sync::atomic::AtomicBool;

use criterion::{Criterion, criterion_group, criterion_main};
use posecov::app::Overrides;
use posecov::app::live::{Control, ControlKind, Edit, EditValue, LiveDocument, passes};
use posecov::app::run::PlanRun;
use posecov::input::scenario::bundled::BUNDLED;
use posecov::sink::Restream;

/// The control a lecturer drags: the first σ of a pose's covariance (else of an operation's
/// noise, else an operation's first number, else a pose's), with two values to alternate.
fn knob(doc: &LiveDocument) -> (String, [f64; 2]) {
    let controls = doc.controls();
    let number = |c: &Control| match c.kind {
        ControlKind::Number { value, .. } => Some((c.id.clone(), value)),
        ControlKind::Toggle { .. } => None,
    };
    let pick = |f: &dyn Fn(&str) -> bool| controls.iter().filter(|c| f(&c.id)).find_map(number);
    let (id, v) = pick(&|id| id.starts_with("pose[") && id.contains(".cov.std"))
        .or_else(|| pick(&|id| id.contains(".noise.std")))
        .or_else(|| pick(&|id| id.starts_with("operation[")))
        .or_else(|| pick(&|id| id.starts_with("pose[") && id.contains(".cov.")))
        .or_else(|| pick(&|id| id.starts_with("pose[")))
        .expect("a scenario with a number to change");
    let other = if v == 0.0 { 0.01 } else { v * 1.1 };
    (id, [v, other])
}

fn live(c: &mut Criterion) {
    for pass in ["preview", "full"] {
        let mut g = c.benchmark_group(format!("live.{pass}"));
        g.sample_size(10);
        for b in BUNDLED {
            let mut doc = LiveDocument::new(b.text, b.name).expect("bundled scenario loads");
            let mut all = passes(doc.loaded(), &Overrides::default()).expect("settings");
            let overrides = if pass == "preview" {
                all.swap_remove(0)
            } else {
                all.pop().expect("a full pass")
            };
            let (id, values) = knob(&doc);
            let (rec, storage) = rerun::RecordingStreamBuilder::new("posecov")
                .memory()
                .expect("memory stream");
            let mut restream = Restream::new();
            let cancel = AtomicBool::new(false);
            let mut k = 0usize;
            eprintln!(
                "{pass} {}: {id} at {:?} samples, steps {:?}",
                b.name, overrides.samples, overrides.steps
            );
            g.bench_function(b.name, |bench| {
                bench.iter(|| {
                    k += 1;
                    let edit = Edit {
                        id: id.clone(),
                        value: EditValue::Number(values[k % 2]),
                    };
                    doc.apply(&edit).expect("the edit loads");
                    let session = PlanRun::from_loaded(doc.loaded().clone(), &overrides, None)
                        .expect("the scenario runs");
                    restream.log(&rec, session.scene, &cancel).expect("logged");
                    black_box(storage.drain_as_bytes().expect("encoded").len())
                });
            });
        }
        g.finish();
    }
}

criterion_group!(benches, live);
criterion_main!(benches);
