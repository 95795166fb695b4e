//! The bounded hand-off from the thread that reads the socket to the collector: channels
//! advertised (never dropped) and messages received. At most [`QUEUE_MESSAGES`] messages and
//! [`QUEUE_BYTES`] bytes wait; a message that arrives while the queue is full is *thinned*
//! (not handed on) and counted, so a server that sends faster than posecov reads and draws
//! never makes posecov queue without bound, and the count thinned is said
//! ([`StreamNotes::thinned`](crate::plan::log::StreamNotes::thinned)).

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TrySendError, sync_channel};
use std::time::Duration;

use tungstenite::Bytes;

use super::super::{Codec, Stream};

/// At most this many received messages wait for the collector: ten seconds of 100 Hz × 4
/// topics, far more than one redraw of the growing view holds the reader up.
pub const QUEUE_MESSAGES: usize = 4096;
/// At most this many bytes of received messages wait for the collector (64 MiB: four frames
/// of the largest size [`MAX_FRAME`](super::client::MAX_FRAME), some 60 000 pose messages).
pub const QUEUE_BYTES: usize = 64 << 20;

/// A message on a subscribed channel, as it arrived.
pub(super) struct Arrived {
    /// The channel's stream (what posecov makes of it) and how its bytes are encoded.
    pub(super) stream: Arc<(Stream, Codec)>,
    /// The server's channel id.
    pub(super) channel: u64,
    /// The server's log time (ns).
    pub(super) log_time_ns: u64,
    /// The message-data frame whole; the message's bytes start at [`Self::offset`].
    pub(super) frame: Bytes,
    /// Where the message's bytes start in the frame.
    pub(super) offset: usize,
}

impl Arrived {
    /// The serialised message.
    pub(super) fn payload(&self) -> &[u8] {
        self.frame.get(self.offset..).unwrap_or_default()
    }
}

/// What the reading thread hands on.
pub(super) enum Event {
    /// A channel advertised: the collector declares it (a topic without messages is listed).
    Declare(Arc<(Stream, Codec)>),
    /// A message received.
    Message(Arrived),
}

/// The reading thread's end.
pub(super) struct Sender<'q> {
    tx: SyncSender<Event>,
    queued: &'q AtomicUsize,
}

/// The collector's end, gone once the run's reading ends.
pub(super) struct Taker<'q> {
    rx: Receiver<Event>,
    queued: &'q AtomicUsize,
}

/// The collector's end is gone (the run ended): the reading thread stops.
#[derive(Debug)]
pub(super) struct Gone;

/// A new queue of [`QUEUE_MESSAGES`] messages, `queued` counting the bytes waiting.
pub(super) fn bounded(queued: &AtomicUsize) -> (Sender<'_>, Taker<'_>) {
    let (tx, rx) = sync_channel(QUEUE_MESSAGES);
    (Sender { tx, queued }, Taker { rx, queued })
}

impl Sender<'_> {
    /// Hands a channel on, waiting while the queue is full (a channel is never dropped).
    pub(super) fn declare(&self, stream: Arc<(Stream, Codec)>) -> Result<(), Gone> {
        self.tx.send(Event::Declare(stream)).map_err(|_| Gone)
    }

    /// Offers a message: `Ok(true)` when queued, `Ok(false)` when thinned (the queue holds
    /// [`QUEUE_MESSAGES`] messages or [`QUEUE_BYTES`] bytes already).
    pub(super) fn offer(&self, message: Arrived) -> Result<bool, Gone> {
        let size = message.frame.len();
        let before = self.queued.fetch_add(size, Ordering::AcqRel);
        if before.saturating_add(size) > QUEUE_BYTES {
            self.queued.fetch_sub(size, Ordering::AcqRel);
            return Ok(false);
        }
        match self.tx.try_send(Event::Message(message)) {
            Ok(()) => Ok(true),
            Err(TrySendError::Full(_)) => {
                self.queued.fetch_sub(size, Ordering::AcqRel);
                Ok(false)
            }
            Err(TrySendError::Disconnected(_)) => Err(Gone),
        }
    }
}

/// What the collector's end gave.
pub(super) enum Next {
    /// The next event.
    Event(Event),
    /// Nothing within the wait.
    Idle,
    /// The reading thread ended and everything it handed on was taken.
    Done,
}

impl Taker<'_> {
    /// The next event, waiting at most `wait`.
    pub(super) fn next(&self, wait: Duration) -> Next {
        match self.rx.recv_timeout(wait) {
            Ok(event) => {
                if let Event::Message(m) = &event {
                    self.queued.fetch_sub(m.frame.len(), Ordering::AcqRel);
                }
                Next::Event(event)
            }
            Err(RecvTimeoutError::Timeout) => Next::Idle,
            Err(RecvTimeoutError::Disconnected) => Next::Done,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arrived(stream: &Arc<(Stream, Codec)>, size: usize) -> Arrived {
        Arrived {
            stream: Arc::clone(stream),
            channel: 1,
            log_time_ns: 0,
            frame: Bytes::from(vec![1u8; size]),
            offset: 13,
        }
    }

    fn stream() -> Arc<(Stream, Codec)> {
        Arc::new(Stream::of_channel(
            "/pose".into(),
            "geometry_msgs/msg/PoseWithCovarianceStamped".into(),
            "cdr",
            String::new,
        ))
    }

    #[test]
    fn a_flood_is_thinned_and_counted_never_queued_without_bound() {
        let queued = AtomicUsize::new(0);
        let (sender, taker) = bounded(&queued);
        let stream = stream();
        sender.declare(Arc::clone(&stream)).unwrap();
        // Nobody takes: 10 000 messages offered, the queue holds what it may.
        let flood = 10_000;
        let taken = (0..flood)
            .filter(|_| sender.offer(arrived(&stream, 100)).unwrap())
            .count();
        // One place of the channel's is the declaration's.
        assert_eq!(taken, QUEUE_MESSAGES - 1);
        assert_eq!(queued.load(Ordering::Acquire), taken * 100);
        // Taking frees places and bytes.
        assert!(matches!(
            taker.next(Duration::ZERO),
            Next::Event(Event::Declare(_))
        ));
        assert!(matches!(
            taker.next(Duration::ZERO),
            Next::Event(Event::Message(_))
        ));
        assert_eq!(queued.load(Ordering::Acquire), (taken - 1) * 100);
        assert!(sender.offer(arrived(&stream, 100)).unwrap());
        assert!(sender.offer(arrived(&stream, 100)).unwrap());
        assert!(!sender.offer(arrived(&stream, 100)).unwrap());
        drop(sender);
        let mut left = 0;
        while let Next::Event(_) = taker.next(Duration::ZERO) {
            left += 1;
        }
        assert_eq!(left, taken + 1);
        assert_eq!(queued.load(Ordering::Acquire), 0);
        assert!(matches!(taker.next(Duration::ZERO), Next::Done));
    }

    #[test]
    fn large_messages_are_bounded_by_bytes() {
        let queued = AtomicUsize::new(0);
        let (sender, taker) = bounded(&queued);
        let stream = stream();
        let big = 16 << 20;
        let taken = (0..10)
            .filter(|_| sender.offer(arrived(&stream, big)).unwrap())
            .count();
        assert_eq!(taken, QUEUE_BYTES / big);
        let Next::Event(Event::Message(m)) = taker.next(Duration::ZERO) else {
            panic!("a message waits");
        };
        assert_eq!(m.payload().len(), big - 13);
        drop(taker);
        assert!(sender.offer(arrived(&stream, 100)).is_err());
    }
}
