//! `posecov`: show a pose-uncertainty scenario in the Rerun viewer.
//!
//! `main` parses the arguments and calls the application ([`posecov::app`]), which resolves
//! the settings once and runs the session. With no sink flag, a native `rerun` 0.36 viewer is
//! spawned if one is on `PATH`, otherwise the web viewer embedded in this binary is served on
//! 127.0.0.1.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context as _;
use clap::{Args, Parser, Subcommand};
use posecov::app::live::{self, LiveOptions};
use posecov::app::sinks::{EXIT_INTERRUPTED, ServeOptions, ViewOptions};
use posecov::app::view::view;
use posecov::app::{AppError, EXIT_CANNOT, EXIT_CODES_HELP, Overrides};
use posecov::app::{commands, many};
use posecov::interop::RosReading;
use posecov::sink::Sink;

mod flags;
use flags::{
    GraphReadingArg, OptimizerArg, parse_duration, parse_joint, parse_probability, parse_size,
};

/// See robot pose uncertainty: Lie-group poses with covariances, propagated and drawn in Rerun.
///
/// Native viewer: `pip install rerun-sdk==0.36.3` (then `rerun` is on PATH and is spawned by
/// default). Without it, posecov serves its embedded web viewer and prints the URL.
#[derive(Debug, Parser)]
#[command(
    name = "posecov",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    after_help = EXIT_CODES_HELP
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
    /// Evaluate a scenario and print every mean, covariance, method and error. Several inputs
    /// (or a directory: every .bag, .mcap, .db3 and ROS 2 bag directory in it) run in parallel;
    /// with --json each prints one compact JSON object per line (JSON Lines) as it finishes.
    #[command(after_help = EXIT_CODES_HELP)]
    Report {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Further inputs, or directories of logs.
        #[arg(value_name = "MORE")]
        more: Vec<String>,
        /// Print JSON (for scripts and tests).
        #[arg(long)]
        json: bool,
    },
    /// Validate a scenario or graph without drawing it; for a robot log, fail (exit 1) on a
    /// covariance defect, printing the first of each topic on stderr. Several inputs (or a
    /// directory of logs) run in parallel: one line each, the worst exit code.
    #[command(after_help = EXIT_CODES_HELP)]
    Check {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Further inputs, or directories of logs.
        #[arg(value_name = "MORE")]
        more: Vec<String>,
        /// Accept this defect class on purpose (repeatable): non_finite, asymmetric, not_psd,
        /// undecodable, bad_orientation, unknown_marker, all_zero, placeholder_used_axis,
        /// constant, frozen_stamp, type_change, tf_cycle, tf_several_parents (then named as
        /// allowed). A log cut short is always reported (exit 1).
        #[arg(long = "allow", value_name = "NAME")]
        allow: Vec<String>,
    },
    /// Write a static figure (SVG, PNG or PDF, by the extension of -o) drawn by posecov itself:
    /// the plane projection of every cloud, region, ellipse and frame, every step at once,
    /// with a legend, axes in metres, a scale bar and the scenario's plots.
    Figure(FigureArgs),
    /// Show a scenario with a control page beside the viewer: every pose, noise and setting
    /// as a slider; each change re-evaluates and re-streams in place.
    Live(LiveArgs),
}

/// Options of `posecov figure`.
#[derive(Debug, Args)]
struct FigureArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The figure file: .svg, .png or .pdf.
    #[arg(short = 'o', long = "output", value_name = "OUT.svg|png|pdf")]
    output: PathBuf,
    /// Size in pixels (points for PDF), WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1280x800", value_parser = parse_size)]
    size: (u32, u32),
    /// The plane the world is projected on: xy (from above), xz or yz.
    #[arg(long, default_value = "xy")]
    plane: posecov::sink::figure::Plane,
    /// Which steps of a propagation: `all` at once (numbered), or one step K as the viewer
    /// shows it there. A pose graph: `all` is the before and the final after; K the state
    /// after K loop closures.
    #[arg(long, value_name = "K|all", default_value = "all")]
    step: posecov::sink::figure::Steps,
}

