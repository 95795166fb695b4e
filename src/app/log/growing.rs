//! A live run's growing view (issue 31): where it goes ([`Growing`]; the viewer's session,
//! `app/session.rs`, is one) and the read's observer that hands it each message as it arrives
//! ([`Observer`]), beside the NEES observer of `--reference`.

use super::nees;
use crate::plan::log::{EstimateMessage, LogObserver, ReferenceSample, SeriesPoint};
use crate::scene::Scene;

/// Where a live run's growing view goes: whole pictures of the run so far, on the read's
/// thread that draws, and between them each message's point of its topic's σ series, on the
/// thread that reads as the message arrives; neither waits for the other.
pub(crate) trait Growing: Sync {
    /// A picture of the run so far (validated), in place of the one before.
    fn picture(&self, scene: &Scene);
    /// A message of `topic` that its σ series took in as it arrived: its point (σ per axis,
    /// the position trace, as the series holds it). Thinned as the series is, so what is
    /// streamed grows with the logarithm of the run's length.
    fn message(&self, topic: &str, point: &SeriesPoint);
}

/// The read's observer: every message to the NEES observer (`--reference`) and, for a
/// growing view, each one its topic's series takes in to the view.
pub(super) struct Observer<'a> {
    pub(super) nees: Option<nees::Forward<'a>>,
    pub(super) growing: Option<&'a dyn Growing>,
}

impl LogObserver for Observer<'_> {
    fn reference(&mut self, frame_id: &str, sample: ReferenceSample) {
        if let Some(nees) = &mut self.nees {
            nees.reference(frame_id, sample);
        }
    }

    fn estimate(&mut self, message: &EstimateMessage<'_>) {
        if let Some(nees) = &mut self.nees {
            nees.estimate(message);
        }
        if let (Some(growing), Some(point)) = (self.growing, &message.series) {
            growing.message(message.topic, point);
        }
    }
}
