//! The supernodal selected inversion (`eval::graph::marginals`) against a dense inverse of H
//! on seeded Manhattan-world walks with loop closures, in the plane and in space: every entry
//! of Σ = H⁻¹ it computes (the whole pattern of the Cholesky factor, not only the blocks the
//! marginals read), and every pose's marginal and every edge's joint marginal that
//! `optimize` returns.

use nalgebra::DMatrix;
use posecov::eval::graph::marginals::selected_inverse;
use posecov::eval::graph::sparse::BlockSystem;
use posecov::eval::graph::{SolverSettings, optimize};
use posecov::lie::LieGroup;
use posecov::plan::graph::PoseGraph;

#[path = "common/graph.rs"]
mod graph_common;
use graph_common::{block, dense_information, manhattan_walk, manhattan_walk_3d};

/// Optimises `graph` (vertex 0 holds the gauge), builds H over the other poses into a
/// [`BlockSystem`] from the dense H, and checks the selected inverse entry by entry, then the
/// solution's marginals, against the dense inverse. Returns (entries checked, unknowns).
fn check<G: LieGroup<N>, const N: usize>(graph: &PoseGraph<G, N>) -> (usize, usize) {
    let s = optimize(graph, &SolverSettings::default(), &mut |_| {}).unwrap();
    assert!(s.converged(), "{:?} {:?}", s.stop, s.log);
    let unknown: Vec<usize> = (1..graph.vertices.len()).collect();
    let h = dense_information(graph, &s.poses, &unknown);
    let inverse: DMatrix<f64> = h.clone().cholesky().expect("positive definite").inverse();
    let scale = inverse.amax();
    let blocks = unknown.len();
    let mut pairs: Vec<(usize, usize)> = graph
        .edges
        .iter()
        .filter(|e| e.from != 0 && e.to != 0)
        .map(|e| ((e.from - 1).min(e.to - 1), (e.from - 1).max(e.to - 1)))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let mut system = BlockSystem::<N>::new(blocks, &pairs).unwrap();
    for b in 0..blocks {
        system.add(b, b, &block::<N>(&h, b, b));
    }
    for &(a, b) in &pairs {
        system.add(a, b, &block::<N>(&h, a, b));
    }
    system.factorize().unwrap();
    let supernodes = system.factor().supernodes();
    assert!(
        supernodes < blocks,
        "some supernode spans several poses ({supernodes} supernodes, {blocks} poses)"
    );
    let selected = selected_inverse(&system).expect("every lookup in the pattern");
    let n = blocks * N;
    let mut checked = 0;
    for a in 0..n {
        for b in 0..=a {
            if let Some(v) = selected.entry(a, b) {
                assert_eq!(selected.entry(b, a), Some(v), "symmetric ({a}, {b})");
                let reference = inverse[(a, b)];
                assert!(
                    (v - reference).abs() <= 1e-9 * scale,
                    "Σ[{a}, {b}] = {v:e}, dense {reference:e}"
                );
                checked += 1;
            }
        }
    }
    // Every pose's block and every edge's are in the pattern; the marginals and the joints
    // the solution carries are those blocks.
    for (k, &v) in unknown.iter().enumerate() {
        assert!(selected.block::<N>(k, k).is_some());
        let cov = s.covariances[v].expect("a marginal");
        assert!(
            (cov - block::<N>(&inverse, k, k)).amax() <= 1e-9 * scale,
            "vertex {v}"
        );
    }
    for (e, joint) in graph.edges.iter().zip(&s.edge_joints) {
        if e.from == 0 || e.to == 0 {
            continue;
        }
        let (a, b) = (e.from - 1, e.to - 1);
        assert!(selected.block::<N>(a, b).is_some());
        let [_, ab, _] = joint.expect("a joint marginal");
        assert!((ab - block::<N>(&inverse, a, b)).amax() <= 1e-9 * scale);
    }
    (checked, n)
}

/// [`check`] on a walk with at least `min_closures` loop closures; the entries checked are
/// far fewer than the dense lower triangle (the inversion is selected).
fn check_walk<G: LieGroup<N>, const N: usize>(graph: &PoseGraph<G, N>, min_closures: usize) {
    let closures = graph.edges.len() - (graph.vertices.len() - 1);
    assert!(closures >= min_closures, "{closures} loop closures");
    let (checked, n) = check(graph);
    eprintln!("{closures} loop closures, {checked} entries of Σ checked ({n} unknowns)");
    assert!(checked > n && checked < n * (n + 1) / 4, "{checked} of {n}");
}

#[test]
fn selected_inverse_equals_the_dense_inverse_on_a_planar_manhattan_walk() {
    check_walk(&manhattan_walk(200, 21), 50);
}

#[test]
fn selected_inverse_equals_the_dense_inverse_on_a_spatial_manhattan_walk() {
    check_walk(&manhattan_walk_3d(150, 21), 20);
}
