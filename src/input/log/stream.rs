//! A log's streams (a ROS 1 connection, an MCAP or `.db3` channel, a live stream's channel):
//! what posecov makes of each ([`Stream`]: a pose, a reference, a sensor, or another type) and
//! how its messages' bytes are encoded ([`Codec`]).

use super::decode::{ros1_kind, ros2_kind};
use super::reference::{ReferenceType, ros1_reference_type, ros2_reference_type};
use super::sensor::{ros1_sensor, ros2_sensor};
use crate::plan::log::{PoseMessageKind, SensorKind};

/// A connection (ROS 1) or channel (MCAP): its topic, type and what posecov makes of it
/// (`None`: another type; `Some(Err(why))`: a pose type in another definition or encoding).
pub(super) struct Stream {
    pub(super) topic: String,
    pub(super) type_name: String,
    pub(super) kind: Option<Result<PoseMessageKind, String>>,
    /// What a reference can be read from it (`Err(why)`: a reference type in another
    /// definition or encoding).
    pub(super) reference: Option<Result<ReferenceType, String>>,
    /// What sensor (a covariance-carrying message that is not a pose) it carries
    /// (`Err(why)`: a sensor type in another definition or encoding).
    pub(super) sensor: Option<Result<SensorKind, String>>,
}

/// How a message's bytes are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Codec {
    /// ROS 1 serialization (little endian, packed).
    Ros1,
    /// ROS 2 CDR, its 4-byte encapsulation header first.
    Cdr,
}

impl Stream {
    /// A channel of schema name `schema` in `encoding` (an MCAP channel, a live stream's
    /// channel): `cdr` reads the ROS 2 name, `ros1` the ROS 1 name with its definition taken
    /// by name (`mcap convert` of a ROS 1 bag writes no MD5 sum); a pose or reference type in
    /// any other encoding is named with `other`'s words, and read as nothing.
    pub(super) fn of_channel(
        topic: String,
        schema: String,
        encoding: &str,
        other: impl Fn() -> String,
    ) -> (Stream, Codec) {
        let (kind, reference, sensor, codec) = match encoding {
            "cdr" => (
                ros2_kind(&schema).map(Ok),
                ros2_reference_type(&schema).map(Ok),
                ros2_sensor(&schema).map(Ok),
                Codec::Cdr,
            ),
            "ros1" => (
                ros1_kind(&schema, "*"),
                ros1_reference_type(&schema, "*"),
                ros1_sensor(&schema, "*"),
                Codec::Ros1,
            ),
            _ => (
                ros2_kind(&schema).map(|_| Err(other())),
                ros2_reference_type(&schema).map(|_| Err(other())),
                ros2_sensor(&schema).map(|_| Err(other())),
                Codec::Cdr,
            ),
        };
        let type_name = if schema.is_empty() {
            format!("(no schema, {encoding} encoding)")
        } else {
            schema
        };
        let stream = Stream {
            topic,
            type_name,
            kind,
            reference,
            sensor,
        };
        (stream, codec)
    }
}
