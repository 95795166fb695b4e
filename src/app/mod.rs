//! The application: open an input (deciding once whether it is a plan or a robot log,
//! [`run::open`]), resolve its settings once (command line over file over defaults, one table
//! of which flags apply to which input), evaluate, draw — one pure [`run::Run`] every command
//! shares — and, with the `viewer` feature, one sequence in `session` that shows a run on any
//! sink (the viewer, `--watch`, `--save`, `--png`); and [`live`] mode, which re-evaluates and
//! re-streams in place as controls change.
//!
//! ```
//! use posecov::app::{Overrides, load, pipeline};
//! let loaded = load("camera_on_robot").unwrap();
//! let overrides = Overrides { samples: Some(64), ..Default::default() };
//! let (evaluation, scene) = pipeline(&loaded, &overrides, None).unwrap();
//! assert!(!evaluation.records().is_empty());
//! assert!(scene.validate().is_ok());
//! ```
//!
//! # What this folder owns
//!
//! - `run.rs`: `open` (the one place an input's kind is decided: `input::locate`, then a plan is
//!   read, a log is kept to stream) and one pure `Run` of any input, started by `Run::start(opened,
//!   &overrides, RunOptions)` — the only place that matches the input's kind, which every command
//!   (`report`, `check`, `figure`, the viewer) goes through, `RunOptions` saying whether the scene
//!   is drawn and progress shown
//! - `checked.rs`: `Checked`, what `check` found (`Run::Plan(PlanRun)`: evaluation, scene, later
//!   Monte Carlo blocks; `Run::Log(LogRun)`: the log read, evaluated, drawn)
//! - settings resolved once (`settings.rs`: flags over file over defaults, errors name the flag;
//!   one resolver, `resolve(&input | RobotLog, …)` over the `Target` it resolves for, every
//!   flag checked first against one table of the flags that apply to one kind of input
//!   only — logs, plans, or pose graphs — `kind_flags`, and a graph's `--joint` ids against its
//!   vertices)
//! - the pure pipeline (`load`, `evaluate`, `pipeline`, `report_json`; every key of every format's
//!   report is documented in `docs/report.schema.json`, `REPORT_SCHEMA_VERSION`)
//! - the printing commands (`commands.rs`)
//! - many inputs at once (`many.rs`: `report` and `check` of several inputs or a directory of logs
//!   — expanded once, run in parallel on rayon's pool under one progress bar, each result printed
//!   whole as it finishes, JSON Lines, the worst exit code)
//! - `figure.rs` (`posecov figure`: any input's `Run`'s scene to `sink::figure`, and the gallery)
//! - robot logs (`log.rs`: `run` — read with a progress bar, evaluate, and draw when
//!   `RunOptions::draw` asks (`report` and `check` print numbers: their run keeps the scene's title
//!   and description only, and `draw::items_drawn` stays where it was); `log/nees.rs`:
//!   `--reference` decided — a topic of the log, `tf:CHILD`, a TUM file; a bare value both or
//!   neither is refused — the observer set up and finished, `topics[].consistency`; a scene that
//!   cannot be drawn is located in the log — and the log's text and JSON report, stamps to the µs)
//! - `view.rs` (the default command: `run::open`, then a watched file to `live::watch_in_place` or
//!   `session::watch_saving`, any other input to `session::show`)
//! - `session.rs` (`show`: the one sequence that logs any `Run` — scene, then later blocks — to any
//!   sink; `--watch --save`); and `sinks.rs`, which every path that shows a picture shares (the
//!   viewer options, the sink chosen, served, finished with the exit code; `--png`). The imports
//!   run one way: `view.rs` → `live/`, `session.rs` → `run.rs` → `log.rs`, and → `sinks.rs`
//!
//! Not here: math.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::draw;
use crate::eval::{self, AnyEvaluation, EvalError, EvalSettings};
use crate::input::{self, Format, Input, InputError, Source};
use crate::scene::{Scene, SceneError};

