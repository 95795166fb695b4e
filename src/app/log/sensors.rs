//! A log's sensor topics (`sensor_msgs/Imu`, twists, accelerations, an Odometry's twist) in `report --json` (`sensors`) and `check`: per
//! topic its findings and per covariance block its findings and σ per axis with its unit.

use serde_json::{Map, Value, json};

use super::{stamp_seconds, stamps_json};
use crate::draw::log::{issue_word, sensor_sentence};
use crate::eval::log::sensor::SensorEvaluation;
use crate::eval::log::sensor_shapes::LocalFixes;
use crate::plan::log::{BlockSummary, Class, Health, Issue, LogSummary, SensorTopicSummary};

/// A health map as the pose topics' (`health` in json-report.md): per finding its class, count,
/// first stamp and message, word and sentence.
fn health_json(health: &Health, block: Option<&BlockSummary>, t: &SensorTopicSummary) -> Value {
    let map: Map<String, Value> = health
        .issues
        .iter()
        .map(|(issue, c)| {
            (
                issue.name().to_owned(),
                json!({
                    "class": t.kind.class_of(*issue),
                    "count": c.count,
                    "first_stamp_s": stamp_seconds(c.first_stamp_ns),
                    "first_message": c.first_index,
                    "word": issue_word(*issue),
                    "sentence": sensor_sentence(*issue, block, t),
                }),
            )
        })
        .collect();
    Value::Object(map)
}

/// `sensors`: one entry per sensor topic, in name order.
pub(super) fn sensors_json(plan: &LogSummary, e: &[SensorEvaluation]) -> Value {
    let topics: Vec<Value> = plan
        .sensors
        .iter()
        .zip(e)
        .map(|(t, te)| {
            let blocks: Map<String, Value> = t
                .blocks
                .iter()
                .zip(&te.blocks)
                .map(|(b, be)| {
                    let sigma: Map<String, Value> = b
                        .spec
                        .axes
                        .iter()
                        .zip(&be.sigma)
                        .filter_map(|(axis, s)| {
                            let mut v = serde_json::to_value(s.as_ref()?).ok()?;
                            v["unit"] = json!(b.spec.unit);
                            Some(((*axis).to_owned(), v))
                        })
                        .collect();
                    let value = json!({
                        "unit": b.spec.unit,
                        "axes": b.spec.axes,
                        "health": health_json(&b.health, Some(b), t),
                        "min_eigenvalue": b.health.min_eigenvalue,
                        "sigma": sigma,
                    });
                    (b.spec.name.to_owned(), value)
                })
                .collect();
            let mut topic = json!({
                "name": t.name,
                "type": t.kind.ros1_name(),
                "kind": t.kind,
                "frame_id": t.frame_id,
                "frame_field": t.kind.frame_field(),
                "messages": t.count,
                "stamps": stamps_json(t.stamp_range, t.stamps_from_log_time, t.stamps_out_of_order),
                "health": health_json(&t.health, None, t),
                "blocks": blocks,
            });
            if let Some(l) = &te.fixes {
                topic["fixes"] = fixes_json(l);
            }
            topic
        })
        .collect();
    Value::Array(topics)
}

/// `fixes` of a NavSatFix topic: the tangent plane its fixes are drawn in.
fn fixes_json(l: &LocalFixes) -> Value {
    let [latitude_deg, longitude_deg, altitude_m] = l.origin;
    json!({
        "projection": "local_tangent_wgs84",
        "origin": {
            "latitude_deg": latitude_deg,
            "longitude_deg": longitude_deg,
            "altitude_m": altitude_m,
            "message": l.fixes.first().map_or(0, |f| f.index),
        },
        "meridian_radius_m": l.radii[0],
        "prime_vertical_radius_m": l.radii[1],
        "drawn": l.fixes.len(),
        "with_region": l.fixes.iter().filter(|f| f.covariance_en.is_some()).count(),
    })
}

/// What `check` says of the sensor topics: for each topic with a defect not in `allow`, its
/// first defect on a line (file, topic, block, message, stamp, count and `--allow` name); the
/// kinds of note found, counted; the defect kinds found but allowed added to `allowed`.
pub(super) fn sensor_defects(
    file: &str,
    plan: &LogSummary,
    allow: &[Issue],
    allowed: &mut Vec<Issue>,
) -> (Vec<String>, usize) {
    let mut lines = Vec::new();
    let mut notes = 0;
    for t in &plan.sensors {
        let findings: Vec<_> = t.findings().collect();
        let mut kinds: Vec<Issue> = findings
            .iter()
            .filter(|f| f.3 == Class::Note)
            .map(|f| f.1)
            .collect();
        kinds.sort();
        kinds.dedup();
        notes += kinds.len();
        for f in findings.iter().filter(|f| f.3 == Class::Defect) {
            if allow.contains(&f.1) && !allowed.contains(&f.1) {
                allowed.push(f.1);
            }
        }
        let mut found: Vec<_> = findings
            .iter()
            .filter(|f| f.3 == Class::Defect && !allow.contains(&f.1))
            .collect();
        found.sort_by_key(|f| (f.2.first_index, f.2.first_stamp_ns));
        let Some((block, issue, c, _)) = found.first() else {
            continue;
        };
        let others = match found.len() - 1 {
            0 => String::new(),
            n => format!("; {n} more defect(s) on this topic, see `posecov report`"),
        };
        let b = t.blocks.iter().find(|b| Some(b.spec.name) == *block);
        lines.push(format!(
            "{file}: topic {}, message {} (stamp {:.3} s): {}{} — {} ({} message(s); `--allow {}` accepts it{others})",
            t.name,
            c.first_index,
            stamp_seconds(c.first_stamp_ns),
            issue.name(),
            b.map_or_else(String::new, |b| format!(" on {}", t.kind.field(&b.spec))),
            sensor_sentence(*issue, b, t),
            c.count,
            issue.name(),
        ));
    }
    (lines, notes)
}
