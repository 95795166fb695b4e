//! The NA 568 / ROB 530 SE(2) workload ([REFERENCE_CASES R2]) end to end in posecov: 1000
//! particles, 7 steps of X_{k+1} = X_k · U_k · Exp(w_k), and at every step the iterative Lie
//! sample mean and the 1/(N−1) covariance about it. Measured: `eval::evaluate` of a plan with
//! one `Op::Odometry` (the crate's Monte Carlo engine; it also runs the first-order recursion
//! and keeps each step's particles). Its NumPy/SciPy twin is `benches/na568_numpy.py` (run by
//! `benches/run_numpy.sh`); BENCHMARKS.md gives the ratio.
//!
//! Run: `cargo bench --no-default-features --bench na568 -- --warm-up-time 1 --measurement-time 3`
//!
//! [REFERENCE_CASES R2]: posecov::reference_cases#r2-se2-odometry-na-568

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix3, Vector3};
use posecov::eval::{AnyEvaluation, EvalSettings, evaluate};
use posecov::lie::{LieGroup, Se2};
use posecov::plan::{AnyPlan, Control, OdometryModel, Op, Plan, StepNoise};
use posecov::uncertain::Method;
use rayon::ThreadPoolBuilder;

/// Particles, as in the lecture script.
const PARTICLES: usize = 1000;

/// R2 inputs: u1 = 0.6 every step; u2, u3 per step (7 steps).
const U2: [f64; 7] = [
    0.043333, 0.062110, 0.089025, 0.127602, 0.182895, 0.262149, 0.375746,
];
const U3: [f64; 7] = [
    0.072096, 0.031054, 0.044150, 0.062248, 0.086330, 0.116042, 0.147573,
];

fn na568(c: &mut Criterion) {
    // U_i = [[R(u3), (u1, u2)ᵀ], [0 0, 1]]: the translation is (u1, u2) itself.
    let increments: Vec<Se2> = (0..7)
        .map(|i| Se2::from_xy_theta(0.6, U2[i], U3[i]))
        .collect();
    let noise = Matrix3::from_diagonal(&Vector3::new(
        0.03f64.powi(2),
        0.03f64.powi(2),
        0.1f64.powi(2),
    ));
    let mut plan = Plan::<Se2, 3>::default();
    let start = plan.known("start", Se2::identity());
    plan.operation(
        "robot",
        Op::Odometry {
            input: start,
            model: OdometryModel::Increment,
            controls: increments
                .iter()
                .map(|u| Control {
                    increment: *u,
                    tangent: u.log(),
                })
                .collect(),
            noise: StepNoise::Same(noise),
        },
    );
    let plan = AnyPlan::Se2(plan);
    let settings = EvalSettings {
        samples: PARTICLES,
        seed: 568,
        methods: vec![Method::MonteCarlo],
        ..Default::default()
    };

    // Sanity: the last step's Lie mean lands near the R2 nominal pose (3.802082, 1.827062, 0.559493).
    let AnyEvaluation::Se2(e) = evaluate(&plan, &settings).expect("R2 runs") else {
        unreachable!("an SE(2) plan")
    };
    let steps: Vec<_> = e.nodes.iter().filter(|n| n.name == "robot").collect();
    assert_eq!(steps.len(), 8);
    assert!(steps.iter().all(|n| n.monte_carlo.is_some()));
    let last = &steps[7]
        .monte_carlo
        .as_ref()
        .expect("Monte Carlo ran")
        .stats
        .mean;
    assert!(
        last.is_approx(&Se2::from_xy_theta(3.802082, 1.827062, 0.559493), 0.1),
        "{last}"
    );

    let mut g = c.benchmark_group("na568.se2_1000x7");
    g.sample_size(20);
    for threads in [1, 2] {
        let pool = ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a rayon pool");
        g.bench_function(format!("posecov/{threads}t"), |b| {
            b.iter(|| {
                pool.install(|| black_box(evaluate(black_box(&plan), &settings).expect("R2 runs")))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, na568);
criterion_main!(benches);
