//! A running robot, live: the topics of a Foxglove WebSocket server (foxglove_bridge for ROS 1
//! and ROS 2, the Foxglove SDK's server) read as one more log source. The server's binary frames
//! carry each message's bytes as a bag stores them (`cdr` for ROS 2, `ros1` for ROS 1), so they
//! go through the same decoders and the same per-topic collector as a file's; everything after
//! sees a [`LogSummary`].
//!
//! - `client.rs`: the connection (`tungstenite`, blocking, `ws://` only): connect timeout,
//!   bounded frames, both subprotocols offered, errors in words;
//! - `protocol.rs`: the protocol's messages (`serverInfo`, `advertise`, `unadvertise`,
//!   message data; `subscribe`, `unsubscribe`);
//! - `record.rs`: `--record run.mcap`, every received message written as it arrives;
//! - `session.rs`: the thread that reads the socket, across its connections;
//! - `queue.rs`: the bounded hand-off from that thread to the collector;
//! - `mailbox.rs`: the one-slot hand-off from the collector to the thread that draws the
//!   growing view (the newest summary wins).
//!
//! The read subscribes to the channels posecov reads (the pose-with-covariance topics chosen,
//! the reference, `/tf` and `/tf_static`), declares every other advertised channel (listed as
//! skipped, as a file's), and ends after [`LiveOptions::duration`], after
//! [`LiveOptions::messages`], on Ctrl-C (the run keeps what arrived), or when the server is
//! gone: a lost connection is made again after a bounded back-off ([`RECONNECT_BACKOFF`]);
//! when that fails, an error if a limit was asked for and not reached. A frame posecov cannot
//! read (malformed JSON, a truncated frame, an unknown subscription) is skipped and noted
//! ([`StreamNotes`]); a frame beyond [`client::MAX_FRAME`] ends the read with an error. It
//! unsubscribes and closes on exit.
//!
//! No async runtime: one thread reads frames as they come and hands them to the thread that
//! collects through a queue of at most [`QUEUE_MESSAGES`] messages and [`QUEUE_BYTES`] bytes;
//! a third draws the growing view, taking the newest summary from a one-slot mailbox, so a
//! slow redraw costs pictures (skipped, counted), never messages. A server that sends faster
//! than posecov reads fills the queue;
//! what arrives then is thinned (recorded by `--record`, not read) and counted
//! ([`StreamNotes::thinned`], said in the panel and in `report --json`'s `meta.stream`):
//! nothing queues without bound, and the socket is always read, so the server never holds
//! back a backlog of its own on posecov's account.
//!
//! ```
//! use posecov::input::log::ws::{LiveOptions, is_live};
//! assert!(is_live("ws://127.0.0.1:8765") && !is_live("run.mcap"));
//! assert!(LiveOptions::default().is_empty());
//! ```

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use super::{Collector, LogOptions};
use crate::input::InputError;

pub mod client;
#[cfg(test)]
mod long_run;
mod mailbox;
pub mod protocol;
mod queue;
mod record;
mod session;

use crate::plan::log::{LogSummary, StreamNotes};
use mailbox::Mailbox;
use queue::{Event, Next};
pub use queue::{QUEUE_BYTES, QUEUE_MESSAGES};
use session::{Session, Shared};

/// The connection's socket.
type Socket = tungstenite::WebSocket<std::net::TcpStream>;

/// How long a live read goes on and what it keeps (`--duration`, `--messages`, `--record`):
/// the flags of a live stream only.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LiveOptions {
    /// Stop after this long (from the connection).
    pub duration: Option<Duration>,
    /// Stop after this many messages received on the subscribed topics.
    pub messages: Option<u64>,
    /// Write every received message of the subscribed topics to this MCAP file.
    pub record: Option<PathBuf>,
}

impl LiveOptions {
    /// No live flag given.
    pub fn is_empty(&self) -> bool {
        self == &Self::default()
    }

    /// The first live flag given and its value, as the command line spells it.
    ///
    /// ```
    /// use posecov::input::log::ws::LiveOptions;
    /// let o = LiveOptions { messages: Some(5), ..Default::default() };
    /// assert_eq!(o.first_flag(), Some(("--messages", "5".to_owned())));
    /// ```
    pub fn first_flag(&self) -> Option<(&'static str, String)> {
        if let Some(d) = self.duration {
            return Some(("--duration", format!("{}s", d.as_secs_f64())));
        }
        if let Some(n) = self.messages {
            return Some(("--messages", n.to_string()));
        }
        self.record
            .as_ref()
            .map(|p| ("--record", p.display().to_string()))
    }
}

/// Whether an input names a live stream (`ws://…` or `wss://…`, refused later in words).
pub fn is_live(name: &str) -> bool {
    name.starts_with("ws://") || name.starts_with("wss://")
}

/// The waits before each attempt to connect again after the connection was lost: bounded
/// (under 4 s in all), and cut short by a limit or Ctrl-C.
pub const RECONNECT_BACKOFF: [Duration; 4] = [
    Duration::from_millis(250),
    Duration::from_millis(500),
    Duration::from_secs(1),
    Duration::from_secs(2),
];

