//! The ROS 1 bag and MCAP readers on bags built here, record by record:
//! chunks uncompressed, bz2 and lz4 (ROS 1) or zstd and lz4 (MCAP), pushed
//! in pieces of 1 byte, 7 bytes and whole, must give the same topics,
//! messages, times and payload bytes; messages before their connection or
//! channel wait for it; a file cut inside a chunk keeps exactly the chunks
//! before it and says what was lost; a chunk whose size or CRC lies, or
//! whose data is damaged, is skipped and said lost, the chunks after it
//! read; unknown compressions, foreign and legacy files, and record
//! lengths that lie are refused with errors naming the record, never a
//! panic. Runs natively and in node (no file system).

use slamlab::formats::bag::mcap::McapReader;
use slamlab::formats::bag::ros1::Ros1Reader;
use slamlab::formats::bag::{
    sniff, BagError, BagReader, Container, Encoding, MessageSink, RawMessage, ReadEnd, Topic,
};
use std::io::Write;
use wasm_bindgen_test::wasm_bindgen_test;

// ---------------------------------------------------------------------------
// Collecting what a reader delivers

#[derive(Clone, Debug, PartialEq)]
struct Msg {
    topic: u32,
    time_ns: u64,
    data: Vec<u8>,
    record: String,
}

#[derive(Debug, Default, PartialEq)]
struct Collected {
    topics: Vec<Topic>,
    messages: Vec<Msg>,
}

impl MessageSink for Collected {
    fn topic(&mut self, topic: &Topic) {
        assert!(
            !self.topics.iter().any(|t| t.id == topic.id),
            "topic {} announced twice",
            topic.id
        );
        self.topics.push(topic.clone());
    }

    fn message(&mut self, m: RawMessage<'_>) -> Result<(), BagError> {
        assert!(
            self.topics.iter().any(|t| t.id == m.topic),
            "a message of topic {} before the topic",
            m.topic
        );
        self.messages.push(Msg {
            topic: m.topic,
            time_ns: m.log_time_ns,
            data: m.data.to_vec(),
            record: m.record.to_string(),
        });
        Ok(())
    }
}

type Outcome = Result<(Collected, ReadEnd), BagError>;

fn read_in_pieces(reader: &mut dyn BagReader, bytes: &[u8], piece: usize) -> Outcome {
    let mut sink = Collected::default();
    for part in bytes.chunks(piece) {
        reader.push(part, &mut sink)?;
    }
    let end = reader.finish(&mut sink)?;
    Ok((sink, end))
}

/// Reads `bytes` pushed in pieces of 1 byte, 7 bytes and whole; asserts
/// the three agree in everything, errors included; returns the outcome.
fn read_alike(new_reader: fn() -> Box<dyn BagReader>, bytes: &[u8]) -> Outcome {
    let whole = read_in_pieces(new_reader().as_mut(), bytes, bytes.len().max(1));
    for piece in [1, 7] {
        let got = read_in_pieces(new_reader().as_mut(), bytes, piece);
        assert_eq!(
            got, whole,
            "pieces of {piece} bytes differ from the whole file"
        );
    }
    whole
}

fn ros1_reader() -> Box<dyn BagReader> {
    Box::new(Ros1Reader::new())
}

fn mcap_reader() -> Box<dyn BagReader> {
    Box::new(McapReader::new())
}

/// `1234567` as `1,234,567`, as the readers write offsets.
fn commas(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A message's payload: its topic and number, and some binary bytes.
fn payload(topic: u32, i: usize) -> Vec<u8> {
    let mut p = format!("topic {topic} message {i};").into_bytes();
    p.extend((0..40 + i).map(|k| (k * 37 + i * 11) as u8));
    p
}

fn time_ns(i: usize) -> u64 {
    (1_600_000_000 + i as u64) * 1_000_000_000 + i as u64 * 1_000 + 7
}

fn compress(compression: &str, data: &[u8]) -> Vec<u8> {
    match compression {
        "bz2" => {
            let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::default());
            e.write_all(data).unwrap();
            e.finish().unwrap()
        }
        "lz4" => {
            // As roslz4 writes it: independent blocks, a content checksum.
            let info = lz4_flex::frame::FrameInfo::new()
                .block_mode(lz4_flex::frame::BlockMode::Independent)
                .content_checksum(true);
            let mut e = lz4_flex::frame::FrameEncoder::with_frame_info(info, Vec::new());
            e.write_all(data).unwrap();
            e.finish().unwrap()
        }
        "zstd" => {
            ruzstd::encoding::compress_to_vec(data, ruzstd::encoding::CompressionLevel::Fastest)
        }
        _ => data.to_vec(),
    }
}

// ---------------------------------------------------------------------------
// A tiny ROS 1 bag writer (format 2.0)

mod ros1w {
    pub const MAGIC: &[u8] = b"#ROSBAG V2.0\n";

    pub fn field(name: &str, value: &[u8]) -> Vec<u8> {
        let mut f = ((name.len() + 1 + value.len()) as u32)
            .to_le_bytes()
            .to_vec();
        f.extend_from_slice(name.as_bytes());
        f.push(b'=');
        f.extend_from_slice(value);
        f
    }

    pub fn record(fields: &[Vec<u8>], data: &[u8]) -> Vec<u8> {
        let header: Vec<u8> = fields.concat();
        let mut r = (header.len() as u32).to_le_bytes().to_vec();
        r.extend(header);
        r.extend((data.len() as u32).to_le_bytes());
        r.extend_from_slice(data);
        r
    }

