//! The typed plan: what to evaluate, with every value checked and every name resolved.
//!
//! A [`Plan`] is the contract between an input format and the evaluation. An input module
//! (`input::scenario` for TOML files) does every check with its own locations and produces
//! a plan; [`crate::eval::evaluate`] takes a plan and settings and computes numbers. A plan
//! holds no spans, no key names and no strings to parse: poses are group elements,
//! covariances are validated matrices, operands are [`Operand`]s resolved to a known
//! transform or to an earlier definition.
//!
//! Definitions are numbered in order: the plan's [`poses`](Plan::poses) first, then one per
//! [`operation`](Plan::operations) (its output). An [`Operand::Defined`] holds that number.
//!
//! A plan can also be built in code:
//!
//! ```
//! use posecov::lie::{LieGroup, Se2};
//! use posecov::plan::{Op, Operand, Plan};
//! use posecov::uncertain::{Side, UncertainPose};
//! let robot = UncertainPose::try_from_std_devs(Se2::from_xy_theta(2.0, 1.0, 0.5), [0.05, 0.05, 0.3], Side::Right).unwrap();
//! let mut plan = Plan::<Se2, 3>::default();
//! let map_from_robot = plan.uncertain("map_from_robot", robot);
//! let robot_from_camera = Se2::from_xy_theta(1.5, 0.0, 0.0);
//! plan.operation("map_from_camera", Op::Compose { lhs: map_from_robot, rhs: Operand::Known(robot_from_camera), cross_cov: None });
//! assert_eq!(plan.definitions(), 2);
//! ```
//!
//! Here: `Plan<G>` (poses, `Op`s with typed values and resolved operands), `StepPolicy` (`plan/steps.rs`:
//! which steps keep numbers, particles and Monte Carlo statistics; a pose graph's
//! `StepPolicy::GRAPH`), `limits` (sizes refused up front); `plan/log.rs`:
//! `LogSummary`, a robot log as bounded data (topics, health counts, drawn messages, series; no
//! container format, no words; `plan/log/health.rs` the one table of health findings); graph, thinning, `/tf`, reference: `plan/`'s module docs. Not
//! here: spans, key names, strings to parse, words for users.

use nalgebra::{Matrix3, Vector3};

pub mod choices;
pub mod graph;
pub mod log;
mod steps;

pub use steps::StepPolicy;

use crate::lie::{LieGroup, Se2, Se3, So2, So3, Tangent, TangentMatrix};
pub use crate::propagate::odometry::StepNoise;
use crate::uncertain::{Side, UncertainPose};

/// What an operation reads: a known transform, or an earlier definition (an uncertain input
/// or an operation's output) by its number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Operand<G> {
    /// A transform known exactly (a pose given without covariance).
    Known(G),
    /// Definition number `k` (see the [module docs](self)).
    Defined(usize),
}

/// A named pose given by the input.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseDef<G: LieGroup<N>, const N: usize> {
    /// Its name, e.g. `world_from_body` (letters, digits, `_`, `-`, `.`).
    pub name: String,
    /// Known exactly, or a Gaussian on the group.
    pub value: PoseValue<G, N>,
}

/// A pose known exactly, or uncertain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PoseValue<G: LieGroup<N>, const N: usize> {
    /// A known transform.
    Known(G),
    /// A mean with a validated covariance on its side.
    Uncertain(UncertainPose<G, N>),
}

/// Which side a known transform is applied on in a change of frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameSide {
    /// `by · X`: re-express X in another parent frame (e.g. `map_from_world · world_from_body`).
    Left,
    /// `X · by`: move to another child frame (e.g. `world_from_body · body_from_camera`).
    Right,
}

/// How odometry controls enter (NA 568 vs the exponential form).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OdometryModel {
    /// X_{k+1} = X_k · U_k · Exp(w_k), U_k a group element (NA 568, R2).
    Increment,
    /// X_{k+1} = X_k · Exp(u_k + w_k), u_k a tangent (NA 568, R4).
    Exp,
}

/// One odometry control: the increment as a group element and as a tangent (U = Exp(u)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Control<G: LieGroup<N>, const N: usize> {
    /// U_k.
    pub increment: G,
    /// u_k with Exp(u_k) = U_k.
    pub tangent: Tangent<N>,
}