/// Options of `posecov live`.
#[derive(Debug, Args)]
struct LiveArgs {
    /// A bundled scenario (see `posecov list`) or a TOML scenario file (live mode edits
    /// scenarios; robot logs and pose graphs are shown without it).
    scenario: String,
    #[command(flatten)]
    settings: EvalArgs,
    #[command(flatten)]
    viewer: ViewerArgs,
    #[command(flatten)]
    serve: ServeArgs,
    /// Address of the control page (port 0: any free port). Only loopback unless you give
    /// another address here.
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1:9091")]
    bind: std::net::SocketAddr,
    /// File that the page's "Save" writes the current scenario to (comments and layout kept).
    #[arg(long, value_name = "FILE.toml")]
    save_scenario: Option<PathBuf>,
}

/// The viewer to stream to (at most one; default: spawn a viewer if `rerun` is on PATH, else
/// serve the web viewer).
#[derive(Debug, Args)]
#[group(id = "viewer", multiple = false)]
struct ViewerArgs {
    /// Spawn a native `rerun` 0.36 viewer and stream to it.
    #[arg(long)]
    spawn: bool,
    /// Stream to a running viewer [default URL: rerun+http://127.0.0.1:9876/proxy].
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = rerun::DEFAULT_CONNECT_URL)]
    connect: Option<String>,
    /// Serve the embedded web viewer on 127.0.0.1 and print its URL (`live`: shown beside
    /// the controls).
    #[arg(long)]
    serve: bool,
}

impl ViewerArgs {
    /// The viewer sink the flags ask for, or `None` for the default.
    fn sink(&self, o: &ServeOptions) -> Option<Sink> {
        if let Some(url) = &self.connect {
            Some(Sink::Connect(url.clone()))
        } else if self.spawn {
            Some(Sink::Spawn)
        } else if self.serve {
            Some(Sink::Serve {
                web_port: o.web_port,
                grpc_port: o.grpc_port,
                open_browser: o.open_browser,
            })
        } else {
            None
        }
    }
}

/// Which scenario, evaluated how.
#[derive(Clone, Debug, Args)]
struct ScenarioArgs {
    /// A bundled example (see `posecov list`), a file or a live stream: a TOML scenario, a g2o /
    /// GTSAM pose graph (.g2o, .txt, TORO .graph), a robot log (ROS 1 .bag, .mcap, a ROS 2 bag
    /// directory or .db3, an ov_eval text trajectory), recognised by content and extension, or
    /// a Foxglove WebSocket server (ws://HOST:PORT).
    // `Option` only so that `posecov <COMMAND>` parses; clap requires it otherwise.
    #[arg(required = true)]
    scenario: Option<String>,
    #[command(flatten)]
    settings: EvalArgs,
    /// Robot logs: read only this topic (repeatable; default every topic with a covariance).
    #[arg(long = "topic", value_name = "NAME")]
    topics: Vec<String>,
    /// Robot logs: draw every N-th message (default: at most ~200 per topic, evenly spaced).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    every: Option<u64>,
    /// Robot logs: how a PoseWithCovariance's 36 numbers are read: `tf2` (default: both errors
    /// in the parent frame's axes, as tf2 moves them) or `body` (the rotation error local).
    #[arg(long = "ros-reading", value_name = "tf2|body")]
    ros_reading: Option<RosReading>,
    /// Robot logs: the ground truth to take each estimate's NEES against — a topic of the log
    /// (PoseStamped, PoseWithCovarianceStamped, Odometry, TransformStamped), `tf:CHILD` (the
    /// child frame's transforms in /tf, parent = the estimate's frame_id) or a TUM trajectory
    /// file. A bare value is a topic of the log, else a file; `topic:NAME` / `file:PATH` say
    /// which.
    #[arg(long, value_name = "TOPIC|tf:CHILD|FILE")]
    reference: Option<String>,
    /// Robot logs with --reference: align the reference to the estimate first — `none`
    /// (default), `first` (the first poses coincide) or `se3` (Umeyama/Horn fit of the
    /// positions, no scale).
    #[arg(long, value_name = "none|first|se3")]
    align: Option<posecov::eval::log::nees::Align>,
    /// A running robot (ws://HOST:PORT): stop reading after this long, e.g. `30s`, `2m`
    /// (default: until --messages, Ctrl-C or the server closes).
    #[arg(long, value_name = "TIME", value_parser = parse_duration)]
    duration: Option<std::time::Duration>,
    /// A running robot (ws://HOST:PORT): stop after this many messages on the subscribed topics.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    messages: Option<u64>,
    /// A running robot (ws://HOST:PORT): write every message received on the subscribed topics
    /// to this MCAP file (`posecov report FILE.mcap` reads it back as the live run read it).
    #[arg(long, value_name = "FILE.mcap")]
    record: Option<PathBuf>,
}

