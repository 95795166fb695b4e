//! OpenVINS `ov_eval` text trajectories with covariance: one pose per line, 20 columns
//! separated by spaces (or commas, as a TUM file), `timestamp(s) tx ty tz qx qy qz qw Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11
//! Pt12 Pt13 Pt22 Pt23 Pt33` (the upper triangles of the rotation block `Pr` and the position
//! block `Pt`), or 8 columns when a line has no covariance; `#` starts a comment line.
//! ov_eval's `Recorder` writes them from a `PoseWithCovarianceStamped` or `Odometry` message
//! (`Pt` its covariance's position block, `Pr` its rotation block, the cross block dropped);
//! its `Loader::load_data` reads them back.
//!
//! **What the numbers mean** (from ov_eval's own code, [CONVENTIONS
//! §12](crate::conventions#12-ov_eval-text-trajectories)): the pose is p_IinG and the Hamilton
//! quaternion q_ItoG in ROS's (x, y, z, w) order, so X = (R(q), p) is parent_from_body;
//! `Pt` is the covariance of the position error in the global (parent) frame's axes,
//! p = p̂ + δp; `Pr` that of the rotation error in the body (IMU) frame, R = R̂ · Exp(δθ)
//! (ov_eval's NEES takes −Log(R_gt R̂ᵀ) read as JPL, i.e. Log(R̂ᵀ R_gt), against `Pr`); the file
//! carries no rotation–position cross-covariance (zero). posecov's right form is then
//! Σ_right = blkdiag(Rᵀ Pt R, Pr). Each line becomes one message whose covariance is stored in
//! ROS's layout in tf2's reading — (x, y, z, rotX, rotY, rotZ), both blocks in the parent's
//! axes: blkdiag(Pt, R Pr Rᵀ) — which the log wing's one conversion
//! (`interop::ros_cov_to_right`, tf2's reading) turns back into exactly that Σ_right.
//!
//! Every line error is located (file:line:column, the field and the value): another number of
//! columns than 20 or 8, a value that is not a number or not finite (a NaN stamp), a stamp
//! beyond what nanoseconds hold, a quaternion whose norm is not 1 within 1e-3 (the one text
//! line reader, [`parse_pose_line`], TUM's too), a position beyond ±1e12 m, a block that is
//! not positive semi-definite (its smallest eigenvalue). A line of 8 columns carries no
//! covariance: it is read as ROS's "unknown" marker (`covariance[0] = −1`).
//!
//! ```
//! use posecov::input::log::ov_eval::{parse_line, recognise};
//! let line = "1.5 1 2 3 0 0 0 1 0.01 0 0 0.01 0 0.04 0.25 0 0 0.25 0 1";
//! assert!(recognise(line.as_bytes()));
//! let m = parse_line("est.txt", 1, line).unwrap().unwrap();
//! assert_eq!((m.stamp_ns, m.covariance[0], m.covariance[35]), (1_500_000_000, 0.25, 0.04));
//! let e = parse_line("est.txt", 7, "1.5 1 2 3 0 0 0 1 0.01").unwrap_err().to_string();
//! assert!(e.starts_with("est.txt:7:1: line: 9 values; a line has 8"), "{e}");
//! ```

use std::io::{BufRead as _, BufReader};
use std::path::Path;

use nalgebra::Matrix3;

use super::Collector;
use crate::input::InputError;
use crate::input::tum::{COLUMNS, parse_pose_line};
use crate::lie::So3;
use crate::plan::log::{COV_LEN, PoseMessage, PoseMessageKind};
use crate::uncertain::validate_covariance;

/// The parent frame the messages name (ov_eval's G, the global frame).
pub const FRAME_ID: &str = "global";
/// The child frame the messages name (ov_eval's I, the IMU).
pub const CHILD_FRAME_ID: &str = "imu";

