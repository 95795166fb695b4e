//! The text panel of a robot log: what was read, each topic's covariance health in words, and
//! what the two pictures mean.

use std::fmt::Write;

use crate::eval::log::{LogEvaluation, PoseState};
use crate::interop::RosReading;
use crate::plan::log::{Class, Issue, LogSummary, TopicSummary};
use crate::uncertain::Confidence;

/// A stamp in seconds, as the timeline shows it.
fn secs(ns: i64) -> String {
    format!("{:.3} s", ns as f64 * 1e-9)
}

/// The short word for a covariance-health finding (its `--allow` name is
/// [`Issue::name`]), shown beside its sentence ([`issue_sentence`]).
///
/// ```
/// use posecov::{draw::log::issue_word, plan::log::Issue};
/// assert_eq!(issue_word(Issue::UnknownMarker), "unknown (-1 marker)");
/// ```
pub fn issue_word(issue: Issue) -> &'static str {
    match issue {
        Issue::NonFinite => "NaN or infinite",
        Issue::Asymmetric => "asymmetric",
        Issue::NotPsd => "not positive semi-definite",
        Issue::Undecodable => "undecodable bytes",
        Issue::BadOrientation => "orientation not a unit quaternion",
        Issue::UnknownMarker => "unknown (-1 marker)",
        Issue::AllZero => "all zero (unknown)",
        Issue::PlaceholderUsedAxis => "placeholder on a used axis",
        Issue::Constant => "constant while moving",
        Issue::FrozenStamp => "frozen stamp",
        Issue::TypeChange => "another message type",
        Issue::Placeholder => "placeholder (≥ 1e6)",
        Issue::StampFallback => "stamp from the log time",
        Issue::StampOrder => "stamp out of order",
        Issue::Drop => "sudden drop (relocalisation?)",
        Issue::Growth => "unbounded growth",
        Issue::TfCycle => "a cycle in /tf",
        Issue::TfSeveralParents => "a frame with several parents in /tf",
        Issue::TfMissingLink => "frames /tf does not join",
        Issue::TfNoTransform => "a frame never in /tf",
        Issue::TfTiltsPlane => "a transform that tilts the plane",
        Issue::CovarianceTypeUnknown => "covariance type unknown",
        Issue::CovarianceApproximated => "covariance approximated",
        Issue::DiagonalKnownOffDiagonal => "off-diagonal entries in a diagonal covariance",
        Issue::NoFix => "no fix",
    }
}

