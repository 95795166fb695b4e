//! The "after" picture of a pose graph: the optimised trajectory and every drawn pose's
//! marginal ellipse at the confidence, true to scale and coloured by the pose's σ
//! ([`super::ramp`]), a few marginal bananas, each loop closure with its residual, the relative
//! uncertainty of the worst loop closures and of every `--joint` pair, robot-scale views of
//! the largest marginal and the worst loop closure ([`super::zoom`]), a legend entry for every
//! colour and mark, and a few labels chosen by importance ([`super::labels`]).

use super::super::shapes;
use super::super::{Painter, legend, v3};
use super::ramp::{self, Ramp};
use super::zoom::{self, Zoom};
use nalgebra::Vector3;
use std::collections::BTreeSet;

use crate::eval::graph::{ClosureStep, GraphEvaluation, LoopClosure, PoseSigma};
use crate::lie::{LieGroup, TangentMatrix};
use crate::scene::{
    self, Arrows, Color, ItemKind, LineStrips, QuatXyzw, Swatch, Timing, Triads, Vec3, paths,
};
use crate::uncertain::{Side, UncertainPose};

/// Most optimised poses drawn with their axes and marginal ellipse (evenly chosen, plus the
/// loop closures' ends; fewer when the ellipses are large beside the map, [`sparse`]).
const MAX_DRAWN_MARGINALS: usize = 600;
/// Most poses drawn with their marginal banana: the largest marginal and the last pose.
const MAX_BANANAS: usize = 2;
/// Most loop closures drawn with their relative uncertainty (the worst ones), besides every
/// `--joint` pair.
const MAX_RELATIVE_LOOP_CLOSURES: usize = 2;
/// Most `--joint` pairs drawn (all are in `report --json`).
const MAX_DRAWN_JOINTS: usize = 12;
/// Colour of the loop closures added so far on the timeline (drawn thick).
pub(super) const OPTIMIZED: Color = Color::rgb(0, 158, 115);
/// Colour of loop closures beyond their radius.
pub(super) const OUTLIER: Color = Color::rgb(213, 94, 0);
/// Colour of a relative pose's uncertainty (X_b as X_a sees it).
pub(super) const RELATIVE: Color = Color::rgb(204, 121, 167);
/// Colour of a marginal's Exp-mapped region (banana).
pub(super) const BANANA: Color = Color::rgb(120, 94, 240);

/// The position σ √tr Σ_ρρ of a marginal (0 for a pose without one).
pub(super) fn position_sigma<G: LieGroup<N>, const N: usize>(
    cov: &Option<TangentMatrix<N>>,
) -> f64 {
    cov.as_ref()
        .map_or(0.0, |c| PoseSigma::of::<G, N>(c).position)
}

