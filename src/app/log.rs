//! Robot logs (ROS 1 bags, MCAP) through the application: read one streamed with a progress
//! bar and Ctrl-C, evaluate, draw (`run`, called by [`super::run::Run::start`]); the
//! printing commands' text and JSON.
//!
//! ```
//! use posecov::app::{Overrides, log, run::{Run, open}};
//! let Run::Log(run) = Run::start(open("covariance_health").unwrap(), &Overrides::default(), posecov::app::run::RunOptions::shown()).unwrap() else { panic!() };
//! assert_eq!(run.summary.topics.len(), 3);
//! let json = log::report_json("covariance_health", &run);
//! assert_eq!(json["topics"][0]["health"]["not_psd"]["count"], 1);
//! ```

mod frames;
mod growing;
mod nees;
mod sensors;

pub(crate) use growing::Growing;

use indicatif::{ProgressBar, ProgressStyle};

use super::AppError;
use super::checked::Checked;
use super::run::RunOptions;
use super::settings::LogSettings;
use crate::draw::log::{LogDrawSettings, description, draw_log, issue_sentence, issue_word};
use crate::eval::log::{LogEvaluation, evaluate_log};
use crate::input::log::{LogOptions, bundled, read_located_growing};
use crate::input::{About, Format, InputError, Located, Place};
use crate::interop::RosReading;
use crate::plan::log::LogObserver;
use crate::plan::log::{Class, Issue, LogSummary, StreamNotes};
use crate::scene::{Origin, Scene, SceneError, Timing};

/// A read, evaluated and drawn log.
#[derive(Debug, Clone)]
pub struct LogRun {
    /// Where it was read from, and its format.
    pub located: Located,
    /// The settings it ran with.
    pub settings: LogSettings,
    /// What was read.
    pub summary: LogSummary,
    /// Its numbers.
    pub evaluation: LogEvaluation,
    /// Its scene (validated); only its title and description when the run was not drawn
    /// (`report`, which prints numbers).
    pub scene: Scene,
}

