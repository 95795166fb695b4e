//! Fuzzing the pure scenario path: TOML text → parse → lower → resolve → evaluate → draw →
//! `Scene::validate` → `records()` and findings (what `posecov check` and `report --json` do).
//!
//! Inputs are mutated from the bundled scenarios (plus three small seeds for what none of them
//! uses, [`EXTRA_SEEDS`]), deterministically from a seed: structure-aware
//! mutations of the parsed TOML (edge numbers, swapped / unknown / point names, dropped and
//! duplicated keys and entries, wrong lengths and types, other kinds, groups and methods) and
//! byte-level mutations of the text. Every input is run in a worker thread under a watchdog
//! and classified:
//!
//! - `ok`, `error_ok`: success, or an error that names `origin:line:column: field:` in the
//!   user's vocabulary;
//! - failures: `panic`, `hang` (> 5 s, or past the 4 GiB allocation cap: the run stops since
//!   the thread cannot be killed; the input is in `target/fuzz-hang-s<seed>-c<case>.toml`),
//!   `slow` (> 1 s), `memory` (peak > 512 MiB allocated, counted by a global allocator),
//!   `error_unlocated`, `error_field_toml`, `error_rust_speak`, `error_field_unusual`,
//!   `error_bad_location`, `nonfinite_record`, `nonfinite_scene`, `scene_invalid`, `non_psd`,
//!   `asymmetric_cov`, `accepted_unknown_name`, `accepted_point_as_pose`,
//!   `accepted_invalid_value`.
//!
//! Every failing input (deduplicated by class + normalised first line of its message) is
//! written to `target/fuzz-failures/<class>-s<seed>-c<case>.toml` with a `.txt` beside it
//! saying what happened and which mutations made it (keys already there are not written
//! again, across runs). Limits: `POSECOV_FUZZ_HANG_MS`, `POSECOV_FUZZ_SLOW_MS`,
//! `POSECOV_FUZZ_MEMORY_MB`, `POSECOV_FUZZ_MEMORY_CAP_MB`; output dir `POSECOV_FUZZ_OUT`
//! (default `<crate>/target`). Reproduce one with
//! `POSECOV_FUZZ_FILE=target/fuzz-failures/x.toml cargo test --no-default-features --test fuzz_scenarios fuzz_file -- --ignored --nocapture`.
//!
//! Entry points:
//! - `fuzz_100k`: `POSECOV_FUZZ_CASES` (default 100 000) cases from `POSECOV_FUZZ_SEED`
//!   (default 0), starting at case `POSECOV_FUZZ_START` (default 0: resume after a hang with
//!   the next case); `POSECOV_FUZZ_CASE=k` runs case k only; `POSECOV_FUZZ_REDUCE=1` also writes a
//!   line-reduced input (`…-reduced.toml`) for each new failure.
//! - `fuzz_smoke`: 300 cases, a few seconds; runs with `cargo test` (CI).
//! - `fuzz_file`: one file (`POSECOV_FUZZ_FILE`); with `POSECOV_FUZZ_REDUCE=1` it also prints
//!   a line-reduced input per failure.
//!
//! If the process dies (abort, stack overflow), the input being run is in
//! `target/fuzz-current.toml`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use nalgebra::{DMatrix, SymmetricEigen};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use toml::{Table, Value};

use posecov::app::{AppError, DEFAULT_SAMPLES, Overrides, evaluate, load_text, resolve};
use posecov::eval::{AnyEvaluation, Evaluation, Finding as EvalFinding};
use posecov::input::scenario::ScenarioError;
use posecov::propagate::ResultRecord;
use posecov::scene::{ItemKind, Scene};

// =========================================================================================
// The path under test. Re-point this ONE function when the API changes.
// =========================================================================================

/// Samples per evaluation, as `posecov check` caps them.
const CHECK_SAMPLES: u64 = 32;

/// What the checks look at, as plain data.
struct Output {
    /// Every record, as the library returns it.
    records: Vec<ResultRecord>,
    /// The same records through serde_json (what `--json` prints).
    records_json: serde_json::Value,
    /// The evaluation's findings (a covariance reported indefinite is not silent).
    findings: Vec<EvalFinding>,
    /// The findings through serde_json.
    findings_json: serde_json::Value,
    /// Every covariance of the output, labelled (records and uncertain points).
    covariances: Vec<(String, DMatrix<f64>)>,
    /// The scene.
    scene: Scene,
    /// `Scene::validate`.
    scene_valid: Result<(), String>,
}

/// An error the path reported.
struct Reported {
    /// `Display` of the error.
    text: String,
    /// The field it names, where the error type has one.
    field: Option<String>,
}

