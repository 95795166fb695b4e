//! Logs written by the tests: ROS 2 messages in CDR through the `mcap` crate's writer, and
//! the NEES test data of issue 20 — a smooth 3-D truth with large roll and pitch, estimates
//! drawn from a known anisotropic covariance in tf2's reading at stamps that never fall on a
//! truth sample, the same truth as a TUM file.

use std::collections::BTreeMap;
use std::io::Cursor;

use nalgebra::{Cholesky, Matrix6, Vector3, Vector6};
use posecov::input::log::decode::{Header, Odometry, Pose, PoseWithCovariance, Time, nested};
use posecov::input::log::reference::{PoseStamped, TfMessage, Transform, TransformStamped};
use posecov::lie::{LieGroup, Se3, So3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// A ROS 2 message in CDR, little endian, with its encapsulation header.
pub fn cdr<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    b.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(msg).unwrap());
    b
}

/// A header at `ns` in `frame`.
pub fn header(ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        },
        frame_id: frame.into(),
    }
}

/// An MCAP file being written: channels by topic, messages at their log time.
pub struct McapLog {
    writer: mcap::Writer<Cursor<Vec<u8>>>,
    channels: BTreeMap<String, u16>,
    schemas: BTreeMap<String, u16>,
    sequence: u32,
}

impl McapLog {
    pub fn new() -> Self {
        Self {
            // The `ros2` profile, as rosbag2 writes it (rosbags' reader asks for it).
            writer: mcap::WriteOptions::new()
                .profile("ros2")
                .create(Cursor::new(Vec::new()))
                .unwrap(),
            channels: BTreeMap::new(),
            schemas: BTreeMap::new(),
            sequence: 0,
        }
    }

    /// Writes `data` (CDR) on `topic` of ROS 2 type `schema`, logged at `log_ns`.
    pub fn put(&mut self, topic: &str, schema: &str, log_ns: i64, data: &[u8]) {
        let schema_id = match self.schemas.get(schema) {
            Some(id) => *id,
            None => {
                let id = self.writer.add_schema(schema, "ros2msg", b"").unwrap();
                self.schemas.insert(schema.to_owned(), id);
                id
            }
        };
        let channel_id = match self.channels.get(topic) {
            Some(id) => *id,
            None => {
                let id = self
                    .writer
                    .add_channel(schema_id, topic, "cdr", &BTreeMap::new())
                    .unwrap();
                self.channels.insert(topic.to_owned(), id);
                id
            }
        };
        self.sequence += 1;
        self.writer
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id,
                    sequence: self.sequence,
                    log_time: log_ns as u64,
                    publish_time: log_ns as u64,
                },
                data,
            )
            .unwrap();
    }

    pub fn finish(mut self) -> Vec<u8> {
        self.writer.finish().unwrap();
        self.writer.into_inner().into_inner()
    }
}

/// The truth map_from_base_link at t seconds: a smooth 3-D path with roll up to 0.8 rad and
/// pitch up to 0.6 rad while the yaw turns.
pub fn truth(t: f64) -> Se3 {
    let p = Vector3::new(
        3.0 * (0.3 * t).cos(),
        2.0 * (0.5 * t).sin(),
        0.5 * (0.2 * t).sin(),
    );
    let r = So3::from_rpy(0.8 * (0.4 * t).sin(), 0.6 * (0.3 * t).cos(), 0.5 * t);
    Se3::from_parts(p, r)
}

/// The published covariance in tf2's reading (x, y, z, rotX, rotY, rotZ in the parent axes):
/// anisotropic, correlated.
pub fn published_cov() -> Matrix6<f64> {
    let sigma = [0.20, 0.08, 0.03, 0.01, 0.03, 0.12];
    let mut c = Matrix6::from_fn(|i, j| sigma[i] * sigma[j]);
    for i in 0..6 {
        for j in 0..6 {
            if i != j {
                c[(i, j)] *= if (i + j) % 3 == 0 { 0.3 } else { 0.0 };
            }
        }
    }
    c
}

/// The truth runs from `T0` for `SECONDS` at 100 Hz.
pub const T0: f64 = 100.0;
pub const SECONDS: f64 = 60.0;
/// Estimates at 10 Hz from `T0 − 0.2 + 0.0037` s (two before the truth, three after its last
/// sample at `T0 + SECONDS`): never on a 10 ms truth sample.
pub const ESTIMATES: usize = estimates(SECONDS);
pub const BEFORE: u64 = 2;
pub const AFTER: u64 = 3;

/// The estimates of a log whose truth spans `seconds`: 10 Hz, `BEFORE` before the truth and
/// `AFTER` after it.
pub const fn estimates(seconds: f64) -> usize {
    (seconds * 10.0) as usize + (BEFORE + AFTER) as usize
}

fn ns(t: f64) -> i64 {
    (t * 1e9).round() as i64
}

