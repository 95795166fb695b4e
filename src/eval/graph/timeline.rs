//! What the loop closures did, one at a time: the graph re-solved with its odometry (every
//! edge that is not a loop closure) and its priors, plus the first k loop closures in file
//! order, for k = 0 … L. Step 0 is dead reckoning — the marginals grow from the anchor along
//! the chain — and each later step shows the marginals shrinking where the new closures join.
//! Each step is warm-started from the one before; the last is the full solution, not solved
//! again.
//!
//! Bounded: at most [`MAX_TIMELINE_STEPS`] values of k after 0 (evenly spaced, always L), and
//! only for graphs of at most [`MAX_TIMELINE_POSES`] poses (re-solving a larger graph a dozen
//! times is minutes, not seconds); a larger graph gets no timeline and says so. Twelve steps
//! show the marginals shrinking as the closures arrive; each more is one more re-solve (on
//! the benchmark graphs the timeline was half of `report`'s work at 24).

use crate::lie::{LieGroup, TangentMatrix};
use crate::plan::graph::PoseGraph;

use super::evaluate::StepMarginals;
use super::{Iteration, SolverSettings, SparseError, Stage, Stop, optimize};

/// Most poses a graph may have to be re-solved loop closure by loop closure.
pub const MAX_TIMELINE_POSES: usize = 10_000;

/// Most steps after step 0 (the values of k are evenly spaced when there are more loop
/// closures).
pub const MAX_TIMELINE_STEPS: usize = 12;

/// The relative decrease of f = χ²/2 at which a state between dead reckoning and the final
/// solution stops (at least; the solver's own when larger; step 0, the dead reckoning and σ
/// before, stops at the solver's own). A state is drawn and its χ² listed: a picture of the
/// way, not a solution to quote. On the benchmark graphs these states are flat along their
/// weakest directions: against the same states solved to 1e-6, 1e-2 leaves χ² within 0.12 %
/// and the median pose 1.2 m away on the 265 m parking garage (largest 8.6 m; city10000's
/// first state: 9.7 m on 105 m, likely another basin), where 1e-3 left 1.0 m (8.1 m; 6.1 m)
/// at up to 40 % more iterations (parking-garage 32 → 23 over the timeline; issue 33). The
/// final solution stops at GTSAM's 1e-5.
pub const STATE_RELATIVE_TOLERANCE: f64 = 1e-2;

/// The graph with its first `closures` loop closures, optimised.
#[derive(Debug, Clone)]
pub struct ClosureStep<G, const N: usize> {
    /// k: the loop closures in the graph (the first k in file order).
    pub closures: usize,
    /// The optimised poses, one per vertex.
    pub poses: Vec<G>,
    /// Each vertex's marginal (right form, [ρ; θ]; None as in
    /// [`Solution::covariances`](super::Solution::covariances), and for every vertex of a step
    /// after 0 evaluated with [`StepMarginals::DeadReckoning`]).
    pub covariances: Vec<Option<TangentMatrix<N>>>,
    /// χ² at this step's optimum, over its own edges and priors.
    pub chi2: f64,
    /// Why its optimiser stopped.
    pub stop: Stop,
}

/// The steps, or why there are none.
#[derive(Debug, Clone)]
pub struct ClosureTimeline<G, const N: usize> {
    /// k = 0, then up to [`MAX_TIMELINE_STEPS`] values up to L (empty: see the other fields).
    pub steps: Vec<ClosureStep<G, N>>,
    /// The graph has more poses than [`MAX_TIMELINE_POSES`]: how many.
    pub too_large: Option<usize>,
    /// The re-solves were interrupted (Ctrl-C): the steps so far are kept.
    pub interrupted: bool,
}

/// The values of k: 0, then every k up to `loops`, or [`MAX_TIMELINE_STEPS`] of them evenly
/// spaced (always ending at `loops`).
///
/// ```
/// use posecov::eval::graph::closure_counts;
/// assert_eq!(closure_counts(3), vec![0, 1, 2, 3]);
/// let many = closure_counts(1000);
/// assert_eq!((many.len(), many[0], many[many.len() - 1]), (13, 0, 1000));
/// assert!(closure_counts(0).is_empty());
/// ```
pub fn closure_counts(loops: usize) -> Vec<usize> {
    if loops == 0 {
        return Vec::new();
    }
    let steps = loops.min(MAX_TIMELINE_STEPS);
    let mut out: Vec<usize> = (0..=steps).map(|i| (i * loops).div_ceil(steps)).collect();
    out.dedup();
    out
}

