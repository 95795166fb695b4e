//! MCAP files (ROS 2) through the `mcap` crate's sans-I/O linear reader: the file is read in
//! bounded pieces, and each chunk is decompressed here, once (zstd, lz4), so memory stays
//! bounded by one chunk whatever the file's length. Messages are CDR
//! (`message_encoding = "cdr"`), decoded in `decode` with `re_cdr`, or ROS 1 serialization
//! (`ros1`, as `mcap convert` writes a ROS 1 bag), decoded as a ROS 1 bag's are.
//!
//! Every read is bounded by the file's size: a record longer than what is left of the file
//! is refused where it starts, a chunk must decompress to exactly the size its header gives
//! (read through a limit of that size), and each record inside a chunk moves the reading on
//! by at least its 9-byte opcode and length. A damaged log therefore ends with a located
//! error in one pass over its bytes. (The crate's own chunk decompression can loop without
//! end on a falsified chunk header; it is not used.)

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::mcap_records::{ChunkHeader, McapRecord, parse};
use super::{Codec, Collector, RECORD_LIMIT, Stream};
use crate::input::InputError;

/// At most this many bytes are read from the file at a time.
const READ_PIECE: usize = 1 << 20;
/// An opcode (1 byte) and a record length (8 bytes).
const OPCODE_LEN: usize = 9;

/// Streams every message of the file into `collector`.
pub(super) fn read(
    path: &Path,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let io = |source: std::io::Error| InputError::Read {
        path: path.display().to_string(),
        reason: source.to_string(),
    };
    let fail = |what: String| InputError::Format {
        file: path.display().to_string(),
        message: what,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let total = file.metadata().map_err(io)?.len();
    let limit = RECORD_LIMIT.min(usize::try_from(total).unwrap_or(RECORD_LIMIT));
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_record_length_limit(limit)
            .with_emit_chunks(true),
    );
    let mut streams = Streams::default();
    // One buffer for every chunk's records, decompressed (its capacity kept from chunk to
    // chunk: no allocation, copy or fresh pages per chunk).
    let mut chunk = Vec::new();
    let mut done = 0u64;
    let mut last_report = 0u64;
    while let Some(event) = reader.next_event() {
        let event =
            event.map_err(|e| fail(format!("at byte {done}: {}", reader_error(&e, total))))?;
        match event {
            LinearReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need.min(READ_PIECE));
                let n = file.read(buf).map_err(io)?;
                reader.notify_read(n);
                done += n as u64;
                if done - last_report >= 4 * READ_PIECE as u64 || n == 0 {
                    progress(done, total);
                    last_report = done;
                }
            }
            LinearReadEvent::Record { data, opcode } => {
                let at = |e: String| fail(format!("record 0x{opcode:02x} near byte {done}: {e}"));
                let flow = match parse(opcode, data).map_err(at)? {
                    McapRecord::Chunk { header, records } => {
                        let records = decompress(&header, records, &mut chunk).map_err(at)?;
                        chunk_records(records, |opcode, body| {
                            let inner = parse(opcode, body)
                                .map_err(|e| format!("record 0x{opcode:02x} in this chunk: {e}"))?;
                            streams.take(inner, collector)
                        })
                        .map_err(at)?
                    }
                    other => streams.take(other, collector).map_err(at)?,
                };
                if flow == Flow::Stop {
                    return Ok(());
                }
            }
        }
    }
    progress(total, total);
    Ok(())
}

/// The linear reader's error in the user's words: a record longer than the whole file means
/// the file was cut short (a copy that did not finish) or damaged.
fn reader_error(e: &mcap::McapError, total: u64) -> String {
    match e {
        mcap::McapError::RecordTooLarge { opcode, len } if *len > total => format!(
            "a record (opcode 0x{opcode:02x}) claims {len} bytes, more than the whole file \
             ({total} bytes): the file is cut short (a copy that did not finish?) or damaged"
        ),
        other => other.to_string(),
    }
}

/// Whether to read on (the collector may ask to stop: Ctrl-C).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Flow {
    Continue,
    Stop,
}

