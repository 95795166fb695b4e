//! Inputs: each format is a module that reads its files, checks them with its own locations,
//! and produces an [`Input`]: a typed [`Plan`](crate::plan::Plan) plus the file's text and
//! settings. Nothing after this stage reads a file format.
//!
//! - [`scenario`]: TOML scenario files (and the bundled lecture scenarios);
//! - [`graph`]: g2o / GTSAM text pose graphs (and two bundled GTSAM examples);
//! - [`log`]: robot logs, ROS 1 bags and MCAP files (ROS 2), streamed.
//!
//! [`locate`] is the one entry: it finds the file (or a bundled example by name) and decides
//! its [`Format`] by content and extension, once; [`Format::kind`] says whether it is a plan
//! ([`open_located`]: that format's reader) or a robot log ([`log::read_located`]). A new plan
//! format is a [`Format`] variant, a [`Source`] variant and one arm in [`open_file`] and
//! [`open_text`]; a new log source is one module under [`log`] and one arm in
//! [`log::read_located`].
//!
//! ```
//! use posecov::input::{Format, open};
//! let (source, input) = open("camera_on_robot").unwrap();
//! assert_eq!(source.format(), Format::Scenario);
//! assert!(!input.about.title.is_empty());
//! ```
//!
//! # What this folder owns
//!
//! - `mod.rs`: `locate` (a file or a bundled example by name → `Located`: where it is and its
//!   `Format`, detected once), `open_located` / `open` (a plan's `Source` + `Input`), the bundled
//!   `examples()`;
//! - `format.rs`: which `Format` a file is (magic bytes, first token, extension; they must agree;
//!   a directory is a ROS 2 bag by its `metadata.yaml`'s storage, `detect_dir`) and its `InputKind` (`Format::kind`: plan or log, the one place that decides);
//! - `located.rs`: `InputError` (file:line:column: field, or file: place for binary formats) and
//!   `Locator`. One module per input format; each reads, checks with its own locations and produces
//!   an `Input` (plan + text + the file's settings and drawing choices).
//! - `input/graph/`: g2o / GTSAM text graphs (`parse.rs` records and numbers, `convention.rs`
//!   information → \[ρ; θ\] covariance and GTSAM's reading, `lower.rs` the odometry chain and loop
//!   closures as drawn before the optimisation (their residuals are evaluated in `eval/graph/`),
//!   `problem.rs` the optimisation problem — a `plan::graph::PoseGraph` with the file's priors and
//!   `FIX` records, and the initial guess chained from the edges when the file has no vertex lines,
//!   `bundled.rs`).
//! - `input/log/`: robot logs, streamed — `ros1.rs` (ROS 1 bags through the `rosbag` crate: chunks
//!   found by the index, decompressed a few per thread in parallel, messages in file order),
//!   `ros1_linear.rs` (a ROS 1 bag without a usable index — cut short, or its recording interrupted
//!   — read chunk by chunk from the start up to the cut, which the plan keeps as `LogCut`)
//!   - `mcap.rs` (MCAP through the `mcap` crate's sans-I/O reader; channels in `cdr` or `ros1`
//!     encoding, each keeping its codec)
//!   - `rosbag2.rs` (ROS 2 bag directories: `metadata.yaml` versions 1–9 read by a small
//!     block-YAML reader, storage `sqlite3` or `mcap`, split files in order and checked present
//!     before reading, zstd `file` compression decompressed to a temporary file and `message`
//!     compression handed to the SQLite reader; the same metadata in a `.db3`'s `metadata` table)
//!   - `sqlite.rs` (one `.db3` through `rusqlite`'s bundled SQLite: `topics`, then `messages` in
//!     row order, one pass; a damaged file located by the last row read and `dbstat`'s corrupted
//!     pages, a cut one by its header's page count)
//!   - `decode.rs` (ROS 1 serialization and CDR via `re_cdr`'s serde of the message types, into
//!     `plan::log::PoseMessage`, the one message struct from decoder to drawn message)
//!   - `health.rs` (every covariance-health word and threshold; `TopicHealth`, the per-message
//!     health and σ work, which `benches/bag_read.rs` times alone; `health/classify.rs` one
//!     message's covariance and orientation on their own: one pass decides the common case, every
//!     check the rest)
//!   - `mod.rs` (`read_located`: one arm per log source; the collector of every message)
//!   - `topic.rs` (one topic's streaming state: stamps, health, constancy, the σ statistics of
//!     every message)
//!   - `bundled.rs`
//!   - `tf.rs` (`/tf` and `/tf_static` decoded by `reference.rs`'s decoder — the one TF decoder —
//!     and kept per edge, bounded, into `plan::log::TfTree`)
//!   - `reference.rs` (the message types a reference is read from — PoseStamped, TransformStamped,
//!     TFMessage, the pose of the covariance types — in ROS 1 and CDR; the collector hands the
//!     reference's samples, and every estimate message, to a `LogObserver` in file order:
//!     `read_located_observed`); `input/tum.rs` reads a TUM trajectory file (a log's
//!     `--reference`); it produces a `plan::log::LogSummary`, not an `Input` (no `Plan<G>`: a log
//!     is evaluated by `eval::log`).
//! - `input/scenario/`: `schema.rs` (serde, spans)
//!   - `parse_errors.rs` (TOML errors in the file's words)
//!   - `values.rs` (means, covariances, controls)
//!   - `lower/` (every check: `mod.rs` the one table of operation keys, settings, names and
//!     operands; `operations.rs` each kind's values and ranges; `choices.rs` the camera and the
//!     sigma-point parameters)
//!   - `bundled.rs`
//!
//! It does not evaluate.

