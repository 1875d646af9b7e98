//! # ROS 1 bags, format 2.0
//!
//! `rosbag record` writes format 2.0 (the ROS wiki's "Bags/Format/2.0",
//! and `tools/rosbag/FORMATS` in `ros_comm`). The file opens with the line
//! `#ROSBAG V2.0\n`, then holds nothing but records:
//!
//! ```text
//! header_len u32 | header (header_len bytes) | data_len u32 | data (data_len bytes)
//! ```
//!
//! all integers little-endian. A header is a run of fields, each `len u32`
//! then `name=value` in `len` bytes (the value is binary: an `op` is one
//! byte, a `conn` a `u32`, a `time` a `u32` of seconds and a `u32` of
//! nanoseconds). Every header has an `op` saying what the record is:
//!
//! | op | record | header | data |
//! |---|---|---|---|
//! | `0x03` | bag header | `index_pos`, `conn_count`, `chunk_count` | padding |
//! | `0x05` | chunk | `compression` (`none`, `bz2`, `lz4`), `size` (uncompressed) | more records, compressed |
//! | `0x07` | connection | `conn` (its id), `topic` | a connection header: `topic`, `type`, `md5sum`, `message_definition`, … |
//! | `0x02` | message data | `conn`, `time` | the message, ROS 1 serialisation |
//! | `0x04` | index data | `conn`, `ver`, `count` | times and offsets of a chunk's messages |
//! | `0x06` | chunk info | `chunk_pos`, `start_time`, `end_time`, `count` | messages per connection |
//!
//! A recorder writes the bag header, then chunks, each chunk holding the
//! connection records of the topics first seen in it and the messages, and
//! followed by its index records; at the end (at `index_pos`) every
//! connection record again and one chunk info per chunk. Only the chunks
//! matter to a reader that goes through the whole file: [`Ros1Reader`]
//! reads the records in order, opens each chunk when it is complete
//! (bz2 with the `bzip2` crate, lz4 with `lz4_flex`: `roslz4` writes the
//! standard LZ4 frame format, independent blocks and a content checksum)
//! and hands its messages over at once; index records are skipped.
//!
//! It does not rely on that order, though. Message records may stand
//! outside chunks, and a message whose connection record has not come yet
//! is kept until it does (at the end, messages that never got one are
//! reported lost). Each connection id becomes one [`Topic`] when first
//! seen; two connections may share a topic name (two publishers), and
//! stay two topics with their own ids.
//!
//! The file is read as a stream: at most the record being read is held
//! (a chunk, compressed, and then its uncompressed records), never the
//! file. A file cut short keeps every message of the chunks before the
//! cut, and [`ReadEnd::lost`] says where it ends. Lengths are checked
//! against their record before they are used: a header longer than 1 MiB,
//! a record longer than 1 GiB or a field running past its header are
//! errors naming the record, never an allocation or a panic. Chunks are
//! numbered from 1 in file order in messages, with the byte offset of
//! their record.
//!
//! ## A damaged chunk is skipped, not fatal
//!
//! A chunk's own record (`header_len`, `data_len`) frames the file; what
//! it holds is checked when it is opened: its data must decompress, give
//! exactly the bytes its `size` field says, and split into whole records
//! with readable headers, all before any of its messages is handed over.
//! A chunk that fails (its `size` lies, its bz2 or lz4 data is damaged, a
//! record inside it runs past its end) is skipped whole, as the MCAP
//! reader skips one, and [`ReadEnd::lost`] names it and says why; the
//! chunks after it are read as usual. A chunk whose *record* length lies
//! throws the framing off instead, and the next "record" is refused with
//! an error naming its offset. A chunk compressed with something other
//! than none, bz2 or lz4 is an error naming the chunk and the
//! compression, since every later chunk is likely the same.
//!
//! The older format 1.2 (`#ROSRECORD V1.2`, ROS before C Turtle) has no
//! chunks nor connections, and is refused with a message saying so. ROS
//! 1's `rosbag` tools read 1.2 and always write 2.0, so copying the bag
//! with them (`rosbag filter old.bag new.bag True`) converts it.

