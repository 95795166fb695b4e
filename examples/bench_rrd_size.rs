//! Bytes per cloud point in a posecov .rrd recording (BENCHMARKS.md, "Recording size").
//!
//! ```text
//! cargo build --release --example bench_rrd_size
//! /usr/bin/time -v target/release/examples/bench_rrd_size 1e3 1e4 1e5 1e6
//! ```
//!
//! For each n: an SE(3) cloud of n samples (right form), one [`PointCloud`] of their
//! translations in an otherwise empty scene, encoded with [`scene_to_rrd_bytes`]. Bytes per
//! point = (bytes(n) − bytes of the same scene with 0 points) / n. Prints one JSON line per n.

use std::time::Instant;

use nalgebra::Matrix6;
use posecov::lie::Se3;
use posecov::sample::Sampler;
use posecov::scene::{Color, ItemKind, PointCloud, Scene, SceneItem, Timing};
use posecov::sink::{RecordingIds, scene_to_rrd_bytes};
use posecov::uncertain::{Side, UncertainPose};

fn scene_with(positions: Vec<[f64; 3]>) -> Scene {
    let mut scene = Scene::new("rrd size", "One cloud.");
    scene.push(SceneItem::new(
        "world/x/monte_carlo/cloud",
        Timing::Static,
        ItemKind::Points(PointCloud {
            positions,
            color: Color::rgb(200, 200, 200),
            radius: 0.01,
        }),
    ));
    scene
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse::<f64>().expect("a count such as 1e6") as usize)
        .collect();
    let sizes = if sizes.is_empty() {
        vec![1_000, 100_000, 1_000_000]
    } else {
        sizes
    };

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
    let ids = RecordingIds::for_scenario("bench_rrd_size", 0);
    let empty = scene_to_rrd_bytes(&scene_with(Vec::new()), &ids)
        .expect("encodes")
        .len();

    for n in sizes {
        let positions: Vec<[f64; 3]> = sampler
            .draw_par(n, 7)
            .iter()
            .map(|x| (*x.translation()).into())
            .collect();
        let start = Instant::now();
        let bytes = scene_to_rrd_bytes(&scene_with(positions), &ids)
            .expect("encodes")
            .len();
        let seconds = start.elapsed().as_secs_f64();
        println!(
            "{{\"n\": {n}, \"bytes\": {bytes}, \"empty_scene_bytes\": {empty}, \"bytes_per_point\": {:.3}, \"encode_seconds\": {seconds:.4}}}",
            (bytes - empty) as f64 / n as f64
        );
    }
}
