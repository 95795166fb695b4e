//! Robot logs (ROS 1 bags, MCAP) through the application: read one streamed with a progress
//! bar and Ctrl-C, evaluate, draw ([`run`], called by [`super::run::Run::start`]); the
//! printing commands' text and JSON.
//!
//! ```
//! use posecov::app::{Overrides, bag, run::{Run, open}};
//! let Run::Log(run) = Run::start(open("covariance_health").unwrap(), &Overrides::default(), None).unwrap() else { panic!() };
//! assert_eq!(run.plan.topics.len(), 3);
//! let json = bag::report_json("covariance_health", &run);
//! assert_eq!(json["topics"][0]["health"]["not_psd"]["count"], 1);
//! ```

use std::sync::atomic::AtomicBool;

use indicatif::{ProgressBar, ProgressStyle};

use super::AppError;
use super::commands::Checked;
use super::settings::LogSettings;
use crate::draw::bag::{BagDrawSettings, bag_scene, description, issue_sentence, issue_word};
use crate::eval::bag::{BagEvaluation, evaluate_bag};
use crate::input::bag::{BagOptions, bundled, read_located};
use crate::input::{About, Located, Place};
use crate::plan::bag::{Class, Issue, LogSummary};
use crate::scene::Scene;

/// A read, evaluated and drawn log.
#[derive(Debug, Clone)]
pub struct LogRun {
    /// Where it was read from, and its format.
    pub located: Located,
    /// The settings it ran with.
    pub settings: LogSettings,
    /// What was read.
    pub plan: LogSummary,
    /// Its numbers.
    pub evaluation: BagEvaluation,
    /// Its scene (validated).
    pub scene: Scene,
}

/// Reads (streamed, a progress bar on a terminal; `cancel` stops the read and keeps what was
/// read), evaluates and draws a log.
///
/// See the [module docs](self) for an example.
pub fn run(
    located: &Located,
    settings: &LogSettings,
    cancel: Option<&AtomicBool>,
) -> Result<LogRun, AppError> {
    let plan = read(located, &settings.read, cancel)?;
    let evaluation = evaluate_bag(&plan, &settings.eval);
    let file = located.origin();
    let title = match &located.place {
        Place::Bundled(e) => bundled::find(e.name).map_or(e.name, |l| l.title).to_owned(),
        Place::File(_) => file.clone(),
    };
    let draw = BagDrawSettings {
        about: About {
            title,
            description: String::new(),
            source: file,
        },
        confidence: settings.confidence,
        axis_length: None,
    };
    let summary = description(&plan, located.format, &evaluation, settings.confidence);
    let scene = bag_scene(&evaluation, &draw, &summary);
    scene.validate()?;
    Ok(LogRun {
        located: located.clone(),
        settings: settings.clone(),
        plan,
        evaluation,
        scene,
    })
}

fn read(
    located: &Located,
    options: &BagOptions,
    cancel: Option<&AtomicBool>,
) -> Result<LogSummary, AppError> {
    let file = located.origin();
    let bar = ProgressBar::new(0).with_message(format!("reading {file}"));
    bar.set_style(
        ProgressStyle::with_template("{msg} {wide_bar} {percent} % ({elapsed}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let plan = read_located(
        located,
        options,
        &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        },
        cancel,
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

fn secs(ns: i64) -> f64 {
    ns as f64 * 1e-9
}

/// The JSON report of a log: per topic its type, frames, counts, stamps (s), planar or 3-D
/// with the χ² dimensions, drawn messages, and health (per issue the count and first stamp in
/// seconds); the skipped topics. Keys are stable (see the README).
///
/// See the [module docs](self) for an example.
pub fn report_json(name: &str, run: &LogRun) -> serde_json::Value {
    let plan = &run.plan;
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
                            "first_stamp_s": secs(c.first_stamp_ns),
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
                "stamps": {
                    "first_s": t.stamp_range.map(|r| secs(r.0)),
                    "last_s": t.stamp_range.map(|r| secs(r.1)),
                    "from_log_time": t.stamps_from_log_time,
                    "out_of_order": t.stamps_out_of_order,
                },
                "planar": t.planar,
                "position_dof": e.position_dof,
                "pose_dof": e.pose_dof,
                "drawn": e.poses.len(),
                "drawn_invalid": e.poses.iter().filter(|p| !p.state.is_drawable()).count(),
                "every": t.stride,
                "dead_reckoned": t.dead_reckoned(),
                "health": health,
                "constant_stretch": t.health.constant.map(|c| serde_json::json!({
                    "messages": c.messages,
                    "first_message": c.first_index,
                    "first_stamp_s": secs(c.first_stamp_ns),
                    "last_stamp_s": secs(c.last_stamp_ns),
                    "distance_m": c.distance_m,
                })),
                "min_eigenvalue": t.health.min_eigenvalue,
                "twist_sigma_last": t.twist_sigmas(),
                "ros_reading": run.evaluation.reading,
                "ros_readings_apart": e.reading_difference,
            })
        })
        .collect();
    serde_json::json!({
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
        },
        "topics": topics,
        "skipped": plan.skipped,
        "not_selected": plan.not_selected,
    })
}

/// The text report: the summary the text panel shows.
///
/// ```
/// use posecov::app::{Overrides, bag, run::{Run, open}};
/// let Run::Log(run) = Run::start(open("jackal_odometry").unwrap(), &Overrides::default(), None).unwrap() else { panic!() };
/// let text = bag::report_text("jackal_odometry", &run);
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

/// What `check` says of a log: one line for stdout (topics, messages, drawn items, defects and
/// notes) and, for each topic with a defect not in `allow`, its first defect on a line for
/// stderr in the file's terms (file, topic, message, stamp), with its count and `--allow` name.
///
/// ```
/// use posecov::app::{Overrides, bag, run::{Run, open}};
/// use posecov::plan::bag::Issue;
/// let Run::Log(run) = Run::start(open("covariance_health").unwrap(), &Overrides::default(), None).unwrap() else { panic!() };
/// let checked = bag::check(&run, "covariance_health", &[]);
/// assert!(checked.line.starts_with("covariance_health: defects on 1 of 3 pose topic(s)"), "{}", checked.line);
/// assert!(checked.defects[0].starts_with("health_cases.mcap (bundled): topic /amcl_pose, message 1 (stamp 101.000 s): all_zero"), "{:?}", checked.defects);
/// let allow: Vec<Issue> = Issue::ALL.to_vec();
/// assert!(bag::check(&run, "covariance_health", &allow).defects.is_empty());
/// ```
pub fn check(run: &LogRun, name: &str, allow: &[Issue]) -> Checked {
    let plan = &run.plan;
    let file = run.located.origin();
    let mut defects = Vec::new();
    let mut notes = 0;
    for t in &plan.topics {
        notes += t
            .health
            .issues
            .iter()
            .filter(|(i, _)| t.class(**i) == Class::Note)
            .count();
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
                secs(c.first_stamp_ns),
                issue.name(),
                issue_sentence(*issue, t),
                c.count,
                issue.name(),
            ));
        }
    }
    let facts = format!(
        "{} messages, {} drawn items{}",
        plan.messages_total,
        run.scene.items.len(),
        match notes {
            0 => String::new(),
            n => format!(", {n} kind(s) of note (see `posecov report`)"),
        }
    );
    let line = if defects.is_empty() {
        format!("{name}: ok ({} pose topic(s), {facts})", plan.topics.len())
    } else {
        format!(
            "{name}: defects on {} of {} pose topic(s) ({facts}; the first of each on stderr)",
            defects.len(),
            plan.topics.len()
        )
    };
    Checked { line, defects }
}
