//! # MCAP, ROS 2's bag format
//!
//! MCAP (<https://mcap.dev/spec>, format version 0) is the default storage
//! of `ros2 bag record` since ROS 2 Iron. The file opens and closes with
//! the magic `\x89MCAP0\r\n`; between them every record is
//!
//! ```text
//! opcode u8 | length u64 | body (length bytes)
//! ```
//!
//! little-endian, the body laid out by the opcode. The file has a *data
//! section* (a Header record, then the recording) ended by a Data End
//! record, and an optional *summary section* after it that repeats the
//! schemas and channels and indexes the chunks for random access. The
//! records that carry the recording:
//!
//! | opcode | record | what it says |
//! |---|---|---|
//! | `0x03` | Schema | `id u16`, `name` (`sensor_msgs/msg/LaserScan`), `encoding` (`ros2msg`, `ros1msg`, …), the definition |
//! | `0x04` | Channel | `id u16`, `schema_id u16`, `topic`, `message_encoding` (`cdr`, `ros1`, `json`, …), metadata |
//! | `0x05` | Message | `channel_id u16`, `sequence u32`, `log_time u64` (ns), `publish_time u64`, the message bytes |
//! | `0x06` | Chunk | `message_start_time`, `message_end_time`, `uncompressed_size u64`, `uncompressed_crc u32` (CRC-32, 0 = none), `compression` (`""`, `zstd`, `lz4`), then `records` (`u64` length + bytes): Schema, Channel and Message records, compressed |
//! | `0x0F` | Data End | the data section's CRC |
//!
//! Message indexes (`0x07`) follow each chunk; attachments, metadata and
//! the summary's records serve random access and are skipped here.
//!
//! [`McapReader`] reads the data section linearly, as the bytes are pushed:
//! it works the same with or without a summary section (it stops at Data
//! End, as everything after it repeats what came before) and on a file cut
//! short. The records themselves are laid out by the `mcap` crate
//! ([`mcap::parse_record`]); the framing around them is this module's, so
//! it knows each chunk's byte offset. A chunk is opened when it is whole:
//! zstd with `ruzstd`, lz4 with `lz4_flex` (the LZ4 frame format), both
//! pure Rust, so the reader builds for the browser without a C compiler.
//! Each opened chunk is checked against its header (its uncompressed size,
//! and its CRC-32 when the writer recorded one) and its records are all
//! framed before any is delivered.
//!
//! ## A damaged chunk is skipped, not fatal
//!
//! A chunk that fails those checks (its CRC or a length lies, its data
//! does not decompress, a record inside it runs past its end) is skipped
//! whole; the records after it are read as usual, and [`ReadEnd::lost`]
//! names each skipped chunk (numbered from 1 in file order, with its byte
//! offset) and why. The chunk's own length field still frames the file: a
//! chunk whose record length lies throws the framing off, and the next
//! "record" is then refused (an opcode MCAP does not define, or an
//! impossible length) with an error naming its offset. A chunk compressed
//! with something other than zstd or lz4 is an error naming the chunk and
//! the compression, since every later chunk is likely the same.
//!
//! Topics: each channel becomes a [`Topic`] with the channel id. Its type
//! is the schema name without ROS 2's `/msg/` (`sensor_msgs/msg/LaserScan`
//! → `sensor_msgs/LaserScan`; a ROS 1 name stays as it is), and its
//! encoding the channel's: `cdr` → [`Encoding::Cdr`], `ros1` →
//! [`Encoding::Ros1`], anything else [`Encoding::Other`]. A message whose
//! channel record has not come yet waits for it; messages whose channel
//! never comes are reported lost.

use super::stream::{
    byte_count, record_at, shown, u64_at, Extent, Flow, Records, Waiting, RECORD_LIMIT,
};
use super::{BagError, BagReader, Encoding, MessageSink, RawMessage, ReadEnd, Topic};
use mcap::records::{op, Record};
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::io::Read;

/// The magic at both ends of an MCAP file.
pub const MAGIC: &[u8] = mcap::MAGIC;
/// Opcode and length before every record's body.
const RECORD_PREFIX: usize = 1 + 8;

/// Reads an MCAP file pushed in pieces; see the module doc.
#[derive(Debug, Default)]
pub struct McapReader {
    /// The opening magic, until it is whole.
    magic: Vec<u8>,
    records: Records,
    state: State,
    /// The error that stopped the read, returned again by later calls.
    failed: Option<BagError>,
}

