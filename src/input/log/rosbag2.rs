//! ROS 2 bag directories (rosbag2): a `metadata.yaml` naming its storage (`sqlite3` or
//! `mcap`), its compression and its files in order (a split bag's `_0`, `_1`, …), beside those
//! files. Each file is read in turn by its storage's reader (`sqlite.rs`, `mcap.rs`) into one
//! collector, so a split bag is one log. Compression (rosbag2 writes zstd only): `file` — each
//! file is one zstd stream (`bag_0.db3.zstd`), decompressed here first: an SQLite file whose
//! header says it fits (`IN_MEMORY_LIMIT`, 256 MiB) in one call straight into the buffer
//! SQLite reads in place, else (and an MCAP file) to a temporary file, as `ros2 bag` does;
//! `message` — every message's bytes are one zstd frame (`sqlite.rs`).
//!
//! The metadata's layout is rosbag2's (`rosbag2_storage/yaml.hpp`): versions 1 to 9 keep the
//! keys read here (`version`, `storage_identifier`, `relative_file_paths`, and from version 3
//! `compression_format` and `compression_mode`) under `rosbag2_bagfile_information`. The same
//! mapping without that key is what a `.db3` file keeps in its `metadata` table (SQLite
//! schema 3 and later), which is read for a lone `.db3`. Only those keys are read, by a reader
//! of the block YAML both rosbag2 (yaml-cpp) and rosbags (ruamel) write: other keys and their
//! nested values are skipped by indentation.

use std::io::Read as _;
use std::path::{Path, PathBuf};

use super::Collector;
use crate::input::InputError;
use crate::input::format::Format;

/// The metadata file of a bag directory.
pub const METADATA_FILE: &str = "metadata.yaml";

/// How a bag's messages are compressed (rosbag2 writes zstd only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// Not compressed.
    None,
    /// Each file is one zstd stream.
    File,
    /// Each message's bytes are one zstd frame.
    Message,
}

/// What posecov reads of a bag's metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct BagMetadata {
    /// `version` (Humble writes 5, Jazzy 9).
    pub version: u32,
    /// `storage_identifier`, as a [`Format`]: `sqlite3` or `mcap`.
    pub storage: Format,
    /// `relative_file_paths`, in order, each with its 1-based line in the metadata.
    pub files: Vec<(String, usize)>,
    /// `compression_mode` with `compression_format`.
    pub compression: Compression,
}

/// One `key: value` of the mapping read, and the block under it (sequence items).
struct Entry<'a> {
    key: &'a str,
    value: &'a str,
    line: usize,
    items: Vec<(&'a str, usize)>,
    /// The indentation of the first item (the items are those at it).
    item_indent: Option<usize>,
}

/// A line's content without a trailing comment (a `#` after a blank, outside quotes).
fn without_comment(line: &str) -> &str {
    let (mut single, mut double, mut prev_blank) = (false, false, true);
    for (i, c) in line.char_indices() {
        match c {
            '\'' if !double => single = !single,
            '"' if !single => double = !double,
            '#' if !single && !double && prev_blank => return line[..i].trim_end(),
            _ => {}
        }
        prev_blank = c == ' ' || c == '\t';
    }
    line.trim_end()
}

/// A scalar's text: quotes removed (`''` in single quotes, `\"` and `\\` in double quotes).
fn unquote(s: &str) -> String {
    let s = s.trim();
    if s.len() >= 2 && s.starts_with('\'') && s.ends_with('\'') {
        return s[1..s.len() - 1].replace("''", "'");
    }
    if s.len() >= 2 && s.starts_with('"') && s.ends_with('"') {
        return s[1..s.len() - 1]
            .replace("\\\"", "\"")
            .replace("\\\\", "\\");
    }
    s.to_owned()
}

/// The entries of the top mapping (under `rosbag2_bagfile_information` when the text has it),
/// with their lines.
fn entries(text: &str) -> Vec<Entry<'_>> {
    let lines: Vec<(usize, usize, &str)> = text
        .lines()
        .enumerate()
        .filter_map(|(i, raw)| {
            let content = without_comment(raw);
            let trimmed = content.trim_start();
            let indent = content.len() - trimmed.len();
            (!trimmed.is_empty() && !trimmed.starts_with("---")).then_some((i + 1, indent, trimmed))
        })
        .collect();
    let (body, base) = match lines.first() {
        Some((_, 0, first)) if first.trim_end() == "rosbag2_bagfile_information:" => {
            let body = &lines[1..];
            (body, body.first().map_or(0, |l| l.1))
        }
        _ => (&lines[..], lines.first().map_or(0, |l| l.1)),
    };
    let mut out: Vec<Entry<'_>> = Vec::new();
    for &(line, indent, content) in body {
        if indent == base && !content.starts_with("- ") && content != "-" {
            let (key, value) = content.split_once(':').unwrap_or((content, ""));
            out.push(Entry {
                key: key.trim(),
                value: value.trim(),
                line,
                items: Vec::new(),
                item_indent: None,
            });
        } else if let Some(last) = out.last_mut()
            && let Some(item) = content
                .strip_prefix("- ")
                .or((content == "-").then_some(""))
        {
            // Items of a block sequence under the last key (at its indentation or deeper);
            // the nested lines of an item that is a mapping are not items of their own.
            if *last.item_indent.get_or_insert(indent) == indent {
                last.items.push((item, line));
            }
        }
    }
    out
}

