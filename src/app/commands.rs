//! The commands that print: `list`, `report`, `check`.

use std::fmt::Write as _;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

pub use super::checked::Checked;
use super::run::{Opened, PlanRun, Run, RunOptions, open};
use super::{AppError, Overrides, SettingsError, log, report_json, resolve};
use crate::input::{Format, examples, open_text};
use crate::plan::log::Issue;

/// Samples `check` evaluates with (enough to exercise every path, quick on any input).
pub const CHECK_SAMPLES: u64 = 32;

/// `posecov list`: every bundled example with its title, by format.
///
/// ```
/// let list = posecov::app::commands::list().unwrap();
/// assert!(list.contains("camera_on_robot") && list.contains("gtsam_pose3example"), "{list}");
/// ```
pub fn list() -> Result<String, AppError> {
    let examples = examples();
    let width = examples.iter().map(|e| e.name.len()).max().unwrap_or(0);
    let mut out = String::new();
    for format in Format::ALL {
        let of_format: Vec<_> = examples.iter().filter(|e| e.format == format).collect();
        if of_format.is_empty() {
            continue;
        }
        let extensions: Vec<String> = format
            .extensions()
            .iter()
            .map(|e| format!(".{e}"))
            .collect();
        if !out.is_empty() {
            out.push('\n');
        }
        let _ = writeln!(out, "{} ({}):", format.name_plural(), extensions.join(", "));
        for e in of_format {
            let title = match crate::input::log::bundled::find(e.name) {
                Some(log) => log.title.to_owned(),
                None => open_text(e.text, e.file, e.format)?.1.about.title,
            };
            let _ = writeln!(out, "{:width$}  {title}", e.name);
        }
    }
    Ok(out)
}

/// How `report` prints one input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReportStyle {
    /// Words for people.
    Text,
    /// One JSON object, indented.
    Json,
    /// One JSON object on one line (a line of JSON Lines, for several inputs).
    JsonLine,
}

/// `posecov report`: every mean, covariance, method, error and finding, as JSON or text.
///
/// ```
/// use posecov::app::{Overrides, commands::report};
/// let text = report("so3_sampling", &Overrides { samples: Some(50), ..Default::default() }, true).unwrap();
/// let json: serde_json::Value = serde_json::from_str(&text).unwrap();
/// assert_eq!(json["meta"]["samples"], 50);
/// ```
pub fn report(scenario: &str, overrides: &Overrides, json: bool) -> Result<String, AppError> {
    let style = if json {
        ReportStyle::Json
    } else {
        ReportStyle::Text
    };
    report_as(scenario, overrides, style, true, None)
}

/// [`report`] of a run that `cancel` (Ctrl-C) may stop: a live stream's (`ws://…`), whose
/// report is of what arrived before it.
///
/// ```
/// use std::sync::{Arc, atomic::AtomicBool};
/// let cancel = Arc::new(AtomicBool::new(false));
/// let text = posecov::app::commands::report_until("covariance_health", &Default::default(), true, cancel).unwrap();
/// assert!(text.contains("\"topics\""));
/// ```
pub fn report_until(
    scenario: &str,
    overrides: &Overrides,
    json: bool,
    cancel: Arc<AtomicBool>,
) -> Result<String, AppError> {
    let style = if json {
        ReportStyle::Json
    } else {
        ReportStyle::Text
    };
    report_as(scenario, overrides, style, true, Some(cancel))
}

/// [`report`] in a [`ReportStyle`]; `bar`: a log's reading shows its progress bar.
pub(super) fn report_as(
    scenario: &str,
    overrides: &Overrides,
    style: ReportStyle,
    bar: bool,
    cancel: Option<Arc<AtomicBool>>,
) -> Result<String, AppError> {
    let printed = |value: serde_json::Value| {
        let text = match style {
            ReportStyle::JsonLine => value.to_string(),
            _ => serde_json::to_string_pretty(&value).unwrap_or_default(),
        } + "\n";
        // A pose graph's tree is millions of nodes: freed beside the output, not before it.
        rayon::spawn(move || drop(value));
        text
    };
    let options = RunOptions {
        progress: bar,
        cancel,
        ..RunOptions::numbers()
    };
    let run = match Run::start(open(scenario)?, overrides, options)? {
        Run::Log(run) => {
            return Ok(match style {
                ReportStyle::Text => log::report_text(scenario, &run),
                _ => printed(log::report_json(scenario, &run)),
            });
        }
        Run::Plan(run) => run,
    };
    let PlanRun {
        loaded,
        settings,
        evaluation,
        ..
    } = *run;
    let confidence = settings.draw.confidence;
    if style != ReportStyle::Text {
        return Ok(printed(report_json(
            scenario,
            &loaded,
            &evaluation,
            confidence,
        )));
    }
    let ran = evaluation.ran_with();
    let (seed, samples) = (ran.seed, ran.samples);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{scenario} — {} (seed {seed}, {samples} samples, {:.1} % regions)",
        loaded.input.about.title,
        100.0 * confidence.get()
    );
    for r in &evaluation.records() {
        let error = r.relative_error_vs_monte_carlo.map_or(String::new(), |e| {
            format!(", vs Monte Carlo {:.2} %", 100.0 * e)
        });
        let _ = writeln!(
            out,
            "\n{} [{}] {} ({:?} side{error})",
            r.label,
            r.group,
            r.method.label(),
            r.side
        );
        let tangent: Vec<String> = r.mean_tangent.iter().map(|v| format!("{v:.6}")).collect();
        let _ = writeln!(out, "  mean Log(μ) = [{}]", tangent.join(", "));
        let _ = writeln!(out, "  covariance:");
        for row in &r.covariance {
            let row: Vec<String> = row.iter().map(|v| format!("{v:>12.6}")).collect();
            let _ = writeln!(out, "   {}", row.join(" "));
        }
    }
    for finding in evaluation.findings() {
        let _ = writeln!(
            out,
            "\nfinding: {}",
            serde_json::to_string(finding).unwrap_or_default()
        );
    }
    Ok(out)
}

