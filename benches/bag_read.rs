//! Reading a robot log with posecov: `input::log::read_log` on robot_localization's test2.bag
//! (ROS 1, bz2 chunks, 3060 nav_msgs/Odometry + 3061 skipped IMU messages): every chunk
//! decompressed, every Odometry decoded and its covariance health classified, the drawn set
//! and the series kept. The twin, reading the same bag with the Python `rosbags` package, is
//! `benches/bag_rosbags.py`; `benches/run_rosbags.sh` runs both side by side (BENCHMARKS.md).
//!
//! Two more groups measure the issue-19 performance rules on the same ROS 1 bags:
//!
//! - `bag_libbz2/NAME` (bz2 bags): libbz2 alone — every chunk of the bag decompressed (the
//!   `rosbag` crate's chunk record, through the `bzip2` crate's C library) and nothing else, in
//!   the same parallel batches on the same rayon threads as posecov's reader. posecov's read
//!   should stay within 1.2× of it.
//! - `bag_health/NAME`: the health classes and σ statistics alone
//!   ([`TopicHealth::add`](posecov::input::log::health::TopicHealth) over every pose message,
//!   decoded beforehand and handed over in cache, a block of 64 at a time, as the read hands
//!   them over after decoding): they should add ≤ 10 % to the read's time.
//!
//! ROS 2 SQLite bags (`bag_read/db3_*`): the committed `arc_v9` and `arc_zstd_message`
//! directories; `benches/run_db3.sh` adds them 200 times over (no, message and file zstd
//! compression) and times `rosbags` reading the same bags (`benches/db3_rosbags.py`).
//!
//! Run: `cargo bench --no-default-features --bench bag_read -- --warm-up-time 1 --measurement-time 3`
//! (`POSECOV_BENCH_BAGS=a.bag:b.bag` adds those bags, as `benches/run_rosbags.sh` does with
//! test2.bag rewritten ten times over with no, lz4 and bz2 chunk compression).

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use posecov::input::log::decode::{decode_ros1, ros1_kind};
use posecov::input::log::health::TopicHealth;
use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::PoseMessage;
use rayon::prelude::*;
use rosbag::{ChunkRecord, IndexRecord, MessageRecord, RosBag};

const TEST2: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/robot_localization/test2.bag"
);
const MCAP: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/mcap/health_cases.mcap"
);
/// ROS 2 SQLite bags (rosbag2 directories written by rosbags: tests/data/ros2/make_bags.py),
/// uncompressed and with zstd-compressed messages.
const DB3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2/arc_v9");
const DB3_ZSTD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/ros2/arc_zstd_message"
);

fn pose_messages(path: &str) -> u64 {
    let plan = read_log(
        Path::new(path),
        &LogOptions::default(),
        &mut |_, _| {},
        None,
    )
    .unwrap();
    plan.topics.iter().map(|t| t.count).sum()
}

/// The bags measured: (name, path).
fn bags() -> Vec<(String, String)> {
    let extra = std::env::var("POSECOV_BENCH_BAGS").unwrap_or_default();
    let mut bags: Vec<(String, String)> = vec![
        ("ros1_test2_bz2".into(), TEST2.into()),
        ("mcap_health_cases".into(), MCAP.into()),
        ("db3_arc_v9".into(), DB3.into()),
        ("db3_arc_zstd_message".into(), DB3_ZSTD.into()),
    ];
    for path in extra.split(':').filter(|p| !p.is_empty()) {
        let stem = Path::new(path)
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        bags.push((stem, path.to_owned()));
    }
    bags
}

/// Per log, its three measures one right after the other (a shared machine's load changes
/// over minutes: what is compared is measured seconds apart).
fn bag_benches(c: &mut Criterion) {
    for (name, path) in &bags() {
        bag_read(c, name, path);
        if name.contains("bz2") {
            bag_libbz2(c, name, path);
        }
        if path.ends_with(".bag") {
            bag_health(c, name, path);
        }
    }
}

fn bag_read(c: &mut Criterion, name: &str, path: &str) {
    let mut group = c.benchmark_group("bag_read");
    group.throughput(Throughput::Elements(pose_messages(path)));
    group.bench_function(name, |b| {
        b.iter(|| {
            let plan = read_log(
                Path::new(black_box(path)),
                &LogOptions::default(),
                &mut |_, _| {},
                None,
            )
            .unwrap();
            black_box(plan)
        })
    });
    group.finish();
}

