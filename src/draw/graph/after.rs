//! The "after" picture of a pose graph: the optimised trajectory and poses, every drawn
//! pose's marginal ellipse at the confidence, a few marginal bananas, each loop closure with
//! its residual, the relative uncertainty of the worst loop closures and of every `--joint`
//! pair, and labels that do not collide.

use super::super::shapes;
use super::super::{Painter, v3};
use std::collections::BTreeSet;

use crate::eval::graph::{ClosureStep, GraphEvaluation, LoopClosure};
use crate::lie::{LieGroup, TangentMatrix};
use crate::scene::{
    self, Arrows, Color, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, QuatXyzw, Timing,
    Triads, Vec3, paths,
};
use crate::uncertain::{Side, UncertainPose};

/// Most optimised poses drawn with their marginal ellipse (evenly chosen, plus the loop
/// closures' ends).
const MAX_DRAWN_MARGINALS: usize = 600;
/// Most poses drawn with their marginal banana: the largest marginal and the last pose.
const MAX_BANANAS: usize = 2;
/// Most loop closures drawn with their relative uncertainty (the worst ones), besides every
/// `--joint` pair.
const MAX_RELATIVE_LOOP_CLOSURES: usize = 2;
/// Most `--joint` pairs drawn (all are in `report --json`).
const MAX_DRAWN_JOINTS: usize = 12;
/// Most labels in the after picture.
const MAX_LABELS: usize = 24;
/// Colour of the optimised poses and their marginals.
pub(super) const OPTIMIZED: Color = Color::rgb(0, 158, 115);
/// Colour of loop closures beyond their radius.
const OUTLIER: Color = Color::rgb(213, 94, 0);
/// Colour of a relative pose's uncertainty (X_b as X_a sees it).
const RELATIVE: Color = Color::rgb(204, 121, 167);

/// The "after" picture at `world/optimized/…`: the optimised trajectory and poses, every
/// drawn pose's marginal position ellipse at the confidence, the marginal bananas of the
/// largest marginal and the last pose, each loop closure as a line between its optimised ends
/// (outliers in [`OUTLIER`]) with its residual as an arrow from the pose it predicts
/// (X_i · Z) to X_j, relative uncertainties ([`relative`]) and labels only where they do not
/// collide. With a loop-closure timeline, the trajectory, ellipses, poses and bananas follow
/// it on the `step` timeline: the graph without loop closures from step 0 (while the chain's
/// banana grows), then one step per value of k after the chain's last step, the loop
/// closures added so far drawn thick; everything else is the final solution, static.
pub(in crate::draw) fn draw_optimized<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
) {
    let s = &g.solution;
    let position = |x: &G| x.to_se3().translation().to_owned();
    let radius = 0.003 * p.extent.max(0.25);
    // Which poses get an ellipse: evenly chosen, plus the worst loop closures' ends.
    let n = s.poses.len();
    let mut drawn: BTreeSet<usize> = (0..MAX_DRAWN_MARGINALS.min(n))
        .map(|k| k * (n.max(2) - 1) / (MAX_DRAWN_MARGINALS.min(n).max(2) - 1))
        .filter(|&k| k < n)
        .collect();
    let index_of: std::collections::HashMap<u64, usize> =
        g.ids.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let mut worst: Vec<&LoopClosure<N>> = g.loop_closures.iter().collect();
    worst.sort_by(|a, b| b.mahalanobis.total_cmp(&a.mahalanobis));
    for l in worst.iter().take(MAX_DRAWN_MARGINALS / 4) {
        drawn.extend([index_of[&l.from], index_of[&l.to]]);
    }
    // Bananas: the largest marginal and the last pose (of the final solution).
    let size = |k: usize| s.covariances[k].map_or(0.0, |c| c.trace());
    let largest = (0..n).max_by(|&a, &b| size(a).total_cmp(&size(b)));
    let mut banana_poses: Vec<usize> = largest.into_iter().chain([n.saturating_sub(1)]).collect();
    banana_poses.dedup();
    banana_poses.truncate(MAX_BANANAS);
    let look = Look {
        radius,
        drawn: &drawn,
        bananas: &banana_poses,
    };
    if g.timeline.steps.is_empty() {
        state(p, g, &s.poses, &s.covariances, None, &look);
    } else {
        let chain_end = p.scene.steps().last().copied().unwrap_or(0).max(0) as u64;
        let mut states = Vec::new();
        for (i, step) in g.timeline.steps.iter().enumerate() {
            let at = if i == 0 { 0 } else { chain_end + i as u64 };
            state(p, g, &step.poses, &step.covariances, Some(at), &look);
            closed_so_far(p, g, step, at, radius);
            states.push(scene::State {
                closures: step.closures as u64,
                step: at as i64,
            });
        }
        p.scene.states = Some(scene::States {
            path: paths::optimized(),
            steps: states,
        });
    }
    // Loop closures: lines between the optimised ends; residual arrows X_i·Z → X_j.
    for (outliers, name, color) in [(false, "inliers", scene::LINK), (true, "outliers", OUTLIER)] {
        let chosen: Vec<&LoopClosure<N>> = g
            .loop_closures
            .iter()
            .filter(|l| (l.mahalanobis > g.radius) == outliers)
            .collect();
        if chosen.is_empty() {
            continue;
        }
        let ends = |l: &LoopClosure<N>| (index_of[&l.from], index_of[&l.to]);
        p.push(
            paths::child(&paths::optimized(), &format!("loop_closures/{name}")),
            None,
            ItemKind::LineStrips(LineStrips {
                strips: chosen
                    .iter()
                    .map(|l| {
                        let (i, j) = ends(l);
                        vec![v3(&position(&s.poses[i])), v3(&position(&s.poses[j]))]
                    })
                    .collect(),
                color,
                radius: radius * 0.7,
            }),
        );
        let (origins, vectors): (Vec<Vec3>, Vec<Vec3>) = chosen
            .iter()
            .map(|l| {
                let (_, j) = ends(l);
                let predicted = l.predicted_position;
                let estimated = position(&s.poses[j]);
                (v3(&predicted), v3(&(estimated - predicted)))
            })
            .unzip();
        p.push(
            paths::child(
                &paths::optimized(),
                &format!("loop_closures/{name}_residuals"),
            ),
            None,
            ItemKind::Arrows(Arrows {
                origins,
                vectors,
                color,
                radius: radius * 0.8,
            }),
        );
    }
    relative(p, g, &worst);
    labels(p, g, &worst, &banana_poses, true);
    labels(p, g, &worst, &banana_poses, false);
}