/// Reads (streamed, a progress bar on a terminal when [`RunOptions::progress`];
/// [`RunOptions::cancel`] stops the read and keeps what was read), evaluates and, when
/// [`RunOptions::draw`], draws a log (`report` and `check` print numbers and findings: their
/// scene keeps the title and description only).
///
/// See the [module docs](self) for an example.
pub(super) fn run(
    located: &Located,
    settings: &LogSettings,
    options: &RunOptions,
    growing: Option<&dyn Growing>,
) -> Result<LogRun, AppError> {
    let (cancel, bar, drawn) = (options.cancel.as_deref(), options.progress, options.draw);
    let file = located.origin();
    if located.format == Format::OvEval && settings.eval.reading != RosReading::Tf2 {
        // Its blocks' frames are ov_eval's, stored in tf2's layout (CONVENTIONS §12).
        return Err(AppError::Input(InputError::Format {
            file,
            message: "--ros-reading applies to ROS messages; an ov_eval trajectory says its \
                      own frames (position in the global frame, rotation in the body)"
                .to_owned(),
        }));
    }
    let reference = match &settings.reference {
        Some(r) => Some(nees::SharedPrepared::new(nees::prepare(
            r,
            settings.eval.reading,
            settings.read.every,
        )?)),
        None => None,
    };
    let mut options = settings.read.clone();
    options.reference = reference.as_ref().and_then(nees::in_log);
    let growing = growing.filter(|_| drawn);
    // Every message to NEES (the growing view reads its NEES so far) and the growing view.
    let nees = reference.as_ref().map(nees::Forward);
    let watched = nees.is_some() || growing.is_some();
    let mut observed = growing::Observer { nees, growing };
    let observer = watched.then_some(&mut observed as &mut dyn LogObserver);
    let title = match &located.place {
        Place::Bundled(e) => bundled::find(e.name).map_or(e.name, |l| l.title).to_owned(),
        Place::File(_) | Place::Live(_) => file.clone(),
    };
    let draw = LogDrawSettings {
        about: About {
            title,
            description: String::new(),
            source: file.clone(),
        },
        confidence: settings.confidence,
        axis_length: None,
    };
    // What the stream has given so far, evaluated and drawn as the end's summary is, with the
    // NEES of the estimates matched so far; an undrawable one is left out. It runs on the
    // read's thread that draws (reading never waits for it).
    let mut grow = |mut plan: LogSummary| {
        if let Some(growing) = growing {
            let mut evaluation = evaluate_log(&mut plan, &settings.eval);
            if let Some(reference) = &reference {
                evaluation = evaluation.with_consistency(nees::so_far(reference, &plan));
            }
            let summary = describe(located, &plan, &evaluation, settings.confidence);
            let scene = draw_log(&evaluation, &draw, &summary);
            if scene.validate().is_ok() {
                growing.picture(&scene);
            }
        }
    };
    let grow = growing
        .is_some()
        .then_some(&mut grow as &mut (dyn FnMut(LogSummary) + Send));
    let mut plan = read(located, &options, cancel, bar, observer, grow)?;
    let mut evaluation = evaluate_log(&mut plan, &settings.eval);
    if let Some(reference) = reference {
        let results = nees::finish(nees::into_prepared(reference), &plan, &file)?;
        evaluation = evaluation.with_consistency(results);
    }
    let summary = describe(located, &plan, &evaluation, settings.confidence);
    let scene = if drawn {
        let scene = draw_log(&evaluation, &draw, &summary);
        scene
            .validate()
            .map_err(|e| undrawable(located, &scene, e))?;
        scene
    } else {
        Scene::new(draw.about.title, summary)
    };
    Ok(LogRun {
        located: located.clone(),
        settings: settings.clone(),
        summary: plan,
        evaluation,
        scene,
    })
}

/// The text panel's description of a log read (so far).
fn describe(
    located: &Located,
    plan: &LogSummary,
    evaluation: &LogEvaluation,
    confidence: crate::uncertain::Confidence,
) -> String {
    let kind = match &located.place {
        // Its channels are MCAP channels, but it is no file.
        Place::Live(_) => "Live stream (Foxglove WebSocket)",
        _ => located.format.name(),
    };
    description(plan, kind, evaluation, confidence)
}

/// A log's scene that cannot be drawn (a number beyond what the viewer holds, `f32`, that
/// evaluation let through), located in the log's words from the item's typed origin
/// ([`SceneItem::origin`](crate::scene::SceneItem::origin)): the topic and the message it
/// shows (a static overview names the topic only).
fn undrawable(located: &Located, scene: &Scene, error: SceneError) -> AppError {
    let item = scene.items.iter().find(|i| i.validate().is_err());
    let place = match item.map(|i| (i.origin.as_ref(), i.timing)) {
        Some((
            Some(Origin::Topic {
                topic,
                message: Some(m),
            }),
            _,
        )) => format!(
            "topic {topic}, message {} (stamp {:.3} s)",
            m.index,
            stamp_seconds(m.stamp_ns)
        ),
        Some((Some(Origin::Topic { topic, .. }), Timing::Stamp(ns))) => {
            format!("topic {topic}, stamp {:.3} s", stamp_seconds(ns))
        }
        Some((Some(Origin::Topic { topic, .. }), _)) => {
            format!("topic {topic} (its overview of every drawn message)")
        }
        Some((Some(Origin::Node(_)) | None, _)) | None => "the log's drawing".to_owned(),
    };
    AppError::Input(InputError::In {
        file: located.origin(),
        place,
        message: format!("a value beyond what the viewer can draw (f32): {error}"),
    })
}

