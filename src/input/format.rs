//! Which format a file is: by its content (magic bytes, first token) and its extension. The
//! two must agree; a file that is none of the formats gets an error naming it and what was
//! expected.
//!
//! | format | extension | content |
//! |---|---|---|
//! | TOML scenario | `.toml` | text whose first line that is not a comment is a `[table]` or `key = value` |
//! | ROS 1 bag | `.bag` | starts with `#ROSBAG V2.0\n` |
//! | MCAP (ROS 2 bag) | `.mcap` | starts with `\x89MCAP0\r\n` |
//! | ROS 2 bag in SQLite | `.db3` | starts with `SQLite format 3\0` |
//! | ROS 2 bag directory | (a directory) | holds `metadata.yaml`; its `storage_identifier` says `sqlite3` (a ROS 2 SQLite bag) or `mcap` (MCAP) |
//! | g2o / GTSAM / TORO pose graph | `.g2o`, `.txt`, `.graph` | text whose first token that is not a comment is `VERTEX_SE2`, `EDGE_SE2`, `VERTEX_SE3:QUAT`, `EDGE_SE3:QUAT`, `VERTEX2` or `EDGE2` |
//! | ov_eval trajectory with covariance | `.txt` | text whose first line that is not a comment has 20 numbers, or 8 after ov_eval's header comment ([`ov_eval::recognise`](super::log::ov_eval::recognise)) |

use std::io::Read as _;
use std::path::Path;

use serde::Serialize;

use super::InputError;

/// An input format posecov recognises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Format {
    /// A TOML scenario ([`crate::input::scenario`]).
    Scenario,
    /// A ROS 1 bag (version 2.0).
    Ros1Bag,
    /// An MCAP file (ROS 2 bags), or a ROS 2 bag directory in MCAP storage.
    Mcap,
    /// A ROS 2 bag in SQLite storage: a `.db3` file, or a bag directory (`metadata.yaml`
    /// naming `sqlite3` storage and its `.db3` files).
    Ros2Sqlite,
    /// A g2o / GTSAM text pose graph ([`crate::input::graph`]).
    Graph,
    /// An OpenVINS `ov_eval` text trajectory with covariance
    /// ([`crate::input::log::ov_eval`]): read as a log of one topic.
    OvEval,
}

/// What posecov does with an input: evaluate a typed plan, or stream a robot log. Decided
/// once, from the [`Format`] ([`Format::kind`]); the application routes on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputKind {
    /// A scenario or a pose graph: read whole into a [`Plan`](crate::plan::Plan), evaluated
    /// with Monte Carlo and the analytic methods.
    Plan,
    /// A robot log (ROS 1 bag, MCAP): streamed, message by message, into a bounded log
    /// summary ([`crate::plan::log`]).
    Log,
}

impl InputKind {
    /// One input of the kind, in words ("this input is a robot log").
    ///
    /// ```
    /// assert_eq!(posecov::input::format::InputKind::Plan.name(), "a scenario or a pose graph");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Plan => "a scenario or a pose graph",
            InputKind::Log => "a robot log",
        }
    }

    /// The kind in words, for messages ("applies to robot logs").
    ///
    /// ```
    /// assert_eq!(posecov::input::format::InputKind::Log.name_plural(), "robot logs (ROS 1 bags, MCAP files, ROS 2 SQLite bags)");
    /// ```
    pub fn name_plural(self) -> &'static str {
        match self {
            InputKind::Plan => "scenarios and pose graphs",
            InputKind::Log => "robot logs (ROS 1 bags, MCAP files, ROS 2 SQLite bags)",
        }
    }
}

/// ROS 1 bag magic (format 2.0).
pub const ROSBAG_MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// MCAP magic.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// SQLite's magic (ROS 2's `.db3` bag storage, Humble's default).
pub const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";
/// The g2o / GTSAM records posecov reads (any of them first identifies a graph).
pub const GRAPH_TAGS: &[&str] = &[
    "VERTEX_SE2",
    "EDGE_SE2",
    "VERTEX_SE3:QUAT",
    "EDGE_SE3:QUAT",
    "VERTEX2",
    "EDGE2",
];
/// How many leading bytes the content is judged by.
pub const SNIFF_BYTES: usize = 64 * 1024;