use super::stream::{byte_count, record_at, shown, u32_at, Extent, Flow, Records, Waiting};
use super::stream::{HEADER_LIMIT, RECORD_LIMIT};
use super::{BagError, BagReader, Encoding, MessageSink, RawMessage, ReadEnd, Topic};
use std::borrow::Cow;
use std::collections::HashSet;
use std::io::Read;

/// The first line of a format 2.0 bag.
pub const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
/// The longest first line looked at before judging it.
const MAGIC_LINE_LIMIT: usize = 16;

/// The record ops of format 2.0.
mod op {
    pub const MESSAGE_DATA: u8 = 0x02;
    pub const BAG_HEADER: u8 = 0x03;
    pub const INDEX_DATA: u8 = 0x04;
    pub const CHUNK: u8 = 0x05;
    pub const CHUNK_INFO: u8 = 0x06;
    pub const CONNECTION: u8 = 0x07;
}

/// What a record is called in messages.
fn op_name(op: u8) -> &'static str {
    match op {
        op::MESSAGE_DATA => "message data",
        op::BAG_HEADER => "bag header",
        op::INDEX_DATA => "index data",
        op::CHUNK => "chunk",
        op::CHUNK_INFO => "chunk info",
        op::CONNECTION => "connection",
        _ => "unknown",
    }
}

/// Reads a ROS 1 bag (format 2.0) pushed in pieces; see the module doc.
#[derive(Debug, Default)]
pub struct Ros1Reader {
    /// The first line, until it is judged.
    magic: Vec<u8>,
    magic_read: bool,
    records: Records,
    state: State,
    /// The error that stopped the read, returned again by later calls.
    failed: Option<BagError>,
}

/// Everything but the byte stream.
#[derive(Debug, Default)]
struct State {
    connections: HashSet<u32>,
    waiting: Waiting,
    bag_header: Option<BagHeader>,
    /// Chunks met (the number of the last one, counting from 1).
    chunks_met: usize,
    /// The chunks skipped, and why.
    skipped: Vec<String>,
    end: ReadEnd,
}

/// The bag header's counts, to tell a bag cut at a record boundary.
#[derive(Clone, Copy, Debug, Default)]
struct BagHeader {
    index_pos: u64,
    chunk_count: u32,
}

/// The fields of a record header this reader uses.
#[derive(Debug, Default)]
struct Header<'a> {
    op: Option<u8>,
    conn: Option<u32>,
    time_ns: Option<u64>,
    compression: Option<&'a [u8]>,
    size: Option<u32>,
    topic: Option<&'a [u8]>,
    index_pos: Option<u64>,
    chunk_count: Option<u32>,
}

impl Ros1Reader {
    pub fn new() -> Ros1Reader {
        Ros1Reader::default()
    }

    /// Gathers and judges the first line; returns the bytes after it.
    fn read_magic<'a>(&mut self, bytes: &'a [u8]) -> Result<&'a [u8], BagError> {
        let mut used = 0;
        while !self.magic_read && used < bytes.len() {
            let b = bytes[used];
            self.magic.push(b);
            used += 1;
            if b == b'\n' || self.magic.len() == MAGIC_LINE_LIMIT {
                judge_magic(&self.magic)?;
                self.magic_read = true;
                self.records = Records::starting_at(self.magic.len() as u64);
            }
        }
        Ok(&bytes[used..])
    }

    fn push_records(&mut self, bytes: &[u8], sink: &mut dyn MessageSink) -> Result<(), BagError> {
        let rest = self.read_magic(bytes)?;
        let state = &mut self.state;
        self.records.feed(rest, record_extent, |record, at| {
            state.record(record, at, sink)?;
            Ok(Flow::Continue)
        })
    }
}