fn read(
    located: &Located,
    options: &LogOptions,
    cancel: Option<&std::sync::atomic::AtomicBool>,
    shown: bool,
    observer: Option<&mut dyn LogObserver>,
    grow: Option<&mut (dyn FnMut(LogSummary) + Send)>,
) -> Result<LogSummary, AppError> {
    let file = located.origin();
    let bar = if shown {
        ProgressBar::new(0)
    } else {
        ProgressBar::hidden()
    }
    .with_message(format!("reading {file}"));
    bar.set_style(
        ProgressStyle::with_template("{msg} {wide_bar} {percent} % ({elapsed}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let plan = read_located_growing(
        located,
        options,
        &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        },
        cancel,
        observer,
        grow,
    );
    bar.finish_and_clear();
    let plan = plan?;
    if plan.cancelled {
        eprintln!(
            "Interrupted: read {} messages of {file}; drawing those.",
            plan.messages_total,
        );
    }
    Ok(plan)
}

/// A stamp in seconds to the microsecond, without float noise: the integer microseconds
/// (rounded half away from zero) divided once, so that 108 764 000 000 ns prints as
/// `108.764`, not `108.76400000000001`.
///
/// ```
/// use posecov::app::log::stamp_seconds;
/// assert_eq!(serde_json::json!(stamp_seconds(108_764_000_000)).to_string(), "108.764");
/// assert_eq!(stamp_seconds(1_499_999), 0.0015);
/// assert_eq!(stamp_seconds(-1_500), -0.000002);
/// ```
pub fn stamp_seconds(ns: i64) -> f64 {
    let whole = ns / 1000;
    let rest = ns % 1000;
    let us = whole + i64::from(rest >= 500) - i64::from(rest <= -500);
    us as f64 / 1e6
}

/// The units of a log report's numbers (`units` in `report --json`).
const LOG_UNITS: [(&str, &str); 7] = [
    ("stamps", "s (suffix _s), to the microsecond"),
    ("sigma_position", "m (sigma.x, .y, .z: parent frame's axes)"),
    ("sigma_rotation", "rad (sigma.roll, .pitch, .yaw)"),
    ("position_trace", "m^2 (suffix _m2)"),
    ("distance", "m (suffix _m)"),
    (
        "eigenvalue",
        "the covariance's own units (m^2, m·rad, rad^2)",
    ),
    (
        "twist_sigma",
        "m/s (vx, vy, vz), rad/s (wx, wy, wz), child frame",
    ),
];

/// A topic's σ statistics per ROS axis with their units; an axis no message estimates is
/// absent.
fn sigma_json(e: &crate::eval::log::TopicEvaluation) -> serde_json::Value {
    let axes = crate::plan::log::ROS_AXES;
    let map: serde_json::Map<String, serde_json::Value> = axes
        .iter()
        .zip(&e.sigma)
        .enumerate()
        .filter_map(|(i, (axis, s))| {
            let s = s.as_ref()?;
            let mut value = serde_json::to_value(s).ok()?;
            value["unit"] = serde_json::json!(if i < 3 { "m" } else { "rad" });
            Some(((*axis).to_owned(), value))
        })
        .collect();
    serde_json::Value::Object(map)
}

