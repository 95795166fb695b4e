//! A running robot, live: the topics of a Foxglove WebSocket server (foxglove_bridge for ROS 1
//! and ROS 2, the Foxglove SDK's server) read as one more log source. The server's binary frames
//! carry each message's bytes as a bag stores them (`cdr` for ROS 2, `ros1` for ROS 1), so they
//! go through the same decoders and the same per-topic collector as a file's; everything after
//! sees a [`LogSummary`](crate::plan::log::LogSummary).
//!
//! - `client.rs`: the connection (`tungstenite`, blocking, `ws://` only): connect timeout,
//!   bounded frames, both subprotocols offered, errors in words;
//! - `protocol.rs`: the protocol's messages (`serverInfo`, `advertise`, `unadvertise`,
//!   message data; `subscribe`, `unsubscribe`);
//! - `record.rs`: `--record run.mcap`, every received message written as it arrives.
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
//! No async runtime: one thread reads frames as they come (the server, not posecov, holds back
//! what a slow reader has not taken, so nothing queues here without bound).
//!
//! ```
//! use posecov::input::log::ws::{LiveOptions, is_live};
//! assert!(is_live("ws://127.0.0.1:8765") && !is_live("run.mcap"));
//! assert!(LiveOptions::default().is_empty());
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::{Codec, Collector, Stream};
use crate::input::InputError;

pub mod client;
pub mod protocol;
mod record;

use crate::plan::log::StreamNotes;
use client::Read;
use protocol::{Channel, ServerMessage};

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

/// One advertised channel as posecov reads it.
struct Live {
    stream: Stream,
    codec: Codec,
    subscription: Option<u32>,
}

/// What posecov makes of an advertised channel: the same rules as an MCAP channel's
/// (`cdr`: the ROS 2 schema name; `ros1`: the ROS 1 name, its definition by name).
fn stream_of(channel: &Channel) -> (Stream, Codec) {
    let schema = channel.schema_name.clone();
    let encoding = channel.encoding.as_str();
    let other = || format!("{schema} in {encoding} encoding; posecov reads cdr or ros1");
    Stream::of_channel(channel.topic.clone(), schema.clone(), encoding, other)
}

/// Whether posecov subscribes to a stream: a chosen pose topic, the reference, or `/tf`.
fn wanted(collector: &Collector<'_, '_>, stream: &Stream) -> bool {
    let pose = matches!(stream.kind, Some(Ok(_))) && collector.selected(&stream.topic);
    let tf = matches!(stream.topic.as_str(), "/tf" | "/tf_static")
        && matches!(stream.reference, Some(Ok(_)));
    pose || tf || collector.is_reference(&stream.topic)
}

/// The waits before each attempt to connect again after the connection was lost: bounded
/// (under 4 s in all), and cut short by a limit or Ctrl-C.
pub const RECONNECT_BACKOFF: [Duration; 4] = [
    Duration::from_millis(250),
    Duration::from_millis(500),
    Duration::from_secs(1),
    Duration::from_secs(2),
];