use std::path::Path;

use crate::plan::AnyPlan;
pub use crate::plan::choices::{About, CameraChoice, DrawChoices, Layout};
use crate::uncertain::Method;

pub mod format;
pub mod graph;
mod located;
pub mod log;
pub mod scenario;
pub mod suggest;
pub mod tum;

pub use format::{Format, InputKind};
pub use located::{InputError, Locator, not_text};

/// The file an [`Input`] came from, kept to locate later (evaluation) errors in it.
#[derive(Debug, Clone)]
pub enum Source {
    /// A TOML scenario (boxed: its typed file is large).
    Scenario(Box<scenario::Scenario>),
    /// A g2o / GTSAM pose graph.
    Graph(graph::Graph),
}

impl Source {
    /// The file's format.
    ///
    /// ```
    /// use posecov::input::{Format, open};
    /// assert_eq!(open("gtsam_pose2example").unwrap().0.format(), Format::Graph);
    /// ```
    pub fn format(&self) -> Format {
        match self {
            Source::Scenario(_) => Format::Scenario,
            Source::Graph(_) => Format::Graph,
        }
    }

    /// What the file holds beyond the plan, for `report --json`: a graph's counts (vertices,
    /// edges, chain edges, loop closures); `null` for a scenario.
    ///
    /// ```
    /// let (source, _) = posecov::input::open("gtsam_pose2example").unwrap();
    /// assert_eq!(source.facts()["loop_closures"], 2);
    /// ```
    pub fn facts(&self) -> serde_json::Value {
        match self {
            Source::Scenario(_) => serde_json::Value::Null,
            Source::Graph(g) => serde_json::to_value(g.summary()).unwrap_or_default(),
        }
    }

    /// An error about plan operation `index` at the place in the file that defined it (a
    /// scenario's `[[operation]]`, a graph's edge line), or about the file as a whole.
    ///
    /// ```
    /// let (source, _) = posecov::input::open("gtsam_pose2example").unwrap();
    /// let e = source.operation_error(None, "odd").to_string();
    /// assert!(e.starts_with("gtsam_pose2example.txt (bundled):1:1: file: odd"), "{e}");
    /// ```
    pub fn operation_error(&self, index: Option<usize>, message: impl Into<String>) -> InputError {
        match self {
            Source::Scenario(s) => s.operation_error(index, message),
            Source::Graph(g) => g.operation_error(index, message),
        }
    }
}

/// A bundled example: its name (what `posecov NAME` takes), format and text.
#[derive(Debug, Clone, Copy)]
pub struct Example {
    /// Name, e.g. `camera_on_robot`.
    pub name: &'static str,
    /// Its format.
    pub format: Format,
    /// The file name it is shown under in messages, e.g. `camera_on_robot.toml`.
    pub file: &'static str,
    /// The file's text.
    pub text: &'static str,
}

/// Every bundled example, scenarios first, then graphs, then robot logs (binary: their
/// `text` is empty, see [`log::bundled`]).
///
/// ```
/// use posecov::input::{Format, examples};
/// assert!(examples().iter().any(|e| e.format == Format::Graph));
/// ```
pub fn examples() -> Vec<Example> {
    let scenarios = scenario::bundled::BUNDLED.iter().map(|b| Example {
        name: b.name,
        format: Format::Scenario,
        file: b.file,
        text: b.text,
    });
    scenarios
        .chain(graph::bundled::examples())
        .chain(log::bundled::examples())
        .collect()
}

