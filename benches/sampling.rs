//! Pose-cloud sampling throughput against its floor, side by side in one run (BENCHMARKS.md).
//!
//! Run: `cargo bench --no-default-features --bench sampling -- --warm-up-time 1 --measurement-time 3`
//!
//! - `posecov_fill_par/<t>t`: [`Sampler::fill_par`] into a pre-allocated buffer on a rayon
//!   pool of `t` threads (1 or 2): z ~ N(0, I), ε = L z, X = μ · Exp(ε).
//! - `posecov_draw_par/2t`: [`Sampler::draw_par`], the same plus allocating the output.
//! - `floor_normals/<t>t`: the floor — the same generator ([`chunk_rng`] via
//!   [`posecov::sample::fill_par`]: ChaCha8, one stream per [`CHUNK_SIZE`] chunk) drawing only
//!   the N standard normals per sample that sampling needs, into an `[f64; N]` per sample.
//!
//! The setup asserts that 1 and 2 threads produce bit-identical clouds for the seed, and that
//! `draw_par` equals `fill_par`, before anything is timed.

use std::hint::black_box;

use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main,
};
use nalgebra::{Matrix3, Matrix6};
use posecov::lie::{LieGroup, Se2, Se3};
use posecov::sample::{CHUNK_SIZE, Sampler, chunk_rng, fill_par};
use posecov::uncertain::{Side, UncertainPose};
use rand::Rng;
use rand_distr::StandardNormal;
use rayon::{ThreadPool, ThreadPoolBuilder};

/// Cloud sizes.
const SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

const SEED: u64 = 2026;

fn pool(threads: usize) -> ThreadPool {
    ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a rayon pool")
}

/// A correlated SE(2) covariance, Σ = L Lᵀ with L lower triangular (x, y, θ).
fn se2_cov() -> Matrix3<f64> {
    let l = Matrix3::new(0.10, 0.0, 0.0, 0.02, 0.08, 0.0, -0.01, 0.03, 0.15);
    l * l.transpose()
}

/// A correlated SE(3) covariance, Σ = L Lᵀ with L lower triangular ([ρ; θ]).
fn se3_cov() -> Matrix6<f64> {
    #[rustfmt::skip]
    let l = Matrix6::new(
        0.10, 0.0, 0.0, 0.0, 0.0, 0.0,
        0.02, 0.12, 0.0, 0.0, 0.0, 0.0,
        0.01, -0.02, 0.05, 0.0, 0.0, 0.0,
        0.00, 0.01, 0.00, 0.03, 0.0, 0.0,
        0.01, 0.00, 0.00, 0.01, 0.04, 0.0,
        -0.02, 0.03, 0.01, 0.00, 0.02, 0.20,
    );
    l * l.transpose()
}

/// The floor: N standard normals per sample from the same chunked generator.
fn floor<const N: usize>(out: &mut [[f64; N]], seed: u64) {
    fill_par(out, seed, 0, |rng, chunk| {
        for x in chunk.iter_mut() {
            *x = std::array::from_fn(|_| rng.sample(StandardNormal));
        }
    });
}

fn bench_group<G: LieGroup<N>, const N: usize>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    sampler: &Sampler<G, N>,
    pools: &[(usize, ThreadPool)],
) {
    for &n in &SIZES {
        g.throughput(Throughput::Elements(n as u64));
        // Identical output per seed whatever the thread count; draw_par == fill_par.
        let mut reference = vec![G::identity(); n];
        pools[0]
            .1
            .install(|| sampler.fill_par(&mut reference, SEED, 0));
        for (threads, p) in &pools[1..] {
            let mut other = vec![G::identity(); n];
            p.install(|| sampler.fill_par(&mut other, SEED, 0));
            assert!(
                other == reference,
                "{threads} threads changed the cloud at n = {n}"
            );
            assert!(p.install(|| sampler.draw_par(n, SEED)) == reference);
        }
        // The floor draws the same normals the sampler consumes: check on the first chunk.
        let mut normals = vec![[0.0; N]; n];
        floor(&mut normals, SEED);
        let mut rng = chunk_rng(SEED, 0, 0);
        for z in normals.iter().take(CHUNK_SIZE.min(n)) {
            let eps = sampler.factor() * posecov::sample::standard_normal::<N, _>(&mut rng);
            let again = sampler.factor() * nalgebra::SVector::<f64, N>::from(*z);
            assert_eq!(eps, again);
        }

        let mut out = vec![G::identity(); n];
        for (threads, p) in pools {
            g.bench_with_input(
                BenchmarkId::new(format!("posecov_fill_par/{threads}t"), n),
                &n,
                |b, _| b.iter(|| p.install(|| sampler.fill_par(black_box(&mut out), SEED, 0))),
            );
            g.bench_with_input(
                BenchmarkId::new(format!("floor_normals/{threads}t"), n),
                &n,
                |b, _| b.iter(|| p.install(|| floor(black_box(&mut normals), SEED))),
            );
        }
        let (threads, p) = pools.last().expect("pools");
        g.bench_with_input(
            BenchmarkId::new(format!("posecov_draw_par/{threads}t"), n),
            &n,
            |b, &n| b.iter(|| p.install(|| black_box(sampler.draw_par(n, SEED)))),
        );
    }
}

fn sampling(c: &mut Criterion) {
    let pools = [(1, pool(1)), (2, pool(2))];

    let se2 = UncertainPose::try_new(Se2::from_xy_theta(1.0, 2.0, 0.3), se2_cov(), Side::Right)
        .expect("valid SE(2) pose");
    let se2 = Sampler::new(&se2).expect("SE(2) sampler");
    let mut g = c.benchmark_group("sampling.se2");
    g.sample_size(10);
    bench_group(&mut g, &se2, &pools);
    g.finish();

    let se3_mean = Se3::from_xyz_rpy([1.0, 2.0, 0.5], [0.1, -0.2, 0.7]);
    let se3 = UncertainPose::try_new(se3_mean, se3_cov(), Side::Right).expect("valid SE(3) pose");
    let se3 = Sampler::new(&se3).expect("SE(3) sampler");
    let mut g = c.benchmark_group("sampling.se3");
    g.sample_size(10);
    bench_group(&mut g, &se3, &pools);
    g.finish();
}

criterion_group!(benches, sampling);
criterion_main!(benches);
