//! Robot logs (ROS 1 bags, MCAP) through the application: find the log (a file, or a bundled
//! log by name), read it streamed with a progress bar and Ctrl-C, evaluate, draw; the
//! printing commands' text and JSON; with the `viewer` feature, the session that logs it.
//!
//! ```
//! use posecov::app::{Overrides, bag};
//! let place = bag::locate("covariance_health").unwrap().unwrap();
//! let run = bag::run(&place, "covariance_health", &Overrides::default(), None).unwrap();
//! assert_eq!(run.plan.topics.len(), 3);
//! let json = bag::report_json(&run);
//! assert_eq!(json["topics"][0]["health"]["not_psd"]["count"], 1);
//! ```

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use indicatif::{ProgressBar, ProgressStyle};

use super::{AppError, DEFAULT_CONFIDENCE, Overrides, SettingsError};
use crate::draw::bag::{BagDrawSettings, bag_scene, description};
use crate::eval::bag::{BagEvalSettings, BagEvaluation, DEFAULT_CLOUD_SAMPLES, evaluate_bag};
use crate::input::bag::bundled::{self, BundledLog};
use crate::input::bag::{BagOptions, read_bag};
use crate::input::format::{self, Format};
use crate::input::{About, InputError};
use crate::plan::bag::BagPlan;
use crate::scene::Scene;

/// At most this many cloud samples per drawn message (`--samples` for a log).
pub const MAX_CLOUD_SAMPLES: u64 = 10_000;

