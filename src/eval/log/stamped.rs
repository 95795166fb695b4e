//! Poses at stamps, looked up between them: a reference trajectory (NEES) or one `/tf` edge
//! (frames joined by the log's transforms) — the one home of "the pose at a stamp".
//!
//! The pose at a stamp t between two samples (t_a, X_a), (t_b, X_b) is interpolated on the
//! group: X_a · Exp(s · Log(X_a⁻¹ X_b)), s = (t − t_a) / (t_b − t_a). A stamp before the first
//! sample or after the last is never extrapolated: [`Lookup::Before`] / [`Lookup::After`].
//!
//! ```
//! use posecov::eval::log::stamped::{Lookup, StampedPoses};
//! use posecov::lie::Se3;
//! let mut tf = StampedPoses::default();
//! tf.insert(100, Se3::from_xyz_rpy([0.0; 3], [0.0; 3]));
//! tf.insert(300, Se3::from_xyz_rpy([2.0, 0.0, 0.0], [0.0, 0.0, 0.0]));
//! let Lookup::At(x) = tf.at(200) else { panic!() };
//! assert!((x.translation().x - 1.0).abs() < 1e-15);
//! assert!(matches!(tf.at(99), Lookup::Before) && matches!(tf.at(301), Lookup::After));
//! ```

use crate::lie::{LieGroup, Se3, So3};
use crate::plan::log::{ReferenceSample, StampRange};

/// The pose of a sample (parent_from_child), if its position is finite and its quaternion a
/// rotation ([`So3::try_from_quaternion_xyzw`]).
///
/// ```
/// use posecov::eval::log::stamped::pose_of_sample;
/// use posecov::plan::log::ReferenceSample;
/// let s = ReferenceSample { stamp_ns: 0, position: [1.0, 2.0, 3.0], orientation_xyzw: [0.0, 0.0, 0.0, 1.0] };
/// assert_eq!(pose_of_sample(&s).unwrap().translation().y, 2.0);
/// assert!(pose_of_sample(&ReferenceSample { orientation_xyzw: [0.0; 4], ..s }).is_none());
/// ```
pub fn pose_of_sample(sample: &ReferenceSample) -> Option<Se3> {
    let rotation = So3::try_from_quaternion_xyzw(sample.orientation_xyzw).ok()?;
    sample
        .position
        .iter()
        .all(|v| v.is_finite())
        .then(|| Se3::from_parts(sample.position.into(), rotation))
}

/// A pose looked up at a stamp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lookup {
    /// Interpolated between the samples that bracket the stamp (or a sample's own).
    At(Se3),
    /// Before the first sample (or no sample at all).
    Before,
    /// After the last sample.
    After,
}

/// Poses at stamps (ns), kept in stamp order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StampedPoses {
    samples: Vec<(i64, Se3)>,
}

impl StampedPoses {
    /// Adds a sample; a sample at a stamp already held replaces it (the later one counts).
    ///
    /// ```
    /// use posecov::eval::log::stamped::StampedPoses;
    /// use posecov::lie::{LieGroup, Se3};
    /// let mut p = StampedPoses::default();
    /// p.insert(20, Se3::identity());
    /// p.insert(10, Se3::identity());
    /// p.insert(20, Se3::identity());
    /// assert_eq!((p.len(), p.span().map(|r| (r.first_ns, r.last_ns))), (2, Some((10, 20))));
    /// ```
    pub fn insert(&mut self, stamp_ns: i64, pose: Se3) {
        match self.samples.last() {
            Some((last, _)) if *last < stamp_ns => self.samples.push((stamp_ns, pose)),
            None => self.samples.push((stamp_ns, pose)),
            Some(_) => {
                let i = self.samples.partition_point(|(s, _)| *s < stamp_ns);
                if self.samples.get(i).is_some_and(|(s, _)| *s == stamp_ns) {
                    self.samples[i] = (stamp_ns, pose);
                } else {
                    self.samples.insert(i, (stamp_ns, pose));
                }
            }
        }
    }