/// The findings `--allow NAME` (repeatable) names, each checked against [`Issue::ALL`].
///
/// ```
/// use posecov::app::commands::allowed;
/// assert_eq!(allowed(&["constant".into()]).unwrap().len(), 1);
/// let e = allowed(&["nan".into()]).unwrap_err().to_string();
/// assert!(e.starts_with("--allow nan: out of range: one of non_finite, "), "{e}");
/// ```
pub fn allowed(names: &[String]) -> Result<Vec<Issue>, AppError> {
    names
        .iter()
        .map(|n| {
            Issue::from_name(n).ok_or_else(|| {
                let all: Vec<&str> = Issue::ALL.iter().map(|i| i.name()).collect();
                AppError::Settings(SettingsError::OutOfRange {
                    flag: "--allow",
                    value: n.clone(),
                    expected: format!("one of {}", all.join(", ")),
                })
            })
        })
        .collect()
}

/// `posecov check`: read, evaluate with few samples and draw, without showing anything; a
/// log's defects (other than the `allow`ed ones) are found, not errors (see [`Checked`]).
///
/// ```
/// let checked = posecov::app::commands::check("camera_on_robot", &Default::default(), &[]).unwrap();
/// assert!(checked.line.starts_with("camera_on_robot: ok ("), "{}", checked.line);
/// assert_eq!(checked.exit_code(), 0);
/// let log = posecov::app::commands::check("covariance_health", &Default::default(), &[]).unwrap();
/// assert_eq!(log.exit_code(), 1);
/// ```
pub fn check(scenario: &str, overrides: &Overrides, allow: &[Issue]) -> Result<Checked, AppError> {
    check_as(scenario, overrides, allow, true, None)
}

/// [`check`] of a run that `cancel` (Ctrl-C) may stop: a live stream's (`ws://…`), checked on
/// what arrived before it.
///
/// ```
/// use std::sync::{Arc, atomic::AtomicBool};
/// let cancel = Arc::new(AtomicBool::new(false));
/// let checked = posecov::app::commands::check_until("covariance_health", &Default::default(), &[], cancel).unwrap();
/// assert_eq!(checked.exit_code(), 1);
/// ```
pub fn check_until(
    scenario: &str,
    overrides: &Overrides,
    allow: &[Issue],
    cancel: Arc<AtomicBool>,
) -> Result<Checked, AppError> {
    check_as(scenario, overrides, allow, true, Some(cancel))
}

/// [`check`]; `bar`: a log's reading shows its progress bar.
pub(super) fn check_as(
    scenario: &str,
    overrides: &Overrides,
    allow: &[Issue],
    bar: bool,
    cancel: Option<Arc<AtomicBool>>,
) -> Result<Checked, AppError> {
    let opened = open(scenario)?;
    let quick = match &opened {
        Opened::Log(_) => overrides.clone(),
        // A plan is checked with few samples, after its flags are checked as given: `check`
        // refuses what `report` refuses.
        Opened::Plan(loaded) => {
            resolve(&loaded.input, overrides, None)?;
            Overrides {
                samples: Some(
                    overrides
                        .samples
                        .unwrap_or(CHECK_SAMPLES)
                        .min(CHECK_SAMPLES),
                ),
                ..overrides.clone()
            }
        }
    };
    // A log is checked on its numbers (not drawn); a plan is drawn, its line counting the
    // items its scenario draws.
    let options = RunOptions {
        draw: matches!(opened, Opened::Plan(_)),
        progress: bar,
        cancel,
        ..RunOptions::numbers()
    };
    let run = match Run::start(opened, &quick, options)? {
        Run::Log(run) => return Ok(log::check(&run, scenario, allow)),
        Run::Plan(run) => run,
    };
    let (evaluation, scene) = (run.evaluation, run.scene);
    let findings = evaluation.findings().len();
    let line = format!(
        "{scenario}: ok ({} results, {} drawn items, {} steps{})",
        evaluation.records().len(),
        scene.items.len(),
        scene.steps().len(),
        match findings {
            0 => String::new(),
            1 => ", 1 finding (see `posecov report`)".to_owned(),
            n => format!(", {n} findings (see `posecov report`)"),
        }
    );
    Ok(Checked {
        line,
        defects: Vec::new(),
        notes: Vec::new(),
    })
}