    pub fn bag_header(index_pos: u64, conn_count: u32, chunk_count: u32) -> Vec<u8> {
        record(
            &[
                field("op", &[0x03]),
                field("index_pos", &index_pos.to_le_bytes()),
                field("conn_count", &conn_count.to_le_bytes()),
                field("chunk_count", &chunk_count.to_le_bytes()),
            ],
            &[b' '; 64],
        )
    }

    pub fn connection(conn: u32, topic: &str, msg_type: &str) -> Vec<u8> {
        let data = [
            field("topic", topic.as_bytes()),
            field("type", msg_type.as_bytes()),
            field("md5sum", b"0123456789abcdef0123456789abcdef"),
            field("message_definition", b"float32 x\n"),
        ]
        .concat();
        record(
            &[
                field("op", &[0x07]),
                field("conn", &conn.to_le_bytes()),
                field("topic", topic.as_bytes()),
            ],
            &data,
        )
    }

    pub fn message(conn: u32, time_ns: u64, data: &[u8]) -> Vec<u8> {
        let (sec, nsec) = (
            (time_ns / 1_000_000_000) as u32,
            (time_ns % 1_000_000_000) as u32,
        );
        let time = [sec.to_le_bytes(), nsec.to_le_bytes()].concat();
        record(
            &[
                field("op", &[0x02]),
                field("conn", &conn.to_le_bytes()),
                field("time", &time),
            ],
            data,
        )
    }

    /// A chunk record whose `size` field says `size` bytes.
    pub fn chunk_sized(compression: &str, size: usize, records: &[u8]) -> Vec<u8> {
        record(
            &[
                field("op", &[0x05]),
                field("compression", compression.as_bytes()),
                field("size", &(size as u32).to_le_bytes()),
            ],
            &super::compress(compression, records),
        )
    }

    pub fn chunk(compression: &str, records: &[u8]) -> Vec<u8> {
        chunk_sized(compression, records.len(), records)
    }

    pub fn index_data(conn: u32) -> Vec<u8> {
        record(
            &[
                field("op", &[0x04]),
                field("ver", &1u32.to_le_bytes()),
                field("conn", &conn.to_le_bytes()),
                field("count", &0u32.to_le_bytes()),
            ],
            &[],
        )
    }

    pub fn chunk_info(chunk_pos: u64) -> Vec<u8> {
        record(
            &[
                field("op", &[0x06]),
                field("ver", &1u32.to_le_bytes()),
                field("chunk_pos", &chunk_pos.to_le_bytes()),
                field("count", &0u32.to_le_bytes()),
            ],
            &[0; 8],
        )
    }
}

/// A ROS 1 bag as a recorder writes it.
struct Ros1Bag {
    bytes: Vec<u8>,
    expected: Vec<Msg>,
    /// Byte offset and length of each chunk record.
    chunks: Vec<(usize, usize)>,
}

/// The connections of [`ros1_bag`]: two publishers of `/scan` and one of
/// `/odom`.
const ROS1_CONNECTIONS: [(u32, &str, &str); 3] = [
    (0, "/scan", "sensor_msgs/LaserScan"),
    (1, "/odom", "nav_msgs/Odometry"),
    (2, "/scan", "sensor_msgs/LaserScan"),
];

/// A bag of one chunk per compression, four messages each; connections 0
/// and 1 are in the first chunk, connection 2 in the second; each chunk is
/// followed by index records, and the index section repeats the
/// connections and has a chunk info per chunk.
fn ros1_bag(compressions: &[&str]) -> Ros1Bag {
    let header_len = ros1w::bag_header(0, 0, 0).len();
    let mut body = Vec::new();
    let mut expected = Vec::new();
    let mut chunks = Vec::new();
    let mut n = 0;
    for (k, compression) in compressions.iter().enumerate() {
        let mut records = Vec::new();
        for &(conn, topic, ty) in &ROS1_CONNECTIONS {
            if (conn < 2 && k == 0) || (conn == 2 && k == 1) {
                records.extend(ros1w::connection(conn, topic, ty));
            }
        }
        let at = ros1w::MAGIC.len() + header_len + body.len();
        for j in 0..4 {
            let conn = if k == 0 { j % 2 } else { j % 3 } as u32;
            records.extend(ros1w::message(conn, time_ns(n), &payload(conn, n)));
            expected.push(Msg {
                topic: conn,
                time_ns: time_ns(n),
                data: payload(conn, n),
                record: format!("chunk {} at byte {}", k + 1, commas(at)),
            });
            n += 1;
        }
        let chunk = ros1w::chunk(compression, &records);
        chunks.push((at, chunk.len()));
        body.extend(chunk);
        for conn in 0..3 {
            body.extend(ros1w::index_data(conn));
        }
    }
    let index_pos = ros1w::MAGIC.len() + header_len + body.len();
    for &(conn, topic, ty) in &ROS1_CONNECTIONS {
        body.extend(ros1w::connection(conn, topic, ty));
    }
    for &(at, _) in &chunks {
        body.extend(ros1w::chunk_info(at as u64));
    }
    let mut bytes = ros1w::MAGIC.to_vec();
    bytes.extend(ros1w::bag_header(
        index_pos as u64,
        3,
        compressions.len() as u32,
    ));
    bytes.extend(body);
    Ros1Bag {
        bytes,
        expected,
        chunks,
    }
}

