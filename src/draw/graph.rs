//! A pose graph's optimisation in words: the findings (outliers, parts, duplicated edges, a
//! solve that did not converge) and the text panel's paragraph.

use std::fmt::Write;

use super::shapes;
use super::{Painter, v3};
use crate::eval::Finding;
use crate::eval::graph::{Anchor, GraphEvaluation, Optimizer, Part, Stop};
use crate::lie::LieGroup;
use crate::scene::{
    self, Arrows, Color, Ellipsoids, FillMode, Frame, ItemKind, LineStrips, QuatXyzw, Timing,
    Triads, Vec3, WORLD,
};
use crate::uncertain::{Side, UncertainPose};

/// The sentence of a graph finding (`None` for any other finding).
pub(super) fn finding_text(f: &Finding) -> Option<String> {
    Some(match f {
        Finding::GraphNotConverged {
            stop,
            optimizer,
            iterations,
            chi2_before,
            chi2_after,
            log,
        } => {
            let mut s = format!(
                "**The {} did not converge**: {} after {iterations} accepted steps; χ² {chi2_before:.6e} → {chi2_after:.6e}. The poses drawn and reported are the last estimate that lowered χ². Steps tried:",
                optimizer_name(*optimizer),
                stop_text(*stop)
            );
            for i in log {
                let _ = write!(
                    s,
                    " #{} χ² {}{}{};",
                    i.iteration,
                    i.chi2
                        .map_or("not finite (no step)".to_owned(), |c| format!("{c:.4e}")),
                    i.lambda.map_or(String::new(), |l| format!(" λ {l:.0e}")),
                    if i.accepted { "" } else { " (rejected)" }
                );
            }
            s
        }
        Finding::LoopClosureOutlier {
            from,
            to,
            line,
            mahalanobis,
            mahalanobis_before,
            radius,
            confidence,
        } => format!(
            "**Loop closure v{from} → v{to} (line {line}) is an outlier**: after the optimisation its residual is d = {mahalanobis:.2} (Mahalanobis, under the edge's own Σ), beyond the {:.0} % radius {radius:.2} (it was {mahalanobis_before:.2} at the file's estimates).",
            100.0 * confidence.get()
        ),
        Finding::MoreLoopClosureOutliers {
            more,
            outliers,
            loop_closures,
        } => format!(
            "… and {more} more outliers: {outliers} of {loop_closures} loop closures in all (`report --json` lists every loop closure)."
        ),
        Finding::GraphParts { parts } => {
            let list: Vec<String> = parts.iter().map(part_text).collect();
            format!(
                "**The graph has {} unconnected parts**, each anchored on its own (marginals are relative to each part's anchor): {}.",
                parts.len(),
                list.join("; ")
            )
        }
        Finding::DuplicateEdges { count, lines } => {
            let list: Vec<String> = lines
                .iter()
                .map(|(line, first)| format!("line {line} repeats line {first}"))
                .collect();
            format!(
                "{count} edge(s) join two vertices an earlier edge already joins; all are kept and counted in χ² ({}).",
                list.join(", ")
            )
        }
        Finding::GraphMarginalsFailed { reason } => {
            format!("*No marginals: {reason}. The optimised poses stand.*")
        }
        _ => return None,
    })
}

fn optimizer_name(o: Optimizer) -> &'static str {
    match o {
        Optimizer::LevenbergMarquardt => "Levenberg–Marquardt optimiser",
        Optimizer::GaussNewton => "Gauss–Newton optimiser",
    }
}

fn stop_text(stop: Stop) -> &'static str {
    match stop {
        Stop::Converged => "converged",
        Stop::MaxIterations => "stopped at the iteration limit",
        Stop::LambdaLimit => "λ reached its bound without lowering χ²",
        Stop::Diverged => "a step raised χ² (diverging)",
        Stop::Singular => "the normal equations were singular",
        Stop::NotFinite => "χ² of the initial guess is not finite",
        Stop::Interrupted => "interrupted",
    }
}

