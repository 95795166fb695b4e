//! The message types a reference (ground truth) is read from, in ROS 1 serialization and CDR:
//! `geometry_msgs/PoseStamped`, `geometry_msgs/TransformStamped`, `tf2_msgs/TFMessage` (`/tf`,
//! also the older `tf/tfMessage`), and the pose of `PoseWithCovarianceStamped` / `Odometry`
//! (decoded as [`decode`](super::decode) does; their covariance is not used).
//!
//! ```
//! use posecov::input::log::reference::{ReferenceType, ros1_reference_type};
//! assert_eq!(ros1_reference_type("geometry_msgs/PoseStamped", "d3812c3cbc69362b77dc0b19b345f8f5"), Some(Ok(ReferenceType::PoseStamped)));
//! assert!(ros1_reference_type("geometry_msgs/PoseStamped", "0").unwrap().is_err());
//! ```

use std::borrow::Cow;

use serde::{Deserialize, Deserializer, Serialize};

use super::Codec;
use super::decode::{
    DecodeError, Header, Ros1, Time, cdr, decode_cdr, decode_ros1, header_stamp, ros2_kind,
};
use crate::plan::log::{PoseMessage, PoseMessageKind, ReferenceSample};

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
    super::decode::by_ros1_definition(ROS1.iter().copied(), type_name, md5)
}

/// The reference type of an MCAP channel's schema name (the ROS 1 spelling accepted too).
///
/// ```
/// use posecov::input::log::reference::{ReferenceType, ros2_reference_type};
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
/// none) and the pose; `stamp_ns` is `None` for a zero stamp. The frame names are borrowed
/// from the message's bytes where they can be (a `/tf` message at 100 Hz allocates nothing).
#[derive(Debug, Clone, PartialEq)]
pub struct ReferencePose<'a> {
    /// `header.frame_id`.
    pub frame_id: Cow<'a, str>,
    /// `child_frame_id` (TransformStamped, Odometry).
    pub child_frame_id: Cow<'a, str>,
    /// The header stamp, ns (`None`: zero).
    pub stamp_ns: Option<i64>,
    /// Position.
    pub position: [f64; 3],
    /// Orientation (x, y, z, w).
    pub orientation_xyzw: [f64; 4],
}

impl From<PoseMessage> for ReferencePose<'_> {
    /// The pose of a pose-with-covariance message (its covariance left out).
    fn from(d: PoseMessage) -> Self {
        ReferencePose {
            frame_id: d.frame_id.into(),
            child_frame_id: d.child_frame_id.into(),
            stamp_ns: (!d.from_log_time).then_some(d.stamp_ns),
            position: d.position,
            orientation_xyzw: d.orientation_xyzw,
        }
    }
}

impl ReferencePose<'_> {
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

/// The poses of one reference message: one, or any number for a `TFMessage` (the first kept
/// inline, so that the usual one-transform `/tf` message allocates nothing).
#[derive(Debug, Clone, PartialEq)]
pub enum Poses<'a> {
    /// The one pose of a message.
    One(ReferencePose<'a>),
    /// None, or several.
    Many(Vec<ReferencePose<'a>>),
}

impl<'a> Poses<'a> {
    /// The poses in message order.
    pub fn iter(&self) -> std::slice::Iter<'_, ReferencePose<'a>> {
        match self {
            Poses::One(pose) => std::slice::from_ref(pose).iter(),
            Poses::Many(poses) => poses.iter(),
        }
    }

    /// How many.
    pub fn len(&self) -> usize {
        self.iter().len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<'a> std::ops::Index<usize> for Poses<'a> {
    type Output = ReferencePose<'a>;
    fn index(&self, i: usize) -> &ReferencePose<'a> {
        match self {
            Poses::One(pose) => std::slice::from_ref(pose).index(i),
            Poses::Many(poses) => &poses[i],
        }
    }
}

impl<'a> FromIterator<ReferencePose<'a>> for Poses<'a> {
    fn from_iter<I: IntoIterator<Item = ReferencePose<'a>>>(poses: I) -> Self {
        let mut poses = poses.into_iter();
        let Some(first) = poses.next() else {
            return Poses::Many(Vec::new());
        };
        let Some(second) = poses.next() else {
            return Poses::One(first);
        };
        let mut all = vec![first, second];
        all.extend(poses);
        Poses::Many(all)
    }
}

impl<'a> IntoIterator for Poses<'a> {
    type Item = ReferencePose<'a>;
    type IntoIter = std::iter::Chain<
        std::option::IntoIter<ReferencePose<'a>>,
        std::vec::IntoIter<ReferencePose<'a>>,
    >;
    fn into_iter(self) -> Self::IntoIter {
        let (one, many) = match self {
            Poses::One(pose) => (Some(pose), Vec::new()),
            Poses::Many(poses) => (None, poses),
        };
        one.into_iter().chain(many)
    }
}

// The CDR types above as they are read: the same fields in the same order, the frame names
// borrowed from the message (the types above, with owned strings, are the ones written).

/// `std_msgs/Header` read.
#[derive(Deserialize)]
struct HeaderIn<'a> {
    stamp: Time,
    frame_id: &'a str,
}

/// `geometry_msgs/TransformStamped` read.
#[derive(Deserialize)]
struct TransformStampedIn<'a> {
    #[serde(borrow)]
    header: HeaderIn<'a>,
    child_frame_id: &'a str,
    transform: Transform,
}

impl<'a> From<TransformStampedIn<'a>> for ReferencePose<'a> {
    fn from(t: TransformStampedIn<'a>) -> Self {
        ReferencePose {
            stamp_ns: header_stamp(t.header.stamp),
            frame_id: t.header.frame_id.into(),
            child_frame_id: t.child_frame_id.into(),
            position: t.transform.translation,
            orientation_xyzw: t.transform.rotation,
        }
    }
}

