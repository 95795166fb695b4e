//! `posecov`: show a pose-uncertainty scenario in the Rerun viewer.
//!
//! `main` parses the arguments, builds the scene and opens the stream; [`run`] logs the
//! scene. With no sink flag, a native `rerun` 0.36 viewer is spawned if one is on `PATH`,
//! otherwise the web viewer embedded in this binary is served on 127.0.0.1.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context as _, bail};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use posecov::draw::build_scene;
use posecov::scenario::Scenario;
use posecov::scenario::bundled::BUNDLED;
use posecov::scenario::eval::{EvalOptions, evaluate};
use posecov::scenario::model::AnyEvaluation;
use posecov::scene::Scene;
use posecov::sink::{
    self, LogOutcome, RecordingIds, Sink, SinkGuard, find_native_viewer, open_stream, render_png,
};

/// Exit code after Ctrl-C (128 + SIGINT), as shells expect.
const EXIT_INTERRUPTED: u8 = 130;
/// How often `--watch` looks at the file's modification time.
const WATCH_POLL: Duration = Duration::from_millis(300);
/// Environment variable bounding how long `--serve` serves (seconds), e.g. for CI.
const SERVE_SECONDS_ENV: &str = "POSECOV_SERVE_SECONDS";

/// See robot pose uncertainty: Lie-group poses with covariances, propagated and drawn in Rerun.
///
/// Native viewer: `pip install rerun-sdk==0.36.3` (then `rerun` is on PATH and is spawned by
/// default). Without it, posecov serves its embedded web viewer and prints the URL.
#[derive(Debug, Parser)]
#[command(
    name = "posecov",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    view: ViewArgs,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// List the bundled scenarios with one-line descriptions.
    List,
    /// Evaluate a scenario and print every mean, covariance, method and error.
    Report {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Print JSON (for scripts and tests).
        #[arg(long)]
        json: bool,
    },
    /// Validate a scenario without drawing it.
    Check {
        #[command(flatten)]
        scenario: ScenarioArgs,
    },
}

/// Which scenario, evaluated how.
#[derive(Clone, Debug, Args)]
struct ScenarioArgs {
    /// A bundled scenario name (see `posecov list`) or a scenario TOML file.
    // `Option` only so that `posecov <COMMAND>` parses; clap requires it otherwise.
    #[arg(required = true)]
    scenario: Option<String>,
    /// Seed of every random draw (default: the scenario's; same seed, same recording content).
    #[arg(long)]
    seed: Option<u64>,
    /// Monte-Carlo samples (default: the scenario's).
    #[arg(long)]
    samples: Option<u64>,
    /// Probability inside drawn regions, strictly between 0 and 1 (default: the scenario's).
    #[arg(long, value_parser = parse_probability)]
    confidence: Option<f64>,
    /// Monte-Carlo particles held in memory at once, rounded up to a multiple of 1024
    /// (default: what fits 128 MiB, at most 65536). Larger samples are simulated block by block: memory
    /// stays bounded, statistics use every sample, and each block's cloud is logged in turn.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    block_samples: Option<u64>,
}

#[derive(Debug, Args)]
struct ViewArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    #[command(flatten)]
    sink: SinkArgs,
    #[command(flatten)]
    serve: ServeArgs,
    /// Re-evaluate and re-stream when the scenario file changes.
    #[arg(long)]
    watch: bool,
    /// Render a PNG with a headless native viewer (needs `rerun` 0.36 on PATH).
    #[arg(long, value_name = "FILE.png", conflicts_with_all = ["spawn", "connect", "serve", "stdout"])]
    png: Option<PathBuf>,
    /// PNG size in points, WIDTHxHEIGHT (the image has 2 pixels per point).
    #[arg(long, value_name = "WxH", default_value = "1024x640", value_parser = parse_size, requires = "png")]
    size: (u32, u32),
}

