//! [`StepPolicy`]: which steps of a long propagation keep numbers, particles and Monte Carlo
//! statistics.

/// Which steps of a long propagation keep their numbers and their particles: numbers at most
/// [`max_recorded`](Self::max_recorded) steps (every k-th, k = ⌈steps / max⌉, and the last),
/// particles (and so clouds and surfaces) at most [`max_detailed`](Self::max_detailed), Monte
/// Carlo statistics (the cloud's mean, covariance and coverage) at most
/// [`max_sampled`](Self::max_sampled) recorded steps besides the detailed ones. Memory
/// and the statistics' time are then bounded whatever the step count; every particle still
/// takes every step. Evaluation and drawing share one value, resolved once.
///
/// ```
/// use posecov::plan::StepPolicy;
/// let p = StepPolicy::default();
/// assert!(p.records(0, 100) && p.records(100, 100));
/// assert!(p.detailed(95, 100) && !p.detailed(96, 100) && p.detailed(100, 100));
/// let long = (0..=100_000).filter(|k| p.records(*k, 100_000)).count();
/// assert!(long <= 1001);
/// // A pose graph's chain: statistics at the drawn steps only (11 of 1727).
/// let g = StepPolicy::GRAPH;
/// let sampled = (0..=1727).filter(|k| g.samples(*k, 1727)).count();
/// let drawn = (0..=1727).filter(|k| g.detailed(*k, 1727)).count();
/// assert!(sampled == drawn && sampled <= 22 && g.samples(1727, 1727) && g.samples(0, 1727));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepPolicy {
    /// At most this many recorded steps per propagation (plus the last).
    pub max_recorded: u64,
    /// At most this many detailed steps per propagation (plus the last).
    pub max_detailed: u64,
    /// At most this many recorded steps per propagation take Monte Carlo statistics (plus
    /// the detailed ones and the last); the default takes them at every recorded step.
    pub max_sampled: u64,
}

impl Default for StepPolicy {
    fn default() -> Self {
        Self {
            max_recorded: 1000,
            max_detailed: 20,
            max_sampled: 1000,
        }
    }
}

impl StepPolicy {
    /// A pose graph's (its input's default, [`crate::input::FileSettings::steps`]): the
    /// odometry chain of a benchmark graph has thousands of steps, and Monte Carlo statistics
    /// (a Lie mean and the coverage of every region over every sample) at each recorded one
    /// were most of `posecov report intel.g2o`'s time (1 727 steps × 2 000 samples): they are
    /// taken at the drawn (detailed) steps only, at most 20 and the last; every sample still
    /// takes every step.
    pub const GRAPH: Self = Self {
        max_recorded: 1000,
        max_detailed: 20,
        max_sampled: 20,
    };

    fn keeps(step: u64, last: u64, max: u64) -> bool {
        let stride = last.div_ceil(max.max(1)).max(1);
        step.is_multiple_of(stride) || step == last
    }

    /// Whether step `step` of a propagation whose last step is `last` keeps its numbers.
    ///
    /// ```
    /// assert!(posecov::plan::StepPolicy::default().records(7, 7));
    /// ```
    pub fn records(&self, step: u64, last: u64) -> bool {
        Self::keeps(step, last, self.max_recorded)
    }

    /// Whether step `step` keeps its particles and is drawn in full.
    ///
    /// ```
    /// assert!(posecov::plan::StepPolicy::default().detailed(0, 7));
    /// ```
    pub fn detailed(&self, step: u64, last: u64) -> bool {
        self.records(step, last) && Self::keeps(step, last, self.max_detailed)
    }

    /// Whether step `step` takes Monte Carlo statistics: a recorded step among at most
    /// [`max_sampled`](Self::max_sampled) evenly spaced ones, or a detailed one (the last
    /// always).
    ///
    /// ```
    /// let p = posecov::plan::StepPolicy::default();
    /// assert!(p.samples(1692, 1727) && !p.samples(1693, 1727) && p.samples(1727, 1727));
    /// ```
    pub fn samples(&self, step: u64, last: u64) -> bool {
        self.records(step, last)
            && (Self::keeps(step, last, self.max_sampled) || self.detailed(step, last))
    }
}