/// The timeline of `graph`, whose loop closures are the edges `loop_edges` (in file order):
/// every step but the last, which is the full solution and is added by the caller (see the
/// [module docs](self)). `marginals` says which steps get every pose's marginal.
pub(super) fn closure_timeline<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    loop_edges: &[usize],
    settings: &SolverSettings,
    marginals: StepMarginals,
    progress: &(dyn Fn(Stage, &Iteration) + Sync),
) -> Result<ClosureTimeline<G, N>, SparseError> {
    let mut timeline = ClosureTimeline {
        steps: Vec::new(),
        too_large: None,
        interrupted: false,
    };
    if graph.vertices.len() > MAX_TIMELINE_POSES {
        timeline.too_large = Some(graph.vertices.len());
        return Ok(timeline);
    }
    let rank = ranks(graph, loop_edges);
    let mut start = graph.estimates();
    let counts = closure_counts(loop_edges.len());
    let of = counts.len().saturating_sub(1);
    for (step, k) in counts.into_iter().enumerate() {
        if k == loop_edges.len() || (k > 0 && marginals == StepMarginals::DeadReckoningOnly) {
            break;
        }
        let solver = SolverSettings {
            pairs: Vec::new(),
            marginals: k == 0 || marginals == StepMarginals::Every,
            // A state keeps each pose's marginal only.
            edge_joints: false,
            relative_tolerance: if k == 0 {
                settings.relative_tolerance
            } else {
                settings.relative_tolerance.max(STATE_RELATIVE_TOLERANCE)
            },
            ..settings.clone()
        };
        let sub = first_closures(graph, &rank, k, &start);
        let stage = Stage::Timeline { step: step + 1, of };
        let s = optimize(&sub, &solver, &mut |i| progress(stage, i))?;
        if s.stop == Stop::Interrupted {
            timeline.interrupted = true;
            break;
        }
        start.clone_from(&s.poses);
        timeline.steps.push(ClosureStep {
            closures: k,
            poses: s.poses,
            covariances: s.covariances,
            chi2: s.chi2_after,
            stop: s.stop,
        });
    }
    Ok(timeline)
}

/// Per edge: its rank among the loop closures `loop_edges` (None: odometry).
fn ranks<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    loop_edges: &[usize],
) -> Vec<Option<usize>> {
    let mut rank = vec![None; graph.edges.len()];
    for (r, &e) in loop_edges.iter().enumerate() {
        rank[e] = Some(r);
    }
    rank
}

/// `graph` with its odometry, priors and first `k` loop closures (by `rank`), its estimates
/// `start`.
fn first_closures<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    rank: &[Option<usize>],
    k: usize,
    start: &[G],
) -> PoseGraph<G, N> {
    let mut sub = PoseGraph {
        vertices: graph.vertices.clone(),
        edges: graph
            .edges
            .iter()
            .zip(rank)
            .filter(|(_, r)| r.is_none_or(|r| r < k))
            .map(|(e, _)| e.clone())
            .collect(),
        priors: graph.priors.clone(),
        fixed: graph.fixed.clone(),
    };
    for (v, x) in sub.vertices.iter_mut().zip(start) {
        v.estimate = *x;
    }
    sub
}

/// Every pose's dead-reckoning marginal: of `graph` without its loop closures `loop_edges`
/// (odometry and priors only), optimised — the timeline's step 0 when it has one, else solved
/// here once (a graph too large for the timeline); None when there are no loop closures (the
/// full solution's marginals are then the dead reckoning's).
pub(super) fn dead_reckoning<G: LieGroup<N>, const N: usize>(
    graph: &PoseGraph<G, N>,
    loop_edges: &[usize],
    timeline: &ClosureTimeline<G, N>,
    settings: &SolverSettings,
    progress: &(dyn Fn(Stage, &Iteration) + Sync),
) -> Result<Option<Vec<Option<TangentMatrix<N>>>>, SparseError> {
    if loop_edges.is_empty() {
        return Ok(None);
    }
    if let Some(step) = timeline.steps.first().filter(|s| s.closures == 0) {
        return Ok(Some(step.covariances.clone()));
    }
    let solver = SolverSettings {
        pairs: Vec::new(),
        edge_joints: false,
        ..settings.clone()
    };
    let sub = first_closures(graph, &ranks(graph, loop_edges), 0, &graph.estimates());
    let stage = Stage::Timeline { step: 1, of: 1 };
    Ok(Some(
        optimize(&sub, &solver, &mut |i| progress(stage, i))?.covariances,
    ))
}