/// The JSON report of a log: per topic its type, frames, counts, stamps (s), planar or 3-D
/// with the χ² dimensions, drawn messages, and health (per issue the count and first stamp in
/// seconds); the skipped topics. Keys are stable (see docs/guide/json-report.md).
///
/// See the [module docs](self) for an example.
pub fn report_json(name: &str, run: &LogRun) -> serde_json::Value {
    let plan = &run.summary;
    let topics: Vec<serde_json::Value> = plan
        .topics
        .iter()
        .zip(&run.evaluation.topics)
        .map(|(t, e)| {
            let health: serde_json::Map<String, serde_json::Value> = t
                .health
                .issues
                .iter()
                .map(|(issue, c)| {
                    (
                        issue.name().to_owned(),
                        serde_json::json!({
                            "class": t.class(*issue),
                            "count": c.count,
                            "first_stamp_s": stamp_seconds(c.first_stamp_ns),
                            "first_message": c.first_index,
                            "word": issue_word(*issue),
                            "sentence": issue_sentence(*issue, t),
                        }),
                    )
                })
                .collect();
            serde_json::json!({
                "name": t.name,
                "type": t.kind.ros1_name(),
                "frame_id": t.frame_id,
                "child_frame_id": t.child_frame_id,
                "messages": t.count,
                "stamps": stamps_json(t.stamp_range, t.stamps_from_log_time, t.stamps_out_of_order),
                "planar": t.group.is_planar(),
                "position_dof": e.group.position_dims(),
                "pose_dof": e.group.dof(),
                "drawn": e.poses.len(),
                "drawn_invalid": e.poses.iter().filter(|p| !p.state.is_drawable()).count(),
                "every": t.stride,
                "dead_reckoned": t.dead_reckoned(),
                "health": health,
                "constant_stretch": t.health.constant.map(|c| serde_json::json!({
                    "messages": c.messages,
                    "first_message": c.first_index,
                    "first_stamp_s": stamp_seconds(c.first_stamp_ns),
                    "last_stamp_s": stamp_seconds(c.last_stamp_ns),
                    "distance_m": c.distance_m,
                })),
                "min_eigenvalue": t.health.min_eigenvalue,
                "twist_sigma_last": t.twist_sigmas().map(|s| {
                    ["vx", "vy", "vz", "wx", "wy", "wz"]
                        .iter()
                        .zip(s)
                        .map(|(k, v)| ((*k).to_owned(), serde_json::json!(v)))
                        .collect::<serde_json::Map<_, _>>()
                }),
                "sigma": sigma_json(e),
                "position_trace": {
                    "stamps_s": e.series.iter().filter(|p| p.position_trace.is_some()).map(|p| stamp_seconds(p.stamp_ns)).collect::<Vec<_>>(),
                    "values_m2": e.series.iter().filter_map(|p| p.position_trace).collect::<Vec<_>>(),
                },
                "ros_reading": run.evaluation.reading,
                "ros_readings_apart": e.reading_difference,
                "consistency": e.consistency.as_ref().map(nees::consistency_json),
                "frame_join": frames::join_json(e),
            })
        })
        .collect();
    serde_json::json!({
        "schema_version": super::REPORT_SCHEMA_VERSION,
        "posecov_version": super::POSECOV_VERSION,
        "units": LOG_UNITS.iter().map(|(k, u)| ((*k).to_owned(), serde_json::json!(u))).collect::<serde_json::Map<_, _>>(),
        "scenario": name,
        "format": run.located.format,
        "meta": {
            "title": run.scene.title,
            "seed": run.settings.eval.seed,
            "samples": run.settings.eval.cloud_samples,
            "confidence": run.settings.confidence,
            "ros_reading": run.evaluation.reading,
            "messages": plan.messages_total,
            "cancelled": plan.cancelled,
            "cut_short": plan.cut,
            "stream": plan.stream,
        },
        "topics": topics,
        "sensors": sensors::sensors_json(plan, &run.evaluation.sensors),
        "frames": frames::frames_json(&plan.tf, &run.evaluation),
        "skipped": plan.skipped,
        "not_selected": plan.not_selected,
    })
}

/// The text report: the summary the text panel shows.
///
/// ```
/// use posecov::app::{Overrides, log, run::{Run, open}};
/// let Run::Log(run) = Run::start(open("jackal_odometry").unwrap(), &Overrides::default(), posecov::app::run::RunOptions::shown()).unwrap() else { panic!() };
/// let text = log::report_text("jackal_odometry", &run);
/// assert!(text.contains("note `placeholder` × 3060, first at 47.584 s (message 0)"), "{text}");
/// ```
pub fn report_text(name: &str, run: &LogRun) -> String {
    format!(
        "{name} — {} ({:.1} % regions, seed {})\n\n{}",
        run.scene.title,
        100.0 * run.settings.confidence.get(),
        run.settings.eval.seed,
        run.scene.description_markdown
    )
}