impl Format {
    /// Every format, in the order `posecov list` shows them.
    pub const ALL: [Format; 6] = [
        Format::Scenario,
        Format::Graph,
        Format::Ros1Bag,
        Format::Mcap,
        Format::Ros2Sqlite,
        Format::OvEval,
    ];

    /// The format in words.
    ///
    /// ```
    /// use posecov::input::Format;
    /// assert_eq!(Format::Graph.name(), "g2o / GTSAM pose graph");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Format::Scenario => "TOML scenario",
            Format::Ros1Bag => "ROS 1 bag",
            Format::Mcap => "MCAP file (ROS 2 bag)",
            Format::Ros2Sqlite => "ROS 2 bag in SQLite (.db3)",
            Format::Graph => "g2o / GTSAM pose graph",
            Format::OvEval => "ov_eval trajectory with covariance",
        }
    }

    /// Whether the format is a plan or a robot log: the one place that decides.
    ///
    /// ```
    /// use posecov::input::{Format, format::InputKind};
    /// assert_eq!(Format::Mcap.kind(), InputKind::Log);
    /// assert_eq!(Format::Graph.kind(), InputKind::Plan);
    /// ```
    pub fn kind(self) -> InputKind {
        match self {
            Format::Scenario | Format::Graph => InputKind::Plan,
            Format::Ros1Bag | Format::Mcap | Format::Ros2Sqlite | Format::OvEval => InputKind::Log,
        }
    }

    /// The format in words, plural (a heading of `posecov list`).
    ///
    /// ```
    /// use posecov::input::Format;
    /// assert_eq!(Format::Mcap.name_plural(), "MCAP files (ROS 2 bags)");
    /// ```
    pub fn name_plural(self) -> &'static str {
        match self {
            Format::Scenario => "TOML scenarios",
            Format::Ros1Bag => "ROS 1 bags",
            Format::Mcap => "MCAP files (ROS 2 bags)",
            Format::Ros2Sqlite => "ROS 2 bags in SQLite (.db3)",
            Format::Graph => "g2o / GTSAM pose graphs",
            Format::OvEval => "ov_eval trajectories with covariance",
        }
    }

    /// The file extensions of the format (lower case, without the dot).
    ///
    /// ```
    /// use posecov::input::Format;
    /// assert_eq!(Format::Graph.extensions(), &["g2o", "txt", "graph"]);
    /// ```
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Format::Scenario => &["toml"],
            Format::Ros1Bag => &["bag"],
            Format::Mcap => &["mcap"],
            Format::Ros2Sqlite => &["db3"],
            Format::Graph => &["g2o", "txt", "graph"],
            Format::OvEval => &["txt"],
        }
    }

    /// The format an extension stands for (case-insensitive), if any; `.txt`, which graphs
    /// and ov_eval trajectories share, stands for a graph (content tells them apart).
    ///
    /// ```
    /// use posecov::input::Format;
    /// assert_eq!(Format::from_extension("BAG"), Some(Format::Ros1Bag));
    /// assert_eq!(Format::from_extension("csv"), None);
    /// ```
    pub fn from_extension(extension: &str) -> Option<Format> {
        let extension = extension.to_ascii_lowercase();
        Format::ALL
            .into_iter()
            .find(|f| f.extensions().contains(&extension.as_str()))
    }

    /// The format the leading bytes of a file show, if any: the bag magics, else the first
    /// token of text that is not a `#` comment (a graph tag, or a TOML table or key).
    ///
    /// ```
    /// use posecov::input::Format;
    /// assert_eq!(Format::from_content(b"#ROSBAG V2.0\n..."), Some(Format::Ros1Bag));
    /// assert_eq!(Format::from_content(b"\x89MCAP0\r\n..."), Some(Format::Mcap));
    /// assert_eq!(Format::from_content(b"SQLite format 3\0..."), Some(Format::Ros2Sqlite));
    /// assert_eq!(Format::from_content(b"# a graph\nVERTEX_SE2 0 0 0 0\n"), Some(Format::Graph));
    /// assert_eq!(Format::from_content(b"# a scenario\n[scenario]\n"), Some(Format::Scenario));
    /// assert_eq!(Format::from_content(b"1.5 0 0 0 0 0 0 1 1 0 0 1 0 1 1 0 0 1 0 1\n"), Some(Format::OvEval));
    /// assert_eq!(Format::from_content(b"\x00\x01binary"), None);
    /// ```
    pub fn from_content(head: &[u8]) -> Option<Format> {
        if head.starts_with(ROSBAG_MAGIC) {
            return Some(Format::Ros1Bag);
        }
        if head.starts_with(MCAP_MAGIC) {
            return Some(Format::Mcap);
        }
        if head.starts_with(SQLITE_MAGIC) {
            return Some(Format::Ros2Sqlite);
        }
        let line = first_text_line(head)?;
        let token = line.split_whitespace().next().unwrap_or("");
        if GRAPH_TAGS.contains(&token) {
            Some(Format::Graph)
        } else if super::log::ov_eval::recognise(head) {
            Some(Format::OvEval)
        } else if line.starts_with('[') || line.contains('=') {
            Some(Format::Scenario)
        } else {
            None
        }
    }
}

