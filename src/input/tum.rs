//! TUM trajectory files (the TUM RGB-D benchmark's ground-truth format, also what evo and
//! ov_eval read): one pose per line, `timestamp tx ty tz qx qy qz qw` — seconds, metres, a
//! unit quaternion in (x, y, z, w) order — separated by spaces (or commas); `#` starts a
//! comment line, blank lines are skipped. Stamps must increase. Used as a log's reference
//! (`--reference FILE`). A line of OpenVINS `ov_eval`'s 20 columns (the same 8, then the
//! covariance: [`crate::input::log::ov_eval`]) is read too, its covariance checked as numbers
//! and left aside, so that an ov_eval trajectory serves as a reference; [`parse_pose_line`]
//! is the one line reader of both.
//!
//! ```
//! use posecov::input::tum::parse_tum;
//! let samples = parse_tum("gt.txt", "# t x y z qx qy qz qw\n1.5 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0 1\n").unwrap();
//! assert_eq!((samples.len(), samples[0].stamp_ns), (2, 1_500_000_000));
//! let e = parse_tum("gt.txt", "1.5 1 2 x 0 0 0 1\n").unwrap_err();
//! assert!(e.to_string().starts_with("gt.txt:1:9: tz: `x` is not a number"), "{e}");
//! ```

use std::path::Path;

use super::InputError;
use crate::lie::So3;
use crate::plan::log::ReferenceSample;

/// The columns of a text trajectory line, in order: TUM's 8 (`timestamp tx ty tz qx qy qz
/// qw`), then OpenVINS `ov_eval`'s covariance, the upper triangles of the rotation block `Pr`
/// and the position block `Pt` ([`crate::input::log::ov_eval`]).
pub const COLUMNS: [&str; 20] = [
    "timestamp",
    "tx",
    "ty",
    "tz",
    "qx",
    "qy",
    "qz",
    "qw",
    "Pr11",
    "Pr12",
    "Pr13",
    "Pr22",
    "Pr23",
    "Pr33",
    "Pt11",
    "Pt12",
    "Pt13",
    "Pt22",
    "Pt23",
    "Pt33",
];

/// One pose line of a text trajectory (TUM's 8 columns, or ov_eval's 20), every value checked.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseLine {
    /// The stamp, nanoseconds (the first column is seconds).
    pub stamp_ns: i64,
    /// (tx, ty, tz), metres.
    pub position: [f64; 3],
    /// (qx, qy, qz, qw), a unit quaternion within 1e-3 ([`So3::try_from_quaternion_xyzw`]).
    pub orientation_xyzw: [f64; 4],
    /// ov_eval's 12 covariance values in [`COLUMNS`]' order (`Pr11` … `Pt33`), when the line
    /// has 20 columns.
    pub covariance: Option<[f64; 12]>,
    /// Each value's column in characters (0-based), for errors found later.
    pub columns: Vec<usize>,
}