/// The "after" picture at `world/optimized/…`: the optimised trajectory and every drawn
/// pose's marginal position ellipse at the confidence, true to scale, both coloured by the
/// pose's position σ on the [`Ramp`] fitted to the final solution (one entity per colour,
/// `trajectory/sigma_<k>` and `marginals/sigma_<k>`); the marginal bananas of the largest
/// marginal and the last pose, each loop closure as a line between its optimised ends
/// (outliers in [`OUTLIER`]) with its residual as an arrow from the pose it predicts
/// (X_i · Z) to X_j, relative uncertainties ([`relative`]), the robot-scale views of the
/// largest marginal and the worst loop closure ([`zoom`], returned for the views) and a few
/// labels ([`super::labels::labels`]); a legend entry for each colour and mark. With a loop-closure
/// timeline, the trajectory, ellipses, poses and bananas follow it on the `step` timeline:
/// the graph without loop closures from step 0 (while the chain's banana grows), then one
/// step per value of k after the chain's last step, the loop closures added so far drawn
/// thick; everything else is the final solution, static.
pub(in crate::draw) fn draw_optimized<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
) -> Vec<Zoom> {
    let s = &g.solution;
    let radius = p.link_radius();
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
    // The final solution's σ: the ramp, and the largest marginal.
    let sigma: Vec<f64> = s.covariances.iter().map(position_sigma::<G, N>).collect();
    let ellipses = sparse(p, g, &drawn);
    let ramp = Ramp::fitted(sigma.iter().copied()).unwrap_or_else(Ramp::flat);
    let largest = (0..n)
        .filter(|&k| sigma[k] > 0.0)
        .max_by(|&a, &b| sigma[a].total_cmp(&sigma[b]));
    let mut banana_poses: Vec<usize> = largest.into_iter().chain([n.saturating_sub(1)]).collect();
    banana_poses.dedup();
    banana_poses.truncate(MAX_BANANAS);
    let look = Look {
        radius,
        ellipses: &ellipses,
        bananas: &banana_poses,
        ramp: &ramp,
        map: box_sides(&s.poses).max(),
    };
    // Under the trajectory: its colours stay on top.
    loop_closure_lines(p, g, &index_of, radius);
    // Regions left out (half-size beyond the map's longest side): on the timeline's states
    // before the final solution, and on the final solution.
    let (mut left_out, mut left_out_final) = (0, 0);
    if g.timeline.steps.is_empty() {
        left_out_final = state(p, g, &s.poses, &s.covariances, None, &look);
    } else {
        let chain_end = p.scene.steps().last().copied().unwrap_or(0).max(0) as u64;
        let mut states = Vec::new();
        for (i, step) in g.timeline.steps.iter().enumerate() {
            let at = if i == 0 { 0 } else { chain_end + i as u64 };
            let last = i + 1 == g.timeline.steps.len();
            // Every state leaves out what would cover the map many times over: dead reckoning's
            // and a few loop closures' marginals, and a final solution's on a graph whose
            // information is weak (parking-garage's: σ ≈ 1 km on a 265 m garage).
            let n = state(p, g, &step.poses, &step.covariances, Some(at), &look);
            if last {
                left_out_final += n;
            } else {
                left_out += n;
            }
            closed_so_far(p, g, (step, last), at, radius);
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
    ramp.legend(p);
    p.legend(
        format!(
            "after: marginal position ellipse at {}, true size, in its σ colour",
            p.confidence()
        ),
        ramp::RAMP[2],
        Swatch::Dashed,
    );
    if left_out_final > 0 {
        p.legend(
            "after: marginals wider than the map not drawn (the trajectory's σ colours carry \
             them, the close-up shows the largest at true size)"
                .to_owned(),
            ramp::RAMP[ramp::RAMP.len() - 1],
            Swatch::Dashed,
        );
    }
    if left_out > 0 {
        p.legend(
            "after, on the step timeline before the final solution: marginals wider than the \
             map not drawn (the trajectory's σ colours carry them; the before view shows dead \
             reckoning's)"
                .to_owned(),
            ramp::RAMP[ramp::RAMP.len() - 1],
            Swatch::Dashed,
        );
    }
    p.scene.add_legend(legend::axes("optimised poses"));
    if !banana_poses.is_empty() && s.covariances.iter().any(Option::is_some) {
        p.legend(
            format!(
                "after: a marginal's Exp-mapped {} region (largest, last pose)",
                p.confidence()
            ),
            BANANA,
            Swatch::Region,
        );
    }
    relative(p, g, &worst);
    let mut zooms = Vec::new();
    if let Some(k) = largest {
        zooms.extend(zoom::largest_marginal(p, g, k, (&sigma, &ramp)));
    }
    if let Some(l) = worst.first() {
        zooms.extend(zoom::worst_loop_closure(p, g, l, (&sigma, &ramp)));
    }
    super::labels::labels(p, g, largest, true);
    super::labels::labels(p, g, largest, false);
    zooms
}

/// Each loop closure as a line between its optimised ends (`loop_closures/inliers`, outliers
/// in [`OUTLIER`]) and its residual as an arrow from X_i · Z to X_j (`…_residuals`).
fn loop_closure_lines<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    index_of: &std::collections::HashMap<u64, usize>,
    radius: f64,
) {
    let s = &g.solution;
    let position = |x: &G| x.to_se3().translation().to_owned();
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
        let what = if outliers {
            format!("beyond its {} radius (outlier)", g.confidence)
        } else {
            "within its radius".to_owned()
        };
        p.legend(
            format!("after: loop closure i → j {what}, and its residual X_i·Z → X_j (arrow)"),
            color,
            Swatch::Line,
        );
    }
}

