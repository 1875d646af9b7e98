//! # rosbag2's SQLite storage (`.db3`) and its `metadata.yaml`
//!
//! A rosbag2 recording is a folder: one or more storage files and a
//! `metadata.yaml` that lists them. With the `sqlite3` storage plugin (the
//! default until ROS 2 Iron, still common) each file is an SQLite 3
//! database, read here by [`super::sqlite`], with two tables that matter:
//!
//! * `topics(id INTEGER PRIMARY KEY, name, type, serialization_format,
//!   offered_qos_profiles, type_description_hash)` — one row per topic. The
//!   last two columns arrived later (Foxy and Iron): older files lack them,
//!   and only `id`, `name`, `type` and `serialization_format` are read, by
//!   column name. `type` is ROS 2's `sensor_msgs/msg/LaserScan`; the
//!   [`Topic`] says `sensor_msgs/LaserScan`. A `serialization_format` of
//!   `cdr` is [`Encoding::Cdr`], `ros1` (a bag converted from ROS 1 without
//!   re-encoding) [`Encoding::Ros1`], anything else is listed and not
//!   decoded.
//! * `messages(id INTEGER PRIMARY KEY, topic_id, timestamp, data)` — one
//!   row per message: the topic's row id, the time it was recorded (ns
//!   since the epoch) and the serialised message. Messages are handed over
//!   in `(timestamp, id)` order, the recording order; rows are stored in id
//!   order, which need not be the same (a bag converted or merged from
//!   others).
//!
//! Other tables (`schema`, `metadata`, `message_definitions`) are not read.
//! A file without a `messages` or `topics` table is not a rosbag2 bag, and
//! says so.
//!
//! ## Streaming, for a file that is random access
//!
//! [`Db3Reader`] implements [`BagReader`] like the other containers, but an
//! SQLite file is a b-tree whose pages point anywhere in the file, so no
//! message can be handed over before the whole file is there:
//! [`BagReader::push`] only collects the bytes, and [`BagReader::finish`]
//! reads the database and hands every message to the sink. Memory is the
//! file's size plus the overflowed messages' copies.
//!
//! ## A recording cut short: the WAL
//!
//! rosbag2 may run SQLite in write-ahead-log mode; a recorder killed before
//! it closed the bag leaves its last messages only in `<file>.db3-wal`.
//! Give that file's bytes too ([`Db3Reader::push_wal`]) and its committed
//! transactions are read; [`ReadEnd::lost`] says when the WAL ends with a
//! transaction that never committed (its messages are lost).
//!
//! ## Compression
//!
//! rosbag2 compresses with zstd either each message (`compression_mode:
//! MESSAGE`: every `data` is a zstd frame) or each whole file
//! (`compression_mode: FILE`: `x.db3.zstd`). Both are read (with the
//! pure-Rust `ruzstd`): a file that begins with zstd's magic number is
//! decompressed first, and the messages of a CDR topic that begin with it
//! are decompressed (a CDR message begins with `00 00` or `00 01`, so the
//! two cannot be confused). Given the metadata ([`Db3Reader::with_metadata`])
//! saying message compression, every message must be a zstd frame.
//!
//! ## `metadata.yaml`
//!
//! [`Metadata::parse`] reads versions 4 to 9 of the file written by
//! rosbag2 (`rosbag2_bagfile_information`): the storage plugin, the files,
//! the start and duration, the message count per topic and the
//! compression. Fields a version lacks are left empty (`offered_qos_profiles`
//! is a YAML string up to version 8 and a list from 9; it is not read).

use super::sqlite::{Database, Row, SqliteError, Table, Value};
use super::{BagError, BagReader, Encoding, MessageSink, RawMessage, ReadEnd, Topic};
use serde::Deserialize;
use std::borrow::Cow;
use std::fmt::Write;

/// The four bytes a zstd frame begins with.
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];

/// The most a zstd frame is allowed to decompress to (1 GiB): a bound on
/// memory against a damaged or hostile frame.
const MAX_DECOMPRESSED: u64 = 1 << 30;

/// rosbag2's `metadata.yaml`, the parts read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metadata {
    /// The file's format version (4 to 9 are known).
    pub version: u32,
    /// `sqlite3` or `mcap`.
    pub storage_identifier: String,
    /// The storage files, relative to the folder.
    pub relative_file_paths: Vec<String>,
    pub duration_ns: u64,
    pub starting_time_ns: i64,
    pub message_count: u64,
    pub topics: Vec<TopicCount>,
    /// `zstd` or empty.
    pub compression_format: String,
    /// `FILE`, `MESSAGE`, or empty (none).
    pub compression_mode: String,
    /// From version 7; empty before.
    pub ros_distro: String,
}

