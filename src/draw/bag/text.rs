//! The text panel of a robot log: what was read, each topic's covariance health in words, and
//! what the two pictures mean.

use std::fmt::Write;

use crate::eval::bag::{BagEvaluation, PoseState};
use crate::input::Format;
use crate::interop::RosReading;
use crate::plan::bag::{BagPlan, Issue, TopicPlan};
use crate::uncertain::chi2_radius;

/// A stamp in seconds, as the timeline shows it.
fn secs(ns: i64) -> String {
    format!("{:.3} s", ns as f64 * 1e-9)
}

/// The word for a covariance issue, shown in the text panel, the text report and the README.
///
/// ```
/// use posecov::{draw::bag::issue_word, plan::bag::Issue};
/// assert_eq!(issue_word(Issue::UnknownMarker), "unknown (-1 marker)");
/// ```
pub fn issue_word(issue: Issue) -> &'static str {
    match issue {
        Issue::AllZero => "all zero (unknown)",
        Issue::UnknownMarker => "unknown (-1 marker)",
        Issue::Placeholder => "placeholder (≥ 1e6)",
        Issue::NonFinite => "NaN or infinite",
        Issue::Asymmetric => "asymmetric",
        Issue::NotPsd => "not positive semi-definite",
        Issue::BadOrientation => "orientation not a unit quaternion",
        Issue::SuddenDrop => "sudden drop (relocalisation?)",
        Issue::Growth => "unbounded growth",
        Issue::Undecodable => "undecodable bytes",
    }
}

/// The Markdown summary of a log (a `format` file): per topic its type, frames, counts, stamps, health (count
/// and first stamp per issue), what is drawn (planar or 3-D, χ² dimensions), then the skipped
/// topics.
///
/// See [`bag_scene`](super::bag_scene) for an example.
pub fn description(plan: &BagPlan, format: Format, e: &BagEvaluation, confidence: f64) -> String {
    let mut s = String::new();
    let format = format.name();
    let _ = writeln!(
        s,
        "**{format}**: {} messages, {} pose topic(s) read.",
        plan.messages_total,
        plan.topics.len()
    );
    if plan.cancelled {
        let _ = writeln!(
            s,
            "\n**Interrupted (Ctrl-C)**: only the messages before the interruption were read."
        );
    }
    for (t, te) in plan.topics.iter().zip(&e.topics) {
        topic(&mut s, t, te, confidence, e.reading);
    }
    if !plan.skipped.is_empty() {
        let _ = writeln!(s, "\n---\n\n**Skipped** (other message types):\n");
        for k in &plan.skipped {
            let _ = writeln!(s, "- `{}`: {} × {}", k.name, k.count, k.message_type);
        }
    }
    if !plan.not_selected.is_empty() {
        let _ = writeln!(
            s,
            "\nPose topics not selected with `--topic`: {}.",
            plan.not_selected
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        s,
        "\n---\n\n**The two pictures**\n\n\
         - **RViz's picture** (magenta, `rviz/`): the ellipsoid of the covariance's position \
         block read in the parent frame's axes, and orientation discs at the axis tips \
         (tan of the angular spread, bounded at 89°) — a yaw fan when RViz takes the pose as \
         2-D (Σzz, Σroll, Σpitch ≤ 0; a 1e6 placeholder makes it draw a 3-D shape kilometres \
         tall, clipped here at half the scene's size).\n\
         - **What the numbers mean** (`meaning/`): ROS's covariance, read {}, converted to \
         posecov's body-frame right form, X = μ · Exp(ε); its Exp-mapped banana, Cartesian \
         ellipsoid and a seeded sample cloud (3-D: sampled axis tips).\n\
         - Regions at {:.1} %; the `stamp` timeline is the message stamp (a date, or the time \
         since the clock's zero when the stamps are simulated time).",
        reading_words(e.reading),
        confidence * 100.0
    );
    s
}

/// How a reading reads a message, in words ([CONVENTIONS §6](crate::conventions)).
fn reading_words(reading: RosReading) -> &'static str {
    match reading {
        RosReading::Tf2 => {
            "as tf2 reads it (`--ros-reading tf2`, the default: position and rotation errors both \
             in the parent frame's axes, p̃ = p + δp, R̃ = Exp(δφ) · R)"
        }
        RosReading::Body => {
            "in the body reading (`--ros-reading body`: position error in the parent's axes, \
             rotation error local, R̃ = R · Exp(δθ); tf2 reads it otherwise)"
        }
    }
}

/// Readings further apart than this (relative Frobenius) are worth a sentence.
const READINGS_APART: f64 = 0.01;