/// Reads the stream at `url` into `collector` until a limit of `options.live`, Ctrl-C or the
/// end of the stream; a lost connection is made again (after [`RECONNECT_BACKOFF`]). A thread
/// reads the socket (`session.rs`) and hands on through the bounded queue (`queue.rs`); this
/// one feeds the collector; when `grow` is given, a third draws the growing view: the
/// collector hands it the newest summary through a one-slot mailbox (`mailbox.rs`), so that
/// reading never waits for drawing. Returns what the stream did besides carrying messages.
/// `progress(done, total)`: messages or ms.
pub(super) fn read(
    url: &str,
    options: &LogOptions,
    collector: &mut Collector<'_, '_>,
    grow: Option<&mut (dyn FnMut(LogSummary) + Send)>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<StreamNotes, InputError> {
    let fail = |reason: String| InputError::Read {
        path: url.to_owned(),
        reason,
    };
    let parsed = client::parse_url(url).map_err(fail)?;
    let recorder = match &options.live.record {
        Some(path) => Some(record::Recorder::create(path).map_err(fail)?),
        None => None,
    };
    let connection = client::connect(&parsed).map_err(fail)?;
    let shared = Shared::new(url);
    let (sender, taker) = queue::bounded(&shared.queued);
    let mailbox = Mailbox::new();
    let outcome = std::thread::scope(|scope| {
        let session = Session::new(&parsed, options, &shared, sender, recorder);
        let reader = std::thread::Builder::new()
            .name("posecov-ws".to_owned())
            .spawn_scoped(scope, move || session.serve(connection))
            .map_err(|e| format!("cannot start the thread that reads the stream ({e})"));
        let drawing = &mailbox;
        let drawer = grow.map(|grow| {
            std::thread::Builder::new()
                .name("posecov-draw".to_owned())
                .spawn_scoped(scope, move || draw(drawing, grow))
        });
        let taken = match (&reader, &drawer) {
            (Err(e), _) => Err(e.clone()),
            (_, Some(Err(e))) => Err(format!("cannot start the thread that draws ({e})")),
            _ => take(
                taker,
                &options.live,
                &shared,
                collector,
                Some(&mailbox),
                progress,
            ),
        };
        // The end (a limit, Ctrl-C, an error): both threads stop, neither waits for the other.
        shared.stop.store(true, Ordering::Release);
        mailbox.close(taken.is_ok() && !collector.stop());
        let served = match reader {
            Ok(reader) => reader
                .join()
                .unwrap_or_else(|_| Err("the thread that reads the stream failed".to_owned())),
            Err(e) => Err(e),
        };
        let drawn = match drawer {
            Some(Ok(drawer)) => drawer
                .join()
                .map_err(|_| "the thread that draws the growing view failed".to_owned()),
            _ => Ok(()),
        };
        served.and(taken).and(drawn)
    });
    outcome.map_err(fail)?;
    let skipped = mailbox.skipped();
    let mut notes = shared.into_notes();
    notes.pictures_skipped = skipped;
    Ok(notes)
}

/// The thread that draws: hands each summary `mailbox` gives to `grow` until it is closed,
/// noting what each took and resting [`DRAWING_REST`](super::growth::DRAWING_REST) times
/// that before the next (the collector's own pacing cannot see a picture still being drawn:
/// a summary put while the first is drawn would otherwise be drawn right after it).
fn draw(mailbox: &Mailbox<LogSummary>, grow: &mut (dyn FnMut(LogSummary) + Send)) {
    let mut rest = Duration::ZERO;
    while let Some(plan) = mailbox.take_after(rest) {
        let started = Instant::now();
        grow(plan);
        let cost = started.elapsed();
        mailbox.handled(cost);
        rest = cost * super::growth::DRAWING_REST;
    }
}

/// Feeds the collector what the reading thread hands on until it ends (Ctrl-C stops it),
/// calling `progress` and putting each summary due in `mailbox` for the thread that draws.
fn take(
    taker: queue::Taker<'_>,
    live: &LiveOptions,
    shared: &Shared,
    collector: &mut Collector<'_, '_>,
    mailbox: Option<&Mailbox<LogSummary>>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), String> {
    let mut last_progress = Instant::now();
    let notes = || {
        let mut notes = shared.notes();
        notes.pictures_skipped = mailbox.map_or(0, Mailbox::skipped);
        notes
    };
    loop {
        if collector.stop() {
            shared.stop.store(true, Ordering::Release);
        }
        if last_progress.elapsed() >= Duration::from_millis(200) {
            let received = shared.received.load(Ordering::Acquire);
            match (live.messages, live.duration) {
                (Some(n), _) => progress(received, n),
                (None, Some(d)) => progress(
                    shared.start.elapsed().as_millis() as u64,
                    d.as_millis() as u64,
                ),
                (None, None) => progress(received, 0),
            }
            last_progress = Instant::now();
        }
        if let Some(mailbox) = mailbox
            && let Some(plan) = collector.grow(&notes, mailbox.cost())
        {
            mailbox.put(plan);
        }
        match taker.next(client::POLL) {
            Next::Event(Event::Declare(stream)) => collector.declare_stream(&stream.0),
            Next::Event(Event::Message(m)) => collector.message_on(
                Some(&m.stream.0),
                "channel",
                m.channel,
                m.log_time_ns,
                m.payload(),
                m.stream.1,
            )?,
            Next::Idle => {}
            Next::Done => return Ok(()),
        }
    }
}

/// The input's name in messages: the URL.
pub(super) fn origin(url: &str) -> &Path {
    Path::new(url)
}
