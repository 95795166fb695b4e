//! Pose graphs, small enough for criterion's repeated samples: `eval::graph::optimize` —
//! Levenberg–Marquardt to convergence from the file's estimates, then every pose's marginal
//! by selected inversion of the undamped factor — on GTSAM's `pose2example` (11 poses, BSD,
//! in `tests/data/`) and on seeded Manhattan-world walks with loop closures (1000 poses in the
//! plane, 500 in space; the test suite's generator). The large standard graphs run once each,
//! beside GTSAM, in `benches/run_graphs.sh` (BENCHMARKS.md §7).
//!
//! Run: `cargo bench --no-default-features --bench graphs -- --warm-up-time 1 --measurement-time 5`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use posecov::eval::graph::{SolverSettings, optimize};
use posecov::lie::LieGroup;
use posecov::plan::graph::PoseGraph;

#[path = "../tests/common/graph.rs"]
mod graph_common;
use graph_common::{manhattan_walk, manhattan_walk_3d, se2_graph};

/// Optimise and every marginal, once per iteration; checked to converge first.
fn bench_graph<G: LieGroup<N>, const N: usize>(
    c: &mut Criterion,
    name: &str,
    graph: &PoseGraph<G, N>,
) {
    let settings = SolverSettings::default();
    let s = optimize(graph, &settings, &mut |_| {}).expect("solvable");
    assert!(s.converged(), "{name}: {:?}", s.stop);
    assert!(s.covariances.iter().skip(1).all(Option::is_some));
    c.bench_function(&format!("graph/{name}/optimize_and_every_marginal"), |b| {
        b.iter(|| optimize(black_box(graph), &settings, &mut |_| {}).expect("solvable"))
    });
}

fn graphs(c: &mut Criterion) {
    let pose2 = se2_graph(include_str!("../tests/data/gtsam/pose2example.txt"));
    bench_graph(c, "pose2example", &pose2);
    bench_graph(c, "manhattan_2d_1000", &manhattan_walk(1000, 1));
    bench_graph(c, "manhattan_3d_500", &manhattan_walk_3d(500, 1));
}

criterion_group!(benches, graphs);
criterion_main!(benches);
