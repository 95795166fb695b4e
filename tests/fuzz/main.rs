//! The fuzz harness: every input posecov reads, mutated, run through what `posecov check` and
//! `report --json` run, under a watchdog, and judged against written invariants. Stable Rust,
//! no extra tools: `cargo test --test fuzz`.
//!
//! # Families
//!
//! | family | inputs | path run |
//! |---|---|---|
//! | `scenario` | bundled scenarios + 3 extra seeds, mutated in TOML structure and bytes | parse → lower → evaluate (≤ 32 samples) → draw → validate → records |
//! | `graph` | the g2o / GTSAM / TORO graphs, mutated by token, line and byte | read → lower → evaluate (16 samples) → draw → validate → `report --json` |
//! | `ros1` | the bundled bz2 bag and a small uncompressed bag written here, mutated by byte (lengths and counts set to edge values) | read → evaluate → draw → validate → `report --json` |
//! | `mcap` | the bundled MCAP, mutated by byte | the same |
//! | `imu` | ROS 1 bags of sensor messages: `sensor_msgs/Imu` (tests/data/imu: −1 "not provided", all-zero covariances), `sensor_msgs/NavSatFix` (tests/data/navsat: each `position_covariance_type`, a NO_FIX), twists, accelerations and an Odometry's twist (tests/data/twist), mutated by byte | the same |
//! | `db3` | four ROS 2 SQLite bags: three of tests/data/ros2 (version 9, Humble's 5, zstd messages) and tests/data/twist's CDR twists, accelerations and Odometry, mutated by byte | the same |
//! | `ov_eval` | the OpenVINS text trajectories of tests/data/ov_eval (cut) and one mixing 8- and 20-column lines, mutated by token, line and byte | read as an estimate → evaluate → draw → validate → `report --json`; read as a NEES reference (the TUM reader) |
//! | `live_ws` | a scripted Foxglove WebSocket server on 127.0.0.1, each session a good one (a ROS 2 and a ROS 1 pose topic) damaged: frames' JSON and bytes mutated, bad frames of the list inserted, frames dropped, repeated, swapped | `report --json` of `ws://127.0.0.1:PORT` (read → evaluate → report), Ctrl-C once the server is done |
//! | `live_api` | raw HTTP requests to the live page's server: methods, paths, `Host`, `Origin`, content types, edits of every control to edge values | a real server on loopback |
//!
//! # Invariants
//!
//! 1. No panic (`panic`).
//! 2. No hang: every run ends within `POSECOV_FUZZ_HANG_MS` (5 s) and below
//!    `POSECOV_FUZZ_MEMORY_CAP_MB` (4 GiB allocated) (`hang`, `memory`); none is slow (> 5 s,
//!    `slow`) or peaks above 512 MiB (`memory`).
//! 3. No known-invalid input accepted (`accepted_*`): undefined names, a point used as a
//!    pose, an array of the wrong length, one uncertain pose on both sides of `compose` /
//!    `between`, a camera beyond ±1e9 m, a non-positive axis length, a non-finite number in a
//!    graph record, a request naming another server (`Host` or `Origin`), an edit that leaves
//!    a scenario `posecov check` refuses.
//! 4. No non-finite number in the output: records, findings and the JSON report have no
//!    `null` where a number belongs; scenes have only finite numbers and validate; every
//!    covariance is symmetric and positive semi-definite, or reported as not
//!    (`nonfinite_*`, `scene_invalid`, `asymmetric_cov`, `non_psd`).
//! 5. Every error is located: a scenario error is `file:line:column: field: message` with
//!    the place inside the text, the field in the file's words and no Rust words
//!    (`error_unlocated`, `error_bad_location`, `error_field_*`, `error_rust_speak`); a graph
//!    error names the file (and a place inside it when it gives one); a log error names the
//!    file (an ov_eval trajectory's: a place inside the text); a live stream's error names
//!    its URL, its report says what the stream did (`meta.stream`) and reads no more
//!    messages than were sent (`stream_unsaid`, `accepted_invalid_value`). The live API answers every request, never with a 5xx (`server_error`).
//!
//! # Running
//!
//! - `cargo test --test fuzz`: the smoke run (CI): `POSECOV_FUZZ_SMOKE` cases per family
//!   (default 400; `live_ws`, whose every case is a whole network session, a quarter of it).
//! - `cargo test --test fuzz long -- --ignored --nocapture`: the long run,
//!   `POSECOV_FUZZ_CASES` per family (default 20 000) from `POSECOV_FUZZ_SEED` (default 0),
//!   families `POSECOV_FUZZ_FAMILIES` (comma-separated; default all), starting at case
//!   `POSECOV_FUZZ_START`. It prints one summary line per family (counts per outcome, time).
//! - Failing inputs are written, one per distinct failure, to
//!   `<out>/fuzz-failures/<family>-<class>-s<seed>-c<case>.<ext>` with a `.txt` saying what
//!   happened and which mutations made it; the input being run is in
//!   `<out>/fuzz-current-<family>.<ext>` (if the process dies). `<out>` is `POSECOV_FUZZ_OUT`,
//!   default `<target dir>/tmp/fuzz` (Cargo's scratch directory for tests, outside the clone
//!   when `CARGO_TARGET_DIR` is, as in CI).
//! - One scenario file: `POSECOV_FUZZ_FILE=x.toml cargo test --test fuzz scenario_file --
//!   --ignored --nocapture` (with `POSECOV_FUZZ_REDUCE=1`, a line-reduced input per failure).