/// Runs the whole pure path. `stage` is told where the run is (for hang reports).
fn run_pipeline(
    text: &str,
    origin: &str,
    stage: &dyn Fn(&'static str),
) -> Result<Output, Reported> {
    let reported = |e: AppError| Reported {
        text: e.to_string(),
        field: match &e {
            AppError::Input(ScenarioError::At { field, .. }) => Some(field.clone()),
            _ => None,
        },
    };
    stage("parse");
    let loaded = load_text(text, origin).map_err(reported)?;
    let file_samples = loaded.input.defaults.samples.unwrap_or(DEFAULT_SAMPLES);
    let overrides = Overrides {
        samples: Some(file_samples.min(CHECK_SAMPLES)),
        ..Default::default()
    };
    let settings = resolve(&loaded.input, &overrides, None).map_err(|e| reported(e.into()))?;
    stage("evaluate");
    let evaluation = evaluate(&loaded, &settings.eval).map_err(reported)?;
    stage("build_scene");
    let scene = posecov::draw::scene(&evaluation, &settings.draw);
    stage("validate");
    let scene_valid = scene.validate().map_err(|e| e.to_string());
    stage("records");
    let records = evaluation.records();
    let records_json = serde_json::to_value(&records).expect("records serialise");
    let findings = evaluation.findings().to_vec();
    let findings_json = serde_json::to_value(&findings).expect("findings serialise");
    let mut covariances: Vec<(String, DMatrix<f64>)> = records
        .iter()
        .map(|r| {
            let n = r.covariance.len();
            let m = DMatrix::from_fn(n, n, |i, j| {
                r.covariance[i].get(j).copied().unwrap_or(f64::NAN)
            });
            (format!("{} ({:?})", r.label, r.method), m)
        })
        .collect();
    fn points<G: posecov::lie::LieGroup<N>, const N: usize>(
        e: &Evaluation<G, N>,
        out: &mut Vec<(String, DMatrix<f64>)>,
    ) {
        for p in &e.points {
            for (method, _, cov) in &p.estimates {
                out.push((
                    format!("point {} ({method:?})", p.name),
                    DMatrix::from_fn(3, 3, |i, j| cov[(i, j)]),
                ));
            }
        }
    }
    match &evaluation {
        AnyEvaluation::So2(e) => points(e, &mut covariances),
        AnyEvaluation::Se2(e) => points(e, &mut covariances),
        AnyEvaluation::So3(e) => points(e, &mut covariances),
        AnyEvaluation::Se3(e) => points(e, &mut covariances),
    }
    stage("done");
    Ok(Output {
        records,
        records_json,
        findings,
        findings_json,
        covariances,
        scene,
        scene_valid,
    })
}

/// The first non-finite numbers of a scene (path, field, value).
fn scene_nonfinite(scene: &Scene) -> Vec<(String, &'static str, f64)> {
    let mut bad = Vec::new();
    let mut check = |path: &str, field: &'static str, values: &mut dyn Iterator<Item = f64>| {
        if let Some(v) = Iterator::find(&mut { values }, |v| !v.is_finite()) {
            bad.push((path.to_owned(), field, v));
        }
    };
    let flat = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<f64>>();
    for item in &scene.items {
        let p = item.path.as_str();
        match &item.kind {
            ItemKind::Frame(f) => {
                check(p, "translation", &mut f.translation.iter().copied());
                check(p, "rotation", &mut f.rotation.iter().copied());
                check(p, "axis_length", &mut std::iter::once(f.axis_length));
            }
            ItemKind::Triads(t) => {
                check(p, "translations", &mut flat(&t.translations).into_iter());
                check(p, "rotations", &mut t.rotations.iter().flatten().copied());
                check(
                    p,
                    "axis_length",
                    &mut [t.axis_length, t.line_radius].into_iter(),
                );
            }
            ItemKind::Points(c) => {
                check(p, "positions", &mut flat(&c.positions).into_iter());
                check(p, "radius", &mut std::iter::once(c.radius));
            }
            ItemKind::Ellipsoids(e) => {
                for s in &e.shapes {
                    check(p, "center", &mut s.center.iter().copied());
                    check(p, "half_sizes", &mut s.half_sizes.iter().copied());
                    check(p, "rotation", &mut s.rotation.iter().copied());
                }
                check(p, "line_radius", &mut std::iter::once(e.line_radius));
            }
            ItemKind::Surface(s) => {
                check(p, "vertices", &mut flat(&s.vertices).into_iter());
                check(p, "normals", &mut flat(&s.normals).into_iter());
            }
            ItemKind::LineStrips(l) => {
                check(
                    p,
                    "strips",
                    &mut l.strips.iter().flatten().flatten().copied(),
                );
                check(p, "radius", &mut std::iter::once(l.radius));
            }
            ItemKind::Arrows(a) => {
                check(p, "origins", &mut flat(&a.origins).into_iter());
                check(p, "vectors", &mut flat(&a.vectors).into_iter());
                check(p, "radius", &mut std::iter::once(a.radius));
            }
            ItemKind::Text(_) => {}
        }
    }
    for s in &scene.series {
        check(
            &s.path,
            "series",
            &mut s.points.iter().map(|p| p.1).chain([s.width]),
        );
    }
    bad
}

// =========================================================================================
// Resource accounting: a counting allocator (peak bytes per case, hard cap per run).
// =========================================================================================

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                let now = CURRENT.fetch_add(new_size - layout.size(), Ordering::Relaxed)
                    + (new_size - layout.size());
                PEAK.fetch_max(now, Ordering::Relaxed);
            } else {
                CURRENT.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

// =========================================================================================
// Running one input: worker thread, watchdog, panic capture.
// =========================================================================================

/// One fuzz run at a time (the allocator counters and the panic hook are global).
static RUN_LOCK: Mutex<()> = Mutex::new(());
/// The last panic's location and message (from any thread).
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

struct Limits {
    hang: Duration,
    slow: Duration,
    memory: usize,
    memory_cap: usize,
}

impl Limits {
    fn from_env() -> Self {
        let ms = |k: &str, d: u64| Duration::from_millis(env_u64(k).unwrap_or(d));
        Self {
            hang: ms("POSECOV_FUZZ_HANG_MS", 5000),
            // The requirement: no run over 5 s (a longer one would need a progress display).
            slow: ms("POSECOV_FUZZ_SLOW_MS", 5000),
            memory: (env_u64("POSECOV_FUZZ_MEMORY_MB").unwrap_or(512) as usize) << 20,
            memory_cap: (env_u64("POSECOV_FUZZ_MEMORY_CAP_MB").unwrap_or(4096) as usize) << 20,
        }
    }
}

/// How one run ended.
#[allow(clippy::large_enum_variant)] // one value per case, moved once: size does not matter
enum Run {
    Finished {
        result: Result<Output, Reported>,
        elapsed: Duration,
        peak: usize,
        /// The stage that took longest.
        slowest: (&'static str, Duration),
    },
    Panicked {
        message: String,
        stage: &'static str,
    },
    /// Still running after the hang limit (or past the memory cap): the thread is left behind.
    Stuck {
        stage: &'static str,
        memory: bool,
        elapsed: Duration,
    },
}

fn install_panic_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        std::panic::set_hook(Box::new(|info| {
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "<non-string panic>".to_owned());
            let loc = info
                .location()
                .map_or("?".to_owned(), |l| format!("{}:{}", l.file(), l.line()));
            *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{loc}: {msg}"));
        }));
    });
}

