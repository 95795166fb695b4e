//! One function per [`Op`]: the analytic methods, the particles, and the node(s) each
//! operation adds. Dispatch is [`Engine::operation`].

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::EvalError;
use super::engine::{Draft, Engine, Extras, Particles};
use super::groups::EvalGroup;
use super::model::{Finding, MatrixFrame, Node, PathKind, PosePath, Role};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::plan::{
    Control, DiffDriveMotion, FrameSide, OdometryModel, Op, OpKind, Operand, limits,
};
use crate::propagate::Propagated;
use crate::propagate::first_order::{self, CorrelatedPair};
use crate::propagate::fourth_order::Order;
use crate::propagate::fusion::{FusionOptions, fuse};
use crate::propagate::odometry::{
    InputNoise, StepNoise, propagate_increments_each, propagate_tangent_inputs_each,
};
use crate::propagate::sigma_point::JointInputs;
use crate::sample::{Sampler, fill_par_from, joint_square_root, retract, standard_normal};
use crate::uncertain::{Method, Side, UncertainPose};

/// Compose (`X · Y`) or between (`X⁻¹ · Y`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Pair {
    Compose,
    Between,
}

impl Pair {
    fn apply<G: LieGroup<N>, const N: usize>(self, x: &G, y: &G) -> G {
        match self {
            Pair::Compose => x.compose(y),
            Pair::Between => x.between(y),
        }
    }
}

impl<G: EvalGroup<N>, const N: usize> Engine<'_, '_, G, N> {
    /// Evaluates one operation of the plan.
    pub(super) fn operation(&mut self, op: &Op<G, N>) -> Result<(), EvalError> {
        match op {
            Op::Inverse { input } => self.inverse(*input),
            Op::ChangeFrame { input, by, side } => self.change_frame(*input, *by, *side),
            Op::Compose {
                lhs,
                rhs,
                cross_cov,
            } => self.pair(*lhs, *rhs, cross_cov.as_ref(), Pair::Compose),
            Op::Between {
                lhs,
                rhs,
                cross_cov,
            } => self.pair(*lhs, *rhs, cross_cov.as_ref(), Pair::Between),
            Op::Odometry {
                input,
                model,
                controls,
                noise,
            } => self.odometry(*input, *model, controls, noise),
            Op::Compound {
                input,
                step,
                noise,
                noise_side,
                steps,
            } => self.compound(*input, *step, noise, *noise_side, *steps),
            Op::DiffDrive { start, motion } => self.diff_drive(*start, motion),
            Op::PointThroughPose {
                input,
                point,
                point_cov,
            } => self.point_through_pose(*input, point, point_cov),
            Op::Fuse { inputs } => self.fuse(inputs),
            Op::EulerVsExp { rate, dt, steps } => self.euler_vs_exp(rate, *dt, *steps),
        }
    }

    fn output(&self) -> String {
        self.current.1.clone()
    }

    /// First order, then `extra`, then sigma points through `map` where requested.
    fn estimates(
        &mut self,
        first: Propagated<G, N>,
        extra: Vec<Propagated<G, N>>,
        map: impl Fn(&[G]) -> G + Sync,
        inputs: crate::Result<JointInputs<G, N>>,
    ) -> Vec<Propagated<G, N>> {
        let mut out = vec![first];
        out.extend(extra);
        if self.wants(Method::SigmaPoints) {
            out.extend(self.sigma_points(inputs, map));
        }
        out
    }

    /// The Smith–Self–Cheeseman compose X·Y in vector coordinates, where requested and defined.
    fn vector_space(
        &mut self,
        x: &UncertainPose<G, N>,
        y: &UncertainPose<G, N>,
    ) -> Option<Propagated<G, N>> {
        if !self.wants(Method::VectorSpace) {
            return None;
        }
        match G::ssc_compose(x, y)? {
            Ok(r) => Some(r),
            Err(e) => {
                self.method_failed(None, Method::VectorSpace, e.to_string());
                None
            }
        }
    }