/// Differential-drive robot and motion (Long et al. 2012), validated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffDriveMotion {
    /// Wheel radius r (m), > 0.
    pub wheel_radius: f64,
    /// Wheelbase l (m), > 0.
    pub wheelbase: f64,
    /// Duration T (s), > 0.
    pub duration: f64,
    /// Wheel noise intensity D ≥ 0.
    pub diffusion: f64,
    /// Forward speed v (m/s), > 0.
    pub speed: f64,
    /// Turn rate α̇ (rad/s), 0 for straight.
    pub turn_rate: f64,
    /// Euler–Maruyama step (s), > 0.
    pub dt: f64,
}

/// An operation: what the robot does to its poses. Each variant is evaluated by one function
/// of [`crate::eval`] (see `ARCHITECTURE.md` for where a new one goes).
#[derive(Debug, Clone, PartialEq)]
pub enum Op<G: LieGroup<N>, const N: usize> {
    /// X⁻¹.
    Inverse {
        /// X.
        input: Operand<G>,
    },
    /// `by · X` (left) or `X · by` (right) with `by` known.
    ChangeFrame {
        /// X.
        input: Operand<G>,
        /// The known transform.
        by: G,
        /// Which side it is applied on.
        side: FrameSide,
    },
    /// X · Y; independent unless `cross_cov` = Σ_XY is given.
    Compose {
        /// X.
        lhs: Operand<G>,
        /// Y.
        rhs: Operand<G>,
        /// Cross-covariance Σ_XY (on X's side).
        cross_cov: Option<TangentMatrix<N>>,
    },
    /// X⁻¹ · Y; independent unless `cross_cov` = Σ_XY is given.
    Between {
        /// X.
        lhs: Operand<G>,
        /// Y.
        rhs: Operand<G>,
        /// Cross-covariance Σ_XY (on X's side).
        cross_cov: Option<TangentMatrix<N>>,
    },
    /// Odometry from `input`, one step per control, noise w_k ~ N(0, `noise.at(k)`) on the
    /// right (one Σ_w for all steps, or one per step as a pose graph's edges give).
    Odometry {
        /// X₀.
        input: Operand<G>,
        /// How controls enter.
        model: OdometryModel,
        /// One per step.
        controls: Vec<Control<G, N>>,
        /// Σ_w (right side, body frame), for all steps or per step.
        noise: StepNoise<N>,
    },
    /// Barfoot & Furgale's repeated compounding T_k = Exp(w_k) · T̄ · T_{k−1}.
    Compound {
        /// T₀.
        input: Operand<G>,
        /// T̄.
        step: G,
        /// Σ_w of the step.
        noise: TangentMatrix<N>,
        /// The side of `noise`.
        noise_side: Side,
        /// How many compounds.
        steps: u64,
    },
    /// A differential-drive robot starting at the known `start` (SE(2) only).
    DiffDrive {
        /// Start pose.
        start: G,
        /// Robot and motion.
        motion: DiffDriveMotion,
    },
    /// An uncertain point (in the pose's frame) seen from an uncertain pose, in world
    /// coordinates. Planar groups use x, y (z and its covariance row are 0).
    PointThroughPose {
        /// The pose.
        input: Operand<G>,
        /// p in the pose's frame.
        point: Vector3<f64>,
        /// Σ_p in the pose's frame.
        point_cov: Matrix3<f64>,
    },
    /// Fuses independent estimates of one pose (Gauss–Newton, Barfoot & Furgale 2014 §IV).
    Fuse {
        /// The estimates.
        inputs: Vec<Operand<G>>,
    },
    /// Euler integration R(I + ω̂dt) against the exponential map (SO(3) only).
    EulerVsExp {
        /// ω (rad/s), body frame.
        rate: Vector3<f64>,
        /// dt (s).
        dt: f64,
        /// Steps.
        steps: u64,
    },
}