mod graph;
mod harness;
mod imu_hour;
#[cfg(feature = "viewer")]
mod live_api;
mod live_ws;
mod logs;
mod oracle;
mod ov_eval;
mod scenario;

use harness::{Family, Summary, campaign, env_u64};

/// Every family, by name.
fn families() -> Vec<Box<dyn Family>> {
    #[cfg_attr(not(feature = "viewer"), allow(unused_mut))]
    let mut all: Vec<Box<dyn Family>> = vec![
        Box::new(scenario::Scenarios::new()),
        Box::new(graph::Graphs),
        Box::new(logs::Logs::new(logs::LogKind::Ros1)),
        Box::new(logs::Logs::new(logs::LogKind::Mcap)),
        Box::new(logs::Logs::new(logs::LogKind::Db3)),
        Box::new(logs::Logs::new(logs::LogKind::Imu)),
        Box::new(ov_eval::OvEval::new()),
        Box::new(live_ws::LiveWs),
    ];
    // The page server needs the viewer feature (axum, tokio).
    #[cfg(feature = "viewer")]
    all.push(Box::new(live_api::LiveApi::new()));
    all
}

fn assert_clean(summaries: &[Summary]) {
    let failing: Vec<String> = summaries
        .iter()
        .filter(|s| !s.clean())
        .map(|s| format!("{} ({} failing cases)", s.family, s.failing_cases))
        .collect();
    assert!(
        failing.is_empty(),
        "fuzzing found failures in {failing:?} (see above)"
    );
}

/// Short and bounded: runs in CI.
#[test]
fn smoke() {
    let cases = env_u64("POSECOV_FUZZ_SMOKE").unwrap_or(400);
    let summaries: Vec<Summary> = families()
        .iter()
        .map(|f| campaign(f.as_ref(), 1, 0..f.smoke_cases(cases)))
        .collect();
    assert_clean(&summaries);
}

/// The long run (see the module docs).
#[test]
#[ignore = "long; POSECOV_FUZZ_CASES per family"]
fn long() {
    let seed = env_u64("POSECOV_FUZZ_SEED").unwrap_or(0);
    let start = env_u64("POSECOV_FUZZ_START").unwrap_or(0);
    let cases = env_u64("POSECOV_FUZZ_CASES").unwrap_or(20_000);
    let wanted = std::env::var("POSECOV_FUZZ_FAMILIES").unwrap_or_default();
    let summaries: Vec<Summary> = families()
        .iter()
        .filter(|f| wanted.is_empty() || wanted.split(',').any(|w| w.trim() == f.name()))
        .map(|f| campaign(f.as_ref(), seed, start..start + cases))
        .collect();
    let total: u64 = summaries.iter().map(|s| s.cases).sum();
    println!("fuzz total: {total} cases");
    assert_clean(&summaries);
}