fn run_one(text: &str, origin: &str, limits: &Limits) -> Run {
    *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
    let stage = Arc::new(Mutex::new(vec![("start", Instant::now())]));
    let (tx, rx) = mpsc::channel();
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let start = Instant::now();
    {
        let text = text.to_owned();
        let origin = origin.to_owned();
        let stage = Arc::clone(&stage);
        std::thread::Builder::new()
            .name("fuzz-case".into())
            .stack_size(16 << 20)
            .spawn(move || {
                let r = catch_unwind(AssertUnwindSafe(|| {
                    run_pipeline(&text, &origin, &|s| {
                        stage.lock().unwrap().push((s, Instant::now()))
                    })
                }));
                let _ = tx.send(r);
            })
            .expect("spawn worker");
    }
    let current_stage = || {
        stage
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .last()
            .unwrap()
            .0
    };
    // The stage that took longest, and its time.
    let slowest_stage = || {
        let st = stage.lock().unwrap_or_else(|e| e.into_inner());
        st.windows(2)
            .map(|w| (w[0].0, w[1].1 - w[0].1))
            .max_by_key(|x| x.1)
            .unwrap_or(("start", Duration::ZERO))
    };
    loop {
        match rx.recv_timeout(Duration::from_millis(10)) {
            Ok(Ok(result)) => {
                let elapsed = start.elapsed();
                let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
                return Run::Finished {
                    result,
                    elapsed,
                    peak,
                    slowest: slowest_stage(),
                };
            }
            Ok(Err(_)) => {
                let message = LAST_PANIC
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .take()
                    .unwrap_or_else(|| "<panic without message>".to_owned());
                return Run::Panicked {
                    message,
                    stage: current_stage(),
                };
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Run::Panicked {
                    message: "worker vanished".to_owned(),
                    stage: current_stage(),
                };
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                let over_memory = CURRENT.load(Ordering::Relaxed) > limits.memory_cap;
                if start.elapsed() > limits.hang || over_memory {
                    return Run::Stuck {
                        stage: current_stage(),
                        memory: over_memory,
                        elapsed: start.elapsed(),
                    };
                }
            }
        }
    }
}

// =========================================================================================
// Classification.
// =========================================================================================

/// One problem found with one input.
#[derive(Debug, Clone)]
struct Finding {
    class: &'static str,
    /// What happened (first line is the dedup key, numbers normalised).
    message: String,
}

/// The classes that are not failures.
const GOOD: [&str; 2] = ["ok", "error_ok"];

/// Words of an error message that speak Rust / serde rather than the file's vocabulary.
const RUST_SPEAK: &[&str] = &[
    "expected struct",
    "expected enum",
    "expected u64",
    "expected u32",
    "expected usize",
    "expected i64",
    "expected f64",
    "expected f32",
    "expected a sequence",
    "expected a map",
    "expected unit",
    "newtype",
    "Spanned",
    "tuple",
    "$__",
    "invalid type: map",
    "invalid type: sequence",
    "Option<",
    "Vec<",
];

fn classify(text: &str, origin: &str, run: Run) -> (Vec<Finding>, Option<Duration>) {
    let f = |class, message: String| Finding { class, message };
    let (result, elapsed, peak, slowest) = match run {
        Run::Panicked { message, stage } => {
            return (
                vec![f("panic", format!("panic in {stage}: {message}"))],
                None,
            );
        }
        Run::Stuck {
            stage,
            memory,
            elapsed,
        } => {
            let class = if memory { "memory" } else { "hang" };
            return (
                vec![f(
                    class,
                    format!(
                        "still running in {stage} after {:.1} s",
                        elapsed.as_secs_f64()
                    ),
                )],
                Some(elapsed),
            );
        }
        Run::Finished {
            result,
            elapsed,
            peak,
            slowest,
        } => (result, elapsed, peak, slowest),
    };
    let limits = Limits::from_env();
    let mut findings = Vec::new();
    if elapsed > limits.slow {
        findings.push(f(
            "slow",
            format!(
                "{} took {:.1} s (of {:.1} s; {})",
                slowest.0,
                slowest.1.as_secs_f64(),
                elapsed.as_secs_f64(),
                outcome_word(&result)
            ),
        ));
    }
    if peak > limits.memory {
        findings.push(f(
            "memory",
            format!(
                "peak {} MiB allocated (slowest stage {}; {})",
                peak >> 20,
                slowest.0,
                outcome_word(&result)
            ),
        ));
    }
    match result {
        Err(e) => findings.extend(check_error(text, origin, &e)),
        Ok(out) => findings.extend(check_output(text, &out)),
    }
    if findings.is_empty() {
        findings.push(f("ok", String::new()));
    }
    (findings, Some(elapsed))
}

fn outcome_word(r: &Result<Output, Reported>) -> &'static str {
    if r.is_ok() {
        "succeeded"
    } else {
        "then errored"
    }
}

