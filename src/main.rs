//! `posecov`: show a pose-uncertainty scenario in the Rerun viewer.
//!
//! `main` parses the arguments, builds the scene and opens the stream; [`run`] logs the
//! scene. With no sink flag, a native `rerun` 0.36 viewer is spawned if one is on `PATH`,
//! otherwise the web viewer embedded in this binary is served on 127.0.0.1.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context as _, bail};
use clap::{Args, Parser, Subcommand};
use posecov::scene::{DEMO_SAMPLES, Scene, demo_scene_with};
use posecov::sink::{
    self, LogOutcome, RecordingIds, Sink, SinkGuard, find_native_viewer, open_stream, render_png,
};

/// Exit code after Ctrl-C (128 + SIGINT), as shells expect.
const EXIT_INTERRUPTED: u8 = 130;
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
    /// A bundled scenario name (see `posecov list`) or a scenario TOML file; `demo` is the
    /// built-in demo.
    // `Option` only so that `posecov <COMMAND>` parses; clap requires it otherwise.
    #[arg(required = true)]
    scenario: Option<String>,
    /// Seed of every random draw (same seed, same recording content).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Monte-Carlo samples (default: the scenario's).
    #[arg(long)]
    samples: Option<usize>,
    /// Probability inside drawn regions, strictly between 0 and 1 (default: the scenario's).
    #[arg(long, value_parser = parse_probability)]
    confidence: Option<f64>,
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
    /// Write .rrd bytes to stdout, e.g. `posecov demo --stdout | rerun -`.
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
}

/// The seam where scenario evaluation plugs in: scenario arguments → scene.
fn scene_for(args: &ScenarioArgs) -> anyhow::Result<Scene> {
    match args.scenario() {
        "demo" => Ok(demo_scene_with(
            args.seed,
            args.samples.unwrap_or(DEMO_SAMPLES),
            args.confidence.unwrap_or(0.95),
        )?),
        other => {
            bail!("scenario {other:?}: scenario files are not implemented yet (try `posecov demo`)")
        }
    }
}

/// Name used in the recording id: a bundled name as is, a file by its stem.
fn scenario_name(scenario: &str) -> String {
    Path::new(scenario)
        .file_stem()
        .map_or_else(|| scenario.to_owned(), |s| s.to_string_lossy().into_owned())
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
        Some(Command::List) => {
            println!("demo    built-in demo: a drifting robot, Monte Carlo vs first order");
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Report { .. }) => {
            bail!("`posecov report` is not implemented yet (it needs scenario evaluation)")
        }
        Some(Command::Check { scenario }) => {
            let scene = scene_for(&scenario)?;
            scene.validate().context("the scene is not drawable")?;
            println!(
                "{}: ok ({} items, {} steps)",
                scenario.scenario(),
                scene.items.len(),
                scene.steps().len()
            );
            Ok(ExitCode::SUCCESS)
        }
        None => view(&cli.view),
    }
}

fn view(args: &ViewArgs) -> anyhow::Result<ExitCode> {
    if args.watch {
        bail!("--watch is not implemented yet (it needs scenario files)");
    }
    let scene = scene_for(&args.scenario)?;
    scene.validate().context("the scene is not drawable")?;
    let cancel = install_ctrl_c()?;
    let ids =
        RecordingIds::for_scenario(&scenario_name(args.scenario.scenario()), args.scenario.seed);
    if let Some(png) = &args.png {
        return render(args, &scene, &ids, png, &cancel);
    }
    let sink = choose_sink(&args.sink, &args.serve)?;
    let (rec, guard) = open_stream(&sink, &ids).context("opening the recording")?;
    if let Some(url) = guard.viewer_url() {
        println!("Web viewer: {url}");
    }
    let outcome = run(&rec, &scene, &cancel)?;
    if guard.viewer_url().is_some() && outcome == LogOutcome::Complete {
        let limit = serve_limit(&args.serve)?;
        match limit {
            Some(l) => eprintln!("Serving for {} s (Ctrl-C stops).", l.as_secs()),
            None => eprintln!("Serving until Ctrl-C."),
        }
        guard.serve_until(&cancel, limit);
    }
    finish(guard, rec, &sink, outcome)
}

/// Logs the scene; reports how far it got if Ctrl-C interrupted it.
fn run(
    rec: &rerun::RecordingStream,
    scene: &Scene,
    cancel: &AtomicBool,
) -> anyhow::Result<LogOutcome> {
    let outcome = sink::log_scene_cancellable(rec, scene, cancel).context("logging the scene")?;
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
    let (rec, guard) = open_stream(&sink, ids).context("opening the recording")?;
    let outcome = run(&rec, scene, cancel)?;
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
