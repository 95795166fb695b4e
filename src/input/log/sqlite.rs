//! ROS 2 bags in SQLite storage (`.db3`, rosbag2's `sqlite3` plugin; Humble's default)
//! through `rusqlite` with its bundled SQLite. The layout is rosbag2's
//! (`rosbag2_storage_sqlite3/src/sqlite_storage.cpp`): `topics(id, name, type,
//! serialization_format, offered_qos_profiles[, type_description_hash])` and
//! `messages(id, topic_id, timestamp, data)`, with `schema` and `metadata` tables from SQLite
//! schema 3 (Humble) and `message_definitions` from schema 4 (Iron); only `topics` and
//! `messages` are needed. Messages are read in the order they were recorded (`messages.id`,
//! SQLite's row order: one pass over the table, no sort), as the other readers read theirs in
//! file order; `timestamp` is the log time (ns). CDR messages are decoded by `decode.rs`, as
//! MCAP's are. One thread steps SQLite and hands rows over in batches, the calling thread
//! decodes them in order (`scan`): each is about half of a read.
//!
//! A file that is not SQLite, or whose pages are damaged, ends with a located error: the
//! table, the last row read, and the damaged pages SQLite finds.

use std::collections::HashMap;
use std::io::Read as _;
use std::path::Path;

use std::sync::mpsc::{Receiver, Sender, SyncSender};

use rusqlite::{Connection, OpenFlags};

use super::rosbag2::{Compression, Image, parse_metadata};
use super::{Codec, Collector, RECORD_LIMIT, Stream};
use crate::input::InputError;
use crate::input::format::SQLITE_MAGIC;

/// Streams every message of the `.db3` file at `path` into `collector`. `compression` is the
/// bag's (from its `metadata.yaml`); `None` for a lone file: then the file's own `metadata`
/// table says it, if it has one. `progress` is called with (row id, last row id).
pub(super) fn read(
    path: &Path,
    compression: Option<Compression>,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let file = path.display().to_string();
    let cut = check_magic(path)?;
    let db = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| InputError::Format {
        file: file.clone(),
        message: format!("SQLite cannot open it: {e}"),
    })?;
    scan(db, &file, &cut, compression, collector, progress)
}

/// Streams every message of a `.db3` held compressed in memory (`image`, a `file`-compressed
/// bag's file) into `collector`: decompressed straight into the buffer SQLite reads in place
/// (no temporary file, no second copy); `named` is the file it came from, for errors. Its
/// messages are not compressed.
pub(super) fn read_image(
    image: Image,
    named: &Path,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let file = named.display().to_string();
    let size = image.size;
    let fail = |message: String| InputError::Format {
        file: file.clone(),
        message,
    };
    let opening = |e: rusqlite::Error| {
        fail(format!(
            "SQLite cannot open it (decompressed, {size} bytes): {e}"
        ))
    };
    /// SQLite's `deserialize` reads the image through `Read`, all of it in one call.
    struct Decompressing<'a> {
        image: &'a Image,
        error: Option<String>,
    }
    impl std::io::Read for Decompressing<'_> {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            if self.error.is_some() || out.len() != self.image.size {
                return Ok(0);
            }
            match self.image.decompress_into(out) {
                Ok(()) => Ok(out.len()),
                Err(e) => {
                    self.error = Some(e);
                    Ok(0)
                }
            }
        }
    }
    let mut db = Connection::open_in_memory().map_err(opening)?;
    let mut source = Decompressing {
        image: &image,
        error: None,
    };
    let opened = db.deserialize_read_exact(rusqlite::MAIN_DB, &mut source, size, true);
    if let Some(e) = source.error {
        return Err(fail(e));
    }
    opened.map_err(opening)?;
    drop(image);
    let cut = String::new();
    scan(
        db,
        &file,
        &cut,
        Some(Compression::None),
        collector,
        progress,
    )
}