/// One plain sentence on what a finding means on topic `t` (with its numbers: the smallest
/// eigenvalue, the constant stretch's span and distance).
///
/// ```
/// use posecov::{draw::log::issue_sentence, plan::log::{Issue, TopicSummary, PoseMessageKind}};
/// # let t = TopicSummary { name: "/odom".into(), kind: PoseMessageKind::Odometry, frame_id: "odom".into(),
/// #     child_frame_id: String::new(), count: 0, stamps_from_log_time: 0, stamps_out_of_order: 0,
/// #     stamp_range: None, health: Default::default(), group: posecov::lie::GroupKind::Se2, drawn: vec![], last_twist_covariance: None, stride: 1,
/// #     trajectory: vec![], series: vec![], sigma_stats: [None; 6] };
/// assert!(issue_sentence(Issue::AllZero, &t).starts_with("every estimated entry is 0"));
/// ```
pub fn issue_sentence(issue: Issue, t: &TopicSummary) -> String {
    match issue {
        Issue::NonFinite => "NaN or ∞ in the covariance.".to_owned(),
        Issue::Asymmetric => "Σ ≠ Σᵀ beyond the tolerance (1e-9 relative).".to_owned(),
        Issue::NotPsd => match t.health.min_eigenvalue {
            Some(lo) => format!(
                "a negative variance along some direction: smallest eigenvalue {lo:.3e}, below −tolerance."
            ),
            None => "a negative variance along some direction.".to_owned(),
        },
        Issue::Undecodable => format!(
            "the bytes are not a {} (truncated, or another definition).",
            t.kind.ros1_name()
        ),
        Issue::BadOrientation => "the quaternion's norm is not 1 (beyond 1e-3).".to_owned(),
        Issue::UnknownMarker => "covariance[0] = −1, ROS's \"unknown\".".to_owned(),
        Issue::AllZero => {
            "every estimated entry is 0: no uncertainty claimed (or never filled in).".to_owned()
        }
        Issue::PlaceholderUsedAxis => {
            let axes = if t.group.is_planar() {
                "x, y or yaw"
            } else {
                "an axis of a 3-D topic"
            };
            format!("a variance ≥ 1e6 on {axes}: an axis the motion uses is not estimated.")
        }
        Issue::Constant => match t.health.constant {
            Some(c) => format!(
                "the covariance {} over {} messages, {:.1} s and {:.1} m of motion{}.",
                if t.dead_reckoned() {
                    "never grows"
                } else {
                    "stays identical"
                },
                c.messages,
                (c.last_stamp_ns - c.first_stamp_ns) as f64 * 1e-9,
                c.distance_m,
                if t.dead_reckoned() {
                    "; dead-reckoned odometry integrates noise, so its covariance must grow"
                } else {
                    ""
                }
            ),
            None => "the covariance does not change while the pose moves.".to_owned(),
        },
        Issue::FrozenStamp => "the same header stamp as the message before.".to_owned(),
        Issue::TypeChange => format!(
            "the topic also carries {} (another publisher or definition): those messages are \
             not read, only its {} ones.",
            if t.health.other_types.is_empty() {
                "another type".to_owned()
            } else {
                t.health.other_types.join(", ")
            },
            t.kind.ros1_name()
        ),
        Issue::Placeholder => {
            "z, roll or pitch ≥ 1e6, \"not estimated\" on axes planar motion does not use."
                .to_owned()
        }
        Issue::StampFallback => "a zero header stamp: the log time is used.".to_owned(),
        Issue::StampOrder => {
            "stamped earlier than the message before (plots are sorted by stamp).".to_owned()
        }
        Issue::Drop => {
            "the position trace fell ÷ ≥ 5 at once (relocalisation, loop closure, reset)."
                .to_owned()
        }
        Issue::Growth => {
            "the position trace reached ≥ 100 × its value since the last drop (dead reckoning)."
                .to_owned()
        }
        // The log's /tf: said with its frames and stamp by `frame_problem_sentence`.
        Issue::TfCycle => {
            "the log's /tf has a cycle, where tf allows no loop: nothing is joined through it."
                .to_owned()
        }
        Issue::TfSeveralParents => "the log's /tf gives a frame several parents, where tf allows \
             one: nothing is joined through it."
            .to_owned(),
        Issue::TfMissingLink => {
            "no chain of transforms in /tf joins the topics' frames: drawn apart.".to_owned()
        }
        Issue::TfNoTransform => {
            format!(
                "frame `{}` never gets a transform in /tf or /tf_static: drawn in its own view.",
                t.frame_id
            )
        }
        Issue::TfTiltsPlane => {
            "the transform to the common frame tilts this planar topic's plane: drawn apart."
                .to_owned()
        }
        // A NavSatFix's own: said on its sensor topic by `sensor_sentence`.
        Issue::CovarianceTypeUnknown
        | Issue::CovarianceApproximated
        | Issue::DiagonalKnownOffDiagonal
        | Issue::NoFix => format!("{}.", issue_word(issue)),
    }
}

