//! ROS 1 bags (format 2.0, wiki.ros.org/Bags/Format/2.0) through the `rosbag` crate: the
//! file is memory-mapped, the index gives every chunk's position, and chunks are decompressed
//! (uncompressed, bz2, lz4) a few per thread at a time, in parallel, their messages handed on
//! in file order: memory stays bounded by those few chunks whatever the bag's length.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use rayon::prelude::*;
use rosbag::record_types::Chunk;
use rosbag::{ChunkRecord, IndexRecord, MessageRecord, RosBag};

use super::decode::ros1_kind;
use super::{Codec, Collector, MAX_CHUNK_RATIO, RECORD_LIMIT, Stream, ros1_linear};
use crate::input::InputError;
use crate::input::format::ROSBAG_MAGIC as ROS1_MAGIC;

fn conn_of(c: &rosbag::record_types::Connection<'_>) -> Stream {
    let md5: String = c.md5sum.iter().map(|b| format!("{b:02x}")).collect();
    Stream {
        topic: c.topic.to_owned(),
        type_name: c.tp.to_owned(),
        kind: ros1_kind(c.tp, &md5),
        reference: super::reference::ros1_reference_type(c.tp, &md5),
        sensor: super::sensor::ros1_sensor(c.tp, &md5),
    }
}

/// Where a bag's chunks begin, and its index position if it can be used (`Err(why)`: a bag
/// whose recording was interrupted has `index_pos = 0`; a copy cut short has one beyond its
/// end; either is read linearly, [`super::ros1_linear`]).
struct Layout {
    chunks_start: u64,
    file_bytes: u64,
    index_pos: Result<u64, String>,
}

