//! Scenario files: TOML in, validated poses and operations out.
//!
//! A scenario names poses (mean + optional covariance) and the operations applied to them
//! (compose, invert, change frame, odometry, fusion, …), the methods to compare and what to
//! draw. [`Scenario::parse`] checks everything a user can get wrong and reports it as
//! `file:line:column: field: message` with the offending source line.
//!
//! ```
//! use posecov::scenario::Scenario;
//! let text = r#"
//! [scenario]
//! title = "demo"
//! group = "se2"
//! [[pose]]
//! name = "world_from_robot"
//! mean = { xy_theta = [1.0, 0.0, 0.0] }
//! cov = { std = [0.1, 0.1, 0.2] }
//! "#;
//! let s = Scenario::parse(text, "demo.toml").unwrap();
//! assert_eq!(s.file.poses.len(), 1);
//! // Values are checked when the scenario is evaluated, with their place in the file.
//! let bad = Scenario::parse(&text.replace("0.2]", "nan]"), "demo.toml").unwrap();
//! let err = posecov::scenario::eval::evaluate(&bad, &Default::default()).unwrap_err();
//! assert!(err.to_string().starts_with("demo.toml:8:"), "{err}");
//! ```

use std::fmt;
use std::ops::Range;
use std::path::Path;

pub mod bundled;
pub mod eval;
pub mod groups;
pub mod model;
pub mod schema;
mod spec;

pub use schema::{GroupName, ScenarioFile};
pub use spec::SpecGroup;

/// A scenario file could not be read, parsed or validated.
#[derive(Debug, Clone, PartialEq)]
pub enum ScenarioError {
    /// The file could not be read.
    Read {
        /// The path given.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
    /// Something in the file is wrong, at a known place.
    At {
        /// File name as given.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (in characters).
        column: usize,
        /// The TOML key or section concerned (e.g. `pose[2].cov`).
        field: String,
        /// What is wrong and what is expected.
        message: String,
        /// The source line, for context.
        source_line: String,
    },
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScenarioError::Read { path, reason } => {
                write!(f, "{path}: cannot read scenario: {reason}")
            }
            ScenarioError::At {
                file,
                line,
                column,
                field,
                message,
                source_line,
            } => {
                write!(f, "{file}:{line}:{column}: {field}: {message}")?;
                if !source_line.is_empty() {
                    let pad = " ".repeat(column.saturating_sub(1));
                    write!(f, "\n  | {source_line}\n  | {pad}^")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for ScenarioError {}

/// Maps byte spans of one source text to `line:column` errors.
#[derive(Debug, Clone)]
pub struct Locator {
    file: String,
    text: String,
}

impl Locator {
    /// A locator for `text` read from `file`.
    ///
    /// ```
    /// use posecov::scenario::Locator;
    /// let l = Locator::new("a.toml", "x = 1\ny = 2\n");
    /// assert_eq!(l.error(6..7, "y", "bad").to_string().lines().next().unwrap(), "a.toml:2:1: y: bad");
    /// ```
    pub fn new(file: &str, text: &str) -> Self {
        Self {
            file: file.to_owned(),
            text: text.to_owned(),
        }
    }

    /// An error at the start of `span`.
    ///
    /// ```
    /// use posecov::scenario::Locator;
    /// let e = Locator::new("f.toml", "abc").error(1..2, "k", "m");
    /// assert!(e.to_string().starts_with("f.toml:1:2: k: m"));
    /// ```
    pub fn error(
        &self,
        span: Range<usize>,
        field: &str,
        message: impl Into<String>,
    ) -> ScenarioError {
        let start = span.start.min(self.text.len());
        let before = &self.text[..floor_char_boundary(&self.text, start)];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = before[line_start..].chars().count() + 1;
        let source_line = self.text[line_start..]
            .lines()
            .next()
            .unwrap_or("")
            .to_owned();
        ScenarioError::At {
            file: self.file.clone(),
            line,
            column,
            field: field.to_owned(),
            message: message.into(),
            source_line,
        }
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// A parsed, syntactically valid scenario with its source (for error locations).
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The file's contents as typed structures.
    pub file: ScenarioFile,
    /// Maps spans back to `file:line:column`.
    pub locator: Locator,
}

impl Scenario {
    /// Parses TOML text; `origin` names the file in messages. Unknown keys, wrong types and
    /// TOML syntax errors are reported with their location. Semantic checks (covariances,
    /// names, operation arguments) happen in [`eval::evaluate`], with locations too.
    ///
    /// ```
    /// use posecov::scenario::Scenario;
    /// let e = Scenario::parse("[scenario]\ntitle = 'x'\ngroup = 'se4'\n", "x.toml").unwrap_err();
    /// assert!(e.to_string().contains("x.toml:3:"), "{e}");
    /// ```
    pub fn parse(text: &str, origin: &str) -> Result<Self, ScenarioError> {
        let locator = Locator::new(origin, text);
        let file: ScenarioFile = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            locator.error(span, "toml", e.message().trim().to_owned())
        })?;
        Ok(Self { file, locator })
    }

    /// A bundled scenario by name (see [`bundled::BUNDLED`]), or else a file path. An unknown
    /// name that is not a file either gets an error listing the bundled names.
    ///
    /// ```
    /// use posecov::scenario::Scenario;
    /// assert!(Scenario::load_any("so3_sampling").is_ok());
    /// let e = Scenario::load_any("no_such_scenario").unwrap_err().to_string();
    /// assert!(e.contains("camera_on_robot"), "{e}");
    /// ```
    pub fn load_any(name_or_path: &str) -> Result<Self, ScenarioError> {
        let path = Path::new(name_or_path);
        if path.exists() {
            return Self::load(path);
        }
        match bundled::find(name_or_path) {
            Some(b) => Self::parse(b.text, &format!("{}.toml (bundled)", b.name)),
            None => {
                let names: Vec<&str> = bundled::BUNDLED.iter().map(|b| b.name).collect();
                Err(ScenarioError::Read {
                    path: name_or_path.to_owned(),
                    reason: format!(
                        "no such file, and no bundled scenario of that name (bundled: {})",
                        names.join(", ")
                    ),
                })
            }
        }
    }

    /// Reads and parses a scenario file.
    ///
    /// ```
    /// use posecov::scenario::Scenario;
    /// let e = Scenario::load(std::path::Path::new("/no/such/file.toml")).unwrap_err();
    /// assert!(e.to_string().starts_with("/no/such/file.toml: cannot read scenario"));
    /// ```
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError::Read {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Self::parse(&text, &path.display().to_string())
    }
}
