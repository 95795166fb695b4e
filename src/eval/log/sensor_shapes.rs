//! The numbers behind what is drawn of a sensor topic: a NavSatFix's fixes in the local
//! East-North-Up tangent plane at its first drawn fix ([`local_fixes`]), and an IMU's
//! orientation uncertainty as seeded SO(3) samples around its mean ([`orientation_spray`]).
//!
//! **The projection.** Each fix (φ, λ, h: WGS84 latitude, longitude, ellipsoidal height) is put
//! in the tangent plane at the first drawn fix (φ₀, λ₀, h₀) by the local (equirectangular)
//! approximation with WGS84's radii of curvature at φ₀ — the meridian radius
//! M = a(1 − e²)/(1 − e² sin²φ₀)^{3/2} and the prime-vertical radius N = a/√(1 − e² sin²φ₀),
//! a = 6 378 137 m, f = 1/298.257223563, e² = f(2 − f):
//! east = (N + h₀) cos φ₀ Δλ, north = (M + h₀) Δφ, up = h − h₀ (Δλ wrapped into ±180°).
//! Its error against the exact tangent plane grows as the square of the distance (about
//! 1 m at 10 km): meant for a robot's run, not a continent. A fix's covariance is already in
//! its own East-North-Up axes (the message's definition), which over such a run are the
//! origin's to well under a milliradian; it is drawn as is.
//!
//! **The spray.** `sensor_msgs/Imu`'s `orientation_covariance` is over rotations about the
//! parent frame's fixed x, y, z axes (REP 145 and the message: "fixed axis"; tf2's reading
//! of a ROS rotation block, [CONVENTIONS §6 and §13](crate::conventions)): R̃ = Exp(δφ) · R̂, δφ ~
//! N(0, Σ) — the left side. `--ros-reading body` reads it on the right, R̃ = R̂ · Exp(δθ).
//!
//! ```
//! use posecov::eval::log::sensor_shapes::local_fixes;
//! use posecov::plan::log::FixPoint;
//! let fix = |lat: f64, lon: f64| FixPoint { index: 0, stamp_ns: 0, latitude_deg: lat, longitude_deg: lon,
//!     altitude_m: 0.0, covariance_enu: None };
//! let l = local_fixes(&[fix(0.0, 0.0), fix(0.0, 0.001), fix(0.001, 0.0)]).unwrap();
//! // A thousandth of a degree at the equator: 111.3 m east, 110.6 m north.
//! assert!((l.fixes[1].east_north_up[0] - 111.319).abs() < 1e-3);
//! assert!((l.fixes[2].east_north_up[1] - 110.574).abs() < 1e-3);
//! ```

use nalgebra::Matrix3;

use crate::interop::RosReading;
use crate::lie::{LieGroup, So3};
use crate::plan::log::{FixPoint, OrientationPoint};
use crate::sample::{Sampler, chunk_rng};
use crate::uncertain::{Side, UncertainPose};

/// WGS84's semi-major axis, m.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84's flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// One fix in the local tangent plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFix {
    /// The message's number on its topic.
    pub index: u64,
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// East, north, up of the origin, m.
    pub east_north_up: [f64; 3],
    /// The horizontal block of its covariance (east, north), m², row-major; `None` when the
    /// block is unusable or not checked.
    pub covariance_en: Option<[f64; 4]>,
}

/// A NavSatFix topic's fixes in the tangent plane at its first drawn fix (see the module
/// docs for the projection).
#[derive(Debug, Clone, PartialEq)]
pub struct LocalFixes {
    /// The origin: the first drawn fix's latitude, longitude (degrees) and height (m).
    pub origin: [f64; 3],
    /// The meridian and prime-vertical radii of curvature at the origin, m.
    pub radii: [f64; 2],
    /// Every drawn fix, in message order.
    pub fixes: Vec<LocalFix>,
}

/// The fixes in the tangent plane at the first (see the module docs); `None` without fixes.
///
/// See the [module docs](self) for an example.
pub fn local_fixes(fixes: &[FixPoint]) -> Option<LocalFixes> {
    let first = fixes.first()?;
    let phi0 = first.latitude_deg.to_radians();
    let e2 = WGS84_F * (2.0 - WGS84_F);
    let w = 1.0 - e2 * phi0.sin().powi(2);
    let prime_vertical = WGS84_A / w.sqrt();
    let meridian = WGS84_A * (1.0 - e2) / w.powf(1.5);
    let h0 = first.altitude_m;
    let local = fixes
        .iter()
        .map(|f| {
            let mut dlon = f.longitude_deg - first.longitude_deg;
            if dlon > 180.0 {
                dlon -= 360.0;
            } else if dlon < -180.0 {
                dlon += 360.0;
            }
            let east = (prime_vertical + h0) * phi0.cos() * dlon.to_radians();
            let north = (meridian + h0) * (f.latitude_deg - first.latitude_deg).to_radians();
            LocalFix {
                index: f.index,
                stamp_ns: f.stamp_ns,
                east_north_up: [east, north, f.altitude_m - h0],
                covariance_en: f.covariance_enu.map(|c| [c[0], c[1], c[3], c[4]]),
            }
        })
        .collect();
    Some(LocalFixes {
        origin: [first.latitude_deg, first.longitude_deg, h0],
        radii: [meridian, prime_vertical],
        fixes: local,
    })
}

