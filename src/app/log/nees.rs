//! `--reference`: which truth a log's estimates are compared with (a topic of the log, a child
//! frame in `/tf`, a TUM file — a bare value is a topic of the log, else an existing file),
//! the observer that takes every message's NEES while the log is read, the errors in the
//! user's words, and `topics[].consistency` of `report --json`.

use std::collections::BTreeMap;
use std::path::Path;

use super::stamp_seconds;
use crate::app::AppError;
use crate::app::settings::{ReferenceArg, ReferenceSettings};
use crate::eval::log::nees::{NeesObserver, NeesSettings, TopicConsistency};
use crate::input::InputError;
use crate::input::tum::read_tum;
use crate::interop::RosReading;
use crate::plan::log::{
    EstimateMessage, LogObserver, LogSummary, Reference, ReferenceInLog, ReferenceSample,
};

/// A reference ready for the read: the observer, and what the reader must look for.
pub(super) struct Prepared {
    /// Takes every message's NEES.
    pub(super) observer: NeesObserver,
    /// What the reader hands to the observer (a topic, `/tf`), or only looks for (a bare value
    /// that is also a file: the log must not have that topic).
    pub(super) in_log: Option<ReferenceInLog>,
    /// The flag's value as given.
    value: String,
    /// A bare value read as a file.
    either_file: bool,
    /// The value was bare ([`ReferenceArg::Either`]): a topic or a file, not said which.
    bare: bool,
}

/// Reads the reference's file, if it is one, and sets up the observer.
pub(super) fn prepare(
    reference: &ReferenceSettings,
    reading: RosReading,
    every: Option<u64>,
) -> Result<Prepared, AppError> {
    let align = reference.align;
    let settings = |reference: Reference| NeesSettings {
        reference,
        reading,
        align,
        every,
    };
    let tum = |path: &str, value: &str| {
        let samples = read_tum(Path::new(path))?;
        let observer =
            NeesObserver::with_trajectory(settings(Reference::File(path.to_owned())), &samples);
        Ok::<_, AppError>(Prepared {
            observer,
            in_log: None,
            value: value.to_owned(),
            either_file: false,
            bare: false,
        })
    };
    Ok(match &reference.arg {
        ReferenceArg::File(path) => tum(path, &format!("file:{path}"))?,
        ReferenceArg::Topic(name) => Prepared {
            observer: NeesObserver::new(settings(Reference::InLog(ReferenceInLog::Topic(
                name.clone(),
            )))),
            in_log: Some(ReferenceInLog::Topic(name.clone())),
            value: format!("topic:{name}"),
            either_file: false,
            bare: false,
        },
        ReferenceArg::Tf(child) => Prepared {
            observer: NeesObserver::new(settings(Reference::InLog(ReferenceInLog::Tf {
                child: child.clone(),
            }))),
            in_log: Some(ReferenceInLog::Tf {
                child: child.clone(),
            }),
            value: format!("tf:{child}"),
            either_file: false,
            bare: false,
        },
        ReferenceArg::Either(value) if Path::new(value).is_file() => {
            let mut p = tum(value, value)?;
            p.in_log = Some(ReferenceInLog::Topic(value.clone()));
            p.either_file = true;
            p.bare = true;
            p
        }
        ReferenceArg::Either(value) => Prepared {
            observer: NeesObserver::new(settings(Reference::InLog(ReferenceInLog::Topic(
                value.clone(),
            )))),
            in_log: Some(ReferenceInLog::Topic(value.clone())),
            value: value.clone(),
            either_file: false,
            bare: true,
        },
    })
}

/// The observer of a run whose view grows: the read hands it every message (through
/// [`Forward`]), the growing view reads the NEES so far ([`so_far`]) on the thread that
/// draws, between messages.
pub(super) type SharedPrepared = std::sync::Mutex<Prepared>;

/// The shared observer, locked (a panic elsewhere leaves it whole: each change is one call).
fn locked(prepared: &SharedPrepared) -> std::sync::MutexGuard<'_, Prepared> {
    prepared
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The prepared reference once the read is over.
pub(super) fn into_prepared(prepared: SharedPrepared) -> Prepared {
    prepared
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Where the reference is read from in the log, if it is.
pub(super) fn in_log(prepared: &SharedPrepared) -> Option<ReferenceInLog> {
    locked(prepared).in_log.clone()
}

/// Hands every message of the read to a shared reference's observer.
pub(super) struct Forward<'c>(pub(super) &'c SharedPrepared);

impl LogObserver for Forward<'_> {
    fn reference(&mut self, frame_id: &str, sample: ReferenceSample) {
        locked(self.0).observer.reference(frame_id, sample);
    }
    fn estimate(&mut self, message: &EstimateMessage<'_>) {
        locked(self.0).observer.estimate(message);
    }
}

/// The NEES so far of a run still being read, for the growing view: each topic's series at
/// the drawn messages of `plan` (the summary so far).
pub(super) fn so_far(
    prepared: &SharedPrepared,
    plan: &LogSummary,
) -> BTreeMap<String, TopicConsistency> {
    locked(prepared).observer.so_far(&strides(plan))
}

/// Each topic's drawn stride (the NEES series is kept at the drawn messages).
fn strides(plan: &LogSummary) -> BTreeMap<String, u64> {
    plan.topics
        .iter()
        .map(|t| (t.name.clone(), t.stride))
        .collect()
}