/// `origin:line:column: rest` → (line, column, rest).
fn split_location<'a>(first: &'a str, origin: &str) -> Option<(usize, usize, &'a str)> {
    let rest = first.strip_prefix(origin)?.strip_prefix(':')?;
    let (line, rest) = rest.split_once(':')?;
    let (column, rest) = rest.split_once(':')?;
    let rest = rest.strip_prefix(' ')?;
    Some((line.parse().ok()?, column.parse().ok()?, rest))
}

/// `scenario.x`, `pose[3].cov`, `operation[0].controls[2]`, `draw.axis_length`.
fn field_in_user_vocabulary(field: &str) -> bool {
    let seg_ok = |s: &str| {
        let (name, index) = match s.split_once('[') {
            Some((n, i)) => (n, Some(i)),
            None => (s, None),
        };
        !name.is_empty()
            // A key as the user typed it (bare-key characters), or one of ours.
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            && index.is_none_or(|i| {
                i.strip_suffix(']')
                    .is_some_and(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()))
            })
    };
    let mut segs = field.split('.');
    let head = segs.next().unwrap_or("");
    // `file`: the text is too broken to name a table (a mangled header, a bad top-level key).
    // A top-level key (where the text lost its table header) is named as the user wrote it.
    let head_ok = seg_ok(head);
    head_ok && segs.all(seg_ok)
}

fn check_error(text: &str, origin: &str, e: &Reported) -> Vec<Finding> {
    let f = |class, message: String| Finding { class, message };
    let first = e.text.lines().next().unwrap_or("");
    let mut out = Vec::new();
    let Some((line, column, rest)) = split_location(first, origin) else {
        return vec![f("error_unlocated", first.to_owned())];
    };
    let lines: Vec<&str> = text.split('\n').collect();
    let bad_location = line == 0
        || column == 0
        || line > lines.len()
        || column > lines[line - 1].chars().count() + 1;
    if bad_location {
        out.push(f("error_bad_location", first.to_owned()));
    }
    match e.field.as_deref() {
        Some("toml") => out.push(f("error_field_toml", rest.to_owned())),
        Some(field) if !field_in_user_vocabulary(field) => {
            out.push(f("error_field_unusual", rest.to_owned()))
        }
        _ => {}
    }
    if let Some(word) = RUST_SPEAK.iter().find(|w| rest.contains(*w)) {
        out.push(f("error_rust_speak", format!("[{word}] {rest}")));
    }
    if out.is_empty() {
        out.push(f("error_ok", first.to_owned()));
    }
    out
}

fn check_output(text: &str, out: &Output) -> Vec<Finding> {
    let f = |class, message: String| Finding { class, message };
    let mut found = Vec::new();
    // Numbers of the records (and what serde_json makes of them: NaN/inf become null).
    for (r, j) in out
        .records
        .iter()
        .zip(out.records_json.as_array().into_iter().flatten())
    {
        let mut nulls = Vec::new();
        for key in ["mean_matrix", "mean_tangent", "covariance"] {
            let mut stack = vec![&j[key]];
            while let Some(v) = stack.pop() {
                match v {
                    serde_json::Value::Array(a) => stack.extend(a),
                    serde_json::Value::Number(_) => {}
                    _ => {
                        nulls.push(key);
                        break;
                    }
                }
            }
        }
        if r.relative_error_vs_monte_carlo
            .is_some_and(|x| !x.is_finite())
        {
            nulls.push("relative_error_vs_monte_carlo");
        }
        if !nulls.is_empty() {
            found.push(f(
                "nonfinite_record",
                format!(
                    "{:?} record: {} non-finite (JSON null) — `{}`",
                    r.method,
                    nulls.join(", "),
                    r.label
                ),
            ));
        }
    }
    let mut stack = vec![&out.findings_json];
    while let Some(v) = stack.pop() {
        match v {
            serde_json::Value::Array(a) => stack.extend(a),
            // `step` is null for a result that is not per step; numbers are never null.
            serde_json::Value::Object(o) => {
                stack.extend(o.iter().filter(|(k, _)| *k != "step").map(|(_, v)| v))
            }
            serde_json::Value::Null => {
                found.push(f(
                    "nonfinite_record",
                    "a finding has a non-finite number (JSON null)".to_owned(),
                ));
                break;
            }
            _ => {}
        }
    }
    for (path, field, v) in scene_nonfinite(&out.scene).into_iter().take(3) {
        found.push(f(
            "nonfinite_scene",
            format!("{} {field} = {v}", normalise_path(&path)),
        ));
    }
    if let Err(e) = &out.scene_valid {
        found.push(f("scene_invalid", e.clone()));
    }
    // Covariances: symmetric and positive semi-definite.
    for (label, m) in &out.covariances {
        if m.iter().any(|v| !v.is_finite()) {
            continue; // reported as non-finite
        }
        let scale = m.amax();
        let asym = (m - m.transpose()).amax();
        if asym > 1e-9 * scale.max(1e-300) {
            found.push(f(
                "asymmetric_cov",
                format!(
                    "{}: |Σ − Σᵀ| = {asym:.3e} of max |Σ| = {scale:.3e}",
                    method_of(label)
                ),
            ));
        }
        let eig = SymmetricEigen::new((m + m.transpose()) * 0.5);
        let max = eig.eigenvalues.amax();
        let min = eig.eigenvalues.min();
        if min < -1e-9 * max && !reported_indefinite(&out.findings, label) {
            found.push(f(
                "non_psd",
                format!(
                    "{} covariance is indefinite: λmin = {min:.3e}, max |λ| = {max:.3e} — `{label}`",
                    method_of(label)
                ),
            ));
        }
    }
    found.extend(input_oracles(text));
    found
}

