//! Figures of every bundled example (BENCHMARKS.md §9): for each, the evaluation alone (read,
//! evaluate and draw: what `posecov figure` does before it writes) beside the evaluation and
//! the figure written as SVG, rendered to PNG (resvg) and converted to PDF (svg2pdf), side by
//! side in one run. The target: the figure adds at most 1 s to a scenario's
//! evaluation, release build.
//!
//! Run (release, no Rerun needed: the figure path is pure Rust):
//! `cargo bench --no-default-features --features figure --bench figure -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use posecov::app::Overrides;
use posecov::app::figure::scene_of;
use posecov::sink::figure::{FigureFormat, FigureOptions, render};

fn figures(c: &mut Criterion) {
    let options = FigureOptions::default();
    let overrides = Overrides::default();
    let mut g = c.benchmark_group("figure");
    g.sample_size(10);
    for example in posecov::input::examples() {
        let name = example.name;
        let scene = scene_of(name, &overrides).expect("bundled example runs");
        for format in [FigureFormat::Svg, FigureFormat::Png, FigureFormat::Pdf] {
            let bytes = render(&scene, &options, format).expect("figure renders");
            eprintln!("figure {name}: {} bytes of {format:?}", bytes.len());
        }
        g.bench_function(format!("{name}/evaluate"), |bench| {
            bench.iter(|| black_box(scene_of(name, &overrides).map(|s| s.items.len())))
        });
        for (label, format) in [
            ("svg", FigureFormat::Svg),
            ("png", FigureFormat::Png),
            ("pdf", FigureFormat::Pdf),
        ] {
            g.bench_function(format!("{name}/evaluate+{label}"), |bench| {
                bench.iter(|| {
                    let scene = scene_of(name, &overrides).expect("bundled example runs");
                    black_box(render(&scene, &options, format).map(|v| v.len()))
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, figures);
criterion_main!(benches);
