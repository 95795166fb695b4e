//! What evaluating a scenario produces: plain data for the scene builder and the JSON report.

use std::sync::Arc;

use serde::Serialize;

use super::schema::{DrawSpec, GroupName};
use crate::lie::{LieGroup, Se2, Se3, So2, So3};
use crate::propagate::{MatrixRows, Propagated, ResultRecord};
use crate::uncertain::Method;

/// The scenario's header after command-line overrides.
#[derive(Debug, Clone, Serialize)]
pub struct Meta {
    /// One-line title.
    pub title: String,
    /// Markdown description.
    pub description: String,
    /// Where the example comes from.
    pub source: String,
    /// The group of every pose.
    #[serde(serialize_with = "group_name")]
    pub group: GroupName,
    /// Seed of every random draw.
    pub seed: u64,
    /// Monte Carlo sample count.
    pub samples: usize,
    /// Monte Carlo particles simulated and held at once (= `samples` unless the sample was
    /// split into blocks to bound memory; see `scenario::eval`).
    pub block_samples: usize,
    /// Confidence (probability) of drawn regions.
    pub confidence: f64,
    /// Methods compared.
    pub methods: Vec<Method>,
    /// What to draw.
    #[serde(skip)]
    pub draw: DrawSpec,
}

fn group_name<S: serde::Serializer>(g: &GroupName, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(match g {
        GroupName::So2 => "SO(2)",
        GroupName::Se2 => "SE(2)",
        GroupName::So3 => "SO(3)",
        GroupName::Se3 => "SE(3)",
    })
}

/// Where a node comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// A pose given with a covariance.
    Input,
    /// A known transform (no covariance).
    Fixed,
    /// The result of an operation.
    Output,
}

/// One method's estimate of a node, with its error against Monte Carlo where that ran.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate<G: LieGroup<N>, const N: usize> {
    /// Mean, covariance, side and method.
    pub result: Propagated<G, N>,
    /// ‖Σ − Σ_MC‖_F / ‖Σ_MC‖_F with both on the right side, where Monte Carlo ran.
    pub error_vs_monte_carlo: Option<f64>,
}

/// A named pose of the scenario at one step, with every method's estimate.
#[derive(Debug, Clone)]
pub struct Node<G: LieGroup<N>, const N: usize> {
    /// Pose name (entity path segment).
    pub name: String,
    /// Input, fixed or output.
    pub role: Role,
    /// Step on the `step` timeline (propagations); `None` for static nodes.
    pub step: Option<u64>,
    /// Whether to draw it.
    pub draw: bool,
    /// The nominal (noise-free) pose.
    pub nominal: G,
    /// One estimate per method that applies.
    pub estimates: Vec<Estimate<G, N>>,
    /// Monte Carlo particles of this node (shared: the same particles flow through operations).
    pub particles: Option<Arc<Vec<G>>>,
}

/// An uncertain point (a landmark seen from an uncertain pose), in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct PointNode {
    /// Name.
    pub name: String,
    /// Per method: (method, mean in world, 3×3 covariance in world, row-major).
    pub estimates: Vec<(Method, [f64; 3], [[f64; 3]; 3])>,
    /// Monte Carlo particles, world coordinates.
    pub particles: Option<Vec<[f64; 3]>>,
}

/// A polyline of poses to draw (nominal trajectories, sampled trajectories).
#[derive(Debug, Clone)]
pub struct PosePath<G> {
    /// Entity-path name, e.g. `robot/nominal`.
    pub name: String,
    /// Colour role.
    pub method: Option<Method>,
    /// The poses, in order.
    pub poses: Vec<G>,
}

/// A frame given by a 3×3 matrix that need not be a rotation (its columns drawn as arrows):
/// what Euler integration leaves of a rotation.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixFrame {
    /// Entity-path name.
    pub name: String,
    /// Step on the `step` timeline.
    pub step: Option<u64>,
    /// The matrix; column k is the image of axis k.
    pub columns: nalgebra::Matrix3<f64>,
    /// Where the arrows start.
    pub origin: [f64; 3],
}

