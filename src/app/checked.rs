//! What `posecov check` found, for one input of any kind: the value the printing command
//! ([`super::commands::check`]) and a log's checker ([`super::log::check`]) both return.

use super::EXIT_FAILED;

/// What `posecov check` found: one line for stdout, and the first defect of each topic of a
/// log for stderr (none for a scenario or a graph, whose errors stop the check).
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    /// `NAME: ok (…)` or `NAME: defects on …`.
    pub line: String,
    /// One line per topic with a defect not `--allow`ed.
    pub defects: Vec<String>,
    /// Lines for stderr that are not defects: what a live stream did besides carrying
    /// messages (damaged frames skipped, connections lost), each naming its URL.
    pub notes: Vec<String>,
}

impl Checked {
    /// 0, or [`EXIT_FAILED`] when a defect was found.
    pub fn exit_code(&self) -> u8 {
        if self.defects.is_empty() {
            0
        } else {
            EXIT_FAILED
        }
    }
}
