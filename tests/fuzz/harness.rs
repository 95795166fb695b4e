//! What every family shares: a counting allocator, one input run under a watchdog with its
//! panic caught, the outcome classes, the campaign (generate, run, count, keep failing
//! inputs), and a byte-level mutator for text and binary inputs.

use std::alloc::{GlobalAlloc, Layout, System};
use std::collections::{BTreeMap, HashSet};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub use crate::oracle::{json_null, null_error_where_monte_carlo_ran};

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

/// One campaign at a time (the allocator counters and the panic hook are global).
pub static RUN_LOCK: Mutex<()> = Mutex::new(());
/// The last panic's location and message (from any thread).
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Bounds of one run.
pub struct Limits {
    /// A run still going after this is a hang.
    pub hang: Duration,
    /// A run longer than this is slow (a longer one would need a progress display).
    pub slow: Duration,
    /// Peak bytes allocated by one run.
    pub memory: usize,
    /// Bytes allocated at which a run is stopped as a hang.
    pub memory_cap: usize,
}

impl Limits {
    /// `POSECOV_FUZZ_HANG_MS` (5000), `POSECOV_FUZZ_SLOW_MS` (5000), `POSECOV_FUZZ_MEMORY_MB`
    /// (512), `POSECOV_FUZZ_MEMORY_CAP_MB` (4096).
    pub fn from_env() -> Self {
        let ms = |k: &str, d: u64| Duration::from_millis(env_u64(k).unwrap_or(d));
        Self {
            hang: ms("POSECOV_FUZZ_HANG_MS", 5000),
            slow: ms("POSECOV_FUZZ_SLOW_MS", 5000),
            memory: (env_u64("POSECOV_FUZZ_MEMORY_MB").unwrap_or(512) as usize) << 20,
            memory_cap: (env_u64("POSECOV_FUZZ_MEMORY_CAP_MB").unwrap_or(4096) as usize) << 20,
        }
    }
}

/// How one run ended.
pub enum Run<T> {
    Finished {
        result: T,
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

/// Tells the watchdog which stage a run is in (for hang reports).
pub type Stage<'a> = &'a dyn Fn(&'static str);

pub fn install_panic_hook() {
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
            // Outside a fuzz case (a test's own assertion), say it as the default hook would.
            if std::thread::current().name() != Some("fuzz-case") {
                eprintln!("panicked at {loc}: {msg}");
            }
            *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{loc}: {msg}"));
        }));
    });
}