    fn single(
        &mut self,
        estimates: Vec<Propagated<G, N>>,
        particles: Option<Arc<Vec<G>>>,
    ) -> Result<(), EvalError> {
        let name = self.output();
        self.push(&name, Role::Output, Draft::single(estimates, particles))
    }

    /// X⁻¹.
    fn inverse(&mut self, input: Operand<G>) -> Result<(), EvalError> {
        let (x, px) = self.gaussian(input)?;
        let first = first_order::inverse(&x);
        let particles = px.map(|p| Arc::new(p.iter().map(G::inverse).collect()));
        let inputs = JointInputs::independent(&[x]);
        let estimates = self.estimates(first, Vec::new(), |g: &[G]| g[0].inverse(), inputs);
        self.single(estimates, particles)
    }

    /// `by · X` or `X · by`, `by` known.
    fn change_frame(&mut self, input: Operand<G>, by: G, side: FrameSide) -> Result<(), EvalError> {
        let (x, px) = self.gaussian(input)?;
        let known = UncertainPose::certain(by);
        let map = move |g: &G| match side {
            FrameSide::Left => by.compose(g),
            FrameSide::Right => g.compose(&by),
        };
        let (first, extra) = match side {
            FrameSide::Left => (
                first_order::change_frame_left(&by, &x),
                self.vector_space(&known, &x),
            ),
            FrameSide::Right => (
                first_order::change_frame_right(&x, &by),
                self.vector_space(&x, &known),
            ),
        };
        let particles = px.map(|p| Arc::new(p.iter().map(&map).collect()));
        let estimates = self.estimates(
            first,
            extra.into_iter().collect(),
            |g: &[G]| map(&g[0]),
            JointInputs::independent(&[x]),
        );
        self.single(estimates, particles)
    }

    /// X · Y or X⁻¹ · Y: independent operands, or correlated by Σ_XY.
    fn pair(
        &mut self,
        lhs: Operand<G>,
        rhs: Operand<G>,
        cross_cov: Option<&TangentMatrix<N>>,
        pair: Pair,
    ) -> Result<(), EvalError> {
        let (x, px) = self.gaussian(lhs)?;
        let (y, py) = self.gaussian(rhs)?;
        let map = move |g: &[G]| pair.apply(&g[0], &g[1]);
        if let Some(cross) = cross_cov {
            let joint = CorrelatedPair::with_cross(&x, &y, cross).map_err(|e| self.math(e))?;
            let first = match pair {
                Pair::Compose => first_order::compose_correlated(&joint),
                Pair::Between => first_order::between_correlated(&joint),
            };
            let particles = if self.monte_carlo {
                Some(Arc::new(self.joint_particles(&joint, pair)))
            } else {
                None
            };
            // Sigma points of the joint 2N-dimensional tangent [εX; εY], like the particles.
            let inputs = Ok(JointInputs::correlated(&joint));
            let estimates = self.estimates(first, Vec::new(), map, inputs);
            return self.single(estimates, particles);
        }
        let first = match pair {
            Pair::Compose => first_order::compose(&x, &y),
            Pair::Between => first_order::between(&x, &y),
        };
        let particles = (self.monte_carlo && (px.is_some() || py.is_some())).then(|| {
            let px = self.particles_of(&x, px);
            let py = self.particles_of(&y, py);
            Arc::new(
                px.iter()
                    .zip(py.iter())
                    .map(|(a, b)| pair.apply(a, b))
                    .collect(),
            )
        });
        let mut extra = Vec::new();
        if pair == Pair::Compose {
            for (order, method) in [
                (Order::Second, Method::SecondOrder),
                (Order::Fourth, Method::FourthOrder),
            ] {
                if self.wants(method) {
                    extra.extend(G::compound(&x, &y, order));
                }
            }
            extra.extend(self.vector_space(&x, &y));
        }
        let estimates = self.estimates(first, extra, map, JointInputs::independent(&[x, y]));
        self.single(estimates, particles)
    }