/// `tf2_msgs/TFMessage` read: its transforms as [`Poses`].
#[derive(Deserialize)]
struct TfMessageIn<'a> {
    #[serde(borrow)]
    transforms: TransformsIn<'a>,
}

/// A `TransformStamped[]` read into [`Poses`].
struct TransformsIn<'a>(Poses<'a>);

impl<'de: 'a, 'a> Deserialize<'de> for TransformsIn<'a> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Each;
        impl<'de> serde::de::Visitor<'de> for Each {
            type Value = Poses<'de>;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a sequence of geometry_msgs/msg/TransformStamped")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Poses<'de>, A::Error> {
                std::iter::from_fn(|| seq.next_element::<TransformStampedIn<'de>>().transpose())
                    .map(|t| t.map(ReferencePose::from))
                    .collect()
            }
        }
        deserializer.deserialize_seq(Each).map(TransformsIn)
    }
}

/// `geometry_msgs/PoseStamped` read.
#[derive(Deserialize)]
struct PoseStampedIn<'a> {
    #[serde(borrow)]
    header: HeaderIn<'a>,
    pose: super::decode::Pose,
}

/// Decodes a reference message of type `kind`: one pose, several for a `TFMessage`.
///
/// ```
/// use posecov::input::log::reference::{ReferenceType, decode_ros1_reference};
/// let mut m = vec![0u8; 12];
/// m.extend(3u32.to_le_bytes());
/// m.extend(b"map");
/// for v in [1.0f64, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] { m.extend(v.to_le_bytes()); }
/// let poses = decode_ros1_reference(ReferenceType::PoseStamped, &m).unwrap();
/// assert_eq!((poses[0].frame_id.as_ref(), poses[0].position), ("map", [1.0, 2.0, 3.0]));
/// ```
pub fn decode_ros1_reference(kind: ReferenceType, bytes: &[u8]) -> Result<Poses<'_>, DecodeError> {
    fn transform<'a>(r: &mut Ros1<'a>) -> Result<ReferencePose<'a>, DecodeError> {
        let (stamp_ns, frame_id) = r.header_borrowed()?;
        let child_frame_id = r.str("child_frame_id")?;
        let position = r.f64s::<3>("transform.translation")?;
        let orientation_xyzw = r.f64s::<4>("transform.rotation")?;
        Ok(ReferencePose {
            frame_id,
            child_frame_id,
            stamp_ns,
            position,
            orientation_xyzw,
        })
    }
    let mut r = Ros1 { bytes, at: 0 };
    match kind {
        ReferenceType::PoseStamped => {
            let (stamp_ns, frame_id) = r.header_borrowed()?;
            let position = r.f64s::<3>("pose.position")?;
            let orientation_xyzw = r.f64s::<4>("pose.orientation")?;
            Ok(Poses::One(ReferencePose {
                frame_id,
                child_frame_id: Cow::Borrowed(""),
                stamp_ns,
                position,
                orientation_xyzw,
            }))
        }
        ReferenceType::TransformStamped => Ok(Poses::One(transform(&mut r)?)),
        ReferenceType::TfMessage => {
            let n = r.u32("transforms (length)")?;
            (0..n).map(|_| transform(&mut r)).collect()
        }
        ReferenceType::Pose(kind) => Ok(Poses::One(decode_ros1(kind, bytes)?.into())),
    }
}

/// Decodes a CDR reference message of type `kind` (encapsulation header included).
///
/// ```
/// use posecov::input::log::reference::{ReferenceType, TfMessage, TransformStamped, decode_cdr_reference};
/// let mut tf = TfMessage::default();
/// tf.transforms.push(TransformStamped { child_frame_id: "base".into(), ..Default::default() });
/// let mut bytes = vec![0, 1, 0, 0];
/// bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&tf).unwrap());
/// let poses = decode_cdr_reference(ReferenceType::TfMessage, &bytes).unwrap();
/// assert_eq!(poses[0].child_frame_id, "base");
/// ```
pub fn decode_cdr_reference(kind: ReferenceType, bytes: &[u8]) -> Result<Poses<'_>, DecodeError> {
    match kind {
        ReferenceType::PoseStamped => {
            let m: PoseStampedIn = cdr(bytes, "geometry_msgs/msg/PoseStamped")?;
            Ok(Poses::One(ReferencePose {
                stamp_ns: header_stamp(m.header.stamp),
                frame_id: m.header.frame_id.into(),
                child_frame_id: Cow::Borrowed(""),
                position: m.pose.position,
                orientation_xyzw: m.pose.orientation,
            }))
        }
        ReferenceType::TransformStamped => {
            let m: TransformStampedIn = cdr(bytes, "geometry_msgs/msg/TransformStamped")?;
            Ok(Poses::One(m.into()))
        }
        ReferenceType::TfMessage => {
            let m: TfMessageIn = cdr(bytes, "tf2_msgs/msg/TFMessage")?;
            Ok(m.transforms.0)
        }
        ReferenceType::Pose(kind) => Ok(Poses::One(decode_cdr(kind, bytes)?.into())),
    }
}

/// Decodes a reference message in `codec`.
pub(super) fn decode_reference(
    kind: ReferenceType,
    codec: Codec,
    bytes: &[u8],
) -> Result<Poses<'_>, DecodeError> {
    match codec {
        Codec::Ros1 => decode_ros1_reference(kind, bytes),
        Codec::Cdr => decode_cdr_reference(kind, bytes),
    }
}
