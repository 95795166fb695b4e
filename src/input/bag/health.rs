//! Covariance health of one message, and the per-topic state that finds drops, unbounded
//! growth and a covariance that stays constant while the pose moves. Names, classes and
//! thresholds are the README's ("Covariance health").

use nalgebra::{DMatrix, SymmetricEigen};

use super::decode::Decoded;
use crate::plan::bag::{AxisStats, COV_LEN, Health, Issue, Stretch};
use crate::uncertain::{psd_tolerance, symmetry_tolerance};

mod issues;
pub use issues::Issues;

pub use crate::plan::bag::PLACEHOLDER;
/// A drop: the position trace divided by at least this from one usable message to the next.
pub const DROP_FACTOR: f64 = 5.0;
/// Growth: the position trace at least this many times its value after the last drop.
pub const GROWTH_FACTOR: f64 = 100.0;
/// A `constant` finding needs a stretch over at least this distance (m) …
pub const CONSTANT_MIN_DISTANCE_M: f64 = 1.0;
/// … and at least this many messages.
pub const CONSTANT_MIN_MESSAGES: u64 = 10;
/// The axes planar motion uses (x, y, yaw), by ROS index.
const PLANAR_AXES: [usize; 3] = [0, 1, 5];

/// What one message's covariance is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MessageHealth {
    /// The issues of this message alone (drops and growth come from [`Trend`]).
    pub issues: Issues,
    /// Axes whose variance is ≥ [`PLACEHOLDER`] or exactly 0, per ROS axis.
    pub unestimated: [bool; 6],
    /// Smallest eigenvalue of the estimated block, computed when it is finite, symmetric and
    /// not positive definite; exactly 0 when it is positive definite but for axes whose row
    /// and column are zero (`None` otherwise: a positive definite block is PSD).
    pub min_eigenvalue: Option<f64>,
    /// Trace of the estimated position block, m² (usable messages only).
    pub position_trace: Option<f64>,
}

impl MessageHealth {
    /// Whether the covariance can be drawn as a Gaussian.
    pub fn usable(&self) -> bool {
        !self.issues.any_unusable()
    }
}

/// The entries of the `kept` axes' block of `cov`, gathered: `b[r][c] = cov[kept[r] · 6 + kept[c]]`
/// for `r, c < kept.len()`.
fn gather(cov: &[f64; COV_LEN], kept: &[usize]) -> [[f64; 6]; 6] {
    let mut b = [[0.0; 6]; 6];
    for (r, &i) in kept.iter().enumerate() {
        for (c, &j) in kept.iter().enumerate() {
            b[r][c] = cov[i * 6 + j];
        }
    }
    b
}

/// Whether the symmetrised N × N block `at(r, c)` (`r, c < N`) is positive definite: its
/// factorisation L D Lᵀ exists with D > 0, computed here on the stack, without square roots
/// (then its smallest eigenvalue is positive, above any −tolerance, and it is positive
/// semi-definite by the one rule without computing it). N is known at compile time, so the
/// loops unroll and the entries are read without index checks.
#[inline(always)]
fn positive_definite_block<const N: usize>(at: &impl Fn(usize, usize) -> f64) -> bool {
    // l[r][c] = L_rc · D_c (c < r), d_inv[c] = 1 / D_c.
    let mut ld = [[0.0f64; N]; N];
    let mut d_inv = [0.0f64; N];
    for r in 0..N {
        for c in 0..r + 1 {
            let mut v = 0.5 * (at(r, c) + at(c, r));
            for k in 0..c {
                v -= ld[r][k] * ld[c][k] * d_inv[k];
            }
            if r == c {
                if v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    return false;
                }
                // The last row's 1 / D is never used: one division fewer.
                if r + 1 < N {
                    d_inv[r] = 1.0 / v;
                }
            } else {
                ld[r][c] = v;
            }
        }
    }
    true
}

/// `f::<N>()` for `N = n` (0 ≤ n ≤ 6): the block functions above are generic in the size.
macro_rules! by_size {
    ($n:expr, $f:ident, $($arg:expr),*) => {
        match $n {
            0 => $f::<0>($($arg),*),
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            _ => $f::<6>($($arg),*),
        }
    };
}