    /// Jointly sampled pairs (X, Y) mapped through compose/between. The pair is sampled from
    /// its joint Gaussian (upstream particles carry no correlation to reuse).
    fn joint_particles(&mut self, joint: &CorrelatedPair<G, N>, pair: Pair) -> Vec<G> {
        let family = self.next_family();
        let factor = joint_square_root(&joint.joint());
        let (mx, my) = joint.means();
        let side = joint.side();
        let mut out = vec![mx; self.block.len()];
        fill_par_from(
            &mut out,
            self.settings.seed,
            family,
            self.first_chunk(),
            |rng, chunk| {
                for z in chunk.iter_mut() {
                    let a = standard_normal::<N, _>(rng);
                    let b = standard_normal::<N, _>(rng);
                    let e =
                        &factor * DVector::from_iterator(2 * N, a.iter().chain(b.iter()).copied());
                    let ex = Tangent::<N>::from_iterator(e.rows(0, N).iter().copied());
                    let ey = Tangent::<N>::from_iterator(e.rows(N, N).iter().copied());
                    let (x, y) = (retract(&mx, &ex, side), retract(&my, &ey, side));
                    *z = pair.apply(&x, &y);
                }
            },
        );
        out
    }

    /// Odometry: analytic recursions, then every particle takes every step with fresh noise;
    /// statistics are taken at each recorded step as the particles pass.
    fn odometry(
        &mut self,
        input: Operand<G>,
        model: OdometryModel,
        controls: &[Control<G, N>],
        noise: &StepNoise<N>,
    ) -> Result<(), EvalError> {
        let (start, start_particles) = self.gaussian(input)?;
        let start_right = start.to_side(Side::Right);
        let increments: Vec<G> = controls.iter().map(|c| c.increment).collect();
        let mut tracks: Vec<Vec<Propagated<G, N>>> = Vec::new();
        match model {
            OdometryModel::Increment => tracks.push(
                propagate_increments_each(&start_right, &increments, noise)
                    .map_err(|e| self.math(e))?,
            ),
            OdometryModel::Exp => {
                let inputs: Vec<Tangent<N>> = controls.iter().map(|c| c.tangent).collect();
                tracks.push(
                    propagate_tangent_inputs_each(
                        &start_right,
                        &inputs,
                        noise,
                        InputNoise::RightJacobian,
                    )
                    .map_err(|e| self.math(e))?,
                );
                if self.wants(Method::LectureNoJr) {
                    tracks.push(
                        propagate_tangent_inputs_each(
                            &start_right,
                            &inputs,
                            noise,
                            InputNoise::LectureNoJr,
                        )
                        .map_err(|e| self.math(e))?,
                    );
                }
            }
        }
        if self.wants(Method::VectorSpace) {
            match (noise, noise.as_slice()) {
                (StepNoise::Same(_), [same]) => {
                    match G::ssc_odometry(&start_right, &increments, same) {
                        Some(Ok(track)) => tracks.push(track),
                        Some(Err(e)) => {
                            self.method_failed(None, Method::VectorSpace, e.to_string())
                        }
                        None => {}
                    }
                }
                _ => self.method_failed(None, Method::VectorSpace, "needs one Σ_w".into()),
            }
        }
        let last = controls.len() as u64;
        let name = self.output();
        let step_estimates = |k: usize| -> Vec<Propagated<G, N>> {
            tracks.iter().filter_map(|t| t.get(k).copied()).collect()
        };
        let mut current: Option<Vec<G>> = self
            .monte_carlo
            .then(|| self.particles_of(&start, start_particles).as_ref().clone());
        let samplers = Sampler::<G, N>::right_noise(noise.as_slice()).map_err(|e| self.math(e))?;
        self.push_step(&name, 0, last, step_estimates(0), current.as_deref())?;
        for (k, control) in controls.iter().enumerate() {
            if self.settings.cancelled() {
                self.out.findings.push(Finding::Interrupted);
                break;
            }
            if let (Some(particles), Some(sampler)) =
                (current.as_mut(), samplers.get(k).or(samplers.first()))
            {
                let family = self.next_family();
                let (seed, first_chunk) = (self.settings.seed, self.first_chunk());
                fill_par_map(particles, seed, family, first_chunk, |rng, x| {
                    let w = sampler.draw_tangent(rng);
                    match model {
                        OdometryModel::Increment => x.compose(&control.increment).rplus(&w),
                        OdometryModel::Exp => x.rplus(&(control.tangent + w)),
                    }
                });
            }
            self.push_step(
                &name,
                k as u64 + 1,
                last,
                step_estimates(k + 1),
                current.as_deref(),
            )?;
        }
        self.nominal_path(tracks[0].iter().map(|r| *r.pose.mean()).collect());
        self.thinned(last);
        Ok(())
    }