/// Whether the leading bytes of a file are an ov_eval trajectory with covariance: the first
/// line that is not blank or a comment has 20 numbers, or ov_eval's own header comment
/// (`# timestamp(s) tx ty tz qx qy qz qw Pr11 …`) comes before a line of 8 numbers.
///
/// ```
/// use posecov::input::log::ov_eval::recognise;
/// assert!(recognise(b"# timestamp(s) tx ty tz qx qy qz qw Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23 Pt33\n1 0 0 0 0 0 0 1\n"));
/// assert!(!recognise(b"1 0 0 0 0 0 0 1\n")); // a TUM line: no covariance
/// assert!(!recognise(b"VERTEX_SE2 0 0 0 0\n"));
/// ```
pub fn recognise(head: &[u8]) -> bool {
    if head.contains(&0) {
        return false;
    }
    let text = match std::str::from_utf8(head) {
        Ok(t) => t,
        Err(e) => match std::str::from_utf8(&head[..e.valid_up_to()]) {
            Ok(t) => t,
            Err(_) => return false,
        },
    };
    let mut header = false;
    for line in text.lines().map(str::trim) {
        if line.is_empty() {
            continue;
        }
        if let Some(comment) = line.strip_prefix('#') {
            let words: Vec<&str> = comment.split_whitespace().collect();
            header |= words.contains(&"Pr11") && words.contains(&"Pt33");
            continue;
        }
        let numbers = line.split_whitespace().map(str::parse::<f64>);
        let n = line.split_whitespace().count();
        return numbers.clone().all(|v| v.is_ok()) && (n == 20 || (header && n == 8));
    }
    false
}

/// Streams the trajectory at `path` into `collector` as one topic (named after the file's
/// stem, `/<stem>`); `progress(bytes read, file size)`. The first line error ends the read.
pub(super) fn read(
    path: &Path,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let file = path.display().to_string();
    let unreadable = |e: std::io::Error| InputError::Read {
        path: file.clone(),
        reason: e.to_string(),
    };
    let handle = std::fs::File::open(path).map_err(unreadable)?;
    let total = handle.metadata().map_err(unreadable)?.len();
    let topic = topic_name(path);
    let kind = PoseMessageKind::OvEval;
    collector.declare(&topic, kind.ros1_name(), Some(&Ok(kind)));
    let mut reader = BufReader::new(handle);
    let mut bytes = Vec::new();
    let (mut done, mut number) = (0u64, 0usize);
    loop {
        bytes.clear();
        let n = reader.read_until(b'\n', &mut bytes).map_err(unreadable)?;
        if n == 0 || collector.stop() {
            break;
        }
        done += n as u64;
        number += 1;
        let Ok(line) = std::str::from_utf8(&bytes) else {
            return Err(InputError::At {
                file,
                line: number,
                column: 1,
                field: "line".to_owned(),
                message: "not UTF-8 text".to_owned(),
                source_line: String::from_utf8_lossy(&bytes).trim_end().to_owned(),
            });
        };
        let line = line.trim_end_matches(['\n', '\r']);
        if let Some(message) = parse_line(&file, number, line)? {
            let stamp = message.stamp_ns;
            collector.total += 1;
            collector.message_decoded(&topic, kind.ros1_name(), kind, stamp, |_| Ok(message));
        }
        if number % 4096 == 0 {
            progress(done, total);
        }
    }
    progress(done, total);
    Ok(())
}

/// The topic a trajectory file stands for: `/` and its file stem, every character other than
/// an ASCII letter, digit or `_` made `_`.
fn topic_name(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let clean: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!(
        "/{}",
        if clean.is_empty() {
            "trajectory"
        } else {
            &clean
        }
    )
}

