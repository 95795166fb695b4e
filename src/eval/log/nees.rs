//! Is a log's published covariance honest? NEES of every estimate message against a reference
//! (ground truth), streamed while the log is read ([`NeesObserver`], a
//! [`LogObserver`]): memory does not grow with the number of estimates (the reference
//! trajectory itself is held, 64 bytes a sample; `--align se3` holds the matched pairs, as
//! the alignment needs them all before any NEES).
//!
//! Per estimate message at stamp t ([CONVENTIONS §6 and §11](crate::conventions)):
//!
//! - the truth X_ref(t) is interpolated on the group between the two reference samples that
//!   bracket t: X_a · Exp(s · Log(X_a⁻¹ X_b)), s = (t − t_a) / (t_b − t_a); a stamp outside the
//!   reference is never extrapolated: it is counted and skipped;
//! - the estimate's Gaussian is the message read in the chosen ROS reading and converted to
//!   posecov's right form, X = X̂ · Exp(ε), ε ~ N(0, Σ) (the one conversion, as the log's
//!   drawing uses); planar topics (z, roll, pitch not estimated) become SE(2) (x, y, yaw);
//! - the error is e = Log(X̂⁻¹ · X_ref) and the **joint NEES** eᵀ Σ⁻¹ e (d = 6, or 3 planar);
//! - as ov_eval reports them, the **position NEES** δpᵀ (R̂ Σ_ρρ R̂ᵀ)⁻¹ δp, δp = p_ref − p̂
//!   (the position error in the parent axes against the position block moved there; d = 3 or
//!   2), and the **orientation NEES** θᵀ Σ_θθ⁻¹ θ, θ = Log(R̂ᵀ R_ref) (d = 3 or 1).
//!
//! Per topic: ANEES = (1/N) Σ NEES with its 95 % band χ²_{Nd}(0.025 / 0.975) / N
//! ([`anees_band`]), the share of messages whose NEES is within χ²_d(0.95), and the verdict
//! ([`Verdict`]): overconfident above the band (Σ too small), underconfident below.
//!
//! ```
//! use posecov::eval::log::nees::{Align, NeesObserver, NeesSettings};
//! use posecov::plan::log::{EstimateMessage, LogObserver, Reference, ReferenceInLog, ReferenceSample};
//! let truth = Reference::InLog(ReferenceInLog::Topic("/truth".into()));
//! let mut nees = NeesObserver::new(NeesSettings::new(truth));
//! for k in 0..3 {
//!     let q = [0.0, 0.0, 0.0, 1.0];
//!     nees.reference("map", ReferenceSample { stamp_ns: k * 100, position: [k as f64, 0.0, 0.0], orientation_xyzw: q });
//! }
//! let mut cov = [0.0; 36];
//! for i in 0..6 { cov[i * 7] = 0.01; }
//! // Truth at t = 150 is x = 1.5; the estimate says 1.6 with σx = 0.1: NEES = 1.
//! nees.estimate(&EstimateMessage { topic: "/ekf", frame_id: "map", index: 0, stamp_ns: 150,
//!     position: [1.6, 0.0, 0.0], orientation_xyzw: [0.0, 0.0, 0.0, 1.0], covariance: &cov,
//!     usable: true, unestimated: [false; 6], series: None });
//! let topics = nees.finish(&[("/ekf".to_owned(), 1)].into());
//! let c = &topics["/ekf"];
//! assert_eq!((c.dof, c.messages), (6, 1));
//! assert!((c.anees.unwrap().value - 1.0).abs() < 1e-9);
//! ```

use std::collections::{BTreeMap, VecDeque};

use nalgebra::{Matrix6, SMatrix, Vector3};

use super::meaning::{RightForm, right_form};

mod math;
mod model;
use super::stamped::{Lookup, StampedPoses, pose_of_sample};
use crate::eval::consistency::{ANEES_BAND_PROBABILITY, Anees};
use crate::interop::RosReading;
use crate::lie::{LieGroup, Se2, Se3, So3};
use crate::plan::limits::MAX_COORDINATE;
use crate::plan::log::{
    DEFAULT_MAX_DRAWN, Decimator, EstimateMessage, LogObserver, MAX_DRAWN_LIMIT, ReferenceSample,
    StampRange,
};
use crate::uncertain::{Information, Side, UncertainPose, anees_band, chi2_radius};
pub use math::{nees_se2, nees_se3, umeyama};
pub use model::{
    Align, MAX_PENDING, MESSAGE_BOUND_PROBABILITY, NeesSettings, Skipped, TopicConsistency, Verdict,
};

