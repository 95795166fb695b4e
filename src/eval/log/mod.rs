//! The numbers of a robot log ([`LogSummary`]): per drawn message, what its covariance means in
//! posecov's body-frame right form (through the one ROS conversion,
//! [`ros_cov_to_right`](crate::interop::ros_cov_to_right)), a seeded sample cloud, and the numbers RViz draws from
//! the same message. Planar topics become SE(2) (x, y, yaw), others SE(3).
//!
//! Confidence regions: a planar topic's position region has d = 2 degrees of freedom and its
//! pose region d = 3; a 3-D topic's d = 3 and d = 6 ([CONVENTIONS §7](crate::conventions)).
//!
//! ```
//! use posecov::eval::log::{LogEvalSettings, evaluate_log};
//! use posecov::input::log::{LogOptions, read_log};
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/robot_localization/test2.bag");
//! let mut plan = read_log(path.as_ref(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
//! let e = evaluate_log(&mut plan, &LogEvalSettings::default());
//! let odom = &e.topics[0];
//! assert_eq!((odom.group.position_dims(), odom.group.dof()), (2, 3));
//! assert!(odom.poses.iter().all(|p| p.state.is_drawable()));
//! ```

pub mod frames;
mod meaning;
pub mod nees;
pub mod sensor;
pub mod sensor_shapes;
pub mod stamped;

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Matrix6};

use crate::interop::RosReading;
use crate::lie::{GroupKind, Se2, Se3, So3};
use serde::Serialize;

use self::frames::{
    FrameFindings, FrameJoin, FrameProblem, FrameProblemKind, TopicFrame, join_plan, move_topic,
};
use self::meaning::{meaning, readings_apart};
use crate::plan::log::{
    AxisStats, DrawnMessage, Issue, LogSummary, SeriesPoint, TopicSummary, TrackPoint,
};
use crate::sample::{Sampler, chunk_rng};
use crate::uncertain::UncertainPose;

/// Samples drawn per message by default (a cloud per drawn message).
pub const DEFAULT_CLOUD_SAMPLES: usize = 100;

/// The random family of sensor topic k's orientation spray is this + k (pose topic k's clouds
/// are family k).
pub const SPRAY_FAMILY: u64 = 1 << 32;

/// What evaluating a log needs.
#[derive(Debug, Clone, PartialEq)]
pub struct LogEvalSettings {
    /// Seed of every cloud (topic k, message i draw from stream (seed, k, i)).
    pub seed: u64,
    /// Samples per drawn message.
    pub cloud_samples: usize,
    /// How each message's 6×6 covariance is read ([`RosReading`], CONVENTIONS §6).
    pub reading: RosReading,
}

impl Default for LogEvalSettings {
    fn default() -> Self {
        Self {
            seed: 0,
            cloud_samples: DEFAULT_CLOUD_SAMPLES,
            reading: RosReading::default(),
        }
    }
}

/// What RViz draws from one message (its `CovarianceVisual`): the position block in the parent
/// frame's axes, the rotation block, and whether it decides the pose is 2-D (Σzz, Σroll,
/// Σpitch all ≤ 0 — placeholders make it draw in 3-D).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RvizNumbers {
    /// Σ of (x, y, z), parent axes.
    pub position_cov: Matrix3<f64>,
    /// Σ of (roll, pitch, yaw), body axes.
    pub rotation_cov: Matrix3<f64>,
    /// RViz's 2-D rule.
    pub pose_2d: bool,
}

/// One drawn message's meaning.
#[derive(Debug, Clone, PartialEq)]
pub enum PoseState {
    /// Planar: x, y, yaw as SE(2), body-frame right form, with its cloud.
    Planar {
        /// The Gaussian.
        pose: UncertainPose<Se2, 3>,
        /// Samples μ · Exp(ε).
        cloud: Vec<Se2>,
    },
    /// 3-D: SE(3), body-frame right form, with its cloud.
    Spatial {
        /// The Gaussian (boxed: 6 × 6).
        pose: Box<UncertainPose<Se3, 6>>,
        /// Samples μ · Exp(ε).
        cloud: Vec<Se3>,
    },
    /// Not a Gaussian posecov can draw: why.
    Invalid {
        /// The issues (or a placeholder in a 3-D topic).
        issues: Vec<Issue>,
    },
}

impl PoseState {
    /// Whether it is drawn as a Gaussian.
    pub fn is_drawable(&self) -> bool {
        !matches!(self, PoseState::Invalid { .. })
    }
}

