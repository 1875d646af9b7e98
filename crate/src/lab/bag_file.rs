//! # The bag session: a ROS bag read in pieces, then replayed or merged
//!
//! What `bag-info`, `run-log BAG` and "Your log…" drive. A bag is one file
//! (a ROS 1 `.bag`, an `.mcap`, a `.db3`) or a rosbag2 folder (its
//! `metadata.yaml` and one or more `.db3` / `.mcap` files, read in the
//! order the metadata lists them). The caller reads each file in pieces —
//! node from disk, the page's worker from a `File` in slices — and pushes
//! them in order ([`BagFile::push`]): the container is recognised from its
//! first bytes, whatever the file is called, and each complete message is
//! decoded into [`BagContents`] and forgotten, so a bag is never held
//! twice. At the end ([`BagFile::finish`]) the session knows every topic
//! and what, if anything, was lost; then it makes a laser log to replay
//! ([`BagFile::replay`], with the user's [`Picks`]) or hands a map topic
//! to the saved-maps merge ([`BagFile::map`]).
//!
//! Every error names the file, and where the bag says so the record and
//! the topic.

use super::log_replay::{BagSource, LogReplay};
use crate::formats::bag::mcap::McapReader;
pub use crate::formats::bag::recording::Picks;
use crate::formats::bag::recording::{BagContents, TopicInfo};
use crate::formats::bag::ros1::Ros1Reader;
use crate::formats::bag::rosbag2::{Db3Reader, Metadata};
use crate::formats::bag::{sniff, BagReader, Container, ReadEnd};
use crate::formats::rosmap::RosMap;
use serde::Serialize;

/// The file being read.
struct Reading {
    name: String,
    /// The first bytes, kept until there are enough to tell the container.
    head: Vec<u8>,
    reader: Option<Box<dyn BagReader>>,
    /// A `.db3-wal` file's bytes, for the `.db3` read next.
    wal: bool,
}

/// A bag being read, then read.
pub struct BagFile {
    name: String,
    metadata: Option<Metadata>,
    contents: BagContents,
    reading: Option<Reading>,
    /// The files read whole, with what each reader said at its end.
    files: Vec<(String, ReadEnd)>,
    /// A write-ahead log waiting for its `.db3`.
    wal: Option<Vec<u8>>,
    bytes: u64,
    finished: bool,
}

/// What `bag-info` prints.
#[derive(Clone, Debug, Serialize)]
pub struct BagInfo {
    pub name: String,
    pub files: Vec<String>,
    pub bytes: u64,
    /// "ROS 1 bag 2.0", "MCAP", "rosbag2 SQLite" (several, joined, for a
    /// folder of mixed files).
    pub container: String,
    pub compression: Vec<String>,
    pub chunks: usize,
    pub messages: u64,
    pub duration_s: f64,
    pub start_s: Option<f64>,
    pub end_s: Option<f64>,
    pub topics: Vec<TopicInfo>,
    /// What was lost (a file cut short), file by file.
    pub lost: Vec<String>,
    /// The `LaserScan` topics and the `OccupancyGrid` topics.
    pub scan_topics: Vec<String>,
    pub map_topics: Vec<String>,
}

impl BagFile {
    /// A bag called `name` (a file's or a folder's name, for messages).
    pub fn new(name: &str) -> BagFile {
        BagFile {
            name: name.to_string(),
            metadata: None,
            contents: BagContents::new(),
            reading: None,
            files: Vec::new(),
            wal: None,
            bytes: 0,
            finished: false,
        }
    }

    /// A rosbag2 folder's `metadata.yaml` (before its data files).
    pub fn set_metadata(&mut self, yaml: &str) -> Result<(), String> {
        let m = Metadata::parse(yaml).map_err(|e| format!("{}/metadata.yaml: {e}", self.name))?;
        self.metadata = Some(m);
        Ok(())
    }

    /// The data files a rosbag2 folder's metadata lists, in order (empty
    /// without metadata).
    pub fn metadata_files(&self) -> Vec<String> {
        self.metadata
            .as_ref()
            .map(|m| m.relative_file_paths.clone())
            .unwrap_or_default()
    }

    /// Starts the next file of the bag (its name, for messages and to
    /// tell a `.db3-wal` apart).
    pub fn begin_file(&mut self, file: &str) -> Result<(), String> {
        if self.finished {
            return Err(format!("{}: the bag has been read", self.name));
        }
        if self.reading.is_some() {
            self.end_file()?;
        }
        self.reading = Some(Reading {
            name: file.to_string(),
            head: Vec::new(),
            reader: None,
            wal: file.ends_with("-wal"),
        });
        Ok(())
    }