/// Reads line `number` (1-based) of a text trajectory named `file`: `None` for a blank or
/// comment (`#`) line, else its 8 or 20 values, separated by spaces or commas.
///
/// Errors (file:line:column, the field and the value): another number of values, a value
/// that is not a number or not finite (a NaN stamp), a stamp beyond what nanoseconds hold
/// (±9.2e9 s), a quaternion whose norm is not 1 within 1e-3.
///
/// ```
/// use posecov::input::tum::parse_pose_line;
/// let p = parse_pose_line("gt.txt", 1, "1.5 1 2 3 0 0 0 1").unwrap().unwrap();
/// assert_eq!((p.stamp_ns, p.position, p.covariance), (1_500_000_000, [1.0, 2.0, 3.0], None));
/// assert_eq!(parse_pose_line("gt.txt", 2, "  # a comment").unwrap(), None);
/// let e = parse_pose_line("gt.txt", 3, "nan 1 2 3 0 0 0 1").unwrap_err().to_string();
/// assert!(e.starts_with("gt.txt:3:1: timestamp: `nan` is not finite"), "{e}");
/// ```
pub fn parse_pose_line(
    file: &str,
    number: usize,
    line: &str,
) -> Result<Option<PoseLine>, InputError> {
    let trimmed = line.trim_start();
    if trimmed.is_empty() || trimmed.starts_with('#') {
        return Ok(None);
    }
    let at = |column: usize, field: &str, message: String| InputError::At {
        file: file.to_owned(),
        line: number,
        column: column + 1,
        field: field.to_owned(),
        message,
        source_line: line.to_owned(),
    };
    // (column in characters, token)
    let mut tokens = Vec::with_capacity(COLUMNS.len());
    let mut start = None;
    for (column, (i, c)) in line.char_indices().enumerate() {
        let separator = c.is_whitespace() || c == ',';
        match (separator, start) {
            (false, None) => start = Some((column, i)),
            (true, Some((col, from))) => {
                tokens.push((col, &line[from..i]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some((col, from)) = start {
        tokens.push((col, &line[from..]));
    }
    if tokens.len() != 8 && tokens.len() != COLUMNS.len() {
        return Err(at(
            0,
            "line",
            format!(
                "{} values; a line has 8 (timestamp tx ty tz qx qy qz qw: TUM) or 20 (those, then \
                 ov_eval's covariance Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23 Pt33)",
                tokens.len()
            ),
        ));
    }
    let mut values = [0.0; 20];
    for (k, (column, token)) in tokens.iter().enumerate() {
        let value: f64 = token
            .parse()
            .map_err(|_| at(*column, COLUMNS[k], format!("`{token}` is not a number")))?;
        if !value.is_finite() {
            return Err(at(*column, COLUMNS[k], format!("`{token}` is not finite")));
        }
        values[k] = value;
    }
    let stamp_s = values[0];
    if stamp_s.abs() > 9.2e9 {
        let message = format!("{stamp_s} s lies beyond what a stamp in ns holds");
        return Err(at(tokens[0].0, "timestamp", message));
    }
    let orientation_xyzw = [values[4], values[5], values[6], values[7]];
    if let Err(e) = So3::try_from_quaternion_xyzw(orientation_xyzw) {
        return Err(at(tokens[4].0, "quaternion (qx qy qz qw)", e.to_string()));
    }
    let mut covariance = [0.0; 12];
    covariance.copy_from_slice(&values[8..]);
    Ok(Some(PoseLine {
        stamp_ns: (stamp_s * 1e9).round() as i64,
        position: [values[1], values[2], values[3]],
        orientation_xyzw,
        covariance: (tokens.len() == COLUMNS.len()).then_some(covariance),
        columns: tokens.iter().map(|t| t.0).collect(),
    }))
}

/// Reads a TUM trajectory file.
///
/// Errors: unreadable file; a line with another number of fields, a value that is not a finite
/// number, a quaternion that is not unit, a stamp not after the one before (file:line:column,
/// the field and the value); no pose at all.
pub fn read_tum(path: &Path) -> Result<Vec<ReferenceSample>, InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError::Read {
        path: file.clone(),
        reason: e.to_string(),
    })?;
    parse_tum(&file, &text)
}

/// Parses the text of a TUM trajectory file named `file` (see [`read_tum`]).
///
/// See the [module docs](self) for an example.
pub fn parse_tum(file: &str, text: &str) -> Result<Vec<ReferenceSample>, InputError> {
    let mut samples: Vec<ReferenceSample> = Vec::new();
    for (number, line) in text.lines().enumerate() {
        // An ov_eval line's covariance is not needed here.
        let Some(pose) = parse_pose_line(file, number + 1, line)? else {
            continue;
        };
        if let Some(last) = samples.last()
            && pose.stamp_ns <= last.stamp_ns
        {
            return Err(InputError::At {
                file: file.to_owned(),
                line: number + 1,
                column: pose.columns[0] + 1,
                field: "timestamp".to_owned(),
                message: format!(
                    "{} s is not after the line before ({} s): stamps must increase",
                    pose.stamp_ns as f64 / 1e9,
                    last.stamp_ns as f64 / 1e9
                ),
                source_line: line.to_owned(),
            });
        }
        samples.push(ReferenceSample {
            stamp_ns: pose.stamp_ns,
            position: pose.position,
            orientation_xyzw: pose.orientation_xyzw,
        });
    }
    if samples.is_empty() {
        return Err(InputError::Format {
            file: file.to_owned(),
            message: "no pose in it; a TUM trajectory has lines `timestamp tx ty tz qx qy qz qw`"
                .to_owned(),
        });
    }
    Ok(samples)
}
