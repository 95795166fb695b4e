//! Lowering a parsed scenario file to a typed [`Plan`]: every check a user can fail, each
//! reported at `file:line:column` with the key (`operation[2].noise`) and the value.
//!
//! This is the only place that reads the flat [`OperationSpec`]: which keys each kind takes
//! ([`OPERATION_KINDS`]), whether names exist and are of the right kind (a known transform,
//! an uncertain pose, or a point, which pose operations reject), and every numeric range.
//! The evaluation then sees only typed values.

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;

use toml::Spanned;

use super::schema::{CovSpec, DrawSpec, OperationSpec, ScenarioFile};
use super::values::{SpecGroup, cov_for, mean_for};
use super::{Scenario, ScenarioError};

mod choices;
mod operations;
use crate::input::{About, DrawChoices, FileSettings, Input};
use crate::lie::{GroupKind, LieGroup, Se2, Se3, So2, So3, TangentMatrix};
use crate::plan::{AnyPlan, Op, Operand, Plan, limits};
use crate::uncertain::{Side, UncertainPose};

/// An operation kind, with the keys it requires and the keys it accepts besides `kind` and
/// `output`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OperationKind {
    /// The kind, as the file writes it (`kind = "compose"`).
    pub kind: &'static str,
    /// Keys it requires.
    pub required: &'static [&'static str],
    /// Keys it accepts besides those.
    pub optional: &'static [&'static str],
}

impl OperationKind {
    /// The kind named `kind`, if any.
    ///
    /// ```
    /// use posecov::input::scenario::OperationKind;
    /// assert_eq!(OperationKind::named("fuse").unwrap().required, &["inputs"]);
    /// assert!(OperationKind::named("invert").is_none());
    /// ```
    pub fn named(kind: &str) -> Option<&'static OperationKind> {
        OPERATION_KINDS.iter().find(|k| k.kind == kind)
    }
}

/// Every operation kind, with the keys it requires and the keys it accepts besides `kind`
/// and `output`. The one table of operation keys.
pub const OPERATION_KINDS: &[OperationKind] = &[
    OperationKind {
        kind: "inverse",
        required: &["input"],
        optional: &[],
    },
    OperationKind {
        kind: "change_frame_left",
        required: &["input", "by"],
        optional: &[],
    },
    OperationKind {
        kind: "change_frame_right",
        required: &["input", "by"],
        optional: &[],
    },
    OperationKind {
        kind: "compose",
        required: &["lhs", "rhs"],
        optional: &[],
    },
    OperationKind {
        kind: "between",
        required: &["lhs", "rhs"],
        optional: &[],
    },
    OperationKind {
        kind: "compose_correlated",
        required: &["lhs", "rhs", "cross_cov"],
        optional: &[],
    },
    OperationKind {
        kind: "between_correlated",
        required: &["lhs", "rhs", "cross_cov"],
        optional: &[],
    },
    OperationKind {
        kind: "odometry",
        required: &["input", "controls", "noise", "model"],
        optional: &["steps"],
    },
    OperationKind {
        kind: "compound",
        required: &["input", "by", "noise", "steps"],
        optional: &[],
    },
    OperationKind {
        kind: "diff_drive",
        required: &[
            "wheel_radius",
            "wheelbase",
            "duration",
            "diffusion",
            "speed",
            "turn_rate",
        ],
        optional: &["input", "dt"],
    },
    OperationKind {
        kind: "point_through_pose",
        required: &["input", "point"],
        optional: &["point_cov"],
    },
    OperationKind {
        kind: "fuse",
        required: &["inputs"],
        optional: &[],
    },
    OperationKind {
        kind: "euler_vs_exp",
        required: &["rate", "dt", "steps"],
        optional: &["input"],
    },
];

