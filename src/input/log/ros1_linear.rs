//! ROS 1 bags without a usable index, read as `rosbag reindex` does: chunk by chunk from the
//! start of the file, until its end or the first record that runs past it (a copy cut short
//! inside a chunk) or is damaged. Every whole chunk before that is read and handed on like an
//! indexed bag's; where and why the read stopped is kept in the plan ([`LogCut`]), said in the
//! text panel, in `report --json` and by `check`.
//!
//! A bag's index lies at its end, so a bag cut anywhere, or whose recording was interrupted
//! (`index_pos = 0`), has none: without this read, everything in it would be lost. Records are
//! read one at a time (memory stays bounded by one chunk, itself bounded as an indexed bag's
//! chunks are).

use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::decode::ros1_kind;
use super::reference::ros1_reference_type;
use super::{Codec, Collector, MAX_CHUNK_RATIO, RECORD_LIMIT, Stream};
use crate::input::InputError;
use crate::plan::log::LogCut;

/// Record opcodes of the bag format 2.0.
const OP_MESSAGE: u8 = 0x02;
const OP_INDEX_DATA: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// The fields of a record header (`len` `name=value` pairs), or why they do not parse.
pub(super) fn fields(header: &[u8]) -> Result<Vec<(&str, &[u8])>, String> {
    let mut out = Vec::new();
    let mut rest = header;
    while !rest.is_empty() {
        let len = rest
            .get(..4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]) as usize)
            .ok_or("a header field's length is cut")?;
        let field = rest
            .get(4..4 + len)
            .ok_or("a header field runs past the header")?;
        let eq = field
            .iter()
            .position(|b| *b == b'=')
            .ok_or("a header field without '='")?;
        let name = std::str::from_utf8(&field[..eq]).map_err(|_| "a header field's name")?;
        out.push((name, &field[eq + 1..]));
        rest = &rest[4 + len..];
    }
    Ok(out)
}

fn field<'a>(fields: &[(&str, &'a [u8])], name: &str) -> Option<&'a [u8]> {
    fields.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
}

fn u32_of(v: &[u8]) -> Option<u32> {
    Some(u32::from_le_bytes(v.try_into().ok()?))
}

/// One record of a byte slice (a decompressed chunk): opcode fields and data, and the rest.
type Record<'a> = (Vec<(&'a str, &'a [u8])>, &'a [u8]);

fn next_record<'a>(bytes: &mut &'a [u8]) -> Result<Record<'a>, String> {
    let take = |b: &mut &'a [u8], what: &str| -> Result<&'a [u8], String> {
        let len = b
            .get(..4)
            .and_then(u32_of)
            .ok_or_else(|| format!("{what}'s length is cut"))? as usize;
        let out = b
            .get(4..4 + len)
            .ok_or_else(|| format!("{what} runs past the end of the chunk"))?;
        *b = &b[4 + len..];
        Ok(out)
    };
    let header = take(bytes, "a record header")?;
    let data = take(bytes, "a record's data")?;
    Ok((fields(header)?, data))
}

fn op(fields: &[(&str, &[u8])]) -> Option<u8> {
    field(fields, "op").and_then(|v| v.first().copied())
}

/// A connection record: its id and stream (topic and type from its data, as the index gives).
fn connection(header: &[(&str, &[u8])], data: &[u8]) -> Result<(u32, Stream), String> {
    let id = field(header, "conn")
        .and_then(u32_of)
        .ok_or("a connection record without its id")?;
    let data = fields(data)?;
    let text = |name: &str| {
        field(&data, name)
            .or_else(|| field(header, name))
            .map(|v| String::from_utf8_lossy(v).into_owned())
            .unwrap_or_default()
    };
    let (topic, type_name, md5) = (text("topic"), text("type"), text("md5sum"));
    Ok((
        id,
        Stream {
            kind: ros1_kind(&type_name, &md5),
            reference: ros1_reference_type(&type_name, &md5),
            sensor: super::sensor::ros1_sensor(&type_name, &md5),
            topic,
            type_name,
        },
    ))
}