fn ros1_topics() -> Vec<Topic> {
    ROS1_CONNECTIONS
        .iter()
        .map(|&(id, name, ty)| Topic {
            id,
            name: name.into(),
            msg_type: ty.into(),
            encoding: Encoding::Ros1,
        })
        .collect()
}

// ---------------------------------------------------------------------------
// ROS 1 bags

#[wasm_bindgen_test(unsupported = test)]
fn ros1_chunks_none_bz2_lz4_read_alike_in_pieces_of_1_7_and_whole() {
    let bag = ros1_bag(&["none", "bz2", "lz4"]);
    let (got, end) = read_alike(ros1_reader, &bag.bytes).unwrap();
    assert_eq!(got.topics, ros1_topics());
    assert_eq!(got.messages.len(), 12);
    assert_eq!(got.messages, bag.expected);
    // Two connections share /scan and stay two topics.
    let per_topic: Vec<usize> = (0..3)
        .map(|id| got.messages.iter().filter(|m| m.topic == id).count())
        .collect();
    assert_eq!(per_topic, [6, 4, 2]);
    assert_eq!(
        end,
        ReadEnd {
            container: "ROS 1 bag 2.0".into(),
            compression: vec!["none".into(), "bz2".into(), "lz4".into()],
            chunks: 3,
            lost: None,
        }
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn ros1_messages_wait_for_a_connection_that_comes_later() {
    let mut bytes = ros1w::MAGIC.to_vec();
    bytes.extend(ros1w::bag_header(0, 0, 0));
    let outside_at = bytes.len();
    // A message outside any chunk, of a connection not yet seen.
    bytes.extend(ros1w::message(4, time_ns(0), &payload(4, 0)));
    let chunk1_at = bytes.len();
    let records1 = [
        ros1w::message(4, time_ns(1), &payload(4, 1)),
        ros1w::connection(0, "/scan", "sensor_msgs/LaserScan"),
        ros1w::message(0, time_ns(2), &payload(0, 2)),
        ros1w::message(9, time_ns(3), &payload(9, 3)),
    ]
    .concat();
    bytes.extend(ros1w::chunk("bz2", &records1));
    let chunk2_at = bytes.len();
    let records2 = [
        ros1w::connection(4, "/tf", "tf2_msgs/TFMessage"),
        ros1w::message(4, time_ns(4), &payload(4, 4)),
    ]
    .concat();
    bytes.extend(ros1w::chunk("none", &records2));

    let (got, end) = read_alike(ros1_reader, &bytes).unwrap();
    let ids: Vec<u32> = got.topics.iter().map(|t| t.id).collect();
    assert_eq!(ids, [0, 4]);
    assert_eq!(got.topics[1].name, "/tf");
    assert_eq!(got.topics[1].msg_type, "tf2_msgs/TFMessage");
    let order: Vec<(u32, u64)> = got.messages.iter().map(|m| (m.topic, m.time_ns)).collect();
    // Connection 0's message at once; connection 4's three when its record
    // comes, in the order they were written.
    assert_eq!(
        order,
        [
            (0, time_ns(2)),
            (4, time_ns(0)),
            (4, time_ns(1)),
            (4, time_ns(4))
        ]
    );
    assert_eq!(got.messages[1].data, payload(4, 0));
    assert_eq!(
        got.messages[1].record,
        format!("the record at byte {outside_at}")
    );
    assert_eq!(
        got.messages[2].record,
        format!("chunk 1 at byte {}", commas(chunk1_at))
    );
    assert_eq!(
        got.messages[3].record,
        format!("chunk 2 at byte {}", commas(chunk2_at))
    );
    assert_eq!(end.chunks, 2);
    assert_eq!(end.compression, ["bz2", "none"]);
    assert_eq!(
        end.lost.as_deref(),
        Some("1 message of connection 9 never got its connection record: it is lost")
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn ros1_bag_cut_inside_a_chunk_keeps_exactly_the_chunks_before() {
    let bag = ros1_bag(&["lz4", "bz2", "bz2"]);
    let (at, len) = bag.chunks[2];
    let cut = at + len / 2;
    let (got, end) = read_alike(ros1_reader, &bag.bytes[..cut]).unwrap();
    assert_eq!(got.messages, bag.expected[..8]);
    assert_eq!(got.topics, ros1_topics());
    assert_eq!(end.chunks, 2);
    assert_eq!(end.compression, ["lz4", "bz2"]);
    assert_eq!(
        end.lost,
        Some(format!(
            "the file ends inside chunk 3 at byte {} (it has {} of its {} bytes): \
             the messages of that chunk are lost",
            commas(at),
            commas(cut - at),
            commas(len)
        ))
    );

    // Cut between records, before the chunk: the bag header's index
    // position and chunk count tell that the rest is missing.
    let (got, end) = read_alike(ros1_reader, &bag.bytes[..at]).unwrap();
    assert_eq!(got.messages, bag.expected[..8]);
    let lost = end.lost.unwrap();
    assert!(
        lost.starts_with(&format!(
            "the file ends at byte {}, before the index",
            commas(at)
        )) && lost.contains("(2 of its 3 chunks read)"),
        "{lost}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn ros1_unknown_compression_is_refused_and_a_lying_size_skips_the_chunk() {
    let records = [
        ros1w::connection(0, "/scan", "sensor_msgs/LaserScan"),
        ros1w::message(0, time_ns(0), &payload(0, 0)),
    ]
    .concat();
    let next = [
        ros1w::connection(0, "/scan", "sensor_msgs/LaserScan"),
        ros1w::message(0, time_ns(1), &payload(0, 1)),
    ]
    .concat();
    let mut start = ros1w::MAGIC.to_vec();
    start.extend(ros1w::bag_header(0, 1, 2));
    let chunk_at = commas(start.len());

    let zip = [
        start.clone(),
        ros1w::chunk_sized("zip", records.len(), &records),
    ]
    .concat();
    let e = read_alike(ros1_reader, &zip).unwrap_err();
    assert_eq!(e.record, format!("chunk 1 at byte {chunk_at}"));
    assert!(
        e.message.contains("compression is \"zip\""),
        "{}",
        e.message
    );

    // The chunk whose size field lies is skipped and said lost; the chunk
    // after it is read.
    for compression in ["none", "bz2", "lz4"] {
        let lying = [
            start.clone(),
            ros1w::chunk_sized(compression, records.len() + 1, &records),
            ros1w::chunk(compression, &next),
        ]
        .concat();
        let (got, end) = read_alike(ros1_reader, &lying).unwrap();
        assert_eq!(got.messages.len(), 1, "{compression}");
        assert_eq!(got.messages[0].time_ns, time_ns(1), "{compression}");
        assert_eq!(got.messages[0].data, payload(0, 1), "{compression}");
        assert_eq!(end.chunks, 1, "{compression}");
        assert_eq!(
            end.lost,
            Some(format!(
                "chunk 1 at byte {chunk_at} is skipped, its messages lost: \
                 its size field says {} bytes uncompressed, its data holds {}",
                records.len() + 1,
                records.len()
            )),
            "{compression}"
        );
    }

    // Damaged bz2 data: skipped, said so.
    let mut bad_bz2 = ros1w::chunk("bz2", &records);
    let n = bad_bz2.len();
    bad_bz2[n - 20..n - 10].fill(0x55);
    let damaged = [start.clone(), bad_bz2, ros1w::chunk("none", &next)].concat();
    let (got, end) = read_alike(ros1_reader, &damaged).unwrap();
    assert_eq!(got.messages.len(), 1);
    assert_eq!(
        end.lost,
        Some(format!(
            "chunk 1 at byte {chunk_at} is skipped, its messages lost: \
             its bz2 data cannot be decompressed: bzip2: invalid data"
        ))
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn ros1_legacy_and_foreign_files_are_refused_by_their_first_line() {
    let mut legacy = b"#ROSRECORD V1.2\n".to_vec();
    legacy.extend(ros1w::record(&[ros1w::field("op", &[0x02])], &[]));
    let e = read_alike(ros1_reader, &legacy).unwrap_err();
    assert!(
        e.message.starts_with("a ROS 1 bag of the old format 1.2")
            && e.message.contains("convert it to format 2.0"),
        "{}",
        e.message
    );

    let mcap = b"\x89MCAP0\r\n\x01\x00\x00\x00\x00\x00\x00\x00\x00".to_vec();
    let e = read_alike(ros1_reader, &mcap).unwrap_err();
    assert!(
        e.message
            .starts_with("not a ROS 1 bag (it starts with \"\\x89MCAP0\\r\\n"),
        "{}",
        e.message
    );

    let e = read_alike(ros1_reader, b"").unwrap_err();
    assert_eq!(e.message, "the file is empty: not a ROS 1 bag");
    let e = read_alike(ros1_reader, b"#ROSBAG V2").unwrap_err();
    assert!(
        e.message.starts_with("the file ends inside its first line"),
        "{}",
        e.message
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn ros1_lengths_that_lie_are_errors_or_losses_never_panics() {
    let magic = ros1w::MAGIC.to_vec();
    // A header field says 200 bytes inside a header of 10.
    let mut field_past = magic.clone();
    field_past.extend(11u32.to_le_bytes());
    field_past.extend(200u32.to_le_bytes());
    field_past.extend(b"op=\x03abc");
    field_past.extend(0u32.to_le_bytes());
    let e = read_alike(ros1_reader, &field_past).unwrap_err();
    assert_eq!(e.record, "the record at byte 13");
    assert_eq!(
        e.message,
        "a header field of 200 bytes runs past the header's end"
    );

    // A header said to be 2 MiB long, and data said to be 2 GiB.
    let mut huge_header = magic.clone();
    huge_header.extend((2u32 << 20).to_le_bytes());
    huge_header.extend([0; 32]);
    let e = read_alike(ros1_reader, &huge_header).unwrap_err();
    assert!(e.message.contains("more than 1 MiB"), "{}", e.message);
    let mut huge_data = magic.clone();
    huge_data.extend(ros1w::record(&[ros1w::field("op", &[0x02])], &[]));
    let n = huge_data.len();
    huge_data[n - 4..].copy_from_slice(&(2u32 << 30).to_le_bytes());
    let e = read_alike(ros1_reader, &huge_data).unwrap_err();
    assert!(e.message.contains("more than 1 GiB"), "{}", e.message);

    // A record inside a chunk runs past the chunk's end: the chunk is
    // skipped, said lost.
    let mut inner = ros1w::message(0, 0, &payload(0, 0));
    let n = inner.len();
    inner.truncate(n - 5);
    let mut past_chunk = magic.clone();
    past_chunk.extend(ros1w::chunk("bz2", &inner));
    let (got, end) = read_alike(ros1_reader, &past_chunk).unwrap();
    assert!(got.messages.is_empty());
    assert_eq!(
        end.lost.as_deref(),
        Some(
            "chunk 1 at byte 13 is skipped, its messages lost: \
             the record at byte 0 of its data runs past the chunk's end"
        )
    );

    // A record inside a chunk with a header said to be 2 MiB long.
    let mut huge_inner = magic.clone();
    huge_inner.extend(ros1w::chunk("lz4", &(2u32 << 20).to_le_bytes()));
    let (got, end) = read_alike(ros1_reader, &huge_inner).unwrap();
    assert!(got.messages.is_empty());
    assert_eq!(
        end.lost.as_deref(),
        Some(
            "chunk 1 at byte 13 is skipped, its messages lost: \
             the record at byte 0 of its data: its header is 2,097,152 bytes long, \
             more than 1 MiB: the file is damaged"
        )
    );

    // A record inside a chunk whose header field runs past its header.
    let mut bad_field = ros1w::connection(0, "/scan", "sensor_msgs/LaserScan");
    bad_field.extend(4u32.to_le_bytes());
    bad_field.extend(200u32.to_le_bytes());
    bad_field.extend(0u32.to_le_bytes());
    let mut field_in_chunk = magic.clone();
    field_in_chunk.extend(ros1w::chunk("none", &bad_field));
    let at = ros1w::connection(0, "/scan", "sensor_msgs/LaserScan").len();
    let (got, end) = read_alike(ros1_reader, &field_in_chunk).unwrap();
    assert!(
        got.topics.is_empty(),
        "nothing of a skipped chunk is handed over"
    );
    assert_eq!(
        end.lost,
        Some(format!(
            "chunk 1 at byte 13 is skipped, its messages lost: the record at byte {} \
             of its data: a header field of 200 bytes runs past the header's end",
            commas(at)
        ))
    );

    // A header length running past the end of the file: cut short.
    let mut header_past = magic.clone();
    header_past.extend(500u32.to_le_bytes());
    header_past.extend(ros1w::field("op", &[0x05]));
    let (got, end) = read_alike(ros1_reader, &header_past).unwrap();
    assert!(got.messages.is_empty());
    assert_eq!(
        end.lost.as_deref(),
        Some("the file ends inside the header of the record at byte 13 (it has 12 bytes)")
    );
}

// ---------------------------------------------------------------------------
// A tiny MCAP writer

mod mcapw {
    pub const MAGIC: &[u8] = b"\x89MCAP0\r\n";

    pub fn record(op: u8, body: &[u8]) -> Vec<u8> {
        let mut r = vec![op];
        r.extend((body.len() as u64).to_le_bytes());
        r.extend_from_slice(body);
        r
    }

    pub fn string(s: &str) -> Vec<u8> {
        let mut b = (s.len() as u32).to_le_bytes().to_vec();
        b.extend_from_slice(s.as_bytes());
        b
    }

    pub fn header() -> Vec<u8> {
        record(0x01, &[string("ros2"), string("slamlab tests")].concat())
    }

    pub fn schema(id: u16, name: &str, encoding: &str) -> Vec<u8> {
        let definition = b"float32 x\n";
        let mut body = id.to_le_bytes().to_vec();
        body.extend(string(name));
        body.extend(string(encoding));
        body.extend((definition.len() as u32).to_le_bytes());
        body.extend_from_slice(definition);
        record(0x03, &body)
    }

    pub fn channel(id: u16, schema_id: u16, topic: &str, encoding: &str) -> Vec<u8> {
        let mut body = id.to_le_bytes().to_vec();
        body.extend(schema_id.to_le_bytes());
        body.extend(string(topic));
        body.extend(string(encoding));
        body.extend(0u32.to_le_bytes());
        record(0x04, &body)
    }

    pub fn message(channel: u16, sequence: u32, time_ns: u64, data: &[u8]) -> Vec<u8> {
        let mut body = channel.to_le_bytes().to_vec();
        body.extend(sequence.to_le_bytes());
        body.extend(time_ns.to_le_bytes());
        body.extend(time_ns.to_le_bytes());
        body.extend_from_slice(data);
        record(0x05, &body)
    }

    /// A chunk record whose header says `size` bytes uncompressed and CRC
    /// `crc` (`None`: the records' true CRC).
    pub fn chunk_with(compression: &str, size: usize, crc: Option<u32>, records: &[u8]) -> Vec<u8> {
        let compressed = super::compress(compression, records);
        let mut body = 0u64.to_le_bytes().to_vec();
        body.extend(u64::MAX.to_le_bytes());
        body.extend((size as u64).to_le_bytes());
        body.extend(
            crc.unwrap_or_else(|| crc32fast::hash(records))
                .to_le_bytes(),
        );
        body.extend(string(if compression == "none" {
            ""
        } else {
            compression
        }));
        body.extend((compressed.len() as u64).to_le_bytes());
        body.extend(compressed);
        record(0x06, &body)
    }

    pub fn chunk(compression: &str, records: &[u8]) -> Vec<u8> {
        chunk_with(compression, records.len(), None, records)
    }

    pub fn message_index(channel: u16) -> Vec<u8> {
        let mut body = channel.to_le_bytes().to_vec();
        body.extend(16u32.to_le_bytes());
        body.extend([0; 16]);
        record(0x07, &body)
    }

    pub fn data_end() -> Vec<u8> {
        record(0x0F, &0u32.to_le_bytes())
    }

    pub fn footer() -> Vec<u8> {
        record(0x02, &[0; 20])
    }
}

struct McapFile {
    bytes: Vec<u8>,
    expected: Vec<Msg>,
    /// Byte offset and length of each chunk record.
    chunks: Vec<(usize, usize)>,
}

/// Schemas and channels of [`mcap_file`]: a ROS 2 scan and odometry in
/// CDR, a JSON channel without a schema, a ROS 1 string.
fn mcap_definitions() -> Vec<u8> {
    [
        mcapw::schema(1, "sensor_msgs/msg/LaserScan", "ros2msg"),
        mcapw::channel(1, 1, "/scan", "cdr"),
        mcapw::schema(2, "nav_msgs/msg/Odometry", "ros2msg"),
        mcapw::channel(2, 2, "/odom", "cdr"),
        mcapw::channel(3, 0, "/events", "json"),
        mcapw::schema(3, "std_msgs/String", "ros1msg"),
        mcapw::channel(4, 3, "/chatter", "ros1"),
    ]
    .concat()
}

fn mcap_topics() -> Vec<Topic> {
    let t = |id, name: &str, ty: &str, encoding| Topic {
        id,
        name: name.into(),
        msg_type: ty.into(),
        encoding,
    };
    vec![
        t(1, "/scan", "sensor_msgs/LaserScan", Encoding::Cdr),
        t(2, "/odom", "nav_msgs/Odometry", Encoding::Cdr),
        t(3, "/events", "", Encoding::Other("json".into())),
        t(4, "/chatter", "std_msgs/String", Encoding::Ros1),
    ]
}

/// One chunk per compression, five messages each (the schemas and
/// channels in the first), message indexes after each chunk; then Data
/// End, a summary section if asked, the footer and the closing magic.
fn mcap_file(compressions: &[&str], summary: bool) -> McapFile {
    let mut bytes = [mcapw::MAGIC.to_vec(), mcapw::header()].concat();
    let mut expected = Vec::new();
    let mut chunks = Vec::new();
    let mut n = 0;
    for (k, compression) in compressions.iter().enumerate() {
        let mut records = if k == 0 {
            mcap_definitions()
        } else {
            Vec::new()
        };
        let at = bytes.len();
        for j in 0..5 {
            let channel = 1 + (j % 4) as u16;
            let data = payload(channel.into(), n);
            records.extend(mcapw::message(channel, n as u32, time_ns(n), &data));
            expected.push(Msg {
                topic: channel.into(),
                time_ns: time_ns(n),
                data,
                record: format!("chunk {} at byte {}", k + 1, commas(at)),
            });
            n += 1;
        }
        let chunk = mcapw::chunk(compression, &records);
        chunks.push((at, chunk.len()));
        bytes.extend(chunk);
        for channel in 1..=4 {
            bytes.extend(mcapw::message_index(channel));
        }
    }
    bytes.extend(mcapw::data_end());
    if summary {
        bytes.extend(mcap_definitions());
        bytes.extend(mcapw::record(0x0B, &[0; 46]));
    }
    bytes.extend(mcapw::footer());
    bytes.extend(mcapw::MAGIC);
    McapFile {
        bytes,
        expected,
        chunks,
    }
}

// ---------------------------------------------------------------------------
// MCAP

#[wasm_bindgen_test(unsupported = test)]
fn mcap_chunks_none_zstd_lz4_read_alike_with_or_without_summary() {
    for summary in [true, false] {
        let file = mcap_file(&["none", "zstd", "lz4"], summary);
        let (got, end) = read_alike(mcap_reader, &file.bytes).unwrap();
        assert_eq!(got.topics, mcap_topics());
        assert_eq!(got.messages.len(), 15);
        assert_eq!(got.messages, file.expected);
        assert_eq!(
            end,
            ReadEnd {
                container: "MCAP".into(),
                compression: vec!["none".into(), "zstd".into(), "lz4".into()],
                chunks: 3,
                lost: None,
            },
            "summary {summary}"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn mcap_written_by_the_mcap_crate_reads_back() {
    for use_chunks in [true, false] {
        let mut writer = mcap::WriteOptions::new()
            .compression(None)
            .profile("ros2")
            .use_chunks(use_chunks)
            .chunk_size(Some(600))
            .create(std::io::Cursor::new(Vec::new()))
            .unwrap();
        let schema = writer
            .add_schema("sensor_msgs/msg/LaserScan", "ros2msg", b"float32 x")
            .unwrap();
        let channel = writer
            .add_channel(schema, "/scan", "cdr", &Default::default())
            .unwrap();
        for i in 0..20 {
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: i as u32,
                log_time: time_ns(i),
                publish_time: time_ns(i),
            };
            writer
                .write_to_known_channel(&header, &payload(1, i))
                .unwrap();
        }
        writer.finish().unwrap();
        let bytes = writer.into_inner().into_inner();
        let (got, end) = read_alike(mcap_reader, &bytes).unwrap();
        assert_eq!(got.topics.len(), 1);
        assert_eq!(got.topics[0].msg_type, "sensor_msgs/LaserScan");
        assert_eq!(got.topics[0].encoding, Encoding::Cdr);
        let sent: Vec<(u64, Vec<u8>)> = (0..20).map(|i| (time_ns(i), payload(1, i))).collect();
        let read: Vec<(u64, Vec<u8>)> = got
            .messages
            .iter()
            .map(|m| (m.time_ns, m.data.clone()))
            .collect();
        assert_eq!(read, sent, "use_chunks {use_chunks}");
        assert_eq!(end.lost, None);
        if use_chunks {
            assert!(end.chunks >= 3, "{} chunks of 600 bytes", end.chunks);
            assert_eq!(end.compression, ["none"]);
        } else {
            assert_eq!(end.chunks, 0);
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn mcap_cut_inside_a_chunk_keeps_exactly_the_chunks_before() {
    let file = mcap_file(&["zstd", "lz4", "zstd"], true);
    let (at, len) = file.chunks[2];
    let cut = at + len / 2;
    let (got, end) = read_alike(mcap_reader, &file.bytes[..cut]).unwrap();
    assert_eq!(got.messages, file.expected[..10]);
    assert_eq!(end.chunks, 2);
    assert_eq!(end.compression, ["zstd", "lz4"]);
    assert_eq!(
        end.lost,
        Some(format!(
            "the file ends inside chunk 3 at byte {} (it has {} of its {} bytes): \
             the messages of that chunk are lost",
            commas(at),
            commas(cut - at),
            commas(len)
        ))
    );

    let (got, end) = read_alike(mcap_reader, &file.bytes[..at]).unwrap();
    assert_eq!(got.messages, file.expected[..10]);
    assert_eq!(
        end.lost,
        Some(format!(
            "the file ends at byte {} without the Data End record that closes MCAP's data \
             section: it was cut short, and whatever followed is missing",
            commas(at)
        ))
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn mcap_chunk_whose_crc_or_size_lies_is_skipped_and_reported() {
    let good = mcap_file(&["none", "zstd", "lz4"], true);
    // Chunk 2's records, rebuilt with a wrong CRC, then a wrong size.
    let records: Vec<u8> = good.expected[5..10]
        .iter()
        .enumerate()
        .flat_map(|(j, m)| mcapw::message(m.topic as u16, 5 + j as u32, m.time_ns, &m.data))
        .collect();
    let true_crc = crc32fast::hash(&records);
    let (at, len) = good.chunks[1];
    let cases = [
        (
            mcapw::chunk_with("zstd", records.len(), Some(true_crc ^ 1), &records),
            format!(
                "its CRC-32 says 0x{:08x}, its data's is 0x{true_crc:08x}",
                true_crc ^ 1
            ),
        ),
        (
            mcapw::chunk_with("zstd", records.len() + 5, None, &records),
            format!(
                "its header says {} bytes uncompressed, its data holds {}",
                commas(records.len() + 5),
                commas(records.len())
            ),
        ),
        (
            mcapw::chunk_with("none", records.len(), Some(true_crc ^ 1), &records),
            format!(
                "its CRC-32 says 0x{:08x}, its data's is 0x{true_crc:08x}",
                true_crc ^ 1
            ),
        ),
    ];
    for (chunk, why) in cases {
        let bytes = [&good.bytes[..at], &chunk, &good.bytes[at + len..]].concat();
        let (got, end) = read_alike(mcap_reader, &bytes).unwrap();
        let kept: Vec<Msg> = [&good.expected[..5], &good.expected[10..]].concat();
        let kept_times: Vec<u64> = kept.iter().map(|m| m.time_ns).collect();
        let got_times: Vec<u64> = got.messages.iter().map(|m| m.time_ns).collect();
        assert_eq!(got_times, kept_times, "{why}");
        assert_eq!(got.messages[..5], kept[..5]);
        assert_eq!(end.chunks, 2);
        assert_eq!(
            end.lost,
            Some(format!(
                "chunk 2 at byte {} is skipped, its messages lost: {why}",
                commas(at)
            ))
        );
    }
}

/// An uncompressed chunk whose `compressed_size` stops inside its first
/// record (the rest of the record still inside the chunk's record length)
/// made the `mcap` crate's own LinearReader subtract past zero and panic;
/// here it is a chunk skipped.
#[wasm_bindgen_test(unsupported = test)]
fn mcap_uncompressed_chunk_shorter_than_its_records_is_skipped_not_a_panic() {
    let good = mcap_file(&["none", "none"], true);
    let (at, len) = good.chunks[1];
    let records: Vec<u8> = good.expected[5..]
        .iter()
        .flat_map(|m| mcapw::message(m.topic as u16, 0, m.time_ns, &m.data))
        .collect();
    let mut body = 0u64.to_le_bytes().to_vec();
    body.extend(0u64.to_le_bytes());
    body.extend((records.len() as u64).to_le_bytes());
    body.extend(0u32.to_le_bytes());
    body.extend(mcapw::string(""));
    body.extend(5u64.to_le_bytes());
    body.extend(&records);
    let short = mcapw::record(0x06, &body);
    let bytes = [&good.bytes[..at], &short, &good.bytes[at + len..]].concat();
    let (got, end) = read_alike(mcap_reader, &bytes).unwrap();
    assert_eq!(got.messages, good.expected[..5]);
    assert_eq!(end.chunks, 1);
    assert_eq!(
        end.lost,
        Some(format!(
            "chunk 2 at byte {} is skipped, its messages lost: its header says {} bytes \
             uncompressed, its data holds 5",
            commas(at),
            commas(records.len())
        ))
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn mcap_chunk_whose_record_length_lies_or_compression_is_unknown_is_an_error() {
    let good = mcap_file(&["none", "lz4", "zstd"], false);
    let (at, len) = good.chunks[1];
    // Chunk 2's record length three bytes too long: the next record is
    // read from inside chunk 3's length field.
    let mut longer = good.bytes.clone();
    longer[at + 1..at + 9].copy_from_slice(&((len - 9 + 3) as u64).to_le_bytes());
    let e = read_alike(mcap_reader, &longer).unwrap_err();
    assert_eq!(
        e.record,
        format!("the record at byte {}", commas(at + len + 3))
    );
    assert!(
        e.message
            .starts_with("opcode 0x00, which MCAP does not define"),
        "{}",
        e.message
    );

    let records = mcapw::message(1, 0, 0, b"x");
    let mut brotli = mcapw::chunk("none", &records);
    // The compression string's length and bytes sit after 28 bytes of
    // times, size and CRC; "" becomes "br".
    let mut body = brotli[9..37].to_vec();
    body.extend(mcapw::string("br"));
    body.extend_from_slice(&brotli[41..]);
    brotli = mcapw::record(0x06, &body);
    let bytes = [&good.bytes[..at], &brotli, &good.bytes[at + len..]].concat();
    let e = read_alike(mcap_reader, &bytes).unwrap_err();
    assert_eq!(e.record, format!("chunk 2 at byte {}", commas(at)));
    assert!(e.message.contains("compression is \"br\""), "{}", e.message);
}

#[wasm_bindgen_test(unsupported = test)]
fn mcap_refuses_other_files_by_their_magic() {
    let bag = ros1_bag(&["none"]);
    let e = read_alike(mcap_reader, &bag.bytes).unwrap_err();
    assert_eq!(
        e.message,
        "not an MCAP file (it starts with \"#ROSBAG \", not \"\\x89MCAP0\\r\\n\")"
    );
    let e = read_alike(mcap_reader, b"\x89MCA").unwrap_err();
    assert!(
        e.message.starts_with("the file ends inside MCAP's magic"),
        "{}",
        e.message
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn mcap_messages_wait_for_a_channel_that_comes_later() {
    let bytes = [
        mcapw::MAGIC.to_vec(),
        mcapw::header(),
        mcapw::message(5, 0, time_ns(0), &payload(5, 0)),
        mcapw::message(9, 1, time_ns(1), &payload(9, 1)),
        mcapw::schema(7, "geometry_msgs/msg/PoseStamped", "ros2msg"),
        mcapw::channel(5, 7, "/pose", "cdr"),
        mcapw::message(5, 2, time_ns(2), &payload(5, 2)),
        mcapw::data_end(),
        mcapw::footer(),
        mcapw::MAGIC.to_vec(),
    ]
    .concat();
    let first_message_at = mcapw::MAGIC.len() + mcapw::header().len();
    let (got, end) = read_alike(mcap_reader, &bytes).unwrap();
    assert_eq!(got.topics.len(), 1);
    assert_eq!(got.topics[0].msg_type, "geometry_msgs/PoseStamped");
    let times: Vec<u64> = got.messages.iter().map(|m| m.time_ns).collect();
    assert_eq!(times, [time_ns(0), time_ns(2)]);
    assert_eq!(got.messages[0].data, payload(5, 0));
    assert_eq!(
        got.messages[0].record,
        format!("the record at byte {first_message_at}")
    );
    assert_eq!(
        end.lost.as_deref(),
        Some("1 message of channel 9 never got its channel record: it is lost")
    );
}

/// A sink that refuses its third message.
#[derive(Default)]
struct Refusing {
    seen: usize,
}

impl MessageSink for Refusing {
    fn topic(&mut self, _: &Topic) {}

    fn message(&mut self, m: RawMessage<'_>) -> Result<(), BagError> {
        self.seen += 1;
        if self.seen == 3 {
            return Err(BagError::new(m.record, "refused by the sink").on_topic("/x"));
        }
        Ok(())
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_sink_error_stops_the_read_and_comes_back_as_it_is() {
    let ros1 = ros1_bag(&["bz2", "none"]);
    let mcap = mcap_file(&["zstd", "none"], true);
    let cases: [(Box<dyn BagReader>, &[u8], String); 2] = [
        (ros1_reader(), &ros1.bytes, ros1.expected[2].record.clone()),
        (mcap_reader(), &mcap.bytes, mcap.expected[2].record.clone()),
    ];
    for (mut reader, bytes, record) in cases {
        let mut sink = Refusing::default();
        let e = reader.push(bytes, &mut sink).unwrap_err();
        let expected = BagError::new(record, "refused by the sink").on_topic("/x");
        assert_eq!(e, expected);
        assert_eq!(sink.seen, 3, "no message after the refusal");
        assert_eq!(reader.push(b"more", &mut sink), Err(expected.clone()));
        assert_eq!(reader.finish(&mut sink), Err(expected));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn sniff_tells_the_containers_by_their_first_bytes() {
    assert_eq!(sniff(&ros1_bag(&["none"]).bytes), Some(Container::Ros1));
    assert_eq!(sniff(b"#ROSRECORD V1.2\n"), Some(Container::Ros1));
    assert_eq!(
        sniff(&mcap_file(&["none"], false).bytes),
        Some(Container::Mcap)
    );
    assert_eq!(sniff(b"SQLite format 3\0\x10\x00"), Some(Container::Sqlite));
    assert_eq!(sniff(b"SQLite format 2\0"), None);
    assert_eq!(sniff(b"\x89MCA"), None);
    assert_eq!(sniff(b"FLASER 180 1.0"), None);
}