impl BagReader for Ros1Reader {
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
        if !self.magic_read {
            return Err(if self.magic.is_empty() {
                BagError::new("", "the file is empty: not a ROS 1 bag")
            } else if MAGIC.starts_with(&self.magic) {
                BagError::new(
                    "",
                    format!(
                        "the file ends inside its first line ({} bytes): not a whole ROS 1 bag",
                        self.magic.len()
                    ),
                )
            } else {
                not_a_bag(&self.magic)
            });
        }
        let mut lost = self.state.skipped.clone();
        if let Some(cut) = self.cut_short() {
            lost.push(cut);
        }
        if let Some(w) = self.state.waiting.lost("connection") {
            lost.push(w);
        }
        let mut end = self.state.end.clone();
        end.container = "ROS 1 bag 2.0".into();
        end.lost = (!lost.is_empty()).then(|| lost.join("; "));
        Ok(end)
    }
}

impl Ros1Reader {
    /// What the file lacks when it ends inside a record, or before the
    /// index its bag header points to.
    fn cut_short(&self) -> Option<String> {
        let tail = self.records.tail();
        let at = self.records.start();
        let file_len = at + tail.len() as u64;
        if tail.is_empty() {
            let header = self.state.bag_header?;
            let before_index = header.index_pos > 0 && file_len < header.index_pos;
            let chunks_missing = (self.state.chunks_met as u64) < u64::from(header.chunk_count);
            return (before_index || chunks_missing).then(|| {
                format!(
                    "the file ends at byte {}, before the index its bag header places at byte {} \
                     ({} of its {} chunks read): the rest of the bag is missing",
                    byte_count(file_len),
                    byte_count(header.index_pos),
                    self.state.chunks_met,
                    header.chunk_count
                )
            });
        }
        let whole = match record_extent(tail, at) {
            Ok(Extent::Whole(len)) => Some(len),
            _ => None,
        };
        let have = byte_count(tail.len() as u64);
        let op = u32_at(tail, 0)
            .and_then(|hl| tail.get(4..4 + hl as usize))
            .and_then(|h| parse_header(h, "").ok())
            .and_then(|h| h.op);
        let of_len = whole.map_or(String::new(), |w| {
            format!(" of its {}", byte_count(w as u64))
        });
        Some(match op {
            Some(op::CHUNK) => format!(
                "the file ends inside chunk {} at byte {} (it has {have}{of_len} bytes): \
                 the messages of that chunk are lost",
                self.state.chunks_met + 1,
                byte_count(at)
            ),
            Some(op::MESSAGE_DATA) => format!(
                "the file ends inside the message data record at byte {} \
                 (it has {have}{of_len} bytes): that message is lost",
                byte_count(at)
            ),
            Some(op) => format!(
                "the file ends inside the {} record at byte {} (it has {have}{of_len} bytes)",
                op_name(op),
                byte_count(at)
            ),
            None => format!(
                "the file ends inside the header of the record at byte {} (it has {have} bytes)",
                byte_count(at)
            ),
        })
    }
}

/// Refuses a first line that is not format 2.0's.
fn judge_magic(line: &[u8]) -> Result<(), BagError> {
    if line == MAGIC {
        Ok(())
    } else if line.starts_with(b"#ROSRECORD V1.") {
        Err(BagError::new(
            "",
            format!(
                "a ROS 1 bag of the old format 1.{} ({}), which this reader does not read: \
                 ROS 1's rosbag tools convert it to format 2.0 \
                 (`rosbag filter old.bag new.bag True` copies it as 2.0)",
                line.get(14).map_or('?', |&b| b as char),
                shown(line)
            ),
        ))
    } else {
        Err(not_a_bag(line))
    }
}

fn not_a_bag(start: &[u8]) -> BagError {
    BagError::new(
        "",
        format!(
            "not a ROS 1 bag (it starts with {}, not {})",
            shown(start),
            shown(MAGIC)
        ),
    )
}

