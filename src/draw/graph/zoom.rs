//! The robot-scale views of a pose graph's final solution, as a robot log has one: on a map
//! tens of metres wide the marginals are centimetres, so two views look closely at what the
//! after picture can only colour — the largest marginal (`world/zoom/largest_marginal`) and
//! the worst loop closure (`world/zoom/worst_loop_closure`), each with the trajectory, poses
//! and marginal ellipses around it, true to scale, in the same colours and legend as the after
//! picture.

use nalgebra::Vector3;

use super::super::{Painter, shapes, v3};
use super::after::{BANANA, OUTLIER, RELATIVE, quat};
use super::ramp::{self, Ramp};
use crate::eval::graph::{GraphEvaluation, LoopClosure};
use crate::lie::LieGroup;
use crate::scene::{self, Arrows, Frame, ItemKind, LineStrips, Timing, Triads, Vec3, paths};
use crate::uncertain::{Side, UncertainPose};

/// A robot-scale view: its title and the subtree it shows.
#[derive(Debug, Clone, PartialEq)]
pub(in crate::draw) struct Zoom {
    /// The view's title, e.g. "close-up: largest marginal, v1227".
    pub name: String,
    /// The subtree it shows (`world/zoom/<what>`).
    pub path: String,
}

/// How far around its centre a zoom reaches, in sizes of what it centres on.
const REACH: f64 = 1.3;

/// The poses of the final solution within `reach` of `centre`.
fn near<G: LieGroup<N>, const N: usize>(
    g: &GraphEvaluation<G, N>,
    centre: &Vector3<f64>,
    reach: f64,
) -> Vec<usize> {
    (0..g.solution.poses.len())
        .filter(|&k| (g.solution.poses[k].to_se3().translation() - centre).norm() <= reach)
        .collect()
}

/// The half size of pose `k`'s marginal position region (its largest), 0 without one.
fn region_size<G: LieGroup<N>, const N: usize>(
    p: &Painter,
    g: &GraphEvaluation<G, N>,
    k: usize,
) -> f64 {
    uncertain(g, k)
        .and_then(|pose| shapes::position_region(&pose, p.confidence()))
        .map_or(0.0, |e| e.half_sizes.iter().copied().fold(0.0, f64::max))
}

fn uncertain<G: LieGroup<N>, const N: usize>(
    g: &GraphEvaluation<G, N>,
    k: usize,
) -> Option<UncertainPose<G, N>> {
    g.solution.covariances[k]
        .map(|cov| UncertainPose::new_unchecked(g.solution.poses[k], cov, Side::Right))
}

/// What every zoom draws around its centre, at `base`: the trajectory segments with both
/// ends among `poses` in their σ colours, those poses as small axes, and the marginal
/// ellipses of `ellipses` in their σ colours. The line widths follow `size`, the zoom's
/// scale; the axes are as long as the after picture's, or shorter in a small zoom.
fn surroundings<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    base: &str,
    (poses, ellipses): (&[usize], &[usize]),
    (sigma, ramp, size): (&[f64], &Ramp, f64),
) {
    let s = &g.solution;
    let points: Vec<Vec3> = s
        .poses
        .iter()
        .map(|x| v3(x.to_se3().translation()))
        .collect();
    let segments: Vec<usize> = poses
        .windows(2)
        .filter(|w| w[1] == w[0] + 1)
        .map(|w| w[0])
        .collect();
    let radius = 0.004 * size;
    ramp::trajectory(
        p,
        &paths::child(base, "trajectory"),
        None,
        (&points, sigma),
        segments,
        (ramp, radius),
    );
    let shapes: Vec<_> = ellipses
        .iter()
        .filter_map(|&k| {
            let region = shapes::position_region(&uncertain(g, k)?, p.confidence())?;
            Some((region, sigma[k]))
        })
        .collect();
    ramp::ellipses(
        p,
        &paths::child(base, "marginals"),
        None,
        shapes,
        (ramp, 0.6 * radius),
    );
    p.push(
        paths::child(base, "poses"),
        None,
        ItemKind::Triads(Triads {
            translations: poses.iter().map(|&k| points[k]).collect(),
            rotations: poses.iter().map(|&k| quat(&s.poses[k])).collect(),
            axis_length: (0.1 * size).min(0.6 * p.axis_length),
            line_radius: 0.5 * radius,
        }),
    );
}

/// A labelled pose of a zoom (`base/v<id>`): its words, and the viewer's tag when shorter.
fn labelled<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    base: &str,
    k: usize,
    (label, tag, size): (String, String, f64),
) {
    let x = &g.solution.poses[k];
    p.push(
        paths::vertex(base, g.ids[k]),
        None,
        ItemKind::Frame(Frame {
            translation: v3(x.to_se3().translation()),
            rotation: quat(x),
            axis_length: (0.15 * size).min(p.axis_length),
            tag: (tag != label).then_some(tag),
            label: Some(label),
        }),
    );
}

