//! The plot that says what the loop closures did: each pose's σ against its index, before
//! (dead reckoning) and after (optimised), position and rotation, with a rug of marks where
//! the loop closures join.

use std::collections::{BTreeSet, HashMap};

use crate::eval::graph::{GraphEvaluation, PoseSigma};
use crate::lie::LieGroup;
use crate::scene::{self, Color, Corner, Plot, PlotId, ScalarSeries, Scene};
use crate::uncertain::Method;

use super::after::OPTIMIZED;

/// The plot's id (`plots/graph_sigma`).
const PLOT: &str = "graph_sigma";
/// σ before: dead reckoning, drawn in first order's colour as the chain's banana is.
const BEFORE: Color = Method::FirstOrder.color();
/// The rotation σ before: a darker blue.
const BEFORE_ROTATION: Color = Color::rgb(0, 90, 150);
/// The rotation σ after: a darker green.
const AFTER_ROTATION: Color = Color::rgb(0, 100, 70);
/// When the largest σ drawn is more than this many times the smallest, the plot is of
/// log₁₀ σ (and says so).
const LOG_RATIO: f64 = 100.0;

/// Adds the σ plot first among `scene`'s plots: per pose (x = its index in vertex order),
/// the position σ √tr Σ_ρρ and the rotation σ √tr Σ_θθ (a 2-D pose's heading σ) of its
/// dead-reckoning marginal and of its optimised one ([`GraphEvaluation::sigmas`]), and a
/// mark below the lines (a rug) at both poses each loop closure joins. Values are in m and rad; when
/// they span more than [`LOG_RATIO`], log₁₀ of them, said in the title and unit. Poses held
/// fixed (no marginal) are left out.
pub(in crate::draw) fn sigma_plot<G: LieGroup<N>, const N: usize>(
    scene: &mut Scene,
    g: &GraphEvaluation<G, N>,
) {
    let sigmas = g.sigmas();
    let all: Vec<f64> = sigmas
        .iter()
        .flat_map(|s| [s.before, s.after])
        .flatten()
        .flat_map(|s| [s.position, s.rotation])
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    if all.is_empty() {
        return;
    }
    let (low, high) = all.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    let log = high > LOG_RATIO * low;
    let value = |v: f64| if log { v.log10() } else { v };
    let id = PlotId::new(PLOT);
    let rotation = if G::KIND.is_planar() {
        "heading σ √Σ_θθ"
    } else {
        "rotation σ √tr Σ_θθ"
    };
    let line = |pick: &dyn Fn(&PoseSigma) -> f64, before: bool| -> Vec<(i64, f64)> {
        sigmas
            .iter()
            .enumerate()
            .filter_map(|(k, s)| {
                let s = if before { s.before } else { s.after }?;
                let v = pick(&s);
                (v > 0.0 && v.is_finite()).then(|| (k as i64, value(v)))
            })
            .collect()
    };
    let position = |s: &PoseSigma| s.position;
    let turn = |s: &PoseSigma| s.rotation;
    let mut series = vec![
        ScalarSeries::new(
            id.clone(),
            "position_before",
            "position σ √tr Σ_ρρ before, m",
            BEFORE,
            2.0,
            line(&position, true),
        ),
        ScalarSeries::new(
            id.clone(),
            "position_after",
            "position σ after, m",
            OPTIMIZED,
            2.0,
            line(&position, false),
        ),
        ScalarSeries::new(
            id.clone(),
            "rotation_before",
            format!("{rotation} before, rad"),
            BEFORE_ROTATION,
            1.2,
            line(&turn, true),
        ),
        ScalarSeries::new(
            id.clone(),
            "rotation_after",
            format!("{rotation} after, rad"),
            AFTER_ROTATION,
            1.2,
            line(&turn, false),
        ),
    ];
    let (bottom, top) = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    // Where the loop closures join: a rug of marks below the lines (on a long graph they are
    // hundreds; on the lines they would hide them), at both ends of each.
    let (rug, range) = if log {
        let pad = 0.08 * (top - bottom).max(0.1);
        (bottom - pad, [bottom - 2.0 * pad, top + pad])
    } else {
        (0.0, [-0.05 * top, 1.05 * top])
    };
    let index: HashMap<u64, usize> = g.ids.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let ends: BTreeSet<usize> = g
        .loop_closures
        .iter()
        .flat_map(|l| [index.get(&l.from), index.get(&l.to)])
        .flatten()
        .copied()
        .collect();
    if !ends.is_empty() {
        series.push(
            ScalarSeries::new(
                id.clone(),
                "loop_closure_ends",
                format!("loop closures' ends ({} poses)", ends.len()),
                scene::LINK,
                5.0,
                ends.iter().map(|&k| (k as i64, rug)).collect(),
            )
            .as_marks(),
        );
    }
    scene.plots.insert(
        0,
        Plot {
            id,
            title: format!(
                "{}σ by pose, before/after loop closures",
                if log { "log₁₀ " } else { "" }
            ),
            unit: if log { "log₁₀ m, rad" } else { "m, rad" }.to_owned(),
            range: range.iter().all(|v| v.is_finite()).then_some(range),
            legend: Corner::LeftTop,
        },
    );
    scene.series.extend(series);
}
