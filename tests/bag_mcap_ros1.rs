//! MCAP channels in `ros1` encoding (what `mcap convert` writes from a ROS 1 bag): the same
//! messages written once as CDR and once as ROS 1 bytes give the same log summary (issue 32).

use std::collections::BTreeMap;
use std::io::Cursor;

mod common;

use common::logs::{cdr, header};
use posecov::input::log::decode::{
    Odometry, Pose, PoseWithCovariance, PoseWithCovarianceStamped, TwistWithCovariance, nested,
};
use posecov::input::log::{LogOptions, read_log};
use posecov::plan::log::{Issue, PoseMessageKind};

/// ROS 1 serialization (little endian, packed, strings as u32 length + bytes).
#[derive(Default)]
struct Ros1(Vec<u8>);

impl Ros1 {
    fn u32(&mut self, v: u32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn f64s(&mut self, v: &[f64]) -> &mut Self {
        for x in v {
            self.0.extend(x.to_le_bytes());
        }
        self
    }
    fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32);
        self.0.extend(s.as_bytes());
        self
    }
    /// `std_msgs/Header` (seq, stamp, frame_id).
    fn header(&mut self, seq: u32, ns: i64, frame: &str) -> &mut Self {
        self.u32(seq)
            .u32((ns / 1_000_000_000) as u32)
            .u32((ns % 1_000_000_000) as u32)
            .string(frame)
    }
    fn pose_with_covariance(&mut self, p: &PoseWithCovariance) -> &mut Self {
        let flat: Vec<f64> = p.covariance.iter().flatten().copied().collect();
        self.f64s(&p.pose.position)
            .f64s(&p.pose.orientation)
            .f64s(&flat)
    }
}

fn cov(k: usize) -> [f64; 36] {
    let mut c = [0.0; 36];
    let s = 1.0 + 0.1 * k as f64;
    for (i, v) in [0.01, 0.02, 1e-6, 1e-6, 1e-6, 0.003].iter().enumerate() {
        c[i * 7] = v * s;
    }
    c[1] = 0.004 * s;
    c[6] = 0.004 * s;
    c
}

fn pose(k: usize) -> PoseWithCovariance {
    let yaw = 0.03 * k as f64;
    PoseWithCovariance {
        pose: Pose {
            position: [0.1 * k as f64, 0.02 * k as f64, 0.0],
            orientation: [0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos()],
        },
        covariance: nested(&cov(k)),
    }
}

/// The same 40 Odometry and 10 PoseWithCovarianceStamped messages, in `ros1` encoding with
/// ROS 1 type names (`ros1`), or in CDR with ROS 2 names.
fn write(ros1: bool) -> Vec<u8> {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let none = BTreeMap::new();
    let (encoding, schema_encoding) = if ros1 {
        ("ros1", "ros1msg")
    } else {
        ("cdr", "ros2msg")
    };
    let name = |k: PoseMessageKind| {
        if ros1 { k.ros1_name() } else { k.ros2_name() }
    };
    let odom_schema = w
        .add_schema(name(PoseMessageKind::Odometry), schema_encoding, b"")
        .unwrap();
    let amcl_schema = w
        .add_schema(
            name(PoseMessageKind::PoseWithCovarianceStamped),
            schema_encoding,
            b"",
        )
        .unwrap();
    let odom = w
        .add_channel(odom_schema, "/odom", encoding, &none)
        .unwrap();
    let amcl = w
        .add_channel(amcl_schema, "/amcl_pose", encoding, &none)
        .unwrap();
    let mut seq = 0;
    for k in 0..40 {
        let ns = 1_000_000_000 + k as i64 * 50_000_000;
        let twist = TwistWithCovariance {
            twist: [0.5, 0.0, 0.0, 0.0, 0.0, 0.3],
            covariance: nested(&cov(0)),
        };
        let odom_bytes = if ros1 {
            let mut b = Ros1::default();
            b.header(k as u32, ns, "odom")
                .string("base_link")
                .pose_with_covariance(&pose(k));
            let flat: Vec<f64> = twist.covariance.iter().flatten().copied().collect();
            b.f64s(&twist.twist).f64s(&flat);
            b.0
        } else {
            cdr(&Odometry {
                header: header(ns, "odom"),
                child_frame_id: "base_link".into(),
                pose: pose(k),
                twist,
            })
        };
        let mut put = |channel_id, data: &[u8]| {
            seq += 1;
            w.write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id,
                    sequence: seq,
                    log_time: ns as u64,
                    publish_time: ns as u64,
                },
                data,
            )
            .unwrap();
        };
        put(odom, &odom_bytes);
        if k % 4 == 0 {
            let amcl_bytes = if ros1 {
                let mut b = Ros1::default();
                b.header(k as u32, ns, "map").pose_with_covariance(&pose(k));
                b.0
            } else {
                cdr(&PoseWithCovarianceStamped {
                    header: header(ns, "map"),
                    pose: pose(k),
                })
            };
            put(amcl, &amcl_bytes);
        }
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

#[test]
fn ros1_encoded_channels_read_as_their_cdr_twins() {
    let dir = std::env::temp_dir().join(format!("posecov-mcap-ros1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let read = |name: &str, bytes: Vec<u8>| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        read_log(&path, &LogOptions::default(), &mut |_, _| {}, None).unwrap()
    };
    let ros1 = read("ros1.mcap", write(true));
    let cdr = read("cdr.mcap", write(false));
    assert!(ros1.skipped.is_empty(), "{:?}", ros1.skipped);
    assert_eq!(ros1.topics.len(), 2);
    let odom = ros1.topics.iter().find(|t| t.name == "/odom").unwrap();
    assert_eq!((odom.count, odom.kind), (40, PoseMessageKind::Odometry));
    assert_eq!(odom.health.count(Issue::Undecodable), 0);
    assert_eq!(odom.child_frame_id, "base_link");
    assert_eq!(ros1.topics, cdr.topics);
    assert_eq!(ros1.messages_total, 50);
    std::fs::remove_dir_all(&dir).ok();
}
