//! The three pose messages read from CDR by hand (issue 32's `.db3` speed): a [`Cdr`] reader
//! walks the message field by field — the 4-byte encapsulation header, then each primitive
//! aligned to its size from the body's start (at most 8), strings as a `u32` length (the NUL
//! counted) and their bytes — as `re_cdr`'s serde deserializer does for the types of
//! `decode.rs`, with the same results (`decode.rs`'s tests compare both on every truncation),
//! without serde's per-field calls or an owned copy of each string before its use.

use super::decode::{DecodeError, Time, header_stamp};
use crate::plan::log::{COV_LEN, PoseMessageKind};

/// The 4-byte CDR encapsulation header: representation id 0x0000 / 0x0002 (big endian) or
/// 0x0001 / 0x0003 (little endian).
const CDR_HEADER: usize = 4;

/// A CDR message being read (its body, after the encapsulation header).
pub(super) struct Cdr<'a> {
    body: &'a [u8],
    at: usize,
    little: bool,
}

impl<'a> Cdr<'a> {
    /// The reader of `bytes`, its encapsulation header checked.
    pub(super) fn new(bytes: &'a [u8]) -> Result<Self, DecodeError> {
        let Some(body) = bytes.get(CDR_HEADER..) else {
            return Err(DecodeError(format!(
                "truncated: {} bytes, no CDR encapsulation header",
                bytes.len()
            )));
        };
        let little = match bytes[1] {
            0x01 | 0x03 => true,
            0x00 | 0x02 if bytes[0] == 0 => false,
            _ => {
                return Err(DecodeError(format!(
                    "unknown CDR encapsulation {:02x} {:02x}",
                    bytes[0], bytes[1]
                )));
            }
        };
        Ok(Cdr {
            body,
            at: 0,
            little,
        })
    }

    /// `n` bytes aligned to `align` (padding skipped first).
    fn take(&mut self, align: usize, n: usize, what: &str) -> Result<&'a [u8], DecodeError> {
        let start = self.at.next_multiple_of(align);
        let end = start.checked_add(n).filter(|e| *e <= self.body.len());
        let Some(end) = end else {
            return Err(DecodeError(format!(
                "truncated: {what} needs {n} bytes at offset {start} of the CDR body, it has {}",
                self.body.len()
            )));
        };
        self.at = end;
        Ok(&self.body[start..end])
    }

    fn u32(&mut self, what: &str) -> Result<u32, DecodeError> {
        let b: [u8; 4] = self.take(4, 4, what)?.try_into().unwrap_or_default();
        Ok(if self.little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    }

    /// `N` doubles, aligned to 8.
    pub(super) fn f64s<const N: usize>(&mut self, what: &str) -> Result<[f64; N], DecodeError> {
        let b = self.take(8, 8 * N, what)?;
        let little = self.little;
        Ok(std::array::from_fn(|i| {
            let w: [u8; 8] = b[8 * i..8 * i + 8].try_into().unwrap_or_default();
            if little {
                f64::from_le_bytes(w)
            } else {
                f64::from_be_bytes(w)
            }
        }))
    }

    /// A string: its length (NUL included), its bytes, the NUL dropped; UTF-8 or an error.
    pub(super) fn string(&mut self, what: &str) -> Result<String, DecodeError> {
        let n = self.u32(what)? as usize;
        let bytes = self.take(1, n, what)?;
        let bytes = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        std::str::from_utf8(bytes)
            .map(str::to_owned)
            .map_err(|e| DecodeError(format!("{what}: {e}")))
    }

    /// `std_msgs/Header` (ROS 2): stamp (sec, nanosec), frame_id; the stamp `None` when zero.
    pub(super) fn header(&mut self) -> Result<(Option<i64>, String), DecodeError> {
        let sec = self.u32("header.stamp.sec")? as i32;
        let nanosec = self.u32("header.stamp.nanosec")?;
        let frame = self.string("header.frame_id")?;
        Ok((header_stamp(Time { sec, nanosec }), frame))
    }
}

/// A pose message's fields as read: stamp, frame, child frame, position, orientation
/// (x, y, z, w), covariance, and an Odometry's twist covariance.
pub(super) type PoseFields = (
    Option<i64>,
    String,
    String,
    [f64; 3],
    [f64; 4],
    [f64; COV_LEN],
    Option<[f64; COV_LEN]>,
);

/// Reads a pose message of `kind` (not a text line's) from CDR `bytes`.
pub(super) fn read_pose(kind: PoseMessageKind, bytes: &[u8]) -> Result<PoseFields, DecodeError> {
    let mut r = Cdr::new(bytes)?;
    let (stamp, frame_id) = match kind {
        PoseMessageKind::PoseWithCovariance | PoseMessageKind::OvEval => (None, String::new()),
        _ => r.header()?,
    };
    let child_frame_id = match kind {
        PoseMessageKind::Odometry => r.string("child_frame_id")?,
        _ => String::new(),
    };
    let position = r.f64s::<3>("pose.position")?;
    let orientation = r.f64s::<4>("pose.orientation")?;
    let covariance = r.f64s::<COV_LEN>("pose.covariance")?;
    let twist = match kind {
        PoseMessageKind::Odometry => {
            let _twist = r.f64s::<6>("twist.twist")?;
            Some(r.f64s::<COV_LEN>("twist.covariance")?)
        }
        _ => None,
    };
    Ok((
        stamp,
        frame_id,
        child_frame_id,
        position,
        orientation,
        covariance,
        twist,
    ))
}
