//! `posecov live` and `--watch`: open the viewer's stream once, start the evaluation
//! thread, then serve the page (live) or poll the file (watch), re-streaming in place.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::document::{Edit, EditValue, LiveDocument};
use super::proxy::Upstream;
use super::server::{PageOptions, bind_page, serve_page};
use super::worker::{Live, passes};
use crate::app::sinks::{
    ServeOptions, ViewOptions, choose_sink, say_serving, scenario_name, serve_limit, watch_file,
};
use crate::app::{AppError, Overrides, pipeline};
use crate::sink::{RecordingIds, Sink, open_stream};

/// What `posecov live` was asked to do.
#[derive(Clone, Debug)]
pub struct LiveOptions {
    /// Bundled name or scenario file.
    pub scenario: String,
    /// Command-line seed, samples, confidence (applied as edits, so the page shows them)
    /// and block size.
    pub overrides: Overrides,
    /// The viewer sink, or `None` for the default (native viewer, else the web viewer).
    pub sink: Option<Sink>,
    /// Web viewer options.
    pub serve: ServeOptions,
    /// Where the control page listens (loopback unless `--bind`).
    pub bind: SocketAddr,
    /// Where "save" writes.
    pub save_scenario: Option<PathBuf>,
}

/// Runs live mode until Ctrl-C (or the serve limit). Returns the exit code.
///
/// ```no_run
/// use std::sync::{Arc, atomic::AtomicBool};
/// use posecov::app::live::{LiveOptions, live};
/// use posecov::app::sinks::ServeOptions;
/// let options = LiveOptions {
///     scenario: "camera_on_robot".into(),
///     overrides: Default::default(),
///     sink: None,
///     serve: ServeOptions { web_port: 9090, grpc_port: 9876, seconds: Some(60), open_browser: false },
///     bind: "127.0.0.1:9091".parse().unwrap(),
///     save_scenario: None,
/// };
/// live(&options, &Arc::new(AtomicBool::new(false))).unwrap();
/// ```
///
/// # Errors
/// The scenario's error; a sink live mode cannot stream to; the page server's.
pub fn live(options: &LiveOptions, cancel: &Arc<AtomicBool>) -> Result<u8, AppError> {
    let mut doc = LiveDocument::open(&options.scenario)?;
    let o = &options.overrides;
    for (id, value) in [
        ("scenario.seed", o.seed.map(|s| s as f64)),
        ("scenario.samples", o.samples.map(|s| s as f64)),
        ("scenario.confidence", o.confidence.map(|c| c.get())),
    ] {
        if let Some(v) = value {
            doc.apply(&Edit {
                id: id.to_owned(),
                value: EditValue::Number(v),
            })
            .map_err(|e| AppError::Live(e.to_string()))?;
        }
    }
    let limit = serve_limit(&options.serve)?;
    // The page's port first: a port in use stops here, before a viewer is started.
    let listener = bind_page(options.bind)?;
    let view = ViewOptions {
        scenario: options.scenario.clone(),
        overrides: Overrides {
            block_samples: o.block_samples,
            ..Overrides::default()
        },
        sink: options.sink.clone(),
        serve: options.serve,
        watch: false,
        png: None,
    };
    let (live, viewer_url, upstream) = start(doc, &view)?;
    let page = PageOptions {
        viewer_url: viewer_url.clone(),
        upstream,
        save_to: options.save_scenario.clone(),
    };
    if !options.bind.ip().is_loopback() {
        eprintln!(
            "warning: --bind {}: the control page is reachable from other machines; anyone who can reach it can change the scenario shown (not the files on disk)",
            options.bind
        );
    }
    let served = serve_page(
        Arc::clone(&live),
        listener,
        page,
        Arc::clone(cancel),
        limit,
        |url| {
            if let Some(v) = &viewer_url {
                println!("Web viewer: {v}");
            }
            println!("Controls: {url}");
            say_serving(limit);
        },
    );
    cancel.store(true, Ordering::SeqCst);
    live.finish()?;
    served?;
    Ok(0)
}

/// A live session and, when the web viewer is served, its URL and loopback servers.
type Started = (Arc<Live>, Option<String>, Option<Upstream>);

/// Opens the viewer's stream (the blueprint from a quick preview of the scene) and starts
/// the evaluation thread on it. Returns the session, and the web viewer's URL and loopback
/// servers if served.
fn start(doc: LiveDocument, view: &ViewOptions) -> Result<Started, AppError> {
    let sink = choose_sink(view)?;
    if matches!(sink, Sink::Save(_) | Sink::Stdout) {
        return Err(AppError::Live(
            "streams to a viewer (--spawn, --connect or --serve); to keep a recording, save the scenario and run `posecov FILE --save out.rrd`".into(),
        ));
    }
    let first = passes(doc.loaded(), &view.overrides)?.swap_remove(0);
    let (_, scene) = pipeline(doc.loaded(), &first, None)?;
    let seed = doc.loaded().input.defaults.seed.unwrap_or(0);
    let mut ids = RecordingIds::for_scenario(&scenario_name(&view.scenario), seed);
    ids.recording_id.push_str("/live");
    let (rec, guard) = open_stream(&sink, &ids, &scene)?;
    let url = guard.viewer_url().map(str::to_owned);
    let upstream = guard
        .served_addrs()
        .map(|(web, grpc)| Upstream { web, grpc });
    Ok((
        Live::start(doc, rec, guard, view.overrides.clone()),
        url,
        upstream,
    ))
}

/// `--watch` on a viewer: one recording, re-streamed in place on every change of the file;
/// a file that does not load is reported and the last good picture stays.
///
/// # Errors
/// The first load's error; the sink's.
///
/// ```no_run
/// use posecov::app::sinks::{ServeOptions, ViewOptions};
/// let options = ViewOptions {
///     scenario: "my_scenario.toml".into(),
///     overrides: Default::default(),
///     sink: None,
///     serve: ServeOptions { web_port: 9090, grpc_port: 9876, seconds: None, open_browser: false },
///     watch: true,
///     png: None,
/// };
/// posecov::app::live::watch_in_place(&options, &Default::default()).unwrap();
/// ```
pub fn watch_in_place(options: &ViewOptions, cancel: &AtomicBool) -> Result<u8, AppError> {
    let path = PathBuf::from(&options.scenario);
    let doc = LiveDocument::open(&options.scenario)?;
    let mut last_text = doc.text();
    let live_view = ViewOptions {
        overrides: options.overrides.clone(),
        ..options.clone()
    };
    let (live, url, _) = start(doc, &live_view)?;
    if let Some(url) = url {
        println!("Web viewer: {url}");
    }
    eprintln!("Watching {} for changes (Ctrl-C stops).", path.display());
    let limit = serve_limit(&options.serve)?;
    let mut reported = 0;
    watch_file(&path, false, cancel, limit, |changed| {
        let status = live.status();
        if let (Some(shown), true) = (status.shown, status.done)
            && shown >= reported
        {
            eprintln!(
                "[{shown}] streamed {} ({} items) in {:.0} ms",
                path.display(),
                status.items,
                status.final_picture_ms.unwrap_or_default()
            );
            reported = shown + 1;
        }
        if !changed {
            return Ok(None);
        }
        let Ok(text) = std::fs::read_to_string(&path) else {
            return Ok(None);
        };
        if text != last_text {
            last_text.clone_from(&text);
            if let Err(err) = live.replace_source(&text) {
                eprintln!(
                    "error: {err}\n(the last good picture stays; waiting for the next change of {})",
                    path.display()
                );
            }
        }
        Ok(None)
    })?;
    live.finish()?;
    Ok(0)
}
