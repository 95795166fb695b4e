//! A growing read's pictures (a live stream drawn while it arrives): when the summary so far is
//! next handed to the view ([`Growth`], [`growth_interval`], [`DRAWING_REST`]) and how much
//! thinner than the end's it is ([`thin`]). The collector hands the summaries on
//! (`Collector::grow`); a live stream's thread that draws rests between them (`ws/mod.rs`).

use std::time::{Duration, Instant};

use crate::plan::log::{Decimator, LogSummary};

/// Points kept per topic for the trajectory and each series in a summary handed to the
/// growing view (the end's keeps [`MAX_SERIES`](super::MAX_SERIES)): a plot a thousand points
/// wide still shows an hour's shape, and the viewer's recording, which keeps every picture
/// of a growing run, holds at most this many points per line and picture.
pub const GROWN_SERIES: usize = 1000;

/// Messages drawn per topic in a summary handed to the growing view (the end's draws up to
/// [`DEFAULT_MAX_DRAWN`](super::DEFAULT_MAX_DRAWN), or what `--every` asks): each drawn
/// message is a cloud and its regions, most of what a picture costs to draw and encode, and a
/// picture that grows while the robot drives needs fewer of them than the run's last one.
pub const GROWN_DRAWN: usize = 50;

/// After a picture of the growing view that took d to draw, the next waits at least this many
/// times d (the collector's pacing, [`Growth::handed_on`], and a live stream's thread that
/// draws): drawing takes at most a seventh of the time, so that a live run at 100 Hz on four
/// topics, reading included, costs under a quarter of one core (BENCHMARKS §12), whatever the
/// picture and the machine.
pub(crate) const DRAWING_REST: u32 = 6;

/// How long after the last summary was handed on the next one is due, `elapsed` into the
/// read: every second, and once the read is past 100 s every hundredth of its age (an hour:
/// every 36 s), so a long run hands on about 100 · (1 + ln(age / 100 s)) summaries, each
/// bounded as the summary is: what drawing them costs does not grow with the messages, and
/// their number grows with the logarithm of the run's length.
///
/// ```
/// use std::time::Duration;
/// use posecov::input::log::growth_interval;
/// assert_eq!(growth_interval(Duration::from_secs(5)), Duration::from_secs(1));
/// assert_eq!(growth_interval(Duration::from_secs(3600)), Duration::from_secs(36));
/// ```
pub fn growth_interval(elapsed: Duration) -> Duration {
    (elapsed / 100).max(Duration::from_secs(1))
}

/// A growing read: when it began, when the next summary is due (`None`: at the first pose
/// message).
pub(super) struct Growth {
    started: Instant,
    next_due: Option<Instant>,
}

impl Growth {
    /// A read beginning now.
    pub(super) fn new() -> Self {
        Self {
            started: Instant::now(),
            next_due: None,
        }
    }

    /// Whether a summary is due now.
    pub(super) fn due(&self) -> bool {
        self.next_due.is_none_or(|at| Instant::now() >= at)
    }

    /// Notes a summary handed on now, `cost` being what drawing the last one took: the next
    /// is due [`growth_interval`] later, or [`DRAWING_REST`] times `cost` if longer.
    pub(super) fn handed_on(&mut self, cost: Duration) {
        self.next_due =
            Some(Instant::now() + growth_interval(self.started.elapsed()).max(DRAWING_REST * cost));
    }
}

/// `plan` thinned for a picture of the run so far: its series and trajectories to
/// [`GROWN_SERIES`] points, its drawn messages to [`GROWN_DRAWN`] a topic (every picture
/// stays in the viewer's recording; the end's summary keeps its own bounds).
pub(super) fn thin(plan: &mut LogSummary) {
    for topic in &mut plan.topics {
        topic.series = Decimator::thinned(std::mem::take(&mut topic.series), GROWN_SERIES);
        topic.trajectory = Decimator::thinned(std::mem::take(&mut topic.trajectory), GROWN_SERIES);
        topic.drawn = Decimator::thinned(std::mem::take(&mut topic.drawn), GROWN_DRAWN);
    }
}