/// What `check` says of a log: one line for stdout (topics, messages, drawn items, defects,
/// notes and the defect kinds found but allowed) and, for each topic with a defect not in
/// `allow`, its first defect on a line for stderr in the file's terms (file, topic, message,
/// stamp), with its count and `--allow` name; a line for each defect of the log's `/tf` not in
/// `allow` (`tf_cycle`, `tf_several_parents`) and for a log cut short (never allowed).
///
/// ```
/// use posecov::app::{Overrides, log, run::{Run, open}};
/// use posecov::plan::log::Issue;
/// let Run::Log(run) = Run::start(open("covariance_health").unwrap(), &Overrides::default(), posecov::app::run::RunOptions::shown()).unwrap() else { panic!() };
/// let checked = log::check(&run, "covariance_health", &[]);
/// assert!(checked.line.starts_with("covariance_health: defects on 1 of 3 pose topic(s)"), "{}", checked.line);
/// assert!(checked.defects[0].starts_with("health_cases.mcap (bundled): topic /amcl_pose, message 1 (stamp 101.000 s): all_zero"), "{:?}", checked.defects);
/// let allow: Vec<Issue> = Issue::ALL.to_vec();
/// let checked = log::check(&run, "covariance_health", &allow);
/// assert!(checked.defects.is_empty());
/// assert!(checked.line.contains(", defects allowed: "), "{}", checked.line);
/// ```
pub fn check(run: &LogRun, name: &str, allow: &[Issue]) -> Checked {
    let plan = &run.summary;
    let file = run.located.origin();
    let mut defects = Vec::new();
    let mut notes = 0;
    // The defect kinds found and accepted on purpose: said, so an allowed defect is not hidden.
    let mut allowed = Vec::new();
    for t in &plan.topics {
        notes += t
            .health
            .issues
            .iter()
            .filter(|(i, _)| t.class(**i) == Class::Note)
            .count();
        for (issue, _) in t.defects().filter(|(i, _)| allow.contains(i)) {
            if !allowed.contains(&issue) {
                allowed.push(issue);
            }
        }
        let mut found: Vec<_> = t.defects().filter(|(i, _)| !allow.contains(i)).collect();
        found.sort_by_key(|(_, c)| (c.first_index, c.first_stamp_ns));
        if let Some((issue, c)) = found.first() {
            let others = match found.len() - 1 {
                0 => String::new(),
                n => format!("; {n} more defect kind(s) on this topic, see `posecov report`"),
            };
            defects.push(format!(
                "{file}: topic {}, message {} (stamp {:.3} s): {} — {} ({} message(s); `--allow {}` accepts it{others})",
                t.name,
                c.first_index,
                stamp_seconds(c.first_stamp_ns),
                issue.name(),
                issue_sentence(*issue, t),
                c.count,
                issue.name(),
            ));
        }
    }
    let pose_defects = defects.len();
    let (sensor_lines, sensor_notes) = sensors::sensor_defects(&file, plan, allow, &mut allowed);
    let sensor_defects = sensor_lines.len();
    defects.extend(sensor_lines);
    notes += sensor_notes;
    if let Some(cut) = &plan.cut {
        // Not a covariance defect, but the log cannot be trusted whole: CI must see it.
        defects.push(format!(
            "{file}: the log stops early, {}; read its first {} whole chunk(s), up to byte {} of \
             its {}: every finding here is from them",
            cut.reason, cut.chunks_read, cut.at_byte, cut.file_bytes
        ));
    }
    let (tf_allowed, tf_defects) = frames::tf_defects(&file, &run.evaluation, allow);
    allowed.extend(tf_allowed);
    let log_defects = usize::from(plan.cut.is_some()) + tf_defects.len();
    defects.extend(tf_defects);
    let facts = format!(
        "{} messages, {} drawn items{}{}",
        plan.messages_total,
        run.scene.items.len(),
        match notes {
            0 => String::new(),
            n => format!(", {n} kind(s) of note (see `posecov report`)"),
        },
        match allowed.len() {
            0 => String::new(),
            _ => format!(
                ", defects allowed: {}",
                allowed
                    .iter()
                    .map(|i| i.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    );
    let sensors = match plan.sensors.len() {
        0 => String::new(),
        n => format!(", {n} sensor topic(s)"),
    };
    let sensors_defects = match plan.sensors.len() {
        0 => String::new(),
        n => format!(" and {sensor_defects} of {n} sensor topic(s)"),
    };
    let line = if defects.is_empty() {
        format!(
            "{name}: ok ({} pose topic(s){sensors}, {facts})",
            plan.topics.len()
        )
    } else {
        format!(
            "{name}: defects on {pose_defects} of {} pose topic(s){sensors_defects}{} ({facts}; the first of each on stderr)",
            plan.topics.len(),
            match (
                plan.cut.is_some(),
                log_defects > usize::from(plan.cut.is_some())
            ) {
                (true, false) => ", the log stops early",
                (false, true) => ", its /tf is broken",
                (true, true) => ", the log stops early, its /tf is broken",
                (false, false) => "",
            }
        )
    };
    let notes = plan
        .stream
        .as_ref()
        .map(StreamNotes::sentences)
        .unwrap_or_default();
    Checked {
        line,
        defects,
        notes,
    }
}

/// A topic's `stamps` in `report --json`: first and last stamp (s), and how many messages had
/// their log time used or came out of order. One shape for pose and sensor topics.
pub(super) fn stamps_json(
    range: Option<crate::plan::log::StampRange>,
    from_log_time: u64,
    out_of_order: u64,
) -> serde_json::Value {
    serde_json::json!({
        "first_s": range.map(|r| stamp_seconds(r.first_ns)),
        "last_s": range.map(|r| stamp_seconds(r.last_ns)),
        "from_log_time": from_log_time,
        "out_of_order": out_of_order,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::{
        Overrides,
        run::{Run, open},
    };
    use crate::scene::{Color, ItemKind, LineStrips, Origin, SceneItem, paths};

    #[test]
    fn an_undrawable_value_is_located_in_the_log() {
        let Ok(Run::Log(run)) = Run::start(
            open("covariance_health").unwrap(),
            &Overrides::default(),
            crate::app::run::RunOptions::shown(),
        ) else {
            panic!("a log")
        };
        let topic = &run.evaluation.topics[1];
        let pose = &topic.poses[2];
        let mut scene = run.scene.clone();
        let mut item = SceneItem::new(
            paths::child(&paths::topic(&topic.name), "meaning/banana_outline"),
            Timing::Stamp(pose.stamp_ns),
            ItemKind::LineStrips(LineStrips {
                strips: vec![vec![[0.0; 3], [1e39, 0.0, 0.0]]],
                color: Color::rgb(0, 0, 0),
                radius: 0.01,
            }),
        );
        // The origin draw stamps on every item of a message (what the place is read from).
        let drawn = run.scene.items.iter().find(|i| {
            matches!(&i.origin, Some(Origin::Topic { topic: t, message: Some(m) })
                if *t == topic.name && m.index == pose.index)
        });
        item.origin = drawn.expect("the message is drawn").origin.clone();
        scene.items.push(item);
        let error = scene.validate().unwrap_err();
        let e = undrawable(&run.located, &scene, error).to_string();
        let expected = format!(
            "health_cases.mcap (bundled): topic {}, message {} (stamp {:.3} s): a value beyond what the viewer can draw (f32): ",
            topic.name,
            pose.index,
            stamp_seconds(pose.stamp_ns)
        );
        assert!(e.starts_with(&expected), "{e}");
    }
}