pub mod checked;
pub mod commands;
pub mod figure;
pub mod live;
pub mod log;
pub mod many;
pub mod run;
#[cfg(feature = "viewer")]
pub mod session;
mod settings;
#[cfg(feature = "viewer")]
pub mod sinks;
#[cfg(feature = "viewer")]
pub mod view;

pub use settings::{
    AppliesTo, DEFAULT_SAMPLES, Given, LogSettings, MAX_CLOUD_SAMPLES, Overrides, ReferenceArg,
    ReferenceSettings, RobotLog, Settings, SettingsError, Target, resolve,
};

/// Exit code: success; notes (and, except for `check`, defects) in a log are not failures.
pub const EXIT_OK: u8 = 0;
/// Exit code: `check` found a defect in a log, or a scenario or graph has an error located in
/// it (file:line:column).
pub const EXIT_FAILED: u8 = 1;
/// Exit code: the input cannot be processed — unreadable, an unknown format, a log with no
/// pose-with-covariance topic, a damaged log — or the command line is wrong.
pub const EXIT_CANNOT: u8 = 2;
/// Exit code after Ctrl-C (128 + SIGINT), as shells expect.
pub const EXIT_INTERRUPTED: u8 = 130;

/// The exit codes of every command, as `--help` and docs/guide/cli.md show them.
pub const EXIT_CODES_HELP: &str = "\
Exit codes (every command; `check` differs where shown):
  0    success (notes in a log are allowed); stdout closed by the reader (`… | head`): quiet
  1    check: defects found in a log (other commands show and report them, exit 0);
       every command: a scenario, graph or text trajectory error located at file:line:column
  2    cannot process: unreadable file, unknown format, no topic with a covariance,
       a damaged log, a usage error
  130  interrupted (Ctrl-C)
Several inputs (`report`, `check`): the worst code of any input.";

