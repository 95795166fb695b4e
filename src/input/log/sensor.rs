//! Covariance-carrying messages that are not poses (`sensor_msgs/Imu`, `sensor_msgs/NavSatFix`
//! in `navsat.rs`): their type names, their decoding from ROS 1 and CDR bytes
//! ([`decode_sensor`]) and one topic's streaming state (`SensorState`: stamps, health per
//! 3 × 3 block, σ statistics, a bounded σ series and what is drawn: the thinned fixes, the
//! newest orientation), reduced to a [`SensorTopicSummary`].

use serde::{Deserialize, Serialize};

use super::Codec;
use super::decode::{DecodeError, Header, Ros1, cdr, header_stamp};
use super::health::{BlockHealth, CONSTANT_MIN_MESSAGES, Trend, classify_block};
use super::navsat::{Declared, Fix, declared, decode_navsat};
use super::topic::Stamps;
use crate::plan::log::{
    AxisStats, BlockSummary, DEFAULT_MAX_DRAWN, Decimator, FixPoint, Health, Issue, IssueCount,
    MAX_BLOCKS, MAX_DRAWN_LIMIT, OrientationPoint, PLACEHOLDER, SensorDrawn, SensorKind,
    SensorSeriesPoint, SensorTopicSummary,
};

/// MD5 sums of the ROS 1 definitions read (what `rosmsg md5` prints).
pub const ROS1_MD5: [(SensorKind, &str); 4] = [
    (SensorKind::Imu, "6a62c6daae103f4ff57a132d6f95cec2"),
    (SensorKind::NavSatFix, "2d3a8cd499b9b4a0249fb98fd05cfa48"),
    (SensorKind::Twist, "8927a1a12fb2607ceea095b2dc440a96"),
    (SensorKind::Accel, "96adb295225031ec8d57fb4251b0a886"),
];

/// The sensor kind of a ROS 1 type (`md5` `*`: taken by name); `Err` when the MD5 sum says
/// another definition.
///
/// ```
/// use posecov::input::log::sensor::ros1_sensor;
/// use posecov::plan::log::SensorKind;
/// assert_eq!(ros1_sensor("sensor_msgs/Imu", "6a62c6daae103f4ff57a132d6f95cec2"), Some(Ok(SensorKind::Imu)));
/// assert!(ros1_sensor("sensor_msgs/Imu", "0").unwrap().is_err());
/// assert_eq!(ros1_sensor("nav_msgs/Odometry", "*"), None);
/// ```
pub fn ros1_sensor(type_name: &str, md5: &str) -> Option<Result<SensorKind, String>> {
    super::decode::by_ros1_definition(
        ROS1_MD5.iter().map(|&(k, sum)| (k.ros1_name(), sum, k)),
        type_name,
        md5,
    )
}

/// The sensor kind of a ROS 2 schema name (the ROS 1 spelling is accepted too).
///
/// ```
/// use posecov::input::log::sensor::ros2_sensor;
/// assert!(ros2_sensor("sensor_msgs/msg/Imu").is_some());
/// assert!(ros2_sensor("geometry_msgs/msg/TwistWithCovarianceStamped").is_some());
/// // An Odometry topic is a pose topic (its twist is read beside it).
/// assert!(ros2_sensor("nav_msgs/msg/Odometry").is_none());
/// assert!(ros2_sensor("sensor_msgs/msg/Image").is_none());
/// ```
pub fn ros2_sensor(schema_name: &str) -> Option<SensorKind> {
    SensorKind::ALL.into_iter().find(|k| {
        k.is_own_message() && (k.ros2_name() == schema_name || k.ros1_name() == schema_name)
    })
}

/// A decoded sensor message: its stamp, frame and covariance blocks (row-major 3 × 3, in
/// [`SensorKind::blocks`]' order; the unused ones zero).
#[derive(Debug, Clone, PartialEq)]
pub struct SensorMessage {
    /// The header stamp, ns (0 with `from_log_time` when zero).
    pub stamp_ns: i64,
    /// The header stamp was zero: the log time is used.
    pub from_log_time: bool,
    /// `header.frame_id`.
    pub frame_id: String,
    /// `orientation` (x, y, z, w) of an IMU.
    pub orientation_xyzw: [f64; 4],
    /// The covariance blocks.
    pub blocks: [[f64; 9]; MAX_BLOCKS],
    /// A NavSatFix's fix (`navsat.rs`).
    pub fix: Option<Fix>,
}