/// Reads the metadata text of a bag (`file` names it in errors: `metadata.yaml`, or a
/// `.db3`'s `metadata` table).
///
/// ```
/// use posecov::input::log::rosbag2::{parse_metadata, Compression};
/// use posecov::input::Format;
/// let m = parse_metadata(
///     "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n  \
///      relative_file_paths:\n  - run_0.db3\n  - run_1.db3\n  compression_format: zstd\n  \
///      compression_mode: FILE\n", "metadata.yaml").unwrap();
/// assert_eq!((m.version, m.storage, m.compression), (5, Format::Ros2Sqlite, Compression::File));
/// assert_eq!(m.files, [("run_0.db3".to_owned(), 5), ("run_1.db3".to_owned(), 6)]);
/// let e = parse_metadata("version: 9\nstorage_identifier: rosbag_v2\nrelative_file_paths: [a]\n", "m.yaml").unwrap_err();
/// assert!(e.to_string().starts_with("m.yaml: line 2, storage_identifier: \"rosbag_v2\""), "{e}");
/// ```
pub fn parse_metadata(text: &str, file: &str) -> Result<BagMetadata, InputError> {
    let entries = entries(text);
    // A log's metadata, located by line and key; an error in it is a log that cannot be
    // read (exit 2), as a damaged bag is, not a scenario's located error.
    let at = |e: &Entry<'_>, message: String| InputError::In {
        file: file.to_owned(),
        place: format!("line {}, {}", e.line, e.key),
        message,
    };
    let missing = |key: &str| InputError::Format {
        file: file.to_owned(),
        message: format!(
            "no `{key}`: not a rosbag2 metadata file (rosbag2 writes `rosbag2_bagfile_information:` \
             with `version`, `storage_identifier` and `relative_file_paths`)"
        ),
    };
    let get = |key: &str| entries.iter().find(|e| e.key == key);
    let version = get("version").ok_or_else(|| missing("version"))?;
    let version_number = unquote(version.value).parse::<u32>().map_err(|_| {
        at(
            version,
            format!(
                "{:?} is not a version number (rosbag2 writes 1 to 9)",
                version.value
            ),
        )
    })?;
    let storage = get("storage_identifier").ok_or_else(|| missing("storage_identifier"))?;
    let storage_format = match unquote(storage.value).as_str() {
        "sqlite3" => Format::Ros2Sqlite,
        "mcap" => Format::Mcap,
        other => {
            return Err(at(
                storage,
                format!("{other:?}: posecov reads rosbag2 storage sqlite3 or mcap"),
            ));
        }
    };
    let paths = get("relative_file_paths").ok_or_else(|| missing("relative_file_paths"))?;
    let mut files: Vec<(String, usize)> = paths
        .items
        .iter()
        .map(|(item, line)| (unquote(item), *line))
        .collect();
    if let Some(flow) = paths
        .value
        .strip_prefix('[')
        .and_then(|v| v.strip_suffix(']'))
    {
        files.extend(
            flow.split(',')
                .map(unquote)
                .filter(|f| !f.is_empty())
                .map(|f| (f, paths.line)),
        );
    }
    if files.is_empty() {
        return Err(at(paths, "names no file".to_owned()));
    }
    let text_of = |key: &str| get(key).map(|e| (unquote(e.value), e));
    let compression = match text_of("compression_mode") {
        None => Compression::None,
        Some((mode, e)) => match mode.to_ascii_lowercase().as_str() {
            "" | "none" => Compression::None,
            "file" => Compression::File,
            "message" => Compression::Message,
            _ => {
                return Err(at(
                    e,
                    format!("{mode:?}: posecov reads compression mode file, message or none"),
                ));
            }
        },
    };
    if compression != Compression::None
        && let Some((format, e)) = text_of("compression_format")
        && !format.eq_ignore_ascii_case("zstd")
    {
        return Err(at(
            e,
            format!("{format:?}: posecov reads zstd compression (what rosbag2 writes)"),
        ));
    }
    Ok(BagMetadata {
        version: version_number,
        storage: storage_format,
        files,
        compression,
    })
}