/// The schemas and channels declared so far.
#[derive(Default)]
struct Streams {
    schemas: HashMap<u16, (String, String)>,
    /// By channel id (a `u16`): an index, not a hash, per message; with its encoding.
    channels: Vec<Option<(Stream, Codec)>>,
}

impl Streams {
    /// Takes one record of the data section (outside a chunk or inside one).
    fn take(
        &mut self,
        record: McapRecord<'_>,
        collector: &mut Collector<'_, '_>,
    ) -> Result<Flow, String> {
        match record {
            McapRecord::Schema { id, name, encoding } => {
                self.schemas.insert(id, (name, encoding));
            }
            McapRecord::Channel {
                id,
                schema_id,
                topic,
                message_encoding,
            } => {
                let (schema, encoding) = self.schemas.get(&schema_id).cloned().unwrap_or_default();
                let other = || {
                    format!(
                        "{schema} in {message_encoding} encoding (schema {encoding}); posecov reads cdr or ros1"
                    )
                };
                let (stream, codec) =
                    Stream::of_channel(topic, schema.clone(), &message_encoding, other);
                collector.declare_stream(&stream);
                let at = usize::from(id);
                if self.channels.len() <= at {
                    self.channels.resize_with(at + 1, || None);
                }
                self.channels[at] = Some((stream, codec));
            }
            McapRecord::Message {
                channel_id,
                log_time,
                data,
            } => {
                if collector.stop() {
                    return Ok(Flow::Stop);
                }
                let channel = self
                    .channels
                    .get(usize::from(channel_id))
                    .and_then(Option::as_ref);
                collector.message_on(
                    channel.map(|c| &c.0),
                    "channel",
                    channel_id.into(),
                    log_time,
                    data,
                    channel.map_or(Codec::Cdr, |c| c.1),
                )?;
            }
            McapRecord::Chunk { .. } => return Err("a chunk inside a chunk".to_owned()),
            McapRecord::Other => {}
        }
        Ok(Flow::Continue)
    }
}

/// A chunk's records, decompressed into `out` (its contents replaced; an uncompressed chunk is
/// its own records, not copied): exactly the `uncompressed_size` its header gives (at most
/// [`RECORD_LIMIT`]), read through a limit of that size, so a falsified header ends here.
fn decompress<'a>(
    header: &ChunkHeader,
    compressed: &'a [u8],
    out: &'a mut Vec<u8>,
) -> Result<&'a [u8], String> {
    let size = usize::try_from(header.uncompressed_size)
        .ok()
        .filter(|&s| s <= RECORD_LIMIT)
        .ok_or_else(|| {
            format!(
                "a chunk of {} bytes uncompressed is larger than the {} MiB posecov reads",
                header.uncompressed_size,
                RECORD_LIMIT >> 20
            )
        })?;
    // One byte more than expected is read, to tell "too long" from "exactly right".
    let bound = header.uncompressed_size.saturating_add(1);
    out.clear();
    let read = match header.compression.as_str() {
        "" => Ok(0),
        // In one call straight into `out` (room for one byte more than expected); a chunk
        // that does not fit or does not decode is read again through the limit below, which
        // says how it is wrong.
        "zstd" => zstd_in_one(compressed, bound, out).or_else(|_| {
            out.clear();
            zstd::stream::read::Decoder::new(compressed)
                .and_then(|d| d.take(bound).read_to_end(out))
        }),
        "lz4" => lz4::Decoder::new(compressed).and_then(|d| d.take(bound).read_to_end(out)),
        other => {
            return Err(format!(
                "chunk compression {other:?}: posecov reads zstd, lz4 or none"
            ));
        }
    };
    read.map_err(|e| format!("the {} chunk does not decompress: {e}", header.compression))?;
    let records: &[u8] = if header.compression.is_empty() {
        compressed
    } else {
        out
    };
    if records.len() != size {
        return Err(format!(
            "the chunk decompresses to {}{} bytes, its header says {size}",
            records.len().min(size.saturating_add(1)),
            if records.len() > size { " or more" } else { "" },
        ));
    }
    Ok(records)
}