/// Runs `work` in a worker thread under the watchdog: its result, a panic, or stuck.
pub fn run_guarded<T: Send + 'static>(
    limits: &Limits,
    work: impl FnOnce(Stage) -> T + Send + 'static,
) -> Run<T> {
    *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
    let stage = Arc::new(Mutex::new(vec![("start", Instant::now())]));
    let (tx, rx) = mpsc::channel();
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let start = Instant::now();
    {
        let stage = Arc::clone(&stage);
        std::thread::Builder::new()
            .name("fuzz-case".into())
            .stack_size(16 << 20)
            .spawn(move || {
                let r = catch_unwind(AssertUnwindSafe(|| {
                    work(&|s| {
                        stage
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .push((s, Instant::now()))
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
            .map_or("start", |s| s.0)
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
        match rx.recv_timeout(Duration::from_millis(5)) {
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
// Outcomes.
// =========================================================================================

/// One problem found with one input (or its good outcome: `ok`, `error_ok`).
#[derive(Debug, Clone)]
pub struct Finding {
    pub class: &'static str,
    /// What happened (first line is the dedup key, numbers normalised).
    pub message: String,
}

/// A finding of class `class`.
pub fn finding(class: &'static str, message: impl Into<String>) -> Finding {
    Finding {
        class,
        message: message.into(),
    }
}

/// The classes that are not failures.
pub const GOOD: [&str; 2] = ["ok", "error_ok"];

/// A run's result with the findings every family shares (slow, memory), or the findings
/// that end it (panic, hang, memory cap).
pub fn settle<T>(run: Run<T>, limits: &Limits) -> Result<(T, Vec<Finding>), Vec<Finding>> {
    match run {
        Run::Panicked { message, stage } => Err(vec![finding(
            "panic",
            format!("panic in {stage}: {message}"),
        )]),
        Run::Stuck {
            stage,
            memory,
            elapsed,
        } => Err(vec![finding(
            if memory { "memory" } else { "hang" },
            format!(
                "still running in {stage} after {:.1} s",
                elapsed.as_secs_f64()
            ),
        )]),
        Run::Finished {
            result,
            elapsed,
            peak,
            slowest,
        } => {
            let mut found = Vec::new();
            if elapsed > limits.slow {
                found.push(finding(
                    "slow",
                    format!(
                        "{} took {:.1} s (of {:.1} s)",
                        slowest.0,
                        slowest.1.as_secs_f64(),
                        elapsed.as_secs_f64()
                    ),
                ));
            }
            if peak > limits.memory {
                found.push(finding(
                    "memory",
                    format!("peak {} MiB allocated (in {})", peak >> 20, slowest.0),
                ));
            }
            Ok((result, found))
        }
    }
}

/// The dedup key of a finding: class + first line with numbers normalised.
pub fn dedup_key(f: &Finding) -> String {
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

/// One kind of input: how to make case `k` and how to run and judge it.
pub trait Family {
    /// The family's name (`scenario`, `graph`, `ros1`, `mcap`, `live_api`).
    fn name(&self) -> &'static str;
    /// The extension its failing inputs are written with.
    fn extension(&self) -> &'static str;
    /// Case `case` of run `seed`: the input and how it was made.
    fn case(&self, seed: u64, case: u64) -> (Vec<u8>, String);
    /// Runs and judges one input; `true` when the run was left stuck (the campaign stops).
    fn check(&self, input: &[u8], limits: &Limits) -> (Vec<Finding>, bool);
    /// This family's cases in the CI smoke run, out of the run's `default` per family.
    fn smoke_cases(&self, default: u64) -> u64 {
        default
    }
}

pub fn env_u64(k: &str) -> Option<u64> {
    std::env::var(k)
        .ok()
        .and_then(|v| v.replace('_', "").parse().ok())
}

/// Where failing inputs and the input being run go: `POSECOV_FUZZ_OUT`, default `fuzz/` in
/// Cargo's scratch directory for tests (`<target dir>/tmp/fuzz`, wherever `CARGO_TARGET_DIR`
/// puts the target dir; never inside the clone). Created when missing.
pub fn target_dir() -> PathBuf {
    let dir = std::env::var_os("POSECOV_FUZZ_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz"));
    if let Err(e) = std::fs::create_dir_all(&dir) {
        panic!(
            "cannot create the fuzz output directory {}: {e}",
            dir.display()
        );
    }
    dir
}

/// What a campaign found.
pub struct Summary {
    pub family: &'static str,
    pub cases: u64,
    pub counts: BTreeMap<&'static str, u64>,
    pub failing_cases: u64,
    /// key → (count, first case).
    pub distinct: BTreeMap<String, (u64, u64)>,
    pub elapsed: Duration,
    pub stopped: Option<String>,
}

impl Summary {
    /// No failure and no stop.
    pub fn clean(&self) -> bool {
        self.stopped.is_none() && self.failing_cases == 0
    }
}

/// Runs cases `cases` of `family` from `seed`. Each failing input (deduplicated by class and
/// normalised first line, across runs too) is written to
/// `<out>/fuzz-failures/<family>-<class>-s<seed>-c<case>.<ext>` with a `.txt` beside it; the
/// input being run is in `<out>/fuzz-current-<family>.<ext>` (if the process dies), `<out>` being
/// [`target_dir`].
pub fn campaign(family: &dyn Family, seed: u64, cases: std::ops::Range<u64>) -> Summary {
    let _guard = RUN_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    install_panic_hook();
    let limits = Limits::from_env();
    let (name, ext) = (family.name(), family.extension());
    let dir = target_dir();
    let failures = dir.join("fuzz-failures");
    std::fs::create_dir_all(&failures).expect("create <out>/fuzz-failures");
    let current = dir.join(format!("fuzz-current-{name}.{ext}"));
    let mut s = Summary {
        family: name,
        cases: 0,
        counts: BTreeMap::new(),
        failing_cases: 0,
        distinct: BTreeMap::new(),
        elapsed: Duration::ZERO,
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
        let (input, how) = family.case(seed, case);
        let _ = std::fs::write(&current, &input);
        let (findings, stuck) = family.check(&input, &limits);
        s.cases += 1;
        let mut failing = false;
        let mut classes = Vec::new();
        for f in &findings {
            if !classes.contains(&f.class) {
                classes.push(f.class);
                *s.counts.entry(f.class).or_default() += 1;
            }
            if GOOD.contains(&f.class) {
                continue;
            }
            failing = true;
            let key = format!("{name}|{}", dedup_key(f));
            s.distinct.entry(key.clone()).or_insert((0, case)).0 += 1;
            if seen.insert(key.clone()) {
                let stem = format!("{name}-{}-s{seed}-c{case}", f.class);
                let path = failures.join(format!("{stem}.{ext}"));
                let _ = std::fs::write(&path, &input);
                let _ = std::fs::write(
                    failures.join(format!("{stem}.txt")),
                    format!(
                        "class: {}\nkey: {key}\nmessage: {}\nseed: {seed}\ncase: {case}\nmutations: {how}\ninput: {}\n",
                        f.class,
                        f.message,
                        path.display()
                    ),
                );
            }
        }
        if failing {
            s.failing_cases += 1;
        }
        if stuck {
            s.stopped = Some(format!(
                "case {case} (seed {seed}): {} — stopping (the thread cannot be killed)",
                findings.first().map_or("", |f| f.message.as_str())
            ));
            break;
        }
        if case % 1000 == 999 {
            eprintln!(
                "fuzz {name}: seed {seed}: {} cases in {:.0} s",
                s.cases,
                started.elapsed().as_secs_f64()
            );
        }
    }
    s.elapsed = started.elapsed();
    let counts: Vec<String> = s.counts.iter().map(|(k, v)| format!("{k}={v}")).collect();
    println!(
        "fuzz summary: {name} seed {seed}: {} cases in {:.1} s | {} | failing cases {} | distinct failures {}",
        s.cases,
        s.elapsed.as_secs_f64(),
        counts.join(" "),
        s.failing_cases,
        s.distinct.len(),
    );
    for (key, (count, case)) in &s.distinct {
        println!("  {count:6} × {key}  (first: case {case})");
    }
    if let Some(stop) = &s.stopped {
        println!("fuzz STOPPED: {stop}");
    }
    s
}

// =========================================================================================
// Byte-level mutation (text and binary inputs).
// =========================================================================================

/// Numbers a length or count field is set to: zero, one, the largest, just past the input.
fn edge_u64(rng: &mut ChaCha8Rng, len: usize) -> u64 {
    let len = len as u64;
    [
        0,
        1,
        7,
        u64::from(u32::MAX),
        u64::MAX,
        len,
        len + 1,
        len.saturating_sub(1),
        1 << 31,
        1 << 40,
        rng.random(),
    ][rng.random_range(0..11)]
}

/// One byte-level mutation of `b`: a bit flipped, bytes set, inserted, deleted or repeated,
/// the input truncated, a little-endian 4- or 8-byte field set to an edge value (a length or
/// a count), or a `token` inserted. Returns what was done.
pub fn mutate_bytes(rng: &mut ChaCha8Rng, b: &mut Vec<u8>, tokens: &[&str]) -> String {
    if b.is_empty() {
        b.push(b'\n');
        return "was empty".into();
    }
    let at = rng.random_range(0..b.len());
    match rng.random_range(0..10) {
        0 | 1 => {
            b[at] ^= 1 << rng.random_range(0..8);
            format!("flip a bit at {at}")
        }
        2 => {
            let v = [0u8, 0xff, 0x7f, 0x80, b'\n', 0][rng.random_range(0..6)];
            b[at] = v;
            format!("byte {at} = {v:#04x}")
        }
        3 => {
            let end = (at + rng.random_range(1..64)).min(b.len());
            b.drain(at..end);
            format!("delete {at}..{end}")
        }
        4 => {
            b.truncate(at);
            format!("truncate at {at}")
        }
        5 => {
            let end = (at + rng.random_range(1..64)).min(b.len());
            let piece = b[at..end].to_vec();
            let to = rng.random_range(0..=b.len());
            b.splice(to..to, piece);
            format!("repeat {at}..{end} at {to}")
        }
        6 | 7 => {
            let width = if rng.random_bool(0.5) { 4 } else { 8 };
            let at = at.min(b.len().saturating_sub(width));
            let v = edge_u64(rng, b.len());
            let bytes = v.to_le_bytes();
            let end = (at + width).min(b.len());
            b[at..end].copy_from_slice(&bytes[..end - at]);
            format!("u{} at {at} = {v}", width * 8)
        }
        8 => {
            let end = (at + rng.random_range(1..256)).min(b.len());
            b[at..end].fill(0);
            format!("zero {at}..{end}")
        }
        _ => {
            let t = tokens
                .get(rng.random_range(0..tokens.len().max(1)))
                .copied()
                .unwrap_or("");
            b.splice(at..at, t.bytes());
            format!("insert {t:?} at {at}")
        }
    }
}
