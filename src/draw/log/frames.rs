//! The words for frames joined through a log's `/tf` ([`crate::eval::log::frames`]): which topic
//! was drawn in which frame by which transforms, and each reason frames were kept apart, in the
//! log's terms (topic, frames, stamp).

use std::fmt::Write;

use crate::eval::log::LogEvaluation;
use crate::eval::log::frames::{FrameProblem, FrameProblemKind};
use crate::interop::RosReading;
use crate::plan::log::Class;

/// A stamp in seconds, as the timeline shows it.
fn secs(ns: i64) -> String {
    format!("{:.3} s", ns as f64 * 1e-9)
}

/// Frames as `a`, `b`.
fn names(frames: &[String], sep: &str) -> String {
    let quoted: Vec<String> = frames.iter().map(|f| format!("`{f}`")).collect();
    quoted.join(sep)
}

/// One plain sentence on why frames were not joined, located by topic, frames and stamp.
///
/// ```
/// use posecov::draw::log::frame_problem_sentence;
/// use posecov::eval::log::frames::{FrameProblem, FrameProblemKind};
/// let p = FrameProblem { kind: FrameProblemKind::NoTransform, frames: vec!["utm".into()], roots: vec![],
///     topics: vec!["/gps".into()], source: "/gps".into(), stamp_ns: Some(3_000_000_000) };
/// assert_eq!(frame_problem_sentence(&p), "frame `utm` of /gps (first message at 3.000 s) never gets a transform in /tf or /tf_static: drawn in its own view");
/// ```
pub fn frame_problem_sentence(p: &FrameProblem) -> String {
    let at = p.stamp_ns.map(secs).unwrap_or_else(|| "?".to_owned());
    let topics = if p.topics.is_empty() {
        "no pose topic".to_owned()
    } else {
        p.topics.join(", ")
    };
    match p.kind {
        FrameProblemKind::Cycle => format!(
            "{} has a cycle {} (closed at {at}), where tf allows no loop: {topics} not joined \
             through it, each frame drawn in its own view",
            p.source,
            names(&p.frames, " → ")
        ),
        FrameProblemKind::SeveralParents => format!(
            "{} gives frame `{}` {} parents ({}; the last one first at {at}), where tf allows \
             one: nothing is joined through `{}` ({topics} drawn apart)",
            p.source,
            p.frames[0],
            p.frames.len() - 1,
            names(&p.frames[1..], ", "),
            p.frames[0]
        ),
        FrameProblemKind::MissingLink => {
            let trees: Vec<String> = p
                .frames
                .iter()
                .zip(&p.roots)
                .map(|(f, r)| format!("`{f}` (under `{r}`)"))
                .collect();
            format!(
                "a missing link: {} are in /tf, but no chain of transforms joins them — the \
                 missing link is a transform between {}; {topics} drawn apart, one view per frame",
                trees.join(" and "),
                names(&p.roots, " and ")
            )
        }
        FrameProblemKind::NoTransform => format!(
            "frame `{}` of {topics} (first message at {at}) never gets a transform in /tf or \
             /tf_static: drawn in its own view",
            p.frames[0]
        ),
        FrameProblemKind::TiltsPlane => format!(
            "{topics} is planar, but the transform from `{}` at {at} tilts its plane: drawn in \
             `{}` on its own",
            p.frames[0], p.frames[0]
        ),
    }
}

/// The panel's paragraph on frames: each topic joined (by which transforms, messages moved and
/// left out), the covariance rule, then each problem with its class; empty when there is
/// nothing to say.
pub(super) fn frames_paragraph(e: &LogEvaluation) -> String {
    let mut s = String::new();
    for t in &e.topics {
        let Some(j) = &t.joined else { continue };
        let left = match j.left_out {
            0 => String::new(),
            n => format!(
                "; {n} stamped outside the transforms' span (first at {}) left out, never \
                 extrapolated",
                j.first_left_out_ns.map(secs).unwrap_or_default()
            ),
        };
        let _ = writeln!(
            s,
            "\n**Joined through the log's /tf**: {} (in `{}`) drawn in `{}`, moved by {} at \
             each stamp (interpolated on SE(3)): {} drawn message(s){left}.",
            t.name,
            j.from,
            j.to,
            j.chain
                .windows(2)
                .rev()
                .map(|w| format!("{}→{}", w[1], w[0]))
                .collect::<Vec<_>>()
                .join(" · "),
            j.moved
        );
    }
    if e.topics.iter().any(|t| t.joined.is_some()) {
        let rule = match e.reading {
            RosReading::Tf2 => "both blocks rotated by the transform (tf2's reading)",
            RosReading::Body => "the position block rotated (body reading)",
        };
        let _ = writeln!(
            s,
            "The covariance moves with the pose: {rule}; the right-form Gaussian drawn is \
             unchanged. /tf carries no covariance: the transform is taken as exact. σ numbers \
             and plots stay in each topic's own frame's axes, as published."
        );
    }
    for p in &e.frames.problems {
        let class = match p.kind.class() {
            Class::Defect => "**defect**",
            Class::Note => "note",
        };
        let _ = writeln!(
            s,
            "\n{class} `{}`: {}.",
            p.kind.issue().name(),
            frame_problem_sentence(p)
        );
    }
    s
}
