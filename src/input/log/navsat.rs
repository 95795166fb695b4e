//! `sensor_msgs/NavSatFix` (a GNSS fix, issue 32): its decoding from ROS 1 and CDR bytes
//! ([`decode_navsat`]) into a [`SensorMessage`] with its [`Fix`], and what its
//! `position_covariance_type` says of the block before its numbers are checked
//! ([`declared`]).
//!
//! The message (`sensor_msgs/msg/NavSatFix`): `header`, `status` (`int8 status`: −1
//! `STATUS_NO_FIX`, 0 `FIX`, 1 `SBAS_FIX`, 2 `GBAS_FIX`; `uint16 service`), `latitude` and
//! `longitude` (degrees, WGS84), `altitude` (m above the WGS84 ellipsoid),
//! `position_covariance` (row-major 3 × 3, m², "defined relative to a tangential plane through
//! the reported position", East-North-Up) and `position_covariance_type` (0 `UNKNOWN`,
//! 1 `APPROXIMATED`, 2 `DIAGONAL_KNOWN`, 3 `KNOWN`).

use serde::{Deserialize, Serialize};

use super::Codec;
use super::decode::{DecodeError, Header, Ros1, cdr, header_stamp};
use super::health::Issues;
use super::sensor::SensorMessage;
use crate::plan::log::{Issue, MAX_BLOCKS};

/// `STATUS_NO_FIX`: the receiver has no position.
pub const STATUS_NO_FIX: i8 = -1;

/// `position_covariance_type` values.
pub mod covariance_type {
    /// `COVARIANCE_TYPE_UNKNOWN`.
    pub const UNKNOWN: u8 = 0;
    /// `COVARIANCE_TYPE_APPROXIMATED` (e.g. from the dilution of precision).
    pub const APPROXIMATED: u8 = 1;
    /// `COVARIANCE_TYPE_DIAGONAL_KNOWN`: only the variances are the receiver's.
    pub const DIAGONAL_KNOWN: u8 = 2;
    /// `COVARIANCE_TYPE_KNOWN`: the whole matrix is the receiver's.
    pub const KNOWN: u8 = 3;
}

/// What a NavSatFix says besides its covariance's numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fix {
    /// `status.status` (−1 no fix … 2 GBAS fix).
    pub status: i8,
    /// WGS84 latitude, degrees.
    pub latitude_deg: f64,
    /// WGS84 longitude, degrees.
    pub longitude_deg: f64,
    /// Altitude above the WGS84 ellipsoid, m.
    pub altitude_m: f64,
    /// `position_covariance_type` (0–3).
    pub covariance_type: u8,
}

impl Fix {
    /// Whether the fix is a position that can be drawn: not `NO_FIX`, latitude in ±90°,
    /// longitude in ±180°, altitude finite.
    ///
    /// ```
    /// use posecov::input::log::navsat::Fix;
    /// let f = Fix { status: 0, latitude_deg: 48.1, longitude_deg: 11.6, altitude_m: 520.0, covariance_type: 2 };
    /// assert!(f.drawable());
    /// assert!(!Fix { status: -1, ..f }.drawable());
    /// assert!(!Fix { latitude_deg: f64::NAN, ..f }.drawable());
    /// ```
    pub fn drawable(&self) -> bool {
        self.status != STATUS_NO_FIX
            && self.latitude_deg.abs() <= 90.0
            && self.longitude_deg.abs() <= 180.0
            && self.altitude_m.is_finite()
    }
}

/// `sensor_msgs/NavSatStatus` as CDR lays it out.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct NavSatStatus {
    /// −1 no fix, 0 fix, 1 SBAS fix, 2 GBAS fix.
    pub status: i8,
    /// Bit mask of the systems used (GPS 1, GLONASS 2, COMPASS 4, GALILEO 8).
    pub service: u16,
}

/// `sensor_msgs/NavSatFix` as CDR lays it out (field order is the wire order).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct NavSatFix {
    /// Header (`frame_id`: the antenna's frame).
    pub header: Header,
    /// Fix status.
    pub status: NavSatStatus,
    /// Degrees, WGS84.
    pub latitude: f64,
    /// Degrees, WGS84.
    pub longitude: f64,
    /// m above the WGS84 ellipsoid.
    pub altitude: f64,
    /// Row-major 3 × 3, m², East-North-Up.
    pub position_covariance: [f64; 9],
    /// 0 unknown, 1 approximated, 2 diagonal known, 3 known.
    pub position_covariance_type: u8,
}

