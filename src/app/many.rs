//! Many inputs in one command: `posecov report DIR_OR_FILES… [--json]` and `posecov check
//! FILES…`. The arguments are expanded once ([`expand`]: a directory means every robot log in
//! it, `.bag`, `.mcap`, `.db3` and ROS 2 bag directories, by name; a ROS 2 bag directory is one
//! log); the inputs run in parallel on rayon's pool under one
//! progress bar (the per-log bars are hidden), and each result is printed whole as soon as it
//! is ready — one compact JSON object per line (JSON Lines), one `check` line — so memory does
//! not grow with the number of inputs. Every line names its input (`scenario`), since lines
//! come in the order the inputs finish. The exit code is the worst of the inputs'
//! ([`EXIT_CODES_HELP`](super::EXIT_CODES_HELP)); a reader that closed stdout ends the run
//! quietly with 0, as for one input.
//!
//! A fleet's logs beyond one machine: one `posecov report LOG --json` per log under any job
//! runner; each prints the same object as one line here.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::commands::{self, Checked, ReportStyle};
use super::{AppError, EXIT_OK, Overrides};
use crate::input::{Format, InputError, InputKind};
use crate::plan::log::Issue;

/// The inputs of one command line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Inputs {
    /// Every input in order: the arguments as given, a directory replaced by its logs sorted
    /// by name.
    pub names: Vec<String>,
    /// More than one argument, or a directory: one result per input, as a line each.
    pub several: bool,
}

/// The inputs `args` stand for: each argument as given (a file, a ROS 2 bag directory or a
/// bundled example), any other directory replaced by every file in it whose extension is a log
/// format's (`.bag`, `.mcap`, `.db3`) and every ROS 2 bag directory in it (not other
/// subdirectories), sorted by name.
///
/// # Errors
/// A directory that cannot be listed, or that holds no log.
///
/// ```
/// use posecov::app::many::expand;
/// let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mcap");
/// let inputs = expand(&[dir.to_owned()]).unwrap();
/// assert!(inputs.several && inputs.names.iter().all(|n| n.ends_with(".mcap")));
/// let one = expand(&["camera_on_robot".to_owned()]).unwrap();
/// assert_eq!((one.names.len(), one.several), (1, false));
/// let empty = concat!(env!("CARGO_MANIFEST_DIR"), "/src");
/// assert!(expand(&[empty.to_owned()]).unwrap_err().to_string().ends_with("no robot log (.bag, .mcap, .db3, or a ROS 2 bag directory) in this directory"));
/// let bags = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2");
/// let inputs = expand(&[bags.to_owned()]).unwrap();
/// assert_eq!(inputs.names.len(), 6); // arc.mcap and five bag directories
/// let one = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2/arc_v9");
/// assert_eq!(expand(&[one.to_owned()]).unwrap().names, [one]);
/// ```
pub fn expand(args: &[String]) -> Result<Inputs, AppError> {
    let extensions: Vec<&str> = Format::ALL
        .iter()
        .filter(|f| f.kind() == InputKind::Log)
        // An extension another format owns (`.txt`, a graph's) is not a log's by name.
        .flat_map(|f| {
            let own = move |e: &&str| Format::from_extension(e) == Some(*f);
            f.extensions().iter().copied().filter(own)
        })
        .collect();
    let mut names = Vec::new();
    let mut directory = false;
    for arg in args {
        let path = Path::new(arg);
        if !path.is_dir() || is_bag_dir(path) {
            names.push(arg.clone());
            continue;
        }
        directory = true;
        let unreadable = |e: std::io::Error| {
            AppError::Input(InputError::Read {
                path: arg.clone(),
                reason: e.to_string(),
            })
        };
        let mut logs = Vec::new();
        for entry in std::fs::read_dir(path).map_err(unreadable)? {
            let file = entry.map_err(unreadable)?.path();
            let is_log = file
                .extension()
                .and_then(|e| e.to_str())
                .and_then(Format::from_extension)
                .is_some_and(|f| f.kind() == InputKind::Log);
            if (is_log && file.is_file()) || is_bag_dir(&file) {
                logs.push(file.display().to_string());
            }
        }
        if logs.is_empty() {
            let listed: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
            return Err(AppError::Input(InputError::Read {
                path: arg.clone(),
                reason: format!(
                    "no robot log ({}, or a ROS 2 bag directory) in this directory",
                    listed.join(", ")
                ),
            }));
        }
        logs.sort();
        names.extend(logs);
    }
    Ok(Inputs {
        several: directory || names.len() > 1,
        names,
    })
}