/// Where the recording goes (at most one; default: spawn a viewer, else serve the web viewer).
#[derive(Debug, Args)]
#[group(id = "sink", multiple = false)]
struct SinkArgs {
    /// Spawn a native `rerun` 0.36 viewer and stream to it.
    #[arg(long)]
    spawn: bool,
    /// Stream to a running viewer [default URL: rerun+http://127.0.0.1:9876/proxy].
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = rerun::DEFAULT_CONNECT_URL)]
    connect: Option<String>,
    /// Serve the embedded web viewer on 127.0.0.1 and print its URL (Ctrl-C stops).
    #[arg(long)]
    serve: bool,
    /// Write an .rrd file (headless); same seed, same content.
    #[arg(long, value_name = "FILE.rrd")]
    save: Option<PathBuf>,
    /// Write .rrd bytes to stdout, e.g. `posecov camera_on_robot --stdout | rerun -`.
    #[arg(long)]
    stdout: bool,
}

/// Options of `--serve` (and of the default when it serves).
#[derive(Debug, Args)]
struct ServeArgs {
    /// HTTP port of the served web viewer.
    #[arg(long, default_value_t = 9090)]
    web_port: u16,
    /// gRPC port the served web viewer reads from.
    #[arg(long, default_value_t = rerun::DEFAULT_SERVER_PORT)]
    grpc_port: u16,
    /// Stop serving after this many seconds (also $POSECOV_SERVE_SECONDS); default: until Ctrl-C.
    #[arg(long, value_name = "SECONDS")]
    serve_seconds: Option<u64>,
    /// Open the served web viewer in the default browser.
    #[arg(long)]
    open_browser: bool,
}

fn parse_probability(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if p > 0.0 && p < 1.0 => Ok(p),
        Ok(p) => Err(format!("{p} is not strictly between 0 and 1")),
        Err(err) => Err(err.to_string()),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|n| (16..=8192).contains(n))
    };
    match s.split_once(['x', 'X']).map(|(w, h)| (parse(w), parse(h))) {
        Some((Some(w), Some(h))) => Ok((w, h)),
        _ => Err(format!(
            "{s:?} is not WIDTHxHEIGHT with sides in 16..=8192, e.g. 1024x640"
        )),
    }
}

impl ScenarioArgs {
    /// The scenario as given on the command line.
    fn scenario(&self) -> &str {
        self.scenario.as_deref().unwrap_or_default()
    }

    fn options(&self, cancel: Option<Arc<AtomicBool>>) -> EvalOptions {
        EvalOptions {
            seed: self.seed,
            samples: self.samples,
            confidence: self.confidence,
            cancel,
            block_samples: self.block_samples.map(|b| b as usize),
        }
    }

    /// Loads (bundled name or file) and evaluates the scenario, with a spinner when it takes
    /// more than a moment.
    fn evaluate(&self, cancel: Option<Arc<AtomicBool>>) -> anyhow::Result<Evaluated> {
        let scenario = Scenario::load_any(self.scenario())?;
        let spinner =
            ProgressBar::new_spinner().with_message(format!("evaluating {}", self.scenario()));
        spinner.set_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        // The spinner draws only on a terminal (indicatif hides it otherwise) and only after
        // 0.3 s, so quick scenarios print nothing; the evaluation wakes the ticker when done.
        let done = AtomicBool::new(false);
        let result = std::thread::scope(|scope| {
            let ticker = scope.spawn(|| {
                let start = std::time::Instant::now();
                while !done.load(Ordering::Acquire) {
                    if start.elapsed() > Duration::from_millis(300) {
                        spinner.tick();
                    }
                    std::thread::park_timeout(Duration::from_millis(80));
                }
            });
            let options = self.options(cancel);
            let result = evaluate(&scenario, &options);
            done.store(true, Ordering::Release);
            ticker.thread().unpark();
            result.map(|evaluation| (options, evaluation))
        });
        spinner.finish_and_clear();
        let (options, evaluation) = result?;
        Ok(Evaluated {
            scenario,
            options,
            evaluation,
        })
    }

