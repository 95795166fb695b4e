//! Velocities and accelerations with covariance (issue 32): `geometry_msgs/TwistWithCovarianceStamped`,
//! `geometry_msgs/AccelWithCovarianceStamped` and the twist half of `nav_msgs/Odometry`, decoded
//! from ROS 1 and CDR bytes into a [`SensorMessage`] whose blocks are the 6 × 6 covariance's two
//! 3 × 3 diagonal blocks (rows and columns 0–2: linear; 3–5: angular). The cross-covariance
//! between the linear and the angular part (the off-diagonal blocks) is not read.
//!
//! ```
//! use posecov::input::log::velocity::{VelocityStamped, decode};
//! use posecov::input::log::Codec;
//! use posecov::plan::log::SensorKind;
//! let mut m = VelocityStamped::default();
//! m.header.stamp.sec = 3;
//! m.value.covariance[0][0] = 0.04; // σ vx = 0.2 m/s
//! m.value.covariance[5][5] = 0.01; // σ ωz = 0.1 rad/s
//! let mut bytes = vec![0, 1, 0, 0];
//! bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&m).unwrap());
//! let d = decode(SensorKind::Twist, Codec::Cdr, &bytes).unwrap();
//! assert_eq!((d.stamp_ns, d.blocks[0][0], d.blocks[1][8]), (3_000_000_000, 0.04, 0.01));
//! ```

use serde::{Deserialize, Serialize};

use super::Codec;
use super::decode::{
    DecodeError, Header, Ros1, TwistWithCovariance, cdr, decode_cdr, decode_ros1, header_stamp,
};
use super::sensor::SensorMessage;
use crate::plan::log::{COV_LEN, MAX_BLOCKS, PoseMessage, PoseMessageKind, SensorKind};

/// `geometry_msgs/TwistWithCovarianceStamped` and `geometry_msgs/AccelWithCovarianceStamped` as
/// CDR lays them out (the same on the wire: a header, six `f64` — linear then angular — and a
/// row-major 6 × 6 covariance).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct VelocityStamped {
    /// Header.
    pub header: Header,
    /// The twist or acceleration with its covariance.
    pub value: TwistWithCovariance,
}

/// Decodes a message of `kind` (`Twist`, `Accel` or `OdometryTwist`; an IMU is an error) from
/// its bytes in `codec`.
///
/// See the [module docs](self) for an example.
pub fn decode(kind: SensorKind, codec: Codec, bytes: &[u8]) -> Result<SensorMessage, DecodeError> {
    let what = kind.ros2_name();
    match (kind, codec) {
        (SensorKind::OdometryTwist, _) => {
            let m = match codec {
                Codec::Ros1 => decode_ros1(PoseMessageKind::Odometry, bytes)?,
                Codec::Cdr => decode_cdr(PoseMessageKind::Odometry, bytes)?,
            };
            odometry_twist(&m)
                .ok_or_else(|| DecodeError("an Odometry message without a twist".to_owned()))
        }
        (SensorKind::Twist | SensorKind::Accel, Codec::Cdr) => {
            let m: VelocityStamped = cdr(bytes, what)?;
            let stamp = header_stamp(m.header.stamp);
            let flat: [f64; COV_LEN] = std::array::from_fn(|i| m.value.covariance[i / 6][i % 6]);
            Ok(message(stamp, m.header.frame_id, &flat))
        }
        (SensorKind::Twist | SensorKind::Accel, Codec::Ros1) => {
            let mut r = Ros1 { bytes, at: 0 };
            let (stamp, frame_id) = r.header()?;
            let field = if kind == SensorKind::Twist {
                "twist"
            } else {
                "accel"
            };
            let _value = r.f64s::<6>(field)?;
            let covariance = r.f64s::<COV_LEN>("covariance")?;
            Ok(message(stamp, frame_id, &covariance))
        }
        (other, _) => Err(DecodeError(format!(
            "{} is not a velocity or acceleration",
            other.ros1_name()
        ))),
    }
}