/// The largest marginal, pose `k`, at the robot's scale (`world/zoom/largest_marginal`): its
/// Exp-mapped region and ellipse with the trajectory and poses within [`REACH`] region sizes
/// (at least its two odometry neighbours); `None` without a region to draw.
pub(super) fn largest_marginal<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    k: usize,
    (sigma, ramp): (&[f64], &Ramp),
) -> Option<Zoom> {
    let pose = uncertain(g, k)?;
    let size = region_size(p, g, k);
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let base = paths::zoom("largest_marginal");
    let centre = *pose.mean().to_se3().translation();
    let position = |k: usize| *g.solution.poses[k].to_se3().translation();
    let step = [k.checked_sub(1), Some(k + 1)]
        .into_iter()
        .flatten()
        .filter(|&q| q < g.solution.poses.len())
        .map(|q| (position(q) - centre).norm())
        .fold(0.0, f64::max);
    let reach = (REACH * size).max(1.05 * step);
    let around = near(g, &centre, reach);
    surroundings(p, g, &base, (&around, &[k]), (sigma, ramp, reach));
    p.region_banana(
        &paths::child(&base, "banana"),
        Timing::Static,
        &pose,
        BANANA,
        |x: &G| x.to_se3().translation().to_owned(),
    );
    let label = format!(
        "v{}: largest marginal, σ {}",
        g.ids[k],
        ramp::length_words(sigma[k])
    );
    let tag = format!("v{} largest σ", g.ids[k]);
    labelled(p, g, &base, k, (label, tag, reach));
    Some(Zoom {
        name: format!("close-up: largest marginal, v{}", g.ids[k]),
        path: base,
    })
}

/// The worst loop closure `l` (i → j) at the robot's scale (`world/zoom/worst_loop_closure`):
/// its two ends, the line between them and its residual arrow from X_i · Z to X_j, the
/// relative uncertainty of X_j as X_i sees it (what the loop closure pins down), and the
/// trajectory and poses around X_j; `None` when an end is not in the graph or there is
/// nothing to size the view by.
pub(super) fn worst_loop_closure<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    l: &LoopClosure<N>,
    (sigma, ramp): (&[f64], &Ramp),
) -> Option<Zoom> {
    let i = g.ids.binary_search(&l.from).ok()?;
    let j = g.ids.binary_search(&l.to).ok()?;
    let base = paths::zoom("worst_loop_closure");
    let (xi, xj) = (&g.solution.poses[i], &g.solution.poses[j]);
    let (pi, pj) = (*xi.to_se3().translation(), *xj.to_se3().translation());
    let predicted = l.predicted_position;
    let spread = [(pi - pj).norm(), (predicted - pj).norm()]
        .into_iter()
        .fold(0.0, f64::max);
    // The relative region: what the loop closure pins down (each end's own marginal, relative
    // to the anchor, is far larger and left to the after view).
    let relative = l
        .relative_cov
        .filter(|c| c.iter().all(|v| v.is_finite()) && c.amax() > 0.0)
        .map(|cov| UncertainPose::new_unchecked(*xj, cov, Side::Right));
    let region = relative
        .as_ref()
        .and_then(|pose| shapes::position_region(pose, p.confidence()))
        .map_or(0.0, |e| e.half_sizes.iter().copied().fold(0.0, f64::max));
    let size = region.max(0.5 * spread);
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let reach = (2.0 * REACH * size).max(1.05 * spread);
    let mut around = near(g, &pj, reach);
    for k in [i, j] {
        if let Err(at) = around.binary_search(&k) {
            around.insert(at, k);
        }
    }
    surroundings(p, g, &base, (&around, &[]), (sigma, ramp, reach));
    let outlier = l.mahalanobis > g.radius;
    let color = if outlier { OUTLIER } else { scene::LINK };
    let radius = 0.004 * reach;
    p.push(
        paths::child(&base, "loop_closure"),
        None,
        ItemKind::LineStrips(LineStrips {
            strips: vec![vec![v3(&pi), v3(&pj)]],
            color,
            radius,
        }),
    );
    p.push(
        paths::child(&base, "residual"),
        None,
        ItemKind::Arrows(Arrows {
            origins: vec![v3(&predicted)],
            vectors: vec![v3(&(pj - predicted))],
            color,
            radius: 1.2 * radius,
        }),
    );
    if let Some(pose) = &relative {
        p.region_banana(
            &paths::child(&base, "relative"),
            Timing::Static,
            pose,
            RELATIVE,
            |x: &G| x.to_se3().translation().to_owned(),
        );
    }
    let label = format!(
        "v{} ← v{}: worst loop closure, d = {:.2}",
        l.to, l.from, l.mahalanobis
    );
    let tag = format!("v{} ← v{} worst", l.to, l.from);
    labelled(p, g, &base, j, (label, tag, reach));
    if i != j && (pi - pj).norm() > 0.1 * reach {
        let from = format!("v{}", l.from);
        labelled(p, g, &base, i, (from.clone(), from, reach));
    }
    Some(Zoom {
        name: format!("close-up: worst loop closure, v{} ← v{}", l.to, l.from),
        path: base,
    })
}
