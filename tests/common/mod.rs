//! Shared test helpers: seeded tangent samples in four regimes and central finite
//! differences on the manifold. Used by every group suite. Also Monte Carlo through the
//! plan + eval engine (the crate's one Monte Carlo engine): settings, evaluation, node access.
#![allow(dead_code)]

use nalgebra::{SMatrix, SVector};
use posecov::eval::{AnyEvaluation, EvalSettings, Evaluation, Node, evaluate};
use posecov::lie::{LieGroup, Se2, Se3, So2, So3, Tangent, TangentMatrix};
use posecov::plan::{AnyPlan, Control, OdometryModel, Op, Plan, StepNoise, StepPolicy};
use posecov::sample::SampleStatistics;
use posecov::uncertain::Method;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Where a tangent sample lives: the branches a closed form can take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Regime {
    /// τ = 0 exactly.
    Identity,
    /// ‖τ‖ ≈ 1e-8: the Taylor branches.
    Tiny,
    /// Uniform in a box: the closed forms.
    Random,
    /// Rotation angle π − 1e-6: the Log branch near π.
    NearPi,
}

/// All four regimes.
pub const REGIMES: [Regime; 4] = [
    Regime::Identity,
    Regime::Tiny,
    Regime::Random,
    Regime::NearPi,
];

/// Samples per regime (Identity gives one distinct sample, repeated).
pub const SAMPLES: usize = 8;

/// Finite-difference step for a regime: near π a step must not cross the cut at π.
pub fn fd_step(regime: Regime) -> f64 {
    match regime {
        Regime::NearPi => 1e-8,
        _ => 1e-5,
    }
}

/// Seeded tangent samples for a regime. `rot` is the index range of the rotation part.
pub fn tangents<const N: usize>(
    regime: Regime,
    rot: std::ops::Range<usize>,
    seed: u64,
) -> Vec<SVector<f64, N>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..SAMPLES)
        .map(|_| {
            let mut v = SVector::<f64, N>::from_fn(|_, _| rng.random_range(-1.0..1.0));
            match regime {
                Regime::Identity => v.fill(0.0),
                Regime::Tiny => v *= 1e-8 / v.norm(),
                Regime::Random => v *= 2.0,
                Regime::NearPi => {
                    let mut r = v.rows_range_mut(rot.clone());
                    let n = r.norm();
                    r *= (std::f64::consts::PI - 1e-6) / n;
                }
            }
            v
        })
        .collect()
}

/// Central-difference Jacobian of g at 0: column i = (g(h eᵢ) − g(−h eᵢ)) / 2h.
/// Callers build g as "perturb the input on the manifold, take the output's ⊖ against the
/// unperturbed output", so this is the Jacobian with respect to right perturbations.
pub fn numeric_jacobian<const I: usize, const O: usize>(
    g: impl Fn(&SVector<f64, I>) -> SVector<f64, O>,
    h: f64,
) -> SMatrix<f64, O, I> {
    let mut j = SMatrix::<f64, O, I>::zeros();
    for i in 0..I {
        let mut e = SVector::<f64, I>::zeros();
        e[i] = h;
        j.set_column(i, &((g(&e) - g(&-e)) / (2.0 * h)));
    }
    j
}

/// Asserts max |a − b| ≤ tol with a readable message.
#[track_caller]
pub fn assert_close<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
    tol: f64,
    what: &str,
) {
    let err = (a - b).amax();
    assert!(
        err <= tol,
        "{what}: max abs error {err:.3e} > {tol:.1e}\n left: {a}\n right: {b}"
    );
}

/// A seeded random symmetric positive-definite matrix A Aᵀ · scale + 1e-3 · scale · I
/// (entries of A uniform in [−1, 1]): well conditioned, with correlations.
pub fn random_spd<const N: usize>(seed: u64, scale: f64) -> SMatrix<f64, N, N> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let a = SMatrix::<f64, N, N>::from_fn(|_, _| rng.random_range(-1.0..1.0));
    (a * a.transpose() + SMatrix::<f64, N, N>::identity() * 1e-3) * scale
}

/// `n` seeded draws of N(0, Σ) as L z with L Lᵀ = Σ (Cholesky) and z standard normal.
/// Panics if Σ is not positive definite (test inputs only).
pub fn gaussian_draws<const N: usize>(
    cov: &SMatrix<f64, N, N>,
    n: usize,
    seed: u64,
) -> Vec<SVector<f64, N>> {
    use rand_distr::StandardNormal;
    let l = cov
        .cholesky()
        .expect("test covariance must be positive definite")
        .l();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| l * SVector::<f64, N>::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal)))
        .collect()
}

/// Sample covariance about zero, (1/n) Σ εεᵀ (the perturbations are already taken about the
/// propagated mean).
pub fn uncentred_cov<const N: usize>(samples: &[SVector<f64, N>]) -> SMatrix<f64, N, N> {
    let mut cov = SMatrix::<f64, N, N>::zeros();
    for e in samples {
        cov += e * e.transpose();
    }
    cov / samples.len() as f64
}

/// [REFERENCE_CASES R4] inputs u_k = (v1, 1.5 v1, 0.05 e^(0.6 v1) − 0.05, ω1, ω2, ω3), k = 0..3.
///
/// [REFERENCE_CASES R4]: posecov::reference_cases#r4-se3-odometry-noise-inside-exp-rob-530
pub fn r4_inputs() -> Vec<nalgebra::Vector6<f64>> {
    let v1: [f64; 4] = [0.0, 4.0 / 3.0, 8.0 / 3.0, 4.0];
    let w1 = [0.0, 1.0 / 6.0, 1.0 / 3.0, 0.5];
    let w2 = [0.0, 0.1, 0.2, 0.3];
    let w3 = [0.0, 0.7 / 3.0, 1.4 / 3.0, 0.7];
    (0..4)
        .map(|k| {
            nalgebra::Vector6::new(
                v1[k],
                1.5 * v1[k],
                0.05 * (0.6 * v1[k]).exp() - 0.05,
                w1[k],
                w2[k],
                w3[k],
            )
        })
        .collect()
}