/// One entry of `topics_with_message_count`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TopicCount {
    pub name: String,
    /// Without ROS 2's `/msg/`, as [`Topic::msg_type`].
    pub msg_type: String,
    pub serialization_format: String,
    pub message_count: u64,
    /// From version 8; empty before.
    pub type_description_hash: String,
}

/// How each message's `data` is compressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MessageCompression {
    None,
    Zstd,
}

#[derive(Deserialize)]
struct RawFile {
    rosbag2_bagfile_information: Option<RawInfo>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct RawInfo {
    version: u32,
    storage_identifier: String,
    relative_file_paths: Vec<String>,
    duration: RawDuration,
    starting_time: RawTime,
    message_count: u64,
    topics_with_message_count: Vec<RawTopicCount>,
    compression_format: Option<String>,
    compression_mode: Option<String>,
    ros_distro: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct RawDuration {
    nanoseconds: u64,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct RawTime {
    nanoseconds_since_epoch: i64,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct RawTopicCount {
    topic_metadata: RawTopic,
    message_count: u64,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct RawTopic {
    name: String,
    #[serde(rename = "type")]
    msg_type: String,
    serialization_format: String,
    type_description_hash: Option<String>,
}

impl Metadata {
    /// Parses a `metadata.yaml`.
    pub fn parse(text: &str) -> Result<Metadata, String> {
        let raw: RawFile =
            serde_yaml_ng::from_str(text).map_err(|e| format!("metadata.yaml: {e}"))?;
        let info = raw
            .rosbag2_bagfile_information
            .ok_or("metadata.yaml: no rosbag2_bagfile_information: not a rosbag2 metadata file")?;
        Ok(Metadata {
            version: info.version,
            storage_identifier: info.storage_identifier,
            relative_file_paths: info.relative_file_paths,
            duration_ns: info.duration.nanoseconds,
            starting_time_ns: info.starting_time.nanoseconds_since_epoch,
            message_count: info.message_count,
            topics: info
                .topics_with_message_count
                .into_iter()
                .map(|t| TopicCount {
                    name: t.topic_metadata.name,
                    msg_type: plain_type(&t.topic_metadata.msg_type),
                    serialization_format: t.topic_metadata.serialization_format,
                    message_count: t.message_count,
                    type_description_hash: t
                        .topic_metadata
                        .type_description_hash
                        .unwrap_or_default(),
                })
                .collect(),
            compression_format: info.compression_format.unwrap_or_default(),
            compression_mode: info.compression_mode.unwrap_or_default(),
            ros_distro: info.ros_distro.unwrap_or_default(),
        })
    }

    /// How each message is compressed: zstd with `MESSAGE` mode and the
    /// `zstd` format, none without a mode or in `FILE` mode (the file
    /// itself is compressed, which [`Db3Reader`] recognises). Another
    /// format is an error.
    pub fn message_compression(&self) -> Result<MessageCompression, String> {
        let mode = self.compression_mode.to_ascii_uppercase();
        let format = self.compression_format.as_str();
        match (mode.as_str(), format) {
            ("" | "NONE", _) => Ok(MessageCompression::None),
            (_, f) if !f.eq_ignore_ascii_case("zstd") => {
                Err(format!("compression format {f:?} is not read (only zstd)"))
            }
            ("FILE", _) => Ok(MessageCompression::None),
            ("MESSAGE", _) => Ok(MessageCompression::Zstd),
            (m, _) => Err(format!("compression mode {m:?} is not FILE or MESSAGE")),
        }
    }
}

/// A type name without ROS 2's `/msg/`.
fn plain_type(msg_type: &str) -> String {
    msg_type.replacen("/msg/", "/", 1)
}

/// Reads one rosbag2 `.db3` file (see the module doc: `push` collects,
/// `finish` reads).
#[derive(Default)]
pub struct Db3Reader {
    file: Vec<u8>,
    wal: Option<Vec<u8>>,
    /// From the metadata, when given.
    compression: Option<MessageCompression>,
}

impl Db3Reader {
    pub fn new() -> Db3Reader {
        Db3Reader::default()
    }

    /// Takes the bag's compression from its metadata.
    pub fn with_metadata(mut self, metadata: &Metadata) -> Result<Db3Reader, BagError> {
        let c = metadata
            .message_compression()
            .map_err(|e| BagError::new("metadata.yaml", e))?;
        self.compression = Some(c);
        Ok(self)
    }

    /// The next bytes of the database's `-wal` file, in order (call before
    /// `finish`).
    pub fn push_wal(&mut self, bytes: &[u8]) {
        self.wal
            .get_or_insert_with(Vec::new)
            .extend_from_slice(bytes);
    }
}

/// An SQLite error as the bag's: the page, or the file as a whole.
impl From<SqliteError> for BagError {
    fn from(e: SqliteError) -> BagError {
        match e.page {
            Some(p) => BagError::new(format!("page {p}"), e.message),
            None => BagError::new("", e.message),
        }
    }
}

/// Decompresses one zstd frame (or several in a row).
fn unzstd(data: &[u8]) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let mut decoder = ruzstd::decoding::StreamingDecoder::new(data)
        .map_err(|e| format!("not a valid zstd frame: {e}"))?;
    let mut out = Vec::new();
    (&mut decoder)
        .take(MAX_DECOMPRESSED + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("zstd: {e}"))?;
    if out.len() as u64 > MAX_DECOMPRESSED {
        return Err(format!(
            "zstd: decompresses to more than {MAX_DECOMPRESSED} bytes"
        ));
    }
    Ok(out)
}

/// One message row, before sorting.
struct MessageRow<'a> {
    timestamp: i64,
    id: i64,
    topic: u32,
    data: Cow<'a, [u8]>,
}

/// The column `name` of `table`, or an error naming what is missing.
fn column(table: &Table, name: &str) -> Result<usize, BagError> {
    table.column(name).ok_or_else(|| {
        BagError::new(
            "",
            format!(
                "table {} has no column {name}: not a rosbag2 bag (its columns: {})",
                table.name,
                table.columns.join(", ")
            ),
        )
    })
}

/// An integer column of a row, or an error naming the row.
fn integer(row: &Row<'_>, col: usize, table: &str, name: &str) -> Result<i64, BagError> {
    row.get(col).as_integer().ok_or_else(|| {
        BagError::new(
            format!("{table} row {}", row.rowid),
            format!("{name} is {}, not an integer", row.get(col).kind()),
        )
    })
}

/// Reads the `topics` table.
fn read_topics(db: &Database<'_>, table: &Table) -> Result<Vec<Topic>, BagError> {
    let (name_c, type_c, format_c) = (
        column(table, "name")?,
        column(table, "type")?,
        column(table, "serialization_format")?,
    );
    let id_c = column(table, "id")?;
    let rows = db.rows(table)?;
    let mut topics = Vec::with_capacity(rows.len());
    for row in &rows {
        let text = |col: usize, name: &str| {
            row.get(col).as_text().map(str::to_string).ok_or_else(|| {
                BagError::new(
                    format!("topic row {}", row.rowid),
                    format!("{name} is {}, not a text", row.get(col).kind()),
                )
            })
        };
        let id = integer(row, id_c, "topic", "id")?;
        let id = u32::try_from(id).map_err(|_| {
            BagError::new(
                format!("topic row {}", row.rowid),
                format!("id {id} is out of range"),
            )
        })?;
        let format = text(format_c, "serialization_format")?;
        topics.push(Topic {
            id,
            name: text(name_c, "name")?,
            msg_type: plain_type(&text(type_c, "type")?),
            encoding: match format.as_str() {
                "cdr" => Encoding::Cdr,
                "ros1" => Encoding::Ros1,
                _ => Encoding::Other(format),
            },
        });
    }
    topics.sort_by_key(|t| t.id);
    Ok(topics)
}

/// Reads the `messages` table: every row, sorted by (timestamp, id).
fn read_messages<'a>(db: &Database<'a>, table: &Table) -> Result<Vec<MessageRow<'a>>, BagError> {
    let (id_c, topic_c, time_c, data_c) = (
        column(table, "id")?,
        column(table, "topic_id")?,
        column(table, "timestamp")?,
        column(table, "data")?,
    );
    let mut rows = Vec::new();
    db.for_each_row(table, |mut row| -> Result<(), BagError> {
        let id = integer(&row, id_c, "message", "id")?;
        let topic = integer(&row, topic_c, "message", "topic_id")?;
        let timestamp = integer(&row, time_c, "message", "timestamp")?;
        let record = || format!("message row {id}");
        let topic = u32::try_from(topic)
            .map_err(|_| BagError::new(record(), format!("topic_id {topic} is out of range")))?;
        let data = match row.take(data_c) {
            Value::Blob(b) => b,
            Value::Text(Cow::Borrowed(t)) => Cow::Borrowed(t.as_bytes()),
            Value::Text(Cow::Owned(t)) => Cow::Owned(t.into_bytes()),
            v => {
                let m = format!("data is {}, not a blob", v.kind());
                return Err(BagError::new(record(), m));
            }
        };
        rows.push(MessageRow {
            timestamp,
            id,
            topic,
            data,
        });
        Ok(())
    })?;
    rows.sort_by_key(|m| (m.timestamp, m.id));
    Ok(rows)
}

impl Db3Reader {
    /// Reads the collected file and hands its messages to `sink`.
    fn read(&mut self, sink: &mut dyn MessageSink) -> Result<ReadEnd, BagError> {
        let mut compression = Vec::new();
        let file: Cow<'_, [u8]> = if self.file.starts_with(&ZSTD_MAGIC) {
            compression.push("zstd".to_string());
            Cow::Owned(unzstd(&self.file).map_err(|e| BagError::new("the compressed file", e))?)
        } else {
            Cow::Borrowed(&self.file)
        };
        let db = Database::open(&file, self.wal.as_deref())?;
        let not_a_bag = |what: &str| {
            BagError::new(
                "",
                format!("this is an SQLite file but not a rosbag2 bag: it has no {what} table"),
            )
        };
        let messages_table = db.table("messages").ok_or_else(|| not_a_bag("messages"))?;
        let topics_table = db.table("topics").ok_or_else(|| not_a_bag("topics"))?;
        let topics = read_topics(&db, topics_table)?;
        let messages = read_messages(&db, messages_table)?;
        for t in &topics {
            sink.topic(t);
        }
        let must_zstd = self.compression == Some(MessageCompression::Zstd);
        let mut record = String::new();
        let mut zstd_seen = false;
        for m in &messages {
            record.clear();
            let _ = write!(record, "message row {}", m.id);
            let topic = topics
                .binary_search_by_key(&m.topic, |t| t.id)
                .ok()
                .and_then(|i| topics.get(i))
                .ok_or_else(|| {
                    BagError::new(
                        record.clone(),
                        format!("topic_id {} is not in the topics table", m.topic),
                    )
                })?;
            let log_time_ns = u64::try_from(m.timestamp).map_err(|_| {
                BagError::new(
                    record.clone(),
                    format!("negative timestamp {}", m.timestamp),
                )
                .on_topic(&topic.name)
            })?;
            let framed = m.data.starts_with(&ZSTD_MAGIC);
            if must_zstd && !framed {
                return Err(BagError::new(
                    record.clone(),
                    "the metadata says each message is zstd-compressed, this one is not",
                )
                .on_topic(&topic.name));
            }
            let unpacked;
            let data: &[u8] = if must_zstd || (framed && topic.encoding == Encoding::Cdr) {
                zstd_seen = true;
                unpacked = unzstd(&m.data)
                    .map_err(|e| BagError::new(record.clone(), e).on_topic(&topic.name))?;
                &unpacked
            } else {
                &m.data
            };
            sink.message(RawMessage {
                topic: m.topic,
                log_time_ns,
                data,
                record: &record,
            })?;
        }
        if zstd_seen {
            compression.push("zstd".to_string());
        }
        if compression.is_empty() {
            compression.push("none".to_string());
        }
        compression.dedup();
        Ok(ReadEnd {
            container: "rosbag2 SQLite".to_string(),
            compression,
            chunks: 0,
            lost: db.wal_summary().and_then(wal_lost),
        })
    }
}

/// What a WAL says was lost: a transaction that never committed, or the
/// whole WAL when its header is damaged.
fn wal_lost(s: &super::sqlite::WalSummary) -> Option<String> {
    if let Some(why) = &s.ignored {
        return Some(format!(
            "the WAL file was ignored ({why}): messages only in it are lost"
        ));
    }
    (s.uncommitted_frames > 0).then(|| {
        format!(
            "the WAL ends with {} page(s) of a transaction that never committed \
             (the recorder stopped while writing): the messages in it are lost; \
             {} committed transaction(s) of the WAL were read",
            s.uncommitted_frames, s.transactions
        )
    })
}

impl BagReader for Db3Reader {
    /// Collects the bytes: an SQLite file is read when it is whole.
    fn push(&mut self, bytes: &[u8], _sink: &mut dyn MessageSink) -> Result<(), BagError> {
        self.file.extend_from_slice(bytes);
        Ok(())
    }

    fn finish(&mut self, sink: &mut dyn MessageSink) -> Result<ReadEnd, BagError> {
        let end = self.read(sink);
        self.file = Vec::new();
        self.wal = None;
        end
    }
}
