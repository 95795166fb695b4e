//! What the NEES of a log is asked with and what it gives: the alignment, the settings, the
//! verdict, the skipped counts and one topic's result.

use serde::Serialize;

use crate::eval::consistency::Anees;
use crate::interop::RosReading;
use crate::lie::Se3;
use crate::plan::log::Reference;

/// The probability of the per-message bound whose share of messages is reported
/// (`inside_95`).
pub const MESSAGE_BOUND_PROBABILITY: f64 = 0.95;

/// Estimates waiting for the reference to pass their stamp, per topic; beyond this the oldest
/// is counted as after the reference (the reference stopped, or lags by more than this many
/// messages).
pub const MAX_PENDING: usize = 1 << 16;

/// How the reference is aligned to the estimate before the errors are taken (`--align`, as
/// evo offers): X_ref ← T · X_ref.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Align {
    /// No alignment (the default): both are in the same frame.
    #[default]
    None,
    /// T = X̂₀ · X_ref(t₀)⁻¹ at each topic's first matched message: the first poses coincide.
    First,
    /// T = (R, t) minimising Σ ‖p̂ᵢ − (R p_refᵢ + t)‖² over every matched message (Umeyama /
    /// Horn, without scale).
    Se3,
}

impl Align {
    /// Its name in flags and outputs.
    ///
    /// ```
    /// use posecov::eval::log::nees::Align;
    /// assert_eq!("se3".parse::<Align>().unwrap().name(), "se3");
    /// assert!("sim3".parse::<Align>().is_err());
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Align::None => "none",
            Align::First => "first",
            Align::Se3 => "se3",
        }
    }
}

impl std::str::FromStr for Align {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "none" => Ok(Align::None),
            "first" => Ok(Align::First),
            "se3" => Ok(Align::Se3),
            other => Err(format!(
                "unknown alignment `{other}`: use `none`, `first` or `se3`"
            )),
        }
    }
}

/// What the NEES of a log needs.
#[derive(Debug, Clone, PartialEq)]
pub struct NeesSettings {
    /// The reference: its topic is left out of the estimates; `/tf` samples compare only
    /// estimate topics whose `frame_id` is their parent; shown as the user names it
    /// (`topic:/truth`, `tf:base_link`, `file:gt.txt`).
    pub reference: Reference,
    /// How each message's covariance is read.
    pub reading: RosReading,
    /// Alignment.
    pub align: Align,
    /// `--every` of the log's drawing: the NEES series is kept at the drawn messages.
    pub every: Option<u64>,
}

impl NeesSettings {
    /// Defaults for `reference`: tf2's reading, no alignment.
    pub fn new(reference: Reference) -> Self {
        Self {
            reference,
            reading: RosReading::default(),
            align: Align::None,
            every: None,
        }
    }
}

/// Whether ANEES says the covariance is honest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// ANEES inside its 95 % band.
    Consistent,
    /// ANEES above the band: the published covariance is too small.
    Overconfident,
    /// ANEES below the band: the published covariance is too large.
    Underconfident,
}

impl Verdict {
    /// The verdict of an ANEES.
    ///
    /// ```
    /// use posecov::eval::{Anees, log::nees::Verdict};
    /// let a = Anees { value: 60.0, dof: 6, band: [5.5, 6.5] };
    /// assert_eq!(Verdict::of(&a), Verdict::Overconfident);
    /// ```
    pub fn of(anees: &Anees) -> Self {
        if anees.value > anees.band[1] {
            Verdict::Overconfident
        } else if anees.value < anees.band[0] {
            Verdict::Underconfident
        } else {
            Verdict::Consistent
        }
    }
}

/// Estimate messages that have no NEES, by reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Skipped {
    /// Stamped before the reference's first sample (never extrapolated).
    pub before_reference: u64,
    /// Stamped after its last sample.
    pub after_reference: u64,
    /// A covariance that is not a Gaussian (a health defect, a placeholder on a used axis).
    pub unusable: u64,
    /// A singular covariance (no NEES: a direction without variance).
    pub singular: u64,
    /// Planar where the topic's first message was 3-D, or the other way round.
    pub other_dof: u64,
    /// `tf:CHILD` only: the message's `frame_id` is not the transform's parent.
    pub other_frame: u64,
}

/// One topic's NEES against the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicConsistency {
    /// The reference (shown as named).
    pub reference: Reference,
    /// The ROS reading of the estimates' covariances.
    pub reading: RosReading,
    /// The alignment asked for.
    pub align: Align,
    /// The transform applied to the reference (identity without alignment; `None` when no
    /// message was matched).
    pub alignment: Option<Se3>,
    /// The estimate's `frame_id`.
    pub estimate_frame: String,
    /// The reference's frame (its `frame_id`; `/tf`: the parent; empty for a file).
    pub reference_frame: String,
    /// d of the joint NEES: 6, or 3 for a planar topic.
    pub dof: usize,
    /// Messages with a NEES.
    pub messages: u64,
    /// Joint ANEES with its band (`None` without messages).
    pub anees: Option<Anees>,
    /// Position-only ANEES (d = 3, planar 2).
    pub position: Option<Anees>,
    /// Orientation-only ANEES (d = 3, planar 1).
    pub orientation: Option<Anees>,
    /// The per-message bound χ²_d(0.95).
    pub bound_95: f64,
    /// Share of messages whose joint NEES ≤ `bound_95`.
    pub inside_95: Option<f64>,
    /// The verdict of the joint ANEES.
    pub verdict: Option<Verdict>,
    /// Messages without NEES, by reason.
    pub skipped: Skipped,
    /// (stamp ns, joint NEES) at the drawn messages, in stamp order.
    pub series: Vec<(i64, f64)>,
}
