//! Settings resolved once: each value from the command line, else the file, else the
//! default, and each stage gets only its own ([`EvalSettings`], [`DrawSettings`]).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::draw::DrawSettings;
use crate::eval::EvalSettings;
use crate::eval::graph::{GraphReading, GraphSettings, Optimizer};
use crate::eval::log::nees::Align;
use crate::eval::log::{DEFAULT_CLOUD_SAMPLES, LogEvalSettings};
use crate::input::log::LogOptions;
use crate::input::{Input, InputKind};
use crate::interop::RosReading;
use crate::plan::{StepPolicy, limits};
use crate::uncertain::Confidence;

pub use crate::plan::limits::DEFAULT_SAMPLES;
/// At most this many cloud samples per drawn message of a robot log (`--samples`).
pub const MAX_CLOUD_SAMPLES: u64 = 10_000;

/// Values given on the command line (or by any other front end), overriding the file's.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// `--seed`.
    pub seed: Option<u64>,
    /// `--samples`.
    pub samples: Option<u64>,
    /// `--confidence` (a probability in (0, 1) by its type: checked where it is parsed).
    pub confidence: Option<Confidence>,
    /// `--block-samples`.
    pub block_samples: Option<u64>,
    /// `--topic` (repeatable; robot logs only): the topics to read.
    pub topics: Vec<String>,
    /// `--every N` (robot logs only): draw every N-th message.
    pub every: Option<u64>,
    /// `--ros-reading` (robot logs only): how a PoseWithCovariance's 6×6 is read
    /// ([`RosReading`], CONVENTIONS §6); `None`: tf2's.
    pub ros_reading: Option<RosReading>,
    /// `--reference` (robot logs only): the ground truth to take NEES against, as given
    /// ([`ReferenceArg::parse`]).
    pub reference: Option<String>,
    /// `--align` (robot logs with `--reference`): how the reference is aligned first.
    pub align: Option<Align>,
    /// Which steps of long propagations are kept (no flag: live mode's quick preview thins
    /// them); `None`: [`StepPolicy::default`].
    pub steps: Option<StepPolicy>,
    /// `--graph-reading` (pose graphs).
    pub graph_reading: Option<GraphReading>,
    /// `--optimizer` (pose graphs).
    pub optimizer: Option<Optimizer>,
    /// `--joint A,B` (repeatable; pose graphs): vertex ids whose joint marginal is wanted.
    pub joints: Vec<(u64, u64)>,
    /// `--duration`, `--messages`, `--record` (a live stream, `ws://…`, only).
    pub live: crate::input::log::ws::LiveOptions,
}

/// What an input is, as far as flags go: a scenario or a pose graph (both plans), or a robot
/// log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Given {
    /// A TOML scenario.
    Scenario,
    /// A g2o / GTSAM pose graph.
    PoseGraph,
    /// A robot log.
    Log,
}

impl Given {
    /// The input in words ("this input is a robot log").
    ///
    /// ```
    /// assert_eq!(posecov::app::Given::PoseGraph.name(), "a pose graph");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Given::Scenario => "a scenario",
            Given::PoseGraph => "a pose graph",
            Given::Log => InputKind::Log.name(),
        }
    }

    /// What a plan input is: a pose graph if its plan carries one.
    fn of(input: &Input) -> Self {
        if input.plan.graph_vertex_ids().is_some() {
            Given::PoseGraph
        } else {
            Given::Scenario
        }
    }
}

/// The inputs a flag applies to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AppliesTo {
    /// Scenarios and pose graphs ([`InputKind::Plan`]).
    Plans,
    /// Pose graphs only.
    PoseGraphs,
    /// Robot logs ([`InputKind::Log`]).
    Logs,
}

impl AppliesTo {
    /// Those inputs in words ("applies to pose graphs").
    ///
    /// ```
    /// assert_eq!(posecov::app::AppliesTo::PoseGraphs.name_plural(), "pose graphs (g2o / GTSAM files)");
    /// ```
    pub fn name_plural(self) -> &'static str {
        match self {
            AppliesTo::Plans => InputKind::Plan.name_plural(),
            AppliesTo::PoseGraphs => "pose graphs (g2o / GTSAM files)",
            AppliesTo::Logs => InputKind::Log.name_plural(),
        }
    }

    fn admits(self, given: Given) -> bool {
        match self {
            AppliesTo::Plans => given != Given::Log,
            AppliesTo::PoseGraphs => given == Given::PoseGraph,
            AppliesTo::Logs => given == Given::Log,
        }
    }
}