/// An IMU's orientation at one message and seeded samples of it.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationSpray {
    /// The message's number on its topic.
    pub index: u64,
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// Its orientation, parent_from_imu.
    pub mean: So3,
    /// The side the covariance is read on ([`Side::Left`]: fixed parent axes, tf2's reading).
    pub side: Side,
    /// σ about x, y, z, rad (`None`: not estimated, not sprayed).
    pub sigma: [Option<f64>; 3],
    /// The samples, parent_from_imu each.
    pub samples: Vec<Matrix3<f64>>,
}

/// `n` samples of `o`'s orientation, read as `reading` says (see the module docs), drawn from
/// stream (`seed`, `family`, `o.index`); `None` when the covariance cannot be sampled.
///
/// ```
/// use posecov::eval::log::sensor_shapes::orientation_spray;
/// use posecov::interop::RosReading;
/// use posecov::plan::log::OrientationPoint;
/// use posecov::uncertain::Side;
/// let o = OrientationPoint { index: 3, stamp_ns: 0, orientation_xyzw: [0.0, 0.0, 0.0, 1.0],
///     covariance: [0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.0], unestimated: [false, false, true] };
/// let s = orientation_spray(&o, RosReading::Tf2, 7, 1, 50).unwrap();
/// assert_eq!((s.samples.len(), s.side, s.sigma[2]), (50, Side::Left, None));
/// assert_eq!(s, orientation_spray(&o, RosReading::Tf2, 7, 1, 50).unwrap());
/// // σ 0.1 rad about x and y only: every sample's z axis stays within a few σ of vertical.
/// assert!(s.samples.iter().all(|r| r[(2, 2)] > 0.8));
/// ```
pub fn orientation_spray(
    o: &OrientationPoint,
    reading: RosReading,
    seed: u64,
    family: u64,
    n: usize,
) -> Option<OrientationSpray> {
    let mean = So3::try_from_quaternion_xyzw(o.orientation_xyzw).ok()?;
    let side = match reading {
        RosReading::Tf2 => Side::Left,
        RosReading::Body => Side::Right,
    };
    let cov = Matrix3::from_row_slice(&o.covariance);
    let sampler = Sampler::new(&UncertainPose::try_new(mean, cov, side).ok()?).ok()?;
    let mut rng = chunk_rng(seed, family, o.index);
    let samples = sampler
        .draw_many(&mut rng, n)
        .iter()
        .map(LieGroup::to_matrix)
        .collect();
    Some(OrientationSpray {
        index: o.index,
        stamp_ns: o.stamp_ns,
        mean,
        side,
        sigma: std::array::from_fn(|i| (!o.unestimated[i]).then(|| o.covariance[i * 4].sqrt())),
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_projection_keeps_distances_near_the_origin() {
        let fix = |lat: f64, lon: f64, h: f64| FixPoint {
            index: 0,
            stamp_ns: 0,
            latitude_deg: lat,
            longitude_deg: lon,
            altitude_m: h,
            covariance_enu: Some([4.0, 1.0, 0.0, 1.0, 9.0, 0.0, 0.0, 0.0, 16.0]),
        };
        // Munich: 1e-4° of longitude is 7.44 m east ((N + h) cos φ); 1e-4° of latitude 11.12 m.
        let l = local_fixes(&[
            fix(48.137, 11.575, 520.0),
            fix(48.137, 11.5751, 521.0),
            fix(48.1371, 11.575, 520.0),
        ])
        .unwrap();
        assert_eq!(l.fixes[0].east_north_up, [0.0, 0.0, 0.0]);
        let e = l.fixes[1].east_north_up;
        assert!(
            (e[0] - 7.4434).abs() < 1e-3 && e[1] == 0.0 && e[2] == 1.0,
            "{e:?}"
        );
        let n = l.fixes[2].east_north_up;
        assert!(n[0] == 0.0 && (n[1] - 11.1202).abs() < 1e-3, "{n:?}");
        assert_eq!(l.fixes[0].covariance_en, Some([4.0, 1.0, 1.0, 9.0]));
        // Across the antimeridian: a small step east, not 360° west.
        let w = local_fixes(&[fix(0.0, 179.9999, 0.0), fix(0.0, -179.9999, 0.0)]).unwrap();
        assert!((w.fixes[1].east_north_up[0] - 22.264).abs() < 1e-2);
    }

    #[test]
    fn the_spray_follows_the_reading_side() {
        // A yaw of 90° and σ only about x: on the left (tf2) the samples turn about the
        // parent's x axis, which is the IMU's −y; on the right about the IMU's own x.
        let half = 0.25 * std::f64::consts::PI;
        let q = [0.0, 0.0, half.sin(), half.cos()];
        let o = OrientationPoint {
            index: 0,
            stamp_ns: 0,
            orientation_xyzw: q,
            covariance: [0.04, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            unestimated: [false, true, true],
        };
        let left = orientation_spray(&o, RosReading::Tf2, 0, 0, 200).unwrap();
        let right = orientation_spray(&o, RosReading::Body, 0, 0, 200).unwrap();
        let mean = left.mean.to_matrix();
        // Left: Exp(δφ x̂) R leaves the IMU's y axis (R ŷ = −x̂ in the parent) where it is.
        for r in &left.samples {
            assert!((r.column(1) - mean.column(1)).norm() < 1e-12);
        }
        // Right: R Exp(δθ x̂) keeps the IMU's own x axis.
        for r in &right.samples {
            assert!((r.column(0) - mean.column(0)).norm() < 1e-12);
        }
        assert_eq!(left.sigma, [Some(0.2), None, None]);
    }
}