/// Most of the map's area the drawn marginal ellipses may cover together.
const ELLIPSE_COVER: f64 = 0.3;
/// Fewest ellipses drawn (when that many poses are drawn).
const MIN_ELLIPSES: usize = 12;

/// The poses of `drawn` that get their marginal ellipse: all of them when their ellipses are
/// small beside the map, else evenly chosen so that together (at their median area) they
/// cover at most [`ELLIPSE_COVER`] of the map's bounding box (its two longest sides), at least
/// [`MIN_ELLIPSES`]: metre-sized marginals on a map tens of metres wide would hide it. The
/// trajectory's σ colours carry every pose.
fn sparse<G: LieGroup<N>, const N: usize>(
    p: &Painter,
    g: &GraphEvaluation<G, N>,
    drawn: &BTreeSet<usize>,
) -> BTreeSet<usize> {
    let s = &g.solution;
    let mut areas: Vec<f64> = drawn
        .iter()
        .filter_map(|&k| {
            let pose = UncertainPose::new_unchecked(s.poses[k], s.covariances[k]?, Side::Right);
            let e = shapes::position_region(&pose, p.confidence())?;
            let mut h = e.half_sizes;
            h.sort_by(f64::total_cmp);
            Some(std::f64::consts::PI * h[1] * h[2])
        })
        .collect();
    if areas.is_empty() {
        return BTreeSet::new();
    }
    areas.sort_by(f64::total_cmp);
    let median = areas[areas.len() / 2];
    let mut sides: Vec<f64> = box_sides(&s.poses).iter().copied().collect();
    sides.sort_by(f64::total_cmp);
    let map = (sides[1] * sides[2]).max(median);
    let fits = if median > 0.0 {
        (ELLIPSE_COVER * map / median) as usize
    } else {
        drawn.len()
    };
    let count = fits.max(MIN_ELLIPSES).min(drawn.len());
    if count >= drawn.len() {
        return drawn.clone();
    }
    let list: Vec<usize> = drawn.iter().copied().collect();
    (0..count)
        .map(|i| list[i * (list.len() - 1) / (count - 1).max(1)])
        .collect()
}

/// What every state of the after picture draws the same way.
#[derive(Clone, Copy)]
struct Look<'a> {
    radius: f64,
    /// The poses drawn as axes with their marginal ellipse ([`sparse`]).
    ellipses: &'a BTreeSet<usize>,
    bananas: &'a [usize],
    ramp: &'a Ramp,
    /// The largest half-size of a marginal region drawn: the final solution's map size (the
    /// longest side of [`box_sides`]). A wider region (dead reckoning's: hundreds of metres on a
    /// map of tens) would cover the view; the trajectory's σ colours carry it.
    map: f64,
}

/// The sides of the bounding box of `poses`' positions (zeros for none): the map's size.
fn box_sides<G: LieGroup<N>, const N: usize>(poses: &[G]) -> Vector3<f64> {
    let (lo, hi) = poses.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), x| {
            let t = x.to_se3().translation().to_owned();
            (lo.inf(&t), hi.sup(&t))
        },
    );
    (hi - lo).map(|side| side.max(0.0))
}

