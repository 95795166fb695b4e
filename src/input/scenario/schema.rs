//! The scenario file format: serde structures that mirror the TOML one to one.
//!
//! Every table rejects unknown keys (serde `deny_unknown_fields`, which lists the valid ones).
//! Values whose meaning is checked after parsing (covariances, quaternions, names) keep their
//! byte span, so errors can point at `file:line:column`.

use serde::Deserialize;
use toml::Spanned;

use crate::interop::{EulerOrder, RosReading};
use crate::uncertain::{Method, Side};

/// A whole scenario file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// The `[scenario]` header.
    pub scenario: Header,
    /// Named poses: inputs, fixed transforms (no `cov`), or uncertain estimates.
    #[serde(default, rename = "pose")]
    pub poses: Vec<PoseSpec>,
    /// Operations, evaluated in file order; each writes a new named pose.
    #[serde(default, rename = "operation")]
    pub operations: Vec<OperationSpec>,
    /// What to draw.
    #[serde(default)]
    pub draw: DrawSpec,
    /// Parameters of the methods (`[methods.sigma_points]`).
    #[serde(default)]
    pub methods: MethodsSpec,
}

/// `[methods.*]`: parameters of the methods that have some.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodsSpec {
    /// `[methods.sigma_points]`: the unscented transform's α, β, κ.
    #[serde(default)]
    pub sigma_points: Option<Spanned<SigmaPointsSpec>>,
}

/// `[methods.sigma_points]`: Julier & Uhlmann's scaling parameters (defaults α = 1, β = 2,
/// κ = 0; see [`crate::propagate::sigma_point`]).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SigmaPointsSpec {
    /// Spread α > 0.
    pub alpha: Option<f64>,
    /// Prior-knowledge weight β (2 is optimal for Gaussians).
    pub beta: Option<f64>,
    /// Secondary scaling κ; L + κ > 0 for every operation (κ > −DOF).
    pub kappa: Option<f64>,
}

/// The Lie group every pose of a scenario lives in (`group = "se2"` etc.).
pub use crate::lie::GroupKind as GroupName;

/// `[scenario]`: what this scenario is and how to evaluate it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Header {
    /// One-line title (also the `posecov list` description).
    pub title: String,
    /// Markdown shown in the viewer's text panel: what the picture teaches.
    #[serde(default)]
    pub description: String,
    /// Where the example comes from (lecture, paper, figure).
    #[serde(default)]
    pub source: String,
    /// The group of every pose.
    pub group: GroupName,
    /// Seed of every random draw (CLI `--seed` overrides).
    #[serde(default)]
    pub seed: Option<u64>,
    /// Monte Carlo sample count (CLI `--samples` overrides).
    #[serde(default)]
    pub samples: Option<Spanned<u64>>,
    /// Confidence of drawn regions as a probability in (0, 1) (CLI `--confidence` overrides).
    #[serde(default)]
    pub confidence: Option<Spanned<f64>>,
    /// Methods to compare, e.g. `["first_order", "monte_carlo"]`.
    #[serde(default)]
    pub methods: Vec<Method>,
}

/// `[[pose]]`: a named pose, deterministic (no `cov`) or uncertain.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Its name, e.g. `world_from_body` (used by operations and as the entity path).
    pub name: Spanned<String>,
    /// The mean.
    pub mean: Spanned<MeanSpec>,
    /// The covariance; absent for a known transform.
    #[serde(default)]
    pub cov: Option<Spanned<CovSpec>>,
    /// Draw this pose. Default: uncertain poses always; a known transform `a_from_b` only when
    /// `a` is the scenario's root frame (the parent of its first uncertain pose), so relative
    /// mounts such as `robot_from_camera` are not drawn as if they were world poses.
    #[serde(default)]
    pub draw: Option<bool>,
}

fn yes() -> bool {
    true
}