    /// Adds step `k` of the current propagation.
    fn push_step(
        &mut self,
        name: &str,
        k: u64,
        last: u64,
        estimates: Vec<Propagated<G, N>>,
        particles: Option<&[G]>,
    ) -> Result<(), EvalError> {
        // Barfoot & Furgale's uncentred Monte Carlo covariance, for compounding's plot.
        let extras = Extras {
            uncentred_left: self.current_kind() == Some(OpKind::Compound),
            position_mean: false,
        };
        let draft = Draft {
            step: Some(k),
            last_step: Some(last),
            estimates,
            particles: particles.map_or(Particles::None, Particles::Step),
            extras,
        };
        self.push(name, Role::Output, draft)
    }

    fn nominal_path(&mut self, poses: Vec<G>) {
        self.out.paths.push(PosePath {
            output: self.output(),
            kind: PathKind::Nominal,
            poses,
        });
    }

    /// Says when a long propagation recorded only some steps.
    fn thinned(&mut self, last: u64) {
        let recorded = (0..=last)
            .filter(|k| self.settings.steps.records(*k, last))
            .count() as u64;
        if recorded < last + 1 {
            self.out.findings.push(Finding::StepsThinned {
                output: self.output(),
                steps: last,
                recorded,
            });
        }
    }

    /// Barfoot & Furgale's repeated compounding T_k = (Exp(w) T̄) · T_{k−1}, left form.
    fn compound(
        &mut self,
        input: Operand<G>,
        step_mean: G,
        noise: &TangentMatrix<N>,
        noise_side: Side,
        steps: u64,
    ) -> Result<(), EvalError> {
        let (start, start_particles) = self.gaussian(input)?;
        let increment = UncertainPose::new_unchecked(step_mean, *noise, noise_side);
        let orders: Vec<(Order, Method)> = [
            (Order::Second, Method::SecondOrder),
            (Order::Fourth, Method::FourthOrder),
        ]
        .into_iter()
        .filter(|(_, m)| self.wants(*m))
        .collect();
        let mut first = Propagated {
            pose: start.to_side(noise_side),
            method: Method::FirstOrder,
        };
        let mut higher: Vec<Propagated<G, N>> = orders
            .iter()
            .map(|(_, m)| Propagated {
                pose: start.to_side(Side::Left),
                method: *m,
            })
            .collect();
        let mut current: Option<Vec<G>> = self
            .monte_carlo
            .then(|| self.particles_of(&start, start_particles).as_ref().clone());
        let sampler = Sampler::new(&increment).map_err(|e| self.math(e))?;
        let name = self.output();
        let mut nominal = vec![*first.pose.mean()];
        let all = |first: &Propagated<G, N>, higher: &[Propagated<G, N>]| {
            let mut v = vec![*first];
            v.extend_from_slice(higher);
            v
        };
        self.push_step(&name, 0, steps, all(&first, &higher), current.as_deref())?;
        for k in 1..=steps {
            if self.settings.cancelled() {
                self.out.findings.push(Finding::Interrupted);
                break;
            }
            first = first_order::compose(&increment, &first.pose);
            for (h, (order, _)) in higher.iter_mut().zip(&orders) {
                if let Some(next) = G::compound(&increment, &h.pose, *order) {
                    *h = next;
                }
            }
            if let Some(particles) = current.as_mut() {
                let family = self.next_family();
                let first_chunk = self.first_chunk();
                fill_par_map(
                    particles,
                    self.settings.seed,
                    family,
                    first_chunk,
                    |rng, x| sampler.draw(rng).compose(x),
                );
            }
            nominal.push(*first.pose.mean());
            self.push_step(&name, k, steps, all(&first, &higher), current.as_deref())?;
        }
        self.nominal_path(nominal);
        self.thinned(steps);
        Ok(())
    }