/// The truth at a stamp.
enum Truth {
    At(Se3),
    Before,
    After,
    Pending,
}

/// An estimate's Gaussian in the right form, with Σ⁻¹ (`None`: Σ is singular).
#[derive(Clone)]
enum Gaussian {
    Planar(Se2, SMatrix<f64, 3, 3>, Option<Information<3>>),
    Spatial(Se3, Box<(Matrix6<f64>, Option<Information<6>>)>),
}

impl Gaussian {
    fn dof(&self) -> usize {
        match self {
            Gaussian::Planar(..) => 3,
            Gaussian::Spatial(..) => 6,
        }
    }
    fn position(&self) -> Vector3<f64> {
        match self {
            Gaussian::Planar(x, ..) => Vector3::new(x.translation().x, x.translation().y, 0.0),
            Gaussian::Spatial(x, _) => *x.translation(),
        }
    }
}

/// A message waiting for the reference, or (se3 alignment) for the alignment.
#[derive(Clone)]
struct Waiting {
    index: u64,
    stamp_ns: i64,
    gaussian: Gaussian,
    truth: Option<Se3>,
}

/// Sums over a topic's messages.
#[derive(Default, Clone)]
struct Sums {
    messages: u64,
    joint: f64,
    position: f64,
    orientation: f64,
    inside: u64,
}

struct TopicState {
    frame_id: String,
    dof: Option<usize>,
    pending: VecDeque<Waiting>,
    matched: Vec<Waiting>,
    alignment: Option<Se3>,
    sums: Sums,
    skipped: Skipped,
    series: Decimator<(u64, i64, f64)>,
    /// χ²_d(0.95) for the topic's d, computed once (an inverse CDF per message was a tenth
    /// of a long log's NEES time).
    bound: Option<(usize, f64)>,
}

/// The streamed NEES of a log's estimate topics against a reference: give it to the log's
/// reader as its [`LogObserver`], or feed it samples (a TUM file's first, with
/// [`NeesObserver::reference`]), then [`finish`](NeesObserver::finish).
///
/// See the [module docs](self) for an example.
pub struct NeesObserver {
    settings: NeesSettings,
    /// parent_from_child at its stamps (the one home of a pose at a stamp).
    reference: StampedPoses,
    reference_frame: Option<String>,
    complete: bool,
    topics: BTreeMap<String, TopicState>,
}

impl NeesObserver {
    /// An observer with no reference yet.
    pub fn new(settings: NeesSettings) -> Self {
        Self {
            settings,
            reference: StampedPoses::default(),
            reference_frame: None,
            complete: false,
            topics: BTreeMap::new(),
        }
    }

    /// An observer whose whole reference is known before the log is read (a TUM file):
    /// estimates are never kept waiting.
    ///
    /// ```
    /// use posecov::eval::log::nees::{NeesObserver, NeesSettings};
    /// use posecov::plan::log::{Reference, ReferenceSample};
    /// let s = ReferenceSample { stamp_ns: 0, position: [0.0; 3], orientation_xyzw: [0.0, 0.0, 0.0, 1.0] };
    /// let nees = NeesObserver::with_trajectory(NeesSettings::new(Reference::File("gt.txt".into())), &[s]);
    /// assert_eq!(nees.reference_samples(), 1);
    /// ```
    pub fn with_trajectory(settings: NeesSettings, samples: &[ReferenceSample]) -> Self {
        let mut observer = Self::new(settings);
        for s in samples {
            observer.reference("", *s);
        }
        observer.complete = true;
        observer
    }

    /// Reference samples held.
    pub fn reference_samples(&self) -> usize {
        self.reference.len()
    }

    /// The stamps the reference spans (ns), if any sample.
    pub fn reference_span(&self) -> Option<StampRange> {
        self.reference.span()
    }

    /// The truth at `stamp_ns`: interpolated between the bracketing samples, never
    /// extrapolated.
    fn truth(&self, stamp_ns: i64) -> Truth {
        match self.reference.at(stamp_ns) {
            Lookup::At(x) => Truth::At(x),
            Lookup::Before if !self.reference.is_empty() => Truth::Before,
            _ if self.complete => Truth::After,
            _ => Truth::Pending,
        }
    }

