//! Re-streaming into the same recording: each new scene (a *generation*) replaces the last in
//! place, so the viewer keeps its camera and layout and its recording list does not grow.
//!
//! Rerun keeps everything ever logged; what a view shows is a query. To leave nothing stale:
//!
//! - **3-D items and text** (latest-at queries): before a generation is logged, every entity
//!   position `(path, time)` touched so far gets a `Clear` at that same time (a static clear
//!   for static items). A clear hides what was logged at or before its index; what the new
//!   generation logs afterwards has a newer row id and shows. Where the new generation has
//!   the entity only at an *earlier* step, its latest item is logged again at the cleared
//!   step, so the step slider shows exactly what a fresh recording would. Clears are
//!   per entity (not recursive) and cost one small chunk each.
//! - **Plots** (range queries, which Rerun does not clear: a cleared point still plots):
//!   each generation's series go under `plots/<plot>/g<N>/…`, and the layout is sent again
//!   with each plot view's origin there. For scenes with plots this resets the camera to the
//!   layout's; scenes without plots keep the camera the user set. (An update of the views'
//!   contents alone would keep it, but the 0.36 viewer does not apply one.)
//!
//! Rerun lets static data shadow temporal data on the same entity forever, so an entity that
//! was ever logged static and is later logged at steps is logged static (its last step):
//! the picture stays right, only that entity's step animation is lost.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::AtomicBool;

use ::rerun as rr;

use super::rerun::{send, time_point};
use super::send_layout;
use super::{LogOutcome, SinkError, log_part_cancellable, log_scene_cancellable};
use crate::scene::{self, Scene, SceneItem, Timing};

/// The state of a recording that generations are re-streamed into.
#[derive(Debug, Default)]
pub struct Restream {
    /// Every entity position logged or cleared so far: path → times (`None`: static).
    touched: BTreeMap<String, BTreeSet<Timing>>,
    /// Entities that were ever static (and so can never show temporal data again).
    ever_static: BTreeSet<String>,
    /// Generations logged so far.
    generation: u64,
}

impl Restream {
    /// A recording with nothing logged yet.
    ///
    /// ```
    /// let r = posecov::sink::Restream::new();
    /// assert_eq!(r.generations(), 0);
    /// ```
    pub fn new() -> Self {
        Self::default()
    }

    /// How many generations were logged.
    pub fn generations(&self) -> u64 {
        self.generation
    }