/// An IMU at 400 Hz for an hour (1.44 M messages, issue 32) is read in bounded memory: the
/// read's peak heap is that of a tenth of the log (within 10 %, and under 64 MiB). No timing.
#[test]
fn imu_hour_is_read_in_bounded_memory() {
    let _guard = harness::RUN_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let [(n_tenth, tenth), (n_hour, hour)] = imu_hour::logs();
    imu_hour::write_imu_mcap(&tenth, n_tenth);
    imu_hour::write_imu_mcap(&hour, n_hour);
    let (peak_tenth, read_tenth) = imu_hour::peak_of_read(&tenth);
    let (peak_hour, read_hour) = imu_hour::peak_of_read(&hour);
    let _ = (std::fs::remove_file(&tenth), std::fs::remove_file(&hour));
    assert_eq!((read_tenth, read_hour), (n_tenth, n_hour));
    println!(
        "IMU at 400 Hz: peak heap {peak_tenth} bytes reading {n_tenth} messages, {peak_hour} \
         bytes reading {n_hour}"
    );
    assert!(
        peak_hour as f64 <= 1.1 * peak_tenth as f64 && peak_hour < 64 << 20,
        "the hour's read peaks at {peak_hour} bytes, a tenth of it at {peak_tenth}"
    );
}

/// The extra scenario seeds are valid scenarios (so their mutants start from something that
/// works), and the small bag written here reads.
#[test]
fn seeds_are_valid() {
    let _guard = harness::RUN_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let limits = harness::Limits::from_env();
    for (name, text) in scenario::EXTRA_SEEDS {
        let found = scenario::classify(
            text,
            scenario::ORIGIN,
            scenario::run_text(text, &limits),
            &limits,
        );
        assert!(found.iter().all(|f| f.class == "ok"), "{name}: {found:?}");
    }
    let ros1 = logs::Logs::new(logs::LogKind::Ros1);
    let (found, _) = ros1.check(&logs::small_bag(), &limits);
    assert!(
        found.iter().all(|f| f.class == "ok"),
        "small bag: {found:?}"
    );
    let db3 = logs::Logs::new(logs::LogKind::Db3);
    for seed in logs::DB3_SEEDS {
        let (found, _) = db3.check(seed, &limits);
        assert!(found.iter().all(|f| f.class == "ok"), "db3 seed: {found:?}");
    }
    let imu = logs::Logs::new(logs::LogKind::Imu);
    for seed in [logs::IMU_SEED, logs::NAVSAT_SEED, logs::TWIST_SEED] {
        let (found, _) = imu.check(seed, &limits);
        assert!(found.iter().all(|f| f.class == "ok"), "imu seed: {found:?}");
    }
    let ov_eval = ov_eval::OvEval::new();
    for seed in ov_eval.seeds() {
        let (found, _) = ov_eval.check(seed.as_bytes(), &limits);
        assert!(
            found.iter().all(|f| f.class == "ok"),
            "ov_eval seed: {found:?}"
        );
    }
}

/// Runs one scenario file (`POSECOV_FUZZ_FILE`) through the same checks and prints what it
/// finds.
#[test]
#[ignore = "needs POSECOV_FUZZ_FILE"]
fn scenario_file() {
    let _guard = harness::RUN_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    harness::install_panic_hook();
    let path = std::env::var("POSECOV_FUZZ_FILE").expect("set POSECOV_FUZZ_FILE");
    let bytes = std::fs::read(&path).expect("read POSECOV_FUZZ_FILE");
    let text = String::from_utf8_lossy(&bytes);
    let limits = harness::Limits::from_env();
    let findings = scenario::classify(
        &text,
        scenario::ORIGIN,
        scenario::run_text(&text, &limits),
        &limits,
    );
    for f in &findings {
        println!("{}: {}", f.class, f.message);
    }
    if env_u64("POSECOV_FUZZ_REDUCE").unwrap_or(0) != 0 {
        for f in findings
            .iter()
            .filter(|f| !harness::GOOD.contains(&f.class))
        {
            match scenario::reduce(&text, &harness::dedup_key(f), &limits) {
                Ok(r) => println!("--- reduced for {}:\n{r}---", f.class),
                Err(_) => println!("--- reduction of {} hung", f.class),
            }
        }
    }
    assert!(findings.iter().all(|f| harness::GOOD.contains(&f.class)));
}