/// Everything but the byte stream.
#[derive(Debug, Default)]
struct State {
    /// Schema id → message type.
    schemas: HashMap<u16, String>,
    channels: HashSet<u16>,
    waiting: Waiting,
    /// Chunks met (the number of the last one, counting from 1).
    chunks_met: usize,
    /// Data End was read: the recording is whole.
    data_end: bool,
    /// The chunks skipped, and why.
    skipped: Vec<String>,
    end: ReadEnd,
}

impl McapReader {
    pub fn new() -> McapReader {
        McapReader::default()
    }

    /// Gathers and checks the opening magic; returns the bytes after it.
    fn read_magic<'a>(&mut self, bytes: &'a [u8]) -> Result<&'a [u8], BagError> {
        let take = (MAGIC.len() - self.magic.len()).min(bytes.len());
        if take == 0 {
            return Ok(bytes);
        }
        self.magic.extend_from_slice(&bytes[..take]);
        if self.magic.len() == MAGIC.len() {
            if self.magic != MAGIC {
                return Err(not_mcap(&self.magic));
            }
            self.records = Records::starting_at(MAGIC.len() as u64);
        }
        Ok(&bytes[take..])
    }

    fn push_records(&mut self, bytes: &[u8], sink: &mut dyn MessageSink) -> Result<(), BagError> {
        let rest = self.read_magic(bytes)?;
        let state = &mut self.state;
        self.records.feed(rest, record_extent, |record, at| {
            state.record(record, at, sink)
        })
    }

    /// What is missing when the file ends before Data End.
    fn cut_short(&self) -> Option<String> {
        if self.state.data_end {
            return None;
        }
        let tail = self.records.tail();
        let at = self.records.start();
        if tail.is_empty() {
            return Some(format!(
                "the file ends at byte {} without the Data End record that closes MCAP's \
                 data section: it was cut short, and whatever followed is missing",
                byte_count(at)
            ));
        }
        let have = byte_count(tail.len() as u64);
        let of_len = u64_at(tail, 1).map_or(String::new(), |len| {
            format!(
                " of its {}",
                byte_count(len.saturating_add(RECORD_PREFIX as u64))
            )
        });
        Some(match tail.first() {
            Some(&op::CHUNK) => format!(
                "the file ends inside chunk {} at byte {} (it has {have}{of_len} bytes): \
                 the messages of that chunk are lost",
                self.state.chunks_met + 1,
                byte_count(at)
            ),
            Some(&op::MESSAGE) => format!(
                "the file ends inside the message record at byte {} \
                 (it has {have}{of_len} bytes): that message is lost",
                byte_count(at)
            ),
            _ => format!(
                "the file ends inside the record at byte {} (it has {have}{of_len} bytes)",
                byte_count(at)
            ),
        })
    }
}

impl BagReader for McapReader {
    fn push(&mut self, bytes: &[u8], sink: &mut dyn MessageSink) -> Result<(), BagError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        let result = self.push_records(bytes, sink);
        if let Err(e) = &result {
            self.failed = Some(e.clone());
        }
        result
    }

    fn finish(&mut self, _sink: &mut dyn MessageSink) -> Result<ReadEnd, BagError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        if self.magic.len() < MAGIC.len() {
            return Err(if self.magic.is_empty() {
                BagError::new("", "the file is empty: not an MCAP file")
            } else if MAGIC.starts_with(&self.magic) {
                BagError::new(
                    "",
                    format!(
                        "the file ends inside MCAP's magic ({} bytes): not a whole MCAP file",
                        self.magic.len()
                    ),
                )
            } else {
                not_mcap(&self.magic)
            });
        }
        let mut lost = self.state.skipped.clone();
        lost.extend(self.cut_short());
        lost.extend(self.state.waiting.lost("channel"));
        let mut end = self.state.end.clone();
        end.container = "MCAP".into();
        end.lost = (!lost.is_empty()).then(|| lost.join("; "));
        Ok(end)
    }
}

fn not_mcap(start: &[u8]) -> BagError {
    BagError::new(
        "",
        format!(
            "not an MCAP file (it starts with {}, not {})",
            shown(start),
            shown(MAGIC)
        ),
    )
}