/// How to evaluate: values that override the file's.
#[derive(Clone, Debug, Args)]
struct EvalArgs {
    /// Seed of every random draw (default: the scenario's; same seed, same recording content).
    #[arg(long)]
    seed: Option<u64>,
    /// Monte-Carlo samples, 2 ..= 10000000 (default: the scenario's).
    #[arg(long)]
    samples: Option<u64>,
    /// Probability inside drawn regions, strictly between 0 and 1 (default: the scenario's).
    #[arg(long, value_parser = parse_probability)]
    confidence: Option<posecov::uncertain::Confidence>,
    /// Monte-Carlo particles held in memory at once, rounded up to a multiple of 1024
    /// (default: what fits 128 MiB, at most 65536). Larger samples are simulated block by block: memory
    /// stays bounded, statistics use every sample, and each block's cloud is logged in turn.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    block_samples: Option<u64>,
    /// Pose graphs: how the file's information matrices are read. `g2o` (default) as g2o
    /// defines them; `gtsam` as GTSAM's readG2o does (3-D edges without the half-angle
    /// factor), for a like-for-like comparison with GTSAM.
    #[arg(long, value_name = "READING", value_enum)]
    graph_reading: Option<GraphReadingArg>,
    /// Pose graphs: the optimiser, `lm` (Levenberg–Marquardt, default) or `gn` (Gauss–Newton).
    #[arg(long, value_name = "NAME", value_enum)]
    optimizer: Option<OptimizerArg>,
    /// Pose graphs: the joint marginal of vertices A and B (ids), e.g. `--joint 5,9`
    /// (repeatable): reported in `report --json` (`optimized.joints`) and drawn as the
    /// relative pose's uncertainty, B as A sees it.
    #[arg(long = "joint", value_name = "A,B", value_parser = parse_joint)]
    joints: Vec<(u64, u64)>,
}

impl EvalArgs {
    fn overrides(&self) -> Overrides {
        Overrides {
            seed: self.seed,
            samples: self.samples,
            confidence: self.confidence,
            block_samples: self.block_samples,
            topics: Vec::new(),
            every: None,
            ros_reading: None,
            reference: None,
            align: None,
            steps: None,
            graph_reading: self.graph_reading.map(GraphReadingArg::reading),
            optimizer: self.optimizer.map(OptimizerArg::optimizer),
            joints: self.joints.clone(),
            live: Default::default(),
        }
    }
}

#[derive(Debug, Args)]
struct ViewArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Further inputs: refused in a sentence (the viewer shows one input at a time).
    #[arg(hide = true, value_name = "MORE")]
    more: Vec<String>,
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
struct SinkArgs {
    #[command(flatten)]
    viewer: ViewerArgs,
    /// Write an .rrd file (headless); same seed, same content.
    #[arg(long, value_name = "FILE.rrd", conflicts_with_all = ["spawn", "connect", "serve", "stdout"])]
    save: Option<PathBuf>,
    /// Write .rrd bytes to stdout, e.g. `posecov camera_on_robot --stdout | rerun -`.
    #[arg(long, conflicts_with_all = ["spawn", "connect", "serve"])]
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

impl ScenarioArgs {
    /// The scenario as given on the command line.
    fn scenario(&self) -> &str {
        self.scenario.as_deref().unwrap_or_default()
    }

