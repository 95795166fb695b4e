//! TUM trajectory files (the TUM RGB-D benchmark's ground-truth format, also what evo and
//! ov_eval read): one pose per line, `timestamp tx ty tz qx qy qz qw` — seconds, metres, a
//! unit quaternion in (x, y, z, w) order — separated by spaces (or commas); `#` starts a
//! comment line, blank lines are skipped. Stamps must increase. Used as a log's reference
//! (`--reference FILE`).
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

/// The eight fields of a line, in order.
const FIELDS: [&str; 8] = ["timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"];

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
        let at = |column: usize, field: &str, message: String| InputError::At {
            file: file.to_owned(),
            line: number + 1,
            column: column + 1,
            field: field.to_owned(),
            message,
            source_line: line.to_owned(),
        };
        let trimmed = line.trim_start();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        // (column in characters, token)
        let mut tokens = Vec::new();
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
        if tokens.len() != FIELDS.len() {
            return Err(at(
                0,
                "line",
                format!(
                    "{} values; a TUM line has 8: timestamp tx ty tz qx qy qz qw",
                    tokens.len()
                ),
            ));
        }
        let mut values = [0.0; 8];
        for (k, (column, token)) in tokens.iter().enumerate() {
            let value: f64 = token
                .parse()
                .map_err(|_| at(*column, FIELDS[k], format!("`{token}` is not a number")))?;
            if !value.is_finite() {
                return Err(at(*column, FIELDS[k], format!("`{token}` is not finite")));
            }
            values[k] = value;
        }
        let stamp_column = tokens[0].0;
        let stamp_s = values[0];
        if stamp_s.abs() > 9.2e9 {
            return Err(at(
                stamp_column,
                "timestamp",
                format!("{stamp_s} s lies beyond what a stamp in ns holds"),
            ));
        }
        let stamp_ns = (stamp_s * 1e9).round() as i64;
        let orientation_xyzw = [values[4], values[5], values[6], values[7]];
        if let Err(e) = So3::try_from_quaternion_xyzw(orientation_xyzw) {
            return Err(at(tokens[4].0, "quaternion (qx qy qz qw)", e.to_string()));
        }
        if let Some(last) = samples.last()
            && stamp_ns <= last.stamp_ns
        {
            return Err(at(
                stamp_column,
                "timestamp",
                format!(
                    "{stamp_s} s is not after the line before ({} s): stamps must increase",
                    last.stamp_ns as f64 / 1e9
                ),
            ));
        }
        samples.push(ReferenceSample {
            stamp_ns,
            position: [values[1], values[2], values[3]],
            orientation_xyzw,
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