/// One line of a trajectory named `file` (1-based `number`): `None` for a blank or comment
/// line, else its message (see the [module docs](self) for the meaning of its covariance), or
/// the located error. The values are read by the one text-trajectory line reader
/// ([`parse_pose_line`], TUM's too); a position beyond ±1e12 m and a block that is not
/// positive semi-definite are refused here.
///
/// See the [module docs](self) for an example.
pub fn parse_line(
    file: &str,
    number: usize,
    line: &str,
) -> Result<Option<PoseMessage>, InputError> {
    let Some(pose) = parse_pose_line(file, number, line)? else {
        return Ok(None);
    };
    let at = |k: usize, field: &str, message: String| InputError::At {
        file: file.to_owned(),
        line: number,
        column: pose.columns[k] + 1,
        field: field.to_owned(),
        message,
        source_line: line.to_owned(),
    };
    let limit = crate::plan::limits::MAX_COORDINATE;
    if let Some(k) = (0..3).find(|k| pose.position[*k].abs() > limit) {
        let message = format!("{} m lies beyond ±{limit:e} m", pose.position[k]);
        return Err(at(k + 1, COLUMNS[k + 1], message));
    }
    let mut covariance = [0.0; COV_LEN];
    match &pose.covariance {
        // No covariance: ROS's "not provided".
        None => covariance[0] = -1.0,
        Some(c) => {
            // The upper triangle (11 12 13 22 23 33) of the block starting at `k` in `c`.
            let block = |k: usize| {
                let [a, b, d, e, f, g] = [c[k], c[k + 1], c[k + 2], c[k + 3], c[k + 4], c[k + 5]];
                Matrix3::new(a, b, d, b, e, f, d, f, g)
            };
            let (pr, pt) = (block(0), block(6));
            for (k, name, m) in [(8, "Pr", &pr), (14, "Pt", &pt)] {
                if let Err(e) = validate_covariance(name, m) {
                    let what = format!("{name} ({}…{})", COLUMNS[k], COLUMNS[k + 5]);
                    return Err(at(k, &what, e.to_string()));
                }
            }
            let rotation = So3::try_from_quaternion_xyzw(pose.orientation_xyzw)
                .map_err(|e| at(4, "quaternion (qx qy qz qw)", e.to_string()))?;
            let r = rotation.quaternion().to_rotation_matrix().into_inner();
            let pr_parent = r * pr * r.transpose();
            for i in 0..3 {
                for j in 0..3 {
                    covariance[i * 6 + j] = pt[(i, j)];
                    // Symmetric to the bit: ½(A + Aᵀ) of the rotated block.
                    covariance[(i + 3) * 6 + j + 3] = 0.5 * (pr_parent[(i, j)] + pr_parent[(j, i)]);
                }
            }
        }
    }
    Ok(Some(PoseMessage {
        stamp_ns: pose.stamp_ns,
        from_log_time: false,
        frame_id: FRAME_ID.to_owned(),
        child_frame_id: CHILD_FRAME_ID.to_owned(),
        position: pose.position,
        orientation_xyzw: pose.orientation_xyzw,
        covariance,
        twist_covariance: None,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interop::{RosReading, ros_cov_to_right};
    use nalgebra::Matrix6;

    #[test]
    fn a_line_means_position_in_the_parent_and_rotation_in_the_body() {
        // Rotated about z by 90° and x by 30°: Pr must come back as it is, Pt rotated into
        // the body, no cross block.
        let q = So3::from_rpy(0.5, 0.0, std::f64::consts::FRAC_PI_2).to_quaternion_xyzw();
        let line = format!(
            "10 1 2 3 {} {} {} {} 0.01 0.002 0 0.02 0.001 0.03 0.5 0.1 0 0.4 0 0.2",
            q[0], q[1], q[2], q[3]
        );
        let m = parse_line("t.txt", 1, &line).unwrap().unwrap();
        let ros = Matrix6::from_row_slice(&m.covariance);
        let rotation = So3::try_from_quaternion_xyzw(q).unwrap();
        let right = ros_cov_to_right(&ros, &rotation, RosReading::Tf2);
        let pr = Matrix3::new(0.01, 0.002, 0.0, 0.002, 0.02, 0.001, 0.0, 0.001, 0.03);
        let pt = Matrix3::new(0.5, 0.1, 0.0, 0.1, 0.4, 0.0, 0.0, 0.0, 0.2);
        let r = rotation.quaternion().to_rotation_matrix().into_inner();
        let expected_rho = r.transpose() * pt * r;
        for i in 0..3 {
            for j in 0..3 {
                assert!((right[(i + 3, j + 3)] - pr[(i, j)]).abs() < 1e-15);
                assert!((right[(i, j)] - expected_rho[(i, j)]).abs() < 1e-15);
                assert!(right[(i, j + 3)].abs() < 1e-15 && right[(i + 3, j)].abs() < 1e-15);
            }
        }
        assert_eq!(ros, ros.transpose());
    }

    #[test]
    fn line_errors_are_located() {
        let cases = [
            ("1 0 0 0 0 0 0 1 1", "t.txt:3:1: line: 9 values"),
            (
                "nan 0 0 0 0 0 0 1",
                "t.txt:3:1: timestamp: `nan` is not finite",
            ),
            ("1 0 0 0 0 0 0 2", "t.txt:3:9: quaternion (qx qy qz qw)"),
            ("1 0 x 0 0 0 0 1", "t.txt:3:5: ty: `x` is not a number"),
            (
                "1 0 0 0 0 0 0 1 1 0 0 1 0 1 1 2 0 1 0 1",
                "t.txt:3:29: Pt (Pt11…Pt33)",
            ),
            (
                "1 0 0 0 0 0 0 1 -1 0 0 1 0 1 1 0 0 1 0 1",
                "t.txt:3:17: Pr (Pr11…Pr33)",
            ),
        ];
        for (line, expected) in cases {
            let e = parse_line("t.txt", 3, line).unwrap_err().to_string();
            assert!(e.starts_with(expected), "{line}: {e}");
        }
        assert_eq!(parse_line("t.txt", 1, "  # comment").unwrap(), None);
        let none = parse_line("t.txt", 1, "1 0 0 0 0 0 0 1").unwrap().unwrap();
        assert_eq!(none.covariance[0], -1.0);
    }
}
