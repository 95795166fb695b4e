//! A log read only up to a cut or a damage ([`LogCut`]): everything before it was read.

use serde::Serialize;

/// Where and why the read of a log stopped before the file's end (a ROS 1 bag cut short
/// inside a chunk, or without an index, read chunk by chunk): every whole chunk before it was
/// read, and is drawn, counted and reported.
///
/// ```
/// use posecov::plan::log::LogCut;
/// let cut = LogCut { reason: "cut".into(), at_byte: 10, file_bytes: 20, chunks_read: 1 };
/// assert!(cut.at_byte < cut.file_bytes);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogCut {
    /// Why, in the log's words (which chunk, at which byte, what is wrong).
    pub reason: String,
    /// The byte at which the read stopped.
    pub at_byte: u64,
    /// The file's length in bytes.
    pub file_bytes: u64,
    /// Whole chunks read before it.
    pub chunks_read: u64,
}