/// Why a command could not run. Each names where the problem is in the user's words: the
/// file, line, column and key, or the command-line flag.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    /// The input file (reading, format, syntax, values), or an evaluation error located in
    /// it.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A command-line value.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The drawing is not valid (a bug: evaluation checks every number it hands on).
    #[error("the scene is not drawable: {0}")]
    Scene(#[from] SceneError),
    /// A plan's drawing is not valid at one of its poses (a bug, as [`AppError::Scene`]):
    /// the pose (from the item's typed [`Origin`](crate::scene::Origin)) and the value.
    #[error("{origin}: the scene is not drawable: {error}")]
    Undrawable {
        /// What the first undrawable item was drawn from.
        origin: crate::scene::Origin,
        /// The entity, field and value.
        error: SceneError,
    },
    /// The viewer, the file or the stream.
    #[cfg(feature = "viewer")]
    #[error(transparent)]
    Sink(#[from] crate::sink::SinkError),
    /// A figure could not be written.
    #[error(transparent)]
    Figure(#[from] crate::sink::figure::FigureError),
    /// `--watch` was given something it cannot watch or a sink it cannot rewrite.
    #[error("--watch {0}")]
    Watch(String),
    /// Live mode: an input it cannot edit, a sink it cannot stream to, the page server.
    #[error("live: {0}")]
    Live(String),
}

impl AppError {
    /// The process exit code of this error ([`EXIT_CODES_HELP`]): [`EXIT_FAILED`] for an
    /// error located in a scenario or graph file, [`EXIT_CANNOT`] for everything else.
    ///
    /// ```
    /// use posecov::app::{EXIT_CANNOT, EXIT_FAILED, load, load_text};
    /// assert_eq!(load("no/such.toml").unwrap_err().exit_code(), EXIT_CANNOT);
    /// assert_eq!(load_text("[scenario]\nsamples = 1\n", "t.toml").unwrap_err().exit_code(), EXIT_FAILED);
    /// ```
    pub fn exit_code(&self) -> u8 {
        match self {
            AppError::Input(InputError::At { .. }) => EXIT_FAILED,
            _ => EXIT_CANNOT,
        }
    }

    /// What `report --json` prints on stdout when the report fails (the text still goes to
    /// stderr): one object `{"error": {…}}` with the `message`, the whole `text` as stderr
    /// shows it, the `exit_code`, and where known the `file`, `line`, `column` (1-based),
    /// `key` (the field in the file's words) or `place` (inside a binary log).
    ///
    /// ```
    /// use posecov::app::load_text;
    /// let text = "[scenario]\ntitle = \"t\"\ngroup = \"se2\"\nsamples = 1\n";
    /// let json = load_text(text, "t.toml").unwrap_err().to_json();
    /// assert_eq!(json["error"]["file"], "t.toml");
    /// assert_eq!((&json["error"]["line"], &json["error"]["column"]), (&4.into(), &11.into()));
    /// assert_eq!(json["error"]["key"], "scenario.samples");
    /// assert_eq!(json["error"]["exit_code"], 1);
    /// ```
    pub fn to_json(&self) -> serde_json::Value {
        let mut error = serde_json::Map::new();
        let mut put = |key: &str, value: serde_json::Value| {
            error.insert(key.to_owned(), value);
        };
        let message = match self {
            AppError::Input(InputError::Read { path, reason }) => {
                put("file", path.as_str().into());
                reason.clone()
            }
            AppError::Input(InputError::Format { file, message }) => {
                put("file", file.as_str().into());
                message.clone()
            }
            AppError::Input(InputError::In {
                file,
                place,
                message,
            }) => {
                put("file", file.as_str().into());
                put("place", place.as_str().into());
                message.clone()
            }
            AppError::Input(InputError::At {
                file,
                line,
                column,
                field,
                message,
                ..
            }) => {
                put("file", file.as_str().into());
                put("line", (*line).into());
                put("column", (*column).into());
                put("key", field.as_str().into());
                message.clone()
            }
            other => other.to_string(),
        };
        put("message", message.into());
        put("text", self.to_string().into());
        put("exit_code", self.exit_code().into());
        serde_json::json!({ "error": error })
    }
}

/// The object of [`AppError::to_json`] for an error found before any input was read (a
/// command-line usage error): only its `message`, `text` and `exit_code`.
///
/// ```
/// let json = posecov::app::usage_error_json("--confidence 95: did you mean 0.95?", 2);
/// assert_eq!(json["error"]["exit_code"], 2);
/// assert!(json["error"].get("file").is_none());
/// ```
pub fn usage_error_json(text: &str, exit_code: u8) -> serde_json::Value {
    let message = text.trim().trim_start_matches("error: ");
    serde_json::json!({ "error": {
        "message": message.lines().next().unwrap_or_default(),
        "text": text.trim(),
        "exit_code": exit_code,
    } })
}

/// An input and the file it came from (to locate evaluation errors in it), of any format.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The parsed file (a scenario, a graph, …).
    pub source: Source,
    /// The checked input.
    pub input: Input,
}

impl Loaded {
    /// An evaluation error, located at the operation it is about (`file:line:column:
    /// operation[k]: …` in a scenario, the edge's line in a graph), or at the file.
    ///
    /// ```
    /// use posecov::eval::EvalError;
    /// let loaded = posecov::app::load("camera_on_robot").unwrap();
    /// let e = loaded.locate(&EvalError::Undefined { operation: 0, output: "x".into(), definition: 9 });
    /// assert!(e.to_string().starts_with("camera_on_robot.toml (bundled):"), "{e}");
    /// ```
    pub fn locate(&self, error: &EvalError) -> InputError {
        // The location names the operation; keep its output's name, not the repeated index.
        self.source
            .operation_error(error.operation(), error.without_place())
    }
}

/// Loads a plan — a scenario or a pose graph file (by content and extension, see
/// [`input::format`]) or a bundled example by name — and checks it ([`input::open`]); a robot
/// log is refused (see [`run::open`] for any input).
///
/// ```
/// let e = posecov::app::load("no_such_thing").unwrap_err().to_string();
/// assert!(e.contains("camera_on_robot"), "{e}");
/// ```
pub fn load(name_or_path: &str) -> Result<Loaded, AppError> {
    let (source, input) = input::open(name_or_path)?;
    Ok(Loaded { source, input })
}

/// Parses and lowers scenario text (`origin` names it in messages).
///
/// ```
/// let e = posecov::app::load_text("[scenario]\ntitle='t'\ngroup='se2'\nsamples=1\n", "t.toml").unwrap_err();
/// assert!(e.to_string().starts_with("t.toml:4:9: scenario.samples: 1 is out of range"), "{e}");
/// ```
pub fn load_text(text: &str, origin: &str) -> Result<Loaded, AppError> {
    let (source, input) = input::open_text(text, origin, Format::Scenario)?;
    Ok(Loaded { source, input })
}

/// Evaluates a loaded input with resolved settings, locating any error in the file.
///
/// ```
/// use posecov::app::{Overrides, load, resolve, evaluate};
/// let loaded = load("so3_sampling").unwrap();
/// let settings = resolve(&loaded.input, &Overrides { samples: Some(100), ..Default::default() }, None).unwrap();
/// assert!(evaluate(&loaded, &settings.eval).is_ok());
/// ```
pub fn evaluate(loaded: &Loaded, settings: &EvalSettings) -> Result<AnyEvaluation, AppError> {
    eval::evaluate(&loaded.input.plan, settings).map_err(|e| AppError::Input(loaded.locate(&e)))
}

/// The pure path in one call: resolve, evaluate, draw, validate.
///
/// See the [module docs](self) for an example.
pub fn pipeline(
    loaded: &Loaded,
    overrides: &Overrides,
    cancel: Option<Arc<AtomicBool>>,
) -> Result<(AnyEvaluation, Scene), AppError> {
    let options = run::RunOptions {
        cancel,
        ..run::RunOptions::shown()
    };
    let (_, evaluation, scene) = evaluate_and_draw(loaded, overrides, &options, Hooks::default())?;
    Ok((evaluation, scene))
}

/// Where an evaluation reports its progress: a pose graph's solves, and the Monte Carlo's
/// steps (none by default).
#[derive(Default)]
struct Hooks {
    graph: Option<crate::eval::graph::ProgressHook>,
    monte_carlo: Option<crate::eval::StepProgress>,
}

/// Resolves, evaluates, draws and validates: the one plan path ([`pipeline`],
/// [`run::Run::start`]) with `options`' cancel, graph step marginals and drawing, reporting
/// to `hooks`; undrawn when [`run::RunOptions::draw`] is false (the scene keeps the title and
/// description).
fn evaluate_and_draw(
    loaded: &Loaded,
    overrides: &Overrides,
    options: &run::RunOptions,
    hooks: Hooks,
) -> Result<(Settings, AnyEvaluation, Scene), AppError> {
    let mut settings = resolve(&loaded.input, overrides, options.cancel.clone())?;
    settings.eval.graph_progress = hooks.graph;
    settings.eval.monte_carlo_progress = hooks.monte_carlo;
    settings.eval.graph.step_marginals = options.step_marginals;
    let evaluation = evaluate(loaded, &settings.eval)?;
    if !options.draw {
        let about = &loaded.input.about;
        return Ok((
            settings,
            evaluation,
            Scene::new(
                about.title.clone(),
                draw::input_description(about, &loaded.input.draw),
            ),
        ));
    }
    let scene = draw::scene(&evaluation, &settings.draw);
    scene
        .validate()
        .map_err(|error| undrawable(&scene, error))?;
    Ok((settings, evaluation, scene))
}

/// A plan's scene that cannot be drawn, named by the pose its first undrawable item was drawn
/// from ([`AppError::Undrawable`]; [`AppError::Scene`] when no pose drew it).
fn undrawable(scene: &Scene, error: SceneError) -> AppError {
    let item = scene.items.iter().find(|i| i.validate().is_err());
    match item.and_then(|i| i.origin.clone()) {
        Some(origin) => AppError::Undrawable { origin, error },
        None => AppError::Scene(error),
    }
}

/// The layout version of `report --json` (top-level `schema_version`): raised only when a key
/// is removed, renamed or changes meaning; new keys do not raise it. Every key is documented
/// in `docs/report.schema.json`, which every bundled example's report validates against.
///
/// 2 (issue 32): `sensor_msgs/Imu` topics are read into `sensors` (they were `skipped`), and
/// `unknown_marker` is a note on them (REP 145's "not provided").
pub const REPORT_SCHEMA_VERSION: u32 = 2;

/// The posecov that wrote a report (`posecov_version`).
pub const POSECOV_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The JSON report of an evaluation: the settings it ran with (`meta`, with the sigma-point
/// parameters), every estimate with its error against Monte Carlo (`results`), every node's
/// Monte Carlo statistics (`monte_carlo`: Lie mean, centred covariance, uncentred covariance
/// about the nominal on both sides, Cartesian mean) and every finding (`findings`, e.g. the
/// fusion cost V). Keys are stable (see docs/guide/json-report.md).
///
/// ```
/// use posecov::app::{Overrides, load, pipeline, report_json};
/// let loaded = load("camera_on_robot").unwrap();
/// let (evaluation, _) = pipeline(&loaded, &Overrides { samples: Some(64), ..Default::default() }, None).unwrap();
/// let json = report_json("camera_on_robot", &loaded, &evaluation, posecov::uncertain::Confidence::DEFAULT);
/// assert_eq!(json["meta"]["samples"], 64);
/// ```
pub fn report_json(
    name: &str,
    loaded: &Loaded,
    evaluation: &AnyEvaluation,
    confidence: crate::uncertain::Confidence,
) -> serde_json::Value {
    let ran = evaluation.ran_with();
    let sigma = loaded.input.defaults.sigma_points.unwrap_or_default();
    // The three large parts (a pose graph's are megabytes) become trees side by side.
    fn value(v: impl serde::Serialize) -> serde_json::Value {
        serde_json::to_value(v).unwrap_or_default()
    }
    let ((results, monte_carlo), optimized) = rayon::join(
        || {
            rayon::join(
                || value(evaluation.records()),
                || value(evaluation.monte_carlo_records()),
            )
        },
        || evaluation.optimized().map(value),
    );
    let mut report = serde_json::json!({
        "schema_version": REPORT_SCHEMA_VERSION,
        "posecov_version": POSECOV_VERSION,
        "scenario": name,
        "format": loaded.source.format(),
        "input": loaded.source.facts(),
        "meta": {
            "title": loaded.input.about.title,
            "description": draw::input_description(&loaded.input.about, &loaded.input.draw),
            "source": loaded.input.about.source,
            "group": evaluation.group().name(),
            "seed": ran.seed,
            "samples": ran.samples,
            "block_samples": ran.block_samples,
            "confidence": confidence,
            "methods": ran.methods,
            "sigma_points": { "alpha": sigma.alpha, "beta": sigma.beta, "kappa": sigma.kappa },
        },
        "results": results,
        "monte_carlo": monte_carlo,
        "along_track": evaluation.along_track(),
        "findings": evaluation.findings(),
    });
    // A pose graph's optimisation: poses, marginals, loop closures (eval::graph).
    if let (Some(optimized), Some(object)) = (optimized, report.as_object_mut()) {
        object.insert("optimized".to_owned(), optimized);
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Color, ItemKind, Origin, PointCloud, SceneItem, Timing, paths};

    #[test]
    fn an_undrawable_plan_scene_names_the_pose_and_the_value() {
        let mut scene = Scene::new("t", "");
        let mut item = SceneItem::new(
            paths::child(&paths::monte_carlo("T_MC"), "cloud"),
            Timing::Static,
            ItemKind::Points(PointCloud {
                positions: vec![[0.0, 1e39, 0.0]],
                color: Color::rgb(0, 0, 0),
                radius: 0.01,
            }),
        );
        item.origin = Some(Origin::Node("T_MC".into()));
        scene.push(item);
        let error = scene.validate().unwrap_err();
        let e = undrawable(&scene, error).to_string();
        assert!(
            e.starts_with(
                "pose T_MC: the scene is not drawable: world/T_MC/monte_carlo/cloud: positions[1] = 1000"
            ) && e.ends_with("is not a finite number (as f32)"),
            "{e}"
        );
    }
}