/// After the read: the reference was in the log as asked (or, for a bare value read as a file,
/// not also a topic), and some estimate message fell within it. Returns each topic's NEES.
pub(super) fn finish(
    prepared: Prepared,
    plan: &LogSummary,
    file: &str,
) -> Result<BTreeMap<String, TopicConsistency>, AppError> {
    let value = &prepared.value;
    let error = |message: String| {
        AppError::Input(InputError::Format {
            file: file.to_owned(),
            message: format!("--reference {value}: {message}"),
        })
    };
    let read = plan.reference.clone().unwrap_or_default();
    let topics: Vec<&str> = plan
        .topics
        .iter()
        .map(|t| t.name.as_str())
        .chain(plan.skipped.iter().map(|t| t.name.as_str()))
        .chain(plan.not_selected.iter().map(String::as_str))
        .collect();
    match (&prepared.in_log, prepared.either_file) {
        (Some(_), true) if read.found => {
            return Err(error(format!(
                "both a topic of this log and a file; say `topic:{value}` or `file:{value}`"
            )));
        }
        (Some(ReferenceInLog::Topic(name)), false) if !read.found => {
            return Err(error(if prepared.bare {
                format!(
                    "neither a topic of this log nor a file; say `topic:NAME` or `file:PATH` (its topics: {})",
                    topics.join(", ")
                )
            } else {
                format!(
                    "no topic {name} in this log (its topics: {})",
                    topics.join(", ")
                )
            }));
        }
        (Some(ReferenceInLog::Tf { .. }), _) if !read.found => {
            return Err(error("this log has no /tf topic".to_owned()));
        }
        (Some(reference), false) if !read.readable => {
            let found = read.message_type.unwrap_or_default();
            return Err(error(match reference {
                ReferenceInLog::Topic(_) => format!(
                    "its messages are {found}; a reference topic is PoseStamped, PoseWithCovarianceStamped, Odometry or TransformStamped (a child frame in /tf: say `tf:CHILD`)"
                ),
                ReferenceInLog::Tf { .. } => {
                    format!("/tf holds {found}, not tf2_msgs/TFMessage")
                }
            }));
        }
        (Some(reference), false) if read.samples == 0 && !plan.cancelled => {
            return Err(error(match reference {
                ReferenceInLog::Topic(_) => format!(
                    "no pose could be read from it ({} undecodable message(s))",
                    read.undecodable
                ),
                ReferenceInLog::Tf { child } => {
                    format!("no transform in /tf has child_frame_id {child}")
                }
            }));
        }
        _ => {}
    }
    let span = prepared.observer.reference_span();
    let results = prepared.observer.finish(&strides(plan));
    if plan.cancelled || results.values().any(|c| c.messages > 0) {
        return Ok(results);
    }
    let span = span.map_or("no pose".to_owned(), |r| {
        format!(
            "{:.3} s … {:.3} s",
            stamp_seconds(r.first_ns),
            stamp_seconds(r.last_ns)
        )
    });
    if results.is_empty() {
        return Err(error(format!(
            "no estimate topic besides the reference (the reference spans {span})"
        )));
    }
    let per_topic: Vec<String> = results
        .iter()
        .map(|(name, c)| {
            let range = plan
                .topics
                .iter()
                .find(|t| t.name == *name)
                .and_then(|t| t.stamp_range)
                .map_or(String::new(), |r| {
                    format!(
                        "{:.3} s … {:.3} s, ",
                        stamp_seconds(r.first_ns),
                        stamp_seconds(r.last_ns)
                    )
                });
            let s = &c.skipped;
            format!(
                "{name}: {range}{} before it, {} after it, {} unusable, {} in another frame than the reference's parent",
                s.before_reference, s.after_reference, s.unusable, s.other_frame
            )
        })
        .collect();
    Err(error(format!(
        "no estimate message could be compared with the reference (spanning {span}): {}",
        per_topic.join("; ")
    )))
}

/// `topics[].consistency` of `report --json`.
pub(super) fn consistency_json(c: &TopicConsistency) -> serde_json::Value {
    let anees = |a: &Option<crate::eval::Anees>| {
        a.map(|a| {
            serde_json::json!({
                "value": a.value,
                "dof": a.dof,
                "band": a.band,
            })
        })
    };
    serde_json::json!({
        "reference": c.reference.to_string(),
        "reading": c.reading,
        "align": c.align,
        "alignment": c.alignment.map(|t| serde_json::json!({
            "translation": [t.translation().x, t.translation().y, t.translation().z],
            "quaternion_xyzw": t.rotation().to_quaternion_xyzw(),
        })),
        "estimate_frame": c.estimate_frame,
        "reference_frame": c.reference_frame,
        "dof": c.dof,
        "messages": c.messages,
        "anees": c.anees.map(|a| a.value),
        "anees_band": c.anees.map(|a| a.band),
        "verdict": c.verdict,
        "inside_95": c.inside_95,
        "bound_95": c.bound_95,
        "position": anees(&c.position),
        "orientation": anees(&c.orientation),
        "skipped": c.skipped,
        "nees": {
            "stamps_s": c.series.iter().map(|p| stamp_seconds(p.0)).collect::<Vec<_>>(),
            "values": c.series.iter().map(|p| p.1).collect::<Vec<_>>(),
        },
    })
}
