//! Scenario files: TOML in, a checked [`Input`](crate::input::Input) out.
//!
//! A scenario names poses (mean + optional covariance) and the operations applied to them
//! (compose, invert, change frame, odometry, fusion, …), the methods to compare and what to
//! draw. [`Scenario::parse`] reads the TOML (syntax, types, unknown keys); [`lower`] checks
//! everything else and produces the typed plan. Every error is reported as
//! `file:line:column: key: message` with the offending source line.
//!
//! ```
//! use posecov::input::scenario::{Scenario, lower};
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
//! assert!(lower(&s).is_ok());
//! // Values are checked by the lowering, with their place in the file.
//! let bad = Scenario::parse(&text.replace("0.2]", "nan]"), "demo.toml").unwrap();
//! let err = lower(&bad).unwrap_err();
//! assert!(err.to_string().starts_with("demo.toml:8:"), "{err}");
//! ```

use std::path::Path;

pub use crate::input::{InputError, Locator};

pub mod bundled;
mod lower;
mod parse_errors;
pub mod schema;
mod values;

pub use lower::{OPERATION_KINDS, OperationKind, lower};
pub use schema::{GroupName, ScenarioFile};
pub use values::{SpecGroup, ValueError};

/// Scenario errors are [`InputError`]s: located at `file:line:column: key`.
pub type ScenarioError = InputError;

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
    /// TOML syntax errors are reported with their location and key, in the file's words.
    /// Semantic checks (covariances, names, operation arguments) happen in [`lower`], with
    /// locations too.
    ///
    /// ```
    /// use posecov::input::scenario::Scenario;
    /// let e = Scenario::parse("[scenario]\ntitle = 'x'\ngroup = 'se4'\n", "x.toml").unwrap_err();
    /// assert!(e.to_string().starts_with("x.toml:3:9: scenario.group:"), "{e}");
    /// let e = Scenario::parse("[scenario]\ntitle = 'x'\ngroup = 'se2'\nsamples = -5\n", "x.toml").unwrap_err();
    /// assert!(e.to_string().starts_with("x.toml:4:11: scenario.samples: -5 is not a whole number ≥ 0"), "{e}");
    /// ```
    pub fn parse(text: &str, origin: &str) -> Result<Self, ScenarioError> {
        let locator = Locator::new(origin, text);
        let file: ScenarioFile = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            let field = parse_errors::key_at(text, span.start);
            locator.error(span, &field, parse_errors::in_file_words(e.message()))
        })?;
        Ok(Self { file, locator })
    }

    /// A bundled scenario by name (see [`bundled::BUNDLED`]), or else a file path. An unknown
    /// name that is not a file either gets an error listing the bundled names.
    ///
    /// ```
    /// use posecov::input::scenario::Scenario;
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

    /// An error about operation `index` (at its `kind`, key `operation[index]`), or about the
    /// file as a whole when `index` is `None` or out of range.
    ///
    /// ```
    /// use posecov::input::scenario::Scenario;
    /// let s = Scenario::parse("[scenario]\ntitle='t'\ngroup='so3'\n[[operation]]\nkind='euler_vs_exp'\noutput='r'\nrate=[0,0,1]\ndt=0.1\nsteps=3\n", "t.toml").unwrap();
    /// assert!(s.operation_error(Some(0), "too big").to_string().starts_with("t.toml:5:6: operation[0]: too big"));
    /// assert!(s.operation_error(None, "odd").to_string().starts_with("t.toml:1:1: file: odd"));
    /// ```
    pub fn operation_error(
        &self,
        index: Option<usize>,
        message: impl Into<String>,
    ) -> ScenarioError {
        match index.and_then(|i| self.file.operations.get(i).map(|op| (i, op))) {
            Some((i, op)) => {
                self.locator
                    .error(op.kind.span(), &format!("operation[{i}]"), message)
            }
            None => self.locator.error(0..0, "file", message),
        }
    }

    /// Reads and parses a scenario file.
    ///
    /// ```
    /// use posecov::input::scenario::Scenario;
    /// let e = Scenario::load(std::path::Path::new("/no/such/file.toml")).unwrap_err();
    /// assert!(e.to_string().starts_with("/no/such/file.toml: cannot read input"));
    /// ```
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| ScenarioError::Read {
            path: file.clone(),
            reason: e.to_string(),
        })?;
        if let Some(located) = crate::input::not_text(&file, &bytes, "a TOML scenario") {
            return Err(located);
        }
        Self::parse(&String::from_utf8(bytes).unwrap_or_default(), &file)
    }
}