/// What every state of the after picture draws the same way.
struct Look<'a> {
    radius: f64,
    drawn: &'a BTreeSet<usize>,
    bananas: &'a [usize],
}

/// One state of the optimised graph (the final one, static; or a timeline step): the
/// trajectory, the drawn poses with their marginal ellipses, and the bananas.
fn state<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    poses: &[G],
    covariances: &[Option<TangentMatrix<N>>],
    step: Option<u64>,
    look: &Look,
) {
    let position = |x: &G| x.to_se3().translation().to_owned();
    p.push(
        paths::child(&paths::optimized(), "trajectory"),
        step,
        ItemKind::LineStrips(LineStrips {
            strips: vec![poses.iter().map(|x| v3(&position(x))).collect()],
            color: OPTIMIZED,
            radius: look.radius,
        }),
    );
    let d = G::KIND.position_dims().max(1);
    let uncertain = |k: usize| {
        covariances[k].map(|cov| UncertainPose::new_unchecked(poses[k], cov, Side::Right))
    };
    let shapes: Vec<_> = look
        .drawn
        .iter()
        .filter_map(|&k| {
            let cov = uncertain(k)?.position_cov_in_world_3d()?;
            Some(shapes::ellipsoid_of(
                &position(&poses[k]),
                &cov,
                p.confidence().radius(d),
            ))
        })
        .collect();
    if !shapes.is_empty() {
        p.push(
            paths::child(&paths::optimized(), "marginals"),
            step,
            ItemKind::Ellipsoids(Ellipsoids {
                shapes,
                color: OPTIMIZED,
                fill: FillMode::MajorWireframe,
                line_radius: look.radius * 0.6,
                label: None,
            }),
        );
    }
    p.push(
        paths::child(&paths::optimized(), "poses"),
        step,
        ItemKind::Triads(Triads {
            translations: look
                .drawn
                .iter()
                .map(|&k| v3(&position(&poses[k])))
                .collect(),
            rotations: look.drawn.iter().map(|&k| quat(&poses[k])).collect(),
            axis_length: p.axis_length * 0.6,
            line_radius: look.radius * 0.5,
        }),
    );
    for &k in look.bananas {
        if let Some(pose) = uncertain(k) {
            p.region_banana(
                &paths::vertex(&paths::child(&paths::optimized(), "bananas"), g.ids[k]),
                step.map_or(Timing::Static, |k| Timing::Step(k as i64)),
                &pose,
                OPTIMIZED,
                |x: &G| x.to_se3().translation().to_owned(),
            );
        }
    }
}

/// The loop closures in the graph at a timeline step, thick between the step's poses
/// (`world/optimized/closed`; nothing at k = 0).
fn closed_so_far<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    step: &ClosureStep<G, N>,
    at: u64,
    radius: f64,
) {
    let index_of = |id: u64| g.ids.binary_search(&id).ok();
    let position = |k: usize| v3(&step.poses[k].to_se3().translation().to_owned());
    let strips: Vec<Vec<Vec3>> = g.loop_closures[..step.closures.min(g.loop_closures.len())]
        .iter()
        .filter_map(|l| Some(vec![position(index_of(l.from)?), position(index_of(l.to)?)]))
        .collect();
    if !strips.is_empty() {
        p.push(
            paths::child(&paths::optimized(), "closed"),
            Some(at),
            ItemKind::LineStrips(LineStrips {
                strips,
                color: OPTIMIZED,
                radius: radius * 1.5,
            }),
        );
    }
}