/// A mean, given in exactly one way (translation and rotation may be combined).
///
/// - SE(2): `xy_theta = [x, y, θ]` (θ in radians) or `xy_theta_deg`.
/// - SO(2): `angle` or `angle_deg`.
/// - SO(3)/SE(3): rotation from `quaternion_xyzw`, `rpy` (radians) or `rpy_deg`
///   (R = Rz(yaw) Ry(pitch) Rx(roll)), or `axis_angle = [x, y, z, angle]`; SE(3) adds `xyz`.
/// - Any group: `matrix` (rotation or homogeneous, row-major rows) or `tangent`
///   (μ = Exp(τ), in the conventions' order).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeanSpec {
    /// SE(2) position and heading (radians).
    #[serde(default, deserialize_with = "exactly")]
    pub xy_theta: Option<[f64; 3]>,
    /// SE(2) position and heading (degrees).
    #[serde(default, deserialize_with = "exactly")]
    pub xy_theta_deg: Option<[f64; 3]>,
    /// SO(2) angle (radians).
    pub angle: Option<f64>,
    /// SO(2) angle (degrees).
    pub angle_deg: Option<f64>,
    /// SE(3) position.
    #[serde(default, deserialize_with = "exactly")]
    pub xyz: Option<[f64; 3]>,
    /// Rotation as a unit quaternion, ROS order (x, y, z, w).
    #[serde(default, deserialize_with = "exactly")]
    pub quaternion_xyzw: Option<[f64; 4]>,
    /// Rotation as roll, pitch, yaw (radians).
    #[serde(default, deserialize_with = "exactly")]
    pub rpy: Option<[f64; 3]>,
    /// Rotation as roll, pitch, yaw (degrees).
    #[serde(default, deserialize_with = "exactly")]
    pub rpy_deg: Option<[f64; 3]>,
    /// Rotation as a unit axis and an angle in radians: [x, y, z, angle].
    #[serde(default, deserialize_with = "exactly")]
    pub axis_angle: Option<[f64; 4]>,
    /// The group element as a matrix, row-major rows.
    pub matrix: Option<Vec<Vec<f64>>>,
    /// The group element as Exp(tangent).
    pub tangent: Option<Vec<f64>>,
}

/// Order of the numbers in a covariance given as a matrix.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// posecov's order: [ρ; θ] (ROS, Solà, Barfoot & Furgale).
    #[default]
    TranslationFirst,
    /// [θ; ρ] (GTSAM Pose3, sophus-rs, Lynch & Park, EEME E6911).
    RotationFirst,
}

/// A covariance, given in exactly one way.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CovSpec {
    /// Per-axis standard deviations (Σ = diag(σ²)), in the conventions' order.
    pub std: Option<Vec<f64>>,
    /// Per-axis standard deviations with the rotational ones in degrees.
    pub std_deg: Option<Vec<f64>>,
    /// Full matrix, row-major rows.
    pub matrix: Option<Vec<Vec<f64>>>,
    /// A ROS covariance, row-major: SE(3) `PoseWithCovariance.covariance`, 36 numbers over
    /// (x, y, z, rotX, rotY, rotZ); SE(2) 9 numbers over (x, y, yaw) (tf2_2d, MRPT's
    /// `CPosePDFGaussian`). Position error in the parent frame's axes; the rotation error as
    /// `reading` says.
    pub ros: Option<Vec<f64>>,
    /// How `ros` is read: `tf2` (default; rotation error in the parent axes, as tf2 moves it)
    /// or `body` (rotation error local).
    pub reading: Option<RosReading>,
    /// An Euler-angle covariance (SE(3)), 36 numbers row-major over (x, y, z) and three angles
    /// in the order `euler_order` names; positions in the parent axes.
    pub euler: Option<Vec<f64>>,
    /// The order of `euler`: `xyz_rpy` (robot_localization's state) or `xyz_ypr` (MRPT's
    /// `CPose3DPDFGaussian`); required with `euler`.
    pub euler_order: Option<EulerOrder>,
    /// Which side the perturbation is on (default `right`: X = μ · Exp(ε)).
    #[serde(default)]
    pub side: Side,
    /// Order of `matrix` / `std` entries (default `translation_first`).
    #[serde(default)]
    pub order: Order,
}

