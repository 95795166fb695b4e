//! Long runs stay bounded (issue 31 item 3), proven without a clock: a simulated hour of a
//! robot at 100 Hz on four topics goes through the queue and the collector exactly as a live
//! stream's messages do (`take` feeding `Collector::message_on`, the summaries due handed to
//! the growing view's thread through its mailbox), and what is kept — the drawn messages, series, trajectories, health
//! and every summary handed to the growing view — stays under a bound that does not depend on
//! the number of messages: after an hour it is what it was after half an hour.

use std::sync::Arc;
use std::sync::atomic::Ordering;

use tungstenite::Bytes;

use super::super::{Codec, Collector, GROWN_SERIES, LogOptions, MAX_SERIES, Stream};
use super::mailbox::Mailbox;
use super::queue::{self, Arrived};
use super::session::Shared;
use super::{LiveOptions, draw, take};
use crate::plan::log::{DEFAULT_MAX_DRAWN, LogSummary};

const TOPICS: [&str; 4] = ["/odom", "/ekf", "/amcl_pose", "/gnss"];
const RATE_HZ: u64 = 100;

/// Message `i` of a topic: a PoseWithCovarianceStamped in CDR (little endian), driving 0.1 m
/// a message around a loop, σ breathing with the turns.
fn pose_cdr(i: u64) -> Vec<u8> {
    let stamp_ns = i * (1_000_000_000 / RATE_HZ);
    let mut b = vec![0, 1, 0, 0];
    b.extend(((stamp_ns / 1_000_000_000) as i32).to_le_bytes());
    b.extend(((stamp_ns % 1_000_000_000) as u32).to_le_bytes());
    b.extend(4u32.to_le_bytes());
    b.extend(b"map\0");
    let t = i as f64 * 0.01;
    let s = 0.05 + 0.02 * (t * 0.1).sin().abs();
    let mut covariance = [0.0; 36];
    for (axis, v) in [s, s, 1e-6, 1e-4, 1e-4, s * 0.1].into_iter().enumerate() {
        covariance[7 * axis] = v;
    }
    let (yaw, r) = (t * 0.05, 50.0);
    let pose = [
        r * yaw.cos(),
        r * yaw.sin(),
        0.0,
        0.0,
        0.0,
        (yaw / 2.0).sin(),
        (yaw / 2.0).cos(),
    ];
    for v in pose.iter().chain(&covariance) {
        b.extend(v.to_le_bytes());
    }
    b
}

/// What a summary keeps, in items: drawn messages, trajectory and series points, noted
/// issues and other types, skipped topics.
fn kept(plan: &LogSummary) -> usize {
    let topics: usize = plan
        .topics
        .iter()
        .map(|t| {
            t.drawn.len()
                + t.trajectory.len()
                + t.series.len()
                + t.health.issues.len()
                + t.health.other_types.len()
        })
        .sum();
    topics + plan.skipped.len() + plan.not_selected.len()
}

/// The bound on [`kept`] whatever the length: per topic the drawn set, the trajectory and
/// the series at their caps, and every issue kind once.
fn bound() -> usize {
    TOPICS.len() * (DEFAULT_MAX_DRAWN + 2 * MAX_SERIES + 64)
}

/// Runs `seconds` of simulated stream through the queue into a growing collector; returns
/// the final summary and the largest summary the growing view was handed.
fn simulate(seconds: u64) -> (LogSummary, usize, u64) {
    let options = LogOptions::default();
    let live = LiveOptions::default();
    let mut largest_grown = 0;
    let mut grown = 0u64;
    let mut show = |plan: LogSummary| {
        largest_grown = largest_grown.max(kept(&plan));
        grown += 1;
    };
    let mut collector = Collector::new(&options, None, None).growing(true);
    let shared = Shared::new("ws://127.0.0.1:8765");
    let (sender, taker) = queue::bounded(&shared.queued);
    let mailbox = Mailbox::new();
    let streams: Vec<Arc<(Stream, Codec)>> = TOPICS
        .iter()
        .map(|topic| {
            Arc::new(Stream::of_channel(
                (*topic).to_owned(),
                "geometry_msgs/msg/PoseWithCovarianceStamped".to_owned(),
                "cdr",
                String::new,
            ))
        })
        .collect();
    std::thread::scope(|scope| {
        scope.spawn(|| {
            for stream in &streams {
                sender.declare(Arc::clone(stream)).expect("taken");
            }
            for i in 0..seconds * RATE_HZ {
                let payload = pose_cdr(i);
                let mut frame = vec![1u8; 13];
                frame.extend(&payload);
                let frame = Bytes::from(frame);
                for (channel, stream) in streams.iter().enumerate() {
                    // Every message is read here (a full queue waits): the flood's
                    // thinning is queue.rs's test.
                    loop {
                        let arrived = Arrived {
                            stream: Arc::clone(stream),
                            channel: channel as u64,
                            log_time_ns: i * (1_000_000_000 / RATE_HZ),
                            frame: frame.clone(),
                            offset: 13,
                        };
                        if sender.offer(arrived).expect("taken") {
                            break;
                        }
                        std::thread::yield_now();
                    }
                    shared.received.fetch_add(1, Ordering::AcqRel);
                }
            }
            drop(sender);
        });
        let drawer = scope.spawn(|| draw(&mailbox, &mut show));
        let taken = take(
            taker,
            &live,
            &shared,
            &mut collector,
            Some(&mailbox),
            &mut |_, _| {},
        );
        mailbox.close(true);
        drawer.join().expect("the thread that draws ends");
        taken.expect("read");
    });
    let plan = collector
        .finish(std::path::Path::new("ws://127.0.0.1:8765"))
        .expect("summary");
    (plan, largest_grown, grown)
}

#[test]
fn an_hour_at_100_hz_on_four_topics_keeps_what_half_an_hour_keeps() {
    let (half, _, _) = simulate(1800);
    let (hour, largest_grown, grown) = simulate(3600);
    let messages = 3600 * RATE_HZ;
    assert!(hour.topics.iter().all(|t| t.count == messages));
    assert_eq!(hour.messages_total, 4 * messages);
    // Bounded whatever the length, and no more after an hour than after half of it (the
    // decimators halve their density as the count doubles).
    assert!(kept(&hour) <= bound(), "{} > {}", kept(&hour), bound());
    assert!(
        kept(&hour) <= kept(&half) + 4 * 64,
        "an hour keeps {}, half an hour {}",
        kept(&hour),
        kept(&half)
    );
    // The growing view was handed bounded summaries, their series thinner.
    let grown_bound = TOPICS.len() * (DEFAULT_MAX_DRAWN + 2 * GROWN_SERIES + 64);
    assert!(
        grown >= 1 && largest_grown <= grown_bound,
        "{largest_grown}"
    );
    // Statistics are of every message, not of those kept.
    for topic in &hour.topics {
        assert!(topic.drawn.len() <= DEFAULT_MAX_DRAWN);
        assert!(topic.series.len() <= MAX_SERIES && topic.trajectory.len() <= MAX_SERIES);
        assert!(topic.stride > 1000, "{}", topic.stride);
        let stats: Vec<u64> = topic
            .sigma_stats
            .iter()
            .flatten()
            .map(|a| a.messages)
            .collect();
        assert!(
            !stats.is_empty() && stats.iter().all(|&n| n == messages),
            "{stats:?}"
        );
    }
}
