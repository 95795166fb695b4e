//! A pose graph's optimisation in words — the findings (outliers, parts, duplicated edges, a
//! solve that did not converge) and the text panel's paragraph — and in pictures
//! ([`after`]: the optimised poses, marginals, loop closures and relative uncertainties, in
//! the σ colours of [`ramp`]; [`zoom`]: the robot-scale views of the largest marginal and the
//! worst loop closure; [`sigma`]: each pose's σ before and after the loop closures, against
//! its index).

use std::fmt::Write;

use super::{Painter, legend, v3};
use crate::eval::Finding;
use crate::eval::graph::{Anchor, GraphEvaluation, MAX_TIMELINE_POSES, Optimizer, Part, Stop};
use crate::lie::{LieGroup, Se3};
use crate::scene::{ItemKind, Triads, paths};

mod about;
mod after;
mod labels;
mod ramp;
mod sigma;
mod zoom;

pub(super) use about::description as file_description;
pub(super) use after::draw_optimized;
pub(super) use sigma::sigma_plot;
pub(super) use zoom::Zoom;

/// A graph's drawn vertex estimates (the fixed poses of its plan: evenly chosen, plus the drawn
/// loop closures' ends) as one batch of frames at [`paths::vertices`], drawn in the before
/// view: one entity, not one per vertex (a recording of hundreds of entities is slow to write
/// and to browse). Nothing when there are none.
pub(super) fn vertex_frames(p: &mut Painter, world_from_vertex: &[Se3]) {
    if world_from_vertex.is_empty() {
        return;
    }
    p.scene.add_legend(legend::axes("pose frames"));
    p.push(
        paths::vertices(),
        None,
        ItemKind::Triads(Triads {
            translations: world_from_vertex
                .iter()
                .map(|x| v3(x.translation()))
                .collect(),
            rotations: world_from_vertex
                .iter()
                .map(|x| x.rotation().to_quaternion_xyzw())
                .collect(),
            axis_length: p.axis_length,
            line_radius: p.link_radius(),
        }),
    );
}

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
            "**Loop closure v{from} → v{to} (line {line}) is an outlier**: after the optimisation its residual is d = {mahalanobis:.2} (Mahalanobis, under the edge's own Σ), beyond the {} radius {radius:.2} (it was {mahalanobis_before:.2} at the file's estimates).",
            confidence
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
    loop_closures(&mut d, g);
    joints(&mut d, g);
    timeline(&mut d, g);
    d
}

/// How to scrub the loop-closure timeline, or why there is none.
fn timeline<G: LieGroup<N>, const N: usize>(d: &mut String, g: &GraphEvaluation<G, N>) {
    let t = &g.timeline;
    if let Some(poses) = t.too_large {
        let _ = write!(
            d,
            "\n\nNo loop-closure timeline: {poses} poses, more than the {MAX_TIMELINE_POSES} posecov re-solves closure by closure."
        );
        return;
    }
    if t.steps.len() < 2 {
        return;
    }
    let ks: Vec<String> = t.steps.iter().map(|s| s.closures.to_string()).collect();
    let chi2: Vec<String> = t.steps.iter().map(|s| format!("{:.3e}", s.chi2)).collect();
    let _ = write!(
        d,
        "\n\n**Loop closures one by one**: scrub the `step` timeline. Up to the chain's last step the after view shows the graph without loop closures — dead reckoning, its marginals grow like the chain's banana; each later step adds the next loop closures in file order (k = {}), re-optimised, drawn thick, and the marginals shrink where they join. χ² at each step: {}.",
        ks.join(", "),
        chi2.join(", ")
    );
    if t.interrupted {
        d.push_str(" *Interrupted: the steps so far.*");
    }
}

/// Most loop closures named in the text panel's paragraph.
const NAMED_LOOP_CLOSURES: usize = 5;

/// The loop closures' residuals before and after, at the confidence: how many lie beyond the
/// radius, and the largest before the optimisation.
fn loop_closures<G: LieGroup<N>, const N: usize>(d: &mut String, g: &GraphEvaluation<G, N>) {
    let all = g.loop_closures.len();
    if all == 0 {
        d.push_str(" No loop closures: nothing to close the chain.");
        return;
    }
    let before = g
        .loop_closures
        .iter()
        .filter(|l| l.mahalanobis_before > g.radius)
        .count();
    let after = g.outliers().len();
    let _ = write!(
        d,
        "\n\n**Loop closures** ({all}): the residual r = Log(Z⁻¹ X_i⁻¹ X_j) of each, measured by its own Σ as d = √(rᵀ Σ⁻¹ r) against the {} radius √χ²_{N} = {:.2}. At the file's estimates {before} of {all} lie beyond it; after the optimisation {after}.",
        g.confidence, g.radius
    );
    let mut worst: Vec<_> = g.loop_closures.iter().collect();
    worst.sort_by(|a, b| b.mahalanobis_before.total_cmp(&a.mahalanobis_before));
    let named: Vec<String> = worst
        .iter()
        .take(NAMED_LOOP_CLOSURES)
        .map(|l| {
            format!(
                "v{} → v{} (line {}) d = {:.2} → {:.2}",
                l.from, l.to, l.line, l.mahalanobis_before, l.mahalanobis
            )
        })
        .collect();
    let _ = write!(d, " Largest before, then after: {}.", named.join("; "));
}

/// The joint marginals asked for (`--joint`): the relative pose's σ.
fn joints<G: LieGroup<N>, const N: usize>(d: &mut String, g: &GraphEvaluation<G, N>) {
    for j in &g.joints {
        let _ = write!(d, "\n\n**Joint marginal of v{} and v{}**: ", j.a, j.b);
        match &j.relative_cov {
            Some(cov) => {
                let sigma: Vec<String> = cov
                    .diagonal()
                    .iter()
                    .map(|v| format!("{:.3}", v.max(0.0).sqrt()))
                    .collect();
                let _ = write!(
                    d,
                    "the relative pose X_a⁻¹ X_b has σ = ({}) over [ρ; θ] (right form, m and rad), drawn as `relative/v{}_v{}` at v{} as v{} sees it.",
                    sigma.join(", "),
                    j.a,
                    j.b,
                    j.b,
                    j.a
                );
            }
            None => d.push_str(
                "no relative uncertainty: the two lie in different parts (each anchored on its own), or one is reached by nothing.",
            ),
        }
    }
}
