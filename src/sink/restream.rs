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
//! - **Frames** are the exception: the viewer resolves a cleared transform to the identity
//!   even when a newer transform follows at the same time (checked in the real viewer: the
//!   robot's axes jumped to the origin), so a frame position that the new generation draws
//!   a frame at again is not cleared but overwritten — transform, axes and, where the old
//!   frame had a label and the new one has none, an empty label marker.
//! - **Plots** (range queries, which Rerun does not clear: a cleared point still plots):
//!   each generation's series go under `plots/<plot>/g<N>/…`, inside the plot view's
//!   `$origin/**`, and every series of an earlier generation gets a *static, empty*
//!   `Scalars`. Static data shadows a component's temporal data for every query, range
//!   queries included, so the old line vanishes from its plot; the layout stays as it was.
//! - **The layout** (a blueprint, which the viewer clones on arrival and the user then edits:
//!   the camera lives there) is sent again only when the views or plots themselves change
//!   (a method switched on adds a plot, a view is split); a change of values keeps the
//!   viewer's camera and layout. A view's camera is not part of that comparison.
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
use crate::scene::{self, ItemKind, Scene, SceneItem, Timing};

/// The state of a recording that generations are re-streamed into.
#[derive(Debug, Default)]
pub struct Restream {
    /// Every entity position logged or cleared so far: path → times (`None`: static).
    touched: BTreeMap<String, BTreeSet<Timing>>,
    /// Entities that were ever static (and so can never show temporal data again).
    ever_static: BTreeSet<String>,
    /// Positions last logged as a frame, and whether with a label (whose marker must be
    /// emptied when the new frame has none).
    frames: BTreeMap<(String, Timing), bool>,
    /// Series logged by earlier generations whose lines are not yet shadowed.
    series: BTreeSet<String>,
    /// What the layout sent last is made of ([`layout_key`]; `None`: the opener's layout,
    /// taken to be the first scene's).
    layout: Option<String>,
    /// Send the layout with the next generation even if its key is the same ([`Self::reframe`]).
    reframe: bool,
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

    /// Sends the layout again with the next generation, its cameras fitted to that scene
    /// (a "frame the picture" request: otherwise the viewer keeps the user's camera).
    ///
    /// ```
    /// let mut r = posecov::sink::Restream::new();
    /// r.reframe();
    /// ```
    pub fn reframe(&mut self) {
        self.reframe = true;
    }

    /// Logs `scene` in place of everything logged before (see the module docs): clears, the
    /// layout when the views changed (or after [`reframe`](Self::reframe)), the shadows of
    /// the last generation's series, then the scene with its series under this generation's
    /// paths. `cancel` as in [`log_scene_cancellable`].
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
        let key = layout_key(&scene);
        if self.reframe || self.layout.as_ref().is_some_and(|sent| *sent != key) {
            send_layout(rec, &scene)?;
            self.reframe = false;
        }
        self.layout = Some(key);
        self.shadow_series(rec)?;
        for series in &mut scene.series {
            series.generation = Some(generation);
            self.series.insert(series.path());
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

    /// Hides the lines of earlier generations: a static, empty `Scalars` on each series
    /// shadows its temporal values in every query (see the module docs).
    fn shadow_series(&mut self, rec: &rr::RecordingStream) -> Result<(), SinkError> {
        let empty = rr::Scalars::new(std::iter::empty::<f64>());
        for path in std::mem::take(&mut self.series) {
            send(rec, path.as_str(), rr::TimePoint::default(), &[&empty])?;
        }
        Ok(())
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
        carried.timeline = next.timeline;
        let mut unlabel = Vec::new();
        for (path, times) in &self.touched {
            let new = at.get(path.as_str());
            // The item the new generation shows at `t`: its own, else (carried) its latest
            // before `t`; static items cover every step.
            let shown = |t: Timing| {
                new.and_then(|n| {
                    n.get(&t)
                        .or_else(|| n.get(&Timing::Static))
                        .or_else(|| match t {
                            Timing::Step(_) => n.range(..t).next_back().map(|(_, i)| i),
                            _ => None,
                        })
                })
            };
            let cleared: BTreeSet<Timing> = times
                .iter()
                .copied()
                .filter(|&t| {
                    let was = self.frames.get(&(path.clone(), t));
                    match (was, shown(t).map(|i| &i.kind)) {
                        (Some(&labelled), Some(ItemKind::Frame(frame))) => {
                            if labelled && frame.viewer_label().is_none() {
                                unlabel.push((path.as_str(), t));
                            }
                            false
                        }
                        _ => true,
                    }
                })
                .collect();
            clear_all(rec, path, &cleared, &clear, next.timeline)?;
            for &t in times {
                let (Timing::Step(step), Some(new)) = (t, new) else {
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
        let no_marker = rr::Points3D::new(std::iter::empty::<[f32; 3]>());
        for (path, t) in unlabel {
            send(rec, path, time_point(t, next.timeline), &[&no_marker])?;
        }
        if !carried.items.is_empty() {
            log_part_cancellable(rec, &carried, &AtomicBool::new(false))?;
            self.touch(&carried);
        }
        Ok(())
    }

    fn touch(&mut self, scene: &Scene) {
        for item in &scene.items {
            let key = (item.path.clone(), item.timing);
            match &item.kind {
                ItemKind::Frame(frame) => self.frames.insert(key, frame.viewer_label().is_some()),
                _ => self.frames.remove(&key),
            };
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
    timeline: scene::Timeline,
) -> Result<(), SinkError> {
    if times.contains(&Timing::Static) {
        send(rec, path, rr::TimePoint::default(), &[clear])?;
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
        builder = builder.with_archetype(rr::log::RowId::new(), time_point(t, timeline), clear);
    }
    let chunk = builder.build().map_err(|err| SinkError::Chunk {
        path: path.to_owned(),
        message: err.to_string(),
    })?;
    rec.send_chunk(chunk);
    Ok(())
}

/// What a layout is made of, cameras (and the grid spacing chosen with them) left out: the
/// views (their names and what they show and hide), the plots (ids and titles), the timeline
/// and whether there is a legend view. Two scenes with the same key get
/// the same layout but for the cameras.
///
/// ```
/// use posecov::scene::{Camera, Scene, View3d};
/// use posecov::sink::restream::layout_key;
/// let mut a = Scene::new("t", "d");
/// a.views.push(View3d { name: "3D".into(), ..Default::default() });
/// let mut b = a.clone();
/// b.views[0].camera = Some(Camera { position: [3.0, 0.0, 1.0], target: [0.0; 3], up: [0.0, 0.0, 1.0] });
/// assert_eq!(layout_key(&a), layout_key(&b));
/// b.views[0].hidden.push("world/x".into());
/// assert_ne!(layout_key(&a), layout_key(&b));
/// ```
pub fn layout_key(scene: &Scene) -> String {
    let views: Vec<_> = scene
        .views
        .iter()
        .map(|v| (&v.name, &v.include, &v.exclude, &v.hidden))
        .collect();
    format!(
        "{views:?} {:?} {:?} legend {:?}",
        scene.plots,
        scene.timeline,
        crate::scene::layout::legend_pane(scene, scene.views.len())
    )
}