fn part_text(p: &Part) -> String {
    let anchor = match &p.anchor {
        Anchor::Priors { count } => format!("{count} prior(s)"),
        Anchor::Fixed { ids } => {
            let ids: Vec<String> = ids.iter().map(|id| format!("v{id}")).collect();
            format!("FIX {}", ids.join(" "))
        }
        Anchor::FirstVertex { id } => format!("v{id} held at its estimate"),
        Anchor::Isolated { id } => {
            return format!(
                "v{id} alone (no edge or prior reaches it: kept as given, no marginal)"
            );
        }
    };
    format!("{} vertices from v{} ({anchor})", p.vertices, p.first_id)
}

/// The text panel's paragraph on the optimisation.
pub(super) fn describe<G: LieGroup<N>, const N: usize>(g: &GraphEvaluation<G, N>) -> String {
    let s = &g.solution;
    let mut d = format!(
        "\n\n**Optimised** ({}, {} accepted steps, {}): χ² = Σ rᵀ Λ r over edges and priors {:.6e} → **{:.6e}** ({} edges, {} unknowns).",
        optimizer_name(s.optimizer),
        s.iterations,
        stop_text(s.stop),
        s.chi2_before,
        s.chi2_after,
        g.edge_chi2.len(),
        s.unknowns
    );
    let anchors: Vec<String> = s.parts.iter().map(part_text).collect();
    let _ = write!(d, " Gauge: {}.", anchors.join("; "));
    let outliers = g.outliers().len();
    let _ = write!(
        d,
        " {} loop closures; {outliers} lie beyond the {:.0} % radius {:.2} of their own Σ after the optimisation.",
        g.loop_closures.len(),
        100.0 * g.confidence.get(),
        g.radius
    );
    d
}

/// The subtree of the "after" picture, under [`WORLD`].
pub(super) const AFTER: &str = "optimized";

/// Most optimised poses drawn with their marginal ellipse (evenly chosen, plus the loop
/// closures' ends).
pub const MAX_DRAWN_MARGINALS: usize = 600;
/// Most poses drawn with their marginal banana: the largest marginal, the last pose and the
/// ends of the loop closures with the largest residuals.
pub const MAX_BANANAS: usize = 6;
/// Most labels in the after picture.
const MAX_LABELS: usize = 24;
/// Colour of the optimised poses and their marginals.
pub const OPTIMIZED: Color = Color::rgb(0, 158, 115);
/// Colour of loop closures beyond their radius.
pub const OUTLIER: Color = Color::rgb(213, 94, 0);