/// Measures the record at the front of `bytes` (file offset `at`):
/// `header_len u32, header, data_len u32, data`.
fn record_extent(bytes: &[u8], at: u64) -> Result<Extent, BagError> {
    let Some(header_len) = u32_at(bytes, 0) else {
        return Ok(Extent::AtLeast(4));
    };
    if u64::from(header_len) > HEADER_LIMIT {
        return Err(BagError::new(
            record_at(at),
            format!(
                "its header is {} bytes long, more than {} MiB: the file is damaged",
                byte_count(header_len.into()),
                HEADER_LIMIT >> 20
            ),
        ));
    }
    let data_len_at = 4 + header_len as usize;
    let Some(data_len) = u32_at(bytes, data_len_at) else {
        return Ok(Extent::AtLeast(data_len_at + 4));
    };
    if u64::from(data_len) > RECORD_LIMIT {
        return Err(BagError::new(
            record_at(at),
            format!(
                "its data is {} bytes long, more than {} GiB: the file is damaged",
                byte_count(data_len.into()),
                RECORD_LIMIT >> 30
            ),
        ));
    }
    Ok(Extent::Whole(data_len_at + 4 + data_len as usize))
}

/// A whole record's header and data (its extent already measured).
fn split_record(record: &[u8]) -> (&[u8], &[u8]) {
    let header_len = u32_at(record, 0).unwrap_or(0) as usize;
    let header = record.get(4..4 + header_len).unwrap_or(&[]);
    let data = record.get(8 + header_len..).unwrap_or(&[]);
    (header, data)
}

/// Reads a record header's fields; `label` names the record in errors.
fn parse_header<'a>(mut bytes: &'a [u8], label: &str) -> Result<Header<'a>, BagError> {
    let mut h = Header::default();
    while !bytes.is_empty() {
        let field_len = u32_at(bytes, 0)
            .ok_or_else(|| BagError::new(label, "its header ends inside a field's length"))?
            as usize;
        let field = bytes.get(4..4 + field_len).ok_or_else(|| {
            BagError::new(
                label,
                format!(
                    "a header field of {} bytes runs past the header's end",
                    byte_count(field_len as u64)
                ),
            )
        })?;
        bytes = &bytes[4 + field_len..];
        let eq = field.iter().position(|&b| b == b'=').ok_or_else(|| {
            BagError::new(
                label,
                format!("the header field {} has no '='", shown(field)),
            )
        })?;
        let (name, value) = (&field[..eq], &field[eq + 1..]);
        let wrong = |n: usize| {
            BagError::new(
                label,
                format!(
                    "the header field {} is {} bytes, not {n}",
                    shown(name),
                    value.len()
                ),
            )
        };
        let as_u32 = || {
            <[u8; 4]>::try_from(value)
                .map(u32::from_le_bytes)
                .map_err(|_| wrong(4))
        };
        let as_u64 = || {
            <[u8; 8]>::try_from(value)
                .map(u64::from_le_bytes)
                .map_err(|_| wrong(8))
        };
        match name {
            b"op" => h.op = Some(<[u8; 1]>::try_from(value).map_err(|_| wrong(1))?[0]),
            b"conn" => h.conn = Some(as_u32()?),
            b"size" => h.size = Some(as_u32()?),
            b"chunk_count" => h.chunk_count = Some(as_u32()?),
            b"index_pos" => h.index_pos = Some(as_u64()?),
            b"time" => {
                // A u32 of seconds, then a u32 of nanoseconds.
                let t = as_u64()?;
                h.time_ns = Some((t & 0xffff_ffff) * 1_000_000_000 + (t >> 32));
            }
            b"compression" => h.compression = Some(value),
            b"topic" => h.topic = Some(value),
            _ => {}
        }
    }
    Ok(h)
}