fn topic(
    s: &mut String,
    t: &TopicPlan,
    e: &crate::eval::bag::TopicEvaluation,
    p: f64,
    reading: RosReading,
) {
    let _ = writeln!(s, "\n---\n\n**{}** ({})\n", t.name, t.kind.ros1_name());
    if !t.frame_id.is_empty() || !t.child_frame_id.is_empty() {
        let child = if t.child_frame_id.is_empty() {
            String::new()
        } else {
            format!(" → `{}`", t.child_frame_id)
        };
        let _ = writeln!(s, "Frames: `{}`{child}.", t.frame_id);
    }
    let _ = write!(s, "{} messages", t.count);
    if let Some((a, b)) = t.stamp_range {
        let _ = write!(s, ", stamps {} … {}", secs(a), secs(b));
    }
    let _ = writeln!(s, ".");
    if t.stamps_from_log_time > 0 {
        let _ = writeln!(
            s,
            "\n{} message(s) had a zero header stamp: their log time is used.",
            t.stamps_from_log_time
        );
    }
    if t.kind == crate::plan::bag::PoseMessageKind::PoseWithCovariance {
        let _ = writeln!(s, "\nNo header: stamps are the log time.");
    }
    if t.stamps_out_of_order > 0 {
        let _ = writeln!(
            s,
            "\n{} message(s) are stamped earlier than the one before (plots are sorted by stamp).",
            t.stamps_out_of_order
        );
    }
    if t.health.issues.is_empty() {
        let _ = writeln!(s, "\nCovariance health: every message fine.");
    } else {
        let _ = writeln!(
            s,
            "\n| covariance health | messages | first at |\n|---|---|---|"
        );
        for (issue, c) in &t.health.issues {
            let mut word = issue_word(*issue).to_owned();
            if *issue == Issue::NotPsd
                && let Some(lo) = t.health.min_eigenvalue
            {
                word = format!("{word} (smallest eigenvalue {lo:.3e})");
            }
            let _ = writeln!(s, "| {word} | {} | {} |", c.count, secs(c.first_stamp_ns));
        }
    }
    if let Some(sig) = t.twist_sigmas() {
        let names = ["vx", "vy", "vz", "ωx", "ωy", "ωz"];
        let parts: Vec<String> = sig
            .iter()
            .zip(names)
            .map(|(v, n)| match v {
                Some(v) => format!("σ{n} {v:.3}"),
                None => format!("σ{n} –"),
            })
            .collect();
        let _ = writeln!(
            s,
            "\nTwist covariance of the last drawn message (child frame; m/s, rad/s; – placeholder): {}.",
            parts.join(", ")
        );
    }
    let invalid = e.poses.iter().filter(|q| !q.state.is_drawable()).count();
    let placeholders3d = e
        .poses
        .iter()
        .filter(|q| matches!(&q.state, PoseState::Invalid { issues } if issues == &[Issue::Placeholder]))
        .count();
    let r2 = |d| chi2_radius(p, d).unwrap_or(f64::NAN);
    let shape = if t.planar {
        format!(
            "**planar** (z, roll and pitch are zero or placeholders in every usable message): \
             drawn in the x–y plane as SE(2) — position region χ²(2), r = {:.3}; pose region \
             χ²(3), r = {:.3}",
            r2(2),
            r2(3)
        )
    } else {
        format!(
            "**3-D**: position region χ²(3), r = {:.3}; pose region χ²(6), r = {:.3}",
            r2(3),
            r2(6)
        )
    };
    if e.reading_difference > READINGS_APART {
        let _ = writeln!(
            s,
            "\n**The ROS reading matters here**: with 3-D attitudes, tf2's reading and the body \
             reading give right-form covariances up to {:.0} % apart (‖Σ_tf2 − Σ_body‖_F / ‖Σ_tf2‖_F); \
             this view uses {}.",
            e.reading_difference * 100.0,
            match reading {
                RosReading::Tf2 => "tf2's (`--ros-reading body` for the other)",
                RosReading::Body => "the body reading (`--ros-reading tf2` for tf2's)",
            }
        );
    }
    let _ = writeln!(
        s,
        "\n{shape}. Drawn: {} message(s), one in {}{}.",
        e.poses.len(),
        t.stride,
        if invalid > 0 {
            format!(
                "; {invalid} unusable drawn as a red cross{}",
                if placeholders3d > 0 {
                    format!(" ({placeholders3d} with a placeholder in a 3-D topic)")
                } else {
                    String::new()
                }
            )
        } else {
            String::new()
        }
    );
}