    /// The seed in effect (for the recording id): the flag, else the scenario's.
    fn seed_of(&self, evaluation: &AnyEvaluation) -> u64 {
        self.seed.unwrap_or(evaluation.meta().seed)
    }
}

/// A scenario with the options it was evaluated with and the result (kept together: the
/// clouds of a blocked Monte Carlo sample are re-simulated from them while logging).
struct Evaluated {
    scenario: Scenario,
    options: EvalOptions,
    evaluation: AnyEvaluation,
}

impl Evaluated {
    /// How many Monte Carlo blocks beyond the first get logged after the main scene.
    fn later_blocks(&self) -> u64 {
        let meta = self.evaluation.meta();
        (meta.samples.div_ceil(meta.block_samples.max(1)) as u64).saturating_sub(1)
    }
}

/// Name used in the recording id: a bundled name as is, a file by its stem.
fn scenario_name(scenario: &str) -> String {
    Path::new(scenario)
        .file_stem()
        .map_or_else(|| scenario.to_owned(), |s| s.to_string_lossy().into_owned())
}

/// `posecov list`: every bundled scenario with its title.
fn list() -> anyhow::Result<ExitCode> {
    let width = BUNDLED.iter().map(|b| b.name.len()).max().unwrap_or(0);
    let mut out = String::new();
    for b in BUNDLED {
        let scenario = Scenario::parse(b.text, b.name)?;
        let _ = writeln!(out, "{:width$}  {}", b.name, scenario.file.scenario.title);
    }
    emit(&out)
}

/// `posecov report`: every mean, covariance, method and error, as JSON or as text.
fn report(args: &ScenarioArgs, json: bool) -> anyhow::Result<ExitCode> {
    let evaluation = args.evaluate(None)?.evaluation;
    let records = evaluation.records();
    let meta = evaluation.meta();
    if json {
        let notes = match &evaluation {
            AnyEvaluation::So2(e) => &e.notes,
            AnyEvaluation::Se2(e) => &e.notes,
            AnyEvaluation::So3(e) => &e.notes,
            AnyEvaluation::Se3(e) => &e.notes,
        };
        let out = serde_json::json!({ "scenario": args.scenario(), "meta": meta, "results": records, "notes": notes });
        return emit(&(serde_json::to_string_pretty(&out)? + "\n"));
    }
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} — {} (seed {}, {} samples, {:.1} % regions)",
        args.scenario(),
        meta.title,
        meta.seed,
        meta.samples,
        100.0 * meta.confidence
    );
    for r in &records {
        let error = r.relative_error_vs_monte_carlo.map_or(String::new(), |e| {
            format!(", vs Monte Carlo {:.2} %", 100.0 * e)
        });
        let _ = writeln!(
            out,
            "\n{} [{}] {} ({:?} side{error})",
            r.label,
            r.group,
            r.method.label(),
            r.side
        );
        let tangent: Vec<String> = r.mean_tangent.iter().map(|v| format!("{v:.6}")).collect();
        let _ = writeln!(out, "  mean Log(μ) = [{}]", tangent.join(", "));
        let _ = writeln!(out, "  covariance:");
        for row in &r.covariance {
            let row: Vec<String> = row.iter().map(|v| format!("{v:>12.6}")).collect();
            let _ = writeln!(out, "   {}", row.join(" "));
        }
    }
    emit(&out)
}

/// Writes to stdout; a closed pipe (`posecov report … | head`) is not an error.
fn emit(text: &str) -> anyhow::Result<ExitCode> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e).context("writing to stdout"),
        _ => Ok(ExitCode::SUCCESS),
    }
}

