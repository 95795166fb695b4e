//! Covariance health of one message, and the per-topic state that finds drops, unbounded
//! growth and a covariance that stays constant while the pose moves. Names, classes and
//! thresholds are the user guide's (docs/guide/logs.md, "Covariance health").

use crate::plan::log::{AxisStats, COV_LEN, Health, Issue, IssueCount, PoseMessage, Stretch};

mod block;
mod classify;
mod issues;
pub use block::{BlockHealth, classify_block};
pub use classify::{MessageHealth, classify};
use classify::{classify_covariance, with_orientation};
pub use issues::Issues;

pub use crate::plan::log::PLACEHOLDER;
/// A drop: the position trace divided by at least this from one usable message to the next.
pub const DROP_FACTOR: f64 = 5.0;
/// Growth: the position trace at least this many times its value after the last drop.
pub const GROWTH_FACTOR: f64 = 100.0;
/// A `constant` finding needs a stretch over at least this distance (m) …
pub const CONSTANT_MIN_DISTANCE_M: f64 = 1.0;
/// … and at least this many messages.
pub const CONSTANT_MIN_MESSAGES: u64 = 10;

/// The running state of a topic's position trace: finds sudden drops and unbounded growth.
#[derive(Debug, Clone, Copy, Default)]
pub struct Trend {
    previous: Option<f64>,
    /// The smallest trace since the last drop (growth is measured from it).
    floor: Option<f64>,
}

impl Trend {
    /// The trend issues of the next usable message with position trace `trace` (> 0).
    ///
    /// ```
    /// use posecov::input::log::health::Trend;
    /// use posecov::plan::log::Issue;
    /// let mut t = Trend::default();
    /// assert!(t.next(1.0).is_empty());
    /// assert_eq!(t.next(0.1), vec![Issue::Drop]);
    /// assert!(t.next(5.0).is_empty());
    /// assert_eq!(t.next(10.0), vec![Issue::Growth]);
    /// ```
    pub fn next(&mut self, trace: f64) -> Issues {
        let mut out = Issues::default();
        if trace <= 0.0 {
            return out;
        }
        if let Some(prev) = self.previous
            && trace * DROP_FACTOR <= prev
        {
            out.push(Issue::Drop);
            self.floor = None;
        }
        let floor = self.floor.map_or(trace, |f| f.min(trace));
        if trace >= GROWTH_FACTOR * floor {
            out.push(Issue::Growth);
        }
        self.floor = Some(floor);
        self.previous = Some(trace);
        out
    }
}

/// The running search for a topic's longest stretch of usable messages whose covariance
/// stays identical — or, on a dead-reckoned topic, does not grow (the trace of the estimated
/// block) — while the pose moves.
#[derive(Debug, Clone, Default)]
pub struct Constancy {
    /// The previous usable message's trace and position (its covariance is kept by the caller,
    /// who says whether the next one is the same: [`TopicHealth`] keeps one copy for this
    /// and its repeat cache).
    previous: Option<(f64, [f64; 3])>,
    current: Option<Stretch>,
    longest: Option<Stretch>,
}

