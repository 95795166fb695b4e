//! The reading thread: one stream across its connections. It reads frames as they come,
//! answers `advertise` with `subscribe`, writes `--record`, notes what it could not read, and
//! hands channels and messages to the collector through the bounded queue (`queue.rs`: a
//! message that finds it full is thinned and counted). A lost connection is made again after
//! [`RECONNECT_BACKOFF`]; it unsubscribes and closes on exit.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use super::super::{Codec, LogOptions, Stream};
use super::client::{self, Read};
use super::protocol::{self, Channel, ServerMessage};
use super::queue::{Arrived, Gone, Sender};
use super::{LiveOptions, RECONNECT_BACKOFF, Socket, record};
use crate::plan::log::StreamNotes;

/// What the reading thread and the collector's side share.
pub(super) struct Shared {
    /// Set by the collector's side when the run ends (Ctrl-C, an error): the thread stops.
    pub(super) stop: AtomicBool,
    /// Messages received on the subscribed channels (thinned ones too).
    pub(super) received: AtomicU64,
    /// Bytes waiting in the queue.
    pub(super) queued: AtomicUsize,
    /// What the stream did besides carrying messages, so far.
    notes: Mutex<StreamNotes>,
    /// When the first connection was made.
    pub(super) start: Instant,
}

impl Shared {
    /// Nothing read yet from the stream at `url`.
    pub(super) fn new(url: &str) -> Self {
        Self {
            stop: AtomicBool::new(false),
            received: AtomicU64::new(0),
            queued: AtomicUsize::new(0),
            notes: Mutex::new(StreamNotes::new(url)),
            start: Instant::now(),
        }
    }

    /// A copy of the notes so far.
    pub(super) fn notes(&self) -> StreamNotes {
        self.note(|n| n.clone())
    }

    /// Changes the notes.
    fn note<T>(&self, change: impl FnOnce(&mut StreamNotes) -> T) -> T {
        change(&mut self.notes.lock().unwrap_or_else(PoisonError::into_inner))
    }

    /// The notes, at the end.
    pub(super) fn into_notes(self) -> StreamNotes {
        self.notes
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner)
    }

    /// Whether a limit of `live` is reached or the run ends.
    fn done(&self, live: &LiveOptions) -> bool {
        self.stop.load(Ordering::Acquire)
            || live.duration.is_some_and(|d| self.start.elapsed() >= d)
            || live
                .messages
                .is_some_and(|n| self.received.load(Ordering::Acquire) >= n)
    }
}

/// One advertised channel as posecov reads it.
struct Live {
    stream: Arc<(Stream, Codec)>,
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
fn wanted(options: &LogOptions, stream: &Stream) -> bool {
    let pose = matches!(stream.kind, Some(Ok(_))) && options.selects(&stream.topic);
    let tf = matches!(stream.topic.as_str(), "/tf" | "/tf_static")
        && matches!(stream.reference, Some(Ok(_)));
    pose || tf || options.carries_reference(&stream.topic)
}

/// What trying to connect again gave.
enum Again {
    Connected(Box<client::Connection>),
    /// A limit, Ctrl-C or the end of the run came first: the run ends as asked.
    Stopped,
    /// Every attempt failed: the last reason.
    Failed(String),
}

/// One stream's state, across its connections.
pub(super) struct Session<'s, 'q> {
    url: &'s client::WsUrl,
    live: &'s LiveOptions,
    options: &'s LogOptions,
    shared: &'s Shared,
    sender: Sender<'q>,
    channels: BTreeMap<u64, Live>,
    /// Subscription id → channel id (this connection's).
    subscriptions: BTreeMap<u32, u64>,
    /// Ids below it were made by posecov (a frame for one no longer held is skipped quietly).
    next_subscription: u32,
    recorder: Option<record::Recorder>,
}

/// Why a connection's reading stopped.
enum Stopped {
    /// A limit, Ctrl-C or the end of the run.
    Asked,
    /// The connection was lost: why.
    Lost(String),
}

impl<'s, 'q> Session<'s, 'q> {
    /// A session of the stream at `url`, handing on through `sender`.
    pub(super) fn new(
        url: &'s client::WsUrl,
        options: &'s LogOptions,
        shared: &'s Shared,
        sender: Sender<'q>,
        recorder: Option<record::Recorder>,
    ) -> Self {
        Self {
            url,
            live: &options.live,
            options,
            shared,
            sender,
            channels: BTreeMap::new(),
            subscriptions: BTreeMap::new(),
            next_subscription: 1,
            recorder,
        }
    }

    /// Reads the stream on `connection` and every connection made again after a loss, until
    /// a limit, Ctrl-C, the end of the run or the server gone for good; the recording is
    /// finished whatever happened.
    pub(super) fn serve(mut self, connection: client::Connection) -> Result<(), String> {
        let mut next = Some(connection);
        let outcome = loop {
            let Some(mut connection) = next.take() else {
                break Ok(());
            };
            let end = self.run(&mut connection.socket);
            self.leave(&mut connection.socket);
            // Gone before the waits to connect again: the server sees the close at once.
            drop(connection);
            match end {
                Ok(Stopped::Asked) => break Ok(()),
                Err(e) => break Err(e),
                Ok(Stopped::Lost(why)) => match self.reconnect() {
                    Again::Connected(again) => {
                        let at = self.shared.start.elapsed().as_secs_f64();
                        self.shared.note(|n| n.lost(why, at));
                        next = Some(*again);
                    }
                    Again::Stopped => break Ok(()),
                    Again::Failed(last) => break self.ended(&why, &last),
                },
            }
        };
        // A complete recording whatever happened.
        let finished = self.recorder.take().map(record::Recorder::finish);
        outcome?;
        finished.transpose().map(|_| ())
    }