/// `posecov check`: parse and evaluate (with few samples) without drawing.
fn check(args: &ScenarioArgs) -> anyhow::Result<ExitCode> {
    let quick = ScenarioArgs {
        samples: Some(args.samples.unwrap_or(32).min(32)),
        ..args.clone()
    };
    let evaluation = quick.evaluate(None)?.evaluation;
    let scene = build_scene(&evaluation);
    scene.validate().context("the scene is not drawable")?;
    println!(
        "{}: ok ({} results, {} drawn items, {} steps)",
        args.scenario(),
        evaluation.records().len(),
        scene.items.len(),
        scene.steps().len()
    );
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    match try_main() {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}

fn try_main() -> anyhow::Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Some(Command::List) => list(),
        Some(Command::Report { scenario, json }) => report(&scenario, json),
        Some(Command::Check { scenario }) => check(&scenario),
        None => view(&cli.view),
    }
}

fn view(args: &ViewArgs) -> anyhow::Result<ExitCode> {
    let cancel = install_ctrl_c()?;
    if args.watch {
        return watch(args, &cancel);
    }
    let evaluated = args.scenario.evaluate(Some(Arc::clone(&cancel)))?;
    let scene = build_scene(&evaluated.evaluation);
    scene.validate().context("the scene is not drawable")?;
    let ids = RecordingIds::for_scenario(
        &scenario_name(args.scenario.scenario()),
        args.scenario.seed_of(&evaluated.evaluation),
    );
    if let Some(png) = &args.png {
        return render(args, &evaluated, &scene, &ids, png, &cancel);
    }
    let sink = choose_sink(&args.sink, &args.serve)?;
    let (rec, guard) = open_stream(&sink, &ids, &scene).context("opening the recording")?;
    if let Some(url) = guard.viewer_url() {
        println!("Web viewer: {url}");
    }
    let outcome = run(&rec, &evaluated, &scene, &cancel)?;
    if guard.viewer_url().is_some() && outcome == LogOutcome::Complete {
        serve(&args.serve, &guard, &cancel)?;
    }
    finish(guard, rec, &sink, outcome)
}

fn serve(args: &ServeArgs, guard: &SinkGuard, cancel: &AtomicBool) -> anyhow::Result<()> {
    let limit = serve_limit(args)?;
    match limit {
        Some(l) => eprintln!("Serving for {} s (Ctrl-C stops).", l.as_secs()),
        None => eprintln!("Serving until Ctrl-C."),
    }
    guard.serve_until(cancel, limit);
    Ok(())
}