/// Decompresses a chunk's data (`none`, `lz4`, `bz2`) to `size` bytes, refusing a size its
/// data cannot hold (the rule of an indexed bag's chunks).
fn decompress(compression: &[u8], size: u64, data: &[u8]) -> Result<Vec<u8>, String> {
    let most = (MAX_CHUNK_RATIO * data.len() as u64 + (1 << 20)).min(RECORD_LIMIT as u64);
    if size > most {
        return Err(format!(
            "the header says {size} bytes uncompressed for {} bytes of data",
            data.len()
        ));
    }
    let mut out = Vec::with_capacity(size as usize);
    match compression {
        b"none" => out.extend_from_slice(data),
        b"lz4" => {
            let decoder = lz4::Decoder::new(data).map_err(|e| format!("lz4: {e}"))?;
            decoder
                .take(size + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("an lz4 chunk does not decompress ({e})"))?;
        }
        b"bz2" => {
            bzip2::read::BzDecoder::new(data)
                .take(size + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("a bz2 chunk does not decompress ({e})"))?;
        }
        other => {
            return Err(format!(
                "unknown chunk compression '{}'",
                String::from_utf8_lossy(other)
            ));
        }
    }
    if out.len() as u64 != size {
        return Err(format!(
            "it decompresses to {} bytes, its header says {size}",
            out.len()
        ));
    }
    Ok(out)
}

/// Reads the chunk section of the bag at `path` from `start` (the first record after the bag
/// header) to `end` (the index position when it lies inside the file, else the file's end),
/// handing every message of every whole chunk to `collector`. `why` says why the index is not
/// used. Where the read stopped, if before `end`, goes to the collector's `cut`.
pub(super) fn read(
    path: &Path,
    start: u64,
    end: u64,
    why: &str,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    collector.cut = read_chunks(path, start, end, why, collector, progress)?;
    Ok(())
}