    /// An uncertain point seen from an uncertain pose.
    fn point_through_pose(
        &mut self,
        input: Operand<G>,
        point: &Vector3<f64>,
        point_cov: &Matrix3<f64>,
    ) -> Result<(), EvalError> {
        let (pose, particles) = self.gaussian(input)?;
        let first = G::point_through(&pose, point, point_cov).map_err(|e| self.math(e))?;
        let mut cloud = None;
        if let Some(particles) = particles.filter(|_| self.monte_carlo) {
            let family = self.next_family();
            let dims = G::KIND.space_dims();
            let factor = joint_square_root(&DMatrix::from_fn(dims, dims, |r, c| point_cov[(r, c)]));
            let mut points = vec![[0.0; 3]; particles.len()];
            let (seed, first_chunk) = (self.settings.seed, self.first_chunk());
            fill_par_from(&mut points, seed, family, first_chunk, |rng, chunk| {
                for q in chunk.iter_mut() {
                    let z = standard_normal::<3, _>(rng);
                    let noise =
                        &factor * DVector::from_iterator(dims, z.iter().take(dims).copied());
                    let mut p = *point;
                    for (i, n) in noise.iter().enumerate() {
                        p[i] += n;
                    }
                    *q = [p.x, p.y, p.z];
                }
            });
            cloud = Some(
                particles
                    .iter()
                    .zip(&points)
                    .map(|(x, q)| {
                        let w = x.to_se3().act(&Vector3::from(*q));
                        [w.x, w.y, w.z]
                    })
                    .collect(),
            );
        }
        let name = self.output();
        self.push_point(&name, first, cloud)
    }

    /// Gauss–Newton fusion of independent estimates.
    fn fuse(&mut self, inputs: &[Operand<G>]) -> Result<(), EvalError> {
        let estimates = inputs
            .iter()
            .map(|o| self.gaussian(*o).map(|(pose, _)| pose))
            .collect::<Result<Vec<_>, _>>()?;
        let fused = fuse(&estimates, FusionOptions::default()).map_err(|e| {
            use crate::propagate::fusion::FusionError;
            let (input, source) = match e {
                FusionError::Estimate { index, source } => (Some(index), source),
                FusionError::Input(source)
                | FusionError::Information(source)
                | FusionError::NotConverged { source, .. } => (None, source),
            };
            EvalError::Fusion {
                operation: self.current.0,
                output: self.output(),
                input,
                source,
            }
        })?;
        self.out.findings.push(Finding::Fusion {
            output: self.output(),
            inputs: estimates.len(),
            // Barfoot & Furgale's V carries the ½ that the Gauss–Newton objective J omits.
            cost: 0.5 * fused.cost,
            iterations: fused.iterations,
        });
        // Fusion has no sampled counterpart: Monte Carlo downstream continues from samples
        // of the fused Gaussian (not from its mean, which would lose the uncertainty).
        let particles = if self.monte_carlo {
            let sampled = self.sample(&fused.result.pose).map_err(|e| self.math(e))?;
            Some(Arc::new(sampled))
        } else {
            None
        };
        self.single(vec![fused.result], particles)
    }