    /// Reads frames until a limit, Ctrl-C or the end of the run, or until the connection is
    /// lost; a frame posecov cannot read is noted and skipped.
    fn run(&mut self, socket: &mut Socket) -> Result<Stopped, String> {
        loop {
            if self.shared.done(self.live) {
                return Ok(Stopped::Asked);
            }
            let frame = match client::read(socket)? {
                Read::Idle => continue,
                Read::Closed(why) => return Ok(Stopped::Lost(why)),
                Read::Frame(frame) => frame,
            };
            let handed = match frame {
                tungstenite::Message::Text(text) => match protocol::parse_text(text.as_str()) {
                    Ok(message) => self.server_message(socket, message)?,
                    Err(e) => {
                        self.shared
                            .note(|n| n.damaged(format!("a text frame: {e}")));
                        Ok(())
                    }
                },
                tungstenite::Message::Binary(bytes) => self.binary(bytes)?,
                _ => Ok(()),
            };
            if handed.is_err() {
                // The collector's side is gone: the run ended.
                return Ok(Stopped::Asked);
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
    fn reconnect(&mut self) -> Again {
        let mut last = String::new();
        for wait in RECONNECT_BACKOFF {
            let until = Instant::now() + wait;
            while Instant::now() < until {
                if self.shared.done(self.live) {
                    return Again::Stopped;
                }
                std::thread::sleep(client::POLL.min(until - Instant::now()));
            }
            match client::connect(self.url) {
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
    fn ended(&mut self, why: &str, last: &str) -> Result<(), String> {
        let again = format!(
            "{why}; connecting again failed {} time(s) (last: {last})",
            RECONNECT_BACKOFF.len()
        );
        let asked = match (self.live.duration, self.live.messages) {
            (_, Some(n)) => format!("--messages {n}"),
            (Some(d), None) => format!("--duration {}s", d.as_secs_f64()),
            (None, None) => {
                self.shared.note(|n| n.ended = Some(again));
                return Ok(());
            }
        };
        Err(format!(
            "the stream ended early: {again}; after {:.1} s and {} message(s), before {asked}",
            self.shared.start.elapsed().as_secs_f64(),
            self.shared.received.load(Ordering::Acquire)
        ))
    }

    /// A JSON message: channels advertised are handed on (and subscribed to when read),
    /// channels gone are forgotten. `Ok(Err(Gone))`: the run ended.
    fn server_message(
        &mut self,
        socket: &mut Socket,
        message: ServerMessage,
    ) -> Result<Result<(), Gone>, String> {
        match message {
            ServerMessage::Advertise(channels) => {
                let mut pairs = Vec::new();
                for channel in channels {
                    if self.channels.contains_key(&channel.id) {
                        continue;
                    }
                    let stream = Arc::new(stream_of(&channel));
                    if self.sender.declare(Arc::clone(&stream)).is_err() {
                        return Ok(Err(Gone));
                    }
                    let subscription = wanted(self.options, &stream.0).then(|| {
                        let id = self.next_subscription;
                        self.next_subscription = self.next_subscription.wrapping_add(1);
                        pairs.push((id, channel.id));
                        self.subscriptions.insert(id, channel.id);
                        id
                    });
                    if let Some(recorder) = &mut self.recorder {
                        recorder.channel(&channel)?;
                    }
                    let live = Live {
                        stream,
                        subscription,
                    };
                    self.channels.insert(channel.id, live);
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
        Ok(Ok(()))
    }

    /// A binary frame: a message on a subscription is recorded and offered to the queue
    /// (thinned and counted when it is full); a frame for a subscription no longer held (one
    /// in flight when a channel went) is skipped; a damaged one, or one for a subscription
    /// posecov never made, is noted. `Ok(Err(Gone))`: the run ended.
    fn binary(&mut self, frame: tungstenite::Bytes) -> Result<Result<(), Gone>, String> {
        let data = match protocol::parse_binary(&frame) {
            Ok(Some(data)) => data,
            Ok(None) => return Ok(Ok(())),
            Err(e) => {
                self.shared.note(|n| n.damaged(e));
                return Ok(Ok(()));
            }
        };
        let Some((channel, live)) = self
            .subscriptions
            .get(&data.subscription)
            .and_then(|channel| self.channels.get(channel).map(|live| (*channel, live)))
        else {
            if data.subscription == 0 || data.subscription >= self.next_subscription {
                self.shared.note(|n| {
                    n.damaged(format!(
                        "a message-data frame for subscription {}, which posecov never made",
                        data.subscription
                    ))
                });
            }
            return Ok(Ok(()));
        };
        self.shared.received.fetch_add(1, Ordering::AcqRel);
        if let Some(recorder) = &mut self.recorder {
            recorder.message(channel, data.log_time_ns, data.payload)?;
        }
        let (log_time_ns, offset) = (data.log_time_ns, frame.len() - data.payload.len());
        let arrived = Arrived {
            stream: Arc::clone(&live.stream),
            channel,
            log_time_ns,
            frame,
            offset,
        };
        Ok(match self.sender.offer(arrived) {
            Ok(true) => Ok(()),
            Ok(false) => {
                self.shared.note(StreamNotes::thin);
                Ok(())
            }
            Err(gone) => Err(gone),
        })
    }
}