/// One state of the optimised graph (the final one, static; or a timeline step): the
/// trajectory and the drawn poses' marginal ellipses in their σ colours, the drawn poses, and
/// the bananas; a region whose half-size exceeds `look.map` is left out. Returns how many
/// were left out.
fn state<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    poses: &[G],
    covariances: &[Option<TangentMatrix<N>>],
    step: Option<u64>,
    look: &Look,
) -> usize {
    let position = |x: &G| x.to_se3().translation().to_owned();
    let points: Vec<Vec3> = poses.iter().map(|x| v3(&position(x))).collect();
    let sigma: Vec<f64> = covariances.iter().map(position_sigma::<G, N>).collect();
    ramp::trajectory(
        p,
        &paths::child(&paths::optimized(), "trajectory"),
        step,
        (&points, &sigma),
        0..points.len().saturating_sub(1),
        (look.ramp, look.radius),
    );
    let uncertain = |k: usize| {
        covariances[k].map(|cov| UncertainPose::new_unchecked(poses[k], cov, Side::Right))
    };
    let fits = |e: &scene::Ellipsoid| e.half_sizes.iter().all(|&h| h <= look.map);
    let mut left_out = 0;
    let shapes: Vec<_> = look
        .ellipses
        .iter()
        .filter_map(|&k| {
            let e = shapes::position_region(&uncertain(k)?, p.confidence())?;
            if !fits(&e) {
                left_out += 1;
                return None;
            }
            Some((e, sigma[k]))
        })
        .collect();
    ramp::ellipses(
        p,
        &paths::child(&paths::optimized(), "marginals"),
        step,
        shapes,
        (look.ramp, look.radius * 0.6),
    );
    p.push(
        paths::child(&paths::optimized(), "poses"),
        step,
        ItemKind::Triads(Triads {
            translations: look
                .ellipses
                .iter()
                .map(|&k| v3(&position(&poses[k])))
                .collect(),
            rotations: look.ellipses.iter().map(|&k| quat(&poses[k])).collect(),
            axis_length: p.axis_length * 0.6,
            line_radius: look.radius * 0.5,
        }),
    );
    let timing = step.map_or(Timing::Static, |k| Timing::Step(k as i64));
    for &k in look.bananas {
        let base = paths::vertex(&paths::child(&paths::optimized(), "bananas"), g.ids[k]);
        match uncertain(k) {
            Some(pose)
                if shapes::position_region(&pose, p.confidence()).is_some_and(|e| fits(&e)) =>
            {
                p.region_banana(&base, timing, &pose, BANANA, |x: &G| {
                    x.to_se3().translation().to_owned()
                });
            }
            Some(_) => {
                // Left out at this step: logged empty, so that an earlier step's does not stay.
                left_out += 1;
                let surface = scene::Surface {
                    vertices: Vec::new(),
                    triangles: Vec::new(),
                    normals: Vec::new(),
                    color: BANANA,
                };
                p.push(
                    paths::child(&base, "banana"),
                    step,
                    ItemKind::Surface(surface),
                );
                let outline = LineStrips {
                    strips: Vec::new(),
                    color: BANANA,
                    radius: look.radius,
                };
                p.push(
                    paths::child(&base, "banana_outline"),
                    step,
                    ItemKind::LineStrips(outline),
                );
            }
            None => {}
        }
    }
    left_out
}

/// The loop closures in the graph at a timeline step, thick between the step's poses
/// (`world/optimized/closed`; nothing at k = 0). The last step (the final solution, every
/// loop closure in) logs none: its thin lines ([`loop_closure_lines`]) leave the trajectory's
/// colours visible.
fn closed_so_far<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    (step, last): (&ClosureStep<G, N>, bool),
    at: u64,
    radius: f64,
) {
    let index_of = |id: u64| g.ids.binary_search(&id).ok();
    let position = |k: usize| v3(&step.poses[k].to_se3().translation().to_owned());
    let added = if last { 0 } else { step.closures };
    let strips: Vec<Vec<Vec3>> = g.loop_closures[..added.min(g.loop_closures.len())]
        .iter()
        .filter_map(|l| Some(vec![position(index_of(l.from)?), position(index_of(l.to)?)]))
        .collect();
    if step.closures > 0 {
        p.push(
            paths::child(&paths::optimized(), "closed"),
            Some(at),
            ItemKind::LineStrips(LineStrips {
                strips,
                color: OPTIMIZED,
                radius: radius * 1.5,
            }),
        );
        p.legend(
            "after, on the step timeline: the loop closures added so far (thick)".to_owned(),
            OPTIMIZED,
            Swatch::Line,
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
    if !drawn.is_empty() {
        p.legend(
            format!(
                "relative uncertainty: X_j as X_i sees it, {} (worst loop closures, --joint)",
                p.confidence()
            ),
            RELATIVE,
            Swatch::Region,
        );
    }
}

/// A covariance with a banana to draw: finite and not all zero (two poses held fixed).
fn is_drawable<const N: usize>(cov: &TangentMatrix<N>) -> bool {
    cov.iter().all(|v| v.is_finite()) && cov.amax() > 0.0
}

pub(super) fn quat<G: LieGroup<N>, const N: usize>(x: &G) -> QuatXyzw {
    let q = x.to_se3().rotation().to_quaternion_xyzw();
    [q[0], q[1], q[2], q[3]]
}
