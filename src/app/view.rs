//! `posecov <input>`: which path shows an input. The input is opened once
//! ([`super::run::open`]: a plan or a robot log); a watched scenario file goes to
//! [`super::live::watch_in_place`] (a viewer, re-streamed in place) or [`super::session`]
//! (`--save`, rewritten whole); any other input, plan or log, to [`super::session`]'s one
//! sequence. Every path takes its sink from [`super::sinks`].

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use super::run::{Opened, open};
use super::sinks::ViewOptions;
use super::{AppError, live, session};
use crate::sink::Sink;

/// Shows an input: in the viewer, a file, stdout or a PNG; with `watch`, again on every change
/// of the file. Returns the process exit code.
///
/// # Errors
/// The input's error (located in the file); a flag that does not combine; the sink's.
///
/// ```no_run
/// use std::sync::{Arc, atomic::AtomicBool};
/// use posecov::app::sinks::{ServeOptions, ViewOptions};
/// let options = ViewOptions {
///     scenario: "camera_on_robot".into(),
///     overrides: Default::default(),
///     sink: Some(posecov::sink::Sink::Save("camera.rrd".into())),
///     serve: ServeOptions { web_port: 9090, grpc_port: 9876, seconds: None, open_browser: false },
///     watch: false,
///     png: None,
/// };
/// assert_eq!(posecov::app::view::view(&options, &Arc::new(AtomicBool::new(false))).unwrap(), 0);
/// ```
pub fn view(options: &ViewOptions, cancel: &Arc<AtomicBool>) -> Result<u8, AppError> {
    let opened = open(&options.scenario)?;
    if !options.watch {
        return session::show(options, opened, cancel);
    }
    if matches!(opened, Opened::Log(_)) {
        return Err(AppError::Watch(
            "needs a scenario file to watch; a robot log is read once".to_owned(),
        ));
    }
    let path = Path::new(&options.scenario);
    if !path.is_file() {
        return Err(AppError::Watch(format!(
            "needs a scenario file to watch; {path:?} is not one (copy a bundled scenario from assets/scenarios/)"
        )));
    }
    if matches!(options.sink, Some(Sink::Stdout)) || options.png.is_some() {
        return Err(AppError::Watch(
            "streams to a viewer or rewrites a --save file; it does not combine with --stdout or --png"
                .to_owned(),
        ));
    }
    match &options.sink {
        Some(Sink::Save(file)) => session::watch_saving(options, file, cancel),
        // A viewer: one recording, re-streamed in place (see `sink::restream`).
        _ => live::watch_in_place(options, cancel),
    }
}