/// Where a robot log is.
#[derive(Debug, Clone)]
pub enum LogPlace {
    /// A file whose content (and extension) says ROS 1 bag or MCAP.
    File(PathBuf),
    /// A bundled log.
    Bundled(&'static BundledLog),
}

/// A read, evaluated and drawn log.
#[derive(Debug, Clone)]
pub struct LogRun {
    /// Name as the user gave it.
    pub name: String,
    /// What was read.
    pub plan: BagPlan,
    /// Its numbers.
    pub evaluation: BagEvaluation,
    /// Its scene (validated).
    pub scene: Scene,
    /// Probability inside drawn regions.
    pub confidence: f64,
    /// Seed of the clouds.
    pub seed: u64,
    /// Samples per drawn message.
    pub cloud_samples: usize,
}

/// The robot log `name_or_path` names, if it names one: an existing file that
/// [`format::detect`] calls a ROS 1 bag or MCAP file, or a bundled log's name. `None` for
/// anything else (a scenario, a graph, an unknown name), which the other inputs handle.
///
/// ```
/// assert!(posecov::app::bag::locate("camera_on_robot").unwrap().is_none());
/// assert!(posecov::app::bag::locate("jackal_odometry").unwrap().is_some());
/// ```
pub fn locate(name_or_path: &str) -> Result<Option<LogPlace>, AppError> {
    let path = Path::new(name_or_path);
    if path.is_file() {
        let head = format::read_head(path)?;
        let by_extension = path
            .extension()
            .and_then(|e| e.to_str())
            .and_then(Format::from_extension);
        let by_content = Format::from_content(&head);
        let is_log = |f: Option<Format>| matches!(f, Some(Format::Ros1Bag | Format::Mcap));
        if is_log(by_extension) || is_log(by_content) {
            // Content and extension must agree; the one detector says why not.
            format::detect(name_or_path, &head)?;
            return Ok(Some(LogPlace::File(path.to_owned())));
        }
        return Ok(None);
    }
    Ok(bundled::find(name_or_path).map(LogPlace::Bundled))
}

/// The options of a log read from the command line; `--block-samples` does not apply.
fn check_overrides(overrides: &Overrides) -> Result<(BagOptions, usize), AppError> {
    if let Some(b) = overrides.block_samples {
        return Err(SettingsError {
            flag: "--block-samples",
            value: b.to_string(),
            expected: "a scenario's Monte Carlo setting; a robot log draws a cloud per message (--samples)".into(),
        }
        .into());
    }
    super::settings::check_confidence(overrides.confidence)?;
    let samples = overrides.samples.unwrap_or(DEFAULT_CLOUD_SAMPLES as u64);
    if !(1..=MAX_CLOUD_SAMPLES).contains(&samples) {
        return Err(SettingsError {
            flag: "--samples",
            value: samples.to_string(),
            expected: format!("1 ..= {MAX_CLOUD_SAMPLES} samples per drawn message of a robot log"),
        }
        .into());
    }
    let options = BagOptions {
        topics: overrides.topics.clone(),
        every: overrides.every,
    };
    Ok((options, samples as usize))
}

/// Reads (streamed, a progress bar on a terminal; `cancel` stops the read and keeps what was
/// read), evaluates and draws a log.
///
/// See the [module docs](self) for an example.
pub fn run(
    place: &LogPlace,
    name: &str,
    overrides: &Overrides,
    cancel: Option<&AtomicBool>,
) -> Result<LogRun, AppError> {
    let (options, cloud_samples) = check_overrides(overrides)?;
    let confidence = overrides.confidence.unwrap_or(DEFAULT_CONFIDENCE);
    let seed = overrides.seed.unwrap_or(0);
    let (plan, file) = match place {
        LogPlace::File(path) => (read(path, &options, cancel)?, path.display().to_string()),
        LogPlace::Bundled(log) => {
            let tmp =
                std::env::temp_dir().join(format!("posecov-{}-{}", std::process::id(), log.file));
            std::fs::write(&tmp, log.bytes).map_err(|e| InputError::Read {
                path: tmp.display().to_string(),
                reason: e.to_string(),
            })?;
            let plan = read(&tmp, &options, cancel);
            std::fs::remove_file(&tmp).ok();
            let plan = plan.map_err(|e| match e {
                AppError::Input(InputError::Format { message, .. }) => {
                    AppError::Input(InputError::Format {
                        file: format!("{} (bundled)", log.file),
                        message,
                    })
                }
                other => other,
            })?;
            (plan, format!("{} (bundled)", log.file))
        }
    };
    let evaluation = evaluate_bag(
        &plan,
        &BagEvalSettings {
            seed,
            cloud_samples,
        },
    );
    let title = match place {
        LogPlace::Bundled(log) => log.title.to_owned(),
        LogPlace::File(_) => file.clone(),
    };
    let settings = BagDrawSettings {
        about: About {
            title,
            description: String::new(),
            source: file,
        },
        confidence,
        axis_length: None,
    };
    let scene = bag_scene(
        &evaluation,
        &settings,
        &description(&plan, &evaluation, confidence),
    );
    scene.validate()?;
    Ok(LogRun {
        name: name.to_owned(),
        plan,
        evaluation,
        scene,
        confidence,
        seed,
        cloud_samples,
    })
}

fn read(
    path: &Path,
    options: &BagOptions,
    cancel: Option<&AtomicBool>,
) -> Result<BagPlan, AppError> {
    let bar = ProgressBar::new(0).with_message(format!("reading {}", path.display()));
    bar.set_style(
        ProgressStyle::with_template("{msg} {wide_bar} {percent} % ({elapsed}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let plan = read_bag(
        path,
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
            "Interrupted: read {} messages of {}; drawing those.",
            plan.messages_total,
            path.display()
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
pub fn report_json(run: &LogRun) -> serde_json::Value {
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
                        serde_json::to_value(issue)
                            .ok()
                            .and_then(|v| v.as_str().map(str::to_owned))
                            .unwrap_or_default(),
                        serde_json::json!({
                            "count": c.count,
                            "first_stamp_s": secs(c.first_stamp_ns),
                            "word": issue.word(),
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
                "health": health,
                "min_eigenvalue": t.health.min_eigenvalue,
                "twist_sigma_last": t.twist_sigmas(),
            })
        })
        .collect();
    serde_json::json!({
        "scenario": run.name,
        "format": plan.format.map(|f| match f {
            crate::plan::bag::LogFormat::Ros1Bag => Format::Ros1Bag,
            crate::plan::bag::LogFormat::Mcap => Format::Mcap,
        }),
        "meta": {
            "title": run.scene.title,
            "seed": run.seed,
            "samples": run.cloud_samples,
            "confidence": run.confidence,
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
/// use posecov::app::{Overrides, bag};
/// let place = bag::locate("jackal_odometry").unwrap().unwrap();
/// let run = bag::run(&place, "jackal_odometry", &Overrides::default(), None).unwrap();
/// assert!(bag::report_text(&run).contains("| placeholder (≥ 1e6) | 3060 | 47.584 s |"));
/// assert!(bag::check_line(&run).starts_with("jackal_odometry: ok (1 pose topic(s), 6121 messages"));
/// ```
pub fn report_text(run: &LogRun) -> String {
    format!(
        "{} — {} ({:.1} % regions, seed {})\n\n{}",
        run.name,
        run.scene.title,
        100.0 * run.confidence,
        run.seed,
        run.scene.description_markdown
    )
}

/// One line: topics, messages, drawn items, health issues (example at [`report_text`]).
pub fn check_line(run: &LogRun) -> String {
    let issues: u64 = run
        .plan
        .topics
        .iter()
        .flat_map(|t| t.health.issues.values())
        .map(|c| c.count)
        .sum();
    format!(
        "{}: ok ({} pose topic(s), {} messages, {} drawn items{})",
        run.name,
        run.plan.topics.len(),
        run.plan.messages_total,
        run.scene.items.len(),
        if issues > 0 {
            format!(", {issues} covariance health notes (see `posecov report`)")
        } else {
            String::new()
        }
    )
}

#[cfg(feature = "viewer")]
pub use view::view;

#[cfg(feature = "viewer")]
mod view {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    use super::{LogPlace, run};
    use crate::app::AppError;
    use crate::app::sinks::{self, EXIT_INTERRUPTED, ViewOptions};
    use crate::sink::{self, LogOutcome, RecordingIds, open_stream};

    /// Shows or saves a log like a scenario (`--save`, `--png`, `--spawn`, `--serve`, …);
    /// exit code 130 when Ctrl-C cut the read (the recording holds what was read, complete).
    pub fn view(
        options: &ViewOptions,
        place: &LogPlace,
        cancel: &Arc<AtomicBool>,
    ) -> Result<u8, AppError> {
        if options.watch {
            return Err(AppError::Watch(
                "needs a scenario file to watch; a robot log is read once".to_owned(),
            ));
        }
        let run = run(place, &options.scenario, &options.overrides, Some(cancel))?;
        let stem = std::path::Path::new(&options.scenario)
            .file_stem()
            .map_or_else(
                || options.scenario.clone(),
                |s| s.to_string_lossy().into_owned(),
            );
        let ids = RecordingIds::for_scenario(&stem, run.seed);
        let log = |rec: &rerun::RecordingStream| -> Result<LogOutcome, AppError> {
            Ok(sink::log_scene_cancellable(rec, &run.scene, cancel)?)
        };
        let read_cut = |code: u8| {
            if run.plan.cancelled {
                EXIT_INTERRUPTED
            } else {
                code
            }
        };
        if let Some((png, size)) = &options.png {
            return sinks::render_with(options, &run.scene, &log, &ids, png, *size).map(read_cut);
        }
        let sink = sinks::choose_sink(options)?;
        let (rec, guard) = open_stream(&sink, &ids, &run.scene)?;
        if let Some(url) = guard.viewer_url() {
            println!("Web viewer: {url}");
        }
        let outcome = log(&rec)?;
        if guard.viewer_url().is_some() && outcome == LogOutcome::Complete {
            sinks::serve(&options.serve, &guard, cancel)?;
        }
        sinks::finish(guard, rec, &sink, outcome).map(read_cut)
    }
}