/// A ROS 1 bag's chunk positions, from its index.
fn chunks(bag: &RosBag) -> Vec<u64> {
    let mut positions: Vec<u64> = bag
        .index_records()
        .filter_map(|r| match r {
            Ok(IndexRecord::ChunkInfo(info)) => Some(info.chunk_pos),
            _ => None,
        })
        .collect();
    positions.sort_unstable();
    positions
}

/// Decompresses every chunk of `bag` as posecov's reader batches them (two per rayon thread
/// at a time), keeping nothing: the decompression library alone. Returns the chunks.
fn decompress_all(bag: &RosBag, positions: &[u64]) -> usize {
    let batch = 2 * rayon::current_num_threads().max(1);
    let mut done = 0;
    for group in positions.chunks(batch) {
        done += group
            .par_iter()
            .map(|&pos| {
                let mut records = bag.chunk_records();
                records.seek(pos).unwrap();
                match records.next() {
                    Some(Ok(ChunkRecord::Chunk(chunk))) => {
                        // The decompressed chunk's first record header, so nothing is skipped.
                        black_box(chunk.messages().next().is_some()) as usize
                    }
                    _ => panic!("no chunk at {pos}"),
                }
            })
            .sum::<usize>();
    }
    done
}

fn bag_libbz2(c: &mut Criterion, name: &str, path: &str) {
    let mut group = c.benchmark_group("bag_libbz2");
    let bag = RosBag::new(path).unwrap();
    let positions = chunks(&bag);
    group.throughput(Throughput::Elements(pose_messages(path)));
    group.bench_function(name, |b| b.iter(|| decompress_all(&bag, &positions)));
    group.finish();
}

/// Every pose message of a ROS 1 log, decoded.
fn decoded(path: &str) -> Vec<(i64, PoseMessage)> {
    let bag = RosBag::new(path).unwrap();
    let mut kinds = std::collections::HashMap::new();
    let mut out = Vec::new();
    for pos in chunks(&bag) {
        let mut records = bag.chunk_records();
        records.seek(pos).unwrap();
        let Some(Ok(ChunkRecord::Chunk(chunk))) = records.next() else {
            panic!("no chunk at {pos}")
        };
        for m in chunk.messages() {
            match m.unwrap() {
                MessageRecord::Connection(c) => {
                    let md5: String = c.md5sum.iter().map(|b| format!("{b:02x}")).collect();
                    if let Some(Ok(kind)) = ros1_kind(c.tp, &md5) {
                        kinds.insert(c.id, kind);
                    }
                }
                MessageRecord::MessageData(m) => {
                    if let Some(kind) = kinds.get(&m.conn_id)
                        && let Ok(d) = decode_ros1(*kind, m.data)
                    {
                        out.push((m.time as i64, d));
                    }
                }
            }
        }
    }
    out
}

/// Messages per block of the health measure: copied into a buffer (untimed), then passed to
/// health (timed), as the read hands each message to health right after decoding it.
const HEALTH_BLOCK: usize = 64;

fn bag_health(c: &mut Criterion, name: &str, path: &str) {
    let mut group = c.benchmark_group("bag_health");
    let messages = decoded(path);
    group.throughput(Throughput::Elements(messages.len() as u64));
    // The decoded messages of a ten-fold bag take 20 MB: read one after the other from there,
    // each message's first touch waits for memory, which the read never does (it decodes a
    // message and classifies it at once, in cache). So each block of messages is copied into
    // a small buffer first, outside the time measured: the same messages in the same order,
    // in cache as in the read.
    let mut buffer: Vec<(i64, PoseMessage)> = Vec::with_capacity(HEALTH_BLOCK);
    group.bench_function(name, |b| {
        b.iter_custom(|iterations| {
            let mut spent = Duration::ZERO;
            for _ in 0..iterations {
                let mut topic = TopicHealth::default();
                let mut k = 0u64;
                for block in messages.chunks(HEALTH_BLOCK) {
                    buffer.clear();
                    buffer.extend_from_slice(block);
                    let start = Instant::now();
                    for (stamp, d) in &buffer {
                        black_box(topic.add(k, *stamp, d, true));
                        k += 1;
                    }
                    spent += start.elapsed();
                }
                black_box(topic);
            }
            spent
        })
    });
    group.finish();
}

criterion_group!(benches, bag_benches);
criterion_main!(benches);