/// Which operation a result comes from (an [`Op`] without its data).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OpKind {
    /// [`Op::Inverse`].
    Inverse,
    /// [`Op::ChangeFrame`].
    ChangeFrame,
    /// [`Op::Compose`].
    Compose,
    /// [`Op::Between`].
    Between,
    /// [`Op::Odometry`].
    Odometry,
    /// [`Op::Compound`].
    Compound,
    /// [`Op::DiffDrive`].
    DiffDrive,
    /// [`Op::PointThroughPose`].
    PointThroughPose,
    /// [`Op::Fuse`].
    Fuse,
    /// [`Op::EulerVsExp`].
    EulerVsExp,
}

impl<G: LieGroup<N>, const N: usize> Op<G, N> {
    /// Which operation this is.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::plan::{Op, OpKind, Operand};
    /// let op = Op::<So2, 1>::Inverse { input: Operand::Known(So2::identity()) };
    /// assert_eq!(op.kind(), OpKind::Inverse);
    /// ```
    pub fn kind(&self) -> OpKind {
        match self {
            Op::Inverse { .. } => OpKind::Inverse,
            Op::ChangeFrame { .. } => OpKind::ChangeFrame,
            Op::Compose { .. } => OpKind::Compose,
            Op::Between { .. } => OpKind::Between,
            Op::Odometry { .. } => OpKind::Odometry,
            Op::Compound { .. } => OpKind::Compound,
            Op::DiffDrive { .. } => OpKind::DiffDrive,
            Op::PointThroughPose { .. } => OpKind::PointThroughPose,
            Op::Fuse { .. } => OpKind::Fuse,
            Op::EulerVsExp { .. } => OpKind::EulerVsExp,
        }
    }

    /// The number of steps this operation records on the `step` timeline (0 for a single
    /// result).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::plan::Op;
    /// let op = Op::<So3, 3>::EulerVsExp { rate: nalgebra::Vector3::z(), dt: 0.1, steps: 7 };
    /// assert_eq!(op.steps(), 7);
    /// ```
    pub fn steps(&self) -> u64 {
        match self {
            Op::Odometry { controls, .. } => controls.len() as u64,
            Op::Compound { steps, .. } | Op::EulerVsExp { steps, .. } => *steps,
            _ => 0,
        }
    }

    /// The steps each Monte Carlo particle takes through this operation: the recorded steps,
    /// a differential drive's Euler–Maruyama steps (⌈duration / dt⌉), at least 1.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::plan::Op;
    /// let op = Op::<So3, 3>::EulerVsExp { rate: nalgebra::Vector3::z(), dt: 0.1, steps: 7 };
    /// assert_eq!(op.particle_steps(), 7);
    /// ```
    pub fn particle_steps(&self) -> u64 {
        match self {
            Op::DiffDrive { motion, .. } => (motion.duration / motion.dt).ceil() as u64,
            op => op.steps().max(1),
        }
    }
}

/// An operation with the name of what it defines.
#[derive(Debug, Clone, PartialEq)]
pub struct Operation<G: LieGroup<N>, const N: usize> {
    /// The output's name.
    pub output: String,
    /// What is done.
    pub op: Op<G, N>,
}

/// Everything to evaluate, for one group.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan<G: LieGroup<N>, const N: usize> {
    /// Definitions `0 .. poses.len()`.
    pub poses: Vec<PoseDef<G, N>>,
    /// Definitions `poses.len() ..`, evaluated in order.
    pub operations: Vec<Operation<G, N>>,
    /// A pose graph to optimise (g2o / GTSAM files), with its marginals
    /// ([`crate::eval::graph`]).
    pub graph: Option<graph::PoseGraph<G, N>>,
}

impl<G: LieGroup<N>, const N: usize> Default for Plan<G, N> {
    fn default() -> Self {
        Self {
            poses: Vec::new(),
            operations: Vec::new(),
            graph: None,
        }
    }
}

impl<G: LieGroup<N>, const N: usize> Plan<G, N> {
    /// How many definitions (poses and operation outputs) the plan has.
    ///
    /// ```
    /// let plan = posecov::plan::Plan::<posecov::lie::So2, 1>::default();
    /// assert_eq!(plan.definitions(), 0);
    /// ```
    pub fn definitions(&self) -> usize {
        self.poses.len() + self.operations.len()
    }

