//! Every bundled example's `report --json` validates against `docs/report.schema.json`, and
//! the schema documents every key the reports carry (it allows more: later work adds keys,
//! and a reader must not break on them — but a key posecov writes and the schema does not
//! list fails here, naming it).
//!
//! The checker below implements exactly the JSON Schema (2020-12) keywords the file uses:
//! `type`, `const`, `enum`, `minimum`, `required`, `properties`, `additionalProperties` (as a
//! schema), `propertyNames`, `items`, `anyOf` and local `$ref`s into `$defs`; the annotations
//! `$schema`, `$id`, `title` and `description` are read only. A keyword it does not know fails
//! the test, so the schema cannot gain a rule that nothing checks. (Why not the `jsonschema`
//! crate: it would add about 20 crates and ~100 000 lines to the test build for the dozen
//! keywords used here.)

mod common;

use posecov::app::{Overrides, commands::report};
use serde_json::Value;

const SCHEMA: &str = include_str!("../docs/report.schema.json");

const KNOWN: [&str; 16] = [
    "$schema",
    "$id",
    "$defs",
    "title",
    "description",
    "type",
    "const",
    "enum",
    "minimum",
    "required",
    "properties",
    "additionalProperties",
    "propertyNames",
    "items",
    "anyOf",
    "$ref",
];

/// What is wrong with a report at a place: a value that breaks the schema, or a key the
/// schema does not document.
#[derive(Debug, Clone, PartialEq)]
enum Problem {
    Invalid(String),
    Undocumented(String),
}

fn type_ok(value: &Value, t: &str) -> bool {
    match t {
        "object" => value.is_object(),
        "array" => value.is_array(),
        "string" => value.is_string(),
        "integer" => value.is_i64() || value.is_u64(),
        "number" => value.is_number(),
        "boolean" => value.is_boolean(),
        "null" => value.is_null(),
        other => panic!("unknown type {other} in the schema"),
    }
}

/// Checks `value` at `at` against `schema` (resolving `$ref`s in `root`), appending problems.
fn check(root: &Value, schema: &Value, value: &Value, at: &str, out: &mut Vec<Problem>) {
    let Some(schema) = schema.as_object() else {
        panic!("{at}: a schema must be an object");
    };
    for key in schema.keys() {
        assert!(
            KNOWN.contains(&key.as_str()),
            "{at}: keyword {key} is not checked"
        );
    }
    let invalid = |out: &mut Vec<Problem>, why: String| out.push(Problem::Invalid(why));
    if let Some(r) = schema.get("$ref").and_then(Value::as_str) {
        let name = r.strip_prefix("#/$defs/").expect("a local $ref");
        let target = &root["$defs"][name];
        assert!(target.is_object(), "{at}: $ref {r} names no definition");
        check(root, target, value, at, out);
    }
    if let Some(t) = schema.get("type") {
        let ok = match t {
            Value::String(t) => type_ok(value, t),
            Value::Array(ts) => ts
                .iter()
                .any(|t| type_ok(value, t.as_str().expect("type names"))),
            _ => panic!("{at}: bad type"),
        };
        if !ok {
            invalid(out, format!("{at}: {value} is not {t}"));
            return;
        }
    }
    if let Some(c) = schema.get("const")
        && c != value
    {
        invalid(out, format!("{at}: {value} is not {c}"));
    }
    if let Some(e) = schema.get("enum").and_then(Value::as_array)
        && !e.contains(value)
    {
        invalid(out, format!("{at}: {value} not in {e:?}"));
    }
    if let (Some(m), Some(v)) = (
        schema.get("minimum").and_then(Value::as_f64),
        value.as_f64(),
    ) && v < m
    {
        invalid(out, format!("{at}: {value} below {m}"));
    }
    if let Some(any) = schema.get("anyOf").and_then(Value::as_array) {
        // The first branch the value satisfies; its undocumented keys count.
        let branches: Vec<Vec<Problem>> = any
            .iter()
            .map(|s| {
                let mut o = Vec::new();
                check(root, s, value, at, &mut o);
                o
            })
            .collect();
        match branches
            .into_iter()
            .find(|o| !o.iter().any(|p| matches!(p, Problem::Invalid(_))))
        {
            Some(o) => out.extend(o),
            None => invalid(out, format!("{at}: {value} matches none of anyOf")),
        }
    }
    if let Some(object) = value.as_object() {
        for key in schema
            .get("required")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if !object.contains_key(key.as_str().expect("required names")) {
                invalid(out, format!("{at}: missing {key}"));
            }
        }
        let properties = schema.get("properties").and_then(Value::as_object);
        let additional = schema.get("additionalProperties");
        let names = schema.get("propertyNames");
        // Where this schema describes the object (anything but a bare `$ref`/`anyOf`), every
        // key must be documented.
        let describes = properties.is_some() || additional.is_some() || schema.contains_key("type");
        for (key, v) in object {
            let here = format!("{at}.{key}");
            if let Some(names) = names {
                check(root, names, &Value::String(key.clone()), &here, out);
            }
            match (properties.and_then(|p| p.get(key)), additional) {
                (Some(s), _) => check(root, s, v, &here, out),
                (None, Some(s)) if s.is_object() => check(root, s, v, &here, out),
                _ if describes => out.push(Problem::Undocumented(here)),
                _ => {}
            }
        }
    }
    if let (Some(items), Some(array)) = (schema.get("items"), value.as_array()) {
        for (i, v) in array.iter().enumerate() {
            check(root, items, v, &format!("{at}[{i}]"), out);
        }
    }
}