/// The metadata of the bag directory `dir` (its `metadata.yaml`), every file it names checked
/// to exist before anything is read: a missing one (a split bag's middle file) is named with
/// its place in the list.
///
/// ```
/// let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ros2/arc_v8_split");
/// let (m, files) = posecov::input::log::rosbag2::read_metadata(dir.as_ref()).unwrap();
/// assert_eq!((m.version, files.len()), (8, 2));
/// ```
pub fn read_metadata(dir: &Path) -> Result<(BagMetadata, Vec<PathBuf>), InputError> {
    let path = dir.join(METADATA_FILE);
    let file = path.display().to_string();
    let text = std::fs::read_to_string(&path).map_err(|e| InputError::Read {
        path: file.clone(),
        reason: e.to_string(),
    })?;
    let metadata = parse_metadata(&text, &file)?;
    let n = metadata.files.len();
    let mut paths = Vec::with_capacity(n);
    for (i, (name, line)) in metadata.files.iter().enumerate() {
        let p = dir.join(name);
        if !p.is_file() {
            let which = match i {
                0 => "the first".to_owned(),
                i if i + 1 == n => "the last".to_owned(),
                _ => "a middle".to_owned(),
            };
            return Err(InputError::In {
                file: file.clone(),
                place: format!("line {line}, relative_file_paths[{i}]"),
                message: format!(
                    "{name}: no such file in {} (file {} of {n}: {which} file of this bag is missing)",
                    dir.display(),
                    i + 1
                ),
            });
        }
        paths.push(p);
    }
    Ok((metadata, paths))
}

/// Streams every file of the bag directory `dir`, in its metadata's order, into `collector`
/// through its storage's reader; `progress` sees the bytes of the whole bag. An error inside a
/// file names that file (not its decompressed copy).
pub(super) fn read_dir(
    dir: &Path,
    collector: &mut Collector<'_, '_>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), InputError> {
    let (metadata, files) = read_metadata(dir)?;
    if metadata.storage == Format::Mcap && metadata.compression == Compression::Message {
        return Err(InputError::Format {
            file: dir.join(METADATA_FILE).display().to_string(),
            message: "zstd message compression in mcap storage: posecov reads message \
                      compression in sqlite3 bags (MCAP files compress their chunks)"
                .to_owned(),
        });
    }
    let sizes: Vec<u64> = files
        .iter()
        .map(|f| f.metadata().map_or(0, |m| m.len()))
        .collect();
    let total = sizes.iter().sum::<u64>().max(1);
    let mut before = 0u64;
    for (file, &size) in files.iter().zip(&sizes) {
        let mcap = metadata.storage == Format::Mcap;
        let unpacked = match metadata.compression {
            // An MCAP reader reads a file; an SQLite image is read in memory when it fits.
            Compression::File => Some(decompress_file(
                file,
                if mcap { 0 } else { IN_MEMORY_LIMIT },
            )?),
            _ => None,
        };
        let mut within = |done: u64, of: u64| {
            let share = u128::from(done.min(of)) * u128::from(size) / u128::from(of.max(1));
            progress(before + u64::try_from(share).unwrap_or(size), total);
        };
        let (readable, read) = match unpacked {
            Some(Unpacked::Memory(image)) => (
                file.clone(),
                super::sqlite::read_image(image, file, collector, &mut within),
            ),
            other => {
                let copy = match &other {
                    Some(Unpacked::File(copy)) => copy.0.clone(),
                    _ => file.clone(),
                };
                let read = if mcap {
                    super::mcap::read(&copy, collector, &mut within)
                } else {
                    let per_message = match metadata.compression {
                        Compression::Message => Compression::Message,
                        _ => Compression::None,
                    };
                    super::sqlite::read(&copy, Some(per_message), collector, &mut within)
                };
                (copy, read)
            }
        };
        read.map_err(|e| e.renamed(&readable.display().to_string(), &file.display().to_string()))?;
        before += size;
        if collector.stop() {
            break;
        }
    }
    progress(total, total);
    Ok(())
}

/// A file decompressed to a temporary file, removed when dropped.
pub(super) struct Decompressed(pub PathBuf);

impl Drop for Decompressed {
    fn drop(&mut self) {
        std::fs::remove_file(&self.0).ok();
    }
}

