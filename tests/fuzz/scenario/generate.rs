//! Case `k` of a run: a bundled scenario (or an extra seed), mutated in its TOML structure
//! (edge numbers, swapped names, dropped and duplicated entries, wrong lengths and types) and
//! in its bytes, deterministically from the run's seed.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use toml::{Table, Value};

use super::mutate::{
    edge_number, mutate_text, names_in, pick_table, random_name, random_value, remove, show,
    wrong_type,
};
use super::seeds::EXTRA_SEEDS;

pub const FLOAT_EDGES: &[f64] = &[
    0.0,
    -0.0,
    -1.0,
    -5.0,
    1.0,
    0.5,
    2.0,
    100.0,
    1e6,
    1e9,
    1e15,
    1e300,
    -1e300,
    f64::MAX,
    f64::MIN,
    1.7e308,
    1e-300,
    5e-324,
    1e-9,
    1e-12,
    std::f64::consts::PI,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
];

pub const INT_EDGES: &[i64] = &[
    0,
    1,
    2,
    3,
    -1,
    -5,
    32,
    1000,
    100_000,
    100_001,
    1_000_000,
    1_000_000_000,
    10_000_000,
    i64::MAX,
    i64::MIN,
];

/// Every operation kind, from the library's one table of operation keys.
pub fn kinds() -> Vec<&'static str> {
    posecov::input::scenario::OPERATION_KINDS
        .iter()
        .map(|k| k.kind)
        .collect()
}

pub const METHODS: &[&str] = &[
    "exact",
    "first_order",
    "lecture_no_jr",
    "second_order",
    "fourth_order",
    "sigma_points",
    "monte_carlo",
    "vector_space",
    "closed_form",
    "numeric_integral",
];

pub const GROUPS: &[&str] = &["so2", "se2", "so3", "se3"];

pub const OPERATION_KEYS: &[&str] = &[
    "kind",
    "output",
    "input",
    "lhs",
    "rhs",
    "by",
    "inputs",
    "cross_cov",
    "controls",
    "steps",
    "noise",
    "model",
    "point",
    "point_cov",
    "wheel_radius",
    "wheelbase",
    "duration",
    "diffusion",
    "speed",
    "turn_rate",
    "dt",
    "rate",
];
pub const SCENARIO_KEYS: &[&str] = &[
    "title",
    "description",
    "source",
    "group",
    "seed",
    "samples",
    "confidence",
    "methods",
];
pub const POSE_KEYS: &[&str] = &["name", "mean", "cov", "draw"];
pub const MEAN_KEYS: &[&str] = &[
    "xy_theta",
    "xy_theta_deg",
    "angle",
    "angle_deg",
    "xyz",
    "quaternion_xyzw",
    "rpy",
    "rpy_deg",
    "axis_angle",
    "matrix",
    "tangent",
];
pub const COV_KEYS: &[&str] = &["std", "std_deg", "matrix", "ros", "side", "order"];
pub const DRAW_KEYS: &[&str] = &[
    "axes",
    "clouds",
    "sample_axes",
    "ellipsoids",
    "bananas",
    "orientation",
    "trajectories",
    "axis_length",
    "view",
];

/// Bytes and tokens the byte mutator inserts.
pub const TOKENS: &[&str] = &[
    "[",
    "]",
    "{",
    "}",
    "=",
    "\"",
    "'",
    ",",
    "\n",
    "#",
    ".",
    "-",
    "0",
    "1",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "1e-300",
    "[[operation]]\n",
    "[[pose]]\n",
    "[draw]\n",
    "[scenario]\n",
    "\"\"\"",
    "\\u0000",
    "\u{e9}",
    "\u{1F600}",
    "true",
    "99999999999999999999",
    "1_000",
    "0x1f",
    "1979-05-27",
];

#[derive(Debug, Clone)]
pub enum Seg {
    Key(String),
    Idx(usize),
}