/// A command-line value the input cannot take: names the flag, the value and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A value out of range.
    #[error("{flag} {value}: out of range: {expected}")]
    OutOfRange {
        /// The flag, e.g. `--samples`.
        flag: &'static str,
        /// The value given.
        value: String,
        /// What is accepted.
        expected: String,
    },
    /// A flag for another kind of input (`--every` on a scenario, `--optimizer` on a log).
    #[error("{flag} {value}: applies to {} only ({why}); this input is {}", .applies_to.name_plural(), .given.name())]
    DoesNotApply {
        /// The flag.
        flag: &'static str,
        /// The value given.
        value: String,
        /// The inputs it applies to.
        applies_to: AppliesTo,
        /// The input given.
        given: Given,
        /// What the flag does.
        why: &'static str,
    },
    /// `--joint` names a vertex the pose graph does not have, or the same vertex twice.
    #[error("{flag} {value}: {reason}")]
    Vertex {
        /// The flag.
        flag: &'static str,
        /// The value given.
        value: String,
        /// What is wrong, with the ids the graph has.
        reason: String,
    },
}

/// The flags that apply to one kind of input only, what each does, and its value: the one
/// table every input's flags are checked against.
fn kind_flags(
    overrides: &Overrides,
) -> [(&'static str, AppliesTo, &'static str, Option<String>); 10] {
    [
        (
            "--reference",
            AppliesTo::Logs,
            "it is the ground truth a log's estimates are compared with (NEES); a scenario's uncertainty is checked against its own Monte Carlo",
            overrides.reference.clone(),
        ),
        (
            "--align",
            AppliesTo::Logs,
            "it aligns a log's --reference to its estimates",
            overrides.align.map(|a| a.name().to_owned()),
        ),
        (
            "--topic",
            AppliesTo::Logs,
            "it picks which of a log's topics to read",
            overrides.topics.first().cloned(),
        ),
        (
            "--every",
            AppliesTo::Logs,
            "it draws every N-th message of a log",
            overrides.every.map(|n| n.to_string()),
        ),
        (
            "--ros-reading",
            AppliesTo::Logs,
            "it says how a log's PoseWithCovariance covariances are read (a scenario says it with `reading` in a pose's `cov`)",
            overrides.ros_reading.map(|r| r.name().to_owned()),
        ),
        (
            // --duration, --messages, --record: a live stream's (a file refuses them where it
            // is read, `input::log::read_located`).
            overrides
                .live
                .first_flag()
                .map_or("--duration", |(flag, _)| flag),
            AppliesTo::Logs,
            "it says how long to read a running robot's topics (ws://HOST:PORT) and where to record them",
            overrides.live.first_flag().map(|(_, value)| value),
        ),
        (
            "--block-samples",
            AppliesTo::Plans,
            "Monte Carlo particles held at once; a log draws one cloud of --samples points per message",
            overrides.block_samples.map(|n| n.to_string()),
        ),
        (
            "--graph-reading",
            AppliesTo::PoseGraphs,
            "it says how a g2o file's information matrices are read, as g2o or as GTSAM does",
            overrides.graph_reading.map(|r| r.name().to_owned()),
        ),
        (
            "--optimizer",
            AppliesTo::PoseGraphs,
            "it picks the optimiser of a pose graph, Levenberg–Marquardt or Gauss–Newton",
            overrides.optimizer.map(|o| o.name().to_owned()),
        ),
        (
            "--joint",
            AppliesTo::PoseGraphs,
            "it asks for the joint marginal of two poses of a pose graph",
            overrides.joints.first().map(|&(a, b)| joint_text(a, b)),
        ),
    ]
}