/// Lowers a parsed scenario: the plan of its group, its text, the file's settings and drawing
/// choices, all checked.
///
/// ```
/// use posecov::input::scenario::{Scenario, lower};
/// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='se2'\n[[pose]]\nname='a'\nmean={xy_theta=[1,0,0]}\ncov={std=[0.1,0.1,0.1]}\n[[operation]]\nkind='inverse'\ninput='b'\noutput='c'\n", "t.toml").unwrap();
/// let e = lower(&s).unwrap_err().to_string();
/// assert!(e.starts_with("t.toml:10:7: operation[0].input: no pose named `b`"), "{e}");
/// ```
pub fn lower(scenario: &Scenario) -> Result<Input, ScenarioError> {
    let file = &scenario.file;
    let lower = Lowering {
        file,
        loc: scenario,
    };
    let defaults = lower.settings()?;
    let draw = lower.draw_choices(&file.draw)?;
    let plan = match file.scenario.group {
        GroupKind::So2 => AnyPlan::So2(lower.plan::<So2, 1>()?),
        GroupKind::Se2 => AnyPlan::Se2(lower.plan::<Se2, 3>()?),
        GroupKind::So3 => AnyPlan::So3(lower.plan::<So3, 3>()?),
        GroupKind::Se3 => AnyPlan::Se3(lower.plan::<Se3, 6>()?),
    };
    let h = &file.scenario;
    Ok(Input {
        about: About {
            title: h.title.clone(),
            description: h.description.clone(),
            source: h.source.clone(),
        },
        plan,
        defaults,
        draw,
    })
}

/// The accepted range of a number: `low` (excluded when `open_low`) ..= `high`.
#[derive(Clone, Copy)]
struct Bounds {
    low: f64,
    open_low: bool,
    high: f64,
}

/// What a name stands for while lowering.
#[derive(Clone, Copy)]
enum Named<G> {
    /// A known transform.
    Known(G),
    /// An uncertain pose (definition number).
    Pose(usize),
    /// An uncertain point (a `point_through_pose` output): not a pose.
    Point,
}

struct Lowering<'a> {
    file: &'a ScenarioFile,
    loc: &'a Scenario,
}

/// The plan being built and the names defined so far.
struct Table<G: LieGroup<N>, const N: usize> {
    plan: Plan<G, N>,
    names: HashMap<String, Named<G>>,
}