/// The twist half of a decoded `nav_msgs/Odometry` (`None` for another pose message): its
/// covariance's blocks in `child_frame_id`, at the message's stamp.
///
/// ```
/// use posecov::input::log::velocity::odometry_twist;
/// use posecov::plan::log::PoseMessage;
/// let mut twist = [0.0; 36];
/// twist[21] = 0.5; // Σ(ωx, ωx)
/// let m = PoseMessage { stamp_ns: 7, from_log_time: false, frame_id: "odom".into(),
///     child_frame_id: "base_link".into(), position: [0.0; 3],
///     orientation_xyzw: [0.0, 0.0, 0.0, 1.0], covariance: [0.0; 36],
///     twist_covariance: Some(twist) };
/// let t = odometry_twist(&m).unwrap();
/// assert_eq!((t.frame_id.as_str(), t.blocks[1][0]), ("base_link", 0.5));
/// ```
pub fn odometry_twist(m: &PoseMessage) -> Option<SensorMessage> {
    let twist = m.twist_covariance.as_ref()?;
    let stamp = (!m.from_log_time).then_some(m.stamp_ns);
    Some(message(stamp, m.child_frame_id.clone(), twist))
}

/// A message at `stamp` (`None`: zero, the log time is used) whose blocks are the diagonal
/// blocks of the row-major 6 × 6 `covariance`.
fn message(stamp: Option<i64>, frame_id: String, covariance: &[f64; COV_LEN]) -> SensorMessage {
    let block = |k: usize| -> [f64; 9] {
        std::array::from_fn(|i| covariance[(3 * k + i / 3) * 6 + 3 * k + i % 3])
    };
    let mut blocks = [[0.0; 9]; MAX_BLOCKS];
    blocks[0] = block(0);
    blocks[1] = block(1);
    SensorMessage {
        stamp_ns: stamp.unwrap_or(0),
        from_log_time: stamp.is_none(),
        frame_id,
        orientation_xyzw: [0.0, 0.0, 0.0, 1.0],
        blocks,
        fix: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ros1_twist(covariance: &[f64; 36]) -> Vec<u8> {
        let mut b = Vec::new();
        for v in [4u32, 2, 250, 4] {
            b.extend(v.to_le_bytes());
        }
        b.extend(b"base");
        for v in [1.0, 0.0, 0.0, 0.0, 0.0, 0.3].iter().chain(covariance) {
            b.extend(f64::to_le_bytes(*v));
        }
        b
    }

    #[test]
    fn ros1_blocks_are_the_diagonal_blocks_and_truncations_are_errors() {
        let covariance: [f64; 36] = std::array::from_fn(|i| i as f64);
        let full = ros1_twist(&covariance);
        for kind in [SensorKind::Twist, SensorKind::Accel] {
            let m = decode(kind, Codec::Ros1, &full).unwrap();
            assert_eq!((m.stamp_ns, m.frame_id.as_str()), (2_000_000_250, "base"));
            assert_eq!(
                m.blocks[0],
                [0.0, 1.0, 2.0, 6.0, 7.0, 8.0, 12.0, 13.0, 14.0]
            );
            assert_eq!(
                m.blocks[1],
                [21.0, 22.0, 23.0, 27.0, 28.0, 29.0, 33.0, 34.0, 35.0]
            );
            assert_eq!(m.blocks[2], [0.0; 9]);
            for cut in 0..full.len() {
                assert!(decode(kind, Codec::Ros1, &full[..cut]).is_err(), "{cut}");
                let _ = decode(kind, Codec::Cdr, &full[..cut]);
            }
        }
        assert!(decode(SensorKind::Imu, Codec::Ros1, &full).is_err());
        assert!(decode(SensorKind::OdometryTwist, Codec::Ros1, &full).is_err());
    }
}
