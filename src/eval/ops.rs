//! One function per [`Op`]: the analytic methods, the particles, and the node(s) each
//! operation adds. Dispatch is [`Engine::operation`].

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::EvalError;
use super::engine::{Draft, Engine, LeftTranslated};
use super::groups::EvalGroup;
use super::model::{FailureReason, Finding, Role};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::plan::{FrameSide, Op, Operand};
use crate::propagate::Propagated;
use crate::propagate::first_order::{self, CorrelatedPair};
use crate::propagate::fourth_order::Order;
use crate::propagate::fusion::{FusionOptions, fuse};
use crate::propagate::sigma_point::JointInputs;
use crate::sample::{fill_par_from, joint_square_root, retract, standard_normal};
use crate::uncertain::{Method, UncertainPose};

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

    pub(super) fn output(&self) -> String {
        self.current.output.clone()
    }

    /// First order, then `extra`, then sigma points through `map` where requested.
    pub(super) fn estimates(
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
    pub(super) fn vector_space(
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
                self.method_failed(
                    None,
                    Method::VectorSpace,
                    FailureReason::Refused {
                        message: e.to_string(),
                    },
                );
                None
            }
        }
    }

    pub(super) fn single(
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
        let moved_from = match side {
            FrameSide::Left => self.node_of(input),
            FrameSide::Right => None,
        };
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
        let name = self.output();
        let mut draft = Draft::single(estimates, particles);
        draft.stats_from = moved_from.map(|of| LeftTranslated { of, by });
        self.push(&name, Role::Output, draft)
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
                operation: self.current.operation,
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
}

/// `run(c, chunk)` over the slice's chunks of [`CHUNK_SIZE`](crate::sample::CHUNK_SIZE), in
/// parallel: chunk `c` (counted from the slice's start) makes its own generators, e.g. one per
/// step of a run of steps with [`chunk_rng`](crate::sample::chunk_rng)`(seed, family_k,
/// first_chunk + c)` — the draws [`fill_par_map`] makes one step at a time.
pub(super) fn fill_par_runs<G: Send>(xs: &mut [G], run: impl Fn(u64, &mut [G]) + Sync) {
    use rayon::prelude::*;
    xs.par_chunks_mut(crate::sample::CHUNK_SIZE)
        .enumerate()
        .for_each(|(c, chunk)| run(c as u64, chunk));
}

/// `x ← f(rng, x)` over a slice, in parallel, deterministic per seed and family.
pub(super) fn fill_par_map<G: Copy + Send + Sync>(
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