/// The value of `name` in a connection record's data (its connection
/// header, the same `len u32, name=value` fields).
fn connection_field<'a>(mut bytes: &'a [u8], name: &[u8]) -> Option<&'a [u8]> {
    while let Some(len) = u32_at(bytes, 0) {
        let field = bytes.get(4..4 + len as usize)?;
        bytes = &bytes[4 + len as usize..];
        if let Some(value) = field
            .strip_prefix(name)
            .and_then(|rest| rest.strip_prefix(b"="))
        {
            return Some(value);
        }
    }
    None
}

/// Where a record is: at the top level, or inside a chunk.
#[derive(Clone, Copy)]
enum Place<'a> {
    File,
    Chunk(&'a str),
}

impl State {
    /// One whole record of the file, at file offset `at`.
    fn record(
        &mut self,
        record: &[u8],
        at: u64,
        sink: &mut dyn MessageSink,
    ) -> Result<(), BagError> {
        let label = record_at(at);
        let (header_bytes, data) = split_record(record);
        let header = parse_header(header_bytes, &label)?;
        match header.op {
            Some(op::BAG_HEADER) => {
                self.bag_header = Some(BagHeader {
                    index_pos: header.index_pos.unwrap_or(0),
                    chunk_count: header.chunk_count.unwrap_or(0),
                });
                Ok(())
            }
            Some(op::CHUNK) => self.chunk(&header, data, at, sink),
            _ => self.inner_record(&header, data, &label, Place::File, sink),
        }
    }

    /// A connection, message data or index record, in the file or in a
    /// chunk; `label` names the record.
    fn inner_record(
        &mut self,
        header: &Header<'_>,
        data: &[u8],
        label: &str,
        place: Place<'_>,
        sink: &mut dyn MessageSink,
    ) -> Result<(), BagError> {
        match header.op {
            Some(op::CONNECTION) => self.connection(header, data, label, sink),
            Some(op::MESSAGE_DATA) => {
                let missing = |field: &str| {
                    BagError::new(
                        label,
                        format!("a message data record without its `{field}`"),
                    )
                };
                let message = RawMessage {
                    topic: header.conn.ok_or_else(|| missing("conn"))?,
                    log_time_ns: header.time_ns.ok_or_else(|| missing("time"))?,
                    data,
                    record: match place {
                        Place::File => label,
                        Place::Chunk(chunk) => chunk,
                    },
                };
                if self.connections.contains(&message.topic) {
                    sink.message(message)
                } else {
                    self.waiting.keep(message, "connection")
                }
            }
            Some(op::INDEX_DATA | op::CHUNK_INFO) => Ok(()),
            Some(op) => Err(BagError::new(
                label,
                match place {
                    Place::File => format!("op 0x{op:02x} is not a record of format 2.0"),
                    Place::Chunk(_) => format!(
                        "a {} record (op 0x{op:02x}) inside a chunk, where format 2.0 has only \
                         connections and messages",
                        op_name(op)
                    ),
                },
            )),
            None => Err(BagError::new(label, "a record without an `op` field")),
        }
    }

    /// A connection record: a new topic, and the messages waiting for it.
    fn connection(
        &mut self,
        header: &Header<'_>,
        data: &[u8],
        label: &str,
        sink: &mut dyn MessageSink,
    ) -> Result<(), BagError> {
        let id = header
            .conn
            .ok_or_else(|| BagError::new(label, "a connection record without its `conn` id"))?;
        if self.connections.contains(&id) {
            return Ok(());
        }
        let name = header
            .topic
            .or_else(|| connection_field(data, b"topic"))
            .ok_or_else(|| BagError::new(label, format!("connection {id} has no topic")))?;
        let name = String::from_utf8_lossy(name).into_owned();
        let msg_type = connection_field(data, b"type").ok_or_else(|| {
            BagError::new(label, format!("connection {id} has no message type")).on_topic(&name)
        })?;
        sink.topic(&Topic {
            id,
            name,
            msg_type: String::from_utf8_lossy(msg_type).into_owned(),
            encoding: Encoding::Ros1,
        });
        self.connections.insert(id);
        self.waiting.release(id, sink)
    }