pub fn at<'a>(v: &'a Value, path: &[Seg]) -> Option<&'a Value> {
    let mut v = v;
    for s in path {
        v = match (s, v) {
            (Seg::Key(k), Value::Table(t)) => t.get(k)?,
            (Seg::Idx(i), Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

pub fn at_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    let mut v = v;
    for s in path {
        v = match (s, v) {
            (Seg::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Seg::Idx(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// Every path in the document (tables, arrays and leaves), root excluded.
pub fn all_paths(v: &Value, prefix: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    match v {
        Value::Table(t) => {
            for (k, c) in t {
                prefix.push(Seg::Key(k.clone()));
                out.push(prefix.clone());
                all_paths(c, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                prefix.push(Seg::Idx(i));
                out.push(prefix.clone());
                all_paths(c, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

/// Seeds besides the bundled scenarios, for what none of them uses: SO(2), `point_through_pose`,
pub struct Generator {
    corpus: Vec<(&'static str, &'static str, Option<Table>)>,
}

impl Generator {
    pub fn new() -> Self {
        let corpus = posecov::input::scenario::bundled::BUNDLED
            .iter()
            .map(|b| (b.name, b.text))
            .chain(EXTRA_SEEDS.iter().copied())
            .map(|(name, text)| (name, text, toml::from_str::<Table>(text).ok()))
            .collect();
        Self { corpus }
    }

    /// Case `case` of run `seed`: (origin, text, what was done).
    pub fn case(&self, seed: u64, case: u64) -> (String, String) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(case);
        let (name, text, table) = &self.corpus[rng.random_range(0..self.corpus.len())];
        let mut log = vec![format!("from {name}")];
        let mode = rng.random_range(0..100);
        let mut out = text.to_string();
        // 60 %: structure only; 15 %: structure then bytes; 25 %: bytes only.
        if mode < 75
            && let Some(table) = table
        {
            let mut doc = Value::Table(table.clone());
            let rounds = [1, 1, 1, 1, 2, 2, 3, 4][rng.random_range(0..8)];
            for _ in 0..rounds {
                log.push(self.mutate_structure(&mut rng, &mut doc));
            }
            if let Value::Table(t) = &doc {
                match toml::to_string(t) {
                    Ok(s) => out = s,
                    Err(e) => log.push(format!("(serialisation failed: {e}; original text)")),
                }
            }
        }
        if mode >= 60 {
            let mut bytes = out.into_bytes();
            for _ in 0..rng.random_range(1..=3) {
                log.push(mutate_text(&mut rng, &mut bytes, &self.corpus));
            }
            out = String::from_utf8_lossy(&bytes).into_owned();
        }
        (out, log.join("; "))
    }

    fn mutate_structure(&self, rng: &mut ChaCha8Rng, doc: &mut Value) -> String {
        let mut paths = Vec::new();
        all_paths(doc, &mut Vec::new(), &mut paths);
        let names = names_in(doc);
        match rng.random_range(0..16) {
            // An edge number at any numeric leaf.
            0..=3 => {
                let nums: Vec<&Vec<Seg>> = paths
                    .iter()
                    .filter(|p| matches!(at(doc, p), Some(Value::Integer(_) | Value::Float(_))))
                    .collect();
                if nums.is_empty() {
                    return "no number".into();
                }
                let p = nums[rng.random_range(0..nums.len())].clone();
                let v = edge_number(rng, at_mut(doc, &p).cloned());
                let msg = format!("{} = {v}", show(&p));
                *at_mut(doc, &p).unwrap() = v;
                msg
            }
            // A known key of some table set to an edge value (of a plausible or wrong type).
            4..=6 => {
                let (table_path, keys) = pick_table(rng, doc);
                let key = keys[rng.random_range(0..keys.len())];
                let v = random_value(rng, &names, key);
                let msg = format!("{}.{key} = {v}", show(&table_path));
                if let Some(Value::Table(t)) = at_mut(doc, &table_path) {
                    t.insert(key.to_owned(), v);
                }
                msg
            }
            // A name reference swapped: another name, a point output, unknown, malformed.
            7 => {
                let refs: Vec<&Vec<Seg>> = paths
                    .iter()
                    .filter(|p| {
                        p.iter().any(|s| {
                            matches!(s, Seg::Key(k) if ["input", "lhs", "rhs", "by", "inputs", "output", "name"].contains(&k.as_str()))
                        })
                    })
                    .collect();
                if refs.is_empty() {
                    return "no name".into();
                }
                let p = refs[rng.random_range(0..refs.len())].clone();
                let v = Value::String(random_name(rng, &names));
                let msg = format!("{} = {v}", show(&p));
                if let Some(slot) = at_mut(doc, &p) {
                    *slot = v;
                }
                msg
            }
            // Drop a key or an entry.
            8 => {
                if paths.is_empty() {
                    return "empty".into();
                }
                let p = paths[rng.random_range(0..paths.len())].clone();
                remove(doc, &p);
                format!("drop {}", show(&p))
            }
            // Duplicate an entry of an array (a pose, an operation, a control, a number).
            9 => {
                let arrays: Vec<&Vec<Seg>> = paths
                    .iter()
                    .filter(|p| matches!(at(doc, p), Some(Value::Array(a)) if !a.is_empty()))
                    .collect();
                if arrays.is_empty() {
                    return "no array".into();
                }
                let p = arrays[rng.random_range(0..arrays.len())].clone();
                if let Some(Value::Array(a)) = at_mut(doc, &p) {
                    let i = rng.random_range(0..a.len());
                    let x = a[i].clone();
                    a.insert(rng.random_range(0..=a.len()), x);
                }
                format!("duplicate an entry of {}", show(&p))
            }
            // Arrays: emptied, shortened, lengthened, nested.
            10 => {
                let arrays: Vec<&Vec<Seg>> = paths
                    .iter()
                    .filter(|p| matches!(at(doc, p), Some(Value::Array(_))))
                    .collect();
                if arrays.is_empty() {
                    return "no array".into();
                }
                let p = arrays[rng.random_range(0..arrays.len())].clone();
                let how = rng.random_range(0..4);
                if let Some(Value::Array(a)) = at_mut(doc, &p) {
                    match how {
                        0 => a.clear(),
                        1 => {
                            a.pop();
                        }
                        2 => a.push(a.last().cloned().unwrap_or(Value::Float(1.0))),
                        _ => {
                            let inner = std::mem::take(a);
                            a.push(Value::Array(inner));
                        }
                    }
                }
                format!("array {} mutated ({how})", show(&p))
            }
            // A wrong type anywhere.
            11 => {
                if paths.is_empty() {
                    return "empty".into();
                }
                let p = paths[rng.random_range(0..paths.len())].clone();
                let v = wrong_type(rng);
                let msg = format!("{} = {v} (type)", show(&p));
                if let Some(slot) = at_mut(doc, &p) {
                    *slot = v;
                }
                msg
            }
            // Another kind / group / methods.
            12 => {
                let n = doc
                    .get("operation")
                    .and_then(Value::as_array)
                    .map_or(0, Vec::len);
                if n > 0 && rng.random_bool(0.5) {
                    let i = rng.random_range(0..n);
                    let kinds = kinds();
                    let k = kinds[rng.random_range(0..kinds.len())];
                    if let Some(Value::Table(t)) =
                        at_mut(doc, &[Seg::Key("operation".into()), Seg::Idx(i)])
                    {
                        t.insert("kind".into(), Value::String(k.into()));
                    }
                    format!("operation[{i}].kind = {k}")
                } else if rng.random_bool(0.5) {
                    let g = GROUPS[rng.random_range(0..GROUPS.len())];
                    if let Some(Value::Table(t)) = at_mut(doc, &[Seg::Key("scenario".into())]) {
                        t.insert("group".into(), Value::String(g.into()));
                    }
                    format!("group = {g}")
                } else {
                    let mut m: Vec<Value> = METHODS
                        .iter()
                        .filter(|_| rng.random_bool(0.5))
                        .map(|s| Value::String((*s).into()))
                        .collect();
                    if rng.random_bool(0.1) {
                        m.push(Value::String("monte_karlo".into()));
                    }
                    let msg = format!("methods = {}", Value::Array(m.clone()));
                    if let Some(Value::Table(t)) = at_mut(doc, &[Seg::Key("scenario".into())]) {
                        t.insert("methods".into(), Value::Array(m));
                    }
                    msg
                }
            }
            // Crossover: a pose or an operation from another bundled scenario.
            13 => {
                let (other, _, t) = &self.corpus[rng.random_range(0..self.corpus.len())];
                let key = if rng.random_bool(0.5) {
                    "pose"
                } else {
                    "operation"
                };
                let Some(entries) = t
                    .as_ref()
                    .and_then(|t| t.get(key))
                    .and_then(Value::as_array)
                else {
                    return "no entries".into();
                };
                if entries.is_empty() {
                    return "no entries".into();
                }
                let e = entries[rng.random_range(0..entries.len())].clone();
                if let Value::Table(root) = doc {
                    let a = root
                        .entry(key.to_owned())
                        .or_insert_with(|| Value::Array(Vec::new()));
                    if let Value::Array(a) = a {
                        let at = rng.random_range(0..=a.len());
                        a.insert(at, e);
                    }
                }
                format!("{key} from {other}")
            }
            // Reorder operations (forward references).
            14 => {
                if let Some(Value::Array(a)) = at_mut(doc, &[Seg::Key("operation".into())])
                    && a.len() > 1
                {
                    let i = rng.random_range(0..a.len());
                    let j = rng.random_range(0..a.len());
                    a.swap(i, j);
                    return format!("swap operations {i} and {j}");
                }
                "no operations".into()
            }
            // A covariance matrix with edge entries (indefinite, asymmetric, huge).
            _ => {
                let Some(Value::Array(poses)) = at_mut(doc, &[Seg::Key("pose".into())]) else {
                    return "no poses".into();
                };
                if poses.is_empty() {
                    return "no poses".into();
                }
                let i = rng.random_range(0..poses.len());
                let n = [1, 3, 6][rng.random_range(0..3)];
                let rows: Vec<Value> = (0..n)
                    .map(|r| {
                        Value::Array(
                            (0..n)
                                .map(|c| {
                                    Value::Float(if r == c {
                                        [0.01, 1.0, 0.0, 1e300, -1e-3][rng.random_range(0..5)]
                                    } else if rng.random_bool(0.7) {
                                        0.0
                                    } else {
                                        FLOAT_EDGES[rng.random_range(0..FLOAT_EDGES.len())]
                                    })
                                })
                                .collect(),
                        )
                    })
                    .collect();
                let mut cov = Table::new();
                cov.insert("matrix".into(), Value::Array(rows));
                if let Value::Table(p) = &mut poses[i] {
                    p.insert("cov".into(), Value::Table(cov));
                }
                format!("pose[{i}].cov = {n}×{n} matrix")
            }
        }
    }
}