impl Constancy {
    /// The next usable message (number `index` on the topic) with covariance `cov` at
    /// `position`; `same`: `cov` has the same entries (`==`) as the previous usable message's;
    /// `dead_reckoned`: a covariance that does not grow counts as constant.
    ///
    /// ```
    /// use posecov::input::log::health::Constancy;
    /// let mut c = Constancy::default();
    /// let mut cov = [0.0; 36];
    /// cov[0] = 0.01;
    /// for k in 0..20 {
    ///     c.next(k, k as i64 * 1_000_000_000, &cov, k > 0, [0.5 * k as f64, 0.0, 0.0], false);
    /// }
    /// let s = c.finding().unwrap();
    /// assert_eq!((s.messages, s.first_index, s.last_stamp_ns), (20, 0, 19_000_000_000));
    /// assert!((s.distance_m - 9.5).abs() < 1e-12);
    /// ```
    pub fn next(
        &mut self,
        index: u64,
        stamp_ns: i64,
        cov: &[f64; COV_LEN],
        same: bool,
        position: [f64; 3],
        dead_reckoned: bool,
    ) {
        let same = same && self.previous.is_some();
        // The same entries, the same trace (only compared when they differ).
        let trace: f64 = match self.previous {
            Some((t, _)) if same => t,
            // The variances below the placeholder, summed from −0 as `Iterator::sum` does (a
            // −0 for each one left out changes nothing, to the bit), without a branch.
            _ => (0..6).fold(-0.0, |t, i| {
                let v = cov[i * 7];
                t + if v < PLACEHOLDER { v } else { -0.0 }
            }),
        };
        let continues = same
            || self
                .previous
                .is_some_and(|(t, _)| dead_reckoned && trace <= t);
        let step = match self.previous {
            Some((_, p)) => {
                let d = (0..3)
                    .map(|i| (position[i] - p[i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if d.is_finite() { d } else { 0.0 }
            }
            None => 0.0,
        };
        match &mut self.current {
            Some(s) if continues => {
                s.messages += 1;
                s.last_stamp_ns = stamp_ns;
                s.distance_m += step;
            }
            _ => {
                self.close();
                self.current = Some(Stretch {
                    messages: 1,
                    first_index: index,
                    first_stamp_ns: stamp_ns,
                    last_stamp_ns: stamp_ns,
                    distance_m: 0.0,
                });
            }
        }
        self.previous = Some((trace, position));
    }

    fn close(&mut self) {
        if let Some(s) = self.current.take()
            && self.longest.is_none_or(|l| s.distance_m > l.distance_m)
        {
            self.longest = Some(s);
        }
    }

    /// The longest stretch, when it makes a `constant` finding: at least
    /// [`CONSTANT_MIN_MESSAGES`] messages over at least [`CONSTANT_MIN_DISTANCE_M`].
    pub fn finding(mut self) -> Option<Stretch> {
        self.close();
        self.longest.filter(|s| {
            s.messages >= CONSTANT_MIN_MESSAGES && s.distance_m >= CONSTANT_MIN_DISTANCE_M
        })
    }
}

/// A topic's health classes and σ statistics, streamed over its messages: per message what
/// [`classify`], [`Trend`] and [`Constancy`] find, counted per issue in [`Health`], and σ per
/// axis ([`AxisStats`], kept as variances: [`Self::sigma_stats`]). This is the work a log's
/// read does per message on top of decoding and keeping the drawn set and series
/// (`benches/bag_read.rs` measures its share).
///
/// ```
/// use posecov::input::log::health::TopicHealth;
/// use posecov::plan::log::{Issue, PoseMessage};
/// let mut covariance = [0.0; 36];
/// for (i, v) in [0.001, 0.001, 1e6, 1e6, 1e6, 0.03].iter().enumerate() { covariance[i * 7] = *v; }
/// let d = PoseMessage { stamp_ns: 1, from_log_time: false, frame_id: "odom".into(), child_frame_id: String::new(),
///     position: [0.0; 3], orientation_xyzw: [0.0, 0.0, 0.0, 1.0], covariance, twist_covariance: None };
/// let mut topic = TopicHealth::default();
/// let (h, variance) = topic.add(0, 1, &d, true);
/// assert!(h.usable() && topic.planar);
/// assert!(variance[5] == Some(0.03) && variance[2].is_none());
/// assert_eq!(topic.sigma_stats()[5].unwrap().max, 0.03f64.sqrt());
/// let (health, constant) = topic.into_findings();
/// assert_eq!(health.count(Issue::Placeholder), 1);
/// assert!(constant.is_none());
/// ```
#[derive(Debug, Clone)]
pub struct TopicHealth {
    /// Per issue, the count and the first message: the topic's own findings (stamps, types);
    /// the messages' own issues are counted in `counts` until [`Self::into_findings`].
    pub health: Health,
    /// Per kind of issue (its place in [`Issues::ORDER`]), the messages' count and the first
    /// ([`Health::note`]'s numbers, without a map lookup per message).
    counts: [IssueCount; Issues::ORDER.len()],
    pub(super) trend: Trend,
    pub(super) constancy: Constancy,
    /// The last message's covariance and its classification ([`classify_covariance`]): the
    /// one copy, for the repeat cache and the constant-stretch search.
    last: Option<([f64; COV_LEN], MessageHealth)>,
    /// Whether the last message was usable (then its covariance, `last`, is the one
    /// [`Constancy`] compares the next usable message with).
    last_usable: bool,
    /// The last usable message's covariance when messages that were not usable came after it
    /// (`last` moved on).
    usable_before: Option<[f64; COV_LEN]>,
    /// Usable messages (drawable as a Gaussian).
    pub usable: u64,
    /// Every usable message so far has placeholders on z, roll and pitch.
    pub planar: bool,
    /// The variance's statistics per ROS axis over the usable messages that estimate it
    /// (clamped at 0): σ's are their square roots, which keep their order.
    variance_stats: VarianceColumns,
}

impl Default for TopicHealth {
    fn default() -> Self {
        Self {
            health: Health::default(),
            counts: [IssueCount {
                count: 0,
                first_stamp_ns: 0,
                first_index: 0,
            }; Issues::ORDER.len()],
            trend: Trend::default(),
            constancy: Constancy::default(),
            last: None,
            last_usable: false,
            usable_before: None,
            usable: 0,
            planar: true,
            variance_stats: VarianceColumns::default(),
        }
    }
}

/// Whether `a` and `b` have the same bits in every entry: then every check gives the same
/// answer, NaN and −0 included. The first row is compared first (an EKF's covariance differs
/// from the one before there), then the other 30 entries; each part as one loop of fixed
/// length without an early exit, which the compiler does in vectors.
fn same_bits(a: &[f64; COV_LEN], b: &[f64; COV_LEN]) -> bool {
    let mut differ = 0u64;
    for i in 0..6 {
        differ |= a[i].to_bits() ^ b[i].to_bits();
    }
    if differ != 0 {
        return false;
    }
    for i in 6..COV_LEN {
        differ |= a[i].to_bits() ^ b[i].to_bits();
    }
    differ == 0
}

/// Whether `a` and `b` are equal in every entry (`==`: ±0 alike, NaN unequal), compared as
/// [`same_bits`] does.
fn same_values(a: &[f64; COV_LEN], b: &[f64; COV_LEN]) -> bool {
    let mut equal = true;
    for i in 0..6 {
        equal &= a[i] == b[i];
    }
    if !equal {
        return false;
    }
    for i in 6..COV_LEN {
        equal &= a[i] == b[i];
    }
    equal
}

/// The variance's statistics per ROS axis, kept as six columns; [`Self::axis`] gives one
/// axis's [`AxisStats`], the same numbers [`AxisStats::add`] would have kept.
#[derive(Debug, Clone, Copy, Default)]
struct VarianceColumns {
    messages: [u64; 6],
    first: [f64; 6],
    last: [f64; 6],
    min: [f64; 6],
    max: [f64; 6],
}

impl VarianceColumns {
    /// Adds the next message's variance `v` on axis `i`: finite and either positive or +0 (a
    /// variance clamped at 0; an exact ±0 is "not estimated"), so `<` and `>` keep what
    /// `f64::min` and `f64::max` would.
    #[inline]
    fn add(&mut self, i: usize, v: f64) {
        if self.messages[i] == 0 {
            (self.first[i], self.min[i], self.max[i]) = (v, v, v);
        }
        self.messages[i] += 1;
        self.last[i] = v;
        if v < self.min[i] {
            self.min[i] = v;
        }
        if v > self.max[i] {
            self.max[i] = v;
        }
    }

    /// Axis `i`'s statistics (`None` before its first message).
    fn axis(&self, i: usize) -> Option<AxisStats> {
        (self.messages[i] > 0).then(|| AxisStats {
            messages: self.messages[i],
            first: self.first[i],
            last: self.last[i],
            min: self.min[i],
            max: self.max[i],
        })
    }
}

impl TopicHealth {
    /// Message number `index` at `stamp_ns` (`dead_reckoned`: an Odometry in an odom frame):
    /// its health and its variance per ROS axis, clamped at 0 (`None` where not estimated, or
    /// unusable; its σ is the square root).
    pub fn add(
        &mut self,
        index: u64,
        stamp_ns: i64,
        d: &PoseMessage,
        dead_reckoned: bool,
    ) -> (MessageHealth, [Option<f64>; 6]) {
        let cov = &d.covariance;
        let repeated = match &self.last {
            Some((last, _)) => same_bits(last, cov),
            None => false,
        };
        let covariance = match &self.last {
            // The same 36 entries as the message before: the same classification.
            Some((_, h)) if repeated => *h,
            _ => classify_covariance(cov),
        };
        let mut h = with_orientation(d.orientation_xyzw, covariance, cov);
        if let Some(trace) = h.position_trace {
            h.issues.extend(self.trend.next(trace).iter());
        }
        if !h.issues.is_empty() {
            for (k, _) in h.issues.iter_placed() {
                // As `Health::note`: the count, and the earliest stamp's message.
                let c = &mut self.counts[k];
                if c.count == 0 || stamp_ns < c.first_stamp_ns {
                    c.first_stamp_ns = stamp_ns;
                    c.first_index = index;
                }
                c.count += 1;
            }
            if h.issues.contains(Issue::NotPsd) {
                let lo = h.min_eigenvalue.unwrap_or(0.0);
                self.health.min_eigenvalue =
                    Some(self.health.min_eigenvalue.map_or(lo, |m| m.min(lo)));
            }
        }
        let usable = h.usable();
        if usable {
            self.usable += 1;
            self.planar &= h.unestimated[2] && h.unestimated[3] && h.unestimated[4];
            // The same entries as the last usable message: `last` itself when that was the
            // message before, else the copy kept when it moved on.
            // (A usable covariance is finite: the same bits are the same values.)
            let same = match (self.last_usable, &self.usable_before, &self.last) {
                (true, _, Some((last, _))) => repeated || same_values(last, cov),
                (false, Some(before), _) => same_values(before, cov),
                _ => false,
            };
            self.constancy
                .next(index, stamp_ns, cov, same, d.position, dead_reckoned);
        } else if self.last_usable
            && let Some((last, _)) = &self.last
        {
            // `last` moves on to a message that is not usable: keep the usable one.
            self.usable_before = Some(*last);
        }
        self.last_usable = usable;
        match &mut self.last {
            Some(_) if repeated => {}
            // In place: one 36-entry copy.
            Some((last, h)) => {
                *last = *cov;
                *h = covariance;
            }
            None => self.last = Some((*cov, covariance)),
        }
        let mut variance = [None; 6];
        if usable {
            for (i, variance) in variance.iter_mut().enumerate() {
                if !h.unestimated[i] {
                    let v = cov[i * 7].max(0.0);
                    self.variance_stats.add(i, v);
                    *variance = Some(v);
                }
            }
        }
        (h, variance)
    }

    /// The topic's findings once every message is in: its [`Health`] with the messages' own
    /// issues counted in, and the longest constant stretch when it makes a finding
    /// ([`Constancy::finding`]).
    pub fn into_findings(self) -> (Health, Option<Stretch>) {
        let mut health = self.health;
        for (issue, counted) in Issues::ORDER.iter().zip(self.counts) {
            if counted.count > 0 {
                health.add(*issue, counted);
            }
        }
        (health, self.constancy.finding())
    }

    /// σ per ROS axis over the usable messages that estimate it: first, last, smallest and
    /// largest (the square roots of the variances' — `√` keeps their order, so these are the
    /// σ's own, to the bit).
    pub fn sigma_stats(&self) -> [Option<AxisStats>; 6] {
        std::array::from_fn(|i| self.variance_stats.axis(i).map(AxisStats::sqrt))
    }
}