/// Whether `path` is a ROS 2 bag directory (it holds `metadata.yaml`): one log, not a
/// directory of logs.
fn is_bag_dir(path: &Path) -> bool {
    path.join(crate::input::log::rosbag2::METADATA_FILE)
        .is_file()
}

/// Runs `work` on every input in parallel under one progress bar; `done` gets each result as
/// it finishes, one at a time, and says whether to go on (`false`: nobody reads any more;
/// inputs not started are skipped).
fn each<T>(
    names: &[String],
    work: impl Fn(&str) -> T + Sync + Send,
    done: impl FnMut(&str, T) -> bool + Send,
) {
    let bar = ProgressBar::new(names.len() as u64).with_message(format!("{} inputs", names.len()));
    bar.set_style(
        ProgressStyle::with_template("{msg} {wide_bar} {pos}/{len} ({elapsed}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let done = Mutex::new(done);
    let stop = AtomicBool::new(false);
    names.par_iter().for_each(|name| {
        if stop.load(Ordering::Relaxed) {
            return;
        }
        let result = work(name.as_str());
        let mut done = done.lock().unwrap_or_else(PoisonError::into_inner);
        if !bar.suspend(|| (*done)(name.as_str(), result)) {
            stop.store(true, Ordering::Relaxed);
        }
        bar.inc(1);
    });
    bar.finish_and_clear();
}

/// `posecov report` of several inputs: per input, as it finishes, its JSON report as one
/// compact line with `json` (JSON Lines), else its text report; an input that fails prints
/// `{"scenario": NAME, "error": {…}}` as its line (`json`) or its error on stderr. `out`
/// writes to stdout and says whether the reader still reads. Returns the exit code: the worst
/// input's, or 0 when the reader closed stdout.
pub fn report(
    names: &[String],
    overrides: &Overrides,
    json: bool,
    out: &mut (dyn FnMut(&str) -> bool + Send),
) -> u8 {
    let style = if json {
        ReportStyle::JsonLine
    } else {
        ReportStyle::Text
    };
    let mut worst = EXIT_OK;
    let mut closed = false;
    each(
        names,
        |name| commands::report_as(name, overrides, style, false, None),
        |name, result| {
            let text = match result {
                Ok(text) => text,
                Err(err) => {
                    worst = worst.max(err.exit_code());
                    if !json {
                        eprintln!("error: {err:#}");
                        return true;
                    }
                    let mut line = err.to_json();
                    line["scenario"] = name.into();
                    line.to_string() + "\n"
                }
            };
            closed = !out(&text);
            !closed
        },
    );
    if closed { EXIT_OK } else { worst }
}

/// `posecov check` of several inputs: one line per input on stdout as it finishes (`NAME: ok
/// (…)`, `NAME: defects on …` or `NAME: error: …`), a log's first defect per topic on stderr.
/// Returns the exit code: the worst input's, or 0 when the reader closed stdout.
pub fn check(
    names: &[String],
    overrides: &Overrides,
    allow: &[Issue],
    out: &mut (dyn FnMut(&str) -> bool + Send),
) -> u8 {
    let mut worst = EXIT_OK;
    let mut closed = false;
    each(
        names,
        |name| commands::check_as(name, overrides, allow, false, None),
        |name, result: Result<Checked, AppError>| {
            let line = match result {
                Ok(checked) => {
                    for defect in &checked.defects {
                        eprintln!("{defect}");
                    }
                    worst = worst.max(checked.exit_code());
                    checked.line
                }
                Err(err) => {
                    worst = worst.max(err.exit_code());
                    // The input's name once: the error's own naming of the file left out.
                    let reason = match &err {
                        AppError::Input(e) => match e.reason() {
                            (file, Some(reason)) if file == name => reason,
                            _ => err.to_string(),
                        },
                        _ => err.to_string(),
                    };
                    format!("{name}: error: {reason}")
                }
            };
            closed = !out(&(line + "\n"));
            !closed
        },
    );
    if closed { EXIT_OK } else { worst }
}