/// Streams every message of the open bag `db` (named `file` in errors; `cut`: words for an
/// error when its header says it is cut short) into `collector` (see [`read`]).
///
/// Two threads share the work: one steps SQLite through the `messages` table (and undoes
/// `message` compression), handing rows over in [`Batch`]es; this one decodes them into the
/// collector, in the same order. Each side is about half of a read (perf, issue 32), so a
/// read takes about half the time on two cores; on one it takes what it took.
fn scan(
    db: Connection,
    file: &str,
    cut: &str,
    compression: Option<Compression>,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let fail = |message: String| InputError::Format {
        file: file.to_owned(),
        message,
    };
    let damaged = |what: &str, e: rusqlite::Error| {
        fail(format!("SQLite cannot read {what}: {e}{}{cut}", check(&db)))
    };
    let tables = tables(&db).map_err(|e| damaged("its list of tables", e))?;
    for needed in ["topics", "messages"] {
        if !tables.iter().any(|t| t == needed) {
            return Err(fail(format!(
                "an SQLite database without a `{needed}` table: not a rosbag2 bag (its tables: {})",
                if tables.is_empty() {
                    "none".to_owned()
                } else {
                    tables.join(", ")
                }
            )));
        }
    }
    let compression = match compression {
        Some(c) => c,
        None if tables.iter().any(|t| t == "metadata") => {
            own_compression(&db, file).map_err(|e| damaged("table metadata", e))??
        }
        None => Compression::None,
    };
    let streams = topics(&db).map_err(|e| damaged("table topics", e))?;
    for stream in streams.values() {
        collector.declare_stream(&stream.0);
    }
    let rows: i64 = db
        .query_row("SELECT coalesce(max(id), 0) FROM messages", [], |r| {
            r.get(0)
        })
        .map_err(|e| damaged("table messages", e))?;
    let total = u64::try_from(rows).unwrap_or(0).max(1);
    let named: HashMap<i64, String> = streams
        .iter()
        .map(|(&id, s)| (id, s.0.topic.clone()))
        .collect();
    let (full, filled) = std::sync::mpsc::sync_channel(BATCHES_IN_FLIGHT);
    let (empty, emptied) = std::sync::mpsc::channel();
    std::thread::scope(|threads| {
        let thread = std::thread::Builder::new()
            .name("posecov-db3".to_owned())
            .spawn_scoped(threads, move || {
                let reader = Reader {
                    file,
                    cut,
                    named,
                    message_compressed: compression == Compression::Message,
                };
                reader.send(db, full, emptied)
            })
            .map_err(|e| fail(format!("cannot start a thread to read it: {e}")))?;
        let read = collect(filled, empty, &streams, file, total, collector, progress);
        match thread.join() {
            Ok(()) => read,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// How many [`Batch`]es may wait between the two threads of a read.
const BATCHES_IN_FLIGHT: usize = 4;

/// A batch ends at this many rows or this many bytes of messages, whichever comes first.
const BATCH_ROWS: usize = 512;
/// See [`BATCH_ROWS`].
const BATCH_BYTES: usize = 1 << 20;

/// Rows of the `messages` table handed from the thread that steps SQLite to the one that
/// decodes: each row's id, topic id and timestamp, and where its (decompressed) bytes end in
/// `bytes`.
#[derive(Default)]
struct Batch {
    rows: Vec<(i64, i64, i64, usize)>,
    bytes: Vec<u8>,
}

/// The reading side of [`scan`]: what it needs to read the rows and to locate an error.
struct Reader<'a> {
    file: &'a str,
    cut: &'a str,
    /// Topic names by topic id, for errors.
    named: HashMap<i64, String>,
    message_compressed: bool,
}

impl Reader<'_> {
    /// Steps through the `messages` table in row order, sending full batches to `full` (and
    /// reusing those that come back on `emptied`); an error ends the batches. Returns when
    /// the table is read, on an error, or when the other side stops listening.
    fn send(
        &self,
        db: Connection,
        full: SyncSender<Result<Batch, InputError>>,
        emptied: Receiver<Batch>,
    ) {
        let mut batch = Batch::default();
        let result = self.fill(
            &db,
            &mut |b| {
                let next = emptied.try_recv().unwrap_or_default();
                full.send(Ok(std::mem::replace(b, next))).is_ok()
            },
            &mut batch,
        );
        let last = match result {
            Ok(()) => Ok(batch),
            Err(e) => Err(e),
        };
        // The other side may have stopped (Ctrl-C, or an error of its own): nobody to tell.
        full.send(last).ok();
    }

    /// Reads every row into `batch`, calling `hand_over` on each full batch (which swaps in
    /// an empty one, and says whether to go on).
    fn fill(
        &self,
        db: &Connection,
        hand_over: &mut dyn FnMut(&mut Batch) -> bool,
        batch: &mut Batch,
    ) -> Result<(), InputError> {
        let at = |place: String, message: String| InputError::In {
            file: self.file.to_owned(),
            place,
            message,
        };
        let damaged = |e: rusqlite::Error| InputError::Format {
            file: self.file.to_owned(),
            message: format!(
                "SQLite cannot read table messages: {e}{}{}",
                check(db),
                self.cut
            ),
        };
        let mut statement = db
            .prepare("SELECT id, topic_id, timestamp, data FROM messages ORDER BY id")
            .map_err(damaged)?;
        let mut query = statement.query([]).map_err(damaged)?;
        let mut last_id: Option<i64> = None;
        let mut read_rows = 0u64;
        let mut unpacked = Vec::new();
        let mut decompressor = if self.message_compressed {
            Some(
                zstd::bulk::Decompressor::new().map_err(|e| InputError::Format {
                    file: self.file.to_owned(),
                    message: format!("zstd cannot start: {e}"),
                })?,
            )
        } else {
            None
        };
        loop {
            let row = match query.next() {
                Ok(Some(row)) => row,
                Ok(None) => return Ok(()),
                Err(e) => {
                    let after = match last_id {
                        Some(id) => format!("after row id {id} ({read_rows} messages read)"),
                        None => "before its first row".to_owned(),
                    };
                    return Err(at(
                        format!("table messages, {after}"),
                        format!("{e}{}{}", check(db), self.cut),
                    ));
                }
            };
            let (id, topic_id, timestamp, data) = row_fields(row).map_err(|e| {
                at(
                    format!("table messages, row after id {}", last_id.unwrap_or(0)),
                    format!("{e} (rosbag2 writes integer id, topic_id and timestamp, and a blob)"),
                )
            })?;
            last_id = Some(id);
            read_rows += 1;
            let bytes = match &mut decompressor {
                Some(d) => unzstd(d, data, &mut unpacked).map_err(|e| {
                    at(
                        format!(
                            "table messages, row id {id}{}",
                            self.named
                                .get(&topic_id)
                                .map_or(String::new(), |t| format!(" (topic {t})"))
                        ),
                        e,
                    )
                })?,
                None => data,
            };
            batch.bytes.extend_from_slice(bytes);
            batch
                .rows
                .push((id, topic_id, timestamp, batch.bytes.len()));
            if (batch.rows.len() >= BATCH_ROWS || batch.bytes.len() >= BATCH_BYTES)
                && !hand_over(batch)
            {
                return Ok(());
            }
        }
    }
}

/// The decoding side of [`scan`]: each batch's rows into `collector`, in order, the emptied
/// batches back to `empty`. Returns at the last batch, at the first error (the reader's or
/// the collector's), or on Ctrl-C; dropping `filled` then stops the reader.
fn collect(
    filled: Receiver<Result<Batch, InputError>>,
    empty: Sender<Batch>,
    streams: &HashMap<i64, (Stream, Codec)>,
    file: &str,
    total: u64,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let mut read_rows = 0u64;
    // The reader sends its last batch (or its error) and ends, closing the channel; it closes
    // early only if it panics, which `scan` passes on.
    while let Ok(batch) = filled.recv() {
        let mut batch = batch?;
        let mut start = 0;
        for &(id, topic_id, timestamp, end) in &batch.rows {
            read_rows += 1;
            if collector.stop() {
                return Ok(());
            }
            let stream = streams.get(&topic_id);
            collector
                .message_on(
                    stream.map(|s| &s.0),
                    "topic id",
                    u64::try_from(topic_id).unwrap_or(0),
                    u64::try_from(timestamp).unwrap_or(0),
                    &batch.bytes[start..end],
                    stream.map_or(Codec::Cdr, |s| s.1),
                )
                .map_err(|e| InputError::In {
                    file: file.to_owned(),
                    place: format!(
                        "table messages, row id {id}{}",
                        stream.map_or(String::new(), |s| format!(" (topic {})", s.0.topic))
                    ),
                    message: e,
                })?;
            start = end;
            if read_rows.is_multiple_of(4096) {
                progress(u64::try_from(id).unwrap_or(0).min(total), total);
            }
        }
        batch.rows.clear();
        batch.bytes.clear();
        empty.send(batch).ok();
    }
    progress(total, total);
    Ok(())
}

/// A `messages` row: id, topic id, timestamp and the data's bytes (borrowed, not copied).
fn row_fields<'r>(row: &'r rusqlite::Row<'_>) -> rusqlite::Result<(i64, i64, i64, &'r [u8])> {
    Ok((
        row.get(0)?,
        row.get(1)?,
        row.get(2)?,
        row.get_ref(3)?.as_blob()?,
    ))
}

/// Refuses a file that is not SQLite before SQLite opens it (SQLite's own words, "file is not
/// a database", name neither the file nor what it is). Returns words for a later error when
/// the file is shorter than its header says (SQLite file format: page size at byte 16, the
/// database's pages at byte 28, both big-endian): a copy cut short.
fn check_magic(path: &Path) -> Result<String, InputError> {
    let mut head = Vec::with_capacity(32);
    let read = std::fs::File::open(path).and_then(|f| {
        let len = f.metadata()?.len();
        f.take(32).read_to_end(&mut head)?;
        Ok(len)
    });
    let len = read.map_err(|e| InputError::Read {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    check_header(&head, len, &path.display().to_string())
}

/// [`check_magic`] on the first bytes `head` (up to 32) of a database of `len` bytes named
/// `file`.
fn check_header(head: &[u8], len: u64, file: &str) -> Result<String, InputError> {
    if !head.starts_with(SQLITE_MAGIC) {
        let shown: String = String::from_utf8_lossy(&head[..head.len().min(16)])
            .chars()
            .map(|c| if c.is_control() { '·' } else { c })
            .collect();
        return Err(InputError::Format {
            file: file.to_owned(),
            message: format!(
                "not an SQLite database (a .db3 starts with \"SQLite format 3\", this file with {shown:?})"
            ),
        });
    }
    if head.len() < 32 {
        return Ok(format!(
            "; the file is cut short ({len} bytes, inside SQLite's header)"
        ));
    }
    let page = match u16::from_be_bytes([head[16], head[17]]) {
        1 => 65_536,
        p => u64::from(p),
    };
    let pages = u64::from(u32::from_be_bytes([head[28], head[29], head[30], head[31]]));
    Ok(if len < page * pages {
        format!(
            "; the file is cut short: {len} bytes, its header says {pages} pages of {page} bytes \
             ({} bytes)",
            page * pages
        )
    } else {
        String::new()
    })
}

/// Where a damaged file is damaged, as words appended to an error: the pages SQLite's page
/// statistics (`dbstat`) find corrupted, with their table (the first three), else the first
/// findings of `PRAGMA integrity_check`; empty when neither says more.
fn check(db: &Connection) -> String {
    let pages: rusqlite::Result<Vec<String>> = db
        .prepare("SELECT name, pageno FROM dbstat WHERE pagetype = 'corrupted' LIMIT 3")
        .and_then(|mut s| {
            s.query_map([], |r| {
                Ok(format!(
                    "page {} (table {})",
                    r.get::<_, i64>(1)?,
                    r.get::<_, String>(0)?
                ))
            })?
            .collect()
        });
    if let Ok(pages) = pages
        && !pages.is_empty()
    {
        return format!("; damaged: {}", pages.join(", "));
    }
    let found: rusqlite::Result<Vec<String>> = db
        .prepare("PRAGMA integrity_check(3)")
        .and_then(|mut s| s.query_map([], |r| r.get::<_, String>(0))?.collect());
    match found {
        Ok(found) if !found.is_empty() && found != ["ok"] => {
            format!("; SQLite's check of the file: {}", found.join("; "))
        }
        _ => String::new(),
    }
}

/// The names of the file's tables.
fn tables(db: &Connection) -> rusqlite::Result<Vec<String>> {
    let mut s = db.prepare("SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")?;
    s.query_map([], |r| r.get(0))?.collect()
}

/// The compression a lone `.db3` says in its `metadata` table (the last row: rosbag2 appends
/// one per update); `None` when the table is empty.
fn own_compression(
    db: &Connection,
    file: &str,
) -> rusqlite::Result<Result<Compression, InputError>> {
    let text: Option<String> = db
        .query_row(
            "SELECT metadata FROM metadata ORDER BY id DESC LIMIT 1",
            [],
            |r| r.get(0),
        )
        .map(Some)
        .or_else(|e| match e {
            rusqlite::Error::QueryReturnedNoRows => Ok(None),
            e => Err(e),
        })?;
    Ok(match text {
        Some(text) => parse_metadata(&text, &format!("{file}: table metadata"))
            .map(|m| m.compression)
            .or_else(|e| match e {
                // A metadata row that is not rosbag2's whole mapping says nothing about
                // compression; a compression it does name wrongly is an error.
                InputError::Format { .. } => Ok(Compression::None),
                e => Err(e),
            }),
        None => Ok(Compression::None),
    })
}

/// The topics by id: each as a stream, with the codec of its serialization format.
fn topics(db: &Connection) -> rusqlite::Result<HashMap<i64, (Stream, Codec)>> {
    let mut s = db.prepare("SELECT id, name, type, serialization_format FROM topics")?;
    let rows = s.query_map([], |r| {
        Ok((
            r.get::<_, i64>(0)?,
            r.get::<_, String>(1)?,
            r.get::<_, String>(2)?,
            r.get::<_, String>(3)?,
        ))
    })?;
    let mut out = HashMap::new();
    for row in rows {
        let (id, topic, type_name, serialization) = row?;
        let why = format!("{type_name} in {serialization} serialization; posecov reads cdr");
        let (stream, codec) = Stream::of_channel(topic, type_name, &serialization, || why.clone());
        out.insert(id, (stream, codec));
    }
    Ok(out)
}

/// One message's bytes, a zstd frame (rosbag2's `message` compression), decompressed into
/// `out`: in one call when the frame says its size (at most [`RECORD_LIMIT`]), else streamed
/// through that limit.
fn unzstd<'a>(
    d: &mut zstd::bulk::Decompressor<'_>,
    frame: &[u8],
    out: &'a mut Vec<u8>,
) -> Result<&'a [u8], String> {
    let fail = |e: std::io::Error| format!("the zstd-compressed message does not decompress: {e}");
    out.clear();
    match zstd::zstd_safe::get_frame_content_size(frame) {
        Ok(Some(size)) if size <= RECORD_LIMIT as u64 => {
            out.reserve_exact(size as usize);
            d.decompress_to_buffer(frame, out).map_err(fail)?;
        }
        Ok(_) => {
            zstd::stream::read::Decoder::new(frame)
                .and_then(|r| r.take(RECORD_LIMIT as u64).read_to_end(out))
                .map_err(fail)?;
        }
        Err(_) => {
            return Err(
                "the bag's metadata says zstd message compression, but this message is not a \
                 zstd frame"
                    .to_owned(),
            );
        }
    }
    Ok(out)
}