/// One drawn message.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseEvaluation {
    /// Index on the topic.
    pub index: u64,
    /// Stamp, ns.
    pub stamp_ns: i64,
    /// The message's pose as published (`None`: not finite / not a rotation).
    pub mean: Option<Se3>,
    /// What the covariance means.
    pub state: PoseState,
    /// RViz's numbers (`None` when the covariance is not finite).
    pub rviz: Option<RvizNumbers>,
    /// σ = √Σᵢᵢ per ROS axis (x, y, z in the parent's axes, m; roll, pitch, yaw, rad) where
    /// the axis is estimated: finite, neither a placeholder (≥ 1e6) nor zero. As published: in
    /// the topic's own frame's axes, also when it is drawn joined to another frame.
    pub sigma: [Option<f64>; 6],
}

/// One axis's σ over a topic: first, last, smallest and largest over every message where the
/// axis is estimated (streamed while reading, [`AxisStats`]), and the median over the kept
/// series (the values a median needs are only kept there, bounded).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SigmaSummary {
    /// Messages counted (every message where the axis is estimated).
    pub messages: u64,
    /// σ of the first such message.
    pub first: f64,
    /// σ of the last.
    pub last: f64,
    /// Smallest σ.
    pub min: f64,
    /// The median σ of the kept series (`None` when none of its points estimates the axis).
    pub median_of_kept: Option<f64>,
    /// Largest σ.
    pub max: f64,
}

/// The σ summary of ROS axis `axis` (0..6) of a topic: its streamed statistics and the median
/// of the kept series (the mean of the two middle values for an even count).
///
/// ```
/// use posecov::eval::log::sigma_summary;
/// use posecov::plan::log::{AxisStats, SeriesPoint};
/// let mut stats = None;
/// let series: Vec<SeriesPoint> = [0.3, 0.1, 0.2, 0.4]
///     .into_iter()
///     .map(|s| {
///         AxisStats::add(&mut stats, s);
///         SeriesPoint { stamp_ns: 0, sigma: [Some(s), None, None, None, None, None], position_trace: None }
///     })
///     .collect();
/// let x = sigma_summary(stats, &series, 0).unwrap();
/// assert_eq!((x.first, x.last, x.min, x.max), (0.3, 0.4, 0.1, 0.4));
/// assert!((x.median_of_kept.unwrap() - 0.25).abs() < 1e-15);
/// assert_eq!(sigma_summary(None, &series, 1), None);
/// ```
pub fn sigma_summary(
    stats: Option<AxisStats>,
    series: &[SeriesPoint],
    axis: usize,
) -> Option<SigmaSummary> {
    summary_of(stats, series.iter().filter_map(|p| p.sigma[axis]).collect())
}

/// The σ summary of streamed `stats` and the `kept` σ's of the series (their median).
fn summary_of(stats: Option<AxisStats>, mut kept: Vec<f64>) -> Option<SigmaSummary> {
    let stats = stats?;
    kept.sort_by(f64::total_cmp);
    let n = kept.len();
    let median_of_kept = match n {
        0 => None,
        _ if n % 2 == 1 => Some(kept[n / 2]),
        _ => Some(0.5 * (kept[n / 2 - 1] + kept[n / 2])),
    };
    Some(SigmaSummary {
        messages: stats.messages,
        first: stats.first,
        last: stats.last,
        min: stats.min,
        median_of_kept,
        max: stats.max,
    })
}

/// One topic's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicEvaluation {
    /// Topic name.
    pub name: String,
    /// The frame its poses are in (`header.frame_id` of its first message; may be empty).
    pub frame_id: String,
    /// The topic's group: SE(2) drawn in the x–y plane, or SE(3). The position region has
    /// [`GroupKind::position_dims`] degrees of freedom (2 or 3), the pose region
    /// [`GroupKind::dof`] (3 or 6).
    pub group: GroupKind,
    /// Drawn messages.
    pub poses: Vec<PoseEvaluation>,
    /// How far apart the two ROS readings put the drawn messages' right-form covariances:
    /// the largest ‖Σ_tf2 − Σ_body‖_F / ‖Σ_tf2‖_F (0 for planar topics, where they coincide).
    pub reading_difference: f64,
    /// Trajectory (stamp ns, position).
    pub trajectory: Vec<TrackPoint>,
    /// Time series.
    pub series: Vec<SeriesPoint>,
    /// σ per ROS axis (x, y, z, roll, pitch, yaw; m and rad), `None` where never estimated.
    pub sigma: [Option<SigmaSummary>; 6],
    /// NEES against the reference (`--reference`), streamed over every message
    /// ([`crate::eval::log::nees`]); `None` without a reference, or for the reference topic itself.
    pub consistency: Option<crate::eval::log::nees::TopicConsistency>,
    /// Drawn in another frame than its own, joined through the log's `/tf`
    /// ([`crate::eval::log::frames`]): `frame_id` is then the common frame.
    pub joined: Option<FrameJoin>,
}