/// `sensor_msgs/Imu` as CDR lays it out (field order is the wire order).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Imu {
    /// Header.
    pub header: Header,
    /// Orientation (x, y, z, w).
    pub orientation: [f64; 4],
    /// Row-major 3 × 3, rad².
    pub orientation_covariance: [f64; 9],
    /// Angular velocity, rad/s.
    pub angular_velocity: [f64; 3],
    /// Row-major 3 × 3, (rad/s)².
    pub angular_velocity_covariance: [f64; 9],
    /// Linear acceleration, m/s².
    pub linear_acceleration: [f64; 3],
    /// Row-major 3 × 3, (m/s²)².
    pub linear_acceleration_covariance: [f64; 9],
}

/// Decodes a sensor message of `kind` from its bytes in `codec`.
///
/// ```
/// use posecov::input::log::sensor::{Imu, decode_sensor};
/// use posecov::plan::log::SensorKind;
/// let mut imu = Imu::default();
/// imu.orientation_covariance[0] = -1.0;
/// let mut bytes = vec![0, 1, 0, 0];
/// bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&imu).unwrap());
/// let m = decode_sensor(SensorKind::Imu, posecov::input::log::Codec::Cdr, &bytes).unwrap();
/// assert_eq!(m.blocks[0][0], -1.0);
/// assert!(decode_sensor(SensorKind::Imu, posecov::input::log::Codec::Ros1, &bytes[..9]).is_err());
/// ```
pub fn decode_sensor(
    kind: SensorKind,
    codec: Codec,
    bytes: &[u8],
) -> Result<SensorMessage, DecodeError> {
    let imu = match (kind, codec) {
        (SensorKind::NavSatFix, _) => return decode_navsat(codec, bytes),
        (SensorKind::Twist | SensorKind::Accel | SensorKind::OdometryTwist, _) => {
            return super::velocity::decode(kind, codec, bytes);
        }
        (SensorKind::Imu, Codec::Cdr) => cdr::<Imu>(bytes, kind.ros2_name())?,
        (SensorKind::Imu, Codec::Ros1) => {
            let mut r = Ros1 { bytes, at: 0 };
            let (stamp, frame_id) = r.header()?;
            let imu = Imu {
                header: Header {
                    stamp: Default::default(),
                    frame_id,
                },
                orientation: r.f64s::<4>("orientation")?,
                orientation_covariance: r.f64s::<9>("orientation_covariance")?,
                angular_velocity: r.f64s::<3>("angular_velocity")?,
                angular_velocity_covariance: r.f64s::<9>("angular_velocity_covariance")?,
                linear_acceleration: r.f64s::<3>("linear_acceleration")?,
                linear_acceleration_covariance: r.f64s::<9>("linear_acceleration_covariance")?,
            };
            return Ok(imu_message(imu, stamp));
        }
    };
    let stamp = header_stamp(imu.header.stamp);
    Ok(imu_message(imu, stamp))
}

fn imu_message(imu: Imu, stamp: Option<i64>) -> SensorMessage {
    SensorMessage {
        stamp_ns: stamp.unwrap_or(0),
        from_log_time: stamp.is_none(),
        frame_id: imu.header.frame_id,
        orientation_xyzw: imu.orientation,
        blocks: [
            imu.orientation_covariance,
            imu.angular_velocity_covariance,
            imu.linear_acceleration_covariance,
        ],
        fix: None,
    }
}

/// One block's running state: its findings, trend, whether it has stayed identical, and its
/// variances' statistics.
#[derive(Debug, Clone, Default)]
struct BlockState {
    health: Health,
    trend: Trend,
    /// The last message's block and its classification (a repeated block is classified once).
    last: Option<([f64; 9], BlockHealth)>,
    /// The first usable block, its message and stamp, and whether every usable one since is
    /// identical.
    first_usable: Option<([f64; 9], u64, i64)>,
    identical: bool,
    usable: u64,
    variance: [Option<AxisStats>; 3],
}

impl BlockState {
    /// Message `index`'s block `b` at `stamp_ns`, with what its message `declared` of it
    /// (a NavSatFix's covariance type): its σ per axis where usable and estimated.
    fn add(
        &mut self,
        index: u64,
        stamp_ns: i64,
        b: &[f64; 9],
        declared: Declared,
    ) -> [Option<f64>; 3] {
        for issue in declared.issues.iter() {
            self.health.note(issue, stamp_ns, index);
        }
        if declared.unchecked {
            return [None; 3];
        }
        let h = match &self.last {
            Some((last, h)) if last.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()) => *h,
            _ => {
                let h = classify_block(b);
                self.last = Some((*b, h));
                h
            }
        };
        let mut issues = h.issues;
        if let Some(trace) = h.trace {
            issues.extend(self.trend.next(trace).iter());
        }
        for issue in issues.iter() {
            self.health.note(issue, stamp_ns, index);
        }
        if let Some(lo) = h.min_eigenvalue {
            self.health.min_eigenvalue = Some(self.health.min_eigenvalue.map_or(lo, |m| m.min(lo)));
        }
        let mut variance = [None; 3];
        if !h.usable() {
            return variance;
        }
        self.usable += 1;
        match &self.first_usable {
            None => {
                self.first_usable = Some((*b, index, stamp_ns));
                self.identical = true;
            }
            Some((first, ..)) => self.identical &= first == b,
        }
        for (i, v) in variance.iter_mut().enumerate() {
            if !h.unestimated[i] {
                let x = b[i * 4].max(0.0);
                AxisStats::add(&mut self.variance[i], x);
                *v = Some(x.sqrt());
            }
        }
        variance
    }

    fn into_plan(self, spec: crate::plan::log::BlockSpec) -> BlockSummary {
        let mut health = self.health;
        if let Some((_, first_index, first_stamp_ns)) = self.first_usable
            && self.identical
            && self.usable >= CONSTANT_MIN_MESSAGES
        {
            health.add(
                Issue::Constant,
                IssueCount {
                    count: self.usable,
                    first_stamp_ns,
                    first_index,
                },
            );
        }
        BlockSummary {
            spec,
            health,
            sigma_stats: self.variance.map(|s| s.map(AxisStats::sqrt)),
        }
    }
}

