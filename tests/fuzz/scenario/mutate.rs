//! The mutations themselves: values at the edges, names, tables, and text lines.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use toml::{Table, Value};

use super::generate::{
    COV_KEYS, DRAW_KEYS, FLOAT_EDGES, GROUPS, INT_EDGES, MEAN_KEYS, METHODS, OPERATION_KEYS,
    POSE_KEYS, SCENARIO_KEYS, Seg, TOKENS, at_mut, kinds,
};
use crate::harness::mutate_bytes;

pub fn show(p: &[Seg]) -> String {
    let mut s = String::new();
    for seg in p {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Idx(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

pub fn remove(doc: &mut Value, p: &[Seg]) {
    let Some((last, parent)) = p.split_last() else {
        return;
    };
    match (at_mut(doc, parent), last) {
        (Some(Value::Table(t)), Seg::Key(k)) => {
            t.remove(k);
        }
        (Some(Value::Array(a)), Seg::Idx(i)) if *i < a.len() => {
            a.remove(*i);
        }
        _ => {}
    }
}

/// Names defined in the document: poses, outputs (points marked).
pub fn names_in(doc: &Value) -> Vec<String> {
    let mut names = Vec::new();
    for p in doc
        .get("pose")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        if let Some(n) = p.get("name").and_then(Value::as_str) {
            names.push(n.to_owned());
        }
    }
    for o in doc
        .get("operation")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        if let Some(n) = o.get("output").and_then(Value::as_str) {
            names.push(n.to_owned());
        }
    }
    names
}

pub fn random_name(rng: &mut ChaCha8Rng, names: &[String]) -> String {
    match rng.random_range(0..10) {
        0..=5 if !names.is_empty() => names[rng.random_range(0..names.len())].clone(),
        6 => "nowhere_from_nothing".into(),
        7 => {
            ["", "a b", "world/x", "ü", "x".repeat(300).as_str()][rng.random_range(0..5)].to_owned()
        }
        8 => "landmark".into(),
        _ => "start".into(),
    }
}

pub fn edge_number(rng: &mut ChaCha8Rng, old: Option<Value>) -> Value {
    let int = matches!(old, Some(Value::Integer(_)));
    // Usually keep the type; sometimes flip it (an integer where a float goes is fine in TOML
    // for f64, a float where a count goes is not).
    if int != rng.random_bool(0.15) {
        Value::Integer(INT_EDGES[rng.random_range(0..INT_EDGES.len())])
    } else {
        Value::Float(FLOAT_EDGES[rng.random_range(0..FLOAT_EDGES.len())])
    }
}

pub fn wrong_type(rng: &mut ChaCha8Rng) -> Value {
    match rng.random_range(0..7) {
        0 => Value::String("1.0".into()),
        1 => Value::Boolean(true),
        2 => Value::Integer(INT_EDGES[rng.random_range(0..INT_EDGES.len())]),
        3 => Value::Float(FLOAT_EDGES[rng.random_range(0..FLOAT_EDGES.len())]),
        4 => Value::Array(Vec::new()),
        5 => Value::Array(vec![Value::Float(1.0), Value::String("x".into())]),
        _ => Value::Table(Table::new()),
    }
}

/// A table of the document and the keys it may hold.
pub fn pick_table(rng: &mut ChaCha8Rng, doc: &mut Value) -> (Vec<Seg>, &'static [&'static str]) {
    let key = |k: &str| Seg::Key(k.to_owned());
    let count = |doc: &Value, k: &str| doc.get(k).and_then(Value::as_array).map_or(0, Vec::len);
    let ops = count(doc, "operation");
    let poses = count(doc, "pose");
    match rng.random_range(0..10) {
        0..=4 if ops > 0 => (
            vec![key("operation"), Seg::Idx(rng.random_range(0..ops))],
            OPERATION_KEYS,
        ),
        5 if poses > 0 => (
            vec![key("pose"), Seg::Idx(rng.random_range(0..poses))],
            POSE_KEYS,
        ),
        6 if poses > 0 => {
            let i = rng.random_range(0..poses);
            if doc
                .get("pose")
                .and_then(|p| p.as_array()?.get(i)?.get("cov"))
                .is_some()
            {
                (vec![key("pose"), Seg::Idx(i), key("cov")], COV_KEYS)
            } else {
                (vec![key("pose"), Seg::Idx(i), key("mean")], MEAN_KEYS)
            }
        }
        7 if poses > 0 => (
            vec![
                key("pose"),
                Seg::Idx(rng.random_range(0..poses)),
                key("mean"),
            ],
            MEAN_KEYS,
        ),
        8 => {
            if let Value::Table(t) = doc {
                t.entry("draw".to_owned())
                    .or_insert_with(|| Value::Table(Table::new()));
            }
            (vec![key("draw")], DRAW_KEYS)
        }
        _ => (vec![key("scenario")], SCENARIO_KEYS),
    }
}

