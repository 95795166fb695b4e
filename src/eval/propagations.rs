//! The propagations among the operations ([`Op`](crate::plan::Op)): odometry, compounding,
//! differential drive and Euler against Exp, each a track of steps; the other operations are
//! in `ops.rs`.

use std::sync::Arc;

use nalgebra::Vector3;

use super::EvalError;
use super::engine::{Draft, Engine, Extras, Particles};
use super::groups::EvalGroup;
use super::model::{
    FailureReason, Finding, MatrixFrame, Node, PathKind, PosePath, Role, orthogonality_error,
};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::plan::{Control, DiffDriveMotion, OdometryModel, OpKind, Operand, limits};
use crate::propagate::Propagated;
use crate::propagate::first_order::{self};
use crate::propagate::fourth_order::Order;
use crate::propagate::odometry::{
    InputNoise, StepNoise, propagate_increments_each, propagate_tangent_inputs_each,
};
use crate::sample::Sampler;
use crate::uncertain::{Method, Side, UncertainPose};

use super::ops::{fill_par_map, fill_par_runs};
use crate::sample::chunk_rng;

impl<G: EvalGroup<N>, const N: usize> Engine<'_, '_, G, N> {
    /// Odometry: analytic recursions, then every particle takes every step with fresh noise;
    /// statistics are taken at each recorded step as the particles pass.
    pub(super) fn odometry(
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
                        Some(Err(e)) => self.method_failed(
                            None,
                            Method::VectorSpace,
                            FailureReason::Refused {
                                message: e.to_string(),
                            },
                        ),
                        None => {}
                    }
                }
                _ => self.method_failed(None, Method::VectorSpace, FailureReason::NeedsOneNoise),
            }
        }
        let last = controls.len() as u64;
        let name = self.output();
        let policy = self.settings.steps;
        let step_estimates = |k: usize| -> Vec<Propagated<G, N>> {
            tracks.iter().filter_map(|t| t.get(k).copied()).collect()
        };
        let mut current: Option<Vec<G>> = self
            .monte_carlo
            .then(|| self.particles_of(&start, start_particles).as_ref().clone());
        let samplers = Sampler::<G, N>::right_noise(noise.as_slice()).map_err(|e| self.math(e))?;
        let first = current.as_deref().filter(|_| policy.samples(0, last));
        self.push_step(&name, 0, last, step_estimates(0), first)?;
        // From one sampled step to the next, each chunk of particles takes every step in one
        // task (the same draws as one parallel pass per step: step k's family, chunk c's
        // stream); the recorded steps between keep their analytic numbers only.
        let mut done = 0usize;
        while done < controls.len() {
            if self.settings.cancelled() {
                self.out.findings.push(Finding::Interrupted);
                break;
            }
            let recorded = |k: usize| policy.records(k as u64, last);
            let sampled = |k: usize| policy.samples(k as u64, last);
            let next = match current {
                Some(_) => (done + 1..=controls.len()).find(|&k| sampled(k)),
                None => (done + 1..=controls.len()).find(|&k| recorded(k)),
            }
            .unwrap_or(controls.len());
            if let Some(particles) = current.as_mut() {
                let families: Vec<u64> = (done..next).map(|_| self.next_family()).collect();
                let (seed, first_chunk) = (self.settings.seed, self.first_chunk());
                let run: Vec<(&Control<G, N>, Option<&Sampler<G, N>>)> = (done..next)
                    .map(|k| (&controls[k], samplers.get(k).or(samplers.first())))
                    .collect();
                fill_par_runs(particles, |c, chunk| {
                    for ((control, sampler), &family) in run.iter().zip(&families) {
                        let Some(sampler) = sampler else { continue };
                        let mut rng = chunk_rng(seed, family, first_chunk + c);
                        for x in chunk.iter_mut() {
                            let w = sampler.draw_tangent(&mut rng);
                            *x = match model {
                                OdometryModel::Increment => x.compose(&control.increment).rplus(&w),
                                OdometryModel::Exp => x.rplus(&(control.tangent + w)),
                            };
                        }
                    }
                });
            }
            if let (Some(particles), Some(hook)) =
                (current.as_ref(), &self.settings.monte_carlo_progress)
            {
                (hook.0)(next, controls.len(), particles.len());
            }
            for k in (done + 1..next).filter(|&k| recorded(k)) {
                self.push_step(&name, k as u64, last, step_estimates(k), None)?;
            }
            self.push_step(
                &name,
                next as u64,
                last,
                step_estimates(next),
                current.as_deref().filter(|_| sampled(next)),
            )?;
            done = next;
        }
        self.nominal_path(tracks[0].iter().map(|r| *r.pose.mean()).collect());
        self.thinned(last);
        Ok(())
    }

    /// Adds step `k` of the current propagation.
    pub(super) fn push_step(
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
            stats_from: None,
        };
        self.push(name, Role::Output, draft)
    }

    pub(super) fn nominal_path(&mut self, poses: Vec<G>) {
        self.out.trajectories.push(PosePath {
            output: self.output(),
            kind: PathKind::Nominal,
            poses,
        });
    }

    /// Says when a long propagation recorded only some steps, or took Monte Carlo statistics
    /// at only some of them.
    pub(super) fn thinned(&mut self, last: u64) {
        let policy = self.settings.steps;
        let recorded = (0..=last).filter(|k| policy.records(*k, last)).count() as u64;
        let sampled = if self.monte_carlo {
            (0..=last).filter(|k| policy.samples(*k, last)).count() as u64
        } else {
            recorded
        };
        if recorded < last + 1 || sampled < recorded {
            self.out.findings.push(Finding::StepsThinned {
                output: self.output(),
                steps: last,
                recorded,
                sampled,
            });
        }
    }

    /// Barfoot & Furgale's repeated compounding T_k = (Exp(w) T̄) · T_{k−1}, left form.
    pub(super) fn compound(
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

    /// A differential-drive robot from a known start (Long et al. 2012).
    pub(super) fn diff_drive(
        &mut self,
        start: G,
        motion: &DiffDriveMotion,
    ) -> Result<(), EvalError> {
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
                    operation: self.current.operation,
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
                cartesian_mean_stderr: mc.position_mean_stderr.map(|s| [s.x, s.y]),
            });
        }
        self.nominal_path(outcome.nominal_path.iter().map(moved).collect());
        for (i, t) in outcome.trajectories.iter().enumerate() {
            self.out.trajectories.push(PosePath {
                output: self.output(),
                kind: PathKind::Sample(i),
                poses: t.iter().map(moved).collect(),
            });
        }
        Ok(())
    }

    /// Euler integration R(I + ω̂dt) against R·Exp(ωdt), from the identity.
    pub(super) fn euler_vs_exp(
        &mut self,
        rate: &Vector3<f64>,
        dt: f64,
        steps: u64,
    ) -> Result<(), EvalError> {
        let Some(track) = G::euler_vs_exp(rate, dt, steps) else {
            return Err(EvalError::WrongGroup {
                operation: self.current.operation,
                output: self.output(),
                what: "euler_vs_exp",
                group: G::NAME,
            });
        };
        let output = self.output();
        let name = format!("{output}_exp");
        for (k, (euler, exp)) in track.iter().enumerate() {
            let k = k as u64;
            if !self.settings.steps.records(k, steps) {
                continue;
            }
            if !euler.iter().all(|v| v.abs() <= limits::OVERFLOW_COORDINATE) {
                return Err(EvalError::NonFinite {
                    operation: self.current.operation,
                    output,
                    step: Some(k),
                    method: "Euler integration",
                });
            }
            self.out.matrix_frames.push(MatrixFrame {
                output: output.clone(),
                exp_node: name.clone(),
                step: k,
                columns: *euler,
                orthogonality_error: orthogonality_error(euler),
                exp_orthogonality_error: orthogonality_error(&exp.to_se3().rotation().to_matrix()),
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
                euler: orthogonality_error(m),
                exp: orthogonality_error(&g.to_se3().rotation().to_matrix()),
            });
        }
        self.thinned(steps);
        Ok(())
    }
}