/// The first line of text that is neither blank nor a `#` comment, if the bytes are text.
fn first_text_line(head: &[u8]) -> Option<&str> {
    if head.contains(&0) {
        return None;
    }
    let text = match std::str::from_utf8(head) {
        Ok(t) => t,
        // A multi-byte character cut at the end of the sniffed bytes is still text.
        Err(e) if e.error_len().is_none() => std::str::from_utf8(&head[..e.valid_up_to()]).ok()?,
        Err(_) => return None,
    };
    text.strip_prefix('\u{feff}')
        .unwrap_or(text)
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
}

/// What the content looks like, for messages: the format, or the first bytes.
fn describe(head: &[u8]) -> String {
    match Format::from_content(head) {
        Some(f) => format!("its content is a {}", f.name()),
        None if head.is_empty() => "it is empty".to_owned(),
        None => {
            let shown: String = String::from_utf8_lossy(&head[..head.len().min(16)])
                .chars()
                .map(|c| if c.is_control() { '·' } else { c })
                .collect();
            format!("its content is none of these (it starts with {shown:?})")
        }
    }
}

fn expected() -> String {
    let list: Vec<String> = Format::ALL
        .iter()
        .map(|f| {
            let ext: Vec<String> = f.extensions().iter().map(|e| format!(".{e}")).collect();
            format!("{} ({})", f.name(), ext.join(", "))
        })
        .collect();
    list.join(", ")
}