fn read_chunks(
    path: &Path,
    start: u64,
    end: u64,
    why: &str,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Option<LogCut>, InputError> {
    let io = |source: std::io::Error| InputError::Read {
        path: path.display().to_string(),
        reason: source.to_string(),
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let file_bytes = file.metadata().map_err(io)?.len();
    let end = end.min(file_bytes);
    let mut conns: HashMap<u32, Stream> = HashMap::new();
    let mut at = start;
    let mut chunks_read = 0u64;
    let cut = |at: u64, chunks_read: u64, what: String| {
        Some(LogCut {
            reason: format!("{why}; {what}"),
            at_byte: at,
            file_bytes,
            chunks_read,
        })
    };
    while at < end {
        if collector.stop() {
            return Ok(None);
        }
        let record = read_record(&mut file, at, end).map_err(io)?;
        let (header, data, next) = match record {
            Ok(r) => r,
            Err(what) => return Ok(cut(at, chunks_read, format!("at byte {at}: {what}"))),
        };
        let header = match fields(&header) {
            Ok(h) => h,
            Err(what) => return Ok(cut(at, chunks_read, format!("at byte {at}: {what}"))),
        };
        let Some(data) = data else {
            let what = match op(&header) {
                Some(OP_CHUNK) => format!("chunk {}", chunks_read + 1),
                _ => "a record".to_owned(),
            };
            let what = format!(
                "{what} at byte {at} ({} bytes) runs past the end of the file ({end} bytes): the \
                 bag is cut short inside it",
                next - at
            );
            return Ok(cut(at, chunks_read, what));
        };
        match op(&header) {
            Some(OP_CHUNK) => {
                let n = chunks_read + 1;
                let size = field(&header, "size").and_then(u32_of);
                let compression = field(&header, "compression");
                let (Some(size), Some(compression)) = (size, compression) else {
                    let what = "its header lacks its size or compression".to_owned();
                    return Ok(cut(
                        at,
                        chunks_read,
                        format!("chunk {n} at byte {at}: {what}"),
                    ));
                };
                let bytes = match decompress(compression, u64::from(size), &data) {
                    Ok(b) => b,
                    Err(what) => {
                        return Ok(cut(
                            at,
                            chunks_read,
                            format!("chunk {n} at byte {at}: {what}"),
                        ));
                    }
                };
                if let Err(what) = chunk_messages(&bytes, &mut conns, collector) {
                    // The messages before the damage were handed on: the chunk counts as read.
                    let what = format!("chunk {n} at byte {at}: {what}");
                    return Ok(cut(next, n, what));
                }
                chunks_read = n;
            }
            Some(OP_CONNECTION) => {
                if let Ok((id, stream)) = connection(&header, &data) {
                    collector.declare_stream(&stream);
                    conns.entry(id).or_insert(stream);
                }
            }
            Some(OP_INDEX_DATA) => {}
            // The index section begins (an index that could not be used).
            Some(OP_CHUNK_INFO) => break,
            other => {
                let what = match other {
                    Some(op) => format!("a record of kind 0x{op:02x} among the chunks"),
                    None => "a record without its kind".to_owned(),
                };
                return Ok(cut(at, chunks_read, format!("at byte {at}: {what}")));
            }
        }
        at = next;
        progress(at.min(end), end);
    }
    Ok(None)
}

/// Hands every message of a decompressed chunk on (connections declared on the way).
fn chunk_messages(
    mut bytes: &[u8],
    conns: &mut HashMap<u32, Stream>,
    collector: &mut Collector<'_, '_>,
) -> Result<(), String> {
    while !bytes.is_empty() {
        let (header, data) = next_record(&mut bytes)?;
        match op(&header) {
            Some(OP_CONNECTION) => {
                let (id, stream) = connection(&header, data)?;
                collector.declare_stream(&stream);
                conns.entry(id).or_insert(stream);
            }
            Some(OP_MESSAGE) => {
                if collector.stop() {
                    return Ok(());
                }
                let id = field(&header, "conn")
                    .and_then(u32_of)
                    .ok_or("a message record without its connection")?;
                let time = field(&header, "time")
                    .filter(|v| v.len() == 8)
                    .ok_or("a message record without its time")?;
                let secs = u64::from(u32_of(&time[..4]).unwrap_or(0));
                let nsecs = u64::from(u32_of(&time[4..]).unwrap_or(0));
                let log_time = secs * 1_000_000_000 + nsecs;
                collector.message_on(
                    conns.get(&id),
                    "connection",
                    id.into(),
                    log_time,
                    data,
                    Codec::Ros1,
                )?;
            }
            Some(other) => {
                return Err(format!(
                    "an unexpected record of kind 0x{other:02x} inside a chunk"
                ));
            }
            None => return Err("a record without its kind inside a chunk".to_owned()),
        }
    }
    Ok(())
}

/// The record at `at`: its header bytes, its data (`None` when it runs past `end`: the file is
/// cut inside it) and where the next begins; `Err(what)` when not even its header is whole or
/// it claims more than [`RECORD_LIMIT`].
type FileRecord = Result<(Vec<u8>, Option<Vec<u8>>, u64), String>;

fn read_record(file: &mut std::fs::File, at: u64, end: u64) -> std::io::Result<FileRecord> {
    let mut bytes_at = |pos: u64, n: u64| -> std::io::Result<Option<Vec<u8>>> {
        if pos + n > end {
            return Ok(None);
        }
        let mut b = vec![0u8; n as usize];
        file.seek(SeekFrom::Start(pos))?;
        file.read_exact(&mut b)?;
        Ok(Some(b))
    };
    let cut = || {
        format!(
            "a record's header runs past the end of the file ({end} bytes): the bag is cut short"
        )
    };
    let len = |b: Vec<u8>| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let Some(header_len) = bytes_at(at, 4)?.map(len) else {
        return Ok(Err(cut()));
    };
    if header_len > 1 << 20 {
        return Ok(Err(format!(
            "a record header of {header_len} bytes: damaged"
        )));
    }
    let Some(header) = bytes_at(at + 4, header_len)? else {
        return Ok(Err(cut()));
    };
    let data_at = at + 8 + header_len;
    let Some(data_len) = bytes_at(data_at - 4, 4)?.map(len) else {
        return Ok(Err(cut()));
    };
    if data_len > RECORD_LIMIT as u64 {
        return Ok(Err(format!(
            "a record claims {data_len} bytes of data: damaged"
        )));
    }
    let next = data_at + data_len;
    Ok(Ok((header, bytes_at(data_at, data_len)?, next)))
}