    /// The next bytes of the current file.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), String> {
        if self.reading.is_none() {
            let name = self.name.clone();
            self.begin_file(&name)?;
        }
        self.bytes += bytes.len() as u64;
        let Some(r) = self.reading.as_mut() else {
            return Ok(());
        };
        if r.wal {
            self.wal
                .get_or_insert_with(Vec::new)
                .extend_from_slice(bytes);
            return Ok(());
        }
        if r.reader.is_none() {
            r.head.extend_from_slice(bytes);
            if r.head.len() < 16 {
                return Ok(());
            }
            let head = std::mem::take(&mut r.head);
            let reader = self.reader_for(&head)?;
            let r = self.reading.as_mut().ok_or("no file")?;
            r.reader = Some(reader);
            return self.feed(&head);
        }
        self.feed(bytes)
    }

    fn feed(&mut self, bytes: &[u8]) -> Result<(), String> {
        let Some(r) = self.reading.as_mut() else {
            return Ok(());
        };
        let Some(reader) = r.reader.as_mut() else {
            return Ok(());
        };
        let name = &r.name;
        reader
            .push(bytes, &mut self.contents)
            .map_err(|e| format!("{name}: {e}"))
    }

    /// The reader for a file that starts with `head`.
    fn reader_for(&mut self, head: &[u8]) -> Result<Box<dyn BagReader>, String> {
        let name = self
            .reading
            .as_ref()
            .map(|r| r.name.clone())
            .unwrap_or_default();
        match sniff(head) {
            Some(Container::Ros1) => Ok(Box::new(Ros1Reader::new())),
            Some(Container::Mcap) => Ok(Box::new(McapReader::new())),
            // A zstd frame: a rosbag2 `.db3.zstd` (compression mode FILE),
            // which the SQLite reader decompresses.
            None if head.starts_with(&ZSTD_MAGIC) => self.db3_reader(&name),
            Some(Container::Sqlite) => self.db3_reader(&name),
            None => Err(format!(
                "{name}: not a ROS bag: neither a ROS 1 bag (#ROSBAG V2.0), an MCAP file nor a rosbag2 SQLite file; it starts with {}",
                printable(head)
            )),
        }
    }

    fn db3_reader(&mut self, name: &str) -> Result<Box<dyn BagReader>, String> {
        let mut reader = Db3Reader::new();
        if let Some(m) = &self.metadata {
            reader = reader
                .with_metadata(m)
                .map_err(|e| format!("{name}: {e}"))?;
        }
        if let Some(wal) = self.wal.take() {
            reader.push_wal(&wal);
        }
        Ok(Box::new(reader))
    }

    /// Ends the current file: its reader hands over what is left.
    pub fn end_file(&mut self) -> Result<(), String> {
        let Some(mut r) = self.reading.take() else {
            return Ok(());
        };
        if r.wal {
            return Ok(());
        }
        if r.reader.is_none() {
            if r.head.is_empty() {
                return Err(format!("{}: the file is empty", r.name));
            }
            let head = std::mem::take(&mut r.head);
            let name = r.name.clone();
            self.reading = Some(r);
            let reader = self.reader_for(&head)?;
            let mut r = self.reading.take().ok_or("no file")?;
            r.reader = Some(reader);
            if let Some(reader) = r.reader.as_mut() {
                reader
                    .push(&head, &mut self.contents)
                    .map_err(|e| format!("{name}: {e}"))?;
            }
            return self.close(r);
        }
        self.close(r)
    }

    fn close(&mut self, mut r: Reading) -> Result<(), String> {
        let Some(reader) = r.reader.as_mut() else {
            return Ok(());
        };
        let end = reader
            .finish(&mut self.contents)
            .map_err(|e| format!("{}: {e}", r.name))?;
        self.files.push((r.name, end));
        Ok(())
    }

    /// The bag has been read: every file ended. Refuses a bag with no
    /// file read.
    pub fn finish(&mut self) -> Result<BagInfo, String> {
        self.end_file()?;
        if self.files.is_empty() {
            return Err(format!(
                "{}: no bag file was read (a rosbag2 folder needs its .db3 or .mcap files)",
                self.name
            ));
        }
        self.finished = true;
        Ok(self.info())
    }

    /// What was read.
    pub fn info(&self) -> BagInfo {
        let mut container: Vec<String> = Vec::new();
        let mut compression: Vec<String> = Vec::new();
        let mut chunks = 0;
        let mut lost = Vec::new();
        for (file, end) in &self.files {
            if !container.contains(&end.container) {
                container.push(end.container.clone());
            }
            for c in &end.compression {
                if !compression.contains(c) {
                    compression.push(c.clone());
                }
            }
            chunks += end.chunks;
            if let Some(l) = &end.lost {
                lost.push(format!("{file}: {l}"));
            }
        }
        let c = &self.contents;
        BagInfo {
            name: self.name.clone(),
            files: self.files.iter().map(|(f, _)| f.clone()).collect(),
            bytes: self.bytes,
            container: container.join(" + "),
            compression,
            chunks,
            messages: c.messages,
            duration_s: c.duration_s(),
            start_s: c.topics.iter().filter_map(|t| t.first_s).reduce(f64::min),
            end_s: c.topics.iter().filter_map(|t| t.last_s).reduce(f64::max),
            topics: c.topics.clone(),
            lost,
            scan_topics: c.scan_topics().into_iter().map(|(t, _)| t).collect(),
            map_topics: c.map_topics(),
        }
    }

    fn read(&self) -> Result<(), String> {
        if self.finished {
            Ok(())
        } else {
            Err(format!("{}: the bag is still being read", self.name))
        }
    }

    /// A replay of the bag's scans, as `picks` asks.
    pub fn replay(&self, picks: &Picks) -> Result<LogReplay, String> {
        self.read()?;
        let log = self
            .contents
            .laser_log(picks)
            .map_err(|e| format!("{}: {e}", self.name))?;
        let info = self.info();
        let source = BagSource {
            file: self.name.clone(),
            container: info.container,
            compression: info.compression,
            lost: info.lost,
            picked: log.picked.clone(),
        };
        Ok(LogReplay::from_bag(log, source))
    }

    /// The last map of an `OccupancyGrid` topic (`None`: `/map`, else the
    /// only one), for the saved-maps merge.
    pub fn map(&self, topic: Option<&str>) -> Result<RosMap, String> {
        self.read()?;
        let topics = self.contents.map_topics();
        let topic = match topic {
            Some(t) => t.to_string(),
            None if topics.iter().any(|t| t == "/map") => "/map".to_string(),
            None if topics.len() == 1 => topics[0].clone(),
            None if topics.is_empty() => {
                return Err(format!(
                    "{}: no nav_msgs/OccupancyGrid topic in the bag",
                    self.name
                ))
            }
            None => {
                return Err(format!(
                    "{}: several OccupancyGrid topics and none is /map: {}",
                    self.name,
                    topics.join(", ")
                ))
            }
        };
        self.contents
            .map(&topic, &self.name)
            .map_err(|e| format!("{}: {e}", self.name))
    }
}