/// Where an input is: a file on disk, or an example built into the binary.
#[derive(Debug, Clone)]
pub enum Place {
    /// A file (its path as given).
    File(std::path::PathBuf),
    /// A bundled example.
    Bundled(Example),
    /// A running robot's topics: a Foxglove WebSocket server's URL, `ws://HOST:PORT`
    /// ([`log::ws`]). Its format is [`Format::Mcap`]: the server's channels are MCAP channels
    /// (topic, message encoding, schema), their messages in the same bytes.
    Live(String),
}

/// An input found and its format decided, once ([`locate`]): what every later step reads
/// by, so that nothing detects the format again.
#[derive(Debug, Clone)]
pub struct Located {
    /// Where it is.
    pub place: Place,
    /// Its format, by content and extension ([`format::detect`]) or the bundled example's.
    pub format: Format,
}

impl Located {
    /// The file as messages name it: the path as given, or `NAME.ext (bundled)`.
    ///
    /// ```
    /// assert_eq!(posecov::input::locate("jackal_odometry").unwrap().origin(), "test2.bag (bundled)");
    /// ```
    pub fn origin(&self) -> String {
        match &self.place {
            Place::File(path) => path.display().to_string(),
            Place::Bundled(e) => format!("{} (bundled)", e.file),
            Place::Live(url) => url.clone(),
        }
    }

    /// Whether it is a plan or a robot log ([`Format::kind`]).
    pub fn kind(&self) -> format::InputKind {
        self.format.kind()
    }
}

/// Finds an input — a file (its format by content and extension, [`format::detect`]), else a
/// bundled example by name — and decides its format, once. Errors name the file, or list the
/// bundled examples for a name that is none.
///
/// ```
/// use posecov::input::{Format, locate};
/// assert_eq!(locate("covariance_health").unwrap().format, Format::Mcap);
/// let e = locate("no_such_thing").unwrap_err().to_string();
/// assert!(e.contains("camera_on_robot") && e.contains("gtsam_pose2example"), "{e}");
/// assert!(e.contains("; MCAP files (ROS 2 bags): covariance_health"), "{e}");
/// ```
pub fn locate(name_or_path: &str) -> Result<Located, InputError> {
    if log::ws::is_live(name_or_path) {
        return Ok(Located {
            place: Place::Live(name_or_path.to_owned()),
            format: Format::Mcap,
        });
    }
    let path = Path::new(name_or_path);
    if path.is_dir() {
        return Ok(Located {
            place: Place::File(path.to_owned()),
            format: format::detect_dir(path)?,
        });
    }
    if path.exists() {
        let format = format::detect(name_or_path, &format::read_head(path)?)?;
        return Ok(Located {
            place: Place::File(path.to_owned()),
            format,
        });
    }
    let examples = examples();
    let stem = |e: &Example| name_or_path == e.name || name_or_path == e.file;
    if let Some(e) = examples.iter().find(|e| stem(e)) {
        return Ok(Located {
            place: Place::Bundled(*e),
            format: e.format,
        });
    }
    // A path (it has a directory in it): the file is missing, a bundled name was not meant.
    if name_or_path.contains(['/', '\\']) {
        return Err(InputError::Read {
            path: name_or_path.to_owned(),
            reason: "no such file".to_owned(),
        });
    }
    let guess = suggest::did_you_mean(name_or_path, examples.iter().map(|e| e.name));
    let by_format: Vec<String> = Format::ALL
        .iter()
        .filter_map(|f| {
            let names: Vec<&str> = examples
                .iter()
                .filter(|e| e.format == *f)
                .map(|e| e.name)
                .collect();
            (!names.is_empty()).then(|| format!("{}: {}", f.name_plural(), names.join(", ")))
        })
        .collect();
    Err(InputError::Read {
        path: name_or_path.to_owned(),
        reason: format!(
            "no such file, and no bundled example of that name; {guess}(see `posecov list`; {})",
            by_format.join("; ")
        ),
    })
}

/// Reads a file (its format by content and extension) or else a bundled example by name, and
/// checks it: [`locate`], then [`open_located`]. Errors name the file and the place in it.
///
/// ```
/// let e = posecov::input::open("no_such_thing").unwrap_err().to_string();
/// assert!(e.contains("camera_on_robot") && e.contains("gtsam_pose2example"), "{e}");
/// let e = posecov::input::open("camera_on_robt").unwrap_err().to_string();
/// assert!(e.contains("did you mean `camera_on_robot`?"), "{e}");
/// let e = posecov::input::open("logs/run_7.mcap").unwrap_err().to_string();
/// assert_eq!(e, "logs/run_7.mcap: cannot read input: no such file");
/// ```
pub fn open(name_or_path: &str) -> Result<(Source, Input), InputError> {
    open_located(&locate(name_or_path)?)
}