fn quaternion(x: &Se3) -> [f64; 4] {
    x.rotation().to_quaternion_xyzw()
}

/// The NEES log: `/ground_truth` (PoseStamped, 100 Hz), `/tf` (map → base_link, 100 Hz),
/// `/ekf` publishing Σ (Odometry), `/ekf_overconfident` publishing Σ / 10 — both with the same
/// estimates X̂ = truth perturbed in tf2's reading by an error drawn from Σ:
/// p_true = p̂ + δp, R_true = Exp(δφ) R̂.
pub fn nees_log(seed: u64) -> Vec<u8> {
    nees_log_named(seed, "/ground_truth")
}

/// [`nees_log`] with the truth's PoseStamped topic named `truth_topic`.
pub fn nees_log_named(seed: u64, truth_topic: &str) -> Vec<u8> {
    nees_log_spanning(seed, truth_topic, SECONDS)
}

/// [`nees_log_named`] whose truth spans `seconds` (the benchmark's one-hour log:
/// `examples/nees_bench.rs`).
pub fn nees_log_spanning(seed: u64, truth_topic: &str, seconds: f64) -> Vec<u8> {
    let estimate_count = estimates(seconds);
    let mut log = McapLog::new();
    let cov = published_cov();
    let chol = Cholesky::new(cov).unwrap().l();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let truth_count = (seconds * 100.0).round() as usize + 1;
    let mut next_estimate = 0;
    let estimate_time = |k: usize| T0 - 0.2 + 0.0037 + 0.1 * k as f64;
    for i in 0..truth_count {
        let t = T0 + 0.01 * i as f64;
        // Estimates logged in time order among the truth samples.
        while next_estimate < estimate_count && estimate_time(next_estimate) < t {
            let te = estimate_time(next_estimate);
            put_estimates(&mut log, te, &truth(te), &chol, &cov, &mut rng);
            next_estimate += 1;
        }
        let x = truth(t);
        let position = [x.translation().x, x.translation().y, x.translation().z];
        let pose = PoseStamped {
            header: header(ns(t), "map"),
            pose: Pose {
                position,
                orientation: quaternion(&x),
            },
        };
        log.put(
            truth_topic,
            "geometry_msgs/msg/PoseStamped",
            ns(t),
            &cdr(&pose),
        );
        let tf = TfMessage {
            transforms: vec![TransformStamped {
                header: header(ns(t), "map"),
                child_frame_id: "base_link".into(),
                transform: Transform {
                    translation: position,
                    rotation: quaternion(&x),
                },
            }],
        };
        log.put("/tf", "tf2_msgs/msg/TFMessage", ns(t), &cdr(&tf));
    }
    while next_estimate < estimate_count {
        let te = estimate_time(next_estimate);
        put_estimates(&mut log, te, &truth(te), &chol, &cov, &mut rng);
        next_estimate += 1;
    }
    log.finish()
}

fn put_estimates(
    log: &mut McapLog,
    t: f64,
    truth: &Se3,
    chol: &Matrix6<f64>,
    cov: &Matrix6<f64>,
    rng: &mut ChaCha8Rng,
) {
    let z = Vector6::from_fn(|_, _| StandardNormal.sample(rng));
    let e = chol * z;
    let dp = Vector3::new(e[0], e[1], e[2]);
    let dphi = Vector3::new(e[3], e[4], e[5]);
    let p = truth.translation() - dp;
    let r = So3::exp(&-dphi).compose(truth.rotation());
    let estimate = Se3::from_parts(p, r);
    for (topic, scale) in [("/ekf", 1.0), ("/ekf_overconfident", 0.1)] {
        let c = cov * scale;
        let msg = Odometry {
            header: header(ns(t), "map"),
            child_frame_id: "base_link".into(),
            pose: PoseWithCovariance {
                pose: Pose {
                    position: [p.x, p.y, p.z],
                    orientation: quaternion(&estimate),
                },
                covariance: nested(&std::array::from_fn(|i| c[(i / 6, i % 6)])),
            },
            twist: Default::default(),
        };
        log.put(topic, "nav_msgs/msg/Odometry", ns(t), &cdr(&msg));
    }
}

/// The truth as a TUM file (`timestamp tx ty tz qx qy qz qw`), moved by `map_from_world`
/// (identity: the same frame).
pub fn truth_tum(world_from_map: &Se3) -> String {
    let mut text = String::from("# timestamp tx ty tz qx qy qz qw\n");
    for i in 0..=(SECONDS * 100.0) as usize {
        let t = T0 + 0.01 * i as f64;
        let x = world_from_map.compose(&truth(t));
        let p = x.translation();
        let q = quaternion(&x);
        text.push_str(&format!(
            "{t:.6} {:.12} {:.12} {:.12} {:.15} {:.15} {:.15} {:.15}\n",
            p.x, p.y, p.z, q[0], q[1], q[2], q[3]
        ));
    }
    text
}