/// Most bytes a `file`-compressed SQLite bag file is decompressed to in memory (an image
/// SQLite reads in place: no temporary file written and read back; the read holds the
/// compressed file beside it); a larger one goes to a temporary file.
pub(super) const IN_MEMORY_LIMIT: usize = 256 << 20;

/// A `file`-compressed bag file, decompressed.
pub(super) enum Unpacked {
    /// To be decompressed in memory, straight into SQLite's buffer (see [`Image`]).
    Memory(Image),
    /// In a temporary file.
    File(Decompressed),
}

/// An SQLite file still compressed, in memory: `frames`, the whole zstd stream, decompresses
/// to `size` bytes, the database's size its SQLite header gives (page size at byte 16 times
/// the page count at byte 28, valid when the change counter at byte 24 equals the number at
/// byte 92: SQLite file format §1.3), at most [`IN_MEMORY_LIMIT`].
pub(super) struct Image {
    frames: Vec<u8>,
    /// The database's size in bytes.
    pub size: usize,
}

impl Image {
    /// Decompresses the database into `out` (`size` bytes long): in one call, zstd's fastest
    /// (no window copies; about 5 ms for a 23 MB bag where streaming took 20: issue 32),
    /// else, when that fails, streamed, which says how the stream is broken, or reads the
    /// first `size` bytes of a stream longer than its header says, all SQLite reads of it.
    pub(super) fn decompress_into(&self, out: &mut [u8]) -> Result<(), String> {
        let whole = zstd::bulk::Decompressor::new()
            .and_then(|mut d| d.decompress_to_buffer(&self.frames[..], &mut *out));
        let got = match whole {
            Ok(n) => n,
            Err(_) => {
                let mut decoder = zstd::stream::read::Decoder::new(&self.frames[..])
                    .map_err(|e| format!("the zstd file does not decompress: {e}"))?;
                let mut got = 0;
                while got < out.len() {
                    match decoder.read(&mut out[got..]) {
                        Ok(0) => break,
                        Ok(n) => got += n,
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                        Err(e) => return Err(format!("the zstd file does not decompress: {e}")),
                    }
                }
                got
            }
        };
        if got < out.len() {
            return Err(format!(
                "the file is cut short: it decompresses to {got} bytes, its SQLite header says \
                 {} bytes",
                out.len()
            ));
        }
        Ok(())
    }
}