    /// The NEES of every estimate matched so far, as [`finish`](Self::finish) gives it, the
    /// stream going on (a growing live view draws it): estimates still waiting for the
    /// reference are not in it yet; with `se3` alignment (which needs the whole run) no
    /// estimate has a NEES before the end.
    ///
    /// ```
    /// use posecov::eval::log::nees::{NeesObserver, NeesSettings};
    /// use posecov::plan::log::{EstimateMessage, LogObserver, Reference, ReferenceInLog, ReferenceSample};
    /// let truth = Reference::InLog(ReferenceInLog::Topic("/truth".into()));
    /// let mut nees = NeesObserver::new(NeesSettings::new(truth));
    /// let q = [0.0, 0.0, 0.0, 1.0];
    /// for k in 0..3 {
    ///     nees.reference("map", ReferenceSample { stamp_ns: k * 100, position: [0.0; 3], orientation_xyzw: q });
    /// }
    /// let mut cov = [0.0; 36];
    /// for i in 0..6 { cov[i * 7] = 0.01; }
    /// nees.estimate(&EstimateMessage { topic: "/ekf", frame_id: "map", index: 0, stamp_ns: 150,
    ///     position: [0.1, 0.0, 0.0], orientation_xyzw: q, covariance: &cov,
    ///     usable: true, unestimated: [false; 6], series: None });
    /// let drawn = [("/ekf".to_owned(), 1)].into();
    /// let so_far = nees.so_far(&drawn);
    /// assert_eq!(so_far["/ekf"].messages, 1);
    /// assert_eq!(so_far, nees.finish(&drawn));
    /// ```
    pub fn so_far(&self, drawn: &BTreeMap<String, u64>) -> BTreeMap<String, TopicConsistency> {
        let reference_frame = self.reference_frame.clone().unwrap_or_default();
        self.topics
            .iter()
            .map(|(name, state)| {
                let taken = TopicState {
                    frame_id: state.frame_id.clone(),
                    dof: state.dof,
                    pending: VecDeque::new(),
                    matched: Vec::new(),
                    alignment: state.alignment,
                    sums: state.sums.clone(),
                    skipped: state.skipped,
                    series: state.series.clone(),
                    bound: state.bound,
                };
                let stride = stride_of(drawn, name);
                let c = summary(&self.settings, &reference_frame, taken, stride);
                (name.clone(), c)
            })
            .collect()
    }

    /// Ends the stream: waiting estimates are after the reference; with `se3` alignment the
    /// transform is fitted and every matched message's NEES taken. `drawn` gives each topic's
    /// drawn stride by topic (the NEES series is kept at the drawn messages). Returns each
    /// topic's NEES by name.
    pub fn finish(mut self, drawn: &BTreeMap<String, u64>) -> BTreeMap<String, TopicConsistency> {
        self.complete = true;
        let settings = self.settings.clone();
        let reference_frame = self.reference_frame.clone().unwrap_or_default();
        let mut out = BTreeMap::new();
        for (name, mut state) in std::mem::take(&mut self.topics) {
            state.skipped.after_reference += state.pending.len() as u64;
            state.pending.clear();
            if settings.align == Align::Se3 {
                state.alignment = umeyama(
                    &state
                        .matched
                        .iter()
                        .map(|w| {
                            let truth = w.truth.unwrap_or_else(Se3::identity);
                            (*truth.translation(), w.gaussian.position())
                        })
                        .collect::<Vec<_>>(),
                );
                if let Some(t) = state.alignment {
                    for w in std::mem::take(&mut state.matched) {
                        let truth = t.compose(&w.truth.unwrap_or_else(Se3::identity));
                        add_nees(&mut state, &w, &truth);
                    }
                }
            }
            let stride = stride_of(drawn, &name);
            let consistency = summary(&settings, &reference_frame, state, stride);
            out.insert(name, consistency);
        }
        out
    }

    /// Takes the NEES of a waiting estimate whose truth is known now.
    fn matched(&mut self, topic: &str, mut w: Waiting, truth: Se3) {
        let align = self.settings.align;
        let tf_parent = self
            .settings
            .reference
            .is_tf()
            .then(|| self.reference_frame.as_deref().unwrap_or_default());
        let Some(state) = self.topics.get_mut(topic) else {
            return;
        };
        if tf_parent.is_some_and(|parent| parent != state.frame_id) {
            state.skipped.other_frame += 1;
            return;
        }
        match align {
            Align::Se3 => {
                w.truth = Some(truth);
                state.matched.push(w);
            }
            Align::First => {
                let t = *state.alignment.get_or_insert_with(|| {
                    let estimate = match &w.gaussian {
                        Gaussian::Spatial(x, _) => *x,
                        Gaussian::Planar(x, ..) => x.to_se3(),
                    };
                    estimate.compose(&truth.inverse())
                });
                add_nees(state, &w, &t.compose(&truth));
            }
            Align::None => {
                state.alignment = Some(Se3::identity());
                add_nees(state, &w, &truth);
            }
        }
    }