/// `--joint`'s value as it is written: `A,B`.
fn joint_text(a: u64, b: u64) -> String {
    format!("{a},{b}")
}

/// Checks every `--joint` pair against the graph's vertex ids (ascending): two different
/// vertices it has.
fn check_joints(joints: &[(u64, u64)], ids: &[u64]) -> Result<(), SettingsError> {
    for &(a, b) in joints {
        let error = |reason: String| SettingsError::Vertex {
            flag: "--joint",
            value: joint_text(a, b),
            reason,
        };
        if a == b {
            return Err(error(format!(
                "name two different vertices (the marginal of v{a} alone is in every report)"
            )));
        }
        if let Some(id) = [a, b].into_iter().find(|id| ids.binary_search(id).is_err()) {
            let range = match (ids.first(), ids.last()) {
                (Some(first), Some(last)) => {
                    format!("{} vertices, ids {first} ..= {last}", ids.len())
                }
                _ => "no vertices".to_owned(),
            };
            return Err(error(format!(
                "this pose graph has no vertex {id} ({range})"
            )));
        }
    }
    Ok(())
}

/// Refuses the first flag given that does not apply to the input `given`, naming it and what
/// it is for.
fn check_flags(given: Given, overrides: &Overrides) -> Result<(), SettingsError> {
    for (flag, applies_to, why, value) in kind_flags(overrides) {
        if let Some(value) = value
            && !applies_to.admits(given)
        {
            return Err(SettingsError::DoesNotApply {
                flag,
                value,
                applies_to,
                given,
                why,
            });
        }
    }
    Ok(())
}

/// Everything the stages need, resolved.
#[derive(Debug, Clone)]
pub struct Settings {
    /// For [`crate::eval::evaluate`].
    pub eval: EvalSettings,
    /// For [`crate::draw::scene`].
    pub draw: DrawSettings,
}

/// What [`resolve`] resolves settings for: a plan's [`Input`] (`&Input`: its file's values
/// under the flags) or a robot log ([`RobotLog`]: the flags alone, a log file has no settings
/// of its own). Each gives its kind as far as flags go and its own values.
///
/// ```
/// use posecov::app::{Given, Overrides, RobotLog, Target, load};
/// let loaded = load("gtsam_pose2example").unwrap();
/// assert_eq!((&loaded.input).given(), Given::PoseGraph);
/// assert_eq!(RobotLog.given(), Given::Log);
/// assert_eq!(RobotLog.values(&Overrides::default(), None).unwrap().eval.cloud_samples, 100);
/// ```
pub trait Target {
    /// The settings it runs with: [`Settings`] for a plan, [`LogSettings`] for a log.
    type Settings;
    /// What it is, as far as flags go.
    fn given(&self) -> Given;
    /// Its values under `overrides`, the flags already checked against the one table.
    ///
    /// # Errors
    /// A flag's value out of range, named by the flag.
    fn values(
        self,
        overrides: &Overrides,
        cancel: Option<Arc<AtomicBool>>,
    ) -> Result<Self::Settings, SettingsError>;
}

/// A robot log, as [`resolve`] sees it: the flags alone (`--samples` is the cloud drawn per
/// message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RobotLog;

impl Target for &Input {
    type Settings = Settings;

    fn given(&self) -> Given {
        Given::of(self)
    }

    fn values(
        self,
        overrides: &Overrides,
        cancel: Option<Arc<AtomicBool>>,
    ) -> Result<Settings, SettingsError> {
        plan_settings(self, overrides, cancel)
    }
}

impl Target for RobotLog {
    type Settings = LogSettings;

    fn given(&self) -> Given {
        Given::Log
    }

    fn values(
        self,
        overrides: &Overrides,
        _cancel: Option<Arc<AtomicBool>>,
    ) -> Result<LogSettings, SettingsError> {
        log_settings(overrides)
    }
}

