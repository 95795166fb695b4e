//! Reading a robot log with posecov: `input::bag::read_bag` on robot_localization's test2.bag
//! (ROS 1, bz2 chunks, 3060 nav_msgs/Odometry + 3061 skipped IMU messages): every chunk
//! decompressed, every Odometry decoded and its covariance health classified, the drawn set
//! and the series kept. The twin, reading the same bag with the Python `rosbags` package, is
//! `benches/bag_rosbags.py`; `benches/run_rosbags.sh` runs both side by side (BENCHMARKS.md).
//!
//! Run: `cargo bench --no-default-features --bench bag_read -- --warm-up-time 1 --measurement-time 3`
//! (`POSECOV_BENCH_BAGS=a.bag:b.bag` adds those bags, as `benches/run_rosbags.sh` does with
//! test2.bag rewritten ten times over with no, lz4 and bz2 chunk compression).

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use posecov::input::bag::{BagOptions, read_bag};

const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);
const MCAP: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/mcap/health_cases.mcap"
);

fn pose_messages(path: &str) -> u64 {
    let plan = read_bag(
        Path::new(path),
        &BagOptions::default(),
        &mut |_, _| {},
        None,
    )
    .unwrap();
    plan.topics.iter().map(|t| t.count).sum()
}

fn bag_read(c: &mut Criterion) {
    let mut group = c.benchmark_group("bag_read");
    let extra = std::env::var("POSECOV_BENCH_BAGS").unwrap_or_default();
    let mut bags: Vec<(String, String)> = vec![
        ("ros1_test2_bz2".into(), TEST2.into()),
        ("mcap_health_cases".into(), MCAP.into()),
    ];
    for path in extra.split(':').filter(|p| !p.is_empty()) {
        let stem = Path::new(path)
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        bags.push((stem, path.to_owned()));
    }
    for (name, path) in &bags {
        let path = path.as_str();
        group.throughput(Throughput::Elements(pose_messages(path)));
        group.bench_function(name, |b| {
            b.iter(|| {
                let plan = read_bag(
                    Path::new(black_box(path)),
                    &BagOptions::default(),
                    &mut |_, _| {},
                    None,
                )
                .unwrap();
                black_box(plan)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bag_read);
criterion_main!(benches);