    /// A chunk record at file offset `at`: opened, checked, its records
    /// read; or skipped, and the reason kept for [`ReadEnd::lost`].
    fn chunk(
        &mut self,
        header: &Header<'_>,
        data: &[u8],
        at: u64,
        sink: &mut dyn MessageSink,
    ) -> Result<(), BagError> {
        self.chunks_met += 1;
        let label = format!("chunk {} at byte {}", self.chunks_met, byte_count(at));
        let compression = header.compression.unwrap_or(b"none");
        if !matches!(compression, b"none" | b"bz2" | b"lz4") {
            return Err(BagError::new(
                &label,
                format!(
                    "its compression is {}, which this reader does not know \
                     (format 2.0 writes none, bz2 or lz4)",
                    shown(compression)
                ),
            ));
        }
        let name = String::from_utf8_lossy(compression).into_owned();
        if !self.end.compression.contains(&name) {
            self.end.compression.push(name);
        }
        let opened = match open_chunk(header.size, compression, data) {
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
        for (header, data) in records {
            self.inner_record(&header, data, &label, Place::Chunk(&label), sink)?;
        }
        self.end.chunks += 1;
        Ok(())
    }

    fn skip(&mut self, label: &str, why: String) {
        self.skipped
            .push(format!("{label} is skipped, its messages lost: {why}"));
    }
}

/// Decompresses a chunk's data (`compression` one of `none`, `bz2`,
/// `lz4`) and checks it against its `size` field.
fn open_chunk<'a>(
    size: Option<u32>,
    compression: &[u8],
    data: &'a [u8],
) -> Result<Cow<'a, [u8]>, String> {
    let size = match (size, compression) {
        (Some(size), _) => size as usize,
        (None, b"none") => data.len(),
        (None, _) => return Err("a compressed chunk without its `size` field".into()),
    };
    if size as u64 > RECORD_LIMIT {
        return Err(format!(
            "its size field says {} bytes, more than {} GiB",
            byte_count(size as u64),
            RECORD_LIMIT >> 30
        ));
    }
    let opened = match compression {
        b"bz2" => Cow::Owned(inflate(bzip2::bufread::BzDecoder::new(data), size, "bz2")?),
        b"lz4" => Cow::Owned(inflate(
            lz4_flex::frame::FrameDecoder::new(data),
            size,
            "lz4",
        )?),
        _ => Cow::Borrowed(data),
    };
    if opened.len() != size {
        return Err(format!(
            "its size field says {} bytes uncompressed, its data holds {}",
            byte_count(size as u64),
            byte_count(opened.len() as u64)
        ));
    }
    Ok(opened)
}

/// Frames every record of an opened chunk and reads its header, or says
/// why it cannot.
fn chunk_records(mut records: &[u8]) -> Result<Vec<(Header<'_>, &[u8])>, String> {
    let mut out = Vec::new();
    let mut offset = 0u64;
    while !records.is_empty() {
        let past_end = || {
            format!(
                "the record at byte {} of its data runs past the chunk's end",
                byte_count(offset)
            )
        };
        let len = match record_extent(records, offset)
            .map_err(|e| format!("{} of its data: {}", e.record, e.message))?
        {
            Extent::Whole(len) if len <= records.len() => len,
            _ => return Err(past_end()),
        };
        let (record, rest) = records.split_at(len);
        let (header_bytes, data) = split_record(record);
        let header = parse_header(header_bytes, "").map_err(|e| {
            format!(
                "the record at byte {} of its data: {}",
                byte_count(offset),
                e.message
            )
        })?;
        out.push((header, data));
        records = rest;
        offset += len as u64;
    }
    Ok(out)
}

/// Decompresses a chunk expected to give `size` bytes; reads at most one
/// byte more, so a chunk that would give far more is caught without
/// holding it.
fn inflate(reader: impl Read, size: usize, name: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(size.min(64 << 20));
    reader
        .take(size as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("its {name} data cannot be decompressed: {e}"))?;
    Ok(out)
}
