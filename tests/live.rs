//! Live mode's control API on an in-memory recording: a change re-streams in place, and what
//! the viewer's own query engine (Rerun's `EntityDb`, latest-at per step) shows afterwards is
//! exactly what a fresh recording of the edited scenario shows: nothing stale, one recording.

use std::collections::BTreeSet;
use std::sync::Arc;
use std::time::Duration;

use posecov::app::live::{Edit, EditValue, Live, LiveDocument, Status};
use posecov::app::{Overrides, load_text, pipeline};
use posecov::sink::{RecordingIds, Sink, open_stream, scene_to_rrd_bytes};
use rerun::external::arrow::array::{Array as _, ArrayRef, StringArray};
use rerun::external::re_entity_db::EntityDb;
use rerun::external::re_entity_db::external::re_chunk_store::LatestAtQuery;
use rerun::external::re_log_encoding::DecoderApp;
use rerun::external::re_log_types::TimeInt;
use rerun::external::re_sdk_types::blueprint::archetypes::ViewBlueprint;
use rerun::log::LogMsg;
use rerun::{EntityPath, StoreKind};

mod rrd;

const WAIT: Duration = Duration::from_secs(120);

fn edit(id: &str, value: f64) -> Edit {
    Edit {
        id: id.into(),
        value: EditValue::Number(value),
    }
}

/// A live session on a memory sink, with `samples` set first.
fn start(name: &str, samples: u64) -> (Arc<Live>, Status) {
    let mut doc = LiveDocument::open(name).unwrap();
    doc.apply(&edit("scenario.samples", samples as f64))
        .unwrap();
    let (_, scene) = pipeline(doc.loaded(), &Overrides::default(), None).unwrap();
    let ids = RecordingIds::for_scenario(name, 0);
    let (rec, guard) = open_stream(&Sink::Memory, &ids, &scene).unwrap();
    let live = Live::start(doc, rec, guard, Overrides::default());
    let status = live.wait_done(0, WAIT);
    assert_eq!(status.shown, Some(0), "{status:?}");
    (live, status)
}

/// A fresh recording of the current text of `live` (its description with live mode's note of
/// the values changed from the file).
fn fresh(live: &Live) -> Vec<u8> {
    let text = live.with_doc(|d| d.text());
    let mut loaded = load_text(&text, "fresh.toml").unwrap();
    let about = live.with_doc(|d| d.loaded().input.about.clone());
    assert!(
        about
            .description
            .starts_with(&loaded.input.about.description)
    );
    loaded.input.about = about;
    let (_, scene) = pipeline(&loaded, &Overrides::default(), None).unwrap();
    scene_to_rrd_bytes(&scene, &RecordingIds::for_scenario("fresh", 0)).unwrap()
}

fn messages(bytes: &[u8]) -> Vec<LogMsg> {
    DecoderApp::decode_eager(std::io::Cursor::new(bytes))
        .unwrap()
        .map(Result::unwrap)
        .collect()
}

fn db_of(bytes: &[u8]) -> EntityDb {
    let chunks = rrd::recording_chunks(bytes);
    let store_id = messages(bytes)
        .iter()
        .find(|m| m.store_id().kind() == StoreKind::Recording)
        .map(|m| m.store_id().clone())
        .unwrap();
    let mut db = EntityDb::new(store_id);
    for chunk in chunks {
        db.add_chunk(&Arc::new(chunk)).unwrap();
    }
    db
}

fn entities(db: &EntityDb) -> BTreeSet<EntityPath> {
    db.storage_engine().store().all_entities_sorted()
}