/// A log's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct LogEvaluation {
    /// Per topic, in the plan's order.
    pub topics: Vec<TopicEvaluation>,
    /// The ROS reading every covariance was read in.
    pub reading: RosReading,
    /// What kept topics in different frames apart ([`crate::eval::log::frames`]).
    pub frames: FrameFindings,
    /// Per sensor topic, in the plan's order ([`sensor`]).
    pub sensors: Vec<sensor::SensorEvaluation>,
}

impl LogEvaluation {
    /// Attaches each topic's NEES ([`crate::eval::log::nees::NeesObserver::finish`]) by name.
    pub fn with_consistency(
        mut self,
        results: BTreeMap<String, crate::eval::log::nees::TopicConsistency>,
    ) -> Self {
        for (name, c) in results {
            if let Some(t) = self.topics.iter_mut().find(|t| t.name == name) {
                t.consistency = Some(c);
            }
        }
        self
    }
}

/// A topic's measured messages, as the evaluation takes them: moved out of its
/// [`TopicSummary`] (whose counts, health and stamps stay), never copied.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TopicMessages {
    /// The frame they are in (the topic's `frame_id`; the common frame once joined).
    pub frame_id: String,
    /// The drawn messages.
    pub drawn: Vec<DrawnMessage>,
    /// The trajectory (stamp ns, position).
    pub trajectory: Vec<TrackPoint>,
    /// The σ time series.
    pub series: Vec<SeriesPoint>,
}

impl TopicMessages {
    /// Moves `topic`'s drawn messages, trajectory and series out (they are empty in `topic`
    /// afterwards).
    ///
    /// ```
    /// use posecov::eval::log::TopicMessages;
    /// use posecov::input::{locate, log::{LogOptions, read_located}};
    /// let mut log = read_located(&locate("jackal_odometry").unwrap(), &LogOptions::default(), &mut |_, _| {}, None).unwrap();
    /// let n = log.topics[0].drawn.len();
    /// let m = TopicMessages::take(&mut log.topics[0]);
    /// assert!(m.drawn.len() == n && n > 0 && log.topics[0].drawn.is_empty());
    /// ```
    pub fn take(topic: &mut TopicSummary) -> Self {
        TopicMessages {
            frame_id: topic.frame_id.clone(),
            drawn: std::mem::take(&mut topic.drawn),
            trajectory: std::mem::take(&mut topic.trajectory),
            series: std::mem::take(&mut topic.series),
        }
    }
}

/// Evaluates every topic of a log. Each topic's drawn messages, trajectory and series move
/// into its evaluation ([`TopicMessages::take`]): `plan` keeps the counts, health, stamps and
/// `/tf` that the report and the text panel read, and those three are empty afterwards.
///
/// See the [module docs](self) for an example.
pub fn evaluate_log(plan: &mut LogSummary, settings: &LogEvalSettings) -> LogEvaluation {
    let named: Vec<TopicFrame<'_>> = plan
        .topics
        .iter()
        .map(|t| TopicFrame {
            topic: &t.name,
            frame_id: &t.frame_id,
            first_stamp_ns: t.stamp_range.map(|r| r.first_ns),
        })
        .collect();
    let joins = join_plan(&plan.tf, &named);
    let mut problems = joins.problems;
    let tf = &plan.tf;
    let topics = plan
        .topics
        .iter_mut()
        .zip(joins.chains)
        .enumerate()
        .map(|(k, (t, chain))| {
            let mut messages = TopicMessages::take(t);
            // σ per axis as published, in the topic's own frame's axes (as its plots, report
            // and check give them), taken before the messages move.
            let published: Vec<(u64, [Option<f64>; 6])> = messages
                .drawn
                .iter()
                .map(|d| (d.index, message_sigma(d)))
                .collect();
            let joined =
                match chain.map(|c| move_topic(tf, &c, t.group, &mut messages, settings.reading)) {
                    Some(Ok(join)) => Some(join),
                    Some(Err(stamp)) => {
                        problems.push(FrameProblem {
                            kind: FrameProblemKind::TiltsPlane,
                            frames: vec![t.frame_id.clone()],
                            roots: Vec::new(),
                            topics: vec![t.name.clone()],
                            source: "/tf".to_owned(),
                            stamp_ns: Some(stamp),
                        });
                        None
                    }
                    None => None,
                };
            let mut e = evaluate_topic(k as u64, t, messages, settings);
            if joined.is_some() {
                for p in &mut e.poses {
                    if let Ok(at) = published.binary_search_by_key(&p.index, |(i, _)| *i) {
                        p.sigma = published[at].1;
                    }
                }
            }
            TopicEvaluation { joined, ..e }
        })
        .collect();
    LogEvaluation {
        topics,
        sensors: plan
            .sensors
            .iter_mut()
            .enumerate()
            .map(|(k, t)| {
                let mut e = sensor::evaluate_sensor(t);
                e.orientation = t.drawn.orientation.as_ref().and_then(|o| {
                    let family = SPRAY_FAMILY + k as u64;
                    let n = settings.cloud_samples;
                    sensor_shapes::orientation_spray(o, settings.reading, settings.seed, family, n)
                });
                e
            })
            .collect(),
        reading: settings.reading,
        frames: FrameFindings {
            has_tf: !plan.tf.edges.is_empty(),
            problems,
        },
    }
}