/// Whether the symmetrised block of `cov` on the `kept` axes is positive definite
/// ([`positive_definite_block`]).
fn positive_definite(cov: &[f64; COV_LEN], kept: &[usize]) -> bool {
    let b = gather(cov, kept);
    by_size!(
        kept.len(),
        positive_definite_block,
        &|r: usize, c: usize| b[r][c]
    )
}

/// What the checks over the estimated block find.
struct BlockChecks {
    /// Every entry is exactly 0.
    all_zero: bool,
    /// Some pair Σᵣ꜀, Σ꜀ᵣ differs by more than the symmetry tolerance at the block's scale
    /// (its largest |variance|).
    asymmetric: bool,
}

/// [`BlockChecks`] of the N × N block `at(r, c)`, every entry read once, without early exits
/// (the compiler compares in vectors).
#[inline(always)]
fn block_checks<const N: usize>(at: &impl Fn(usize, usize) -> f64) -> BlockChecks {
    let mut all_zero = true;
    let mut scale = 0.0f64;
    for r in 0..N {
        scale = scale.max(at(r, r).abs());
        for c in 0..N {
            all_zero &= at(r, c) == 0.0;
        }
    }
    // The symmetry rule is evaluation's (`uncertain`): what health calls symmetric,
    // evaluation accepts.
    let tol = symmetry_tolerance(scale);
    let mut asymmetric = false;
    // Each pair once (|Σᵢⱼ − Σⱼᵢ| is the same from either side; every entry is finite here).
    for r in 0..N {
        for c in r + 1..N {
            asymmetric |= (at(r, c) - at(c, r)).abs() > tol;
        }
    }
    BlockChecks {
        all_zero,
        asymmetric,
    }
}

/// [`block_checks`] and, when wanted (`pd_wanted(&checks)`), [`positive_definite_block`] of
/// the N × N block `at`: one function per size, so both unroll.
fn checks_and_pd<const N: usize>(
    at: &impl Fn(usize, usize) -> f64,
    pd_wanted: &impl Fn(&BlockChecks) -> bool,
) -> (BlockChecks, Option<bool>) {
    let checks = block_checks::<N>(at);
    let pd =
        pd_wanted(&checks).then(|| weakly_correlated::<N>(at) || positive_definite_block::<N>(at));
    (checks, pd)
}

/// Whether the symmetrised N × N block `at(r, c)` has a positive diagonal and correlations
/// ρᵣ꜀ = Σᵣ꜀ / √(Σᵣᵣ Σ꜀꜀) with Σ_{r<c} ρᵣ꜀² ≤ 0.45: then the correlation matrix is I + E with
/// ‖E‖₂ ≤ ‖E‖_F ≤ √0.9 < 0.95, so its eigenvalues are ≥ 0.05 and the block is positive definite
/// (by far: the rounding of this sum is 10¹³ times smaller than the margin; anything not
/// finite fails). A sufficient test without the L D Lᵀ's chain of dependent divisions (six
/// independent ones here); a block it does not decide goes to [`positive_definite_block`].
#[inline(always)]
fn weakly_correlated<const N: usize>(at: &impl Fn(usize, usize) -> f64) -> bool {
    let mut inv = [0.0f64; N];
    let mut positive = true;
    for (r, inv) in inv.iter_mut().enumerate() {
        let d = at(r, r);
        positive &= d > 0.0;
        *inv = 1.0 / d;
    }
    let mut sum = 0.0;
    for r in 0..N {
        for c in r + 1..N {
            let m = 0.5 * (at(r, c) + at(c, r));
            sum += (m * inv[r]) * (m * inv[c]);
        }
    }
    positive && sum <= 0.45
}