/// The format of a file named `file` whose first bytes are `head` (at most [`SNIFF_BYTES`]).
/// Content decides when the extension is unknown; a known extension must agree with
/// recognisable content. Text whose first token is not recognised keeps its extension's
/// format, so that the format's own parser names the line that is wrong.
///
/// ```
/// use posecov::input::{Format, format::detect};
/// assert_eq!(detect("a.g2o", b"VERTEX2 0 0 0 0\n").unwrap(), Format::Graph);
/// assert_eq!(detect("noext", b"EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n").unwrap(), Format::Graph);
/// let e = detect("a.bag", b"\x89MCAP0\r\n").unwrap_err().to_string();
/// assert!(e.starts_with("a.bag: the extension .bag says ROS 1 bag, but its content is a MCAP file"), "{e}");
/// assert_eq!(detect("run_0.db3", b"SQLite format 3\0...").unwrap(), Format::Ros2Sqlite);
/// assert_eq!(detect("est.txt", b"1 0 0 0 0 0 0 1 1 0 0 1 0 1 1 0 0 1 0 1\n").unwrap(), Format::OvEval);
/// let e = detect("notes.csv", b"1,2,3\n").unwrap_err().to_string();
/// assert!(e.starts_with("notes.csv: not a file posecov reads"), "{e}");
/// ```
pub fn detect(file: &str, head: &[u8]) -> Result<Format, InputError> {
    let by_extension = Path::new(file)
        .extension()
        .and_then(|e| e.to_str())
        .and_then(Format::from_extension);
    let by_content = Format::from_content(head);
    let extension = Path::new(file)
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    let error = |message: String| InputError::Format {
        file: file.to_owned(),
        message,
    };
    match (by_extension, by_content) {
        (Some(e), Some(c)) if e == c => Ok(e),
        // An extension two formats share (`.txt`): the content says which.
        (Some(_), Some(c))
            if c.extensions()
                .contains(&extension.to_ascii_lowercase().as_str()) =>
        {
            Ok(c)
        }
        (Some(e), Some(c)) => Err(error(format!(
            "the extension .{extension} says {}, but its content is a {} ({}); rename the file or check that it is the one you meant",
            e.name(),
            c.name(),
            what_identifies(c)
        ))),
        (None, Some(c)) => Ok(c),
        (Some(e @ (Format::Ros1Bag | Format::Mcap | Format::Ros2Sqlite)), None) => {
            Err(error(format!(
                "the extension .{extension} says {}, but {} (a {} starts with {})",
                e.name(),
                describe(head),
                e.name(),
                what_identifies(e)
            )))
        }
        (Some(e), None) => match super::not_text(file, head, &format!("a {}", e.name())) {
            // A multi-byte character cut by the sniffed length is not the file's end.
            Some(_) if head.len() == SNIFF_BYTES && first_text_line(head).is_some() => Ok(e),
            Some(located) => Err(located),
            // Text whose first token is not recognised: the format's parser names the line.
            None => Ok(e),
        },
        (None, None) => Err(error(format!(
            "not a file posecov reads: {}; expected a {}",
            describe(head),
            expected()
        ))),
    }
}

fn what_identifies(format: Format) -> &'static str {
    match format {
        Format::Ros1Bag => "`#ROSBAG V2.0`",
        Format::Mcap => "the MCAP magic `\\x89MCAP0\\r\\n`",
        Format::Ros2Sqlite => "SQLite's `SQLite format 3`",
        Format::Graph => "its first record is a g2o vertex or edge",
        Format::Scenario => "its first line is a TOML table or key",
        Format::OvEval => "its first line has 20 numbers",
    }
}

/// The format of a directory: a ROS 2 bag directory (its `metadata.yaml`'s storage, `sqlite3`
/// or `mcap`, and every file it names present), else an error saying what a directory must
/// hold to be read.
///
/// ```
/// use posecov::input::{Format, format::detect_dir};
/// let bag = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2/arc_humble");
/// assert_eq!(detect_dir(bag.as_ref()).unwrap(), Format::Ros2Sqlite);
/// let src = concat!(env!("CARGO_MANIFEST_DIR"), "/src");
/// assert!(detect_dir(src.as_ref()).unwrap_err().to_string().contains("no metadata.yaml"));
/// ```
pub fn detect_dir(dir: &Path) -> Result<Format, InputError> {
    use super::log::rosbag2::{METADATA_FILE, read_metadata};
    if !dir.join(METADATA_FILE).is_file() {
        return Err(InputError::Format {
            file: dir.display().to_string(),
            message: format!(
                "a directory with no {METADATA_FILE}: not a ROS 2 bag directory \
                 (`posecov report DIR` and `posecov check DIR` read every log in a directory)"
            ),
        });
    }
    Ok(read_metadata(dir)?.0.storage)
}

/// The first [`SNIFF_BYTES`] of a file (fewer if it is shorter).
///
/// ```
/// let e = posecov::input::format::read_head(std::path::Path::new("/no/such.g2o")).unwrap_err();
/// assert!(e.to_string().starts_with("/no/such.g2o: cannot read input:"), "{e}");
/// ```
pub fn read_head(path: &Path) -> Result<Vec<u8>, InputError> {
    let read_error = |e: std::io::Error| InputError::Read {
        path: path.display().to_string(),
        reason: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(read_error)?;
    let mut head = Vec::with_capacity(4096);
    file.take(SNIFF_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(read_error)?;
    Ok(head)
}
