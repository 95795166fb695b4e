//! The Foxglove WebSocket protocol's messages as posecov reads and sends them (the server's
//! `serverInfo`, `status`, `advertise` and `unadvertise` in JSON text frames, its
//! message-data binary frames; the client's `subscribe` and `unsubscribe`). Every other
//! operation (parameters, services, assets, time) is read and ignored, as the protocol allows.
//!
//! Source: the protocol's specification, `docs/spec.md` of `foxglove/ws-protocol`, which both
//! subprotocols (`foxglove.sdk.v1`, `foxglove.websocket.v1`) follow for these operations.

use serde::Deserialize;

/// The subprotocols posecov offers, in order of preference: the Foxglove SDK's (and current
/// foxglove_bridge's) and the older one that ROS 1 bridges speak.
pub const SUBPROTOCOLS: [&str; 2] = ["foxglove.sdk.v1", "foxglove.websocket.v1"];

/// The binary opcode of a message-data frame (server to client).
pub const MESSAGE_DATA: u8 = 0x01;

/// One channel the server advertises: a topic, its message encoding and schema.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Channel {
    /// The server's id of the channel (subscriptions name it).
    pub id: u64,
    /// The topic, e.g. `/odometry/filtered`.
    pub topic: String,
    /// The message encoding: `cdr` (ROS 2), `ros1`, or another posecov does not read.
    pub encoding: String,
    /// The schema name, e.g. `nav_msgs/msg/Odometry` (ROS 2) or `nav_msgs/Odometry` (ROS 1).
    pub schema_name: String,
    /// The schema's encoding (`ros2msg`, `ros1msg`, …), when the server says it.
    #[serde(default)]
    pub schema_encoding: Option<String>,
    /// The schema's text (a message definition), kept for a recording.
    #[serde(default)]
    pub schema: String,
}

/// A JSON message from the server, as far as posecov reads it.
#[derive(Debug, Clone, PartialEq)]
pub enum ServerMessage {
    /// `serverInfo`: the server's name and capabilities.
    ServerInfo {
        /// The server's name.
        name: String,
    },
    /// `status`: a line from the server (level 0 info, 1 warning, 2 error).
    Status {
        /// 0, 1 or 2.
        level: u8,
        /// What it says.
        message: String,
    },
    /// `advertise`: channels now available.
    Advertise(Vec<Channel>),
    /// `unadvertise`: channels gone.
    Unadvertise(Vec<u64>),
    /// Any other operation (parameters, services, connection graph, …): ignored.
    Other(String),
}

/// Parses one text frame from the server. Errors say what is wrong in the JSON, in words.
///
/// ```
/// use posecov::input::log::ws::protocol::{ServerMessage, parse_text};
/// let m = parse_text(r#"{"op":"advertise","channels":[{"id":3,"topic":"/odom","encoding":"cdr",
///     "schemaName":"nav_msgs/msg/Odometry","schema":"","schemaEncoding":"ros2msg"}]}"#).unwrap();
/// let ServerMessage::Advertise(channels) = m else { panic!() };
/// assert_eq!((channels[0].id, channels[0].topic.as_str()), (3, "/odom"));
/// assert!(parse_text("{").unwrap_err().starts_with("malformed JSON"));
/// assert_eq!(parse_text(r#"{"op":"time"}"#).unwrap(), ServerMessage::Other("time".into()));
/// ```
pub fn parse_text(text: &str) -> Result<ServerMessage, String> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("malformed JSON ({e})"))?;
    let op = value
        .get("op")
        .and_then(serde_json::Value::as_str)
        .ok_or_else(|| "a JSON message without an \"op\" string".to_owned())?;
    let field = |name: &str| {
        value
            .get(name)
            .ok_or_else(|| format!("`{op}` without its \"{name}\" field"))
    };
    Ok(match op {
        "serverInfo" => ServerMessage::ServerInfo {
            name: value
                .get("name")
                .and_then(serde_json::Value::as_str)
                .unwrap_or_default()
                .to_owned(),
        },
        "status" => ServerMessage::Status {
            level: value
                .get("level")
                .and_then(serde_json::Value::as_u64)
                .map_or(0, |l| l.min(2) as u8),
            message: value
                .get("message")
                .and_then(serde_json::Value::as_str)
                .unwrap_or_default()
                .to_owned(),
        },
        "advertise" => ServerMessage::Advertise(
            Vec::<Channel>::deserialize(field("channels")?)
                .map_err(|e| format!("`advertise` with a malformed channel ({e})"))?,
        ),
        "unadvertise" => ServerMessage::Unadvertise(
            Vec::<u64>::deserialize(field("channelIds")?)
                .map_err(|e| format!("`unadvertise` with malformed channel ids ({e})"))?,
        ),
        other => ServerMessage::Other(other.to_owned()),
    })
}