fn problems(schema: &Value, value: &Value, name: &str) -> Vec<Problem> {
    let mut out = Vec::new();
    check(schema, schema, value, name, &mut out);
    out
}

/// Undocumented keys inside arrays are reported once per path without indices.
fn dedup(problems: Vec<Problem>) -> Vec<String> {
    let mut seen: Vec<String> = problems
        .into_iter()
        .map(|p| match p {
            Problem::Invalid(s) => format!("invalid: {s}"),
            Problem::Undocumented(s) => {
                let generic: String = s
                    .split('[')
                    .map(|part| part.split_once(']').map_or(part, |(_, rest)| rest))
                    .collect::<Vec<_>>()
                    .join("[]");
                format!("not in docs/report.schema.json: {generic}")
            }
        })
        .collect();
    seen.sort();
    seen.dedup();
    seen
}

#[test]
fn every_bundled_example_validates_against_the_schema_and_every_key_is_documented() {
    let schema: Value = serde_json::from_str(SCHEMA).expect("the schema is JSON");
    let overrides = Overrides {
        samples: Some(64),
        ..Default::default()
    };
    let mut formats = std::collections::BTreeSet::new();
    for example in posecov::input::examples() {
        let text = report(example.name, &overrides, true).expect(example.name);
        let value: Value = serde_json::from_str(&text).expect("JSON");
        let found = dedup(problems(&schema, &value, example.name));
        assert!(found.is_empty(), "{}: {found:#?}", example.name);
        assert_eq!(value["schema_version"], 2);
        assert_eq!(value["posecov_version"], env!("CARGO_PKG_VERSION"));
        formats.insert(value["format"].as_str().unwrap().to_owned());
    }
    let every: Vec<&str> = vec!["graph", "mcap", "ros1_bag", "scenario"];
    assert_eq!(
        formats.iter().map(String::as_str).collect::<Vec<_>>(),
        every
    );
}

#[test]
fn a_ros2_sqlite_bag_report_validates_with_its_format() {
    let schema: Value = serde_json::from_str(SCHEMA).unwrap();
    let bag = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2/arc_humble");
    let overrides = Overrides {
        reference: Some("/truth".into()),
        ..Default::default()
    };
    let text = report(bag, &overrides, true).unwrap();
    let value: Value = serde_json::from_str(&text).unwrap();
    let found = dedup(problems(&schema, &value, "arc_humble"));
    assert!(found.is_empty(), "{found:#?}");
    assert_eq!(value["format"], "ros2_sqlite");
}

#[test]
fn an_ov_eval_trajectory_report_validates_with_its_format() {
    let schema: Value = serde_json::from_str(SCHEMA).unwrap();
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ov_eval");
    let overrides = Overrides {
        reference: Some(format!("{data}/gt.txt")),
        ..Default::default()
    };
    let text = report(&format!("{data}/estimate.txt"), &overrides, true).unwrap();
    let value: Value = serde_json::from_str(&text).unwrap();
    let found = dedup(problems(&schema, &value, "estimate"));
    assert!(found.is_empty(), "{found:#?}");
    assert_eq!(value["format"], "ov_eval");
}