/// Whether the evaluation reported the covariance labelled `name[@step] (Method)` as not
/// positive semi-definite (reported, not hidden, is what is required).
fn reported_indefinite(findings: &[EvalFinding], label: &str) -> bool {
    let (name_step, _) = label.rsplit_once(" (").unwrap_or((label, ""));
    let (name, step) = match name_step.split_once('@') {
        Some((n, k)) => (n, k.parse::<u64>().ok()),
        None => (name_step, None),
    };
    findings.iter().any(|f| {
        // One finding per output and method: its first step, and a count of later ones.
        matches!(f, EvalFinding::NotPositiveSemiDefinite { output, step: s, method, later_steps, .. }
            if output == name
                && (*s == step || (*later_steps > 0 && *s < step))
                && format!("{method:?}") == method_of(label))
    })
}

/// The `(Method)` part of a covariance label.
fn method_of(label: &str) -> &str {
    label
        .rsplit_once('(')
        .map_or(label, |(_, m)| m.trim_end_matches(')'))
}

/// `world/robot/first_order/banana` → `world/*/first_order/banana` (dedup by what, not where).
fn normalise_path(p: &str) -> String {
    let segs: Vec<&str> = p.split('/').collect();
    if segs.len() > 2 {
        let mut s = segs.clone();
        s[1] = "*";
        s.join("/")
    } else {
        p.to_owned()
    }
}

/// What a successful evaluation should have rejected, judged from the TOML itself.
fn input_oracles(text: &str) -> Vec<Finding> {
    let f = |class, message: String| Finding { class, message };
    let Ok(doc) = toml::from_str::<Table>(text) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    let mut defined: BTreeSet<String> = BTreeSet::new();
    let mut points: BTreeSet<String> = BTreeSet::new();
    for p in doc
        .get("pose")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        if let Some(n) = p.get("name").and_then(Value::as_str) {
            defined.insert(n.to_owned());
        }
    }
    for op in doc
        .get("operation")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        let kind = op.get("kind").and_then(Value::as_str).unwrap_or("?");
        let mut refs: Vec<(&str, &str)> = Vec::new();
        for key in ["input", "lhs", "rhs", "by"] {
            if let Some(s) = op.get(key).and_then(Value::as_str) {
                refs.push((key, s));
            }
        }
        for v in op
            .get("inputs")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if let Some(s) = v.as_str() {
                refs.push(("inputs", s));
            }
        }
        for (key, name) in refs {
            if points.contains(name) {
                found.push(f(
                    "accepted_point_as_pose",
                    format!("`{kind}`.{key} names a point_through_pose output; accepted as a pose"),
                ));
            } else if !defined.contains(name) {
                found.push(f(
                    "accepted_unknown_name",
                    format!("`{kind}`.{key} names an undefined pose; accepted"),
                ));
            }
        }
        if let Some(o) = op.get("output").and_then(Value::as_str) {
            defined.insert(o.to_owned());
            if kind == "point_through_pose" {
                points.insert(o.to_owned());
            }
        }
    }
    if let Some(v) = doc.get("draw").and_then(|d| d.get("axis_length")) {
        let x = v.as_float().or(v.as_integer().map(|i| i as f64));
        if x.is_some_and(|x| !(x.is_finite() && x > 0.0)) {
            found.push(f(
                "accepted_invalid_value",
                format!("draw.axis_length = {} accepted", x.unwrap()),
            ));
        }
    }
    found
}

/// The dedup key of a finding: class + first line with numbers normalised.
fn dedup_key(f: &Finding) -> String {
    let first = f.message.lines().next().unwrap_or("");
    let mut key = String::with_capacity(first.len());
    let mut in_number = false;
    for c in first.chars() {
        if c.is_ascii_digit() {
            if !in_number {
                key.push('#');
            }
            in_number = true;
        } else {
            in_number = false;
            key.push(c);
        }
    }
    format!("{}|{key}", f.class)
}

// =========================================================================================
// Generation: the bundled scenarios, mutated.
// =========================================================================================