/// A message-data frame: the subscription it is for, the server's timestamp (ns) and the
/// message bytes as a bag stores them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MessageData<'a> {
    /// The client's subscription id.
    pub subscription: u32,
    /// The message's log time (ns since the epoch) as the server gives it.
    pub log_time_ns: u64,
    /// The serialised message.
    pub payload: &'a [u8],
}

/// Parses one binary frame: `Ok(None)` for an opcode posecov does not read (time, service
/// responses, assets); an error for a message-data frame shorter than its 13-byte header.
/// Layout (little endian): opcode `u8`, subscription id `u32`, timestamp `u64`, payload.
///
/// ```
/// use posecov::input::log::ws::protocol::parse_binary;
/// let mut frame = vec![1u8];
/// frame.extend(7u32.to_le_bytes());
/// frame.extend(5u64.to_le_bytes());
/// frame.extend([9, 9]);
/// let m = parse_binary(&frame).unwrap().unwrap();
/// assert_eq!((m.subscription, m.log_time_ns, m.payload), (7, 5, &[9u8, 9][..]));
/// assert!(parse_binary(&frame[..6]).unwrap_err().contains("truncated"));
/// assert_eq!(parse_binary(&[2, 0]).unwrap(), None);
/// ```
pub fn parse_binary(frame: &[u8]) -> Result<Option<MessageData<'_>>, String> {
    match frame.first() {
        None => Err("an empty binary frame".to_owned()),
        Some(&MESSAGE_DATA) => {
            if frame.len() < 13 {
                return Err(format!(
                    "a truncated message-data frame ({} bytes, its header alone is 13)",
                    frame.len()
                ));
            }
            let mut id = [0u8; 4];
            id.copy_from_slice(&frame[1..5]);
            let mut time = [0u8; 8];
            time.copy_from_slice(&frame[5..13]);
            Ok(Some(MessageData {
                subscription: u32::from_le_bytes(id),
                log_time_ns: u64::from_le_bytes(time),
                payload: &frame[13..],
            }))
        }
        Some(_) => Ok(None),
    }
}

/// The client's `subscribe` of channels, each `(subscription id, channel id)`.
///
/// ```
/// let s = posecov::input::log::ws::protocol::subscribe(&[(1, 42)]);
/// assert_eq!(s, r#"{"op":"subscribe","subscriptions":[{"channelId":42,"id":1}]}"#);
/// ```
pub fn subscribe(pairs: &[(u32, u64)]) -> String {
    let subscriptions: Vec<serde_json::Value> = pairs
        .iter()
        .map(|(id, channel)| serde_json::json!({"id": id, "channelId": channel}))
        .collect();
    serde_json::json!({"op": "subscribe", "subscriptions": subscriptions}).to_string()
}

/// The client's `unsubscribe` of subscription ids.
///
/// ```
/// let s = posecov::input::log::ws::protocol::unsubscribe(&[1, 2]);
/// assert_eq!(s, r#"{"op":"unsubscribe","subscriptionIds":[1,2]}"#);
/// ```
pub fn unsubscribe(ids: &[u32]) -> String {
    serde_json::json!({"op": "unsubscribe", "subscriptionIds": ids}).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damaged_messages_are_errors_in_words() {
        for (text, start) in [
            (r#"{"op":1}"#, "a JSON message without"),
            (r#"{"op":"advertise"}"#, "`advertise` without"),
            (
                r#"{"op":"advertise","channels":[{"id":-1}]}"#,
                "`advertise` with a malformed",
            ),
            (
                r#"{"op":"unadvertise","channelIds":["x"]}"#,
                "`unadvertise` with malformed",
            ),
            ("[]", "a JSON message without"),
        ] {
            let e = parse_text(text).unwrap_err();
            assert!(e.starts_with(start), "{text}: {e}");
        }
        assert_eq!(
            parse_text(r#"{"op":"status","level":7,"message":"m"}"#).unwrap(),
            ServerMessage::Status {
                level: 2,
                message: "m".into()
            }
        );
        assert!(parse_binary(&[]).is_err());
    }
}