    /// The name of definition `k`.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// let mut plan = posecov::plan::Plan::<So2, 1>::default();
    /// plan.known("world_from_a", So2::identity());
    /// assert_eq!(plan.name_of(0), Some("world_from_a"));
    /// ```
    pub fn name_of(&self, k: usize) -> Option<&str> {
        match self.poses.get(k) {
            Some(p) => Some(&p.name),
            None => self
                .operations
                .get(k - self.poses.len())
                .map(|o| o.output.as_str()),
        }
    }

    /// Adds a known transform; returns it as an operand.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::plan::{Operand, Plan};
    /// let mut plan = Plan::<So2, 1>::default();
    /// assert_eq!(plan.known("a_from_b", So2::identity()), Operand::Known(So2::identity()));
    /// ```
    pub fn known(&mut self, name: &str, pose: G) -> Operand<G> {
        self.poses.push(PoseDef {
            name: name.to_owned(),
            value: PoseValue::Known(pose),
        });
        Operand::Known(pose)
    }

    /// Adds an uncertain input pose; returns it as an operand.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::plan::{Operand, Plan};
    /// use posecov::uncertain::UncertainPose;
    /// let mut plan = Plan::<So2, 1>::default();
    /// assert_eq!(plan.uncertain("a", UncertainPose::certain(So2::identity())), Operand::Defined(0));
    /// ```
    pub fn uncertain(&mut self, name: &str, pose: UncertainPose<G, N>) -> Operand<G> {
        self.poses.push(PoseDef {
            name: name.to_owned(),
            value: PoseValue::Uncertain(pose),
        });
        Operand::Defined(self.poses.len() - 1)
    }

    /// Adds an operation defining `output`; returns its output as an operand. Operands must
    /// refer to earlier definitions (an input module checks this; evaluation reports it).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::plan::{Op, Operand, Plan};
    /// use posecov::uncertain::UncertainPose;
    /// let mut plan = Plan::<So2, 1>::default();
    /// let a = plan.uncertain("a", UncertainPose::certain(So2::identity()));
    /// assert_eq!(plan.operation("a_inv", Op::Inverse { input: a }), Operand::Defined(1));
    /// ```
    pub fn operation(&mut self, output: &str, op: Op<G, N>) -> Operand<G> {
        self.operations.push(Operation {
            output: output.to_owned(),
            op,
        });
        Operand::Defined(self.definitions() - 1)
    }

    /// Adds `output = lhs · rhs` for independent operands ([`Op::Compose`] without a
    /// cross-covariance); returns it as an operand.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::plan::{Operand, Plan};
    /// use posecov::uncertain::UncertainPose;
    /// let mut plan = Plan::<So2, 1>::default();
    /// let a = plan.uncertain("a", UncertainPose::certain(So2::identity()));
    /// assert_eq!(plan.compose("aa", a, a), Operand::Defined(1));
    /// ```
    pub fn compose(&mut self, output: &str, lhs: Operand<G>, rhs: Operand<G>) -> Operand<G> {
        self.operation(
            output,
            Op::Compose {
                lhs,
                rhs,
                cross_cov: None,
            },
        )
    }
}

/// A plan of any group (input files choose the group at run time).
#[derive(Debug, Clone, PartialEq)]
pub enum AnyPlan {
    /// SO(2).
    So2(Plan<So2, 1>),
    /// SE(2).
    Se2(Plan<Se2, 3>),
    /// SO(3).
    So3(Plan<So3, 3>),
    /// SE(3).
    Se3(Plan<Se3, 6>),
}

impl AnyPlan {
    /// The Monte Carlo work of `samples` particles, in particle-steps: each input pose's
    /// draw and each operation's [`Op::particle_steps`], times `samples`.
    ///
    /// ```
    /// use posecov::app::load;
    /// let plan = load("barfoot_compounding").unwrap().input.plan;
    /// assert_eq!(plan.monte_carlo_work(1000), 1000.0 * (2.0 + 100.0));
    /// ```
    pub fn monte_carlo_work(&self, samples: u64) -> f64 {
        fn steps<G: LieGroup<N>, const N: usize>(plan: &Plan<G, N>) -> f64 {
            let ops: u64 = plan.operations.iter().map(|o| o.op.particle_steps()).sum();
            plan.poses.len() as f64 + ops as f64
        }
        samples as f64
            * match self {
                Self::So2(p) => steps(p),
                Self::Se2(p) => steps(p),
                Self::So3(p) => steps(p),
                Self::Se3(p) => steps(p),
            }
    }