/// Checks the bag header before the crate maps it: the index position must lie inside the
/// file.
fn check_header(path: &Path) -> Result<Layout, InputError> {
    let err = |what: String| InputError::Format {
        file: path.display().to_string(),
        message: what,
    };
    let io = |source: std::io::Error| InputError::Read {
        path: path.display().to_string(),
        reason: source.to_string(),
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let mut head = vec![0u8; 4096];
    let mut n = 0;
    while n < head.len() {
        let k = file.read(&mut head[n..]).map_err(io)?;
        if k == 0 {
            break;
        }
        n += k;
    }
    let head = &head[..n];
    let rest = head
        .strip_prefix(ROS1_MAGIC)
        .ok_or_else(|| err("not a ROS 1 bag of format 2.0 (no '#ROSBAG V2.0' line)".into()))?;
    let u32_at = |b: &[u8], at: usize| -> Option<u32> {
        b.get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let header_len = u32_at(rest, 0).ok_or_else(|| err("truncated bag header".into()))? as usize;
    let header = rest
        .get(4..4 + header_len)
        .ok_or_else(|| err("truncated bag header".into()))?;
    let padding = u32_at(rest, 4 + header_len).ok_or_else(|| err("truncated bag header".into()))?;
    let chunks_start = (ROS1_MAGIC.len() + 8 + header_len) as u64 + u64::from(padding);
    let fields = ros1_linear::fields(header).map_err(|e| err(format!("the bag header: {e}")))?;
    let index_pos = fields
        .iter()
        .find(|(name, v)| *name == "index_pos" && v.len() == 8)
        .map(|(_, v)| u64::from_le_bytes(v[..8].try_into().unwrap_or([0; 8])))
        .ok_or_else(|| err("the bag header has no index_pos field".into()))?;
    let index_pos = match index_pos {
        0 => Err(
            "the bag has no index (index_pos = 0: its recording was interrupted; \
                   `rosbag reindex` would rebuild it)"
                .to_owned(),
        ),
        p if p > len || p < chunks_start => Err(format!(
            "the bag header puts its index at byte {p}, outside the file ({len} bytes): \
             the file is cut short (a copy that did not finish?) or damaged"
        )),
        p => Ok(p),
    };
    Ok(Layout {
        chunks_start,
        file_bytes: len,
        index_pos,
    })
}

/// Checks a chunk record's header before the crate reads it: the record lies inside the file,
/// and its uncompressed `size` is what its data can hold (equal to the data's length when
/// uncompressed; at most [`MAX_CHUNK_RATIO`] times it, plus 1 MiB, and at most
/// [`RECORD_LIMIT`] when compressed). The crate allocates `size` bytes up front: a falsified
/// size must not reach it.
fn check_chunk(file: &mut std::fs::File, pos: u64) -> Result<(), String> {
    use std::io::{Seek, SeekFrom};
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut read_at = |at: u64, n: usize| -> Result<Vec<u8>, String> {
        if at.saturating_add(n as u64) > len {
            return Err(format!(
                "the record runs past the end of the file ({len} bytes)"
            ));
        }
        let mut buf = vec![0u8; n];
        file.seek(SeekFrom::Start(at)).map_err(|e| e.to_string())?;
        file.read_exact(&mut buf).map_err(|e| e.to_string())?;
        Ok(buf)
    };
    let u32_of = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let header_len = u32_of(&read_at(pos, 4)?) as usize;
    if header_len > 4096 {
        return Err(format!("a chunk header of {header_len} bytes"));
    }
    let header = read_at(pos + 4, header_len)?;
    let data_len = u64::from(u32_of(&read_at(pos + 4 + header_len as u64, 4)?));
    if pos + 8 + header_len as u64 + data_len > len {
        return Err(format!(
            "its {data_len} bytes of data run past the end of the file ({len} bytes)"
        ));
    }
    let (mut size, mut compression) = (None, None);
    for (name, v) in ros1_linear::fields(&header)? {
        match name {
            "size" if v.len() == 4 => size = Some(u64::from(u32_of(v))),
            "compression" => compression = Some(String::from_utf8_lossy(v).into_owned()),
            _ => {}
        }
    }
    let (Some(size), Some(compression)) = (size, compression) else {
        return Err("the chunk header lacks its size or compression".to_owned());
    };
    let most = if compression == "none" {
        data_len
    } else {
        (MAX_CHUNK_RATIO * data_len + (1 << 20)).min(RECORD_LIMIT as u64)
    };
    if size > most || (compression == "none" && size != data_len) {
        return Err(format!(
            "the header says {size} bytes uncompressed ({compression}) for {data_len} bytes of data"
        ));
    }
    Ok(())
}

/// Streams every message of the bag into `collector`.
pub(super) fn read(
    path: &Path,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let layout = check_header(path)?;
    let start = layout.chunks_start;
    let index_pos = match &layout.index_pos {
        Ok(p) => *p,
        Err(why) => {
            return ros1_linear::read(path, start, layout.file_bytes, why, collector, progress);
        }
    };
    let fail = |what: String| InputError::Format {
        file: path.display().to_string(),
        message: what,
    };
    let bag = RosBag::new(path).map_err(|source| InputError::Read {
        path: path.display().to_string(),
        reason: source.to_string(),
    })?;
    // Connections from the index section (every topic and type up front), then any the
    // chunks declare themselves.
    let mut conns: HashMap<u32, Stream> = HashMap::new();
    let mut chunk_positions = Vec::new();
    for record in bag.index_records() {
        match record {
            Ok(IndexRecord::Connection(c)) => {
                let conn = conn_of(&c);
                collector.declare_stream(&conn);
                conns.insert(c.id, conn);
            }
            Ok(IndexRecord::ChunkInfo(info)) => chunk_positions.push(info.chunk_pos),
            Ok(_) => {}
            Err(e) => {
                let why = format!("its index section is damaged ({})", words(&e));
                return ros1_linear::read(path, start, index_pos, &why, collector, progress);
            }
        }
    }
    if chunk_positions.is_empty() {
        let why = "its index lists no chunks (an unindexed or empty bag)".to_owned();
        return ros1_linear::read(path, start, index_pos, &why, collector, progress);
    }
    chunk_positions.sort_unstable();
    chunk_positions.dedup();
    let mut file = std::fs::File::open(path).map_err(|source| InputError::Read {
        path: path.display().to_string(),
        reason: source.to_string(),
    })?;
    for (k, &pos) in chunk_positions.iter().enumerate() {
        check_chunk(&mut file, pos).map_err(|e| {
            fail(format!(
                "chunk {} of {} at byte {pos}: {e}",
                k + 1,
                chunk_positions.len()
            ))
        })?;
    }
    let total = chunk_positions.len() as u64;
    // Chunks are decompressed in parallel, a few per thread at a time (memory stays bounded
    // by that many chunks), and their messages handed on in file order.
    let batch = 2 * rayon::current_num_threads().max(1);
    let mut done = 0u64;
    for group in chunk_positions.chunks(batch) {
        if collector.stop() {
            return Ok(());
        }
        let chunks: Vec<Result<Chunk<'_>, String>> = group
            .par_iter()
            .map(|&pos| {
                let mut records = bag.chunk_records();
                records
                    .seek(pos)
                    .map_err(|e| format!("at byte {pos}: {}", words(&e)))?;
                match records.next() {
                    Some(Ok(ChunkRecord::Chunk(chunk))) => Ok(chunk),
                    Some(Ok(_)) => Err(format!("at byte {pos}: the index points at no chunk")),
                    Some(Err(e)) => Err(format!("at byte {pos}: {}", words(&e))),
                    None => Err(format!("at byte {pos}: past the end of the chunks")),
                }
            })
            .collect();
        for chunk in chunks {
            done += 1;
            let chunk = chunk.map_err(|e| fail(format!("chunk {done} of {total}: {e}")))?;
            for message in chunk.messages() {
                match message {
                    Ok(MessageRecord::Connection(c)) => {
                        conns.entry(c.id).or_insert_with(|| conn_of(&c));
                    }
                    Ok(MessageRecord::MessageData(m)) => {
                        if collector.stop() {
                            return Ok(());
                        }
                        let id = m.conn_id;
                        collector
                            .message_on(
                                conns.get(&id),
                                "connection",
                                id.into(),
                                m.time,
                                m.data,
                                Codec::Ros1,
                            )
                            .map_err(|e| fail(format!("chunk {done} of {total}: {e}")))?;
                    }
                    Err(e) => {
                        return Err(fail(format!("chunk {done} of {total}: {}", words(&e))));
                    }
                }
            }
            progress(done, total);
        }
    }
    Ok(())
}

/// A `rosbag` error in the user's words (the crate's own text starts with its Rust type name).
///
/// Only the bag's own records are named: a damaged header, a record that runs past the end
/// of the file, a compressed chunk that does not decompress.
fn words(e: &rosbag::Error) -> String {
    use rosbag::Error as E;
    match e {
        E::InvalidHeader => "a record header is damaged (a field length or name is invalid)".into(),
        E::InvalidRecord => "a record is damaged (its header does not match its kind)".into(),
        E::UnsupportedVersion => "not a ROS 1 bag of format version 2.0".into(),
        E::OutOfBounds => {
            "a record runs past the end of the file (the bag is truncated or damaged)".into()
        }
        E::UnexpectedChunkSectionRecord(kind) => {
            format!("an unexpected {kind} record among the chunks")
        }
        E::UnexpectedIndexSectionRecord(kind) => {
            format!("an unexpected {kind} record in the index section")
        }
        E::UnexpectedMessageRecord(kind) => {
            format!("an unexpected {kind} record inside a chunk")
        }
        E::Bzip2DecompressionError(why) => format!("a bz2 chunk does not decompress ({why})"),
        E::Lz4DecompressionError(why) => format!("an lz4 chunk does not decompress ({why})"),
    }
}
