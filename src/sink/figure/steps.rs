//! Which items a figure draws at the chosen [`Steps`]: every step at once (a long propagation's
//! detailed steps, thinned; a graph's final after state), or the state at one step.

use super::Steps;
use crate::scene::{ItemKind, Scene, SceneItem, Timing};

/// The items a figure draws: geometry only (no text), at the chosen steps. With every step, a
/// robot log's items (at stamps) are each entity's last, as the viewer opens: the last message
/// drawn whole over the static outlines of every drawn message.
pub(super) fn selected(scene: &Scene, steps: Steps) -> Vec<&SceneItem> {
    let drawable = |i: &&SceneItem| !matches!(i.kind, ItemKind::Text(_));
    match steps {
        Steps::All if scene.states.is_some() => {
            // A graph: the chain's steps at once, and the after view's final state only.
            let last = scene
                .states
                .as_ref()
                .and_then(|s| s.steps.last())
                .map(|s| s.step);
            let drawn = drawn_steps(scene);
            let states = scene.states.as_ref();
            scene
                .items
                .iter()
                .filter(|i| match (i.timing, states) {
                    (Timing::Step(k), Some(st)) if st.contains(&i.path) => Some(k) == last,
                    (Timing::Step(k), _) => drawn.contains(&k),
                    _ => true,
                })
                .filter(drawable)
                .collect()
        }
        Steps::All => {
            let drawn = drawn_steps(scene);
            let mut last_stamp: std::collections::BTreeMap<&str, i64> = Default::default();
            for item in &scene.items {
                if let Timing::Stamp(ns) = item.timing {
                    let last = last_stamp.entry(item.path.as_str()).or_insert(ns);
                    *last = (*last).max(ns);
                }
            }
            scene
                .items
                .iter()
                .filter(|i| match i.timing {
                    Timing::Step(k) => drawn.contains(&k),
                    Timing::Stamp(ns) => last_stamp.get(i.path.as_str()) == Some(&ns),
                    Timing::Static => true,
                })
                .filter(drawable)
                .collect()
        }
        Steps::At(k) => {
            // A graph's K: the state after K loop closures.
            let k = scene
                .states
                .as_ref()
                .and_then(|s| s.step_after(k.max(0) as u64))
                .unwrap_or(k);
            // Per entity, its latest item at or before step k (static first, then by step).
            let mut order: Vec<usize> = (0..scene.items.len()).collect();
            order.sort_by_key(|&i| match scene.items[i].timing {
                Timing::Static => (0, 0),
                Timing::Step(s) => (1, s),
                Timing::Stamp(ns) => (2, ns),
            });
            let mut latest: std::collections::BTreeMap<&str, usize> = Default::default();
            for i in order {
                let item = &scene.items[i];
                if !matches!(item.timing, Timing::Step(s) if s > k) {
                    latest.insert(item.path.as_str(), i);
                }
            }
            let keep: std::collections::BTreeSet<usize> = latest.into_values().collect();
            scene
                .items
                .iter()
                .enumerate()
                .filter(|(i, _)| keep.contains(i))
                .map(|(_, item)| item)
                .filter(drawable)
                .collect()
        }
    }
}

/// At most this many steps are drawn at once: a longer propagation shows its steps with
/// clouds and regions (the detailed ones), evenly thinned to this many, always the last.
pub const MAX_DRAWN_STEPS: usize = 12;

/// The steps an all-steps figure draws: every step when they are few, else the detailed
/// steps (those with clouds or regions), evenly thinned to [`MAX_DRAWN_STEPS`] with the first
/// and the last.
pub(super) fn drawn_steps(scene: &Scene) -> Vec<i64> {
    let steps = scene.steps();
    if steps.len() <= MAX_DRAWN_STEPS {
        return steps;
    }
    let mut detailed: Vec<i64> = scene
        .items
        .iter()
        .filter(|i| matches!(i.kind, ItemKind::Points(_) | ItemKind::Surface(_)))
        .filter(|i| !scene.states.as_ref().is_some_and(|s| s.contains(&i.path)))
        .filter_map(|i| match i.timing {
            Timing::Step(k) => Some(k),
            _ => None,
        })
        .collect();
    detailed.sort_unstable();
    detailed.dedup();
    let pool = if detailed.len() >= 2 { detailed } else { steps };
    let stride = (pool.len() - 1).div_ceil(MAX_DRAWN_STEPS - 1).max(1);
    let mut drawn: Vec<i64> = pool.iter().step_by(stride).copied().collect();
    if let Some(last) = pool.last().filter(|l| drawn.last() != Some(l)) {
        drawn.push(*last);
    }
    drawn
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Color, LineStrips, States};

    fn line(path: &str, timing: Timing) -> SceneItem {
        SceneItem::new(
            path,
            timing,
            ItemKind::LineStrips(LineStrips {
                strips: vec![vec![[0.0; 3], [1.0, 0.0, 0.0]]],
                color: Color::rgb(0, 0, 0),
                radius: 0.01,
            }),
        )
    }

    /// A graph: the chain at steps 0–3, the after view's states at 0 (no loop closures),
    /// 4 (2 closures) and 5 (all 6), a static loop-closure line.
    fn graph() -> Scene {
        let mut scene = Scene::new("g", "");
        for k in 0..4 {
            scene.items.push(line("world/chain", Timing::Step(k)));
        }
        for k in [0, 4, 5] {
            scene
                .items
                .push(line("world/optimized/trajectory", Timing::Step(k)));
        }
        scene
            .items
            .push(line("world/optimized/loop_closures", Timing::Static));
        scene.states = Some(States {
            path: "world/optimized".into(),
            steps: [(0, 0), (2, 4), (6, 5)]
                .map(|(closures, step)| crate::scene::State { closures, step })
                .to_vec(),
        });
        scene
    }

    fn after_steps(items: &[&SceneItem]) -> Vec<Timing> {
        items
            .iter()
            .filter(|i| i.path == "world/optimized/trajectory")
            .map(|i| i.timing)
            .collect()
    }

    #[test]
    fn a_graph_figure_draws_the_chain_and_only_the_final_after_state() {
        let scene = graph();
        let items = selected(&scene, Steps::All);
        assert_eq!(after_steps(&items), vec![Timing::Step(5)]);
        assert_eq!(items.iter().filter(|i| i.path == "world/chain").count(), 4);
        assert!(items.iter().any(|i| i.timing == Timing::Static));
    }

    #[test]
    fn a_graph_figure_at_step_k_draws_the_state_after_k_loop_closures() {
        let scene = graph();
        for (k, want) in [(0, 0), (1, 0), (2, 4), (5, 4), (6, 5), (99, 5)] {
            let items = selected(&scene, Steps::At(k));
            assert_eq!(after_steps(&items), vec![Timing::Step(want)], "--step {k}");
        }
    }
}