/// `[[operation]]`: one step of what the robot does. `kind` selects which other keys apply;
/// the evaluator rejects keys that do not belong to the kind.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OperationSpec {
    /// One of the [`OPERATION_KINDS`](super::lower::OPERATION_KINDS).
    pub kind: Spanned<String>,
    /// Name of the pose this operation creates.
    pub output: Spanned<String>,
    /// The single input (inverse, change of frame, odometry start, point_through_pose).
    pub input: Option<Spanned<String>>,
    /// Left operand (compose, between).
    pub lhs: Option<Spanned<String>>,
    /// Right operand (compose, between).
    pub rhs: Option<Spanned<String>>,
    /// A known transform (change of frame: `world_from_map` on the left, `body_from_camera` on the right).
    pub by: Option<Spanned<String>>,
    /// Several inputs (fuse).
    pub inputs: Option<Vec<Spanned<String>>>,
    /// Cross-covariance Σ_XY between `lhs` and `rhs` (correlated compose/between).
    pub cross_cov: Option<Spanned<Vec<Vec<f64>>>>,
    /// Per-step control inputs (odometry): one tangent per step, or one repeated `steps` times.
    pub controls: Option<Spanned<Vec<Vec<f64>>>>,
    /// Number of steps (odometry with a single control, compound).
    pub steps: Option<Spanned<u64>>,
    /// Process noise per step (odometry, compound).
    pub noise: Option<Spanned<CovSpec>>,
    /// Odometry model: `"increment"` X·U·Exp(w) (NA 568) or `"exp"` X·Exp(u + w).
    pub model: Option<Spanned<String>>,
    /// Point coordinates in the input pose's frame (point_through_pose).
    pub point: Option<Spanned<Vec<f64>>>,
    /// Point covariance in the input pose's frame (point_through_pose).
    pub point_cov: Option<Spanned<Vec<Vec<f64>>>>,
    /// Differential drive: wheel radius r (m).
    pub wheel_radius: Option<Spanned<f64>>,
    /// Differential drive: wheelbase l (m).
    pub wheelbase: Option<Spanned<f64>>,
    /// Differential drive: duration T (s).
    pub duration: Option<Spanned<f64>>,
    /// Differential drive: wheel noise intensity D.
    pub diffusion: Option<Spanned<f64>>,
    /// Differential drive: forward speed v (m/s).
    pub speed: Option<Spanned<f64>>,
    /// Differential drive: turn rate α̇ (rad/s), 0 for straight.
    pub turn_rate: Option<Spanned<f64>>,
    /// Time step (s) of sampled integration (differential drive, Euler vs Exp).
    pub dt: Option<Spanned<f64>>,
    /// Body angular rate ω (rad/s) for `euler_vs_exp`.
    pub rate: Option<Spanned<Vec<f64>>>,
}

impl OperationSpec {
    /// The names of the keys set besides `kind` and `output`.
    ///
    /// ```
    /// let op: posecov::input::scenario::schema::OperationSpec =
    ///     toml::from_str("kind = 'inverse'\noutput = 'b'\ninput = 'a'\n").unwrap();
    /// assert_eq!(op.keys_set(), vec!["input"]);
    /// ```
    pub fn keys_set(&self) -> Vec<&'static str> {
        [
            ("input", self.input.is_some()),
            ("lhs", self.lhs.is_some()),
            ("rhs", self.rhs.is_some()),
            ("by", self.by.is_some()),
            ("inputs", self.inputs.is_some()),
            ("cross_cov", self.cross_cov.is_some()),
            ("controls", self.controls.is_some()),
            ("steps", self.steps.is_some()),
            ("noise", self.noise.is_some()),
            ("model", self.model.is_some()),
            ("point", self.point.is_some()),
            ("point_cov", self.point_cov.is_some()),
            ("wheel_radius", self.wheel_radius.is_some()),
            ("wheelbase", self.wheelbase.is_some()),
            ("duration", self.duration.is_some()),
            ("diffusion", self.diffusion.is_some()),
            ("speed", self.speed.is_some()),
            ("turn_rate", self.turn_rate.is_some()),
            ("dt", self.dt.is_some()),
            ("rate", self.rate.is_some()),
        ]
        .iter()
        .filter(|(_, on)| *on)
        .map(|(k, _)| *k)
        .collect()
    }
}

