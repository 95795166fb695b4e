//! Peak memory of SE(3) cloud sampling (BENCHMARKS.md, "Memory"): run under `/usr/bin/time -v`.
//!
//! ```text
//! cargo build --release --no-default-features --example bench_cloud_memory
//! /usr/bin/time -v target/release/examples/bench_cloud_memory 10000000 held
//! /usr/bin/time -v target/release/examples/bench_cloud_memory 10000000 streamed
//! /usr/bin/time -v target/release/examples/bench_cloud_memory 10000000 normals
//! ```
//!
//! Modes:
//! - `held`: `Sampler::draw_par(n)`, the whole cloud in memory (56 bytes per SE(3) pose);
//! - `streamed`: the same draws, chunk by chunk into one reused buffer (random family 0, chunk
//!   `c` uses `chunk_rng(seed, 0, c)`, so the points are exactly those of `held`), keeping only
//!   the f32 positions a viewer needs would be the next step; here only their sum is kept;
//! - `normals`: the floor, the 6 standard normals per sample, held (48 bytes per sample).

use std::time::Instant;

use nalgebra::Matrix6;
use posecov::lie::{LieGroup, Se3};
use posecov::sample::{CHUNK_SIZE, Sampler, chunk_rng, fill_par};
use posecov::uncertain::{Side, UncertainPose};
use rand::Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

const SEED: u64 = 2026;

/// Chunks drawn per streamed block (a multiple of CHUNK_SIZE keeps chunk ids aligned).
const BLOCK_CHUNKS: usize = 256;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .and_then(|s| s.parse::<f64>().ok())
        .map(|f| f as usize)
        .unwrap_or(10_000_000);
    let mode = args.next().unwrap_or_else(|| "held".into());

    let cov = Matrix6::from_diagonal(&nalgebra::Vector6::new(
        0.01, 0.0144, 0.0025, 0.0009, 0.0016, 0.04,
    ));
    let pose = UncertainPose::try_new(
        Se3::from_xyz_rpy([1.0, 2.0, 0.5], [0.1, -0.2, 0.7]),
        cov,
        Side::Right,
    )
    .expect("valid pose");
    let sampler = Sampler::new(&pose).expect("sampler");

    let start = Instant::now();
    let checksum: f64 = match mode.as_str() {
        "held" => {
            let cloud = sampler.draw_par(n, SEED);
            cloud.par_iter().map(|x| x.translation().x).sum()
        }
        "streamed" => {
            let block = BLOCK_CHUNKS * CHUNK_SIZE;
            let mut buffer = vec![Se3::identity(); block];
            let mut sum = 0.0;
            let mut done = 0;
            while done < n {
                let len = block.min(n - done);
                let first_chunk = (done / CHUNK_SIZE) as u64;
                buffer[..len]
                    .par_chunks_mut(CHUNK_SIZE)
                    .enumerate()
                    .for_each(|(c, chunk)| {
                        let mut rng = chunk_rng(SEED, 0, first_chunk + c as u64);
                        chunk.iter_mut().for_each(|x| *x = sampler.draw(&mut rng));
                    });
                sum += buffer[..len]
                    .par_iter()
                    .map(|x| x.translation().x)
                    .sum::<f64>();
                done += len;
            }
            sum
        }
        "normals" => {
            let mut z = vec![[0.0f64; 6]; n];
            fill_par(&mut z, SEED, 0, |rng, chunk| {
                chunk
                    .iter_mut()
                    .for_each(|x| *x = std::array::from_fn(|_| rng.sample(StandardNormal)))
            });
            z.par_iter().map(|x| x[0]).sum()
        }
        other => panic!("unknown mode {other:?}: held | streamed | normals"),
    };
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{{\"mode\": \"{mode}\", \"n\": {n}, \"seconds\": {seconds:.4}, \"ns_per_sample\": {:.2}, \"checksum\": {checksum:.6}}}",
        seconds * 1e9 / n as f64
    );
}