/// A scalar per step, plotted per method.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Series {
    /// What is plotted, e.g. `trace of position covariance (m²)`; one plot per quantity.
    pub quantity: String,
    /// Which method's line (`None`: a line named by `label`).
    pub method: Option<Method>,
    /// Legend label.
    pub label: String,
    /// (step, value).
    pub points: Vec<(i64, f64)>,
}

/// Everything a scenario evaluates to, for one group.
#[derive(Debug, Clone)]
pub struct Evaluation<G: LieGroup<N>, const N: usize> {
    /// Header after overrides.
    pub meta: Meta,
    /// Every pose at every step, in evaluation order.
    pub nodes: Vec<Node<G, N>>,
    /// Uncertain points.
    pub points: Vec<PointNode>,
    /// Polylines of poses.
    pub paths: Vec<PosePath<G>>,
    /// Non-orthonormal frames (Euler integration).
    pub matrix_frames: Vec<MatrixFrame>,
    /// Plots.
    pub series: Vec<Series>,
    /// Extra findings for the text panel (markdown lines), e.g. Lie vs Cartesian mean.
    pub notes: Vec<String>,
}

impl<G: LieGroup<N>, const N: usize> Evaluation<G, N>
where
    G::Matrix: MatrixRows,
{
    /// Every estimate as a plain record (label `name` or `name@step`).
    ///
    /// ```
    /// use posecov::scenario::{Scenario, eval::{evaluate, EvalOptions}};
    /// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='se2'\nmethods=['first_order']\n[[pose]]\nname='a'\nmean={xy_theta=[1,2,0]}\ncov={std=[0.1,0.1,0.1]}\n", "t.toml").unwrap();
    /// let e = evaluate(&s, &EvalOptions::default()).unwrap();
    /// assert!(!e.records().is_empty());
    /// ```
    pub fn records(&self) -> Vec<ResultRecord> {
        self.nodes
            .iter()
            .flat_map(|node| {
                let label = match node.step {
                    Some(k) => format!("{}@{k}", node.name),
                    None => node.name.clone(),
                };
                node.estimates
                    .iter()
                    .map(move |e| ResultRecord::new(&label, &e.result, e.error_vs_monte_carlo))
            })
            .collect()
    }
}

/// An evaluation of any group (scenario files choose the group at run time).
#[derive(Debug, Clone)]
pub enum AnyEvaluation {
    /// SO(2) scenario.
    So2(Evaluation<So2, 1>),
    /// SE(2) scenario.
    Se2(Evaluation<Se2, 3>),
    /// SO(3) scenario.
    So3(Evaluation<So3, 3>),
    /// SE(3) scenario.
    Se3(Evaluation<Se3, 6>),
}

impl AnyEvaluation {
    /// The header.
    ///
    /// ```
    /// use posecov::scenario::{Scenario, eval::{evaluate, EvalOptions}};
    /// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='so3'\n", "t.toml").unwrap();
    /// assert_eq!(evaluate(&s, &EvalOptions::default()).unwrap().meta().title, "t");
    /// ```
    pub fn meta(&self) -> &Meta {
        match self {
            AnyEvaluation::So2(e) => &e.meta,
            AnyEvaluation::Se2(e) => &e.meta,
            AnyEvaluation::So3(e) => &e.meta,
            AnyEvaluation::Se3(e) => &e.meta,
        }
    }

    /// Every estimate as a plain record.
    ///
    /// ```
    /// use posecov::scenario::{Scenario, eval::{evaluate, EvalOptions}};
    /// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='so3'\n", "t.toml").unwrap();
    /// assert!(evaluate(&s, &EvalOptions::default()).unwrap().records().is_empty());
    /// ```
    pub fn records(&self) -> Vec<ResultRecord> {
        match self {
            AnyEvaluation::So2(e) => e.records(),
            AnyEvaluation::Se2(e) => e.records(),
            AnyEvaluation::So3(e) => e.records(),
            AnyEvaluation::Se3(e) => e.records(),
        }
    }
}