/// A zstd chunk decompressed in one call into `out`'s room for `bound` bytes (the streaming
/// decoder copied each block through its window and zeroed `out` first: a tenth of a long
/// log's read).
/// Only up to [`ONE_CALL_LIMIT`] bytes: the room is taken before a byte is read, and a
/// falsified header must not take a gigabyte.
fn zstd_in_one(compressed: &[u8], bound: u64, out: &mut Vec<u8>) -> std::io::Result<usize> {
    let room = usize::try_from(bound)
        .ok()
        .filter(|&b| b <= ONE_CALL_LIMIT)
        .ok_or_else(|| std::io::Error::other("a chunk this large is streamed"))?;
    out.reserve_exact(room);
    zstd::bulk::Decompressor::new()?.decompress_to_buffer(compressed, out)
}

/// The largest chunk [`zstd_in_one`] decompresses (MCAP writers' chunks are a few MiB).
const ONE_CALL_LIMIT: usize = 64 << 20;

/// Calls `take` with each record (opcode, body) of a decompressed chunk, in order; every
/// record moves on by its opcode and length, and a length past the chunk's end is refused.
fn chunk_records(
    mut records: &[u8],
    mut take: impl FnMut(u8, &[u8]) -> Result<Flow, String>,
) -> Result<Flow, String> {
    while !records.is_empty() {
        let Some((head, rest)) = records.split_first_chunk::<OPCODE_LEN>() else {
            return Err(format!(
                "the chunk ends inside a record header ({} bytes left)",
                records.len()
            ));
        };
        let opcode = head[0];
        let len = u64::from_le_bytes(head[1..].try_into().unwrap_or_default());
        let body = usize::try_from(len)
            .ok()
            .and_then(|l| rest.get(..l))
            .ok_or_else(|| {
                format!(
                    "record 0x{opcode:02x} of {len} bytes runs past the chunk's end ({} bytes left)",
                    rest.len()
                )
            })?;
        if take(opcode, body)? == Flow::Stop {
            return Ok(Flow::Stop);
        }
        records = &rest[body.len()..];
    }
    Ok(Flow::Continue)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(compression: &str, compressed: usize, uncompressed: u64) -> ChunkHeader {
        ChunkHeader {
            uncompressed_size: uncompressed,
            compression: compression.to_owned(),
            compressed_size: compressed as u64,
        }
    }

    #[test]
    fn a_falsified_uncompressed_size_is_refused_at_once() {
        let records = [0x0f, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        let zstd = zstd::bulk::compress(&records, 3).unwrap();
        let mut out = Vec::new();
        let good = decompress(
            &header("zstd", zstd.len(), records.len() as u64),
            &zstd,
            &mut out,
        )
        .unwrap();
        assert_eq!(good, records);
        for wrong in [0, 5, records.len() as u64 + 1, 1 << 29, u64::MAX] {
            let e = decompress(&header("zstd", zstd.len(), wrong), &zstd, &mut out).unwrap_err();
            assert!(
                e.contains("header says") || e.contains("larger than"),
                "{wrong}: {e}"
            );
        }
        let e = decompress(&header("bz2", 3, 3), b"abc", &mut out).unwrap_err();
        assert!(e.contains("\"bz2\""), "{e}");
    }

    #[test]
    fn a_record_length_past_the_chunk_is_refused() {
        let mut seen = 0;
        let ok = [0x0f, 1, 0, 0, 0, 0, 0, 0, 0, 7];
        chunk_records(&ok, |o, b| {
            seen += 1;
            assert_eq!((o, b), (0x0f, &[7u8][..]));
            Ok(Flow::Continue)
        })
        .unwrap();
        assert_eq!(seen, 1);
        let long = [0x0f, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 7];
        let e = chunk_records(&long, |_, _| Ok(Flow::Continue)).unwrap_err();
        assert!(e.contains("runs past the chunk's end"), "{e}");
        let e = chunk_records(&ok[..5], |_, _| Ok(Flow::Continue)).unwrap_err();
        assert!(e.contains("inside a record header"), "{e}");
    }
}