/// The first bytes of a zstd frame (a rosbag2 `.db3.zstd`).
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];

/// Which container a file is from its first bytes: `"ros1"`, `"mcap"`,
/// `"sqlite"` (also a zstd-compressed `.db3.zstd`), or `""` (not a bag: a
/// CARMEN log, say).
pub fn bag_kind(first_bytes: &[u8]) -> &'static str {
    match sniff(first_bytes) {
        Some(Container::Ros1) => "ros1",
        Some(Container::Mcap) => "mcap",
        Some(Container::Sqlite) => "sqlite",
        None if first_bytes.starts_with(&ZSTD_MAGIC) => "sqlite",
        None => "",
    }
}

/// The first bytes of a file as text a person can read.
fn printable(head: &[u8]) -> String {
    let text: String = head
        .iter()
        .take(16)
        .map(|&b| {
            if b.is_ascii_graphic() || b == b' ' {
                b as char
            } else {
                '.'
            }
        })
        .collect();
    format!("\"{text}\"")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_container_is_told_by_its_first_bytes() {
        assert_eq!(bag_kind(b"#ROSBAG V2.0\nxxxx"), "ros1");
        assert_eq!(bag_kind(b"#ROSRECORD V1.2\n"), "ros1");
        assert_eq!(bag_kind(b"\x89MCAP0\r\nxxxxxxxx"), "mcap");
        assert_eq!(bag_kind(b"SQLite format 3\0"), "sqlite");
        // rosbag2's compression mode FILE: a zstd-compressed .db3.
        assert_eq!(bag_kind(&[0x28, 0xb5, 0x2f, 0xfd, 0, 0, 0, 0]), "sqlite");
        assert_eq!(bag_kind(b"FLASER 180 1.0 2"), "");
        assert_eq!(bag_kind(&[0x1f, 0x8b, 8, 0]), "");
    }

    #[test]
    fn a_file_that_is_no_bag_is_named_with_its_first_bytes() {
        let mut bag = BagFile::new("x.bag");
        bag.begin_file("x.bag").expect("begins");
        let e = bag.push(b"hello, this is not a bag").unwrap_err();
        assert!(
            e.contains("x.bag: not a ROS bag") && e.contains("\"hello, this is n"),
            "{e}"
        );
        let mut empty = BagFile::new("e.bag");
        empty.begin_file("e.bag").expect("begins");
        assert!(empty.finish().unwrap_err().contains("the file is empty"));
    }
}