/// The "after" picture at `world/optimized/…` (static): the optimised trajectory and poses,
/// every drawn pose's marginal position ellipse at the confidence, the marginal bananas of a
/// few poses, each loop closure as a line between its optimised ends (outliers in
/// [`OUTLIER`]) with its residual as an arrow from the pose it predicts (X_i · Z) to X_j,
/// and labels only where they do not collide.
pub(super) fn draw_optimized<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
) {
    let s = &g.solution;
    let position = |x: &G| x.to_se3().translation().to_owned();
    let radius = 0.003 * p.extent.max(0.25);
    p.push(
        format!("{WORLD}/{AFTER}/trajectory"),
        None,
        ItemKind::LineStrips(LineStrips {
            strips: vec![s.poses.iter().map(|x| v3(&position(x))).collect()],
            color: OPTIMIZED,
            radius,
        }),
    );
    // Which poses get an ellipse: evenly chosen, plus every loop closure's ends.
    let n = s.poses.len();
    let mut drawn: std::collections::BTreeSet<usize> = (0..MAX_DRAWN_MARGINALS.min(n))
        .map(|k| k * (n.max(2) - 1) / (MAX_DRAWN_MARGINALS.min(n).max(2) - 1))
        .filter(|&k| k < n)
        .collect();
    let index_of: std::collections::HashMap<u64, usize> =
        g.ids.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let mut worst: Vec<&crate::eval::graph::LoopClosure<N>> = g.loop_closures.iter().collect();
    worst.sort_by(|a, b| b.mahalanobis.total_cmp(&a.mahalanobis));
    for l in worst.iter().take(MAX_DRAWN_MARGINALS / 4) {
        drawn.extend([index_of[&l.from], index_of[&l.to]]);
    }
    let d = G::KIND.position_dims().max(1);
    let uncertain = |k: usize| {
        s.covariances[k].map(|cov| UncertainPose::new_unchecked(s.poses[k], cov, Side::Right))
    };
    let shapes: Vec<_> = drawn
        .iter()
        .filter_map(|&k| {
            let pose = uncertain(k)?;
            let cov = pose.position_cov_in_world_3d()?;
            Some(shapes::ellipsoid_of(
                &position(&s.poses[k]),
                &cov,
                p.confidence().radius(d),
            ))
        })
        .collect();
    if !shapes.is_empty() {
        p.push(
            format!("{WORLD}/{AFTER}/marginals"),
            None,
            ItemKind::Ellipsoids(Ellipsoids {
                shapes,
                color: OPTIMIZED,
                fill: FillMode::MajorWireframe,
                line_radius: radius * 0.6,
                label: None,
            }),
        );
    }
    p.push(
        format!("{WORLD}/{AFTER}/poses"),
        None,
        ItemKind::Triads(Triads {
            translations: drawn.iter().map(|&k| v3(&position(&s.poses[k]))).collect(),
            rotations: drawn.iter().map(|&k| quat(&s.poses[k])).collect(),
            axis_length: p.axis_length * 0.6,
            line_radius: radius * 0.5,
        }),
    );
    // Bananas: the largest marginal, the last pose, the worst loop closures' ends.
    let size = |k: usize| s.covariances[k].map_or(0.0, |c| c.trace());
    let largest = (0..n).max_by(|&a, &b| size(a).total_cmp(&size(b)));
    let mut banana_poses: Vec<usize> = largest.into_iter().chain([n.saturating_sub(1)]).collect();
    for l in &worst {
        banana_poses.push(index_of[&l.to]);
    }
    banana_poses.dedup();
    let mut seen = std::collections::BTreeSet::new();
    banana_poses.retain(|k| seen.insert(*k));
    for &k in banana_poses.iter().take(MAX_BANANAS) {
        if let Some(pose) = uncertain(k) {
            p.region_banana(
                &format!("{WORLD}/{AFTER}/bananas/v{}", g.ids[k]),
                Timing::Static,
                &pose,
                OPTIMIZED,
                |x: &G| x.to_se3().translation().to_owned(),
            );
        }
    }
    // Loop closures: lines between the optimised ends; residual arrows X_i·Z → X_j.
    for (outliers, name, color) in [(false, "inliers", scene::LINK), (true, "outliers", OUTLIER)] {
        let chosen: Vec<&crate::eval::graph::LoopClosure<N>> = g
            .loop_closures
            .iter()
            .filter(|l| (l.mahalanobis > g.radius) == outliers)
            .collect();
        if chosen.is_empty() {
            continue;
        }
        let ends = |l: &crate::eval::graph::LoopClosure<N>| (index_of[&l.from], index_of[&l.to]);
        p.push(
            format!("{WORLD}/{AFTER}/loop_closures/{name}"),
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
                let (i, j) = ends(l);
                // X_j = X_i · Z · Exp(r): the predicted pose is X_j · Exp(−r).
                let predicted = position(&s.poses[j].compose(&G::exp(&-l.residual)));
                let estimated = position(&s.poses[j]);
                let _ = i;
                (v3(&predicted), v3(&(estimated - predicted)))
            })
            .unzip();
        p.push(
            format!("{WORLD}/{AFTER}/loop_closures/{name}_residuals"),
            None,
            ItemKind::Arrows(Arrows {
                origins,
                vectors,
                color,
                radius: radius * 0.8,
            }),
        );
    }
    labels(p, g, &worst, &banana_poses, true);
    labels(p, g, &worst, &banana_poses, false);
}

/// Labels that do not collide: the first and last pose, the loop closures' ends (worst
/// first), the largest marginal — each only if it is farther than 4 % of the drawing from
/// every label already placed. `after`: at the optimised poses (with the residual's d),
/// else at the file's estimates (`world/labels/…`).
fn labels<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    worst: &[&crate::eval::graph::LoopClosure<N>],
    bananas: &[usize],
    after: bool,
) {
    let (poses, prefix) = if after {
        (&g.solution.poses, format!("{WORLD}/{AFTER}/labels"))
    } else {
        (&g.initial, format!("{WORLD}/labels"))
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
            format!("{prefix}/v{}", g.ids[k]),
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
