//! The Rust side of the Python package's call overhead (issue 34, BENCHMARKS.md §11): the same
//! calls `benches/python_bench.py overhead` makes from Python, here without Python.
//!
//! Run: `cargo bench --no-default-features --bench compose -- --warm-up-time 1 --measurement-time 3`
//!
//! - `compose/se3_first_order`: Z = X · Y of two independent SE(3) poses with covariance, first
//!   order ([`posecov::propagate::first_order::compose`]).
//! - `compose/se3_fourth_order`: the same, Barfoot & Furgale's fourth order
//!   ([`posecov::propagate::fourth_order::compound_se3`]).
//! - `compose/se3_new`: an [`UncertainPose`] from a mean and a covariance, checked (symmetric,
//!   PSD, finite), as the Python constructor checks it.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Matrix6;
use posecov::lie::{LieGroup, Se3};
use posecov::propagate::first_order;
use posecov::propagate::fourth_order::{Order, compound_se3};
use posecov::uncertain::{Side, UncertainPose};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// A random SPD covariance A Aᵀ · 0.05² + 10⁻⁴ I, as the Python side draws it.
fn spd(rng: &mut ChaCha8Rng) -> Matrix6<f64> {
    let a = Matrix6::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal) * 0.05);
    a * a.transpose() + Matrix6::identity() * 1e-4
}

fn compose(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let tangent = |v: [f64; 6]| Se3::exp(&nalgebra::Vector6::from(v));
    let (mean_a, mean_b) = (
        tangent([1.0, 2.0, 0.5, 0.1, -0.2, 0.7]),
        tangent([0.3, -1.0, 0.2, 0.05, 0.1, -0.3]),
    );
    let (cov_a, cov_b) = (spd(&mut rng), spd(&mut rng));
    let x = UncertainPose::try_new(mean_a, cov_a, Side::Right).expect("valid pose");
    let y = UncertainPose::try_new(mean_b, cov_b, Side::Right).expect("valid pose");
    let mut g = c.benchmark_group("compose");
    g.bench_function("se3_first_order", |b| {
        b.iter(|| first_order::compose(black_box(&x), black_box(&y)))
    });
    g.bench_function("se3_fourth_order", |b| {
        b.iter(|| compound_se3(black_box(&x), black_box(&y), Order::Fourth))
    });
    g.bench_function("se3_new", |b| {
        b.iter(|| UncertainPose::try_new(black_box(mean_a), black_box(cov_a), Side::Right))
    });
    g.finish();
}

criterion_group!(benches, compose);
criterion_main!(benches);