    /// Every input of a command that takes several: the first, then `more`.
    fn inputs(&self, more: &[String]) -> Vec<String> {
        std::iter::once(self.scenario().to_owned())
            .chain(more.iter().cloned())
            .collect()
    }

    fn overrides(&self) -> Overrides {
        Overrides {
            topics: self.topics.clone(),
            every: self.every,
            ros_reading: self.ros_reading,
            reference: self.reference.clone(),
            align: self.align,
            live: posecov::input::log::ws::LiveOptions {
                duration: self.duration,
                messages: self.messages,
                record: self.record.clone(),
            },
            ..self.settings.overrides()
        }
    }
}

impl ServeArgs {
    fn options(&self) -> ServeOptions {
        ServeOptions {
            web_port: self.web_port,
            grpc_port: self.grpc_port,
            seconds: self.serve_seconds,
            open_browser: self.open_browser,
        }
    }
}

impl LiveArgs {
    fn options(&self) -> LiveOptions {
        let serve = self.serve.options();
        let sink = self.viewer.sink(&serve);
        LiveOptions {
            scenario: self.scenario.clone(),
            overrides: self.settings.overrides(),
            sink,
            serve,
            bind: self.bind,
            save_scenario: self.save_scenario.clone(),
        }
    }
}

impl ViewArgs {
    /// The default command shows one input. Further words are refused in a sentence (clap
    /// would say "unexpected argument"), naming the command meant when the first word is a
    /// near miss of one (`posecov lve x.toml`).
    fn one_input(&self) -> anyhow::Result<()> {
        if self.more.is_empty() {
            return Ok(());
        }
        let first = self.scenario.scenario();
        let cli = <Cli as clap::CommandFactory>::command();
        let commands = cli.get_subcommands().map(clap::Command::get_name);
        if let Some(command) = posecov::input::suggest::nearest(first, commands) {
            anyhow::bail!(
                "`{first}` is not a command; did you mean `posecov {command} {}`?",
                self.more.join(" ")
            );
        }
        let inputs: Vec<String> = std::iter::once(first)
            .chain(self.more.iter().map(String::as_str))
            .map(|i| format!("`{i}`"))
            .collect();
        anyhow::bail!(
            "posecov shows one input at a time, and was given {}: {}. Show each with its own \
             `posecov FILE`; `posecov report FILE --json` prints the numbers of one.",
            inputs.len(),
            inputs.join(", ")
        )
    }

    fn options(&self) -> ViewOptions {
        let sink = &self.sink;
        let serve = self.serve.options();
        let chosen = if let Some(path) = &sink.save {
            Some(Sink::Save(path.clone()))
        } else if sink.stdout {
            Some(Sink::Stdout)
        } else {
            sink.viewer.sink(&serve)
        };
        ViewOptions {
            scenario: self.scenario.scenario().to_owned(),
            overrides: self.scenario.overrides(),
            sink: chosen,
            serve,
            watch: self.watch,
            png: self.png.clone().map(|p| (p, self.size)),
        }
    }
}

/// Writes to stdout and says whether the reader got it: a closed pipe (`posecov report … |
/// head`) is not an error (`Ok(false)`; the run ends quietly with 0).
fn write_out(text: &str) -> anyhow::Result<bool> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(false),
        Err(e) => Err(e).context("writing to stdout"),
        Ok(()) => Ok(true),
    }
}

/// Writes to stdout: success, also when the reader closed it.
fn emit(text: &str) -> anyhow::Result<ExitCode> {
    write_out(text).map(|_| ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    match try_main() {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            // The table of `posecov --help`: 1 for an error located in a scenario or graph,
            // 2 when the input cannot be processed at all.
            ExitCode::from(
                err.downcast_ref::<AppError>()
                    .map_or(EXIT_CANNOT, AppError::exit_code),
            )
        }
    }
}