/// `--watch`: evaluate, stream, and again whenever the file changes. Each generation is a new
/// recording (id suffix `/gen-N`) sent to the same viewer, so nothing stale survives an edit;
/// errors in the file are printed and the previous picture stays up.
fn watch(args: &ViewArgs, cancel: &AtomicBool) -> anyhow::Result<ExitCode> {
    let path = PathBuf::from(args.scenario.scenario());
    if !path.is_file() {
        bail!(
            "--watch needs a scenario file to watch; {:?} is not one (copy a bundled scenario from assets/scenarios/)",
            path
        );
    }
    if args.sink.stdout || args.png.is_some() {
        bail!(
            "--watch streams to a viewer or rewrites a --save file; it does not combine with --stdout or --png"
        );
    }
    let first_sink = choose_sink(&args.sink, &args.serve)?;
    // Later generations connect to the viewer the first one reached.
    let next_sink = match &first_sink {
        Sink::Spawn => Sink::Connect(rerun::DEFAULT_CONNECT_URL.to_owned()),
        Sink::Serve { grpc_port, .. } => {
            Sink::Connect(format!("rerun+http://127.0.0.1:{grpc_port}/proxy"))
        }
        other => other.clone(),
    };
    let mut keep_alive: Option<(rerun::RecordingStream, SinkGuard)> = None;
    let mut generation = 0u64;
    let mut last_seen = None;
    while !cancel.load(Ordering::Relaxed) {
        let modified = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
        if modified != last_seen {
            last_seen = modified;
            match args.scenario.evaluate(None).map(|e| {
                (
                    build_scene(&e.evaluation),
                    args.scenario.seed_of(&e.evaluation),
                    e,
                )
            }) {
                Err(err) => eprintln!(
                    "error: {err:#}\n(waiting for the next change of {})",
                    path.display()
                ),
                Ok((scene, seed, evaluated)) => {
                    let mut ids =
                        RecordingIds::for_scenario(&scenario_name(args.scenario.scenario()), seed);
                    ids.recording_id = format!("{}/gen-{generation}", ids.recording_id);
                    let sink = if generation == 0 {
                        &first_sink
                    } else {
                        &next_sink
                    };
                    let (rec, guard) =
                        open_stream(sink, &ids, &scene).context("opening the recording")?;
                    if let Some(url) = guard.viewer_url() {
                        println!("Web viewer: {url}");
                    }
                    run(&rec, &evaluated, &scene, cancel)?;
                    if matches!(sink, Sink::Serve { .. }) {
                        // The served viewer lives as long as this first stream's guard.
                        rec.flush_blocking()
                            .map_err(|e| anyhow::anyhow!("flushing: {e}"))?;
                        keep_alive = Some((rec, guard));
                    } else {
                        guard.finish(rec).context("finishing the recording")?;
                        if let Sink::Save(file) = sink {
                            eprintln!("Wrote {}", file.display());
                        }
                    }
                    eprintln!(
                        "[{generation}] streamed {} ({} items); watching {} for changes (Ctrl-C stops)",
                        path.display(),
                        scene.items.len(),
                        path.display()
                    );
                    generation += 1;
                }
            }
        }
        std::thread::sleep(WATCH_POLL);
    }
    if let Some((rec, guard)) = keep_alive {
        guard.finish(rec).context("finishing the recording")?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Logs the scene, then the clouds of any later Monte Carlo blocks one block at a time
/// (each re-simulated, logged, flushed and dropped: memory stays bounded); reports how far it
/// got if Ctrl-C interrupted it.
fn run(
    rec: &rerun::RecordingStream,
    evaluated: &Evaluated,
    scene: &Scene,
    cancel: &AtomicBool,
) -> anyhow::Result<LogOutcome> {
    let mut outcome =
        sink::log_scene_cancellable(rec, scene, cancel).context("logging the scene")?;
    let later = evaluated.later_blocks();
    if outcome == LogOutcome::Complete && later > 0 {
        let bar = ProgressBar::new(later).with_message("logging Monte Carlo blocks");
        bar.set_style(
            ProgressStyle::with_template("{msg} {pos}/{len} ({elapsed}, eta {eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let parts = posecov::draw::particle_parts(
            &evaluated.scenario,
            &evaluated.options,
            &evaluated.evaluation,
        );
        for part in parts {
            if cancel.load(Ordering::Relaxed) {
                outcome = LogOutcome::Cancelled { next_step: None };
                break;
            }
            let part = part.context("evaluating a Monte Carlo block")?;
            outcome = sink::log_part_cancellable(rec, &part, cancel)
                .context("logging a Monte Carlo block")?;
            drop(part);
            // Hands the block to the sink's writer before the next one is simulated.
            rec.flush_blocking()
                .map_err(|e| anyhow::anyhow!("flushing a Monte Carlo block: {e}"))?;
            bar.inc(1);
            if outcome != LogOutcome::Complete {
                break;
            }
        }
        bar.finish_and_clear();
        if outcome != LogOutcome::Complete {
            eprintln!(
                "Interrupted: recorded the scene and the clouds of the first {} of {} Monte Carlo blocks.",
                bar.position() + 1,
                later + 1
            );
            return Ok(outcome);
        }
    }
    if let LogOutcome::Cancelled { next_step } = outcome {
        match next_step {
            Some(k) => eprintln!("Interrupted: recorded the static items and steps before {k}."),
            None => eprintln!("Interrupted: recorded part of the static items."),
        }
    }
    Ok(outcome)
}

fn finish(
    guard: SinkGuard,
    rec: rerun::RecordingStream,
    sink: &Sink,
    outcome: LogOutcome,
) -> anyhow::Result<ExitCode> {
    guard.finish(rec).context("finishing the recording")?;
    if let Sink::Save(path) = sink {
        eprintln!("Wrote {}", path.display());
    }
    Ok(match outcome {
        LogOutcome::Complete => ExitCode::SUCCESS,
        LogOutcome::Cancelled { .. } => ExitCode::from(EXIT_INTERRUPTED),
    })
}

/// The sink the flags ask for; without one: a native 0.36 viewer if available, else serve.
fn choose_sink(args: &SinkArgs, serve_args: &ServeArgs) -> anyhow::Result<Sink> {
    let serve = Sink::Serve {
        web_port: serve_args.web_port,
        grpc_port: serve_args.grpc_port,
        open_browser: serve_args.open_browser,
    };
    Ok(if let Some(path) = &args.save {
        Sink::Save(path.clone())
    } else if let Some(url) = &args.connect {
        Sink::Connect(url.clone())
    } else if args.stdout {
        Sink::Stdout
    } else if args.spawn {
        Sink::Spawn
    } else if args.serve {
        serve
    } else {
        match find_native_viewer() {
            Ok(_) => Sink::Spawn,
            Err(why) => {
                eprintln!("{why}\nServing the embedded web viewer instead.");
                serve
            }
        }
    })
}

fn serve_limit(args: &ServeArgs) -> anyhow::Result<Option<Duration>> {
    if let Some(s) = args.serve_seconds {
        return Ok(Some(Duration::from_secs(s)));
    }
    match std::env::var(SERVE_SECONDS_ENV) {
        Ok(s) => {
            let secs: u64 = s
                .trim()
                .parse()
                .with_context(|| format!("${SERVE_SECONDS_ENV}={s:?} is not a whole number"))?;
            Ok(Some(Duration::from_secs(secs)))
        }
        Err(_) => Ok(None),
    }
}

/// `--png`: record to an .rrd (the `--save` file, or a temporary one) and render it.
fn render(
    args: &ViewArgs,
    evaluated: &Evaluated,
    scene: &Scene,
    ids: &RecordingIds,
    png: &Path,
    cancel: &AtomicBool,
) -> anyhow::Result<ExitCode> {
    let viewer = find_native_viewer().context("--png renders with the native viewer")?;
    let (rrd, temporary) = match &args.sink.save {
        Some(path) => (path.clone(), false),
        None => (
            std::env::temp_dir().join(format!("posecov-{}.rrd", std::process::id())),
            true,
        ),
    };
    let sink = Sink::Save(rrd.clone());
    let (rec, guard) = open_stream(&sink, ids, scene).context("opening the recording")?;
    let outcome = run(&rec, evaluated, scene, cancel)?;
    guard.finish(rec).context("finishing the recording")?;
    if outcome != LogOutcome::Complete {
        return Ok(ExitCode::from(EXIT_INTERRUPTED));
    }
    let rendered = render_png(&viewer, &rrd, png, args.size);
    if temporary {
        std::fs::remove_file(&rrd).ok();
    }
    rendered.with_context(|| format!("rendering {}", png.display()))?;
    eprintln!("Wrote {}", png.display());
    Ok(ExitCode::SUCCESS)
}

/// First Ctrl-C raises the returned flag (finish cleanly); a second one exits at once.
fn install_ctrl_c() -> anyhow::Result<Arc<AtomicBool>> {
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&cancel);
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(EXIT_INTERRUPTED));
        }
        eprintln!("\nStopping… (Ctrl-C again to quit at once)");
    })
    .context("installing the Ctrl-C handler")?;
    Ok(cancel)
}