const FLOAT_EDGES: &[f64] = &[
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

const INT_EDGES: &[i64] = &[
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
fn kinds() -> Vec<&'static str> {
    posecov::input::scenario::OPERATION_KINDS
        .iter()
        .map(|(k, ..)| *k)
        .collect()
}

const METHODS: &[&str] = &[
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

const GROUPS: &[&str] = &["so2", "se2", "so3", "se3"];

const OPERATION_KEYS: &[&str] = &[
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
const SCENARIO_KEYS: &[&str] = &[
    "title",
    "description",
    "source",
    "group",
    "seed",
    "samples",
    "confidence",
    "methods",
];
const POSE_KEYS: &[&str] = &["name", "mean", "cov", "draw"];
const MEAN_KEYS: &[&str] = &[
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
const COV_KEYS: &[&str] = &["std", "std_deg", "matrix", "ros", "side", "order"];
const DRAW_KEYS: &[&str] = &[
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
const TOKENS: &[&str] = &[
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
enum Seg {
    Key(String),
    Idx(usize),
}

fn at<'a>(v: &'a Value, path: &[Seg]) -> Option<&'a Value> {
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

fn at_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
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
fn all_paths(v: &Value, prefix: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
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
/// `fuse`, `between`, `compose_correlated`, `between_correlated`, `odometry` with `steps`.
const EXTRA_SEEDS: &[(&str, &str)] = &[
    (
        "extra_se3",
        r#"[scenario]
title = "extra: points, fusion, correlated (SE(3))"
group = "se3"
seed = 3
samples = 500
methods = ["first_order", "second_order", "fourth_order", "sigma_points", "monte_carlo", "vector_space"]

[[pose]]
name = "world_from_a"
mean = { xyz = [1.0, 0.0, 0.0], rpy = [0.0, 0.0, 0.3] }
cov = { std = [0.1, 0.1, 0.1, 0.05, 0.05, 0.2] }

[[pose]]
name = "world_from_b"
mean = { xyz = [1.1, 0.1, 0.0], rpy = [0.0, 0.1, 0.35] }
cov = { std = [0.2, 0.1, 0.1, 0.05, 0.05, 0.1] }

[[pose]]
name = "a_from_sensor"
mean = { xyz = [0.5, 0.0, 0.2], quaternion_xyzw = [0.0, 0.0, 0.0, 1.0] }

[[operation]]
kind = "point_through_pose"
input = "world_from_a"
point = [2.0, 0.0, 0.0]
point_cov = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]
output = "landmark"

[[operation]]
kind = "fuse"
inputs = ["world_from_a", "world_from_b"]
output = "world_from_fused"

[[operation]]
kind = "between"
lhs = "world_from_a"
rhs = "world_from_b"
output = "a_from_b"

[[operation]]
kind = "compose_correlated"
lhs = "world_from_a"
rhs = "a_from_b"
cross_cov = [[0.001, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]]
output = "world_from_b2"

[[operation]]
kind = "change_frame_right"
input = "world_from_a"
by = "a_from_sensor"
output = "world_from_sensor"

[[operation]]
kind = "odometry"
input = "world_from_a"
model = "exp"
controls = [[0.5, 0.0, 0.0, 0.0, 0.0, 0.1]]
steps = 5
noise = { std = [0.01, 0.01, 0.01, 0.01, 0.01, 0.02] }
output = "world_from_robot"
"#,
    ),
    (
        "extra_se2",
        r#"[scenario]
title = "extra: points, fusion, correlated (SE(2))"
group = "se2"
seed = 4
samples = 300
methods = ["first_order", "sigma_points", "monte_carlo", "vector_space", "lecture_no_jr"]

[[pose]]
name = "map_from_a"
mean = { xy_theta = [1.0, 2.0, 0.3] }
cov = { std = [0.1, 0.2, 0.1] }

[[pose]]
name = "map_from_b"
mean = { xy_theta_deg = [1.2, 2.1, 20.0] }
cov = { matrix = [[0.02, 0.001, 0.0], [0.001, 0.03, 0.0], [0.0, 0.0, 0.01]], side = "left" }

[[operation]]
kind = "point_through_pose"
input = "map_from_a"
point = [1.0, 0.5]
output = "corner"

[[operation]]
kind = "fuse"
inputs = ["map_from_a", "map_from_b"]
output = "map_from_fused"

[[operation]]
kind = "between_correlated"
lhs = "map_from_a"
rhs = "map_from_b"
cross_cov = [[0.001, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
output = "a_from_b"

[[operation]]
kind = "odometry"
input = "map_from_fused"
model = "increment"
controls = [[0.3, 0.0, 0.1], [0.3, 0.0, -0.1]]
noise = { std_deg = [0.01, 0.01, 1.0] }
output = "map_from_robot"
"#,
    ),
    (
        "extra_so2",
        r#"[scenario]
title = "extra: SO(2)"
group = "so2"
seed = 5
samples = 200
methods = ["first_order", "sigma_points", "monte_carlo"]

[[pose]]
name = "world_from_dial"
mean = { angle_deg = 30.0 }
cov = { std_deg = [10.0] }

[[pose]]
name = "dial_from_needle"
mean = { angle = 0.5 }

[[operation]]
kind = "change_frame_right"
input = "world_from_dial"
by = "dial_from_needle"
output = "world_from_needle"

[[operation]]
kind = "inverse"
input = "world_from_needle"
output = "needle_from_world"

[[operation]]
kind = "point_through_pose"
input = "world_from_dial"
point = [1.0, 0.0]
point_cov = [[0.01, 0.0], [0.0, 0.01]]
output = "tip"

[[operation]]
kind = "compound"
input = "world_from_dial"
by = "dial_from_needle"
steps = 3
noise = { std = [0.05] }
output = "spun"
"#,
    ),
];

struct Generator {
    corpus: Vec<(&'static str, &'static str, Option<Table>)>,
}

impl Generator {
    fn new() -> Self {
        let corpus = posecov::input::scenario::bundled::BUNDLED
            .iter()
            .map(|b| (b.name, b.text))
            .chain(EXTRA_SEEDS.iter().copied())
            .map(|(name, text)| (name, text, toml::from_str::<Table>(text).ok()))
            .collect();
        Self { corpus }
    }

    /// Case `case` of run `seed`: (origin, text, what was done).
    fn case(&self, seed: u64, case: u64) -> (String, String) {
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
                log.push(mutate_bytes(&mut rng, &mut bytes, &self.corpus));
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

fn show(p: &[Seg]) -> String {
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

fn remove(doc: &mut Value, p: &[Seg]) {
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
fn names_in(doc: &Value) -> Vec<String> {
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

fn random_name(rng: &mut ChaCha8Rng, names: &[String]) -> String {
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

fn edge_number(rng: &mut ChaCha8Rng, old: Option<Value>) -> Value {
    let int = matches!(old, Some(Value::Integer(_)));
    // Usually keep the type; sometimes flip it (an integer where a float goes is fine in TOML
    // for f64, a float where a count goes is not).
    if int != rng.random_bool(0.15) {
        Value::Integer(INT_EDGES[rng.random_range(0..INT_EDGES.len())])
    } else {
        Value::Float(FLOAT_EDGES[rng.random_range(0..FLOAT_EDGES.len())])
    }
}

fn wrong_type(rng: &mut ChaCha8Rng) -> Value {
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
fn pick_table(rng: &mut ChaCha8Rng, doc: &mut Value) -> (Vec<Seg>, &'static [&'static str]) {
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
fn random_value(rng: &mut ChaCha8Rng, names: &[String], key: &str) -> Value {
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

fn mutate_bytes(
    rng: &mut ChaCha8Rng,
    b: &mut Vec<u8>,
    corpus: &[(&'static str, &'static str, Option<Table>)],
) -> String {
    if b.is_empty() {
        b.extend_from_slice(b"[scenario]\n");
        return "was empty".into();
    }
    let at = rng.random_range(0..b.len());
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
        0 => {
            b[at] ^= 1 << rng.random_range(0..8);
            format!("flip a bit at {at}")
        }
        1 => {
            let t = TOKENS[rng.random_range(0..TOKENS.len())];
            b.splice(at..at, t.bytes());
            format!("insert {t:?} at {at}")
        }
        2 => {
            b[at] = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes()[0];
            format!("set byte {at}")
        }
        3 => {
            let end = (at + rng.random_range(1..16)).min(b.len());
            b.drain(at..end);
            format!("delete {at}..{end}")
        }
        4 => {
            b.truncate(at);
            format!("truncate at {at}")
        }
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

// =========================================================================================
// The run: generate, classify, count, write failures.
// =========================================================================================

fn env_u64(k: &str) -> Option<u64> {
    std::env::var(k)
        .ok()
        .and_then(|v| v.replace('_', "").parse().ok())
}

fn target_dir() -> PathBuf {
    std::env::var_os("POSECOV_FUZZ_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"))
}

struct Summary {
    counts: BTreeMap<&'static str, u64>,
    failing_cases: u64,
    distinct: BTreeMap<String, (u64, u64)>, // key → (count, first case)
    written: u64,
    slowest: Vec<(Duration, u64)>,
    stopped: Option<String>,
}

const ORIGIN: &str = "fuzz.toml";

/// Line-based reduction: drop lines (then single characters of what remains is not tried)
/// while the input keeps the same dedup key. Stops on a hang (returned as `Err`).
fn reduce(text: &str, key: &str, limits: &Limits) -> Result<String, String> {
    let still = |t: &str| -> Result<bool, String> {
        let run = run_one(t, ORIGIN, limits);
        if let Run::Stuck { .. } = run {
            return Err(t.to_owned());
        }
        let (findings, _) = classify(t, ORIGIN, run);
        Ok(findings.iter().any(|f| dedup_key(f) == key))
    };
    let mut lines: Vec<String> = text.split_inclusive('\n').map(str::to_owned).collect();
    let mut chunk = (lines.len() / 2).max(1);
    let mut tries = 0;
    loop {
        let mut changed = false;
        let mut i = 0;
        while i < lines.len() && tries < 2000 {
            let end = (i + chunk).min(lines.len());
            let candidate: String = lines[..i].concat() + &lines[end..].concat();
            tries += 1;
            if still(&candidate)? {
                lines.drain(i..end);
                changed = true;
            } else {
                i += chunk;
            }
        }
        if tries >= 2000 || (!changed && chunk == 1) {
            break;
        }
        if !changed {
            chunk = (chunk / 2).max(1);
        }
    }
    Ok(lines.concat())
}

fn fuzz(seed: u64, cases: std::ops::Range<u64>, reduce_failures: bool) -> Summary {
    let _guard = RUN_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    install_panic_hook();
    let limits = Limits::from_env();
    let generator = Generator::new();
    let dir = target_dir();
    let failures = dir.join("fuzz-failures");
    std::fs::create_dir_all(&failures).expect("create target/fuzz-failures");
    let current = dir.join("fuzz-current.toml");
    let mut s = Summary {
        counts: BTreeMap::new(),
        failing_cases: 0,
        distinct: BTreeMap::new(),
        written: 0,
        slowest: Vec::new(),
        stopped: None,
    };
    // Failures already written (by earlier runs too) are not written again.
    let mut seen: HashSet<String> = std::fs::read_dir(&failures)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "txt"))
        .filter_map(|e| std::fs::read_to_string(e.path()).ok())
        .filter_map(|t| {
            t.lines()
                .find_map(|l| l.strip_prefix("key: ").map(str::to_owned))
        })
        .collect();
    let started = Instant::now();
    for case in cases {
        let (text, how) = generator.case(seed, case);
        let _ = std::fs::write(&current, &text);
        let run = run_one(&text, ORIGIN, &limits);
        let stuck = matches!(run, Run::Stuck { .. });
        let (findings, elapsed) = classify(&text, ORIGIN, run);
        if let Some(e) = elapsed {
            s.slowest.push((e, case));
            s.slowest.sort_by_key(|a| std::cmp::Reverse(a.0));
            s.slowest.truncate(5);
        }
        let mut failing = false;
        let mut classes_this_case = BTreeSet::new();
        for f in &findings {
            if classes_this_case.insert(f.class) {
                *s.counts.entry(f.class).or_default() += 1;
            }
            if GOOD.contains(&f.class) {
                continue;
            }
            failing = true;
            let key = dedup_key(f);
            let entry = s.distinct.entry(key.clone()).or_insert((0, case));
            entry.0 += 1;
            if seen.insert(key.clone()) {
                s.written += 1;
                let stem = format!("{}-s{seed}-c{case}", f.class);
                let path = if stuck {
                    dir.join(format!("fuzz-{}-s{seed}-c{case}.toml", f.class))
                } else {
                    failures.join(format!("{stem}.toml"))
                };
                let _ = std::fs::write(&path, &text);
                let _ = std::fs::write(
                    failures.join(format!("{stem}.txt")),
                    format!(
                        "class: {}\nkey: {key}\nmessage: {}\nseed: {seed}\ncase: {case}\nmutations: {how}\ninput: {}\n",
                        f.class,
                        f.message,
                        path.display()
                    ),
                );
                if reduce_failures && !stuck && !["slow", "memory"].contains(&f.class) {
                    match reduce(&text, &key, &limits) {
                        Ok(r) => {
                            let _ =
                                std::fs::write(failures.join(format!("{stem}-reduced.toml")), r);
                        }
                        Err(hung) => {
                            let p = dir
                                .join(format!("fuzz-hang-s{seed}-c{case}-during-reduction.toml"));
                            let _ = std::fs::write(&p, hung);
                            s.stopped = Some(format!(
                                "a reduction candidate of case {case} hung; written to {}",
                                p.display()
                            ));
                        }
                    }
                }
            }
        }
        if failing {
            s.failing_cases += 1;
        }
        if stuck {
            let f = &findings[0];
            let _ = std::fs::write(
                dir.join(format!("fuzz-{}-s{seed}-c{case}.toml", f.class)),
                &text,
            );
            s.stopped = Some(format!(
                "case {case} (seed {seed}): {} {} — input in {}; stopping (the thread cannot be killed)",
                f.class,
                f.message,
                dir.join(format!("fuzz-{}-s{seed}-c{case}.toml", f.class))
                    .display()
            ));
        }
        if s.stopped.is_some() {
            break;
        }
        if case % 1000 == 999 {
            eprintln!(
                "fuzz: seed {seed}: {} cases in {:.0} s",
                case + 1,
                started.elapsed().as_secs_f64()
            );
        }
    }
    let counts: Vec<String> = s.counts.iter().map(|(k, v)| format!("{k}={v}")).collect();
    println!(
        "fuzz summary: seed {seed}: {} | failing cases {} | distinct failures {} | {:.1} s",
        counts.join(" "),
        s.failing_cases,
        s.distinct.len(),
        started.elapsed().as_secs_f64()
    );
    for (key, (count, case)) in &s.distinct {
        println!("  {count:6} × {key}  (first: case {case})");
    }
    for (d, case) in &s.slowest {
        println!("  slow: case {case}: {:.2} s", d.as_secs_f64());
    }
    if let Some(stop) = &s.stopped {
        println!("fuzz STOPPED: {stop}");
    }
    println!("failing inputs in {}", failures.display());
    s
}

#[test]
#[ignore = "long; run with POSECOV_FUZZ_CASES / POSECOV_FUZZ_SEED"]
fn fuzz_100k() {
    let seed = env_u64("POSECOV_FUZZ_SEED").unwrap_or(0);
    let cases = match env_u64("POSECOV_FUZZ_CASE") {
        Some(k) => k..k + 1,
        None => {
            let start = env_u64("POSECOV_FUZZ_START").unwrap_or(0);
            start..start + env_u64("POSECOV_FUZZ_CASES").unwrap_or(100_000)
        }
    };
    let reduce = env_u64("POSECOV_FUZZ_REDUCE").unwrap_or(0) != 0;
    let s = fuzz(seed, cases, reduce);
    assert!(
        s.stopped.is_none() && s.failing_cases == 0,
        "fuzzing found failures (see above)"
    );
}

/// Short and bounded: runs in CI.
#[test]
fn fuzz_smoke() {
    let s = fuzz(1, 0..300, false);
    assert!(
        s.stopped.is_none() && s.failing_cases == 0,
        "fuzzing found failures (see above)"
    );
}

/// The extra seeds are valid scenarios (so their mutants start from something that works).
#[test]
fn extra_seeds_evaluate() {
    for (name, text) in EXTRA_SEEDS {
        let out = run_pipeline(text, name, &|_| {});
        assert!(
            out.is_ok(),
            "{name}: {}",
            out.err().map(|e| e.text).unwrap_or_default()
        );
    }
}

/// Runs one file (`POSECOV_FUZZ_FILE`) through the same checks and prints what it finds.
#[test]
#[ignore = "needs POSECOV_FUZZ_FILE"]
fn fuzz_file() {
    let _guard = RUN_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    install_panic_hook();
    let path = std::env::var("POSECOV_FUZZ_FILE").expect("set POSECOV_FUZZ_FILE");
    let bytes = std::fs::read(&path).expect("read POSECOV_FUZZ_FILE");
    let text = String::from_utf8_lossy(&bytes);
    let limits = Limits::from_env();
    let run = run_one(&text, ORIGIN, &limits);
    if let Run::Finished {
        result,
        peak,
        slowest,
        ..
    } = &run
    {
        if let Err(e) = result {
            println!("error:\n{}", e.text);
        }
        println!(
            "peak {:.1} MiB; slowest stage {} {:.3} s",
            *peak as f64 / 1048576.0,
            slowest.0,
            slowest.1.as_secs_f64()
        );
    }
    let (findings, elapsed) = classify(&text, ORIGIN, run);
    if let Some(e) = elapsed {
        println!("elapsed {:.3} s", e.as_secs_f64());
    }
    for f in &findings {
        println!("{}: {}", f.class, f.message);
    }
    if env_u64("POSECOV_FUZZ_REDUCE").unwrap_or(0) != 0 {
        for f in findings
            .iter()
            .filter(|f| !["ok", "error_ok", "hang", "slow", "memory"].contains(&f.class))
        {
            match reduce(&text, &dedup_key(f), &limits) {
                Ok(r) => println!("--- reduced for {}:\n{r}---", f.class),
                Err(_) => println!("--- reduction of {} hung", f.class),
            }
        }
    }
    assert!(findings.iter().all(|f| GOOD.contains(&f.class)));
}