/// [REFERENCE_CASES R4] noise Σ_w = diag(0.01², 0.01², 0.05², 0.05², 0.05², 0.2²).
///
/// [REFERENCE_CASES R4]: posecov::reference_cases#r4-se3-odometry-noise-inside-exp-rob-530
pub fn r4_noise() -> nalgebra::Matrix6<f64> {
    nalgebra::Matrix6::from_diagonal(&nalgebra::Vector6::new(
        0.01f64.powi(2),
        0.01f64.powi(2),
        0.05f64.powi(2),
        0.05f64.powi(2),
        0.05f64.powi(2),
        0.2f64.powi(2),
    ))
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo through the plan + eval engine.

/// A group whose plans the helpers below evaluate: into [`AnyPlan`] and back out of
/// [`AnyEvaluation`].
pub trait PlanGroup<const N: usize>: LieGroup<N> {
    /// The plan as an [`AnyPlan`].
    fn any_plan(plan: Plan<Self, N>) -> AnyPlan;
    /// The evaluation of this group (panics on another group).
    fn evaluation(e: AnyEvaluation) -> Evaluation<Self, N>;
}

macro_rules! plan_group {
    ($g:ty, $n:literal, $v:ident) => {
        impl PlanGroup<$n> for $g {
            fn any_plan(plan: Plan<Self, $n>) -> AnyPlan {
                AnyPlan::$v(plan)
            }
            fn evaluation(e: AnyEvaluation) -> Evaluation<Self, $n> {
                match e {
                    AnyEvaluation::$v(e) => e,
                    other => panic!("expected {}, got {:?}", stringify!($v), other.group()),
                }
            }
        }
    };
}
plan_group!(So2, 1, So2);
plan_group!(Se2, 3, Se2);
plan_group!(So3, 3, So3);
plan_group!(Se3, 6, Se3);

/// Monte Carlo only: `samples` particles from `seed`, simulated in one block (so every kept
/// node's `particles` is the whole sample), every step of a propagation recorded and kept.
pub fn mc_settings(samples: usize, seed: u64) -> EvalSettings {
    EvalSettings {
        samples,
        seed,
        methods: vec![Method::MonteCarlo],
        block_samples: Some(samples),
        steps: StepPolicy {
            max_recorded: u64::MAX,
            max_detailed: u64::MAX,
            max_sampled: u64::MAX,
        },
        ..Default::default()
    }
}

/// Evaluates `plan` (panics on an error).
pub fn evaluate_plan<G: PlanGroup<N>, const N: usize>(
    plan: Plan<G, N>,
    settings: &EvalSettings,
) -> Evaluation<G, N> {
    G::evaluation(evaluate(&G::any_plan(plan), settings).expect("the plan evaluates"))
}

/// The nodes named `name`, in evaluation order (step 0 first for a propagation).
pub fn nodes<'e, G: LieGroup<N>, const N: usize>(
    e: &'e Evaluation<G, N>,
    name: &str,
) -> Vec<&'e Node<G, N>> {
    let found: Vec<_> = e.nodes.iter().filter(|n| n.name == name).collect();
    assert!(!found.is_empty(), "no node named {name}");
    found
}

/// A node's Monte Carlo statistics: the Lie mean and the centred 1/(N−1) covariance, right
/// side (panics where Monte Carlo did not run).
pub fn mc_stats<G: LieGroup<N>, const N: usize>(node: &Node<G, N>) -> SampleStatistics<G, N> {
    let stats = node
        .monte_carlo
        .as_ref()
        .unwrap_or_else(|| panic!("{} (step {:?}): no Monte Carlo", node.name, node.step))
        .stats;
    assert_eq!(
        node.estimates.last().map(|e| e.result.method),
        Some(Method::MonteCarlo),
        "the Monte Carlo estimate comes last"
    );
    stats
}

/// A node's particles (panics where it kept none).
pub fn particles<G: LieGroup<N>, const N: usize>(node: &Node<G, N>) -> &[G] {
    node.particles
        .as_deref()
        .unwrap_or_else(|| panic!("{} (step {:?}): no particles", node.name, node.step))
}

/// Odometry controls from increments U_k (u_k = Log U_k).
pub fn increment_controls<G: LieGroup<N>, const N: usize>(increments: &[G]) -> Vec<Control<G, N>> {
    increments
        .iter()
        .map(|u| Control {
            increment: *u,
            tangent: u.log(),
        })
        .collect()
}

/// Odometry controls from tangents u_k (U_k = Exp u_k).
pub fn tangent_controls<G: LieGroup<N>, const N: usize>(
    inputs: &[Tangent<N>],
) -> Vec<Control<G, N>> {
    inputs
        .iter()
        .map(|u| Control {
            increment: G::exp(u),
            tangent: *u,
        })
        .collect()
}

/// A plan of one odometry operation, output `x`, from the known pose `start`: nodes `x` at
/// steps 0 ..= controls.len().
pub fn odometry_plan<G: LieGroup<N>, const N: usize>(
    start: G,
    model: OdometryModel,
    controls: Vec<Control<G, N>>,
    noise: TangentMatrix<N>,
) -> Plan<G, N> {
    let mut plan = Plan::default();
    let input = plan.known("start", start);
    plan.operation(
        "x",
        Op::Odometry {
            input,
            model,
            controls,
            noise: StepNoise::Same(noise),
        },
    );
    plan
}
pub mod logs;
