//! # ROS bags: the recordings roboticists make today
//!
//! Three containers hold ROS messages on disk:
//!
//! | container | module | what it is |
//! |---|---|---|
//! | ROS 1 bag, format 2.0 (`.bag`) | `ros1` | records with a header of `name=value` fields; chunks, uncompressed, bz2 or lz4 |
//! | MCAP (`.mcap`, ROS 2's default since Iron) | `mcap` | records with an opcode; chunks, uncompressed, zstd or lz4 |
//! | rosbag2 SQLite (`.db3`, Humble's default) | `sqlite`, `rosbag2` | a `topics` and a `messages` table in an SQLite file, `metadata.yaml` beside it |
//!
//! Every container is read the same way, as a stream: the caller pushes the
//! file's bytes in pieces, in order ([`BagReader::push`]), and the reader
//! hands each complete message to a [`MessageSink`] as soon as it can, then
//! forgets its bytes. So a page can read a 200 MB bag from a `File` in
//! slices without ever holding it whole, and the command line reads a file
//! the same way. At the end ([`BagReader::finish`]) the reader says what,
//! if anything, was incomplete (a file cut inside a chunk keeps every
//! message of the chunks before it).
//!
//! The messages themselves (`messages`) are decoded from either encoding —
//! ROS 1 serialisation or ROS 2's CDR — into one set of plain structs, so
//! what follows never knows which container or encoding a message came in.

pub mod mcap;
pub mod messages;
pub mod recording;
pub mod ros1;
pub mod rosbag2;
pub mod sqlite;
mod stream;

use std::fmt;

/// The containers [`sniff`] tells apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// A ROS 1 bag (`#ROSBAG V2.0`, or the older `#ROSRECORD V1.2`, which
    /// [`ros1::Ros1Reader`] refuses with a message saying what it is).
    Ros1,
    /// An MCAP file (`\x89MCAP0\r\n`).
    Mcap,
    /// An SQLite database (`SQLite format 3\0`): a rosbag2 `.db3`.
    Sqlite,
}

/// Which container a file is, from its first bytes (16 are enough), so a
/// caller picks the reader by content rather than by file name. `None`
/// when the bytes are none of these, or too few to tell.
pub fn sniff(first_bytes: &[u8]) -> Option<Container> {
    if first_bytes.starts_with(b"#ROSBAG V") || first_bytes.starts_with(b"#ROSRECORD V") {
        Some(Container::Ros1)
    } else if first_bytes.starts_with(self::mcap::MAGIC) {
        Some(Container::Mcap)
    } else if first_bytes.starts_with(b"SQLite format 3\0") {
        Some(Container::Sqlite)
    } else {
        None
    }
}

/// How a message's bytes are serialised.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// ROS 1 serialisation: little-endian, packed, `u32` lengths.
    Ros1,
    /// ROS 2's CDR (OMG XTypes, encapsulation header first), aligned.
    Cdr,
    /// Anything else (an MCAP channel of JSON or protobuf, say): listed,
    /// counted, never decoded.
    Other(String),
}

/// One topic of a bag: a ROS 1 connection, an MCAP channel, a rosbag2
/// topic.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    /// The container's own id of the topic (connection id, channel id,
    /// topic row id); messages name their topic by it.
    pub id: u32,
    /// The topic's name, e.g. `/scan`.
    pub name: String,
    /// The message type without ROS 2's `/msg/`: `sensor_msgs/LaserScan`
    /// whether the bag says `sensor_msgs/LaserScan` (ROS 1) or
    /// `sensor_msgs/msg/LaserScan` (ROS 2).
    pub msg_type: String,
    pub encoding: Encoding,
}

/// One message as the container holds it.
#[derive(Clone, Copy, Debug)]
pub struct RawMessage<'a> {
    /// The [`Topic::id`] of its topic.
    pub topic: u32,
    /// When it was recorded (ns since the epoch, or since the simulator's
    /// start), the container's own time; not the message's `header.stamp`.
    pub log_time_ns: u64,
    /// The serialised message.
    pub data: &'a [u8],
    /// Where it is, for messages about it: "chunk 12 at byte 1,234,567",
    /// "message row 4711".
    pub record: &'a str,
}

/// What a reader hands its messages to.
pub trait MessageSink {
    /// A topic became known. Called once per topic, before any of its
    /// messages.
    fn topic(&mut self, topic: &Topic);
    /// One message; an error stops the read and is returned by `push` /
    /// `finish` as it is.
    fn message(&mut self, message: RawMessage<'_>) -> Result<(), BagError>;
}

/// A bag that cannot be read (or a message that cannot be decoded): where
/// and what. The caller prefixes the file's name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BagError {
    /// The record at fault ("chunk at byte 4,096", "the file header",
    /// "message row 17"); empty for the whole file.
    pub record: String,
    /// The topic, when the fault is a message's.
    pub topic: Option<String>,
    pub message: String,
}

impl BagError {
    pub fn new(record: impl Into<String>, message: impl Into<String>) -> BagError {
        BagError {
            record: record.into(),
            topic: None,
            message: message.into(),
        }
    }

    pub fn on_topic(mut self, topic: &str) -> BagError {
        self.topic = Some(topic.to_string());
        self
    }
}

impl fmt::Display for BagError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.topic, self.record.is_empty()) {
            (Some(t), false) => write!(f, "{}, topic {t}: {}", self.record, self.message),
            (Some(t), true) => write!(f, "topic {t}: {}", self.message),
            (None, false) => write!(f, "{}: {}", self.record, self.message),
            (None, true) => write!(f, "{}", self.message),
        }
    }
}

impl std::error::Error for BagError {}

/// What a reader says when the file has ended.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReadEnd {
    /// The container: "ROS 1 bag 2.0", "MCAP", "rosbag2 SQLite".
    pub container: String,
    /// The chunk compressions met, in order of first appearance ("none",
    /// "bz2", "lz4", "zstd").
    pub compression: Vec<String>,
    /// Chunks read whole.
    pub chunks: usize,
    /// What was lost, when the file was cut short or a part of it could
    /// not be read but what came before it could: e.g. "the file ends
    /// inside chunk 12 (byte 1,234,567 of 1,300,000): the messages of that
    /// chunk are lost". `None` when everything was read.
    pub lost: Option<String>,
}

/// A container read as a stream of bytes.
pub trait BagReader {
    /// The next bytes of the file, in order; complete messages go to `sink`.
    fn push(&mut self, bytes: &[u8], sink: &mut dyn MessageSink) -> Result<(), BagError>;
    /// The file has ended: hands over what is left and says what was lost.
    fn finish(&mut self, sink: &mut dyn MessageSink) -> Result<ReadEnd, BagError>;
}
