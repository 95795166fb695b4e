//! The MCAP records posecov reads, parsed here with every length checked against the bytes
//! that hold it (the `mcap` crate's record parser allocates a length prefix's worth before it
//! reads: a falsified prefix inside a 6 kB file asked for 1.6 GB). Layouts from the MCAP
//! specification (mcap.dev/spec): little-endian integers, strings and byte arrays with a
//! `u32` length prefix, a map with a `u32` byte length.

/// A chunk's header: where its records are and how they are compressed.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct ChunkHeader {
    /// Size of the records once decompressed.
    pub uncompressed_size: u64,
    /// `""` (none), `"zstd"` or `"lz4"`.
    pub compression: String,
    /// Size of the compressed records.
    pub compressed_size: u64,
}

/// A record of the data section that posecov reads; everything else is `Other`.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum McapRecord<'a> {
    /// Opcode 0x03.
    Schema {
        id: u16,
        name: String,
        encoding: String,
    },
    /// Opcode 0x04.
    Channel {
        id: u16,
        schema_id: u16,
        topic: String,
        message_encoding: String,
    },
    /// Opcode 0x05.
    Message {
        channel_id: u16,
        log_time: u64,
        data: &'a [u8],
    },
    /// Opcode 0x06.
    Chunk {
        header: ChunkHeader,
        records: &'a [u8],
    },
    /// Any other opcode (header, footer, indexes, attachments, metadata, …).
    Other,
}

/// The opcode of a chunk.
const CHUNK: u8 = 0x06;

/// Reads fields off the front of a record's body, refusing any that run past it.
struct Fields<'a> {
    rest: &'a [u8],
}

impl<'a> Fields<'a> {
    fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], String> {
        let n = usize::try_from(n)
            .ok()
            .filter(|&n| n <= self.rest.len())
            .ok_or_else(|| {
                format!(
                    "{what} of {n} bytes runs past the record ({} bytes left)",
                    self.rest.len()
                )
            })?;
        let (head, rest) = self.rest.split_at(n);
        self.rest = rest;
        Ok(head)
    }
    fn u16(&mut self, what: &str) -> Result<u16, String> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let b = self.take(8, what)?;
        let mut w = [0u8; 8];
        w.copy_from_slice(b);
        Ok(u64::from_le_bytes(w))
    }
    fn bytes(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32(what)?;
        self.take(u64::from(n), what)
    }
    fn string(&mut self, what: &str) -> Result<String, String> {
        let b = self.bytes(what)?;
        String::from_utf8(b.to_vec()).map_err(|_| format!("{what} is not UTF-8"))
    }
}

/// Parses the body of a record with opcode `opcode`.
pub(super) fn parse(opcode: u8, body: &[u8]) -> Result<McapRecord<'_>, String> {
    let mut f = Fields { rest: body };
    Ok(match opcode {
        0x03 => McapRecord::Schema {
            id: f.u16("schema id")?,
            name: f.string("schema name")?,
            encoding: f.string("schema encoding")?,
        },
        0x04 => McapRecord::Channel {
            id: f.u16("channel id")?,
            schema_id: f.u16("schema id")?,
            topic: f.string("topic")?,
            message_encoding: f.string("message encoding")?,
        },
        0x05 => {
            let channel_id = f.u16("channel id")?;
            f.u32("sequence")?;
            let log_time = f.u64("log time")?;
            f.u64("publish time")?;
            McapRecord::Message {
                channel_id,
                log_time,
                data: f.rest,
            }
        }
        CHUNK => {
            f.u64("message start time")?;
            f.u64("message end time")?;
            let uncompressed_size = f.u64("uncompressed size")?;
            f.u32("uncompressed CRC")?;
            let compression = f.string("compression")?;
            let compressed_size = f.u64("compressed size")?;
            let records = f.take(compressed_size, "compressed records")?;
            McapRecord::Chunk {
                header: ChunkHeader {
                    uncompressed_size,
                    compression,
                    compressed_size,
                },
                records,
            }
        }
        _ => McapRecord::Other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn string(s: &str) -> Vec<u8> {
        let mut out = (s.len() as u32).to_le_bytes().to_vec();
        out.extend(s.as_bytes());
        out
    }

    #[test]
    fn a_length_prefix_past_the_record_is_refused_before_anything_is_allocated() {
        let mut schema = 7u16.to_le_bytes().to_vec();
        schema.extend(string("nav_msgs/msg/Odometry"));
        schema.extend(string("ros2msg"));
        schema.extend(string(""));
        assert_eq!(
            parse(0x03, &schema).unwrap(),
            McapRecord::Schema {
                id: 7,
                name: "nav_msgs/msg/Odometry".into(),
                encoding: "ros2msg".into()
            }
        );
        let mut falsified = 7u16.to_le_bytes().to_vec();
        falsified.extend(u32::MAX.to_le_bytes());
        let e = parse(0x03, &falsified).unwrap_err();
        assert!(
            e.contains("schema name of 4294967295 bytes runs past the record"),
            "{e}"
        );
        let mut message = 1u16.to_le_bytes().to_vec();
        message.extend(0u32.to_le_bytes());
        message.extend(5u64.to_le_bytes());
        message.extend(6u64.to_le_bytes());
        message.extend([1, 2, 3]);
        assert_eq!(
            parse(0x05, &message).unwrap(),
            McapRecord::Message {
                channel_id: 1,
                log_time: 5,
                data: &[1, 2, 3]
            }
        );
        assert!(parse(0x05, &message[..10]).is_err());
        assert_eq!(parse(0x0a, &[]).unwrap(), McapRecord::Other);
    }
}