/// One sensor topic's streaming state (cloned for a growing live read's summary so far).
#[derive(Debug, Clone)]
pub(super) struct SensorState {
    pub(super) kind: SensorKind,
    frame_id: Option<String>,
    count: u64,
    stamps: Stamps,
    /// The topic's own findings (stamps, undecodable messages, other types).
    pub(super) health: Health,
    blocks: Vec<BlockState>,
    series: Decimator<SensorSeriesPoint>,
    /// A NavSatFix's drawn fixes, thinned as a pose topic's drawn messages.
    fixes: Decimator<FixPoint>,
    orientation: Option<OrientationPoint>,
}

impl SensorState {
    /// A topic of `kind`, its fixes drawn every `every`-th (`--every`; `None`: at most
    /// [`DEFAULT_MAX_DRAWN`]).
    pub(super) fn new(kind: SensorKind, every: Option<u64>) -> Self {
        SensorState {
            kind,
            frame_id: None,
            count: 0,
            stamps: Stamps::default(),
            health: Health::default(),
            blocks: vec![BlockState::default(); kind.blocks().len()],
            series: Decimator::new(1, super::MAX_SERIES),
            fixes: match every {
                Some(n) => Decimator::new(n, MAX_DRAWN_LIMIT),
                None => Decimator::new(1, DEFAULT_MAX_DRAWN),
            },
            orientation: None,
        }
    }

    /// Takes the next message, logged at `log_time_ns` (an Odometry's twist: every message of
    /// the pose topic, so that both count messages alike).
    pub(super) fn add(&mut self, decoded: Result<SensorMessage, DecodeError>, log_time_ns: i64) {
        let index = self.count;
        self.count += 1;
        // An Odometry's twist: its bytes and stamps are the pose topic's, whose findings they are.
        let own = self.kind.is_own_message();
        let Ok(mut m) = decoded else {
            if own {
                self.health.note(Issue::Undecodable, log_time_ns, index);
            }
            return;
        };
        if m.from_log_time {
            m.stamp_ns = log_time_ns;
        }
        let mut pose_topics = Health::default();
        let health = if own {
            &mut self.health
        } else {
            &mut pose_topics
        };
        self.stamps
            .next(m.stamp_ns, m.from_log_time, true, index, health);
        if self.frame_id.is_none() && !m.frame_id.is_empty() {
            self.frame_id = Some(std::mem::take(&mut m.frame_id));
        }
        let mut sigma = [[None; 3]; MAX_BLOCKS];
        for (k, block) in self.blocks.iter_mut().enumerate() {
            // A fix's covariance type speaks of its one block.
            let said = match &m.fix {
                Some(fix) if k == 0 => declared(fix, &m.blocks[0]),
                _ => Declared::default(),
            };
            sigma[k] = block.add(index, m.stamp_ns, &m.blocks[k], said);
        }
        self.keep_drawn(index, &m, &sigma);
        self.series.push(
            index,
            SensorSeriesPoint {
                stamp_ns: m.stamp_ns,
                sigma,
            },
        );
    }