/// The Markdown summary of a log (a `format` file, its format's name, e.g. `ROS 1 bag`): per topic its type, frames, counts, stamps, health (count
/// and first stamp per issue), what is drawn (planar or 3-D, χ² dimensions), then the skipped
/// topics.
///
/// See [`draw_log`](super::draw_log) for an example.
pub fn description(
    plan: &LogSummary,
    format: &str,
    e: &LogEvaluation,
    confidence: Confidence,
) -> String {
    let mut s = String::new();
    let sensor_defects = plan.sensors.iter().flat_map(|t| {
        t.findings()
            .filter(|f| f.3 == Class::Defect)
            .map(|f| f.2.count)
    });
    let defects: u64 = plan
        .topics
        .iter()
        .flat_map(|t| t.defects().map(|(_, c)| c.count))
        .chain(sensor_defects)
        .sum();
    let verdict = match defects {
        0 => "no covariance defect".to_owned(),
        n => format!("**{n} message(s) with defects** (`posecov check` fails)"),
    };
    let sensors = match plan.sensors.len() {
        0 => String::new(),
        n => format!(", {n} sensor topic(s)"),
    };
    let _ = writeln!(
        s,
        "**{format}**: {} messages, {} pose topic(s){sensors} read; {verdict}.",
        plan.messages_total,
        plan.topics.len()
    );
    let mut frames: Vec<&str> = e.topics.iter().map(|t| t.frame_id.as_str()).collect();
    frames.sort_unstable();
    frames.dedup();
    if frames.len() > 1 {
        let names: Vec<String> = frames
            .iter()
            .map(|f| {
                if f.is_empty() {
                    "(none)".to_owned()
                } else {
                    format!("`{f}`")
                }
            })
            .collect();
        let why = if e.frames.has_tf {
            "the log's /tf does not join them, see below"
        } else {
            "the log has no /tf or /tf_static to join them"
        };
        let _ = writeln!(
            s,
            "\n**{} frames** ({}): one whole-log view each — topics in different frames are \
             never overlaid as if they were one ({why}).",
            frames.len(),
            names.join(", ")
        );
    }
    s.push_str(&super::frames::frames_paragraph(e));
    if plan.cancelled {
        let _ = writeln!(
            s,
            "\n**Interrupted (Ctrl-C)**: only the messages before the interruption were read."
        );
    }
    for sentence in plan.stream.iter().flat_map(|n| n.sentences()) {
        let _ = writeln!(s, "\n**Live stream**: {sentence}.");
    }
    if let Some(cut) = &plan.cut {
        let _ = writeln!(
            s,
            "\n**The log stops early** ({}): read its first {} whole chunk(s), up to byte {} of \
             its {}; everything here is from them.",
            cut.reason, cut.chunks_read, cut.at_byte, cut.file_bytes
        );
    }
    for (t, te) in plan.topics.iter().zip(&e.topics) {
        topic(&mut s, t, te, confidence, e.reading);
    }
    super::sensor::sensor_paragraph(plan, &mut s);
    super::sensor_shapes::shapes_paragraph(e, confidence, &mut s);
    if !plan.skipped.is_empty() {
        let _ = writeln!(s, "\n---\n\n**Skipped** (other message types):\n");
        for k in &plan.skipped {
            let joined = e.topics.iter().any(|t| t.joined.is_some());
            let tf = if joined && ["/tf", "/tf_static"].contains(&k.name.as_str()) {
                " (its transforms read to join frames, above)"
            } else {
                ""
            };
            let _ = writeln!(s, "- `{}`: {} × {}{tf}", k.name, k.count, k.message_type);
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
        "\n---\n\n**The views**: the whole log per frame; beside it, per topic, the message at \
         the time cursor at the robot's scale (at the origin, the parent frame's axes; its σ on \
         the pose; the camera fits the last message). Plots: σ in mm and degrees (or m, mrad) \
         where that reads best, ranges from 0.\n\n**The two pictures**\n\n\
         - **RViz's picture** (magenta, `rviz/`): the ellipsoid of the covariance's position \
         block read in the parent frame's axes, and orientation discs at the axis tips \
         (tan of the angular spread, bounded at 89°) — a yaw fan when RViz takes the pose as \
         2-D (Σzz, Σroll, Σpitch ≤ 0; a 1e6 placeholder makes it draw a 3-D shape kilometres \
         tall: drawn here clipped at 3 × the estimated axes, and labelled).\n\
         - **What the numbers mean** (`meaning/`): ROS's covariance, read {}, converted to \
         posecov's body-frame right form, X = μ · Exp(ε); its Exp-mapped banana, Cartesian \
         ellipsoid and a seeded sample cloud (3-D: sampled axis tips).\n\
         - Regions at {:.1} %; the `stamp` timeline is the message stamp (a date, or the time \
         since the clock's zero when the stamps are simulated time).",
        reading_words(e.reading),
        confidence.get() * 100.0
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
    t: &TopicSummary,
    e: &crate::eval::log::TopicEvaluation,
    p: Confidence,
    reading: RosReading,
) {
    let _ = write!(s, "\n---\n\n**{}** ({}", t.name, t.kind.ros1_name());
    if !t.frame_id.is_empty() {
        let _ = write!(s, ", `{}`", t.frame_id);
        if !t.child_frame_id.is_empty() {
            let _ = write!(s, " → `{}`", t.child_frame_id);
        }
    }
    if t.dead_reckoned() {
        let _ = write!(s, ", dead-reckoned");
    }
    let _ = write!(s, "): {} messages", t.count);
    if let Some(r) = t.stamp_range {
        let _ = write!(s, ", stamps {} … {}", secs(r.first_ns), secs(r.last_ns));
    }
    let _ = writeln!(s, ".");
    health(s, t);
    if t.kind == crate::plan::log::PoseMessageKind::PoseWithCovariance {
        let _ = writeln!(s, "\nNo header: stamps are the log time.");
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
        .filter(|q| matches!(&q.state, PoseState::Invalid { issues } if issues == &[Issue::PlaceholderUsedAxis]))
        .count();
    let r2 = |d| p.radius(d);
    let shape = if t.group.is_planar() {
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
    if let Some(c) = &e.consistency {
        super::nees::paragraph(s, c);
    }
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

/// A topic's health: its defects first (each with its `--allow` name, count, first stamp and
/// message, and sentence), then its notes.
fn health(s: &mut String, t: &TopicSummary) {
    if t.health.issues.is_empty() {
        let _ = writeln!(s, "\nCovariance health: no defect, no note.");
        return;
    }
    let mut findings: Vec<_> = t.health.issues.iter().collect();
    findings.sort_by_key(|(i, _)| (t.class(**i), **i));
    for (issue, c) in findings {
        let class = match t.class(*issue) {
            Class::Defect => "**defect**",
            Class::Note => "note",
        };
        let _ = writeln!(
            s,
            "\n- {class} `{}` × {}, first at {} (message {}): {}",
            issue.name(),
            c.count,
            secs(c.first_stamp_ns),
            c.first_index,
            issue_sentence(*issue, t)
        );
    }
}