    /// Estimates of every topic that the reference now covers.
    fn flush(&mut self) {
        if self.topics.values().all(|t| t.pending.is_empty()) {
            return;
        }
        let waiting: Vec<String> = self
            .topics
            .iter()
            .filter(|(_, t)| !t.pending.is_empty())
            .map(|(name, _)| name.clone())
            .collect();
        for name in waiting {
            while let Some(stamp) = self
                .topics
                .get(&name)
                .and_then(|t| t.pending.front())
                .map(|w| w.stamp_ns)
            {
                let found = self.truth(stamp);
                if matches!(found, Truth::Pending) {
                    break;
                }
                let Some(state) = self.topics.get_mut(&name) else {
                    break;
                };
                let Some(w) = state.pending.pop_front() else {
                    break;
                };
                match found {
                    Truth::At(x) => self.matched(&name, w, x),
                    Truth::Before => state.skipped.before_reference += 1,
                    _ => state.skipped.after_reference += 1,
                }
            }
        }
    }
}

impl LogObserver for NeesObserver {
    fn reference(&mut self, frame_id: &str, sample: ReferenceSample) {
        let Some(x) = pose_of_sample(&sample) else {
            return;
        };
        let frame = frame_id.trim_start_matches('/');
        match &self.reference_frame {
            None => self.reference_frame = Some(frame.to_owned()),
            // `/tf`: the first parent seen is the reference's; other parents are left out.
            Some(f) if self.settings.reference.is_tf() && f != frame => return,
            Some(_) => {}
        }
        self.reference.insert(sample.stamp_ns, x);
        self.flush();
    }

    fn estimate(&mut self, m: &EstimateMessage<'_>) {
        if self.settings.reference.topic() == Some(m.topic) {
            return;
        }
        let every = self.settings.every;
        if !self.topics.contains_key(m.topic) {
            // The topic's name is allocated once, not per message.
            self.topics.insert(
                m.topic.to_owned(),
                TopicState {
                    frame_id: m.frame_id.trim_start_matches('/').to_owned(),
                    dof: None,
                    pending: VecDeque::new(),
                    matched: Vec::new(),
                    alignment: None,
                    sums: Sums::default(),
                    skipped: Skipped::default(),
                    series: match every {
                        Some(n) => Decimator::new(n, MAX_DRAWN_LIMIT),
                        None => Decimator::new(1, DEFAULT_MAX_DRAWN),
                    },
                    bound: None,
                },
            );
        }
        let Some(state) = self.topics.get_mut(m.topic) else {
            return;
        };
        let Some(gaussian) = gaussian_of(m, self.settings.reading) else {
            state.skipped.unusable += 1;
            return;
        };
        match state.dof {
            None => state.dof = Some(gaussian.dof()),
            Some(d) if d != gaussian.dof() => {
                state.skipped.other_dof += 1;
                return;
            }
            Some(_) => {}
        }
        let w = Waiting {
            index: m.index,
            stamp_ns: m.stamp_ns,
            gaussian,
            truth: None,
        };
        if !state.pending.is_empty() {
            // Keep file order behind the ones already waiting.
            state.pending.push_back(w);
            if state.pending.len() > MAX_PENDING {
                state.pending.pop_front();
                state.skipped.after_reference += 1;
            }
            return;
        }
        let truth = self.truth(m.stamp_ns);
        let Some(state) = self.topics.get_mut(m.topic) else {
            return;
        };
        match truth {
            Truth::At(x) => self.matched(m.topic, w, x),
            Truth::Before => state.skipped.before_reference += 1,
            Truth::After => state.skipped.after_reference += 1,
            Truth::Pending => state.pending.push_back(w),
        }
    }
}