/// Measures the record at the front of `bytes` (file offset `at`):
/// `opcode u8, length u64, body`. An opcode MCAP does not define (0, or
/// 0x10 to 0x7F; 0x80 and up are private records) means the framing is
/// off.
fn record_extent(bytes: &[u8], at: u64) -> Result<Extent, BagError> {
    let Some(&opcode) = bytes.first() else {
        return Ok(Extent::AtLeast(RECORD_PREFIX));
    };
    if opcode == 0 || (0x10..0x80).contains(&opcode) {
        return Err(BagError::new(
            record_at(at),
            format!(
                "opcode 0x{opcode:02x}, which MCAP does not define: the file is damaged here, \
                 or the length of the record before it is wrong"
            ),
        ));
    }
    let Some(len) = u64_at(bytes, 1) else {
        return Ok(Extent::AtLeast(RECORD_PREFIX));
    };
    if len > RECORD_LIMIT {
        return Err(BagError::new(
            record_at(at),
            format!(
                "its length says {} bytes, more than {} GiB: the file is damaged",
                byte_count(len),
                RECORD_LIMIT >> 30
            ),
        ));
    }
    Ok(Extent::Whole(RECORD_PREFIX + len as usize))
}

/// The message type a schema names: ROS 2's `pkg/msg/Type` as `pkg/Type`.
fn msg_type(schema_name: &str) -> String {
    schema_name.replacen("/msg/", "/", 1)
}

fn encoding(message_encoding: &str) -> Encoding {
    match message_encoding {
        "cdr" => Encoding::Cdr,
        "ros1" => Encoding::Ros1,
        other => Encoding::Other(other.to_string()),
    }
}

/// One record of a chunk's data: opcode, body, offset in the data.
type InnerRecord<'a> = (u8, &'a [u8], u64);

/// Frames every record of an opened chunk, or says why it cannot.
fn chunk_records(mut data: &[u8]) -> Result<Vec<InnerRecord<'_>>, String> {
    let mut out = Vec::new();
    let mut offset = 0u64;
    while !data.is_empty() {
        let len = u64_at(data, 1)
            .and_then(|len| usize::try_from(len).ok())
            .and_then(|len| len.checked_add(RECORD_PREFIX))
            .filter(|&len| len <= data.len())
            .ok_or_else(|| {
                format!(
                    "the record at byte {} of its data runs past the chunk's end",
                    byte_count(offset)
                )
            })?;
        out.push((data[0], &data[RECORD_PREFIX..len], offset));
        data = &data[len..];
        offset += len as u64;
    }
    Ok(out)
}

impl State {
    /// One whole record of the file, at file offset `at`.
    fn record(
        &mut self,
        record: &[u8],
        at: u64,
        sink: &mut dyn MessageSink,
    ) -> Result<Flow, BagError> {
        let opcode = record.first().copied().unwrap_or(0);
        let body = record.get(RECORD_PREFIX..).unwrap_or(&[]);
        match opcode {
            op::SCHEMA | op::CHANNEL | op::MESSAGE => {
                let label = record_at(at);
                self.inner_record(opcode, body, &label, &label, sink)?
            }
            op::CHUNK => self.chunk(body, at, sink)?,
            op::DATA_END | op::FOOTER => {
                self.data_end = true;
                return Ok(Flow::Stop);
            }
            _ => {}
        }
        Ok(Flow::Continue)
    }