impl Lowering<'_> {
    fn err(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> ScenarioError {
        self.loc.locator.error(span, field, message)
    }

    /// `[scenario]` seed, samples, confidence, methods.
    fn settings(&self) -> Result<FileSettings, ScenarioError> {
        let h = &self.file.scenario;
        if let Some(n) = &h.samples
            && let Err(expected) = limits::check_samples(*n.get_ref())
        {
            return Err(self.err(
                n.span(),
                "scenario.samples",
                format!("{} is out of range: {expected}", n.get_ref()),
            ));
        }
        let confidence = match &h.confidence {
            Some(c) => Some(
                crate::uncertain::Confidence::new(*c.get_ref())
                    .map_err(|e| self.err(c.span(), "scenario.confidence", e.to_string()))?,
            ),
            None => None,
        };
        let mut methods = h.methods.clone();
        methods.dedup();
        Ok(FileSettings {
            seed: h.seed,
            samples: h.samples.as_ref().map(|s| *s.get_ref()),
            confidence,
            methods,
            sigma_points: self.sigma_points(&self.file.methods.sigma_points, h.group.dof())?,
            steps: None,
        })
    }

    /// `[draw]` and each pose's `draw`.
    fn draw_choices(&self, spec: &DrawSpec) -> Result<DrawChoices, ScenarioError> {
        if let Some(len) = &spec.axis_length {
            let v = *len.get_ref();
            if !(limits::MIN_AXIS_LENGTH..=limits::MAX_AXIS_LENGTH).contains(&v) {
                return Err(self.err(
                    len.span(),
                    "draw.axis_length",
                    format!(
                        "{v} is out of range: a length in metres, {} ..= {}",
                        limits::MIN_AXIS_LENGTH,
                        limits::MAX_AXIS_LENGTH
                    ),
                ));
            }
        }
        let shown: BTreeMap<String, bool> = self
            .file
            .poses
            .iter()
            .filter_map(|p| p.draw.map(|d| (p.name.get_ref().clone(), d)))
            .collect();
        Ok(DrawChoices {
            axes: spec.axes,
            clouds: spec.clouds,
            sample_axes: spec.sample_axes,
            ellipsoids: spec.ellipsoids,
            bananas: spec.bananas,
            orientation: spec.orientation,
            trajectories: spec.trajectories,
            axis_length: spec.axis_length.as_ref().map(|l| *l.get_ref()),
            top_view: spec.view.map(|v| v == super::schema::View::Top),
            shown,
            camera: self.camera(&spec.camera)?,
            layout: spec.layout,
            ..DrawChoices::default()
        })
    }

    fn plan<G: SpecGroup<N>, const N: usize>(&self) -> Result<Plan<G, N>, ScenarioError> {
        let mut t = Table {
            plan: Plan::default(),
            names: HashMap::new(),
        };
        for (i, spec) in self.file.poses.iter().enumerate() {
            let field = format!("pose[{i}]");
            let name = self.new_name(&t, &spec.name, &format!("{field}.name"))?;
            let mean: G = mean_for(spec.mean.get_ref())
                .map_err(|e| self.err(spec.mean.span(), &format!("{field}.mean"), e.to_string()))?;
            match &spec.cov {
                None => {
                    t.plan.known(&name, mean);
                    t.names.insert(name, Named::Known(mean));
                }
                Some(cov) => {
                    let (cov, side) = self.cov::<G, N>(cov, &mean, &format!("{field}.cov"))?;
                    let operand = t
                        .plan
                        .uncertain(&name, UncertainPose::new_unchecked(mean, cov, side));
                    let Operand::Defined(k) = operand else {
                        unreachable!("an uncertain pose is a definition")
                    };
                    t.names.insert(name, Named::Pose(k));
                }
            }
        }
        for (i, op) in self.file.operations.iter().enumerate() {
            let field = format!("operation[{i}]");
            self.check_keys(op, &field)?;
            let output = self.new_name(&t, &op.output, &format!("{field}.output"))?;
            let lowered = self.operation::<G, N>(&t, op, &field)?;
            let is_point = matches!(lowered, Op::PointThroughPose { .. });
            let k = t.plan.definitions();
            t.plan.operation(&output, lowered);
            t.names.insert(
                output,
                if is_point {
                    Named::Point
                } else {
                    Named::Pose(k)
                },
            );
        }
        Ok(t.plan)
    }

    fn new_name<G: LieGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        name: &Spanned<String>,
        field: &str,
    ) -> Result<String, ScenarioError> {
        let n = name.get_ref();
        if n.is_empty()
            || !n
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        {
            return Err(self.err(
                name.span(),
                field,
                format!("`{n}` is not a valid name: use letters, digits, `_`, `-` or `.` (e.g. `world_from_body`)"),
            ));
        }
        if t.names.contains_key(n) {
            return Err(self.err(name.span(), field, format!("`{n}` is already defined")));
        }
        Ok(n.clone())
    }

    /// The keys set are the kind's: none foreign, none missing.
    fn check_keys(&self, op: &OperationSpec, field: &str) -> Result<(), ScenarioError> {
        let kind = op.kind.get_ref().as_str();
        let Some(OperationKind {
            required, optional, ..
        }) = OperationKind::named(kind)
        else {
            let kinds: Vec<&str> = OPERATION_KINDS.iter().map(|k| k.kind).collect();
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.kind"),
                format!(
                    "unknown operation `{kind}`; {}expected one of {}",
                    crate::input::suggest::did_you_mean(kind, kinds.iter().copied()),
                    kinds.join(", ")
                ),
            ));
        };
        let set = op.keys_set();
        if let Some(extra) = set
            .iter()
            .find(|k| !required.contains(k) && !optional.contains(k))
        {
            let mut takes: Vec<&str> = required.to_vec();
            takes.extend(*optional);
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.{extra}"),
                format!(
                    "`{extra}` does not apply to `{kind}`, which takes {} (and output)",
                    takes.join(", ")
                ),
            ));
        }
        if let Some(missing) = required.iter().find(|k| !set.contains(k)) {
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.{missing}"),
                format!("`{kind}` needs `{missing}`"),
            ));
        }
        Ok(())
    }

    /// A key the kind requires (present after [`check_keys`](Self::check_keys)).
    fn need<'b, T>(
        &self,
        value: &'b Option<T>,
        op: &OperationSpec,
        field: &str,
        key: &str,
    ) -> Result<&'b T, ScenarioError> {
        value.as_ref().ok_or_else(|| {
            self.err(
                op.kind.span(),
                &format!("{field}.{key}"),
                format!("`{}` needs `{key}`", op.kind.get_ref()),
            )
        })
    }

    /// A name that must stand for a pose (known or uncertain).
    fn operand<G: LieGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        name: &Spanned<String>,
        field: &str,
        kind: &str,
    ) -> Result<Operand<G>, ScenarioError> {
        match self.lookup(t, name, field)? {
            Named::Known(g) => Ok(Operand::Known(g)),
            Named::Pose(k) => Ok(Operand::Defined(k)),
            Named::Point => Err(self.err(
                name.span(),
                field,
                format!(
                    "`{}` is a point (the output of `point_through_pose`), but `{kind}` needs a pose",
                    name.get_ref()
                ),
            )),
        }
    }

    /// A name that must stand for a known transform.
    fn known<G: LieGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        name: &Spanned<String>,
        field: &str,
    ) -> Result<G, ScenarioError> {
        match self.lookup(t, name, field)? {
            Named::Known(g) => Ok(g),
            _ => Err(self.err(
                name.span(),
                field,
                format!(
                    "`{}` must be a known transform (a pose without `cov`)",
                    name.get_ref()
                ),
            )),
        }
    }

    fn lookup<G: LieGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        name: &Spanned<String>,
        field: &str,
    ) -> Result<Named<G>, ScenarioError> {
        t.names.get(name.get_ref()).copied().ok_or_else(|| {
            let mut known: Vec<&str> = t.names.keys().map(String::as_str).collect();
            known.sort_unstable();
            self.err(
                name.span(),
                field,
                format!(
                    "no pose named `{}`; {}(defined so far: {})",
                    name.get_ref(),
                    crate::input::suggest::did_you_mean(name.get_ref(), known.iter().copied()),
                    known.join(", ")
                ),
            )
        })
    }

    fn cov<G: SpecGroup<N>, const N: usize>(
        &self,
        spec: &Spanned<CovSpec>,
        mean: &G,
        field: &str,
    ) -> Result<(TangentMatrix<N>, Side), ScenarioError> {
        cov_for::<G, N>(spec.get_ref(), mean)
            .map_err(|e| self.err(spec.span(), field, e.to_string()))
    }

    fn steps(&self, op: &OperationSpec, field: &str) -> Result<Option<u64>, ScenarioError> {
        match &op.steps {
            None => Ok(None),
            Some(s) if (1..=limits::MAX_STEPS).contains(s.get_ref()) => Ok(Some(*s.get_ref())),
            Some(s) => Err(self.err(
                s.span(),
                &format!("{field}.steps"),
                format!(
                    "{} is out of range: use 1 ..= {}",
                    s.get_ref(),
                    limits::MAX_STEPS
                ),
            )),
        }
    }

    /// A finite number within `bounds`.
    fn number(
        &self,
        value: &Option<Spanned<f64>>,
        op: &OperationSpec,
        field: &str,
        key: &str,
        bounds: Bounds,
    ) -> Result<f64, ScenarioError> {
        let Bounds {
            low,
            open_low,
            high,
        } = bounds;
        let v = self.need(value, op, field, key)?;
        let x = *v.get_ref();
        let above = if open_low { x > low } else { x >= low };
        if x.is_finite() && above && x <= high {
            return Ok(x);
        }
        Err(self.err(
            v.span(),
            &format!("{field}.{key}"),
            format!(
                "{x} is out of range: must be finite, {} {low} and ≤ {high}",
                if open_low { ">" } else { "≥" }
            ),
        ))
    }
}