    /// Keeps what is drawn of message `index` (`sigma`: its blocks' σ, `None` where unusable
    /// or not estimated): a fix that has a position (else `no_fix`), an IMU's orientation.
    fn keep_drawn(&mut self, index: u64, m: &SensorMessage, sigma: &[[Option<f64>; 3]]) {
        if let Some(fix) = &m.fix {
            if fix.status == super::navsat::STATUS_NO_FIX {
                self.health.note(Issue::NoFix, m.stamp_ns, index);
            }
            if fix.drawable() && self.fixes.wants(index) {
                let checked = sigma[0].iter().any(Option::is_some);
                let point = FixPoint {
                    index,
                    stamp_ns: m.stamp_ns,
                    latitude_deg: fix.latitude_deg,
                    longitude_deg: fix.longitude_deg,
                    altitude_m: fix.altitude_m,
                    covariance_enu: checked.then_some(m.blocks[0]),
                };
                self.fixes.push(index, point);
            }
            return;
        }
        let q = m.orientation_xyzw;
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let unit = (norm - 1.0).abs() < 1e-6; // false for NaN too
        if self.kind != SensorKind::Imu || !unit {
            return;
        }
        let unestimated = sigma[0].map(|s| s.is_none());
        if unestimated.iter().all(|u| *u) {
            return;
        }
        let b = &m.blocks[0];
        let covariance = std::array::from_fn(|i| {
            let (r, c) = (i / 3, i % 3);
            if unestimated[r] || unestimated[c] || b[i] >= PLACEHOLDER {
                0.0
            } else {
                b[i]
            }
        });
        self.orientation = Some(OrientationPoint {
            index,
            stamp_ns: m.stamp_ns,
            orientation_xyzw: q,
            covariance,
            unestimated,
        });
    }

    /// Messages taken so far.
    pub(super) fn count(&self) -> u64 {
        self.count
    }

    pub(super) fn into_plan(self, name: String) -> SensorTopicSummary {
        let mut series = self.series.into_items();
        series.sort_by_key(|p| p.stamp_ns);
        SensorTopicSummary {
            name,
            kind: self.kind,
            frame_id: self.frame_id.unwrap_or_default(),
            count: self.count,
            stamps_from_log_time: self.stamps.from_log,
            stamps_out_of_order: self.stamps.out_of_order,
            stamp_range: self.stamps.range,
            health: self.health,
            blocks: self
                .blocks
                .into_iter()
                .zip(self.kind.blocks())
                .map(|(b, spec)| b.into_plan(*spec))
                .collect(),
            series,
            drawn: SensorDrawn {
                fixes: self.fixes.into_items(),
                orientation: self.orientation,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn imu_ros1(cov0: f64) -> Vec<u8> {
        let mut b = Vec::new();
        for v in [1u32, 12, 500, 3] {
            b.extend(v.to_le_bytes());
        }
        b.extend(b"imu");
        let diagonal = |first: f64| {
            let mut c = [0.0; 9];
            c[0] = first;
            c[4] = 0.01;
            c[8] = 0.01;
            c
        };
        let values = [0.0, 0.0, 0.0, 1.0]
            .into_iter()
            .chain(diagonal(cov0))
            .chain([0.0; 3])
            .chain(diagonal(0.01))
            .chain([0.0; 3])
            .chain(diagonal(0.01));
        for v in values {
            b.extend(f64::to_le_bytes(v));
        }
        b
    }

    #[test]
    fn ros1_imu_decodes_and_every_truncation_is_an_error() {
        let full = imu_ros1(-1.0);
        let m = decode_sensor(SensorKind::Imu, Codec::Ros1, &full).unwrap();
        assert_eq!((m.stamp_ns, m.frame_id.as_str()), (12_000_000_500, "imu"));
        assert_eq!(m.blocks[0][0], -1.0);
        assert_eq!(
            (m.blocks[1][0], m.blocks[1][4], m.blocks[2][8]),
            (0.01, 0.01, 0.01)
        );
        for cut in 1..full.len() {
            assert!(decode_sensor(SensorKind::Imu, Codec::Ros1, &full[..cut]).is_err());
            let _ = decode_sensor(SensorKind::Imu, Codec::Cdr, &full[..cut]);
        }
    }

    #[test]
    fn a_not_provided_block_is_a_note_and_the_others_are_read() {
        let mut s = SensorState::new(SensorKind::Imu, None);
        for k in 0..12 {
            let m = decode_sensor(SensorKind::Imu, Codec::Ros1, &imu_ros1(-1.0));
            s.add(m, k);
        }
        let t = s.into_plan("/imu".into());
        assert_eq!(t.blocks[0].health.count(Issue::UnknownMarker), 12);
        assert_eq!(t.blocks[0].sigma_stats, [None; 3]);
        assert_eq!(t.blocks[1].sigma_stats[0].unwrap().max, 0.1);
        assert_eq!(t.blocks[1].health.count(Issue::Constant), 12);
        // The same stamp on every message: frozen.
        assert_eq!(t.health.count(Issue::FrozenStamp), 11);
        let classes: Vec<_> = t.findings().map(|(b, i, _, c)| (b, i, c)).collect();
        use crate::plan::log::Class;
        assert!(classes.contains(&(Some("orientation"), Issue::UnknownMarker, Class::Note)));
        assert_eq!(classes[0], (None, Issue::FrozenStamp, Class::Defect));
    }
}
