//! Lowering one `[[operation]]` of each kind: its operands, values and ranges.

use nalgebra::{DMatrix, Matrix3, Vector3};
use toml::Spanned;

use super::super::schema::OperationSpec;
use super::super::values::{SpecGroup, control_for, fixed_matrix};
use super::{Bounds, Lowering, Table};
use crate::input::scenario::ScenarioError;
use crate::lie::{GroupKind, TangentMatrix};
use crate::plan::{
    DiffDriveMotion, FrameSide, OdometryModel, Op, Operand, PoseValue, StepNoise, limits,
};
use crate::propagate::first_order::CorrelatedPair;
use crate::uncertain::{Side, UncertainPose};

impl Lowering<'_> {
    /// Lowers operation `op` (at `field`, e.g. `operation[2]`) by its kind: its operands
    /// looked up in `t`, its values checked and located.
    pub(super) fn operation<G: SpecGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        op: &OperationSpec,
        field: &str,
    ) -> Result<Op<G, N>, ScenarioError> {
        let kind = op.kind.get_ref().as_str();
        let f = |k: &str| format!("{field}.{k}");
        let pose =
            |value: &Option<Spanned<String>>, key: &str| -> Result<Operand<G>, ScenarioError> {
                self.operand(t, self.need(value, op, field, key)?, &f(key), kind)
            };
        let known = |value: &Option<Spanned<String>>, key: &str| -> Result<G, ScenarioError> {
            self.known(t, self.need(value, op, field, key)?, &f(key))
        };
        Ok(match kind {
            "inverse" => Op::Inverse {
                input: pose(&op.input, "input")?,
            },
            "change_frame_left" | "change_frame_right" => Op::ChangeFrame {
                input: pose(&op.input, "input")?,
                by: known(&op.by, "by")?,
                side: if kind == "change_frame_left" {
                    FrameSide::Left
                } else {
                    FrameSide::Right
                },
            },
            "compose" | "between" | "compose_correlated" | "between_correlated" => {
                self.binary(t, op, field, pose(&op.lhs, "lhs")?, pose(&op.rhs, "rhs")?)?
            }
            "odometry" => self.odometry(op, field, pose(&op.input, "input")?)?,
            "compound" => {
                let step = known(&op.by, "by")?;
                let noise = self.need(&op.noise, op, field, "noise")?;
                let (noise, noise_side) = self.cov::<G, N>(noise, &step, &f("noise"))?;
                Op::Compound {
                    input: pose(&op.input, "input")?,
                    step,
                    noise,
                    noise_side,
                    steps: self.steps(op, field)?.unwrap_or(1),
                }
            }
            "diff_drive" => self.diff_drive(op, field, t)?,
            "point_through_pose" => {
                self.point_through_pose(op, field, pose(&op.input, "input")?)?
            }
            "fuse" => self.fuse(t, op, field)?,
            "euler_vs_exp" => self.euler_vs_exp(t, op, field)?,
            other => {
                return Err(self.err(
                    op.kind.span(),
                    &f("kind"),
                    format!("`{other}` is not available for {} yet", G::NAME),
                ));
            }
        })
    }

    /// `compose`, `between` and their `_correlated` forms of `lhs` and `rhs`: one uncertain
    /// pose on both sides is refused unless its correlation is given (`cross_cov`, checked).
    fn binary<G: SpecGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        op: &OperationSpec,
        field: &str,
        lhs: Operand<G>,
        rhs: Operand<G>,
    ) -> Result<Op<G, N>, ScenarioError> {
        let kind = op.kind.get_ref().as_str();
        if let (Operand::Defined(a), Operand::Defined(b)) = (lhs, rhs)
            && a == b
            && op.cross_cov.is_none()
            && let Some(rhs_name) = &op.rhs
        {
            let base = kind.trim_end_matches("_correlated");
            return Err(self.err(
                rhs_name.span(),
                &format!("{field}.rhs"),
                format!(
                    "`lhs` and `rhs` are the same uncertain pose `{}`: `{kind}` treats its two sides as independent, but they are one draw ({}); use two poses, or `{base}_correlated` with `cross_cov` equal to its covariance",
                    rhs_name.get_ref(),
                    if base == "between" {
                        "X⁻¹·X is exactly the identity"
                    } else {
                        "X·X is not X·Y with Y drawn apart"
                    }
                ),
            ));
        }
        let cross_cov = match &op.cross_cov {
            None => None,
            Some(c) => Some(self.cross_cov(t, field, lhs, rhs, c)?),
        };
        Ok(if kind.starts_with("compose") {
            Op::Compose {
                lhs,
                rhs,
                cross_cov,
            }
        } else {
            Op::Between {
                lhs,
                rhs,
                cross_cov,
            }
        })
    }

    /// `fuse`: at least two estimates, each an operand.
    fn fuse<G: SpecGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        op: &OperationSpec,
        field: &str,
    ) -> Result<Op<G, N>, ScenarioError> {
        let kind = op.kind.get_ref().as_str();
        let inputs = op.inputs.as_deref().unwrap_or(&[]);
        if inputs.len() < 2 {
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.inputs"),
                format!("`fuse` needs at least 2 estimates, got {}", inputs.len()),
            ));
        }
        let inputs = inputs
            .iter()
            .enumerate()
            .map(|(i, name)| self.operand(t, name, &format!("{field}.inputs[{i}]"), kind))
            .collect::<Result<_, _>>()?;
        Ok(Op::Fuse { inputs })
    }

    /// `euler_vs_exp`: SO(3) only, from the identity, a finite body rate, its `dt` and steps.
    fn euler_vs_exp<G: SpecGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        op: &OperationSpec,
        field: &str,
    ) -> Result<Op<G, N>, ScenarioError> {
        let f = |k: &str| format!("{field}.{k}");
        if G::KIND != GroupKind::So3 {
            return Err(self.err(
                op.kind.span(),
                &f("kind"),
                format!(
                    "`euler_vs_exp` integrates a 3D body rate: it needs group = \"so3\", not {}",
                    G::NAME
                ),
            ));
        }
        if let Some(input) = &op.input
            && !self
                .known(t, input, &f("input"))?
                .is_approx(&G::identity(), 1e-12)
        {
            return Err(self.err(
                input.span(),
                &f("input"),
                "`euler_vs_exp` starts at the identity: give a start pose equal to it, or drop `input`",
            ));
        }
        let rate_spec = self.need(&op.rate, op, field, "rate")?;
        let rate = rate_spec.get_ref();
        if rate.len() != 3 || rate.iter().any(|v| !v.is_finite() || v.abs() > 1e6) {
            return Err(self.err(
                rate_spec.span(),
                &f("rate"),
                format!("needs 3 finite numbers (rad/s, |ω| ≤ 1e6), got {rate:?}"),
            ));
        }
        Ok(Op::EulerVsExp {
            rate: Vector3::new(rate[0], rate[1], rate[2]),
            dt: self.number(
                &op.dt,
                op,
                field,
                "dt",
                Bounds {
                    low: 0.0,
                    open_low: true,
                    high: 1e3,
                },
            )?,
            steps: self.steps(op, field)?.unwrap_or(1),
        })
    }

    /// Σ_XY, checked against the operands' covariances: the joint covariance must be PSD.
    fn cross_cov<G: SpecGroup<N>, const N: usize>(
        &self,
        t: &Table<G, N>,
        field: &str,
        lhs: Operand<G>,
        rhs: Operand<G>,
        spec: &Spanned<Vec<Vec<f64>>>,
    ) -> Result<TangentMatrix<N>, ScenarioError> {
        let at = |m: String| self.err(spec.span(), &format!("{field}.cross_cov"), m);
        let cross: TangentMatrix<N> =
            fixed_matrix::<N, N>("cross_cov", spec.get_ref()).map_err(|e| at(e.to_string()))?;
        // Inputs given in the file can be checked now; outputs of operations are checked
        // when evaluated (their covariance is computed there).
        let given = |o: Operand<G>| match o {
            Operand::Known(g) => Some(UncertainPose::certain(g)),
            Operand::Defined(k) => match t.plan.poses.get(k).map(|p| p.value) {
                Some(PoseValue::Uncertain(p)) => Some(p),
                _ => None,
            },
        };
        if let (Some(x), Some(y)) = (given(lhs), given(rhs)) {
            CorrelatedPair::with_cross(&x, &y, &cross).map_err(|e| {
                at(format!(
                    "the joint covariance [[Σ_X, Σ_XY], [Σ_XYᵀ, Σ_Y]] is invalid: {e}"
                ))
            })?;
        }
        Ok(cross)
    }

    fn odometry<G: SpecGroup<N>, const N: usize>(
        &self,
        op: &OperationSpec,
        field: &str,
        input: Operand<G>,
    ) -> Result<Op<G, N>, ScenarioError> {
        let model_spec = self.need(&op.model, op, field, "model")?;
        let model = match model_spec.get_ref().as_str() {
            "increment" => OdometryModel::Increment,
            "exp" => OdometryModel::Exp,
            other => {
                return Err(self.err(
                    model_spec.span(),
                    &format!("{field}.model"),
                    format!("unknown odometry model `{other}`; use `increment` (X·U·Exp(w), NA 568) or `exp` (X·Exp(u + w))"),
                ));
            }
        };
        let noise_spec = self.need(&op.noise, op, field, "noise")?;
        let (noise, side) =
            self.cov::<G, N>(noise_spec, &G::identity(), &format!("{field}.noise"))?;
        if side != Side::Right {
            return Err(self.err(
                noise_spec.span(),
                &format!("{field}.noise"),
                "odometry noise enters on the right (body frame): remove `side = \"left\"`",
            ));
        }
        let controls_spec = self.need(&op.controls, op, field, "controls")?;
        let mut controls = Vec::new();
        for (i, c) in controls_spec.get_ref().iter().enumerate() {
            let control =
                control_for::<G, N>(c, model == OdometryModel::Increment).map_err(|e| {
                    self.err(
                        controls_spec.span(),
                        &format!("{field}.controls[{i}]"),
                        e.to_string(),
                    )
                })?;
            controls.push(control);
        }
        if controls.is_empty() {
            return Err(self.err(
                controls_spec.span(),
                &format!("{field}.controls"),
                "needs at least one control",
            ));
        }
        if controls.len() as u64 > limits::MAX_STEPS {
            return Err(self.err(
                controls_spec.span(),
                &format!("{field}.controls"),
                format!(
                    "{} controls: at most {} steps",
                    controls.len(),
                    limits::MAX_STEPS
                ),
            ));
        }
        if let Some(steps) = self.steps(op, field)? {
            if controls.len() != 1 {
                return Err(self.err(
                    self.need(&op.steps, op, field, "steps")?.span(),
                    &format!("{field}.steps"),
                    "`steps` repeats a single control: give one control, or drop `steps`",
                ));
            }
            controls = vec![controls[0]; steps as usize];
        }
        Ok(Op::Odometry {
            input,
            model,
            controls,
            noise: StepNoise::Same(noise),
        })
    }

    fn diff_drive<G: SpecGroup<N>, const N: usize>(
        &self,
        op: &OperationSpec,
        field: &str,
        t: &Table<G, N>,
    ) -> Result<Op<G, N>, ScenarioError> {
        if G::KIND != GroupKind::Se2 {
            return Err(self.err(
                op.kind.span(),
                &format!("{field}.kind"),
                format!(
                    "`diff_drive` is a planar robot: it needs group = \"se2\", not {}",
                    G::NAME
                ),
            ));
        }
        let start = match &op.input {
            Some(name) => self.known(t, name, &format!("{field}.input"))?,
            None => G::identity(),
        };
        let n = |key: &str, value: &Option<Spanned<f64>>, low: f64, open_low: bool, high: f64| {
            self.number(
                value,
                op,
                field,
                key,
                Bounds {
                    low,
                    open_low,
                    high,
                },
            )
        };
        let big = limits::MAX_DIFF_DRIVE_VALUE;
        let dt = match &op.dt {
            Some(_) => n("dt", &op.dt, 0.0, true, 1.0)?,
            None => limits::DEFAULT_DIFF_DRIVE_DT,
        };
        let motion = DiffDriveMotion {
            wheel_radius: n("wheel_radius", &op.wheel_radius, 1e-6, false, big)?,
            wheelbase: n("wheelbase", &op.wheelbase, 1e-6, false, big)?,
            duration: n("duration", &op.duration, 0.0, true, big)?,
            diffusion: n("diffusion", &op.diffusion, 0.0, false, big)?,
            speed: n("speed", &op.speed, 0.0, true, big)?,
            turn_rate: n("turn_rate", &op.turn_rate, -big, false, big)?,
            dt,
        };
        let turned = (motion.turn_rate * motion.duration).abs();
        if turned > limits::MAX_DIFF_DRIVE_TURN {
            let span = self.need(&op.turn_rate, op, field, "turn_rate")?.span();
            return Err(self.err(
                span,
                &format!("{field}.turn_rate"),
                format!(
                    "turn_rate × duration = {turned:.3e} rad: at most {} rad (about {:.0} turns) are integrated",
                    limits::MAX_DIFF_DRIVE_TURN,
                    limits::MAX_DIFF_DRIVE_TURN / std::f64::consts::TAU
                ),
            ));
        }
        let euler_steps = motion.duration / motion.dt;
        if euler_steps > limits::MAX_STEPS as f64 {
            let span = op.dt.as_ref().map_or_else(|| op.kind.span(), Spanned::span);
            return Err(self.err(
                span,
                &format!("{field}.dt"),
                format!(
                    "duration / dt = {euler_steps:.3e} Euler–Maruyama steps: at most {}; raise dt or shorten duration",
                    limits::MAX_STEPS
                ),
            ));
        }
        Ok(Op::DiffDrive { start, motion })
    }

    fn point_through_pose<G: SpecGroup<N>, const N: usize>(
        &self,
        op: &OperationSpec,
        field: &str,
        input: Operand<G>,
    ) -> Result<Op<G, N>, ScenarioError> {
        let point = self.need(&op.point, op, field, "point")?;
        let dims = G::KIND.space_dims();
        let p = point.get_ref();
        if p.len() != dims
            || p.iter()
                .any(|v| !v.is_finite() || v.abs() > limits::MAX_COORDINATE)
        {
            return Err(self.err(
                point.span(),
                &format!("{field}.point"),
                format!(
                    "needs {dims} finite coordinates of at most {:e} m for {}, got {p:?}",
                    limits::MAX_COORDINATE,
                    G::NAME
                ),
            ));
        }
        let mut point_cov = Matrix3::zeros();
        if let Some(cov) = &op.point_cov {
            let at = |m: String| self.err(cov.span(), &format!("{field}.point_cov"), m);
            let dyn_cov = if dims == 2 {
                let c = fixed_matrix::<2, 2>("point_cov", cov.get_ref())
                    .map_err(|e| at(e.to_string()))?;
                point_cov.fixed_view_mut::<2, 2>(0, 0).copy_from(&c);
                DMatrix::from_iterator(2, 2, c.iter().copied())
            } else {
                point_cov = fixed_matrix::<3, 3>("point_cov", cov.get_ref())
                    .map_err(|e| at(e.to_string()))?;
                DMatrix::from_iterator(3, 3, point_cov.iter().copied())
            };
            if dyn_cov.amax() > limits::MAX_VARIANCE {
                return Err(at(format!(
                    "an entry of {:e} is too large: at most {:e}",
                    dyn_cov.amax(),
                    limits::MAX_VARIANCE
                )));
            }
            crate::uncertain::validate_covariance_dyn("point_cov", &dyn_cov)
                .map_err(|e| at(e.to_string()))?;
        }
        Ok(Op::PointThroughPose {
            input,
            point: Vector3::new(p[0], p[1], p.get(2).copied().unwrap_or(0.0)),
            point_cov,
        })
    }
}