/// What a view shows of `path` at `step` (`None`: before any step): every component's
/// latest-at value, clears applied (the clear's own component left out).
fn shown(db: &EntityDb, path: &EntityPath, step: Option<i64>) -> Vec<(String, ArrayRef)> {
    let components: Vec<_> = db
        .storage_engine()
        .store()
        .schema()
        .all_components_for_entity(path)
        .map(|set| set.iter().copied().collect())
        .unwrap_or_default();
    let clear = rerun::Clear::descriptor_is_recursive().component;
    let at = step.map_or(TimeInt::MIN, TimeInt::new_temporal);
    let query = LatestAtQuery::new("step".into(), at);
    let results = db.latest_at(&query, path, components.iter().copied());
    let mut out: Vec<(String, ArrayRef)> = components
        .iter()
        .filter(|c| **c != clear)
        .filter_map(|c| results.component_batch_raw(*c).map(|a| (c.to_string(), a)))
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Panics unless the 3-D world and the text look the same in both recordings at every step
/// up to `last_step` (and before the first).
fn assert_same_view(live: &[u8], fresh: &[u8], last_step: i64) {
    let (a, b) = (db_of(live), db_of(fresh));
    let world = |p: &EntityPath| {
        let s = p.to_string();
        s.starts_with("/world") || s.starts_with("/description")
    };
    let paths: BTreeSet<EntityPath> = entities(&a)
        .into_iter()
        .chain(entities(&b))
        .filter(world)
        .collect();
    assert!(!paths.is_empty());
    for step in std::iter::once(None).chain((0..=last_step + 1).map(Some)) {
        for path in &paths {
            let (x, y) = (shown(&a, path, step), shown(&b, path, step));
            if x != y {
                let names =
                    |v: &[(String, ArrayRef)]| v.iter().map(|c| c.0.clone()).collect::<Vec<_>>();
                let differ: Vec<&String> = x
                    .iter()
                    .zip(&y)
                    .filter(|(p, q)| p != q)
                    .map(|(p, _)| &p.0)
                    .collect();
                panic!(
                    "{path} at step {step:?}: live shows {:?}, a fresh recording {:?}; values differ in {differ:?}",
                    names(&x),
                    names(&y),
                );
            }
        }
    }
}

fn recordings(bytes: &[u8]) -> BTreeSet<String> {
    messages(bytes)
        .iter()
        .filter(|m| m.store_id().kind() == StoreKind::Recording)
        .map(|m| format!("{:?}", m.store_id()))
        .collect()
}

#[test]
fn a_sigma_change_re_streams_in_place_like_a_fresh_recording() {
    let (live, _) = start("camera_on_robot", 2000);
    let before = fresh(&live);
    let generation = live.apply(&edit("pose[0].cov.std_deg[2]", 40.0)).unwrap();
    assert_eq!(generation, 1);
    let status = live.wait_done(1, WAIT);
    assert_eq!((status.shown, status.done), (Some(1), true), "{status:?}");
    assert!(
        live.with_doc(|d| d.text())
            .contains("std_deg = [0.05, 0.05, 40.0]")
    );
    let after = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    assert_same_view(&bytes, &after, 0);
    // The check can fail: the picture did change.
    let old = db_of(&before);
    let new = db_of(&after);
    let cloud: EntityPath = "world/map_from_camera/monte_carlo/cloud".into();
    assert_ne!(shown(&old, &cloud, None), shown(&new, &cloud, None));
    assert_eq!(recordings(&bytes).len(), 1, "one recording");
}

#[test]
fn a_bad_value_is_refused_with_its_field_and_the_picture_stays() {
    let (live, _) = start("camera_on_robot", 2000);
    let err = live
        .apply(&edit("pose[0].cov.std_deg[2]", -5.0))
        .unwrap_err();
    assert_eq!(err.field().as_deref(), Some("pose[0].cov"), "{err}");
    assert!(err.to_string().contains("negative"), "{err}");
    let status = live.status();
    assert_eq!(
        (status.generation, status.shown),
        (0, Some(0)),
        "{status:?}"
    );
    let expected = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    assert_same_view(&bytes, &expected, 0);
}

#[test]
fn fewer_steps_and_hidden_clouds_leave_nothing_stale() {
    let (live, first) = start("barfoot_compounding", 1024);
    // 100 compounds: a preview with fewer steps kept came first, then the full picture.
    let (preview, full) = (
        first.first_picture_ms.unwrap(),
        first.final_picture_ms.unwrap(),
    );
    assert!(preview < full, "{first:?}");
    live.apply(&edit("operation[0].steps", 30.0)).unwrap();
    live.apply(&Edit {
        id: "draw.clouds".into(),
        value: EditValue::Toggle(false),
    })
    .unwrap();
    let status = live.wait_done(2, WAIT);
    assert_eq!((status.shown, status.done), (Some(2), true), "{status:?}");
    let expected = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    assert_same_view(&bytes, &expected, 101);
    assert_eq!(recordings(&bytes).len(), 1, "one recording");
}

#[test]
fn reset_returns_to_the_files_picture() {
    let (live, _) = start("na568_se2_odometry", 1024);
    live.apply(&edit("operation[0].noise.std[2]", 0.3)).unwrap();
    live.apply(&edit("operation[0].controls[6][0]", 1.2))
        .unwrap();
    let generation = live.reset().unwrap();
    let status = live.wait_done(generation, WAIT);
    assert_eq!(status.shown, Some(generation), "{status:?}");
    let text = live.with_doc(|d| d.text());
    let file = posecov::input::scenario::bundled::find("na568_se2_odometry").unwrap();
    assert_eq!(text, file.text, "reset returns to the file's text");
    let expected = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    assert_same_view(&bytes, &expected, 10);
}

/// The blueprint stores sent into a recording: one per layout.
fn layouts(bytes: &[u8]) -> Vec<String> {
    let mut ids: Vec<String> = Vec::new();
    for m in messages(bytes) {
        let id = format!("{:?}", m.store_id());
        if m.store_id().kind() == StoreKind::Blueprint && !ids.contains(&id) {
            ids.push(id);
        }
    }
    ids
}

/// The space origins of the plot views in the recording's blueprints, in the order sent.
fn plot_origins(bytes: &[u8]) -> Vec<String> {
    messages(bytes)
        .iter()
        .filter_map(|m| match m {
            LogMsg::ArrowMsg(store, arrow) if store.kind() == StoreKind::Blueprint => {
                rerun::log::Chunk::from_arrow_msg(arrow).ok()
            }
            _ => None,
        })
        .filter_map(|c| {
            let origin = ViewBlueprint::descriptor_space_origin().component;
            let array = c.component_batch_raw(origin, 0)?.ok()?;
            let text = array
                .as_any()
                .downcast_ref::<StringArray>()?
                .value(0)
                .to_owned();
            text.trim_start_matches('/')
                .strip_prefix("plots/")
                .map(str::to_owned)
        })
        .collect()
}

/// The plots: each generation's series go under `plots/<plot>/g<N>/`, inside the plot view;
/// the series of earlier generations get a static, empty `Scalars` (which shadows their
/// points in every query: Rerun's plots ignore clears); the layout is sent once, so the
/// viewer keeps its camera.
#[test]
fn plots_show_the_newest_generation_only_and_the_layout_stays() {
    let (live, _) = start("na568_se2_odometry", 1024);
    live.apply(&edit("operation[0].noise.std[2]", 0.3)).unwrap();
    let status = live.wait_done(1, WAIT);
    assert_eq!(status.shown, Some(1), "{status:?}");
    let expected = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    if let Some(path) = std::env::var_os("POSECOV_LIVE_RRD") {
        std::fs::write(path, &bytes).unwrap();
    }
    let chunks = rrd::recording_chunks(&bytes);
    // The newest generation's series hold exactly the fresh recording's points.
    let series = |chunks: &[rerun::log::Chunk], prefix: &str| -> Vec<(String, usize)> {
        let mut v: Vec<(String, usize)> = chunks
            .iter()
            .filter_map(|c| {
                let p = c.entity_path().to_string();
                let rest = p.strip_prefix("/plots/")?;
                let (plot, tail) = rest.split_once('/')?;
                let tail = tail.strip_prefix(prefix)?;
                (c.num_rows() > 1).then(|| (format!("{plot}/{tail}"), c.num_rows()))
            })
            .collect();
        v.sort();
        v
    };
    let newest = series(&chunks, "g1/");
    assert!(!newest.is_empty());
    assert_eq!(newest, series(&rrd::recording_chunks(&expected), ""));
    // Generation 0's series are shadowed: a static chunk with an empty Scalars each.
    let scalars = rerun::Scalars::descriptor_scalars().component;
    let shadowed: BTreeSet<String> = chunks
        .iter()
        .filter(|c| c.is_static() && c.entity_path().to_string().contains("/g0/"))
        .filter(|c| {
            c.component_batch_raw(scalars, 0)
                .and_then(Result::ok)
                .is_some_and(|a| a.is_empty())
        })
        .map(|c| c.entity_path().to_string().replace("/g0/", "/"))
        .collect();
    let old: BTreeSet<String> = series(&chunks, "g0/")
        .into_iter()
        .map(|(p, _)| format!("/plots/{p}"))
        .collect();
    assert!(!old.is_empty());
    assert_eq!(shadowed, old);
    // The newest generation is not shadowed.
    assert!(!chunks.iter().any(|c| c.is_static()
        && c.entity_path().to_string().contains("/g1/")
        && c.component_batch_raw(scalars, 0).is_some()));
    // One layout, its plot views rooted at the plot (all generations inside).
    assert_eq!(layouts(&bytes).len(), 1, "the layout is sent once");
    let origins = plot_origins(&bytes);
    assert!(
        !origins.is_empty() && origins.iter().all(|o| !o.contains('/')),
        "{origins:?}"
    );
}

/// The layout is sent again when what the views are changes (a method switched off removes
/// its view) and on "Frame" (cameras fitted to the current picture), not for a change of
/// values (the previous test); the picture stays the fresh one throughout.
#[test]
fn views_changing_and_frame_send_the_layout_again() {
    let (live, _) = start("camera_on_robot", 1024);
    live.apply(&edit("pose[0].cov.std_deg[2]", 60.0)).unwrap();
    assert_eq!(live.wait_done(1, WAIT).shown, Some(1));
    let framed = live.reframe();
    assert_eq!(live.wait_done(framed, WAIT).shown, Some(framed));
    live.apply(&Edit {
        id: "scenario.methods.sigma_points".into(),
        value: EditValue::Toggle(false),
    })
    .unwrap();
    let status = live.wait_done(framed + 1, WAIT);
    assert_eq!(status.shown, Some(framed + 1), "{status:?}");
    let expected = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    assert_eq!(layouts(&bytes).len(), 3, "opened, framed, views changed");
    assert_same_view(&bytes, &expected, 0);
}

/// A frame drawn again at the same position is overwritten, never cleared: the viewer
/// resolves a cleared transform to the identity even when a newer one follows at that time
/// (the robot's axes jumped to the origin). Clears stay for what is no longer drawn.
#[test]
fn frames_are_overwritten_not_cleared() {
    let (live, _) = start("na568_se2_odometry", 1024);
    live.apply(&edit("operation[0].noise.std[2]", 0.3)).unwrap();
    assert_eq!(live.wait_done(1, WAIT).shown, Some(1));
    let expected = fresh(&live);
    let bytes = live.finish().unwrap().unwrap();
    let chunks = rrd::recording_chunks(&bytes);
    let has = |c: &rerun::log::Chunk, component| c.component_batch_raw(component, 0).is_some();
    let translation = rerun::Transform3D::descriptor_translation().component;
    let clear = rerun::Clear::descriptor_is_recursive().component;
    let framed: BTreeSet<String> = chunks
        .iter()
        .filter(|c| has(c, translation))
        .map(|c| c.entity_path().to_string())
        .collect();
    assert!(!framed.is_empty());
    let cleared: Vec<String> = chunks
        .iter()
        .filter(|c| has(c, clear) && framed.contains(&c.entity_path().to_string()))
        .map(|c| c.entity_path().to_string())
        .collect();
    assert!(cleared.is_empty(), "frames cleared: {cleared:?}");
    // Other entities were cleared (the mechanism still runs), and the view is the fresh one.
    assert!(chunks.iter().any(|c| has(c, clear)));
    assert_same_view(&bytes, &expected, 8);
}

/// The preview's Monte Carlo particles are exactly the full run's first draws, pose by pose
/// and step by step, in every bundled scenario that shows a preview with fewer samples: the
/// full picture refines the preview, it does not replace it with another cloud.
#[test]
fn the_previews_particles_are_the_full_runs_first_draws() {
    use posecov::app::live::{PREVIEW_SAMPLES, passes};
    use posecov::app::{evaluate, load, resolve};
    use posecov::eval::AnyEvaluation;
    use posecov::input::scenario::bundled::BUNDLED;
    use posecov::lie::LieGroup as _;

    /// (name, step) → particles, each as its matrix in `{:?}` (every f64 in full: Rust's
    /// `Debug` prints the shortest text that reads back to the same bits).
    fn particles(
        e: &AnyEvaluation,
    ) -> std::collections::BTreeMap<(String, Option<u64>), Vec<String>> {
        posecov::with_evaluation!(e, e => e
            .nodes
            .iter()
            .filter_map(|n| {
                let p = n.particles.as_ref()?;
                let text = p.iter().map(|x| format!("{:?}", x.to_matrix())).collect();
                Some(((n.name.clone(), n.step), text))
            })
            .collect())
    }
    let mut checked = Vec::new();
    for b in BUNDLED {
        let loaded = load(b.name).unwrap();
        let all = passes(&loaded, &Overrides::default()).unwrap();
        let [preview, full] = all.as_slice() else {
            continue;
        };
        if preview.samples != Some(PREVIEW_SAMPLES) {
            continue;
        }
        let run = |o: &Overrides| {
            let settings = resolve(&loaded.input, o, None).unwrap();
            particles(&evaluate(&loaded, &settings.eval).unwrap())
        };
        let (short, long) = (run(preview), run(full));
        let mut shared = 0;
        for (key, draws) in &short {
            let Some(all_draws) = long.get(key) else {
                continue;
            };
            assert_eq!(draws.len() as u64, PREVIEW_SAMPLES, "{} {key:?}", b.name);
            assert!(all_draws.len() > draws.len(), "{} {key:?}", b.name);
            assert!(
                all_draws[..draws.len()] == draws[..],
                "{} {key:?}: the preview drew other particles than the full run's first",
                b.name
            );
            shared += 1;
        }
        assert!(
            shared > 0,
            "{}: no pose with particles in both passes",
            b.name
        );
        checked.push(b.name);
    }
    // The scenarios large enough for a preview (BENCHMARKS §6).
    assert_eq!(
        checked,
        [
            "vector_space_vs_lie",
            "barfoot_compounding",
            "diff_drive_banana"
        ]
    );
}

/// While a slider is dragged faster than pictures are made (here an edit every 4 ms, each
/// picture of na568_se2_odometry taking longer), pictures keep coming, each of a newer value:
/// a change's first picture is finished, not cancelled by the next mouse event (before, no
/// picture came until the drag stopped).
#[test]
fn pictures_keep_coming_while_a_slider_is_dragged() {
    let (live, _) = start("na568_se2_odometry", 2000);
    let id = "operation[0].noise.std[2]";
    let start = std::time::Instant::now();
    let mut shown = BTreeSet::new();
    let mut last = 0;
    let mut k = 0u32;
    while shown.len() < 3 {
        assert!(
            start.elapsed() < WAIT,
            "no new picture while dragging: {shown:?} after {k} edits"
        );
        k += 1;
        last = live
            .apply(&edit(id, 0.05 + 0.001 * f64::from(k % 50)))
            .unwrap();
        std::thread::sleep(Duration::from_millis(4));
        if let Some(g) = live.status().shown.filter(|&g| g > 0) {
            shown.insert(g);
        }
    }
    let status = live.wait_done(last, WAIT);
    assert_eq!(
        (status.shown, status.done),
        (Some(last), true),
        "{status:?}"
    );
    assert_eq!(recordings(&live.finish().unwrap().unwrap()).len(), 1);
}