    /// A differential-drive robot from a known start (Long et al. 2012).
    fn diff_drive(&mut self, start: G, motion: &DiffDriveMotion) -> Result<(), EvalError> {
        let samples = if self.monte_carlo {
            self.block.len()
        } else {
            0
        };
        let seed = self.settings.seed.wrapping_add(self.next_family());
        let integral = self.wants(Method::NumericIntegral);
        let outcome = match G::diff_drive(motion, integral, samples, self.first_chunk(), seed) {
            None => {
                return Err(EvalError::WrongGroup {
                    operation: self.current.0,
                    output: self.output(),
                    what: "diff_drive",
                    group: G::NAME,
                });
            }
            Some(Err(e)) => return Err(self.math(e)),
            Some(Ok(o)) => o,
        };
        let moved = |g: &G| start.compose(g);
        // Results are relative to the start pose: move them with a known left change of frame.
        let estimates: Vec<Propagated<G, N>> = outcome
            .estimates
            .iter()
            .filter(|e| self.wants(e.method) || e.method == Method::ClosedForm)
            .map(|e| Propagated {
                pose: first_order::change_frame_left(&start, &e.pose).pose,
                method: e.method,
            })
            .collect();
        let particles = (!outcome.end_poses.is_empty())
            .then(|| Arc::new(outcome.end_poses.iter().map(moved).collect::<Vec<G>>()));
        let name = self.output();
        let mut draft = Draft::single(estimates, particles);
        draft.extras.position_mean = true;
        self.push(&name, Role::Output, draft)?;
        let node = &self.out.nodes[self.out.nodes.len() - 1];
        if let (Some(mc), Some(end)) = (&node.monte_carlo, outcome.nominal_path.last())
            && let Some(cartesian) = mc.position_mean
        {
            let lie = mc.stats.mean.to_se3();
            let nominal = moved(end).to_se3();
            self.out.findings.push(Finding::DiffDriveMeans {
                output: name,
                diffusion: motion.diffusion,
                nominal_end: [nominal.translation().x, nominal.translation().y],
                lie_mean: [lie.translation().x, lie.translation().y],
                cartesian_mean: [cartesian.x, cartesian.y],
            });
        }
        self.nominal_path(outcome.nominal_path.iter().map(moved).collect());
        for (i, t) in outcome.trajectories.iter().enumerate() {
            self.out.paths.push(PosePath {
                output: self.output(),
                kind: PathKind::Sample(i),
                poses: t.iter().map(moved).collect(),
            });
        }
        Ok(())
    }

    /// Euler integration R(I + ω̂dt) against R·Exp(ωdt), from the identity.
    fn euler_vs_exp(&mut self, rate: &Vector3<f64>, dt: f64, steps: u64) -> Result<(), EvalError> {
        let Some(track) = G::euler_vs_exp(rate, dt, steps) else {
            return Err(EvalError::WrongGroup {
                operation: self.current.0,
                output: self.output(),
                what: "euler_vs_exp",
                group: G::NAME,
            });
        };
        let output = self.output();
        let name = format!("{output}_exp");
        let drift = |m: &Matrix3<f64>| (m.transpose() * m - Matrix3::identity()).amax();
        for (k, (euler, exp)) in track.iter().enumerate() {
            let k = k as u64;
            if !self.settings.steps.records(k, steps) {
                continue;
            }
            if !euler.iter().all(|v| v.abs() <= limits::OVERFLOW_COORDINATE) {
                return Err(EvalError::NonFinite {
                    operation: self.current.0,
                    output,
                    step: Some(k),
                    method: "Euler integration",
                });
            }
            self.out.matrix_frames.push(MatrixFrame {
                output: output.clone(),
                step: k,
                columns: *euler,
            });
            // A rotation known exactly: a node with no estimate, drawn as its frame.
            self.out.nodes.push(Node {
                name: name.clone(),
                role: Role::Output,
                op: Some(OpKind::EulerVsExp),
                step: Some(k),
                last_step: Some(steps),
                nominal: *exp,
                estimates: Vec::new(),
                monte_carlo: None,
                particles: None,
            });
        }
        if let Some((m, g)) = track.last() {
            self.out.findings.push(Finding::EulerDrift {
                output,
                steps,
                dt,
                euler: drift(m),
                exp: drift(&g.to_se3().rotation().to_matrix()),
            });
        }
        self.thinned(steps);
        Ok(())
    }
}

/// `x ← f(rng, x)` over a slice, in parallel, deterministic per seed and family.
fn fill_par_map<G: Copy + Send + Sync>(
    xs: &mut [G],
    seed: u64,
    family: u64,
    first_chunk: u64,
    f: impl Fn(&mut rand_chacha::ChaCha8Rng, &G) -> G + Sync,
) {
    fill_par_from(xs, seed, family, first_chunk, |rng, chunk| {
        for x in chunk.iter_mut() {
            *x = f(rng, x);
        }
    });
}