/// Whether the block of `cov` on the `kept` axes is positive definite once the axes whose row
/// and column are zero in it are left out (a variance of exactly 0 without correlation, "not
/// estimated", as some drivers publish z, roll and pitch): each such axis adds an eigenvalue
/// of exactly 0 and leaves the others to the rest, so the block is then PSD with smallest
/// eigenvalue 0, without an eigen-decomposition.
fn positive_definite_but_zero_axes(cov: &[f64; COV_LEN], kept: &[usize]) -> bool {
    let mut rest = [0usize; 6];
    let mut m = 0;
    for &i in kept {
        if kept
            .iter()
            .any(|&j| cov[i * 6 + j] != 0.0 || cov[j * 6 + i] != 0.0)
        {
            rest[m] = i;
            m += 1;
        }
    }
    m < kept.len() && positive_definite(cov, &rest[..m])
}

/// The smallest eigenvalue and the largest (at least 0) of the symmetrised block of `cov` on
/// the `kept` axes, by nalgebra's symmetric eigen-decomposition: the numbers a covariance
/// that is not positive definite reports.
fn eigenvalue_range(cov: &[f64; COV_LEN], kept: &[usize]) -> (f64, f64) {
    let block = DMatrix::from_fn(kept.len(), kept.len(), |r, c| {
        0.5 * (cov[kept[r] * 6 + kept[c]] + cov[kept[c] * 6 + kept[r]])
    });
    let eig = SymmetricEigen::new(block);
    let lo = eig
        .eigenvalues
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let hi = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    (lo, hi)
}

/// Classifies one covariance (ROS layout) and its orientation quaternion.
///
/// ```
/// use posecov::input::bag::health::classify;
/// use posecov::plan::bag::Issue;
/// let mut cov = [0.0; 36];
/// for (i, v) in [0.001, 0.001, 1e6, 1e6, 1e6, 0.03].iter().enumerate() { cov[i * 7] = *v; }
/// let h = classify(&cov, [0.0, 0.0, 0.0, 1.0]);
/// assert_eq!(h.issues, vec![Issue::Placeholder]);
/// assert!(h.usable());
/// assert_eq!(h.unestimated, [false, false, true, true, true, false]);
/// ```
pub fn classify(cov: &[f64; COV_LEN], orientation_xyzw: [f64; 4]) -> MessageHealth {
    with_orientation(orientation_xyzw, classify_covariance(cov), cov)
}

/// The message's health from its orientation and its covariance's classification
/// ([`classify_covariance`]): a bad orientation first, then the covariance's issues, and the
/// position trace if the message is usable.
fn with_orientation(
    orientation_xyzw: [f64; 4],
    covariance: MessageHealth,
    cov: &[f64; COV_LEN],
) -> MessageHealth {
    let mut issues = Issues::default();
    let norm = orientation_xyzw.iter().map(|q| q * q).sum::<f64>().sqrt();
    if !norm.is_finite() || (norm - 1.0).abs() > 1e-3 {
        issues.push(Issue::BadOrientation);
    }
    issues.extend(covariance.issues.iter());
    let health = MessageHealth {
        issues,
        ..covariance
    };
    let unestimated = health.unestimated;
    let position_trace = health.usable().then(|| {
        (0..3)
            .filter(|&i| !unestimated[i])
            .map(|i| cov[i * 7])
            .sum::<f64>()
    });
    MessageHealth {
        position_trace,
        ..health
    }
}

