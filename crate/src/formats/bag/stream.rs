//! # The byte stream under the record containers
//!
//! A ROS 1 bag and an MCAP file are both a magic string followed by a
//! sequence of records, each of which says its own length up front: ROS 1
//! writes `header_len u32, header, data_len u32, data`, MCAP `opcode u8,
//! length u64, body`. A reader fed by [`super::BagReader::push`] receives
//! the file in pieces that cut records anywhere, so both readers share this
//! machinery:
//!
//! * [`Records`] splits the pushed bytes into whole records. A record that
//!   lies whole inside one pushed piece is handed over in place, without a
//!   copy; one cut by a piece boundary is gathered in a buffer until it is
//!   complete. So the reader never holds more than the record being read,
//!   whatever the piece sizes. The container's own [`Extent`] function
//!   says how long a record is from its first bytes, and refuses lengths
//!   past a sane cap before any byte of the record is stored.
//! * [`Waiting`] keeps the messages that arrive before the record naming
//!   their topic (a ROS 1 connection, an MCAP channel), copied, until it
//!   arrives; what never gets one is reported as lost.
//! * [`byte_count`] and [`shown`] write positions and file starts in
//!   messages.

use super::{BagError, MessageSink, RawMessage};

/// The longest record header a reader accepts (ROS 1's headers are tens of
/// bytes; a longer one means a damaged length field).
pub const HEADER_LIMIT: u64 = 1 << 20;
/// The longest record a reader accepts; longer is a damaged length field,
/// refused before anything is allocated.
pub const RECORD_LIMIT: u64 = 1 << 30;
/// The most bytes of messages kept waiting for their topic's record.
pub const WAITING_LIMIT: usize = 256 << 20;

/// How long the record at the front of some bytes is, as far as those
/// bytes tell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extent {
    /// The whole record is this many bytes.
    Whole(usize),
    /// At least this many bytes are needed to tell more.
    AtLeast(usize),
}

/// Whether to go on after a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    Continue,
    /// The records of interest are over: the rest of the file is ignored.
    Stop,
}

/// Splits a pushed byte stream into whole records.
#[derive(Debug, Default)]
pub struct Records {
    /// The start of a record cut by a piece boundary, gathered so far.
    buf: Vec<u8>,
    /// The file offset of the record being gathered (or of the next one).
    start: u64,
    /// Set once a record said [`Flow::Stop`].
    stopped: bool,
}

impl Records {
    /// Records that begin at file offset `start` (after the magic).
    pub fn starting_at(start: u64) -> Records {
        Records {
            buf: Vec::new(),
            start,
            stopped: false,
        }
    }

    /// The file offset of the record being gathered, or of the next one.
    pub fn start(&self) -> u64 {
        self.start
    }

    /// The bytes of an incomplete record gathered so far (empty between
    /// records).
    pub fn tail(&self) -> &[u8] {
        &self.buf
    }

    /// Hands every record completed by `input` to `each(record, offset)`,
    /// in order; keeps the start of an incomplete one. `extent(bytes,
    /// offset)` measures the record at the front of `bytes`.
    pub fn feed(
        &mut self,
        mut input: &[u8],
        extent: impl Fn(&[u8], u64) -> Result<Extent, BagError>,
        mut each: impl FnMut(&[u8], u64) -> Result<Flow, BagError>,
    ) -> Result<(), BagError> {
        while !input.is_empty() && !self.stopped {
            if self.buf.is_empty() {
                // Whole records inside the piece are read in place.
                if let Extent::Whole(len) = extent(input, self.start)? {
                    if let Some((record, rest)) = input.split_at_checked(len) {
                        let at = self.start;
                        self.start += len as u64;
                        input = rest;
                        self.stopped = each(record, at)? == Flow::Stop;
                        continue;
                    }
                }
            }
            let need = match extent(&self.buf, self.start)? {
                Extent::Whole(len) | Extent::AtLeast(len) => len,
            };
            let take = need.saturating_sub(self.buf.len()).min(input.len());
            if take == 0 {
                // An extent that asks for no more bytes than it has would
                // never finish; it is the reader's fault, not the file's.
                return Err(BagError::new(
                    "",
                    format!(
                        "a record at byte {} cannot be measured",
                        byte_count(self.start)
                    ),
                ));
            }
            self.buf.extend_from_slice(&input[..take]);
            input = &input[take..];
            if let Extent::Whole(len) = extent(&self.buf, self.start)? {
                if self.buf.len() == len {
                    let record = std::mem::take(&mut self.buf);
                    let at = self.start;
                    self.start += len as u64;
                    let flow = each(&record, at);
                    // Keep the allocation for the next cut record.
                    self.buf = record;
                    self.buf.clear();
                    self.stopped = flow? == Flow::Stop;
                }
            }
        }
        Ok(())
    }
}

/// A message whose topic is not known yet.
#[derive(Debug)]
struct WaitingMessage {
    topic: u32,
    log_time_ns: u64,
    data: Vec<u8>,
    record: String,
}

/// Messages kept until the record naming their topic arrives.
#[derive(Debug, Default)]
pub struct Waiting {
    messages: Vec<WaitingMessage>,
    bytes: usize,
}

