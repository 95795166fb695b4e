//! The message types a reference (ground truth) is read from, in ROS 1 serialization and CDR:
//! `geometry_msgs/PoseStamped`, `geometry_msgs/TransformStamped`, `tf2_msgs/TFMessage` (`/tf`,
//! also the older `tf/tfMessage`), and the pose of `PoseWithCovarianceStamped` / `Odometry`
//! (decoded as [`decode`](super::decode) does; their covariance is not used).
//!
//! ```
//! use posecov::input::bag::reference::{ReferenceType, ros1_reference_type};
//! assert_eq!(ros1_reference_type("geometry_msgs/PoseStamped", "d3812c3cbc69362b77dc0b19b345f8f5"), Some(Ok(ReferenceType::PoseStamped)));
//! assert!(ros1_reference_type("geometry_msgs/PoseStamped", "0").unwrap().is_err());
//! ```

use serde::{Deserialize, Serialize};

use super::Codec;
use super::decode::{
    DecodeError, Decoded, Header, Ros1, cdr, decode_cdr, decode_ros1, header_stamp, ros2_kind,
};
use crate::plan::bag::{PoseMessageKind, ReferenceSample};

/// A message type a reference pose is read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceType {
    /// `geometry_msgs/PoseStamped`.
    PoseStamped,
    /// `geometry_msgs/TransformStamped` (parent `header.frame_id`, `child_frame_id`).
    TransformStamped,
    /// `tf2_msgs/TFMessage`: an array of `TransformStamped`.
    TfMessage,
    /// The pose of a pose-with-covariance type.
    Pose(PoseMessageKind),
}

/// ROS 1 names and MD5 sums of the reference-only types.
const ROS1: [(&str, &str, ReferenceType); 4] = [
    (
        "geometry_msgs/PoseStamped",
        "d3812c3cbc69362b77dc0b19b345f8f5",
        ReferenceType::PoseStamped,
    ),
    (
        "geometry_msgs/TransformStamped",
        "b5764a33bfeb3588febc2682852579b0",
        ReferenceType::TransformStamped,
    ),
    (
        "tf2_msgs/TFMessage",
        "94810edda583a504dfda3829e70d7eec",
        ReferenceType::TfMessage,
    ),
    (
        "tf/tfMessage",
        "94810edda583a504dfda3829e70d7eec",
        ReferenceType::TfMessage,
    ),
];

/// ROS 2 schema names of the reference-only types.
const ROS2: [(&str, ReferenceType); 3] = [
    ("geometry_msgs/msg/PoseStamped", ReferenceType::PoseStamped),
    (
        "geometry_msgs/msg/TransformStamped",
        ReferenceType::TransformStamped,
    ),
    ("tf2_msgs/msg/TFMessage", ReferenceType::TfMessage),
];

/// The reference type of a ROS 1 connection; `Err` when the name is known and the MD5 sum
/// says another definition. Pose-with-covariance types follow [`super::decode::ros1_kind`].
pub fn ros1_reference_type(type_name: &str, md5: &str) -> Option<Result<ReferenceType, String>> {
    if let Some(kind) = super::decode::ros1_kind(type_name, md5) {
        return Some(kind.map(ReferenceType::Pose));
    }
    let (_, expected, kind) = ROS1.iter().find(|(name, ..)| *name == type_name)?;
    Some(if md5 == *expected || md5 == "*" {
        Ok(*kind)
    } else {
        Err(format!(
            "{type_name} with MD5 {md5} (posecov reads definition {expected})"
        ))
    })
}

/// The reference type of an MCAP channel's schema name (the ROS 1 spelling accepted too).
///
/// ```
/// use posecov::input::bag::reference::{ReferenceType, ros2_reference_type};
/// assert_eq!(ros2_reference_type("tf2_msgs/msg/TFMessage"), Some(ReferenceType::TfMessage));
/// assert_eq!(ros2_reference_type("sensor_msgs/msg/Imu"), None);
/// ```
pub fn ros2_reference_type(schema_name: &str) -> Option<ReferenceType> {
    if let Some(kind) = ros2_kind(schema_name) {
        return Some(ReferenceType::Pose(kind));
    }
    ROS2.iter()
        .find(|(name, _)| *name == schema_name)
        .map(|(_, k)| *k)
        .or_else(|| {
            ROS1.iter()
                .find(|(name, ..)| *name == schema_name)
                .map(|(.., k)| *k)
        })
}

/// One decoded reference pose: its parent frame, its child frame (empty where the type has
/// none) and the pose; `stamp_ns` is `None` for a zero stamp.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferencePose {
    /// `header.frame_id`.
    pub frame_id: String,
    /// `child_frame_id` (TransformStamped, Odometry).
    pub child_frame_id: String,
    /// The header stamp, ns (`None`: zero).
    pub stamp_ns: Option<i64>,
    /// Position.
    pub position: [f64; 3],
    /// Orientation (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
}

impl From<Decoded> for ReferencePose {
    /// The pose of a pose-with-covariance message (its covariance left out).
    fn from(d: Decoded) -> Self {
        ReferencePose {
            frame_id: d.frame_id,
            child_frame_id: d.child_frame_id,
            stamp_ns: d.stamp_ns,
            position: d.position,
            orientation_xyzw: d.orientation_xyzw,
        }
    }
}