/// Reads the stream at `url` into `collector` until a limit of `live`, Ctrl-C or the end of
/// the stream; a lost connection is made again (after [`RECONNECT_BACKOFF`]). Returns what
/// the stream did besides carrying messages. `progress(done, total)`: messages or ms.
pub(super) fn read(
    url: &str,
    live: &LiveOptions,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<StreamNotes, InputError> {
    let fail = |reason: String| InputError::Read {
        path: url.to_owned(),
        reason,
    };
    let parsed = client::parse_url(url).map_err(fail)?;
    let recorder = match &live.record {
        Some(path) => Some(record::Recorder::create(path).map_err(fail)?),
        None => None,
    };
    let mut connection = client::connect(&parsed).map_err(fail)?;
    let mut session = Session {
        channels: BTreeMap::new(),
        subscriptions: BTreeMap::new(),
        next_subscription: 1,
        received: 0,
        recorder,
        notes: StreamNotes::new(url),
        start: Instant::now(),
    };
    let outcome = loop {
        let end = session.run(&mut connection.socket, live, collector, progress);
        session.leave(&mut connection.socket);
        match end {
            Ok(None) => break Ok(()),
            Err(e) => break Err(e),
            Ok(Some(why)) => match session.reconnect(&parsed, live, collector) {
                Again::Connected(next) => {
                    session
                        .notes
                        .lost(why, session.start.elapsed().as_secs_f64());
                    connection = *next;
                }
                Again::Stopped => break Ok(()),
                Again::Failed(last) => break session.ended(live, &why, &last),
            },
        }
    };
    // A complete recording whatever happened.
    let finished = session.recorder.take().map(record::Recorder::finish);
    outcome.map_err(fail)?;
    if let Some(Err(e)) = finished {
        return Err(fail(e));
    }
    Ok(session.notes)
}

/// What trying to connect again gave.
enum Again {
    Connected(Box<client::Connection>),
    /// A limit or Ctrl-C came first: the run ends as asked.
    Stopped,
    /// Every attempt failed: the last reason.
    Failed(String),
}

/// One stream's state, across its connections.
struct Session {
    channels: BTreeMap<u64, Live>,
    /// Subscription id → channel id (this connection's).
    subscriptions: BTreeMap<u32, u64>,
    /// Ids below it were made by posecov (a frame for one no longer held is skipped quietly).
    next_subscription: u32,
    received: u64,
    recorder: Option<record::Recorder>,
    notes: StreamNotes,
    start: Instant,
}

impl Session {
    /// Whether a limit of `live` is reached.
    fn done(&self, live: &LiveOptions) -> bool {
        live.duration.is_some_and(|d| self.start.elapsed() >= d)
            || live.messages.is_some_and(|n| self.received >= n)
    }

    /// Reads frames until a limit or Ctrl-C (`Ok(None)`) or until the connection is lost
    /// (`Ok(Some(why))`); a frame posecov cannot read is noted and skipped.
    fn run(
        &mut self,
        socket: &mut Socket,
        live: &LiveOptions,
        collector: &mut Collector<'_, '_>,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<Option<String>, String> {
        let mut last_progress = Instant::now();
        loop {
            if collector.stop() || self.done(live) {
                return Ok(None);
            }
            if last_progress.elapsed() >= Duration::from_millis(200) {
                let elapsed = self.start.elapsed();
                match (live.messages, live.duration) {
                    (Some(n), _) => progress(self.received, n),
                    (None, Some(d)) => progress(elapsed.as_millis() as u64, d.as_millis() as u64),
                    (None, None) => progress(self.received, 0),
                }
                last_progress = Instant::now();
            }
            collector.grow(&self.notes);
            let frame = match client::read(socket)? {
                Read::Idle => continue,
                Read::Closed(why) => return Ok(Some(why)),
                Read::Frame(frame) => frame,
            };
            match frame {
                tungstenite::Message::Text(text) => match protocol::parse_text(text.as_str()) {
                    Ok(message) => self.server_message(socket, message, collector)?,
                    Err(e) => self.notes.damaged(format!("a text frame: {e}")),
                },
                tungstenite::Message::Binary(bytes) => self.binary(&bytes, collector)?,
                _ => {}
            }
        }
    }

    /// Unsubscribes and closes the connection (whatever state it is in).
    fn leave(&mut self, socket: &mut Socket) {
        let ids: Vec<u32> = self.subscriptions.keys().copied().collect();
        if !ids.is_empty() {
            let _ = client::send(socket, protocol::unsubscribe(&ids));
        }
        client::close(socket);
    }

    /// Connects again after a loss, waiting [`RECONNECT_BACKOFF`] before each attempt; the
    /// new connection's channels are advertised afresh (the recording keeps its channels).
    fn reconnect(
        &mut self,
        url: &client::WsUrl,
        live: &LiveOptions,
        collector: &mut Collector<'_, '_>,
    ) -> Again {
        let mut last = String::new();
        for wait in RECONNECT_BACKOFF {
            let until = Instant::now() + wait;
            while Instant::now() < until {
                if collector.stop() || self.done(live) {
                    return Again::Stopped;
                }
                std::thread::sleep(client::POLL.min(until - Instant::now()));
            }
            match client::connect(url) {
                Ok(connection) => {
                    self.channels.clear();
                    self.subscriptions.clear();
                    if let Some(recorder) = &mut self.recorder {
                        recorder.reconnected();
                    }
                    return Again::Connected(Box::new(connection));
                }
                Err(e) => last = e,
            }
        }
        Again::Failed(last)
    }

    /// The connection lost for good (`why`; connecting again failed with `last`): an error
    /// when a limit was asked for and not reached, else the end of the run, noted.
    fn ended(&mut self, live: &LiveOptions, why: &str, last: &str) -> Result<(), String> {
        let again = format!(
            "{why}; connecting again failed {} time(s) (last: {last})",
            RECONNECT_BACKOFF.len()
        );
        let asked = match (live.duration, live.messages) {
            (_, Some(n)) => format!("--messages {n}"),
            (Some(d), None) => format!("--duration {}s", d.as_secs_f64()),
            (None, None) => {
                self.notes.ended = Some(again);
                return Ok(());
            }
        };
        Err(format!(
            "the stream ended early: {again}; after {:.1} s and {} message(s), before {asked}",
            self.start.elapsed().as_secs_f64(),
            self.received
        ))
    }

    fn server_message(
        &mut self,
        socket: &mut Socket,
        message: ServerMessage,
        collector: &mut Collector<'_, '_>,
    ) -> Result<(), String> {
        match message {
            ServerMessage::Advertise(channels) => {
                let mut pairs = Vec::new();
                for channel in channels {
                    if self.channels.contains_key(&channel.id) {
                        continue;
                    }
                    let (stream, codec) = stream_of(&channel);
                    collector.declare_stream(&stream);
                    let subscription = wanted(collector, &stream).then(|| {
                        let id = self.next_subscription;
                        self.next_subscription = self.next_subscription.wrapping_add(1);
                        pairs.push((id, channel.id));
                        self.subscriptions.insert(id, channel.id);
                        id
                    });
                    if let Some(recorder) = &mut self.recorder {
                        recorder.channel(&channel)?;
                    }
                    self.channels.insert(
                        channel.id,
                        Live {
                            stream,
                            codec,
                            subscription,
                        },
                    );
                }
                if !pairs.is_empty() {
                    client::send(socket, protocol::subscribe(&pairs))?;
                }
            }
            ServerMessage::Unadvertise(ids) => {
                for id in ids {
                    if let Some(Live {
                        subscription: Some(s),
                        ..
                    }) = self.channels.remove(&id)
                    {
                        self.subscriptions.remove(&s);
                    }
                }
            }
            ServerMessage::ServerInfo { .. }
            | ServerMessage::Status { .. }
            | ServerMessage::Other(_) => {}
        }
        Ok(())
    }

    /// A binary frame: a message on a subscription goes to the collector (and the recording);
    /// a frame for a subscription no longer held (one in flight when a channel went) is
    /// skipped; a damaged one, or one for a subscription posecov never made, is noted.
    fn binary(&mut self, frame: &[u8], collector: &mut Collector<'_, '_>) -> Result<(), String> {
        let data = match protocol::parse_binary(frame) {
            Ok(Some(data)) => data,
            Ok(None) => return Ok(()),
            Err(e) => {
                self.notes.damaged(e);
                return Ok(());
            }
        };
        let Some(live) = self
            .subscriptions
            .get(&data.subscription)
            .and_then(|channel| self.channels.get(channel).map(|live| (*channel, live)))
        else {
            if data.subscription == 0 || data.subscription >= self.next_subscription {
                self.notes.damaged(format!(
                    "a message-data frame for subscription {}, which posecov never made",
                    data.subscription
                ));
            }
            return Ok(());
        };
        let (channel, live) = live;
        self.received += 1;
        if let Some(recorder) = &mut self.recorder {
            recorder.message(channel, data.log_time_ns, data.payload)?;
        }
        collector.message_on(
            Some(&live.stream),
            "channel",
            channel,
            data.log_time_ns,
            data.payload,
            live.codec,
        )
    }
}

/// The input's name in messages: the URL.
pub(super) fn origin(url: &str) -> &Path {
    Path::new(url)
}