impl Waiting {
    /// Keeps a copy of `message` until its topic is known. `topic_record`
    /// names the record it waits for ("connection", "channel").
    pub fn keep(&mut self, message: RawMessage<'_>, topic_record: &str) -> Result<(), BagError> {
        self.bytes += message.data.len();
        if self.bytes > WAITING_LIMIT {
            return Err(BagError::new(
                message.record,
                format!(
                    "more than {} MiB of messages wait for {topic_record} records that have not come \
                     (the message here is for {topic_record} {}): the file is damaged",
                    WAITING_LIMIT >> 20,
                    message.topic
                ),
            ));
        }
        self.messages.push(WaitingMessage {
            topic: message.topic,
            log_time_ns: message.log_time_ns,
            data: message.data.to_vec(),
            record: message.record.to_string(),
        });
        Ok(())
    }

    /// Hands the messages waiting for `topic` to `sink`, in the order they
    /// came, and forgets them.
    pub fn release(&mut self, topic: u32, sink: &mut dyn MessageSink) -> Result<(), BagError> {
        if !self.messages.iter().any(|m| m.topic == topic) {
            return Ok(());
        }
        let (mine, others): (Vec<_>, Vec<_>) = std::mem::take(&mut self.messages)
            .into_iter()
            .partition(|m| m.topic == topic);
        self.messages = others;
        for m in mine {
            self.bytes -= m.data.len();
            sink.message(RawMessage {
                topic: m.topic,
                log_time_ns: m.log_time_ns,
                data: &m.data,
                record: &m.record,
            })?;
        }
        Ok(())
    }

    /// What is lost when the file ends with messages still waiting:
    /// "3 messages of connection 7 never got their connection record: they
    /// are lost".
    pub fn lost(&self, topic_record: &str) -> Option<String> {
        if self.messages.is_empty() {
            return None;
        }
        let mut topics: Vec<u32> = self.messages.iter().map(|m| m.topic).collect();
        topics.sort_unstable();
        topics.dedup();
        let ids: Vec<String> = topics.iter().map(u32::to_string).collect();
        let n = self.messages.len();
        Some(format!(
            "{n} message{} of {topic_record}{} {} never got {} {topic_record} record: {} lost",
            if n == 1 { "" } else { "s" },
            if topics.len() == 1 { "" } else { "s" },
            ids.join(", "),
            if topics.len() == 1 { "its" } else { "their" },
            if n == 1 { "it is" } else { "they are" },
        ))
    }
}

/// A byte count or offset with thousands separators: `1,234,567`.
pub fn byte_count(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A record's label in messages: "the record at byte 4,117".
pub fn record_at(at: u64) -> String {
    format!("the record at byte {}", byte_count(at))
}

/// Bytes as a quoted string for a message: printable ASCII as it is,
/// anything else as `\xNN` (`\n` as `\n`).
pub fn shown(bytes: &[u8]) -> String {
    let mut out = String::from("\"");
    for &b in bytes {
        match b {
            b'\n' => out.push_str("\\n"),
            b'\r' => out.push_str("\\r"),
            b'"' => out.push_str("\\\""),
            b'\\' => out.push_str("\\\\"),
            0x20..=0x7e => out.push(b as char),
            _ => out.push_str(&format!("\\x{b:02x}")),
        }
    }
    out.push('"');
    out
}

/// Reads a little-endian `u32` at `at`, if the bytes are there.
pub fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Reads a little-endian `u64` at `at`, if the bytes are there.
pub fn u64_at(bytes: &[u8], at: usize) -> Option<u64> {
    let b = bytes.get(at..at.checked_add(8)?)?;
    let mut a = [0u8; 8];
    a.copy_from_slice(b);
    Some(u64::from_le_bytes(a))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_have_thousands_separators() {
        assert_eq!(byte_count(0), "0");
        assert_eq!(byte_count(999), "999");
        assert_eq!(byte_count(1000), "1,000");
        assert_eq!(byte_count(1_234_567), "1,234,567");
    }

    #[test]
    fn shown_escapes_what_is_not_printable() {
        assert_eq!(shown(b"#ROS\n\x89\0"), "\"#ROS\\n\\x89\\x00\"");
    }

    /// Records of a toy container: a length byte, then that many bytes.
    fn toy_extent(bytes: &[u8], _at: u64) -> Result<Extent, BagError> {
        Ok(match bytes.first() {
            None => Extent::AtLeast(1),
            Some(&n) => Extent::Whole(1 + n as usize),
        })
    }

    #[test]
    fn records_are_whole_whatever_the_piece_sizes() {
        let stream = [2u8, 10, 11, 0, 3, 20, 21, 22, 1, 30];
        for piece in 1..=stream.len() {
            let mut records = Records::starting_at(100);
            let mut got = Vec::new();
            for part in stream.chunks(piece) {
                records
                    .feed(part, toy_extent, |r, at| {
                        got.push((at, r.to_vec()));
                        Ok(Flow::Continue)
                    })
                    .unwrap();
            }
            assert_eq!(
                got,
                vec![
                    (100, vec![2, 10, 11]),
                    (103, vec![0]),
                    (104, vec![3, 20, 21, 22]),
                    (108, vec![1, 30]),
                ],
                "pieces of {piece}"
            );
            assert!(records.tail().is_empty());
            assert_eq!(records.start(), 110);
        }
    }
}
