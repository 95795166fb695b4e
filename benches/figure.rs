//! Figures of every bundled scenario (BENCHMARKS.md §7): for each, the evaluation and drawing
//! (`pipeline`, what `posecov figure` does before it draws) beside the figure itself (SVG
//! written, PNG rendered), so their ratio is measured side by side. The target: the
//! figure adds at most 1 s to a scenario's evaluation, release build.
//!
//! Run: `cargo bench --bench figure -- --warm-up-time 1 --measurement-time 3`
//! (needs the `viewer` and `figure` features, on by default).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use posecov::app::{Overrides, load_text, pipeline};
use posecov::input::scenario::bundled::BUNDLED;
use posecov::sink::figure::{FigureFormat, FigureOptions, render};

fn figures(c: &mut Criterion) {
    let options = FigureOptions::default();
    let mut g = c.benchmark_group("figure");
    g.sample_size(10);
    for b in BUNDLED {
        let loaded = load_text(b.text, b.name).expect("bundled scenario loads");
        let (_, scene) = pipeline(&loaded, &Overrides::default(), None).expect("scenario runs");
        let png = render(&scene, &options, FigureFormat::Png).expect("figure renders");
        eprintln!("figure {}: {} PNG bytes", b.name, png.len());
        g.bench_function(format!("{}/evaluate_and_draw", b.name), |bench| {
            bench.iter(|| black_box(pipeline(&loaded, &Overrides::default(), None).is_ok()))
        });
        g.bench_function(format!("{}/svg", b.name), |bench| {
            bench.iter(|| black_box(render(&scene, &options, FigureFormat::Svg).map(|v| v.len())))
        });
        g.bench_function(format!("{}/png", b.name), |bench| {
            bench.iter(|| black_box(render(&scene, &options, FigureFormat::Png).map(|v| v.len())))
        });
    }
    g.finish();
}

criterion_group!(benches, figures);
criterion_main!(benches);