fn try_main() -> anyhow::Result<ExitCode> {
    let cli = Cli::try_parse().unwrap_or_else(|e| {
        // `report --json` answers a usage error in JSON on stdout too.
        let args: Vec<String> = std::env::args().skip(1).collect();
        let report_json =
            args.first().is_some_and(|a| a == "report") && args.iter().any(|a| a == "--json");
        if e.use_stderr() && report_json {
            let json = posecov::app::usage_error_json(&e.render().to_string(), EXIT_CANNOT);
            let _ = write_out(&format!("{json}\n"));
        }
        e.exit()
    });
    match cli.command {
        Some(Command::List) => emit(&commands::list()?),
        Some(Command::Report {
            scenario,
            more,
            json,
        }) => {
            let inputs = match many::expand(&scenario.inputs(&more)) {
                Ok(inputs) => inputs,
                Err(err) => {
                    if json {
                        write_out(&format!("{}\n", err.to_json()))?;
                    }
                    return Err(err.into());
                }
            };
            if inputs.several {
                let overrides = scenario.overrides();
                let code = many::report(&inputs.names, &overrides, json, &mut |text| {
                    write_out(text).unwrap_or(false)
                });
                return Ok(ExitCode::from(code));
            }
            let name = &inputs.names[0];
            let report = if posecov::input::log::ws::is_live(name) {
                let cancel = install_ctrl_c()?;
                let report =
                    commands::report_until(name, &scenario.overrides(), json, Arc::clone(&cancel));
                if report.is_ok() && cancel.load(Ordering::SeqCst) {
                    write_out(&report?)?;
                    return Ok(ExitCode::from(EXIT_INTERRUPTED));
                }
                report
            } else {
                commands::report(name, &scenario.overrides(), json)
            };
            match report {
                Ok(text) => emit(&text),
                Err(err) => {
                    // Scripts reading `--json` get the error as JSON too; people get stderr.
                    if json {
                        write_out(&format!("{}\n", err.to_json()))?;
                    }
                    Err(err.into())
                }
            }
        }
        Some(Command::Check {
            scenario,
            more,
            allow,
        }) => {
            let allow = commands::allowed(&allow)?;
            let inputs = many::expand(&scenario.inputs(&more))?;
            if inputs.several {
                let overrides = scenario.overrides();
                let code = many::check(&inputs.names, &overrides, &allow, &mut |line| {
                    write_out(line).unwrap_or(false)
                });
                return Ok(ExitCode::from(code));
            }
            let name = &inputs.names[0];
            // A running robot is read until a limit or Ctrl-C: then checked on what arrived,
            // and the exit code says it was interrupted.
            let (checked, interrupted) = if posecov::input::log::ws::is_live(name) {
                let cancel = install_ctrl_c()?;
                let checked = commands::check_until(
                    name,
                    &scenario.overrides(),
                    &allow,
                    Arc::clone(&cancel),
                )?;
                (checked, cancel.load(Ordering::SeqCst))
            } else {
                (commands::check(name, &scenario.overrides(), &allow)?, false)
            };
            for note in &checked.notes {
                eprintln!("warning: {note}");
            }
            for defect in &checked.defects {
                eprintln!("{defect}");
            }
            let read = write_out(&(checked.line.clone() + "\n"))?;
            // A reader that closed stdout (`… | head`) ends the run quietly with 0.
            Ok(ExitCode::from(match (read, interrupted) {
                (_, true) => EXIT_INTERRUPTED,
                (true, false) => checked.exit_code(),
                (false, false) => 0,
            }))
        }
        Some(Command::Figure(args)) => {
            let options = posecov::sink::figure::FigureOptions {
                size: args.size,
                plane: args.plane,
                steps: args.step,
            };
            posecov::app::figure::figure(
                args.scenario.scenario(),
                &args.scenario.overrides(),
                &options,
                &args.output,
            )?;
            eprintln!("Wrote {}", args.output.display());
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Live(args)) => {
            let cancel = install_ctrl_c()?;
            Ok(ExitCode::from(live::live(&args.options(), &cancel)?))
        }
        None => {
            cli.view.one_input()?;
            let cancel = install_ctrl_c()?;
            Ok(ExitCode::from(view(&cli.view.options(), &cancel)?))
        }
    }
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