#[test]
fn a_log_report_with_a_reference_validates_and_documents_its_consistency_keys() {
    let schema: Value = serde_json::from_str(SCHEMA).unwrap();
    let dir = std::env::temp_dir().join(format!("posecov-schema-nees-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("nees.mcap");
    std::fs::write(&log, common::logs::nees_log(3)).unwrap();
    let overrides = Overrides {
        reference: Some("tf:base_link".into()),
        align: Some(posecov::eval::log::nees::Align::Se3),
        ..Default::default()
    };
    let text = report(log.to_str().unwrap(), &overrides, true).unwrap();
    let value: Value = serde_json::from_str(&text).unwrap();
    let found = dedup(problems(&schema, &value, "nees"));
    assert!(found.is_empty(), "{found:#?}");
    assert!(value["topics"][0]["consistency"]["anees"].is_number());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_checker_refuses_what_the_schema_forbids_and_finds_undocumented_keys() {
    let schema: Value = serde_json::from_str(SCHEMA).unwrap();
    let bad = serde_json::json!({
        "schema_version": "1",
        "format": "csv",
        "meta": { "seed": -1, "samples": 1, "confidence": 0.9, "mystery": 1 },
        "topics": [{ "health": { "made_up": {} } }],
    });
    let found = dedup(problems(&schema, &bad, "bad"));
    for expected in [
        "invalid: bad: missing \"scenario\"",
        "invalid: bad.schema_version: \"1\" is not \"integer\"",
        "invalid: bad.format: \"csv\" not in",
        "invalid: bad.meta.seed: -1 below 0",
        "invalid: bad.topics[0]: missing \"sigma\"",
        "invalid: bad.topics[0].health.made_up: \"made_up\" not in",
        "not in docs/report.schema.json: bad.meta.mystery",
    ] {
        assert!(
            found.iter().any(|f| f.starts_with(expected)),
            "{expected} in {found:#?}"
        );
    }
}

#[test]
fn a_log_report_has_sigma_per_axis_in_si_units_and_clean_stamps() {
    let text = report("jackal_odometry", &Overrides::default(), true).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    let odom = &v["topics"][0];
    // test2.bag: Σxx = Σyy = 0.001 m², Σyaw = 0.03 rad² in every message; z, roll and pitch
    // are 1e6 placeholders (not estimated: absent).
    for (axis, sigma, unit) in [
        ("x", 0.001f64.sqrt(), "m"),
        ("y", 0.001f64.sqrt(), "m"),
        ("yaw", 0.03f64.sqrt(), "rad"),
    ] {
        let s = &odom["sigma"][axis];
        assert_eq!(s["unit"], unit);
        assert_eq!(s["messages"], 3060);
        for key in ["first", "last", "min", "median_of_kept", "max"] {
            assert!(
                (s[key].as_f64().unwrap() - sigma).abs() < 1e-15,
                "{axis} {key}: {s}"
            );
        }
    }
    for axis in ["z", "roll", "pitch"] {
        assert!(odom["sigma"].get(axis).is_none(), "{axis}");
    }
    // The position trace as plotted: x + y variances, every message (3060 < 4 096 kept).
    let trace = &odom["position_trace"];
    assert_eq!(trace["stamps_s"].as_array().unwrap().len(), 3060);
    assert!(
        trace["values_m2"]
            .as_array()
            .unwrap()
            .iter()
            .all(|t| (t.as_f64().unwrap() - 0.002).abs() < 1e-15)
    );
    assert_eq!(
        (odom["frame_id"].as_str(), odom["ros_reading"].as_str()),
        (Some("odom"), Some("tf2"))
    );
    assert_eq!(odom["health"]["constant"]["class"], "defect");
    assert_eq!(
        v["units"]["sigma_rotation"],
        "rad (sigma.roll, .pitch, .yaw)"
    );
    // Stamps to the microsecond, without float noise.
    assert!(text.contains("\"last_s\": 108.764,"), "{}", &odom["stamps"]);
    assert!(text.contains("\"first_stamp_s\": 47.584,"));
    assert!(!text.contains("108.76400000000001"));
    assert_eq!(trace["stamps_s"][1], serde_json::json!(47.604));
}

#[test]
fn the_median_is_of_the_kept_series_and_the_rest_of_every_message() {
    // covariance_health's /odom: a planar Odometry whose σ changes from message to message.
    let text = report("covariance_health", &Overrides::default(), true).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    for topic in v["topics"].as_array().unwrap() {
        for (axis, s) in topic["sigma"].as_object().unwrap() {
            let (lo, hi) = (s["min"].as_f64().unwrap(), s["max"].as_f64().unwrap());
            for key in ["first", "last", "median_of_kept"] {
                let x = s[key].as_f64().unwrap();
                assert!(lo <= x && x <= hi, "{} {axis} {key}: {s}", topic["name"]);
            }
            assert!(s["messages"].as_u64().unwrap() <= topic["messages"].as_u64().unwrap());
        }
    }
}
