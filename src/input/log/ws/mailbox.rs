//! The growing view's hand-off from the collector to the thread that draws it: one slot, the
//! newest wins. The collector puts each summary due and never waits for drawing; a summary put
//! while an older one is still waiting replaces it (the older is *skipped*, counted), so the
//! thread that draws always takes the newest, and a redraw slower than the stream costs
//! pictures, never messages. The thread that draws waits for the slot to fill and ends once it
//! is closed (the read ended).

use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

/// A one-slot mailbox: [`put`](Self::put) never waits for [`take`](Self::take).
pub(super) struct Mailbox<T> {
    slot: Mutex<Slot<T>>,
    filled: Condvar,
}

/// What the mailbox holds.
struct Slot<T> {
    newest: Option<T>,
    closed: bool,
    /// Items replaced before they were taken, put after the close, or dropped at the close.
    skipped: u64,
    /// What handling the last item taken cost ([`Mailbox::handled`]).
    cost: Duration,
}

impl<T> Mailbox<T> {
    /// An empty, open mailbox.
    pub(super) fn new() -> Self {
        Self {
            slot: Mutex::new(Slot {
                newest: None,
                closed: false,
                skipped: 0,
                cost: Duration::ZERO,
            }),
            filled: Condvar::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Slot<T>> {
        // A panic while handling an item is the drawing thread's, seen when it is joined;
        // the slot itself is whole between any two statements that change it.
        self.slot.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Puts `item` in the slot, replacing (skipping) one not yet taken; after the close it is
    /// skipped at once. Never waits for the taker.
    pub(super) fn put(&self, item: T) {
        let mut slot = self.lock();
        if slot.closed {
            slot.skipped += 1;
            return;
        }
        if slot.newest.replace(item).is_some() {
            slot.skipped += 1;
        }
        drop(slot);
        self.filled.notify_one();
    }

    /// The newest item, waiting for one; `None` once the mailbox is closed and empty.
    pub(super) fn take(&self) -> Option<T> {
        let mut slot = self.lock();
        loop {
            if let Some(item) = slot.newest.take() {
                return Some(item);
            }
            if slot.closed {
                return None;
            }
            slot = self
                .filled
                .wait(slot)
                .unwrap_or_else(PoisonError::into_inner);
        }
    }

    /// The newest item after `rest` has passed (the taker's pause between two items, so that
    /// handling them takes a bounded share of the time), waiting for one then; at once, with
    /// no pause, once the mailbox is closed (the last item is not kept waiting); `None` once
    /// it is closed and empty.
    pub(super) fn take_after(&self, rest: Duration) -> Option<T> {
        let until = std::time::Instant::now() + rest;
        let mut slot = self.lock();
        loop {
            let now = std::time::Instant::now();
            if slot.closed || now >= until {
                drop(slot);
                return self.take();
            }
            slot = self
                .filled
                .wait_timeout(slot, until - now)
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
    }

    /// Closes the mailbox: the taker gets the item still waiting when `keep` (else it is
    /// skipped), then `None`.
    pub(super) fn close(&self, keep: bool) {
        let mut slot = self.lock();
        slot.closed = true;
        if !keep && slot.newest.take().is_some() {
            slot.skipped += 1;
        }
        drop(slot);
        self.filled.notify_all();
    }

    /// Items skipped so far.
    pub(super) fn skipped(&self) -> u64 {
        self.lock().skipped
    }

    /// Notes what handling the item last taken cost.
    pub(super) fn handled(&self, cost: Duration) {
        self.lock().cost = cost;
    }

    /// What handling the item last taken cost ([`Duration::ZERO`] before the first).
    pub(super) fn cost(&self) -> Duration {
        self.lock().cost
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_newest_wins_and_the_skipped_are_counted() {
        let mailbox = Mailbox::new();
        // Nobody takes: each put replaces the one before.
        for picture in 1..=5 {
            mailbox.put(picture);
        }
        assert_eq!(mailbox.skipped(), 4);
        assert_eq!(mailbox.take(), Some(5));
        mailbox.put(6);
        mailbox.close(true);
        // Kept at the close, then the end; a put after the close is skipped at once.
        mailbox.put(7);
        assert_eq!(mailbox.take(), Some(6));
        assert_eq!(mailbox.take(), None);
        assert_eq!(mailbox.skipped(), 5);
    }

    #[test]
    fn a_close_that_drops_skips_the_waiting_item() {
        let mailbox = Mailbox::new();
        mailbox.put("old");
        mailbox.close(false);
        assert_eq!(mailbox.take(), None);
        assert_eq!(mailbox.skipped(), 1);
    }

    #[test]
    fn a_waiting_taker_wakes_for_a_put_and_for_the_close() {
        // No clock: the taker blocks until the putter acts, whatever the order of the two
        // threads; the test cannot end unless both wake-ups happen.
        let mailbox = Mailbox::new();
        let taken = std::thread::scope(|scope| {
            let taker = scope.spawn(|| {
                let mut taken = Vec::new();
                while let Some(item) = mailbox.take() {
                    taken.push(item);
                }
                taken
            });
            mailbox.put(1);
            mailbox.close(true);
            taker.join().expect("the taker ends")
        });
        // The one item put was taken before the close, or was still waiting then and kept.
        assert_eq!(taken, [1]);
        assert_eq!(mailbox.skipped(), 0);
        mailbox.handled(Duration::from_millis(3));
        assert_eq!(mailbox.cost(), Duration::from_millis(3));
    }

    #[test]
    fn a_resting_taker_still_ends_at_the_close() {
        // A pause far longer than any test: the close must cut it short, with the item that
        // waits handed over, not dropped.
        let mailbox = Mailbox::new();
        let taken = std::thread::scope(|scope| {
            let taker = scope.spawn(|| {
                let mut taken = Vec::new();
                while let Some(item) = mailbox.take_after(Duration::from_secs(3600)) {
                    taken.push(item);
                }
                taken
            });
            mailbox.put(1);
            mailbox.put(2);
            mailbox.close(true);
            taker.join().expect("the taker ends")
        });
        // 1 was replaced by 2 while the taker rested (or taken before the close: then only
        // 2 follows); the newest is never lost.
        assert_eq!(taken.last(), Some(&2));
        assert_eq!(mailbox.skipped() + taken.len() as u64, 2);
    }
}
