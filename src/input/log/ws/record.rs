//! `--record run.mcap`: every message received on the subscribed channels written as it
//! arrives, each channel with its schema, encoding and the server's log time, so that the
//! file reads back (`posecov report run.mcap`) as the live run read it. A channel advertised
//! again after a lost connection (a new id, the same topic, encoding and schema) is the same
//! channel of the file.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use super::protocol::Channel;

/// A channel as the file knows it: topic, message encoding, schema name.
type ChannelKey = (String, String, String);

/// An MCAP file being written.
pub(super) struct Recorder {
    path: PathBuf,
    writer: mcap::Writer<BufWriter<File>>,
    /// Every channel written → the file's channel id.
    written: BTreeMap<ChannelKey, u16>,
    /// This connection's channel ids → the file's channel id.
    channels: BTreeMap<u64, u16>,
    sequence: u32,
}

impl Recorder {
    /// Creates the file.
    pub(super) fn create(path: &Path) -> Result<Self, String> {
        let fail = |e: String| format!("--record {}: cannot create it ({e})", path.display());
        let file = File::create(path).map_err(|e| fail(e.to_string()))?;
        let writer = mcap::Writer::new(BufWriter::new(file)).map_err(|e| fail(e.to_string()))?;
        Ok(Self {
            path: path.to_owned(),
            writer,
            written: BTreeMap::new(),
            channels: BTreeMap::new(),
            sequence: 0,
        })
    }

    fn fail(&self, e: &mcap::McapError) -> String {
        format!("--record {}: cannot write it ({e})", self.path.display())
    }

    /// The connection was made again: the server's channel ids start afresh.
    pub(super) fn reconnected(&mut self) {
        self.channels.clear();
    }

    /// A channel the server advertises, written once.
    pub(super) fn channel(&mut self, channel: &Channel) -> Result<(), String> {
        let key = (
            channel.topic.clone(),
            channel.encoding.clone(),
            channel.schema_name.clone(),
        );
        if let Some(&id) = self.written.get(&key) {
            self.channels.insert(channel.id, id);
            return Ok(());
        }
        let encoding =
            channel
                .schema_encoding
                .clone()
                .unwrap_or_else(|| match channel.encoding.as_str() {
                    "ros1" => "ros1msg".to_owned(),
                    _ => "ros2msg".to_owned(),
                });
        let schema = self
            .writer
            .add_schema(&channel.schema_name, &encoding, channel.schema.as_bytes())
            .map_err(|e| self.fail(&e))?;
        let id = self
            .writer
            .add_channel(schema, &channel.topic, &channel.encoding, &BTreeMap::new())
            .map_err(|e| self.fail(&e))?;
        self.written.insert(key, id);
        self.channels.insert(channel.id, id);
        Ok(())
    }

    /// One message on server channel `channel`.
    pub(super) fn message(
        &mut self,
        channel: u64,
        log_time_ns: u64,
        bytes: &[u8],
    ) -> Result<(), String> {
        let Some(&channel_id) = self.channels.get(&channel) else {
            return Ok(());
        };
        self.sequence = self.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: self.sequence,
            log_time: log_time_ns,
            publish_time: log_time_ns,
        };
        self.writer
            .write_to_known_channel(&header, bytes)
            .map_err(|e| self.fail(&e))
    }

    /// Writes the summary and closes the file: a complete MCAP.
    pub(super) fn finish(mut self) -> Result<(), String> {
        self.writer.finish().map_err(|e| self.fail(&e))?;
        Ok(())
    }
}