/// What the covariance alone says (no orientation, no position trace): a function of its 36
/// entries, so a topic whose covariance repeats classifies it once ([`TopicHealth::add`]).
fn classify_covariance(cov: &[f64; COV_LEN]) -> MessageHealth {
    let mut issues = Issues::default();
    // Every entry read once, without an early exit: in vectors.
    if !cov.iter().fold(true, |finite, v| finite & v.is_finite()) {
        issues.push(Issue::NonFinite);
        return MessageHealth {
            issues,
            unestimated: [false; 6],
            min_eigenvalue: None,
            position_trace: None,
        };
    }
    let diag: [f64; 6] = std::array::from_fn(|i| cov[i * 7]);
    let unestimated = diag.map(|v| v == 0.0 || v >= PLACEHOLDER);
    // The estimated axes: not a placeholder (a huge row would swamp the rounding of the rest).
    let mut axes = [0, 1, 2, 3, 4, 5];
    let mut n = 6;
    let unknown_marker = cov[0] == -1.0;
    // Positive definiteness is only asked of a symmetric block (not the −1 marker's).
    let pd_wanted = |checks: &BlockChecks| !checks.asymmetric && !unknown_marker;
    let (checks, positive_definite) = if diag.iter().all(|v| *v < PLACEHOLDER) {
        // Every axis estimated (an EKF's covariance): the block is `cov` itself, read in place.
        checks_and_pd::<6>(&|r: usize, c: usize| cov[r * 6 + c], &pd_wanted)
    } else {
        n = 0;
        for i in (0..6).filter(|&i| diag[i] < PLACEHOLDER) {
            axes[n] = i;
            n += 1;
        }
        let b = gather(cov, &axes[..n]);
        by_size!(n, checks_and_pd, &|r: usize, c: usize| b[r][c], &pd_wanted)
    };
    let kept = &axes[..n];
    if unknown_marker {
        issues.push(Issue::UnknownMarker);
    } else if n > 0 && checks.all_zero {
        issues.push(Issue::AllZero);
    }
    if PLANAR_AXES.iter().any(|&i| diag[i] >= PLACEHOLDER) {
        issues.push(Issue::PlaceholderUsedAxis);
    } else if diag.iter().any(|v| *v >= PLACEHOLDER) {
        // z, roll or pitch only: a note if the topic turns out planar, else a defect (the
        // topic's collector decides when it has seen every message).
        issues.push(Issue::Placeholder);
    }
    let mut min_eigenvalue = None;
    if checks.asymmetric {
        issues.push(Issue::Asymmetric);
    } else if n > 0 && positive_definite == Some(false) {
        // Only a block that is not positive definite needs more (most messages' are: one
        // factorisation on the stack decides; the eigen-decomposition was most of the health
        // classes' time).
        min_eigenvalue = Some(match positive_definite_but_zero_axes(cov, kept) {
            // Positive definite but for axes whose row and column are zero: their
            // eigenvalue, exactly 0, is the smallest; PSD.
            true => 0.0,
            false => {
                let (lo, hi) = eigenvalue_range(cov, kept);
                if lo < -psd_tolerance(hi) {
                    issues.push(Issue::NotPsd);
                }
                lo
            }
        });
    }
    MessageHealth {
        issues,
        unestimated,
        min_eigenvalue,
        position_trace: None,
    }
}

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
    /// use posecov::input::bag::health::Trend;
    /// use posecov::plan::bag::Issue;
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
    /// use posecov::input::bag::health::Constancy;
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
        let trace: f64 = (0..6)
            .map(|i| cov[i * 7])
            .filter(|v| *v < PLACEHOLDER)
            .sum();
        let same = same && self.previous.is_some();
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
/// use posecov::input::bag::decode::Decoded;
/// use posecov::input::bag::health::TopicHealth;
/// use posecov::plan::bag::Issue;
/// let mut covariance = [0.0; 36];
/// for (i, v) in [0.001, 0.001, 1e6, 1e6, 1e6, 0.03].iter().enumerate() { covariance[i * 7] = *v; }
/// let d = Decoded { stamp_ns: Some(1), frame_id: "odom".into(), child_frame_id: String::new(),
///     position: [0.0; 3], orientation_xyzw: [0.0, 0.0, 0.0, 1.0], covariance, twist_covariance: None };
/// let mut topic = TopicHealth::default();
/// let (h, variance) = topic.add(0, 1, &d, true);
/// assert!(h.usable() && topic.planar);
/// assert_eq!(topic.health.count(Issue::Placeholder), 1);
/// assert!(variance[5] == Some(0.03) && variance[2].is_none());
/// assert_eq!(topic.sigma_stats()[5].unwrap().max, 0.03f64.sqrt());
/// ```
#[derive(Debug, Clone)]
pub struct TopicHealth {
    /// Per issue, the count and the first message.
    pub health: Health,
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
    variance_stats: [Option<AxisStats>; 6],
}