    /// A Schema, Channel or Message record (in the file or a chunk):
    /// `label` names the record in errors, `place` in messages.
    fn inner_record(
        &mut self,
        opcode: u8,
        body: &[u8],
        label: &str,
        place: &str,
        sink: &mut dyn MessageSink,
    ) -> Result<(), BagError> {
        let unreadable = |e: mcap::McapError| BagError::new(label, format!("{e}"));
        match mcap::parse_record(opcode, body).map_err(unreadable)? {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, msg_type(&header.name));
            }
            Record::Channel(channel) => {
                if self.channels.contains(&channel.id) {
                    return Ok(());
                }
                let msg_type = match channel.schema_id {
                    0 => String::new(),
                    id => self.schemas.get(&id).cloned().ok_or_else(|| {
                        BagError::new(
                            label,
                            format!(
                                "channel {} names schema {id}, which no schema record before it \
                                 defines",
                                channel.id
                            ),
                        )
                        .on_topic(&channel.topic)
                    })?,
                };
                sink.topic(&Topic {
                    id: channel.id.into(),
                    name: channel.topic,
                    msg_type,
                    encoding: encoding(&channel.message_encoding),
                });
                self.channels.insert(channel.id);
                self.waiting.release(channel.id.into(), sink)?;
            }
            Record::Message { header, data } => {
                let message = RawMessage {
                    topic: header.channel_id.into(),
                    log_time_ns: header.log_time,
                    data: &data,
                    record: place,
                };
                if self.channels.contains(&header.channel_id) {
                    sink.message(message)?;
                } else {
                    self.waiting.keep(message, "channel")?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// A Chunk record's body, at file offset `at`: opened, checked, its
    /// records read; or skipped, and the reason kept for [`ReadEnd::lost`].
    fn chunk(&mut self, body: &[u8], at: u64, sink: &mut dyn MessageSink) -> Result<(), BagError> {
        self.chunks_met += 1;
        let label = format!("chunk {} at byte {}", self.chunks_met, byte_count(at));
        let (header, compressed) = match mcap::parse_record(op::CHUNK, body) {
            Ok(Record::Chunk { header, data }) => (header, data),
            Ok(_) => return Ok(()),
            Err(e) => {
                self.skip(&label, format!("its header cannot be read ({e})"));
                return Ok(());
            }
        };
        let compression = match header.compression.as_str() {
            "" => "none",
            "zstd" => "zstd",
            "lz4" => "lz4",
            other => {
                return Err(BagError::new(
                    label,
                    format!(
                        "its compression is {}, which this reader does not know \
                         (MCAP writers use zstd, lz4 or none)",
                        shown(other.as_bytes())
                    ),
                ))
            }
        };
        if !self.end.compression.iter().any(|c| c == compression) {
            self.end.compression.push(compression.to_string());
        }
        let opened = match open_chunk(&header, &compressed, compression) {
            Ok(opened) => opened,
            Err(why) => {
                self.skip(&label, why);
                return Ok(());
            }
        };
        let records = match chunk_records(&opened) {
            Ok(records) => records,
            Err(why) => {
                self.skip(&label, why);
                return Ok(());
            }
        };
        for (opcode, body, offset) in records {
            if matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) {
                let inner = format!("{label}, record at byte {} of its data", byte_count(offset));
                self.inner_record(opcode, body, &inner, &label, sink)?;
            }
        }
        self.end.chunks += 1;
        Ok(())
    }

    fn skip(&mut self, label: &str, why: String) {
        self.skipped
            .push(format!("{label} is skipped, its messages lost: {why}"));
    }
}

/// Decompresses a chunk's records and checks them against its header.
fn open_chunk<'a>(
    header: &mcap::records::ChunkHeader,
    compressed: &'a [u8],
    compression: &str,
) -> Result<Cow<'a, [u8]>, String> {
    let size = header.uncompressed_size;
    if size > RECORD_LIMIT {
        return Err(format!(
            "its header says {} bytes uncompressed, more than {} GiB",
            byte_count(size),
            RECORD_LIMIT >> 30
        ));
    }
    let size = size as usize;
    let opened = match compression {
        "zstd" => Cow::Owned(zstd_frames(compressed, size)?),
        "lz4" => {
            let mut out = Vec::with_capacity(size.min(64 << 20));
            lz4_flex::frame::FrameDecoder::new(compressed)
                .take(size as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("its lz4 data cannot be decompressed: {e}"))?;
            Cow::Owned(out)
        }
        _ => Cow::Borrowed(compressed),
    };
    if opened.len() != size {
        return Err(format!(
            "its header says {} bytes uncompressed, its data holds {}",
            byte_count(size as u64),
            byte_count(opened.len() as u64)
        ));
    }
    if header.uncompressed_crc != 0 {
        let crc = crc32fast::hash(&opened);
        if crc != header.uncompressed_crc {
            return Err(format!(
                "its CRC-32 says 0x{:08x}, its data's is 0x{crc:08x}",
                header.uncompressed_crc
            ));
        }
    }
    Ok(opened)
}

/// Decodes the zstd frames of a chunk (skippable frames skipped) into at
/// most `size + 1` bytes.
fn zstd_frames(mut src: &[u8], size: usize) -> Result<Vec<u8>, String> {
    use ruzstd::decoding::errors::{FrameDecoderError, ReadFrameHeaderError};
    let mut out = Vec::with_capacity(size.min(64 << 20));
    while !src.is_empty() && out.len() <= size {
        match ruzstd::decoding::StreamingDecoder::new(&mut src) {
            Ok(mut frame) => {
                let room = (size + 1 - out.len()) as u64;
                (&mut frame)
                    .take(room)
                    .read_to_end(&mut out)
                    .map_err(|e| format!("its zstd data cannot be decompressed: {e}"))?;
            }
            Err(FrameDecoderError::ReadFrameHeaderError(ReadFrameHeaderError::SkipFrame {
                length,
                ..
            })) => {
                src = src.get(length as usize..).unwrap_or(&[]);
            }
            Err(e) => return Err(format!("its zstd data cannot be decompressed: {e}")),
        }
    }
    Ok(out)
}