    /// Samples held.
    ///
    /// See [`insert`](Self::insert) and the [module docs](self) for examples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// No sample.
    ///
    /// See [`insert`](Self::insert) and the [module docs](self) for examples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The first and last stamps, if any sample.
    ///
    /// See [`insert`](Self::insert) and the [module docs](self) for examples.
    pub fn span(&self) -> Option<StampRange> {
        Some(StampRange {
            first_ns: self.samples.first()?.0,
            last_ns: self.samples.last()?.0,
        })
    }

    /// The latest sample's pose (a static transform's value).
    ///
    /// See [`insert`](Self::insert) and the [module docs](self) for examples.
    pub fn latest(&self) -> Option<Se3> {
        self.samples.last().map(|(_, x)| *x)
    }

    /// The pose at `stamp_ns`: interpolated on SE(3) between the bracketing samples, never
    /// extrapolated.
    ///
    /// See the [module docs](self) for an example.
    pub fn at(&self, stamp_ns: i64) -> Lookup {
        let (Some(first), Some(last)) = (self.samples.first(), self.samples.last()) else {
            return Lookup::Before;
        };
        if stamp_ns < first.0 {
            return Lookup::Before;
        }
        if stamp_ns > last.0 {
            return Lookup::After;
        }
        let i = self.first_at_or_after(stamp_ns);
        let (tb, xb) = self.samples[i];
        if tb == stamp_ns || i == 0 {
            return Lookup::At(xb);
        }
        let (ta, xa) = self.samples[i - 1];
        let s = (stamp_ns - ta) as f64 / (tb - ta) as f64;
        Lookup::At(xa.interpolate(&xb, s))
    }

    /// The first sample at or after `stamp_ns` (≤ the last stamp): searched back from the
    /// newest sample, doubling the step, then by halves — a streamed log looks up stamps near
    /// its newest reference sample, where a search from the middle of an hour's 360 000
    /// samples missed the cache at every step.
    fn first_at_or_after(&self, stamp_ns: i64) -> usize {
        let mut hi = self.samples.len();
        let mut step = 1;
        let lo = loop {
            let lo = hi.saturating_sub(step);
            if lo == 0 || self.samples[lo].0 < stamp_ns {
                break lo;
            }
            hi = lo + 1;
            step *= 2;
        };
        lo + self.samples[lo..hi].partition_point(|(t, _)| *t < stamp_ns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_on_the_group_and_out_of_order_samples_are_sorted() {
        let a = Se3::from_xyz_rpy([0.0; 3], [0.0, 0.0, 0.0]);
        let b = Se3::from_xyz_rpy([1.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        let mut p = StampedPoses::default();
        p.insert(20, b);
        p.insert(10, a);
        p.insert(20, b);
        assert_eq!(
            (p.len(), p.span().map(|r| (r.first_ns, r.last_ns))),
            (2, Some((10, 20)))
        );
        let Lookup::At(mid) = p.at(15) else { panic!() };
        assert!(mid.rminus(&a.interpolate(&b, 0.5)).norm() < 1e-15);
        assert!((mid.rotation().to_rpy()[2] - 0.5).abs() < 1e-12);
        assert_eq!(p.at(10), Lookup::At(a));
        assert_eq!(StampedPoses::default().at(0), Lookup::Before);
    }

    #[test]
    fn the_search_from_the_newest_sample_finds_what_a_search_from_the_middle_finds() {
        let mut p = StampedPoses::default();
        for k in 0..1000 {
            p.insert(k * 10, Se3::identity());
        }
        for stamp in -5..10_000 {
            let expected = p.samples.partition_point(|(t, _)| *t < stamp);
            if expected < p.len() {
                assert_eq!(p.first_at_or_after(stamp), expected, "{stamp}");
            }
        }
    }
}