impl Default for TopicHealth {
    fn default() -> Self {
        Self {
            health: Health::default(),
            trend: Trend::default(),
            constancy: Constancy::default(),
            last: None,
            last_usable: false,
            usable_before: None,
            usable: 0,
            planar: true,
            variance_stats: [None; 6],
        }
    }
}

/// Whether `a` and `b` have the same bits in every entry (then every check gives the same
/// answer, NaN and −0 included), and whether they are equal (`==`: ±0 alike, NaN unequal).
fn same_entries(a: &[f64; COV_LEN], b: &[f64; COV_LEN]) -> (bool, bool) {
    // Every entry compared, without an early exit: the compiler compares them in vectors.
    a.iter().zip(b).fold((true, true), |(bits, equal), (x, y)| {
        (bits & (x.to_bits() == y.to_bits()), equal & (x == y))
    })
}

impl TopicHealth {
    /// Message number `index` at `stamp_ns` (`dead_reckoned`: an Odometry in an odom frame):
    /// its health and its variance per ROS axis, clamped at 0 (`None` where not estimated, or
    /// unusable; its σ is the square root).
    pub fn add(
        &mut self,
        index: u64,
        stamp_ns: i64,
        d: &Decoded,
        dead_reckoned: bool,
    ) -> (MessageHealth, [Option<f64>; 6]) {
        let cov = &d.covariance;
        let (same_bits, same_values) = match &self.last {
            Some((last, _)) => same_entries(last, cov),
            None => (false, false),
        };
        let covariance = match &self.last {
            // The same 36 entries as the message before: the same classification.
            Some((_, h)) if same_bits => *h,
            _ => classify_covariance(cov),
        };
        let mut h = with_orientation(d.orientation_xyzw, covariance, cov);
        if let Some(trace) = h.position_trace {
            h.issues.extend(self.trend.next(trace).iter());
        }
        for issue in h.issues.iter() {
            self.health.note(issue, stamp_ns, index);
        }
        if h.issues.contains(Issue::NotPsd) {
            let lo = h.min_eigenvalue.unwrap_or(0.0);
            self.health.min_eigenvalue = Some(self.health.min_eigenvalue.map_or(lo, |m| m.min(lo)));
        }
        let usable = h.usable();
        if usable {
            self.usable += 1;
            self.planar &= h.unestimated[2] && h.unestimated[3] && h.unestimated[4];
            // The same entries as the last usable message: `last` itself when that was the
            // message before, else the copy kept when it moved on.
            let same = match (self.last_usable, &self.usable_before) {
                (true, _) => same_values,
                (false, Some(before)) => same_entries(before, cov).1,
                (false, None) => false,
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
            Some(_) if same_bits => {}
            // In place: one 36-entry copy.
            Some((last, h)) => {
                *last = *cov;
                *h = covariance;
            }
            None => self.last = Some((*cov, covariance)),
        }
        let variance: [Option<f64>; 6] =
            std::array::from_fn(|i| (usable && !h.unestimated[i]).then(|| cov[i * 7].max(0.0)));
        for (stats, v) in self.variance_stats.iter_mut().zip(variance) {
            if let Some(v) = v {
                AxisStats::add(stats, v);
            }
        }
        (h, variance)
    }

    /// σ per ROS axis over the usable messages that estimate it: first, last, smallest and
    /// largest (the square roots of the variances' — `√` keeps their order, so these are the
    /// σ's own, to the bit).
    pub fn sigma_stats(&self) -> [Option<AxisStats>; 6] {
        self.variance_stats.map(|s| s.map(AxisStats::sqrt))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diag(d: [f64; 6]) -> [f64; 36] {
        let mut c = [0.0; 36];
        for i in 0..6 {
            c[i * 7] = d[i];
        }
        c
    }
    const Q: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

    #[test]
    fn each_case_has_its_word() {
        assert!(classify(&diag([0.1; 6]), Q).issues.is_empty());
        assert_eq!(classify(&[0.0; 36], Q).issues, vec![Issue::AllZero]);
        let mut m = diag([0.1; 6]);
        m[0] = -1.0;
        assert_eq!(classify(&m, Q).issues, vec![Issue::UnknownMarker]);
        assert_eq!(
            classify(&diag([0.1, 0.1, 1.79e308, 0.1, 0.1, 0.1]), Q).issues,
            vec![Issue::Placeholder]
        );
        assert_eq!(
            classify(&diag([1e6, 0.1, 0.1, 0.1, 0.1, 0.1]), Q).issues,
            vec![Issue::PlaceholderUsedAxis]
        );
        // Zeros on x, y, yaw with placeholders elsewhere: nothing is estimated.
        assert_eq!(
            classify(&diag([0.0, 0.0, 1e6, 1e6, 1e6, 0.0]), Q).issues,
            vec![Issue::AllZero, Issue::Placeholder]
        );
        let mut n = diag([0.1; 6]);
        n[3] = f64::NAN;
        assert_eq!(classify(&n, Q).issues, vec![Issue::NonFinite]);
        let mut a = diag([0.1; 6]);
        a[1] = 0.05;
        assert_eq!(classify(&a, Q).issues, vec![Issue::Asymmetric]);
        let mut p = diag([0.1; 6]);
        p[1] = 0.5;
        p[6] = 0.5;
        let h = classify(&p, Q);
        assert_eq!(h.issues, vec![Issue::NotPsd]);
        assert!((h.min_eigenvalue.unwrap() - (0.1 - 0.5)).abs() < 1e-12);
        assert_eq!(
            classify(&diag([0.1; 6]), [0.0, 0.0, 0.0, 2.0]).issues,
            vec![Issue::BadOrientation]
        );
    }

    #[test]
    fn zero_axes_are_psd_without_an_eigen_decomposition() {
        // z, roll and pitch published as exact zeros: positive definite on x, y and yaw, and
        // the smallest eigenvalue is the zero axes' 0 (what the eigen-decomposition gives).
        let h = classify(&diag([1e-3, 1e-3, 0.0, 0.0, 0.0, 0.03]), Q);
        assert!(h.usable() && h.issues.is_empty(), "{:?}", h.issues);
        assert_eq!(h.min_eigenvalue, Some(0.0));
        assert_eq!(h.unestimated, [false, false, true, true, true, false]);
        assert_eq!(
            eigenvalue_range(
                &diag([1e-3, 1e-3, 0.0, 0.0, 0.0, 0.03]),
                &[0, 1, 2, 3, 4, 5]
            )
            .0,
            0.0
        );
        // A zero variance correlated with another axis is no zero axis: not PSD.
        let mut c = diag([1e-3, 1e-3, 0.0, 0.0, 0.0, 0.03]);
        c[2] = 1e-4;
        c[12] = 1e-4;
        let h = classify(&c, Q);
        assert!(h.issues.contains(Issue::NotPsd), "{:?}", h.issues);
        assert!(h.min_eigenvalue.unwrap() < -1e-6);
    }

    #[test]
    fn placeholders_do_not_spoil_the_psd_check() {
        // 1.79e308 next to 1e-3: eigenvalues of the whole matrix would be rounding noise.
        let h = classify(&diag([1e-3, 1e-3, 1.79e308, 1e6, 1e6, 0.03]), Q);
        assert!(h.usable());
        // Positive definite: decided by Cholesky, no eigenvalue computed.
        assert_eq!(h.min_eigenvalue, None);
        assert_eq!(h.position_trace, Some(2e-3));
        // Singular but PSD (x and y fully correlated): the eigenvalues decide, within the
        // tolerance.
        let mut s = diag([1e-3, 1e-3, 1e6, 1e6, 1e6, 0.03]);
        s[1] = 1e-3;
        s[6] = 1e-3;
        let h = classify(&s, Q);
        assert!(!h.issues.contains(Issue::NotPsd), "{:?}", h.issues);
        assert!(h.min_eigenvalue.unwrap().abs() < 1e-15);
    }
}