/// The one settings resolver: flags over the file's values over defaults. Every flag is first
/// checked against the one table of flags that apply to one kind of input only (the other kind
/// refuses it by name, saying what it is for); then the target's own values are checked and
/// resolved — a plan's `--samples` is its Monte Carlo sample, a log's the cloud drawn per
/// message. Values in a file were checked when it was read.
///
/// ```
/// use posecov::app::{Overrides, RobotLog, load, resolve};
/// let loaded = load("camera_on_robot").unwrap();
/// let e = resolve(&loaded.input, &Overrides { samples: Some(1), ..Default::default() }, None).unwrap_err();
/// assert_eq!(e.to_string(), "--samples 1: out of range: use 2 ..= 10000000");
/// let every = Overrides { every: Some(3), ..Default::default() };
/// let e = resolve(&loaded.input, &every, None).unwrap_err();
/// assert!(e.to_string().starts_with("--every 3: applies to robot logs (ROS 1 bags, MCAP files, ROS 2 SQLite bags) only"), "{e}");
/// assert!(resolve(RobotLog, &every, None).is_ok());
/// let s = resolve(&loaded.input, &Overrides { seed: Some(9), ..Default::default() }, None).unwrap();
/// assert_eq!(s.eval.seed, 9);
/// let blocks = Overrides { block_samples: Some(4096), ..Default::default() };
/// let e = resolve(RobotLog, &blocks, None).unwrap_err();
/// assert!(e.to_string().starts_with("--block-samples 4096: applies to scenarios and pose graphs only"), "{e}");
/// assert_eq!(resolve(RobotLog, &Overrides::default(), None).unwrap().eval.cloud_samples, 100);
/// ```
///
/// # Errors
/// A flag the target cannot take, or a value out of range, named by the flag.
pub fn resolve<T: Target>(
    target: T,
    overrides: &Overrides,
    cancel: Option<Arc<AtomicBool>>,
) -> Result<T::Settings, SettingsError> {
    check_flags(target.given(), overrides)?;
    target.values(overrides, cancel)
}

/// A plan's values, its flags checked against the table already ([`resolve`]).
fn plan_settings(
    input: &Input,
    overrides: &Overrides,
    cancel: Option<Arc<AtomicBool>>,
) -> Result<Settings, SettingsError> {
    let file = &input.defaults;
    if let Some(ids) = input.plan.graph_vertex_ids() {
        check_joints(&overrides.joints, &ids)?;
    }
    if let Some(n) = overrides.samples
        && let Err(expected) = limits::check_samples(n)
    {
        return Err(SettingsError::OutOfRange {
            flag: "--samples",
            value: n.to_string(),
            expected,
        });
    }
    if let Some(b) = overrides.block_samples
        && !(1..=limits::MAX_SAMPLES).contains(&b)
    {
        return Err(SettingsError::OutOfRange {
            flag: "--block-samples",
            value: b.to_string(),
            expected: format!("use 1 ..= {}", limits::MAX_SAMPLES),
        });
    }
    let samples = overrides
        .samples
        .or(file.samples)
        .unwrap_or(DEFAULT_SAMPLES);
    let confidence = overrides
        .confidence
        .or(file.confidence)
        .unwrap_or(Confidence::DEFAULT);
    let steps = overrides.steps.or(file.steps).unwrap_or_default();
    Ok(Settings {
        eval: EvalSettings {
            seed: overrides.seed.or(file.seed).unwrap_or(0),
            samples: samples as usize,
            methods: file.methods.clone(),
            block_samples: overrides.block_samples.map(|b| b as usize),
            steps,
            confidence,
            unscented: file.sigma_points.unwrap_or_default(),
            cancel,
            graph: GraphSettings {
                optimizer: overrides.optimizer.unwrap_or_default(),
                reading: overrides.graph_reading.unwrap_or_default(),
                joints: overrides.joints.clone(),
                // Chosen by what the run is for (`RunOptions::step_marginals`).
                step_marginals: Default::default(),
            },
            graph_progress: None,
            monte_carlo_progress: None,
        },
        draw: DrawSettings {
            about: input.about.clone(),
            confidence,
            choices: input.draw.clone(),
            steps,
        },
    })
}

/// `--reference VALUE` as given: `topic:NAME`, `file:PATH`, `tf:CHILD`, or a bare value that
/// is a topic of the log or else an existing file (decided once the log is read; both or
/// neither is refused).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReferenceArg {
    /// `topic:NAME`.
    Topic(String),
    /// `file:PATH`: a TUM trajectory.
    File(String),
    /// `tf:CHILD`: the child frame's transforms in `/tf`.
    Tf(String),
    /// A bare value.
    Either(String),
}