impl ReferencePose {
    /// The sample, its stamp the header's or else `log_time_ns`.
    pub fn sample(&self, log_time_ns: i64) -> ReferenceSample {
        ReferenceSample {
            stamp_ns: self.stamp_ns.unwrap_or(log_time_ns),
            position: self.position,
            orientation_xyzw: self.orientation_xyzw,
        }
    }
}

/// `geometry_msgs/Transform` (CDR): translation, rotation (x, y, z, w).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transform {
    /// Translation.
    pub translation: [f64; 3],
    /// Rotation (x, y, z, w).
    pub rotation: [f64; 4],
}

/// `geometry_msgs/TransformStamped` (CDR).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Header (the parent frame).
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// parent_from_child.
    pub transform: Transform,
}

/// `tf2_msgs/TFMessage` (CDR).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `geometry_msgs/PoseStamped` (CDR).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Header.
    pub header: Header,
    /// The pose.
    pub pose: super::decode::Pose,
}

/// Decodes a reference message of type `kind`: one pose, several for a `TFMessage`.
///
/// ```
/// use posecov::input::bag::reference::{ReferenceType, decode_ros1_reference};
/// let mut m = vec![0u8; 12];
/// m.extend(3u32.to_le_bytes());
/// m.extend(b"map");
/// for v in [1.0f64, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] { m.extend(v.to_le_bytes()); }
/// let poses = decode_ros1_reference(ReferenceType::PoseStamped, &m).unwrap();
/// assert_eq!((poses[0].frame_id.as_str(), poses[0].position), ("map", [1.0, 2.0, 3.0]));
/// ```
pub fn decode_ros1_reference(
    kind: ReferenceType,
    bytes: &[u8],
) -> Result<Vec<ReferencePose>, DecodeError> {
    let mut r = Ros1 { bytes, at: 0 };
    let transform = |r: &mut Ros1<'_>| -> Result<ReferencePose, DecodeError> {
        let (stamp_ns, frame_id) = r.header()?;
        let child_frame_id = r.string("child_frame_id")?;
        let position = r.f64s::<3>("transform.translation")?;
        let orientation_xyzw = r.f64s::<4>("transform.rotation")?;
        Ok(ReferencePose {
            frame_id,
            child_frame_id,
            stamp_ns,
            position,
            orientation_xyzw,
        })
    };
    match kind {
        ReferenceType::PoseStamped => {
            let (stamp_ns, frame_id) = r.header()?;
            let position = r.f64s::<3>("pose.position")?;
            let orientation_xyzw = r.f64s::<4>("pose.orientation")?;
            Ok(vec![ReferencePose {
                frame_id,
                child_frame_id: String::new(),
                stamp_ns,
                position,
                orientation_xyzw,
            }])
        }
        ReferenceType::TransformStamped => Ok(vec![transform(&mut r)?]),
        ReferenceType::TfMessage => {
            let n = r.u32("transforms (length)")?;
            (0..n).map(|_| transform(&mut r)).collect()
        }
        ReferenceType::Pose(kind) => Ok(vec![decode_ros1(kind, bytes)?.into()]),
    }
}

/// Decodes a CDR reference message of type `kind` (encapsulation header included).
///
/// ```
/// use posecov::input::bag::reference::{ReferenceType, TfMessage, TransformStamped, decode_cdr_reference};
/// let mut tf = TfMessage::default();
/// tf.transforms.push(TransformStamped { child_frame_id: "base".into(), ..Default::default() });
/// let mut bytes = vec![0, 1, 0, 0];
/// bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&tf).unwrap());
/// let poses = decode_cdr_reference(ReferenceType::TfMessage, &bytes).unwrap();
/// assert_eq!(poses[0].child_frame_id, "base");
/// ```
pub fn decode_cdr_reference(
    kind: ReferenceType,
    bytes: &[u8],
) -> Result<Vec<ReferencePose>, DecodeError> {
    let of_transform = |t: TransformStamped| ReferencePose {
        stamp_ns: header_stamp(&t.header),
        frame_id: t.header.frame_id,
        child_frame_id: t.child_frame_id,
        position: t.transform.translation,
        orientation_xyzw: t.transform.rotation,
    };
    match kind {
        ReferenceType::PoseStamped => {
            let m: PoseStamped = cdr(bytes, "geometry_msgs/msg/PoseStamped")?;
            Ok(vec![ReferencePose {
                stamp_ns: header_stamp(&m.header),
                frame_id: m.header.frame_id,
                child_frame_id: String::new(),
                position: m.pose.position,
                orientation_xyzw: m.pose.orientation,
            }])
        }
        ReferenceType::TransformStamped => Ok(vec![of_transform(cdr(
            bytes,
            "geometry_msgs/msg/TransformStamped",
        )?)]),
        ReferenceType::TfMessage => {
            let m: TfMessage = cdr(bytes, "tf2_msgs/msg/TFMessage")?;
            Ok(m.transforms.into_iter().map(of_transform).collect())
        }
        ReferenceType::Pose(kind) => Ok(vec![decode_cdr(kind, bytes)?.into()]),
    }
}

/// Decodes a reference message in `codec`.
pub(super) fn decode_reference(
    kind: ReferenceType,
    codec: Codec,
    bytes: &[u8],
) -> Result<Vec<ReferencePose>, DecodeError> {
    match codec {
        Codec::Ros1 => decode_ros1_reference(kind, bytes),
        Codec::Cdr => decode_cdr_reference(kind, bytes),
    }
}
