//! g2o / GTSAM text pose graphs: vertices (pose estimates) and edges (relative measurements
//! with information matrices) in, a checked [`Input`] out.
//!
//! What is evaluated and drawn:
//! - the **odometry chain**: the edges between consecutive vertex ids (k, k+1), from the
//!   first vertex's estimate, propagated as [`Op::Odometry`](crate::plan::Op::Odometry) with
//!   each edge's own covariance (first order and Monte Carlo): the banana grows along the
//!   chain on the `step` timeline (step k = vertex first + k);
//! - the **vertex estimates** of the file as axes (`v<id>`: at most 300, evenly chosen, plus
//!   the drawn loop closures' ends; drawn as one batch of frames);
//! - each **loop closure** (every other edge i → j; at most [`MAX_LOOP_CLOSURES`], evenly
//!   chosen) as a line between the two estimates and the pose it predicts for j, X_i · Z with
//!   Z's uncertainty (`v<j>_via_v<i>`).
//!
//! The edge covariance is posecov's right-perturbation Σ over [ρ; θ] — for `EDGE_SE3:QUAT`
//! with the rotation block scaled from the quaternion's vector part, see [`convention`] and
//! [CONVENTIONS §10](crate::conventions#10-pose-graphs-g2o-and-gtsam).
//!
//! ```
//! use posecov::input::graph::read_text;
//! let text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\n";
//! let (graph, input) = read_text(text, "g.g2o").unwrap();
//! assert_eq!(graph.summary().vertices, 2);
//! assert!(input.about.title.contains("g.g2o"));
//! let e = read_text(&text.replace(" 400", " -400"), "g.g2o").unwrap_err().to_string();
//! assert!(e.starts_with("g.g2o:3:"), "{e}");
//! ```

use std::path::Path;

use super::{Input, InputError, Locator};
use crate::plan::choices::GraphCounts;

pub mod bundled;
pub mod convention;
mod lower;
pub mod parse;
mod problem;

pub use lower::MAX_LOOP_CLOSURES;

/// Largest graph file read (bytes); larger ones are refused before reading.
pub const MAX_FILE_BYTES: u64 = 256 * 1024 * 1024;

/// A read graph file: where its records are (to locate later errors) and what it holds.
#[derive(Debug, Clone)]
pub struct Graph {
    locator: Locator,
    /// The line of the edge each plan operation comes from.
    operation_lines: Vec<usize>,
    summary: GraphCounts,
}

impl Graph {
    /// What the file holds.
    pub fn summary(&self) -> &GraphCounts {
        &self.summary
    }

    /// An error about plan operation `index`, at the line of the edge it comes from, or
    /// about the file as a whole.
    ///
    /// ```
    /// use posecov::input::graph::read_text;
    /// let text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 400\n";
    /// let (graph, _) = read_text(text, "g.g2o").unwrap();
    /// assert!(graph.operation_error(Some(0), "overflow").to_string().starts_with("g.g2o:3:1: EDGE_SE2: overflow"));
    /// ```
    pub fn operation_error(&self, index: Option<usize>, message: impl Into<String>) -> InputError {
        match index.and_then(|i| self.operation_lines.get(i)) {
            Some(&line) => {
                let start = line_offset(self.locator.text(), line);
                let tag = self.locator.text()[start..]
                    .split_whitespace()
                    .next()
                    .unwrap_or("edge")
                    .to_owned();
                self.locator.error(start..start, &tag, message)
            }
            None => self.locator.error(0..0, "file", message),
        }
    }
}

/// Byte offset of the start of 1-based `line`.
fn line_offset(text: &str, line: usize) -> usize {
    text.split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum()
}

/// Reads and checks a graph file (refused beyond [`MAX_FILE_BYTES`]).
///
/// ```
/// let e = posecov::input::graph::read_file(std::path::Path::new("/no/such.g2o")).unwrap_err();
/// assert!(e.to_string().starts_with("/no/such.g2o: cannot read input"), "{e}");
/// ```
pub fn read_file(path: &Path) -> Result<(Graph, Input), InputError> {
    let file = path.display().to_string();
    let read_error = |e: std::io::Error| InputError::Read {
        path: file.clone(),
        reason: e.to_string(),
    };
    let size = std::fs::metadata(path).map_err(read_error)?.len();
    if size > MAX_FILE_BYTES {
        return Err(InputError::Format {
            file,
            message: format!(
                "{size} bytes is larger than the {} MiB posecov reads as a pose graph",
                MAX_FILE_BYTES / (1024 * 1024)
            ),
        });
    }
    let bytes = std::fs::read(path).map_err(read_error)?;
    if let Some(located) = super::not_text(&file, &bytes, "a g2o / GTSAM graph") {
        return Err(located);
    }
    let text = String::from_utf8(bytes).unwrap_or_default();
    read_text(&text, &file)
}

/// Parses and checks graph text; `origin` names the file in messages.
///
/// See the [module docs](self) for an example.
pub fn read_text(text: &str, origin: &str) -> Result<(Graph, Input), InputError> {
    // A byte-order mark some editors write is not part of the first tag.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let locator = Locator::new(origin, text);
    let records = parse::read_records(&locator)?;
    let (input, operation_lines, summary) = lower::lower(&locator, &records)?;
    Ok((
        Graph {
            locator,
            operation_lines,
            summary,
        },
        input,
    ))
}