/// The right-form Gaussian of a usable message (the log drawing's conversion) with Σ⁻¹ from
/// the factorisation that validates Σ (`uncertain::try_information`), `None` when it has none.
fn gaussian_of(m: &EstimateMessage<'_>, reading: RosReading) -> Option<Gaussian> {
    if !m.usable
        || m.position
            .iter()
            .any(|v| !v.is_finite() || v.abs() > MAX_COORDINATE)
    {
        return None;
    }
    let rotation = So3::try_from_quaternion_xyzw(m.orientation_xyzw).ok()?;
    let mean = Se3::from_parts(m.position.into(), rotation);
    let planar = m.unestimated[2] && m.unestimated[3] && m.unestimated[4];
    let cov = Matrix6::from_row_slice(m.covariance);
    Some(
        match right_form(&mean, &cov, &m.unestimated, planar, reading).ok()? {
            RightForm::Planar(mean, cov) => {
                let (pose, info) =
                    UncertainPose::try_new_with_information(mean, cov, Side::Right).ok()?;
                Gaussian::Planar(*pose.mean(), *pose.cov(), info.ok())
            }
            RightForm::Spatial(mean, cov) => {
                let (pose, info) =
                    UncertainPose::try_new_with_information(mean, cov, Side::Right).ok()?;
                Gaussian::Spatial(*pose.mean(), Box::new((*pose.cov(), info.ok())))
            }
        },
    )
}

fn add_nees(state: &mut TopicState, w: &Waiting, truth: &Se3) {
    let parts = match &w.gaussian {
        Gaussian::Planar(x, cov, info) => info
            .as_ref()
            .and_then(|info| math::nees_se2_informed(x, cov, info, truth)),
        Gaussian::Spatial(x, cov_info) => cov_info
            .1
            .as_ref()
            .and_then(|info| math::nees_se3_informed(x, &cov_info.0, info, truth)),
    };
    let Some([joint, position, orientation]) = parts.filter(|p| p.iter().all(|v| v.is_finite()))
    else {
        state.skipped.singular += 1;
        return;
    };
    let d = w.gaussian.dof();
    let bound = match state.bound {
        Some((dof, bound)) if dof == d => bound,
        _ => {
            let bound = chi2_radius(MESSAGE_BOUND_PROBABILITY, d).map_or(f64::INFINITY, |r| r * r);
            state.bound = Some((d, bound));
            bound
        }
    };
    let s = &mut state.sums;
    s.messages += 1;
    s.joint += joint;
    s.position += position;
    s.orientation += orientation;
    s.inside += u64::from(joint <= bound);
    if state.series.wants(w.index) {
        state.series.push(w.index, (w.index, w.stamp_ns, joint));
    }
}

/// The drawn stride of topic `name` in `drawn` (1 when not there).
fn stride_of(drawn: &BTreeMap<String, u64>, name: &str) -> u64 {
    drawn.get(name).map_or(1, |s| (*s).max(1))
}

fn summary(
    settings: &NeesSettings,
    reference_frame: &str,
    state: TopicState,
    stride: u64,
) -> TopicConsistency {
    let dof = state.dof.unwrap_or(6);
    let (position_dof, orientation_dof) = if dof == 3 { (2, 1) } else { (3, 3) };
    let s = &state.sums;
    let n = s.messages as usize;
    let anees = |sum: f64, d: usize| {
        let band = anees_band(n, d, ANEES_BAND_PROBABILITY).ok()?;
        Some(Anees {
            value: sum / n as f64,
            dof: d,
            band,
        })
    };
    let joint = anees(s.joint, dof);
    // The drawn messages' stride is a multiple of this series' (both double from `every`,
    // and this one holds fewer items): keeping its multiples keeps the drawn messages.
    let mut kept: Vec<(i64, f64)> = state
        .series
        .into_items()
        .into_iter()
        .filter(|(index, ..)| index.is_multiple_of(stride))
        .map(|(_, stamp, nees)| (stamp, nees))
        .collect();
    kept.sort_by_key(|p| p.0);
    TopicConsistency {
        reference: settings.reference.clone(),
        reading: settings.reading,
        align: settings.align,
        alignment: state.alignment,
        estimate_frame: state.frame_id,
        reference_frame: reference_frame.to_owned(),
        dof,
        messages: s.messages,
        verdict: joint.as_ref().map(Verdict::of),
        anees: joint,
        position: anees(s.position, position_dof),
        orientation: anees(s.orientation, orientation_dof),
        bound_95: chi2_radius(MESSAGE_BOUND_PROBABILITY, dof).map_or(f64::NAN, |r| r * r),
        inside_95: (n > 0).then(|| s.inside as f64 / n as f64),
        skipped: state.skipped,
        series: kept,
    }
}