/// The relative uncertainty of the worst loop closures and of every `--joint` pair: X_b as
/// X_a sees it, X_a · (X_a⁻¹ X_b) · Exp(ξ) with ξ ~ N(0, Σ_rel) from the joint marginal, a
/// banana around X_b (`world/optimized/relative/v<a>_v<b>`). Where it is smaller than X_b's
/// own marginal, the two poses are known better together than either alone.
fn relative<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    worst: &[&LoopClosure<N>],
) {
    let index_of = |id: u64| g.ids.binary_search(&id).ok();
    let closures = worst
        .iter()
        .take(MAX_RELATIVE_LOOP_CLOSURES)
        .filter_map(|l| Some((l.from, l.to, l.relative_cov?)));
    let joints = g
        .joints
        .iter()
        .take(MAX_DRAWN_JOINTS)
        .filter_map(|j| Some((j.a, j.b, j.relative_cov?)));
    let mut drawn = std::collections::BTreeSet::new();
    for (a, b, cov) in closures.chain(joints) {
        let (Some(ia), Some(ib)) = (index_of(a), index_of(b)) else {
            continue;
        };
        if !drawn.insert((a, b)) || !is_drawable(&cov) {
            continue;
        }
        // X_a · (X_a⁻¹ X_b) = X_b: the relative pose placed where X_a puts it.
        let (xa, xb) = (&g.solution.poses[ia], &g.solution.poses[ib]);
        let at = xa.compose(&xa.inverse().compose(xb));
        p.region_banana(
            &paths::relative(a, b),
            Timing::Static,
            &UncertainPose::new_unchecked(at, cov, Side::Right),
            RELATIVE,
            |x: &G| x.to_se3().translation().to_owned(),
        );
    }
}

/// A covariance with a banana to draw: finite and not all zero (two poses held fixed).
fn is_drawable<const N: usize>(cov: &TangentMatrix<N>) -> bool {
    cov.iter().all(|v| v.is_finite()) && cov.amax() > 0.0
}

/// Labels that do not collide: the first and last pose, the loop closures' ends (worst
/// first), the largest marginal — each only if it is farther than 4 % of the drawing from
/// every label already placed. `after`: at the optimised poses (with the residual's d),
/// else at the file's estimates (`world/labels/…`).
fn labels<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    worst: &[&LoopClosure<N>],
    bananas: &[usize],
    after: bool,
) {
    let (poses, prefix) = if after {
        (
            &g.solution.poses,
            paths::child(&paths::optimized(), "labels"),
        )
    } else {
        (&g.initial, paths::initial_labels())
    };
    let n = poses.len();
    let index_of = |id: u64| g.ids.iter().position(|&x| x == id);
    let mut candidates: Vec<(usize, String)> = Vec::new();
    if n > 0 {
        candidates.push((0, format!("v{}", g.ids[0])));
        candidates.push((n - 1, format!("v{}", g.ids[n - 1])));
    }
    if let (Some(&k), true) = (bananas.first(), after) {
        candidates.push((k, format!("v{} (largest marginal)", g.ids[k])));
    }
    for l in worst {
        if let (Some(i), Some(j)) = (index_of(l.from), index_of(l.to)) {
            let d = if after {
                l.mahalanobis
            } else {
                l.mahalanobis_before
            };
            candidates.push((j, format!("v{} ← v{} d={d:.2}", l.to, l.from)));
            candidates.push((i, format!("v{}", l.from)));
        }
    }
    let min_distance = 0.04 * p.extent.max(1e-9);
    let mut placed: Vec<nalgebra::Vector3<f64>> = Vec::new();
    let mut placed_poses = std::collections::BTreeSet::new();
    for (k, text) in candidates {
        if placed.len() >= MAX_LABELS {
            break;
        }
        let at = poses[k].to_se3().translation().to_owned();
        if placed_poses.contains(&k) || placed.iter().any(|q| (q - at).norm() < min_distance) {
            continue;
        }
        placed.push(at);
        placed_poses.insert(k);
        p.push(
            paths::vertex(&prefix, g.ids[k]),
            None,
            ItemKind::Frame(Frame {
                translation: v3(&at),
                rotation: quat(&poses[k]),
                axis_length: p.axis_length * 0.6,
                label: Some(text),
            }),
        );
    }
}

fn quat<G: LieGroup<N>, const N: usize>(x: &G) -> QuatXyzw {
    let q = x.to_se3().rotation().to_quaternion_xyzw();
    [q[0], q[1], q[2], q[3]]
}
