//! Errors of every input format, located in the user's file: `file:line:column: field:
//! message` for text formats (with the offending source line), `file: place: message` for
//! binary ones (a bag's topic and message), `file: message` for the file as a whole.

use std::fmt;
use std::ops::Range;

/// An input file could not be read, recognised, parsed or validated.
#[derive(Debug, Clone, PartialEq)]
pub enum InputError {
    /// The file could not be read (or no file or bundled example has that name).
    Read {
        /// The path given.
        path: String,
        /// The operating system's reason, or what was looked for.
        reason: String,
    },
    /// The file as a whole: not a known format, extension and content disagree, too large, a
    /// format this build cannot read yet.
    Format {
        /// File name as given.
        file: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// Something in a text file is wrong, at a known place.
    At {
        /// File name as given.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (in characters).
        column: usize,
        /// The key, section or field concerned (e.g. `pose[2].cov`, `EDGE_SE2.information`).
        field: String,
        /// What is wrong and what is expected.
        message: String,
        /// The source line, for context.
        source_line: String,
    },
    /// Something in a binary file is wrong, at a place named in the format's words.
    In {
        /// File name as given.
        file: String,
        /// Where, e.g. `topic /odom, message 12 (log time 3.25 s)`.
        place: String,
        /// What is wrong and what is expected.
        message: String,
    },
}

impl std::error::Error for InputError {}

impl InputError {
    /// The same error about the file named `to` instead of `from` (a bundled input read
    /// through a temporary file is named as the user knows it).
    ///
    /// ```
    /// use posecov::input::InputError;
    /// let e = InputError::Format { file: "/tmp/x".into(), message: "cut".into() };
    /// assert_eq!(e.renamed("/tmp/x", "a.bag (bundled)").to_string(), "a.bag (bundled): cut");
    /// ```
    pub fn renamed(mut self, from: &str, to: &str) -> InputError {
        let (InputError::Read { path: file, .. }
        | InputError::Format { file, .. }
        | InputError::At { file, .. }
        | InputError::In { file, .. }) = &mut self;
        if file == from {
            *file = to.to_owned();
        }
        self
    }

    /// The file it names, and what follows its name (`file: reason`) when the place is not a
    /// line and column (`file:line:column: …` has no separate reason): for a line per input
    /// that names the input first itself.
    ///
    /// ```
    /// use posecov::input::InputError;
    /// let e = InputError::In { file: "a.bag".into(), place: "topic /odom".into(), message: "cut".into() };
    /// assert_eq!(e.reason(), ("a.bag", Some("topic /odom: cut".to_owned())));
    /// ```
    pub fn reason(&self) -> (&str, Option<String>) {
        match self {
            InputError::Read { path, reason } => {
                (path, Some(format!("cannot read input: {reason}")))
            }
            InputError::Format { file, message } => (file, Some(message.clone())),
            InputError::In {
                file,
                place,
                message,
            } => (file, Some(format!("{place}: {message}"))),
            InputError::At { file, .. } => (file, None),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::Read { path, reason } => {
                write!(f, "{path}: cannot read input: {reason}")
            }
            InputError::Format { file, message } => write!(f, "{file}: {message}"),
            InputError::In {
                file,
                place,
                message,
            } => write!(f, "{file}: {place}: {message}"),
            InputError::At {
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
    /// use posecov::input::Locator;
    /// let l = Locator::new("a.toml", "x = 1\ny = 2\n");
    /// assert_eq!(l.error(6..7, "y", "bad").to_string().lines().next().unwrap(), "a.toml:2:1: y: bad");
    /// ```
    pub fn new(file: &str, text: &str) -> Self {
        Self {
            file: file.to_owned(),
            text: text.to_owned(),
        }
    }

    /// The file name as given.
    ///
    /// ```
    /// assert_eq!(posecov::input::Locator::new("a.g2o", "").file(), "a.g2o");
    /// ```
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The whole text.
    ///
    /// ```
    /// assert_eq!(posecov::input::Locator::new("a.g2o", "x").text(), "x");
    /// ```
    pub fn text(&self) -> &str {
        &self.text
    }

    /// An error at the start of `span`.
    ///
    /// ```
    /// use posecov::input::Locator;
    /// let e = Locator::new("f.toml", "abc").error(1..2, "k", "m");
    /// assert!(e.to_string().starts_with("f.toml:1:2: k: m"));
    /// ```
    pub fn error(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> InputError {
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
        InputError::At {
            file: self.file.clone(),
            line,
            column,
            field: field.to_owned(),
            message: message.into(),
            source_line,
        }
    }
}

/// The first byte of `bytes` that is not text (a NUL byte, or a byte that is not valid
/// UTF-8, including a sequence cut short), located at its line and column, or `None` when all
/// of `bytes` is text. `what` names the format ("a TOML scenario").
///
/// ```
/// use posecov::input::not_text;
/// let e = not_text("a.toml", b"x = 1\ny = \xff\n", "a TOML scenario").unwrap();
/// assert_eq!(e.to_string().lines().next().unwrap(), "a.toml:2:5: file: byte 0xFF is not UTF-8 text; a TOML scenario is text");
/// assert!(not_text("a.toml", b"x = 1\n", "a TOML scenario").is_none());
/// ```
pub fn not_text(file: &str, bytes: &[u8], what: &str) -> Option<InputError> {
    let (valid, kind) = match std::str::from_utf8(bytes) {
        Ok(_) => (bytes.len(), None),
        Err(e) if e.error_len().is_none() => (
            e.valid_up_to(),
            Some("a UTF-8 sequence cut short at the end of the file"),
        ),
        Err(e) => (e.valid_up_to(), Some("")),
    };
    let nul = bytes[..valid].iter().position(|&b| b == 0);
    let (offset, message) = match (nul, kind) {
        (Some(i), _) => (i, "a NUL byte is not text".to_owned()),
        (None, None) => return None,
        (None, Some("")) => (
            valid,
            format!("byte 0x{:02X} is not UTF-8 text", bytes[valid]),
        ),
        (None, Some(k)) => (valid, format!("{k} is not UTF-8 text")),
    };
    let text = std::str::from_utf8(&bytes[..offset]).unwrap_or_default();
    let line_start = text.rfind('\n').map_or(0, |i| i + 1);
    Some(InputError::At {
        file: file.to_owned(),
        line: text.matches('\n').count() + 1,
        column: text[line_start..].chars().count() + 1,
        field: "file".to_owned(),
        message: format!("{message}; {what} is text"),
        source_line: String::new(),
    })
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}