/// Reads and checks a located plan input (a scenario or a graph) in its decided format; a
/// robot log is refused (it is streamed by [`log::read_located`]).
///
/// ```
/// let located = posecov::input::locate("camera_on_robot").unwrap();
/// let (_, input) = posecov::input::open_located(&located).unwrap();
/// assert!(!input.about.title.is_empty());
/// ```
pub fn open_located(located: &Located) -> Result<(Source, Input), InputError> {
    match &located.place {
        Place::File(path) => open_file_as(path, located.format),
        Place::Bundled(e) => open_text(e.text, &located.origin(), located.format),
        Place::Live(url) => Err(not_a_plan(url, located.format)),
    }
}

/// Reads and checks a file whose format is decided by [`format::detect`].
///
/// ```
/// let e = posecov::input::open_file(std::path::Path::new("/no/such.toml")).unwrap_err();
/// assert!(e.to_string().starts_with("/no/such.toml: cannot read input"), "{e}");
/// ```
pub fn open_file(path: &Path) -> Result<(Source, Input), InputError> {
    let file = path.display().to_string();
    open_file_as(path, format::detect(&file, &format::read_head(path)?)?)
}

/// Reads and checks a file of a format already decided.
fn open_file_as(path: &Path, format: Format) -> Result<(Source, Input), InputError> {
    match format {
        Format::Scenario => {
            let s = scenario::Scenario::load(path)?;
            let input = scenario::lower(&s)?;
            Ok((Source::Scenario(Box::new(s)), input))
        }
        Format::Graph => {
            let (g, input) = graph::read_file(path)?;
            Ok((Source::Graph(g), input))
        }
        Format::Ros1Bag | Format::Mcap | Format::Ros2Sqlite | Format::OvEval => {
            Err(not_a_plan(&path.display().to_string(), format))
        }
    }
}

/// Parses and checks text of a known format (`origin` names it in messages).
///
/// ```
/// use posecov::input::{Format, open_text};
/// let (_, input) = open_text("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\n", "g.g2o", Format::Graph).unwrap();
/// assert!(input.about.title.contains("g.g2o"));
/// ```
pub fn open_text(text: &str, origin: &str, format: Format) -> Result<(Source, Input), InputError> {
    match format {
        Format::Scenario => {
            let s = scenario::Scenario::parse(text, origin)?;
            let input = scenario::lower(&s)?;
            Ok((Source::Scenario(Box::new(s)), input))
        }
        Format::Graph => {
            let (g, input) = graph::read_text(text, origin)?;
            Ok((Source::Graph(g), input))
        }
        Format::Ros1Bag | Format::Mcap | Format::Ros2Sqlite | Format::OvEval => {
            Err(not_a_plan(origin, format))
        }
    }
}

/// A robot log is streamed into a log summary ([`log::read_located`]), not opened as an
/// [`Input`]: the application routes it by [`Format::kind`].
fn not_a_plan(file: &str, format: Format) -> InputError {
    InputError::Format {
        file: file.to_owned(),
        message: format!(
            "a {} is a robot log, read by `posecov FILE`, `report` and `check`; it has no scenario to edit or evaluate",
            format.name()
        ),
    }
}

/// Evaluation settings an input file gives (each validated; the command line overrides).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FileSettings {
    /// Seed of every random draw.
    pub seed: Option<u64>,
    /// Monte Carlo samples.
    pub samples: Option<u64>,
    /// Probability inside drawn regions.
    pub confidence: Option<crate::uncertain::Confidence>,
    /// Methods to compare.
    pub methods: Vec<Method>,
    /// Sigma-point parameters (`[methods.sigma_points]`), if given.
    pub sigma_points: Option<crate::propagate::sigma_point::Unscented>,
    /// Which steps of long propagations keep numbers, particles and Monte Carlo statistics
    /// (a pose graph's: [`crate::plan::StepPolicy::GRAPH`]); `None`: the default.
    pub steps: Option<crate::plan::StepPolicy>,
}

/// A checked input: the plan to evaluate and what the file says about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// Title, description, source.
    pub about: About,
    /// What to evaluate.
    pub plan: AnyPlan,
    /// The file's evaluation settings.
    pub defaults: FileSettings,
    /// The file's drawing choices.
    pub draw: DrawChoices,
}