/// `path` (one zstd stream, rosbag2's `file` compression) decompressed: in memory when its
/// SQLite header says it holds at most `in_memory` bytes (0: never), else to a temporary file
/// named after it.
pub(super) fn decompress_file(path: &Path, in_memory: usize) -> Result<Unpacked, InputError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let io = |p: &Path, e: std::io::Error| InputError::Read {
        path: p.display().to_string(),
        reason: e.to_string(),
    };
    let broken = |e: std::io::Error| InputError::Format {
        file: path.display().to_string(),
        message: format!("the zstd file does not decompress: {e}"),
    };
    let input = std::fs::File::open(path).map_err(|e| io(path, e))?;
    let mut head = [0u8; 4];
    let n = (&input).take(4).read(&mut head).map_err(|e| io(path, e))?;
    if head[..n] != [0x28, 0xb5, 0x2f, 0xfd] {
        return Err(InputError::Format {
            file: path.display().to_string(),
            message: "the bag's metadata says zstd file compression, but this file is not \
                      zstd (it does not start with zstd's magic 28 b5 2f fd)"
                .to_owned(),
        });
    }
    if in_memory > 0 {
        let input = std::fs::File::open(path).map_err(|e| io(path, e))?;
        let mut header = Vec::with_capacity(100);
        zstd::stream::read::Decoder::new(input)
            .map_err(|e| io(path, e))?
            .take(100)
            .read_to_end(&mut header)
            .map_err(broken)?;
        if let Some(size) = sqlite_size(&header)
            && size <= in_memory
        {
            let frames = std::fs::read(path).map_err(|e| io(path, e))?;
            return Ok(Unpacked::Memory(Image { frames, size }));
        }
    }
    let stem = path
        .file_name()
        .map(|n| n.to_string_lossy().trim_end_matches(".zstd").to_owned())
        .unwrap_or_default();
    let out = Decompressed(std::env::temp_dir().join(format!(
        "posecov-{}-{}-{stem}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    )));
    let input = std::fs::File::open(path).map_err(|e| io(path, e))?;
    let mut decoder = zstd::stream::read::Decoder::new(input).map_err(|e| io(path, e))?;
    let mut file = std::fs::File::create(&out.0).map_err(|e| io(&out.0, e))?;
    std::io::copy(&mut decoder, &mut file).map_err(broken)?;
    Ok(Unpacked::File(out))
}

/// The size in bytes an SQLite file's 100-byte `header` gives its database, when the header
/// is SQLite's and that size is valid (SQLite file format §1.3: page size at byte 16, 1 for
/// 65 536; page count at byte 28, valid when not 0 and the change counter at byte 24 equals
/// the "version-valid-for" number at byte 92).
fn sqlite_size(header: &[u8]) -> Option<usize> {
    let be32 = |at: usize| {
        header
            .get(at..at + 4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    };
    if !header.starts_with(crate::input::format::SQLITE_MAGIC) || be32(24)? != be32(92)? {
        return None;
    }
    let page = match u16::from_be_bytes([header[16], header[17]]) {
        1 => 65_536,
        p => usize::from(p),
    };
    let pages = usize::try_from(be32(28)?).ok()?;
    page.checked_mul(pages).filter(|&size| size > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_values_and_comments_are_skipped() {
        let text = "rosbag2_bagfile_information:\n  version: 8 # Iron\n  storage_identifier: 'sqlite3'\n  \
                    topics_with_message_count:\n    - topic_metadata:\n        name: /x\n        \
                    offered_qos_profiles: \"- history: 3\\n  depth: 0\"\n      message_count: 4\n  \
                    relative_file_paths:\n    - \"a b_0.db3\"\n    - a b_1.db3\n  files:\n  - path: x\n    \
                    message_count: 3\n  compression_format: \"\"\n  compression_mode: \"\"\n";
        let m = parse_metadata(text, "m").unwrap();
        assert_eq!(m.version, 8);
        assert_eq!(m.storage, Format::Ros2Sqlite);
        assert_eq!(
            m.files,
            [("a b_0.db3".to_owned(), 10), ("a b_1.db3".to_owned(), 11)]
        );
        assert_eq!(m.compression, Compression::None);
    }

    #[test]
    fn a_file_compressed_image_is_read_to_the_size_its_header_says() {
        let packed = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/ros2/arc_zstd_file/arc_zstd_file.db3.zstd"
        ))
        .unwrap();
        let image = zstd::decode_all(&packed[..]).unwrap();
        let size = sqlite_size(&image[..100]).unwrap();
        assert_eq!(size, image.len());
        // In one call.
        let mut out = vec![0; size];
        Image {
            frames: packed,
            size,
        }
        .decompress_into(&mut out)
        .unwrap();
        assert!(out == image);
        // A stream longer than its header says: its first `size` bytes, all SQLite reads.
        let mut longer = image.clone();
        longer.extend([7u8; 4096]);
        let mut out = vec![0; size];
        Image {
            frames: zstd::encode_all(&longer[..], 3).unwrap(),
            size,
        }
        .decompress_into(&mut out)
        .unwrap();
        assert!(out == image);
        // Shorter: cut short, both sizes said.
        let e = Image {
            frames: zstd::encode_all(&image[..size / 2], 3).unwrap(),
            size,
        }
        .decompress_into(&mut vec![0; size])
        .unwrap_err();
        assert!(
            e.contains("cut short") && e.contains(&format!("to {} bytes", size / 2)),
            "{e}"
        );
        // A broken stream: said as such.
        let broken = Image {
            frames: zstd::encode_all(&image[..], 3).unwrap()[..200].to_vec(),
            size,
        };
        let e = broken.decompress_into(&mut vec![0; size]).unwrap_err();
        assert!(e.contains("does not decompress"), "{e}");
        // A header whose change counter and "version-valid-for" differ gives no size.
        let mut stale = image[..100].to_vec();
        stale[92] ^= 1;
        assert_eq!(sqlite_size(&stale), None);
        assert_eq!(sqlite_size(&image[..50]), None);
    }

    #[test]
    fn unknown_compression_is_located() {
        let text = "version: 9\nstorage_identifier: sqlite3\nrelative_file_paths:\n- a.db3\n\
                    compression_format: lz4\ncompression_mode: message\n";
        let e = parse_metadata(text, "m").unwrap_err().to_string();
        assert!(
            e.starts_with("m: line 5, compression_format: \"lz4\""),
            "{e}"
        );
        let text = text.replace("lz4", "zstd").replace("message", "chunk");
        let e = parse_metadata(&text, "m").unwrap_err().to_string();
        assert!(
            e.starts_with("m: line 6, compression_mode: \"chunk\""),
            "{e}"
        );
        let e = parse_metadata("a: 1\n", "m").unwrap_err().to_string();
        assert!(e.contains("no `version`"), "{e}");
    }
}
