//! MCAP files (ROS 2) through the `mcap` crate's sans-I/O linear reader: the file is read in
//! bounded pieces and each chunk decompressed once (zstd, lz4), so memory stays bounded by one
//! chunk whatever the file's length. Messages are CDR (`message_encoding = "cdr"`), decoded
//! in `decode` with `re_cdr`.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::decode::ros2_kind;
use super::{Codec, Collector, Stream};
use crate::input::InputError;

/// The largest record (or decompressed chunk) read: larger ones are refused, not allocated.
pub const RECORD_LIMIT: usize = 1 << 30;
/// At most this many bytes are read from the file at a time.
const READ_PIECE: usize = 1 << 20;

/// Streams every message of the file into `collector`.
pub(super) fn read(
    path: &Path,
    collector: &mut Collector<'_>,
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
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(RECORD_LIMIT),
    );
    let mut schemas: HashMap<u16, (String, String)> = HashMap::new();
    let mut channels: HashMap<u16, Stream> = HashMap::new();
    let mut done = 0u64;
    let mut last_report = 0u64;
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| fail(format!("at byte {done}: {e}")))?;
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
                let record = mcap::parse_record(opcode, data)
                    .map_err(|e| fail(format!("record 0x{opcode:02x} near byte {done}: {e}")))?;
                match record {
                    Record::Schema { header, .. } => {
                        schemas.insert(header.id, (header.name, header.encoding));
                    }
                    Record::Channel(c) => {
                        let (schema, encoding) =
                            schemas.get(&c.schema_id).cloned().unwrap_or_default();
                        let kind = ros2_kind(&schema).map(|k| {
                            if c.message_encoding == "cdr" {
                                Ok(k)
                            } else {
                                Err(format!(
                                    "{schema} in {} encoding (schema {encoding}); posecov reads cdr",
                                    c.message_encoding
                                ))
                            }
                        });
                        let type_name = if schema.is_empty() {
                            format!("(no schema, {} encoding)", c.message_encoding)
                        } else {
                            schema
                        };
                        collector.declare(&c.topic, &type_name, kind.as_ref());
                        channels.insert(
                            c.id,
                            Stream {
                                topic: c.topic,
                                type_name,
                                kind,
                            },
                        );
                    }
                    Record::Message { header, data } => {
                        if collector.stop() {
                            return Ok(());
                        }
                        let id = header.channel_id;
                        collector
                            .message_on(
                                channels.get(&id),
                                "channel",
                                id.into(),
                                header.log_time,
                                &data,
                                Codec::Cdr,
                            )
                            .map_err(fail)?;
                    }
                    _ => {}
                }
            }
        }
    }
    progress(total, total);
    Ok(())
}