fn evaluate_topic(
    family: u64,
    topic: &TopicSummary,
    messages: TopicMessages,
    settings: &LogEvalSettings,
) -> TopicEvaluation {
    let mut reading_difference: f64 = 0.0;
    let planar = topic.group.is_planar();
    let poses = messages
        .drawn
        .iter()
        .map(|d| {
            let m = &d.message;
            let finite = m.covariance.iter().all(|v| v.is_finite());
            let cov_ros = Matrix6::from_row_slice(&m.covariance);
            let rotation = So3::try_from_quaternion_xyzw(m.orientation_xyzw).ok();
            let mean = rotation
                .filter(|_| m.position.iter().all(|v| v.is_finite()))
                .map(|r| Se3::from_parts(m.position.into(), r));
            let rviz = finite.then(|| RvizNumbers {
                position_cov: cov_ros.fixed_view::<3, 3>(0, 0).into_owned(),
                rotation_cov: cov_ros.fixed_view::<3, 3>(3, 3).into_owned(),
                pose_2d: m.covariance[14] <= 0.0
                    && m.covariance[21] <= 0.0
                    && m.covariance[28] <= 0.0,
            });
            let state = match (mean, d.unusable.is_empty()) {
                (Some(mean), true) => {
                    if !planar && finite {
                        reading_difference =
                            reading_difference.max(readings_apart(&mean, &cov_ros));
                    }
                    meaning(&mean, &cov_ros, &d.unestimated, planar, settings.reading).map_or_else(
                        |issues| PoseState::Invalid { issues },
                        |state| with_cloud(state, settings, family, d.index),
                    )
                }
                _ => PoseState::Invalid {
                    issues: if d.unusable.is_empty() {
                        vec![Issue::BadOrientation]
                    } else {
                        d.unusable.clone()
                    },
                },
            };
            let sigma = message_sigma(d);
            PoseEvaluation {
                index: d.index,
                stamp_ns: m.stamp_ns,
                mean,
                state,
                rviz,
                sigma,
            }
        })
        .collect();
    TopicEvaluation {
        name: topic.name.clone(),
        frame_id: messages.frame_id,
        group: topic.group,
        poses,
        reading_difference,
        sigma: std::array::from_fn(|axis| {
            sigma_summary(topic.sigma_stats[axis], &messages.series, axis)
        }),
        trajectory: messages.trajectory,
        series: messages.series,
        consistency: None,
        joined: None,
    }
}

/// σ = √Σᵢᵢ per ROS axis of a message where the axis is estimated.
fn message_sigma(d: &DrawnMessage) -> [Option<f64>; 6] {
    std::array::from_fn(|i| {
        let v = d.message.covariance[i * 7];
        (v.is_finite() && v >= 0.0 && !d.unestimated[i]).then(|| v.sqrt())
    })
}

fn with_cloud(state: PoseState, settings: &LogEvalSettings, family: u64, index: u64) -> PoseState {
    let mut rng = chunk_rng(settings.seed, family, index);
    let n = settings.cloud_samples;
    match state {
        PoseState::Planar { pose, .. } => match Sampler::new(&pose) {
            Ok(s) => PoseState::Planar {
                cloud: s.draw_many(&mut rng, n),
                pose,
            },
            Err(_) => PoseState::Invalid {
                issues: vec![Issue::NonFinite],
            },
        },
        PoseState::Spatial { pose, .. } => match Sampler::new(&pose) {
            Ok(s) => PoseState::Spatial {
                cloud: s.draw_many(&mut rng, n),
                pose,
            },
            Err(_) => PoseState::Invalid {
                issues: vec![Issue::NonFinite],
            },
        },
        invalid => invalid,
    }
}