/// Decodes a `sensor_msgs/NavSatFix` from its bytes in `codec`; a `position_covariance_type`
/// beyond 3 is an error naming it.
///
/// ```
/// use posecov::input::log::navsat::{NavSatFix, decode_navsat};
/// use posecov::input::log::Codec;
/// let mut fix = NavSatFix { latitude: 48.1, longitude: 11.6, position_covariance_type: 2, ..Default::default() };
/// fix.position_covariance[0] = 4.0;
/// let mut bytes = vec![0, 1, 0, 0];
/// bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&fix).unwrap());
/// let m = decode_navsat(Codec::Cdr, &bytes).unwrap();
/// assert_eq!((m.blocks[0][0], m.fix.unwrap().latitude_deg), (4.0, 48.1));
/// fix.position_covariance_type = 9;
/// let mut bad = vec![0, 1, 0, 0];
/// bad.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&fix).unwrap());
/// assert!(decode_navsat(Codec::Cdr, &bad).unwrap_err().0.contains("position_covariance_type 9"));
/// ```
pub fn decode_navsat(codec: Codec, bytes: &[u8]) -> Result<SensorMessage, DecodeError> {
    let (fix, stamp) = match codec {
        Codec::Cdr => {
            let fix = cdr::<NavSatFix>(bytes, "sensor_msgs/msg/NavSatFix")?;
            let stamp = header_stamp(fix.header.stamp);
            (fix, stamp)
        }
        Codec::Ros1 => {
            let mut r = Ros1 { bytes, at: 0 };
            let (stamp, frame_id) = r.header()?;
            let status = r.take(1, "status.status")?[0] as i8;
            let service = r.take(2, "status.service")?;
            let service = u16::from_le_bytes([service[0], service[1]]);
            let [latitude, longitude, altitude] = r.f64s::<3>("latitude, longitude, altitude")?;
            let fix = NavSatFix {
                header: Header {
                    stamp: Default::default(),
                    frame_id,
                },
                status: NavSatStatus { status, service },
                latitude,
                longitude,
                altitude,
                position_covariance: r.f64s::<9>("position_covariance")?,
                position_covariance_type: r.take(1, "position_covariance_type")?[0],
            };
            (fix, stamp)
        }
    };
    if fix.position_covariance_type > covariance_type::KNOWN {
        return Err(DecodeError(format!(
            "position_covariance_type {} is not one of 0 (unknown), 1 (approximated), \
             2 (diagonal known), 3 (known)",
            fix.position_covariance_type
        )));
    }
    let mut blocks = [[0.0; 9]; MAX_BLOCKS];
    blocks[0] = fix.position_covariance;
    Ok(SensorMessage {
        stamp_ns: stamp.unwrap_or(0),
        from_log_time: stamp.is_none(),
        frame_id: fix.header.frame_id,
        orientation_xyzw: [0.0, 0.0, 0.0, 1.0],
        blocks,
        fix: Some(Fix {
            status: fix.status.status,
            latitude_deg: fix.latitude,
            longitude_deg: fix.longitude,
            altitude_m: fix.altitude,
            covariance_type: fix.position_covariance_type,
        }),
    })
}

/// What a message's declared covariance type says of a block before its numbers are
/// checked: the findings it makes, and whether the numbers are checked at all.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Declared {
    /// The findings the declaration makes.
    pub issues: Issues,
    /// `false`: the block is not checked (its numbers mean nothing).
    pub unchecked: bool,
}