    /// The most steps any one operation records ([`Op::steps`]; 0 without propagations).
    ///
    /// ```
    /// use posecov::app::load;
    /// assert_eq!(load("barfoot_compounding").unwrap().input.plan.longest_propagation(), 100);
    /// assert_eq!(load("camera_on_robot").unwrap().input.plan.longest_propagation(), 0);
    /// ```
    pub fn longest_propagation(&self) -> u64 {
        fn longest<G: LieGroup<N>, const N: usize>(plan: &Plan<G, N>) -> u64 {
            plan.operations
                .iter()
                .map(|o| o.op.steps())
                .max()
                .unwrap_or(0)
        }
        match self {
            Self::So2(p) => longest(p),
            Self::Se2(p) => longest(p),
            Self::So3(p) => longest(p),
            Self::Se3(p) => longest(p),
        }
    }
}

/// What a plan and its settings may ask for: sizes beyond these are refused up front, with
/// the limit in the message, so that every accepted input runs in bounded time and memory.
pub mod limits {
    /// Fewest Monte Carlo samples (a covariance needs two).
    pub const MIN_SAMPLES: u64 = 2;
    /// Most Monte Carlo samples (larger ones run in blocks of bounded memory).
    pub const MAX_SAMPLES: u64 = 10_000_000;
    /// Monte Carlo samples when neither the command line nor the file says.
    pub const DEFAULT_SAMPLES: u64 = 2000;

    /// The one check of a Monte Carlo sample count ([`MIN_SAMPLES`] ..= [`MAX_SAMPLES`]),
    /// for the command line, the file and the evaluation alike: `Err` with what is accepted.
    ///
    /// ```
    /// use posecov::plan::limits::check_samples;
    /// assert_eq!(check_samples(2000), Ok(2000));
    /// assert_eq!(check_samples(1).unwrap_err(), "use 2 ..= 10000000");
    /// ```
    pub fn check_samples(n: u64) -> Result<u64, String> {
        if (MIN_SAMPLES..=MAX_SAMPLES).contains(&n) {
            Ok(n)
        } else {
            Err(format!("use {MIN_SAMPLES} ..= {MAX_SAMPLES}"))
        }
    }
    /// Most steps of one propagation (odometry, compounding, Euler vs Exp, Euler–Maruyama).
    pub const MAX_STEPS: u64 = 100_000;
    /// Most particle-steps (samples × steps, summed over operations) one evaluation runs:
    /// about a few minutes on two cores, with a progress display and Ctrl-C.
    pub const MAX_PARTICLE_STEPS: f64 = 1e10;
    /// Largest differential-drive length, speed, rate or noise accepted.
    pub const MAX_DIFF_DRIVE_VALUE: f64 = 1e6;
    /// Largest total turn |α̇|·T (rad) of a differential drive: the numeric integral's cost
    /// grows with the number of turns.
    pub const MAX_DIFF_DRIVE_TURN: f64 = 1000.0;
    /// Euler–Maruyama step when the file gives none (s).
    pub const DEFAULT_DIFF_DRIVE_DT: f64 = 1e-3;
    /// Longest frame axes drawn (m).
    pub const MAX_AXIS_LENGTH: f64 = 1e3;
    /// Shortest frame axes drawn (m): shorter ones and their line widths vanish.
    pub const MIN_AXIS_LENGTH: f64 = 1e-4;
    /// Largest coordinate of a given position or point (m): beyond it, products overflow
    /// long before anything can be drawn.
    pub const MAX_COORDINATE: f64 = 1e12;
    /// Largest entry of a given covariance (σ up to 1e12).
    pub const MAX_VARIANCE: f64 = 1e24;
    /// Results beyond these magnitudes count as overflow (not finite) in evaluation: a mean
    /// coordinate, a covariance entry.
    pub const OVERFLOW_COORDINATE: f64 = 1e15;
    /// See [`OVERFLOW_COORDINATE`].
    pub const OVERFLOW_VARIANCE: f64 = 1e30;
}