impl ReferenceArg {
    /// Reads the flag's value by its prefix.
    ///
    /// ```
    /// use posecov::app::ReferenceArg;
    /// assert_eq!(ReferenceArg::parse("tf:base_link").unwrap(), ReferenceArg::Tf("base_link".into()));
    /// assert_eq!(ReferenceArg::parse("/ground_truth").unwrap(), ReferenceArg::Either("/ground_truth".into()));
    /// assert!(ReferenceArg::parse("topic:").is_err());
    /// ```
    pub fn parse(value: &str) -> Result<Self, SettingsError> {
        let named = |rest: &str, what: &str, make: fn(String) -> ReferenceArg| {
            if rest.is_empty() {
                Err(SettingsError::OutOfRange {
                    flag: "--reference",
                    value: value.to_owned(),
                    expected: format!("name {what} after the prefix"),
                })
            } else {
                Ok(make(rest.to_owned()))
            }
        };
        if let Some(rest) = value.strip_prefix("topic:") {
            named(rest, "a topic of the log", ReferenceArg::Topic)
        } else if let Some(rest) = value.strip_prefix("file:") {
            named(rest, "a TUM trajectory file", ReferenceArg::File)
        } else if let Some(rest) = value.strip_prefix("tf:") {
            named(rest, "a child frame in /tf", ReferenceArg::Tf)
        } else if value.is_empty() {
            named(
                value,
                "a topic, `tf:CHILD` or a TUM file",
                ReferenceArg::Either,
            )
        } else {
            Ok(ReferenceArg::Either(value.to_owned()))
        }
    }
}

/// A log's reference and alignment, resolved from the flags.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceSettings {
    /// Where the truth comes from.
    pub arg: ReferenceArg,
    /// The alignment (none by default).
    pub align: Align,
}

/// Everything reading, evaluating and drawing a robot log needs, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct LogSettings {
    /// `--reference` and `--align`: NEES against a ground truth, if asked for.
    pub reference: Option<ReferenceSettings>,
    /// For [`crate::input::log::read_located`]: topics and thinning.
    pub read: LogOptions,
    /// For [`crate::eval::log::evaluate_log`]: seed and cloud samples.
    pub eval: LogEvalSettings,
    /// Probability inside drawn regions.
    pub confidence: Confidence,
}

/// A robot log's values, its flags checked against the table already ([`resolve`]):
/// `--samples` is the cloud drawn per message.
fn log_settings(overrides: &Overrides) -> Result<LogSettings, SettingsError> {
    let samples = overrides.samples.unwrap_or(DEFAULT_CLOUD_SAMPLES as u64);
    if !(1..=MAX_CLOUD_SAMPLES).contains(&samples) {
        return Err(SettingsError::OutOfRange {
            flag: "--samples",
            value: samples.to_string(),
            expected: format!("1 ..= {MAX_CLOUD_SAMPLES} samples per drawn message of a robot log"),
        });
    }
    let reference = match &overrides.reference {
        Some(value) => Some(ReferenceSettings {
            arg: ReferenceArg::parse(value)?,
            align: overrides.align.unwrap_or_default(),
        }),
        None => {
            if let Some(align) = overrides.align {
                return Err(SettingsError::OutOfRange {
                    flag: "--align",
                    value: align.name().to_owned(),
                    expected: "it aligns a --reference, and none is given".to_owned(),
                });
            }
            None
        }
    };
    Ok(LogSettings {
        reference,
        read: LogOptions {
            topics: overrides.topics.clone(),
            every: overrides.every,
            reference: None,
            live: overrides.live.clone(),
        },
        eval: LogEvalSettings {
            seed: overrides.seed.unwrap_or(0),
            cloud_samples: samples as usize,
            reading: overrides.ros_reading.unwrap_or_default(),
        },
        confidence: overrides.confidence.unwrap_or(Confidence::DEFAULT),
    })
}