/// What `fix`'s `position_covariance_type` says of its `block` (row-major 3 × 3):
/// `UNKNOWN` is the note `covariance_type_unknown` and the block is not checked;
/// `APPROXIMATED` the note `covariance_approximated`; `DIAGONAL_KNOWN` with an off-diagonal
/// entry that is not 0 the defect `diagonal_known_off_diagonal`; `KNOWN` nothing.
///
/// ```
/// use posecov::input::log::navsat::{Fix, declared};
/// use posecov::plan::log::Issue;
/// let fix = |t| Fix { status: 0, latitude_deg: 0.0, longitude_deg: 0.0, altitude_m: 0.0, covariance_type: t };
/// let mut b = [4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 9.0];
/// assert!(declared(&fix(0), &b).unchecked);
/// assert_eq!(declared(&fix(1), &b).issues, vec![Issue::CovarianceApproximated]);
/// assert!(declared(&fix(2), &b).issues.is_empty());
/// b[1] = 0.5;
/// assert_eq!(declared(&fix(2), &b).issues, vec![Issue::DiagonalKnownOffDiagonal]);
/// assert!(declared(&fix(3), &b).issues.is_empty());
/// ```
pub fn declared(fix: &Fix, block: &[f64; 9]) -> Declared {
    let mut d = Declared::default();
    match fix.covariance_type {
        covariance_type::UNKNOWN => {
            d.issues.push(Issue::CovarianceTypeUnknown);
            d.unchecked = true;
        }
        covariance_type::APPROXIMATED => d.issues.push(Issue::CovarianceApproximated),
        covariance_type::DIAGONAL_KNOWN => {
            let off_diagonal = [1, 2, 3, 5, 6, 7].iter().any(|&i| block[i] != 0.0);
            if off_diagonal {
                d.issues.push(Issue::DiagonalKnownOffDiagonal);
            }
        }
        _ => {}
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ROS 1 NavSatFix's bytes.
    fn navsat_ros1(status: i8, cov: [f64; 9], cov_type: u8) -> Vec<u8> {
        let mut b = Vec::new();
        for v in [7u32, 100, 5, 3] {
            b.extend(v.to_le_bytes());
        }
        b.extend(b"gps");
        b.push(status as u8);
        b.extend(1u16.to_le_bytes());
        for v in [48.1, 11.6, 520.0].into_iter().chain(cov) {
            b.extend(f64::to_le_bytes(v));
        }
        b.push(cov_type);
        b
    }

    #[test]
    fn ros1_navsat_decodes_and_every_truncation_is_an_error() {
        let mut cov = [0.0; 9];
        cov[0] = 2.0;
        cov[8] = 5.0;
        let full = navsat_ros1(-1, cov, 2);
        let m = decode_navsat(Codec::Ros1, &full).unwrap();
        assert_eq!((m.stamp_ns, m.frame_id.as_str()), (100_000_000_005, "gps"));
        let fix = m.fix.unwrap();
        assert_eq!((fix.status, fix.covariance_type), (-1, 2));
        assert_eq!((fix.latitude_deg, fix.altitude_m), (48.1, 520.0));
        assert_eq!(m.blocks[0], cov);
        for cut in 0..full.len() {
            assert!(decode_navsat(Codec::Ros1, &full[..cut]).is_err());
            let _ = decode_navsat(Codec::Cdr, &full[..cut]);
        }
        let bad = navsat_ros1(0, cov, 4);
        let e = decode_navsat(Codec::Ros1, &bad).unwrap_err();
        assert!(e.0.contains("position_covariance_type 4"), "{}", e.0);
    }

    #[test]
    fn cdr_and_ros1_give_the_same_message() {
        let mut fix = NavSatFix {
            latitude: -33.9,
            longitude: 151.2,
            altitude: 40.0,
            position_covariance_type: 3,
            ..Default::default()
        };
        fix.header.frame_id = "gps".into();
        fix.header.stamp.sec = 100;
        fix.header.stamp.nanosec = 5;
        fix.status.status = 1;
        fix.position_covariance = [1.0, 0.2, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0, 4.0];
        let mut cdr_bytes = vec![0, 1, 0, 0];
        cdr_bytes.extend(re_cdr::to_vec::<_, re_cdr::LittleEndian>(&fix).unwrap());
        let a = decode_navsat(Codec::Cdr, &cdr_bytes).unwrap();
        let mut ros1 = navsat_ros1(1, fix.position_covariance, 3);
        // The same latitude, longitude and altitude.
        ros1[4 * 4 + 3 + 3..4 * 4 + 3 + 3 + 24].copy_from_slice(
            &[-33.9f64, 151.2, 40.0]
                .iter()
                .flat_map(|v| v.to_le_bytes())
                .collect::<Vec<u8>>(),
        );
        let b = decode_navsat(Codec::Ros1, &ros1).unwrap();
        assert_eq!(a, b);
    }
}
