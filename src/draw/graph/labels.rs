//! The few labels of a pose graph's views, chosen by importance and joined where they would
//! sit on each other (the figure places their boxes apart, the viewer writes short tags).

use crate::eval::graph::{GraphEvaluation, LoopClosure};
use crate::lie::LieGroup;
use crate::scene::{Frame, ItemKind, paths};

use super::super::{Painter, v3};
use super::after::{position_sigma, quat};
use super::ramp;

/// At most four labels, by importance: the worst loop closure (the largest residual d after
/// the optimisation; before it, at the file's estimates), the largest marginal (after only),
/// the first and the last pose. Labels of one pose, or of poses closer than 4 % of the
/// drawing, are joined into one ("; "), so no two sit on each other. `after`: at the optimised
/// poses (`world/optimized/labels/…`), else at the file's estimates (`world/labels/…`). A
/// figure places each label's box where it overlaps no other (`sink::figure`); the viewer
/// writes a short tag ("v9 ← v5 worst", "v7 largest σ", "v0 first"), the whole words going to
/// the text panel, and leaves out a tag that would cover a more important one
/// ([`crate::draw::tags`]).
pub(super) fn labels<G: LieGroup<N>, const N: usize>(
    p: &mut Painter,
    g: &GraphEvaluation<G, N>,
    largest: Option<usize>,
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
    if n == 0 {
        return;
    }
    let index_of = |id: u64| g.ids.binary_search(&id).ok();
    let d = |l: &LoopClosure<N>| {
        if after {
            l.mahalanobis
        } else {
            l.mahalanobis_before
        }
    };
    let worst = g.loop_closures.iter().max_by(|a, b| d(a).total_cmp(&d(b)));
    // (pose index, who: "v9 ← v5", what in words, what in a tag)
    let mut candidates: Vec<(usize, String, String, &str)> = Vec::new();
    if let Some(l) = worst
        && let Some(j) = index_of(l.to)
    {
        let what = if after {
            "worst loop closure"
        } else {
            "worst loop closure at the file's estimates"
        };
        candidates.push((
            j,
            format!("v{} ← v{}", l.to, l.from),
            format!("{what}, d = {:.2}", d(l)),
            "worst",
        ));
    }
    if let (Some(k), true) = (largest, after) {
        let sigma = position_sigma::<G, N>(&g.solution.covariances[k]);
        candidates.push((
            k,
            format!("v{}", g.ids[k]),
            format!("largest marginal, σ {}", ramp::length_words(sigma)),
            "largest σ",
        ));
    }
    let pose = |k: usize| format!("v{}", g.ids[k]);
    candidates.push((0, pose(0), "first pose".to_owned(), "first"));
    candidates.push((n - 1, pose(n - 1), "last pose".to_owned(), "last"));
    let position = |k: usize| poses[k].to_se3().translation().to_owned();
    let near = 0.04 * p.extent.max(1e-9);
    // (pose index, words, tag)
    let mut placed: Vec<(usize, String, String)> = Vec::new();
    for (k, who, what, short) in candidates {
        match placed
            .iter_mut()
            .find(|(q, ..)| *q == k || (position(*q) - position(k)).norm() < near)
        {
            // The same pose: its name once ("v9 ← v5: worst …; last pose").
            Some((q, words, tag)) if *q == k => {
                words.push_str(&format!("; {what}"));
                tag.push_str(&format!(", {short}"));
            }
            Some((_, words, tag)) => {
                words.push_str(&format!("; {who}: {what}"));
                tag.push_str(&format!("; {who} {short}"));
            }
            None => placed.push((k, format!("{who}: {what}"), format!("{who} {short}"))),
        }
    }
    for (k, text, tag) in placed {
        p.push(
            paths::vertex(&prefix, g.ids[k]),
            None,
            ItemKind::Frame(Frame {
                translation: v3(&position(k)),
                rotation: quat(&poses[k]),
                axis_length: p.axis_length * 0.6,
                label: Some(text),
                tag: Some(tag),
            }),
        );
    }
}