/// A value for `key`: usually of a plausible shape with edge numbers, sometimes wrong.
pub fn random_value(rng: &mut ChaCha8Rng, names: &[String], key: &str) -> Value {
    let f =
        |rng: &mut ChaCha8Rng| Value::Float(FLOAT_EDGES[rng.random_range(0..FLOAT_EDGES.len())]);
    let small =
        |rng: &mut ChaCha8Rng| Value::Float([0.0, 0.1, 1.0, -1.0, 0.5][rng.random_range(0..5)]);
    if rng.random_bool(0.1) {
        return wrong_type(rng);
    }
    let vec_of = |rng: &mut ChaCha8Rng, n: usize| {
        Value::Array(
            (0..n)
                .map(|_| {
                    if rng.random_bool(0.3) {
                        f(rng)
                    } else {
                        small(rng)
                    }
                })
                .collect(),
        )
    };
    let n = [1, 2, 3, 4, 6, 36][rng.random_range(0..6)];
    match key {
        "input" | "lhs" | "rhs" | "by" | "output" | "name" => {
            Value::String(random_name(rng, names))
        }
        "inputs" => Value::Array(
            (0..rng.random_range(0..4))
                .map(|_| Value::String(random_name(rng, names)))
                .collect(),
        ),
        "kind" => {
            let kinds = kinds();
            Value::String(kinds[rng.random_range(0..kinds.len())].into())
        }
        "group" => Value::String(GROUPS[rng.random_range(0..GROUPS.len())].into()),
        "model" => Value::String(["increment", "exp", "euler"][rng.random_range(0..3)].into()),
        "side" => Value::String(["left", "right", "up"][rng.random_range(0..3)].into()),
        "order" => Value::String(
            ["rotation_first", "translation_first", "x"][rng.random_range(0..3)].into(),
        ),
        "view" => Value::String(["top", "perspective", "side"][rng.random_range(0..3)].into()),
        "methods" => Value::Array(
            METHODS
                .iter()
                .filter(|_| rng.random_bool(0.4))
                .map(|s| Value::String((*s).into()))
                .collect(),
        ),
        "steps" | "samples" | "seed" => {
            Value::Integer(INT_EDGES[rng.random_range(0..INT_EDGES.len())])
        }
        "title" | "description" | "source" => Value::String("t".repeat(rng.random_range(0..3))),
        "axes" | "clouds" | "sample_axes" | "ellipsoids" | "bananas" | "orientation"
        | "trajectories" | "draw" => Value::Boolean(rng.random_bool(0.5)),
        "controls" | "cross_cov" | "point_cov" | "matrix" => {
            let rows = [0, 1, 2, 3, 4, 6][rng.random_range(0..6)];
            Value::Array((0..rows).map(|_| vec_of(rng, n.min(6))).collect())
        }
        "mean" => {
            let mut t = Table::new();
            let k = MEAN_KEYS[rng.random_range(0..MEAN_KEYS.len())];
            t.insert(k.into(), random_value(rng, names, k));
            Value::Table(t)
        }
        "cov" | "noise" => {
            let mut t = Table::new();
            let k = ["std", "std_deg", "matrix", "ros"][rng.random_range(0..4)];
            t.insert(k.into(), random_value(rng, names, k));
            if rng.random_bool(0.3) {
                t.insert("side".into(), Value::String("left".into()));
            }
            Value::Table(t)
        }
        "angle" | "angle_deg" | "wheel_radius" | "wheelbase" | "duration" | "diffusion"
        | "speed" | "turn_rate" | "dt" | "confidence" | "axis_length" => f(rng),
        "xy_theta" | "xy_theta_deg" | "xyz" | "rpy" | "rpy_deg" | "rate" => {
            let len = if rng.random_bool(0.8) { 3 } else { n };
            vec_of(rng, len)
        }
        "quaternion_xyzw" | "axis_angle" => {
            let len = if rng.random_bool(0.8) { 4 } else { n };
            vec_of(rng, len)
        }
        _ => vec_of(rng, n),
    }
}

/// One text mutation: a byte-level one ([`mutate_bytes`], with TOML tokens) or a line
/// duplicated, deleted, swapped or taken from another scenario.
pub fn mutate_text(
    rng: &mut ChaCha8Rng,
    b: &mut Vec<u8>,
    corpus: &[(&'static str, &'static str, Option<Table>)],
) -> String {
    if b.is_empty() {
        b.extend_from_slice(b"[scenario]\n");
        return "was empty".into();
    }
    let lines = |b: &[u8]| -> Vec<(usize, usize)> {
        let mut v = Vec::new();
        let mut s = 0;
        for (i, c) in b.iter().enumerate() {
            if *c == b'\n' {
                v.push((s, i + 1));
                s = i + 1;
            }
        }
        if s < b.len() {
            v.push((s, b.len()));
        }
        v
    };
    match rng.random_range(0..9) {
        0..=4 => mutate_bytes(rng, b, TOKENS),
        5 | 6 => {
            let ls = lines(b);
            let (s, e) = ls[rng.random_range(0..ls.len())];
            let line = b[s..e].to_vec();
            if rng.random_bool(0.5) {
                b.splice(e..e, line);
                format!("duplicate line at {s}")
            } else {
                b.drain(s..e);
                format!("delete line at {s}")
            }
        }
        7 => {
            let ls = lines(b);
            let (s1, e1) = ls[rng.random_range(0..ls.len())];
            let (s2, e2) = ls[rng.random_range(0..ls.len())];
            if s1 < s2 && e1 <= s2 {
                let l1 = b[s1..e1].to_vec();
                let l2 = b[s2..e2].to_vec();
                b.splice(s2..e2, l1);
                b.splice(s1..e1, l2);
            }
            "swap lines".into()
        }
        _ => {
            let (_, other, _) = corpus[rng.random_range(0..corpus.len())];
            let ls: Vec<&str> = other.lines().collect();
            let l = ls[rng.random_range(0..ls.len())];
            let pos = lines(b)
                .iter()
                .map(|(s, _)| *s)
                .nth(rng.random_range(0..lines(b).len()))
                .unwrap_or(0);
            b.splice(pos..pos, format!("{l}\n").into_bytes());
            format!("insert line {l:?}")
        }
    }
}
