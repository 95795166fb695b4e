//! A log's frames in `report --json` and `check`: the `/tf` edges read, each topic drawn in a
//! common frame (`topics[].frame_join`), and what kept frames apart (`frames.problems`), each
//! with its class and sentence ([`crate::draw::log::frame_problem_sentence`]).

use serde_json::{Value, json};

use super::stamp_seconds;
use crate::draw::log::frame_problem_sentence;
use crate::eval::log::{LogEvaluation, TopicEvaluation};
use crate::plan::log::{Class, Issue, TfTree};

/// `frames`: the `/tf` edges read (what was kept of them) and the problems.
pub(super) fn frames_json(tf: &TfTree, e: &LogEvaluation) -> Value {
    json!({
        "has_tf": e.frames.has_tf,
        "tf_edges": tf.edges.iter().map(|edge| json!({
            "parent": edge.parent,
            "child": edge.child,
            "topic": edge.topic,
            "first_stamp_s": stamp_seconds(edge.first_stamp_ns),
            "messages": edge.messages,
            "kept": edge.samples.len() + usize::from(edge.static_value.is_some()),
            "every": edge.stride,
            "static": edge.samples.is_empty() && edge.static_value.is_some(),
            "dropped": edge.dropped,
        })).collect::<Vec<_>>(),
        "undecodable": tf.undecodable.iter().map(|u| json!({
            "topic": u.topic, "count": u.count, "first_log_time_s": stamp_seconds(u.first_log_time_ns),
        })).collect::<Vec<_>>(),
        "problems": e.frames.problems.iter().map(|p| json!({
            "kind": p.kind.issue().name(),
            "class": p.kind.class(),
            "frames": p.frames,
            "roots": p.roots,
            "topics": p.topics,
            "source": p.source,
            "first_stamp_s": p.stamp_ns.map(stamp_seconds),
            "sentence": frame_problem_sentence(p),
        })).collect::<Vec<_>>(),
    })
}

/// `topics[].frame_join`: the common frame a topic is drawn in, if joined.
pub(super) fn join_json(t: &TopicEvaluation) -> Value {
    t.joined.as_ref().map_or(Value::Null, |j| {
        json!({
            "from": j.from,
            "to": j.to,
            "chain": j.chain,
            "moved": j.moved,
            "left_out": j.left_out,
            "first_left_out_s": j.first_left_out_ns.map(stamp_seconds),
            "trajectory_left_out": j.trajectory_left_out,
        })
    })
}

/// The defects of the log's `/tf` (a cycle, several parents): the kinds `allow` names that
/// were found (accepted on purpose, each once), and `check`'s line for each other one, in the
/// file's terms.
pub(super) fn tf_defects(
    file: &str,
    e: &LogEvaluation,
    allow: &[Issue],
) -> (Vec<Issue>, Vec<String>) {
    let mut allowed = Vec::new();
    let mut lines = Vec::new();
    for p in e.frames.problems.iter() {
        let issue = p.kind.issue();
        if p.kind.class() != Class::Defect {
            continue;
        }
        if allow.contains(&issue) {
            if !allowed.contains(&issue) {
                allowed.push(issue);
            }
        } else {
            let name = issue.name();
            lines.push(format!(
                "{file}: {name} — {} (`--allow {name}` accepts it)",
                frame_problem_sentence(p)
            ));
        }
    }
    (allowed, lines)
}