/// `[draw]`: what the viewer shows (all default to true).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrawSpec {
    /// Mean frames as axis triads.
    #[serde(default = "yes")]
    pub axes: bool,
    /// Monte Carlo sample positions.
    #[serde(default = "yes")]
    pub clouds: bool,
    /// Small axis triads on a subsample of the samples.
    #[serde(default = "yes")]
    pub sample_axes: bool,
    /// Position covariance ellipsoids (first-order, world frame).
    #[serde(default = "yes")]
    pub ellipsoids: bool,
    /// Exp-mapped "banana" surfaces of each method's tangent ellipsoid.
    #[serde(default = "yes")]
    pub bananas: bool,
    /// Orientation uncertainty: axis-tip sprays and their Exp-mapped ellipses.
    #[serde(default = "yes")]
    pub orientation: bool,
    /// Nominal and sampled trajectories.
    #[serde(default = "yes")]
    pub trajectories: bool,
    /// Length of the mean frames' axes (m); default from the scene size.
    #[serde(default)]
    pub axis_length: Option<Spanned<f64>>,
    /// How the 3D view faces the scene; default `top` for planar groups, else `perspective`.
    #[serde(default)]
    pub view: Option<View>,
    /// The 3D camera: `{ position | direction, target, up }`, each optional; overrides `view`.
    #[serde(default)]
    pub camera: Option<Spanned<CameraSpec>>,
    /// How the 3D views show several methods and poses: `together`, `main`, `per_method`,
    /// `per_pose`; default chosen per scene.
    #[serde(default)]
    pub layout: Option<crate::input::Layout>,
}

/// `[draw] camera = { ... }`: where the 3D eye is and what it looks at (world frame, metres).
#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    #[serde(default, deserialize_with = "exactly")]
    pub position: Option<[f64; 3]>,
    /// Direction from the target towards the eye; the distance is chosen to fit the scene.
    #[serde(default, deserialize_with = "exactly")]
    pub direction: Option<[f64; 3]>,
    /// The point looked at (default: the middle of what is drawn).
    #[serde(default, deserialize_with = "exactly")]
    pub target: Option<[f64; 3]>,
    /// World direction up on screen (default +z).
    #[serde(default, deserialize_with = "exactly")]
    pub up: Option<[f64; 3]>,
}

/// How the 3D view faces the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum View {
    /// From straight above the x–y plane, x to the right (planar motion).
    Top,
    /// z up, seen from the direction chosen for the scene.
    Perspective,
}

impl DrawSpec {
    /// The on/off switches of `[draw]`, as the file spells them (live mode offers each).
    pub const SWITCHES: [&'static str; 7] = [
        "axes",
        "clouds",
        "sample_axes",
        "ellipsoids",
        "bananas",
        "orientation",
        "trajectories",
    ];
}

impl Default for DrawSpec {
    /// Every switch on, no axis length, no view: the values of an empty `[draw]` table.
    fn default() -> Self {
        toml::from_str("").unwrap_or_else(|_| unreachable!("every [draw] key has a default"))
    }
}

/// An optional array of exactly `N` numbers: more are refused as fewer are (serde's arrays
/// read the first `N` of a longer TOML array and drop the rest without a word).
fn exactly<'de, D, const N: usize>(deserializer: D) -> Result<Option<[f64; N]>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    struct Exactly<const N: usize>;
    impl<'de, const N: usize> serde::de::Visitor<'de> for Exactly<N> {
        type Value = [f64; N];
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(f, "an array of {N} numbers")
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; N], A::Error> {
            let mut out = [0.0; N];
            let mut count = 0usize;
            while let Some(x) = seq.next_element::<f64>()? {
                if let Some(slot) = out.get_mut(count) {
                    *slot = x;
                }
                count += 1;
            }
            if count != N {
                return Err(serde::de::Error::custom(format!(
                    "expected an array of {N} numbers, found {count}"
                )));
            }
            Ok(out)
        }
    }
    deserializer.deserialize_seq(Exactly::<N>).map(Some)
}