    /// Logs `scene` in place of everything logged before (see the module docs): clears,
    /// the scene itself with its series under this generation's paths, and the plots'
    /// blueprint update. `cancel` as in [`log_scene_cancellable`].
    ///
    /// # Errors
    /// [`SinkError::Scene`] if the scene is invalid (nothing is logged then), or an SDK error.
    ///
    /// ```
    /// use std::sync::atomic::AtomicBool;
    /// use posecov::sink::{RecordingIds, Restream, Sink, open_stream};
    /// let scene = posecov::scene::Scene::new("t", "d");
    /// let (rec, guard) = open_stream(&Sink::Memory, &RecordingIds::for_scenario("doc", 0), &scene)?;
    /// let mut live = Restream::new();
    /// live.log(&rec, scene.clone(), &AtomicBool::new(false))?;
    /// live.log(&rec, scene, &AtomicBool::new(false))?;
    /// assert_eq!(live.generations(), 2);
    /// # guard.finish(rec)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn log(
        &mut self,
        rec: &rr::RecordingStream,
        mut scene: Scene,
        cancel: &AtomicBool,
    ) -> Result<LogOutcome, SinkError> {
        scene.validate()?;
        self.static_where_needed(&mut scene);
        let generation = self.generation;
        self.generation += 1;
        self.clear_and_carry(rec, &scene)?;
        if !scene.series.is_empty() {
            for series in &mut scene.series {
                series.path = generation_path(&series.path, generation);
            }
            // The plot views show this generation's series only (a new layout: Rerun's
            // plots do not honour clears).
            let ids: Vec<String> = scene.plots.iter().map(|p| p.id.clone()).collect();
            for plot in &mut scene.plots {
                plot.id = format!("{}/g{generation}", plot.id);
            }
            let sent = send_layout(rec, &scene);
            for (plot, id) in scene.plots.iter_mut().zip(ids) {
                plot.id = id;
            }
            sent?;
        }
        let outcome = log_scene_cancellable(rec, &scene, cancel)?;
        self.touch(&scene);
        Ok(outcome)
    }

    /// Logs a later part of the current generation (a Monte Carlo block's clouds).
    ///
    /// # Errors
    /// As [`log_part_cancellable`].
    pub fn log_part(
        &mut self,
        rec: &rr::RecordingStream,
        mut part: Scene,
        cancel: &AtomicBool,
    ) -> Result<LogOutcome, SinkError> {
        self.static_where_needed(&mut part);
        let outcome = log_part_cancellable(rec, &part, cancel)?;
        self.touch(&part);
        Ok(outcome)
    }

    /// Items at steps on entities that were ever static become static (their last step).
    fn static_where_needed(&mut self, scene: &mut Scene) {
        let now_static: BTreeSet<String> = scene
            .items
            .iter()
            .filter(|i| i.timing == Timing::Static)
            .map(|i| i.path.clone())
            .collect();
        self.ever_static.extend(now_static);
        let ever = &self.ever_static;
        let mut last: BTreeMap<String, i64> = BTreeMap::new();
        for item in &scene.items {
            if let (Timing::Step(k), true) = (item.timing, ever.contains(&item.path)) {
                let e = last.entry(item.path.clone()).or_insert(k);
                *e = (*e).max(k);
            }
        }
        if last.is_empty() {
            return;
        }
        scene.items.retain_mut(|item| match item.timing {
            Timing::Step(k) if ever.contains(&item.path) => {
                let keep = last.get(&item.path) == Some(&k);
                item.timing = Timing::Static;
                keep
            }
            _ => true,
        });
    }

    /// Clears every touched position; where `next` has the entity only at an earlier step,
    /// logs its latest item again at the cleared step.
    fn clear_and_carry(
        &mut self,
        rec: &rr::RecordingStream,
        next: &Scene,
    ) -> Result<(), SinkError> {
        let clear = rr::Clear::flat();
        let mut at: BTreeMap<&str, BTreeMap<Timing, &SceneItem>> = BTreeMap::new();
        for item in &next.items {
            at.entry(item.path.as_str())
                .or_default()
                .insert(item.timing, item);
        }
        let mut carried = Scene::new(String::new(), String::new());
        for (path, times) in &self.touched {
            clear_all(rec, path, times, &clear)?;
            for &t in times {
                let (Timing::Step(step), Some(new)) = (t, at.get(path.as_str())) else {
                    continue;
                };
                if new.contains_key(&t) || new.contains_key(&Timing::Static) {
                    continue;
                }
                if let Some((_, latest)) = new.range(..t).next_back() {
                    let mut item = (*latest).clone();
                    item.timing = Timing::Step(step);
                    carried.push(item);
                }
            }
        }
        if !carried.items.is_empty() {
            log_part_cancellable(rec, &carried, &AtomicBool::new(false))?;
        }
        Ok(())
    }

    fn touch(&mut self, scene: &Scene) {
        for item in &scene.items {
            self.touched
                .entry(item.path.clone())
                .or_default()
                .insert(item.timing);
        }
    }
}

/// One chunk of clears per entity: a static row if it was static, one row per step (or stamp)
/// it was logged at.
fn clear_all(
    rec: &rr::RecordingStream,
    path: &str,
    times: &BTreeSet<Timing>,
    clear: &rr::Clear,
) -> Result<(), SinkError> {
    if times.contains(&Timing::Static) {
        send(rec, path, Timing::Static, &[clear])?;
    }
    let timed: Vec<Timing> = times
        .iter()
        .copied()
        .filter(|t| *t != Timing::Static)
        .collect();
    if timed.is_empty() {
        return Ok(());
    }
    let mut builder = rr::log::Chunk::builder(rr::EntityPath::from(path));
    for t in timed {
        builder = builder.with_archetype(rr::log::RowId::new(), time_point(t), clear);
    }
    let chunk = builder.build().map_err(|err| SinkError::Chunk {
        path: path.to_owned(),
        message: err.to_string(),
    })?;
    rec.send_chunk(chunk);
    Ok(())
}

/// `plots/<plot>/<rest>` → `plots/<plot>/g<N>/<rest>`.
///
/// ```
/// assert_eq!(posecov::sink::restream::generation_path("plots/trace/first_order", 3), "plots/trace/g3/first_order");
/// ```
pub fn generation_path(path: &str, generation: u64) -> String {
    let prefix = format!("{}/", scene::PLOTS);
    match path
        .strip_prefix(&prefix)
        .and_then(|rest| rest.split_once('/'))
    {
        Some((plot, rest)) => format!("{prefix}{plot}/g{generation}/{rest}"),
        None => path.to_owned(),
    }
}
