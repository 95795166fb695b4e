//! What a live stream (`ws://…`) did besides carrying messages ([`StreamNotes`]): frames
//! posecov could not read and skipped (the run went on), messages thinned because they came
//! faster than posecov read them, connections lost and made again, and pictures of the
//! growing view skipped. Bounded: counts, and the first few of each in words.

use serde::Serialize;

/// At most this many damaged frames, and this many lost connections, are kept in words (the
/// rest are counted).
pub const MAX_NOTED: usize = 8;

/// What a live stream did besides carrying messages.
///
/// ```
/// use posecov::plan::log::StreamNotes;
/// let mut notes = StreamNotes::new("ws://127.0.0.1:8765");
/// notes.damaged("malformed JSON (EOF while parsing)".into());
/// notes.lost("closed by the server".into(), 1.5);
/// notes.pictures_skipped = 2;
/// let lines = notes.sentences();
/// assert!(lines[2].contains("skipped 2 picture(s) of the growing view"), "{lines:?}");
/// assert!(lines[0].starts_with("ws://127.0.0.1:8765: skipped 1 damaged frame(s)"), "{lines:?}");
/// assert!(lines[1].contains("lost 1 time(s)"), "{lines:?}");
/// ```
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StreamNotes {
    /// The stream's URL.
    pub url: String,
    /// Frames skipped as unreadable: malformed JSON, a truncated message-data frame, a frame
    /// for a subscription posecov never made.
    pub damaged: u64,
    /// The first [`MAX_NOTED`] of them, each in words.
    pub damaged_first: Vec<String>,
    /// Messages received on the subscribed topics but not read: they arrived while the
    /// queue between the socket and the collector was full (the server sent faster than
    /// posecov reads and draws). Counts, health and statistics are of the messages read.
    pub thinned: u64,
    /// Connections lost and made again.
    pub lost: u64,
    /// The first [`MAX_NOTED`] losses: why, and when (seconds since the first connection).
    pub lost_first: Vec<String>,
    /// Why the stream ended for good without a limit asked (`--duration`, `--messages`):
    /// the server went and did not come back.
    pub ended: Option<String>,
    /// Pictures of the growing view not drawn: a newer summary replaced each while the one
    /// before was still being drawn (reading never waits for drawing). Absent from the JSON
    /// when none (a run that is not drawn, `report`, never skips one).
    #[serde(skip_serializing_if = "is_zero")]
    pub pictures_skipped: u64,
}

/// Whether a count is zero (a key left out of the JSON).
fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl StreamNotes {
    /// Nothing noted yet, for the stream at `url`.
    ///
    /// ```
    /// assert!(posecov::plan::log::StreamNotes::new("ws://robot:8765").sentences().is_empty());
    /// ```
    pub fn new(url: &str) -> Self {
        Self {
            url: url.to_owned(),
            ..Self::default()
        }
    }

    /// A frame skipped, `why` in words.
    ///
    /// ```
    /// let mut notes = posecov::plan::log::StreamNotes::new("ws://robot:8765");
    /// for _ in 0..20 { notes.damaged("a truncated frame".into()); }
    /// assert_eq!((notes.damaged, notes.damaged_first.len()), (20, 8));
    /// ```
    pub fn damaged(&mut self, why: String) {
        self.damaged += 1;
        if self.damaged_first.len() < MAX_NOTED {
            self.damaged_first.push(why);
        }
    }

    /// A message received and thinned (not read: posecov was behind).
    ///
    /// ```
    /// let mut notes = posecov::plan::log::StreamNotes::new("ws://robot:8765");
    /// notes.thin();
    /// assert_eq!(notes.thinned, 1);
    /// assert!(notes.sentences()[0].contains("thinned 1 message(s)"));
    /// ```
    pub fn thin(&mut self) {
        self.thinned += 1;
    }

    /// The connection lost, `why` in words, `at_s` seconds after the first connection.
    ///
    /// ```
    /// let mut notes = posecov::plan::log::StreamNotes::new("ws://robot:8765");
    /// notes.lost("the connection was reset".into(), 2.0);
    /// assert_eq!(notes.lost_first, ["the connection was reset (at 2.0 s)"]);
    /// ```
    pub fn lost(&mut self, why: String, at_s: f64) {
        self.lost += 1;
        if self.lost_first.len() < MAX_NOTED {
            self.lost_first.push(format!("{why} (at {at_s:.1} s)"));
        }
    }

    /// One sentence per kind of note, each naming the URL (none when nothing happened).
    ///
    /// ```
    /// let mut notes = posecov::plan::log::StreamNotes::new("ws://robot:8765");
    /// notes.ended = Some("closed by the server".into());
    /// assert_eq!(notes.sentences(), ["ws://robot:8765: the stream ended: closed by the server"]);
    /// ```
    pub fn sentences(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let more = |shown: usize, count: u64| match count.saturating_sub(shown as u64) {
            0 => String::new(),
            n => format!("; {n} more"),
        };
        if self.damaged > 0 {
            lines.push(format!(
                "{}: skipped {} damaged frame(s), the run went on: {}{}",
                self.url,
                self.damaged,
                self.damaged_first.join("; "),
                more(self.damaged_first.len(), self.damaged)
            ));
        }
        if self.thinned > 0 {
            lines.push(format!(
                "{}: thinned {} message(s) that arrived faster than posecov read them (none queued without bound); counts, health and statistics are of the messages read",
                self.url, self.thinned
            ));
        }
        if self.lost > 0 {
            lines.push(format!(
                "{}: the connection was lost {} time(s) and made again: {}{}",
                self.url,
                self.lost,
                self.lost_first.join("; "),
                more(self.lost_first.len(), self.lost)
            ));
        }
        if let Some(why) = &self.ended {
            lines.push(format!("{}: the stream ended: {why}", self.url));
        }
        if self.pictures_skipped > 0 {
            lines.push(format!(
                "{}: skipped {} picture(s) of the growing view, each replaced by a newer one while the one before was drawn (every message was read)",
                self.url, self.pictures_skipped
            ));
        }
        lines
    }
}
