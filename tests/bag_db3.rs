//! The SQLite reader and the rosbag2 `.db3` reader on files written here,
//! by a minimal SQLite writer of the test's own (leaf pages, interior
//! pages of a chosen fan-out, overflow chains, a WAL): rows in rowid order
//! across interior pages, overflowed payloads byte-exact, every serial
//! type, messages in (timestamp, id) order, a WAL's committed transactions
//! applied and its torn or uncommitted ones not, old and new `topics`
//! tables, zstd compression per message and per file, `metadata.yaml`; and
//! damaged files (a page pointer out of range, a cycle in a b-tree or an
//! overflow chain, a cell past its page, a file cut short) refused with an
//! error naming the page, never a hang.
//!
//! The writer follows the file format document the reader follows
//! (<https://www.sqlite.org/fileformat2.html>); its output was checked with
//! the `sqlite3` shell (`PRAGMA integrity_check` is `ok`, the rows read
//! back) while the test was written.

use slamlab::formats::bag::rosbag2::{Db3Reader, MessageCompression, Metadata};
use slamlab::formats::bag::sqlite::{Database, Value};
use slamlab::formats::bag::{
    BagError, BagReader, Encoding, MessageSink, RawMessage, ReadEnd, Topic,
};
use std::borrow::Cow;
use wasm_bindgen_test::wasm_bindgen_test;

// ---------------------------------------------------------------- writer

/// A column value to write.
#[derive(Clone, Debug)]
enum V {
    Null,
    Int(i64),
    Real(f64),
    Text(String),
    Blob(Vec<u8>),
}

fn put_varint(out: &mut Vec<u8>, v: u64) {
    if v > 0x00ff_ffff_ffff_ffff {
        let mut b = [0u8; 9];
        b[8] = v as u8;
        let mut r = v >> 8;
        for x in b[..8].iter_mut().rev() {
            *x = (r & 0x7f) as u8 | 0x80;
            r >>= 7;
        }
        out.extend_from_slice(&b);
        return;
    }
    let mut groups = vec![(v & 0x7f) as u8];
    let mut r = v >> 7;
    while r > 0 {
        groups.push((r & 0x7f) as u8 | 0x80);
        r >>= 7;
    }
    groups.reverse();
    out.extend(groups);
}

/// A record: header (its length, serial types), then the values.
fn record(values: &[V]) -> Vec<u8> {
    let (mut types, mut body) = (Vec::new(), Vec::new());
    for v in values {
        match v {
            V::Null => put_varint(&mut types, 0),
            V::Int(0) => put_varint(&mut types, 8),
            V::Int(1) => put_varint(&mut types, 9),
            V::Int(i) => {
                let (serial, n) = match *i {
                    -128..=127 => (1, 1),
                    -32768..=32767 => (2, 2),
                    -8_388_608..=8_388_607 => (3, 3),
                    -2_147_483_648..=2_147_483_647 => (4, 4),
                    -140_737_488_355_328..=140_737_488_355_327 => (5, 6),
                    _ => (6, 8),
                };
                put_varint(&mut types, serial);
                body.extend_from_slice(&i.to_be_bytes()[8 - n..]);
            }
            V::Real(f) => {
                put_varint(&mut types, 7);
                body.extend_from_slice(&f.to_bits().to_be_bytes());
            }
            V::Text(s) => {
                put_varint(&mut types, 13 + 2 * s.len() as u64);
                body.extend_from_slice(s.as_bytes());
            }
            V::Blob(b) => {
                put_varint(&mut types, 12 + 2 * b.len() as u64);
                body.extend_from_slice(b);
            }
        }
    }
    let mut header_len = types.len() + 1;
    let mut head = Vec::new();
    loop {
        head.clear();
        put_varint(&mut head, header_len as u64);
        if head.len() + types.len() == header_len {
            break;
        }
        header_len = head.len() + types.len();
    }
    [head, types, body].concat()
}

/// Bytes of a table leaf cell's payload kept on the page (§1.6).
fn local_size(p: usize, u: usize) -> usize {
    let (x, m) = (u - 35, ((u - 12) * 32 / 255) - 23);
    let k = m + (p - m.min(p)) % (u - 4);
    if p <= x {
        p
    } else if k <= x {
        k
    } else {
        m
    }
}

/// A minimal SQLite writer: tables built bottom-up from sorted rows.
struct Writer {
    page_size: usize,
    /// Cells per interior page (at least 1): small values make deep trees.
    fanout: usize,
    pages: Vec<Vec<u8>>,
    tables: Vec<(String, u32, String)>,
    /// Every overflow chain written, its pages in order.
    chains: Vec<Vec<u32>>,
    /// Interior pages written.
    interiors: Vec<u32>,
    /// Leaf pages written, per table, in order.
    leaves: Vec<Vec<u32>>,
}

impl Writer {
    fn new(page_size: usize, fanout: usize) -> Writer {
        Writer {
            page_size,
            fanout,
            pages: vec![vec![0; page_size]],
            tables: Vec::new(),
            chains: Vec::new(),
            interiors: Vec::new(),
            leaves: Vec::new(),
        }
    }

    fn alloc(&mut self) -> u32 {
        self.pages.push(vec![0; self.page_size]);
        self.pages.len() as u32
    }

    fn leaf_cell(&mut self, rowid: i64, payload: &[u8]) -> Vec<u8> {
        let mut cell = Vec::new();
        put_varint(&mut cell, payload.len() as u64);
        put_varint(&mut cell, rowid as u64);
        let local = local_size(payload.len(), self.page_size);
        cell.extend_from_slice(&payload[..local]);
        if local < payload.len() {
            let first = self.overflow(&payload[local..]);
            cell.extend_from_slice(&first.to_be_bytes());
        }
        cell
    }

    fn overflow(&mut self, rest: &[u8]) -> u32 {
        let chunks: Vec<&[u8]> = rest.chunks(self.page_size - 4).collect();
        let chain: Vec<u32> = chunks.iter().map(|_| self.alloc()).collect();
        for (i, c) in chunks.iter().enumerate() {
            let next = chain.get(i + 1).copied().unwrap_or(0);
            let page = &mut self.pages[chain[i] as usize - 1];
            page[..4].copy_from_slice(&next.to_be_bytes());
            page[4..4 + c.len()].copy_from_slice(c);
        }
        self.chains.push(chain.clone());
        chain[0]
    }

    fn write_page(&mut self, n: u32, kind: u8, cells: &[Vec<u8>], right: Option<u32>) {
        let hdr = if n == 1 { 100 } else { 0 };
        let u = self.page_size;
        let page = &mut self.pages[n as usize - 1];
        let array = hdr + if right.is_some() { 12 } else { 8 };
        let mut content = u;
        for (i, c) in cells.iter().enumerate() {
            content -= c.len();
            page[content..content + c.len()].copy_from_slice(c);
            page[array + 2 * i..array + 2 * i + 2].copy_from_slice(&(content as u16).to_be_bytes());
        }
        assert!(array + 2 * cells.len() <= content, "page {n} overfull");
        page[hdr] = kind;
        page[hdr + 3..hdr + 5].copy_from_slice(&(cells.len() as u16).to_be_bytes());
        page[hdr + 5..hdr + 7].copy_from_slice(&((content % 65536) as u16).to_be_bytes());
        if let Some(r) = right {
            page[hdr + 8..hdr + 12].copy_from_slice(&r.to_be_bytes());
        }
    }

    /// Writes a table of rows sorted by rowid; returns its root page.
    fn table(&mut self, name: &str, sql: &str, rows: &[(i64, Vec<V>)]) -> u32 {
        let mut level: Vec<(u32, i64)> = Vec::new();
        let (mut cells, mut used, mut last) = (Vec::new(), 8, 0);
        let mut leaves = Vec::new();
        for (rowid, values) in rows {
            let cell = self.leaf_cell(*rowid, &record(values));
            if used + cell.len() + 2 > self.page_size && !cells.is_empty() {
                let p = self.alloc();
                self.write_page(p, 0x0d, &cells, None);
                level.push((p, last));
                leaves.push(p);
                cells.clear();
                used = 8;
            }
            used += cell.len() + 2;
            cells.push(cell);
            last = *rowid;
        }
        let p = self.alloc();
        self.write_page(p, 0x0d, &cells, None);
        level.push((p, last));
        leaves.push(p);
        self.leaves.push(leaves);
        while level.len() > 1 {
            // Groups of fanout + 1 children; a lone last child joins the
            // group before it, so every leaf is at the same depth.
            let mut groups: Vec<&[(u32, i64)]> = level.chunks(self.fanout + 1).collect();
            if groups.len() > 1 && groups.last().unwrap().len() == 1 {
                groups.pop();
                let n = groups.len() - 1;
                let start = n * (self.fanout + 1);
                groups[n] = &level[start..];
            }
            let mut next = Vec::new();
            for group in groups {
                let (right, max) = *group.last().unwrap();
                let cells: Vec<Vec<u8>> = group[..group.len() - 1]
                    .iter()
                    .map(|&(child, key)| {
                        let mut c = child.to_be_bytes().to_vec();
                        put_varint(&mut c, key as u64);
                        c
                    })
                    .collect();
                let p = self.alloc();
                self.write_page(p, 0x05, &cells, Some(right));
                self.interiors.push(p);
                next.push((p, max));
            }
            level = next;
        }
        let root = level[0].0;
        self.tables.push((name.to_string(), root, sql.to_string()));
        root
    }

    fn finish(&mut self) -> Vec<u8> {
        let rows: Vec<(i64, Vec<V>)> = self
            .tables
            .clone()
            .into_iter()
            .enumerate()
            .map(|(i, (name, root, sql))| {
                let t = |s: &str| V::Text(s.to_string());
                (
                    i as i64 + 1,
                    vec![t("table"), t(&name), t(&name), V::Int(root as i64), t(&sql)],
                )
            })
            .collect();
        let cells: Vec<Vec<u8>> = rows
            .iter()
            .map(|(id, v)| self.leaf_cell(*id, &record(v)))
            .collect();
        self.write_page(1, 0x0d, &cells, None);
        let ps = self.page_size;
        let count = self.pages.len() as u32;
        let h = &mut self.pages[0];
        h[..16].copy_from_slice(b"SQLite format 3\0");
        h[16..18].copy_from_slice(&((ps % 65536) as u16 | (ps / 65536) as u16).to_be_bytes());
        h[18] = 1;
        h[19] = 1;
        h[21..24].copy_from_slice(&[64, 32, 32]);
        h[24..28].copy_from_slice(&1u32.to_be_bytes());
        h[28..32].copy_from_slice(&count.to_be_bytes());
        h[44..48].copy_from_slice(&4u32.to_be_bytes());
        h[56..60].copy_from_slice(&1u32.to_be_bytes());
        h[92..96].copy_from_slice(&1u32.to_be_bytes());
        h[96..100].copy_from_slice(&3_040_001u32.to_be_bytes());
        self.pages.concat()
    }
}

/// The WAL checksum (§4.2), continuing from `s`.
fn checksum(big_endian: bool, data: &[u8], s: (u32, u32)) -> (u32, u32) {
    let (mut s0, mut s1) = s;
    for w in data.chunks(8) {
        let word = |b: &[u8]| {
            let a = [b[0], b[1], b[2], b[3]];
            if big_endian {
                u32::from_be_bytes(a)
            } else {
                u32::from_le_bytes(a)
            }
        };
        s0 = s0.wrapping_add(word(&w[..4])).wrapping_add(s1);
        s1 = s1.wrapping_add(word(&w[4..])).wrapping_add(s0);
    }
    (s0, s1)
}

/// One transaction for a WAL: a database's pages, committed or not.
struct Tx<'a> {
    db: &'a [u8],
    commit: bool,
}

/// A WAL holding every page of each transaction's database in turn.
fn wal(page_size: usize, big_endian: bool, salts: (u32, u32), txs: &[Tx]) -> Vec<u8> {
    let mut w = Vec::new();
    let magic: u32 = if big_endian { 0x377f_0683 } else { 0x377f_0682 };
    for v in [magic, 3_007_000, page_size as u32, 0, salts.0, salts.1] {
        w.extend_from_slice(&v.to_be_bytes());
    }
    let mut sum = checksum(big_endian, &w, (0, 0));
    w.extend_from_slice(&sum.0.to_be_bytes());
    w.extend_from_slice(&sum.1.to_be_bytes());
    for tx in txs {
        let pages: Vec<&[u8]> = tx.db.chunks(page_size).collect();
        for (i, page) in pages.iter().enumerate() {
            let last = i + 1 == pages.len();
            let size = if tx.commit && last {
                pages.len() as u32
            } else {
                0
            };
            let mut head = Vec::new();
            for v in [i as u32 + 1, size, salts.0, salts.1] {
                head.extend_from_slice(&v.to_be_bytes());
            }
            sum = checksum(big_endian, &head[..8], sum);
            sum = checksum(big_endian, page, sum);
            head.extend_from_slice(&sum.0.to_be_bytes());
            head.extend_from_slice(&sum.1.to_be_bytes());
            w.extend_from_slice(&head);
            w.extend_from_slice(page);
        }
    }
    w
}

// ---------------------------------------------------------------- bags

const TOPICS_OLD: &str = "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,\
    type TEXT NOT NULL,serialization_format TEXT NOT NULL)";
const TOPICS_NEW: &str = "CREATE TABLE topics(\n      id INTEGER PRIMARY KEY,\n      \
    name TEXT NOT NULL,\n      type TEXT NOT NULL,\n      serialization_format TEXT NOT NULL,\n      \
    offered_qos_profiles TEXT NOT NULL,\n      type_description_hash TEXT NOT NULL\n    )";
const MESSAGES: &str = "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,\
    timestamp INTEGER NOT NULL, data BLOB NOT NULL)";

/// A deterministic byte stream (xorshift).
fn noise(seed: u64, n: usize) -> Vec<u8> {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 24) as u8
        })
        .collect()
}

/// A message row: id, topic id, timestamp, data.
type Msg = (i64, i64, i64, Vec<u8>);

/// `n` messages on topics 1 (scan-sized, 1.5–3 KB) and 2 (small), with
/// timestamps out of id order and ties (rows 3k + 2 and 3k − 3).
fn messages(n: usize) -> Vec<Msg> {
    (1..=n as i64)
        .map(|id| {
            let topic = 1 + id % 2;
            let len = if topic == 1 {
                1500 + (id as usize * 97) % 1500
            } else {
                60 + id as usize % 40
            };
            let ts = 1_000_000_000 + (id / 3) * 1000 - (id % 3) * 500;
            (id, topic, ts, noise(id as u64, len))
        })
        .collect()
}

/// A rosbag2 database with two topics and `msgs`.
fn bag(w: &mut Writer, topics_sql: &str, msgs: &[Msg]) -> Vec<u8> {
    w.table(
        "schema",
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL)",
        &[(3, vec![V::Null, V::Text("humble".into())])],
    );
    let new = topics_sql.contains("offered_qos_profiles");
    let topic = |id: i64, name: &str, ty: &str, format: &str| {
        let mut v = vec![
            V::Null,
            V::Text(name.into()),
            V::Text(ty.into()),
            V::Text(format.into()),
        ];
        if new {
            v.push(V::Text("- history: 3\n  depth: 0".into()));
            v.push(V::Text("RIHS01_00".into()));
        }
        (id, v)
    };
    w.table(
        "topics",
        topics_sql,
        &[
            topic(1, "/scan", "sensor_msgs/msg/LaserScan", "cdr"),
            topic(2, "/odom", "nav_msgs/msg/Odometry", "cdr"),
        ],
    );
    let rows: Vec<(i64, Vec<V>)> = msgs
        .iter()
        .map(|(id, t, ts, d)| {
            (
                *id,
                vec![V::Null, V::Int(*t), V::Int(*ts), V::Blob(d.clone())],
            )
        })
        .collect();
    w.table("messages", MESSAGES, &rows);
    w.finish()
}

/// What a read handed over.
#[derive(Default)]
struct Got {
    topics: Vec<Topic>,
    /// (topic, time, data, record)
    messages: Vec<(u32, u64, Vec<u8>, String)>,
}

impl MessageSink for Got {
    fn topic(&mut self, topic: &Topic) {
        self.topics.push(topic.clone());
    }

    fn message(&mut self, m: RawMessage<'_>) -> Result<(), BagError> {
        self.messages.push((
            m.topic,
            m.log_time_ns,
            m.data.to_vec(),
            m.record.to_string(),
        ));
        Ok(())
    }
}

/// Reads a bag pushed in 1000-byte pieces.
fn read(reader: Db3Reader, file: &[u8]) -> Result<(Got, ReadEnd), BagError> {
    let mut reader = reader;
    let mut got = Got::default();
    for piece in file.chunks(1000) {
        reader.push(piece, &mut got)?;
    }
    let end = reader.finish(&mut got)?;
    Ok((got, end))
}

/// `msgs` in the order a reader must hand them over: (timestamp, id).
fn expected(msgs: &[Msg]) -> Vec<(u32, u64, Vec<u8>, String)> {
    let mut v: Vec<&Msg> = msgs.iter().collect();
    v.sort_by_key(|m| (m.2, m.0));
    v.iter()
        .map(|(id, t, ts, d)| {
            (
                *t as u32,
                *ts as u64,
                d.clone(),
                format!("message row {id}"),
            )
        })
        .collect()
}

fn read_err(file: &[u8]) -> String {
    match read(Db3Reader::new(), file) {
        Ok(_) => panic!("a damaged file was read"),
        Err(e) => e.to_string(),
    }
}

// ---------------------------------------------------------------- tests

#[wasm_bindgen_test(unsupported = test)]
fn rows_come_in_rowid_order_across_five_levels_of_interior_pages() {
    let mut w = Writer::new(512, 1);
    let rows: Vec<(i64, Vec<V>)> = (0..300)
        .map(|i| {
            (
                i * 7 - 1000,
                vec![
                    V::Int(i),
                    V::Text(format!("row {i} {}", "x".repeat(i as usize % 50))),
                ],
            )
        })
        .collect();
    w.table("t", "CREATE TABLE t(a INTEGER, b TEXT)", &rows);
    let file = w.finish();
    assert!(
        w.interiors.len() >= 20,
        "{} interior pages",
        w.interiors.len()
    );
    let db = Database::open(&file, None).unwrap();
    assert_eq!(db.header().page_size, 512);
    assert_eq!(db.header().page_count as usize, file.len() / 512);
    let t = db.table("T").unwrap();
    assert_eq!(t.columns, ["a", "b"]);
    let got = db.rows(t).unwrap();
    assert_eq!(got.len(), 300);
    for (i, r) in got.iter().enumerate() {
        assert_eq!(r.rowid, i as i64 * 7 - 1000);
        assert_eq!(r.get(0), &Value::Integer(i as i64));
        let text = format!("row {i} {}", "x".repeat(i % 50));
        assert_eq!(r.get(1).as_text(), Some(text.as_str()));
        assert_eq!(r.get(5), &Value::Null);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn overflowed_payloads_are_byte_exact_at_every_threshold() {
    // U = 1024: X = 989, M = 103; a record is the blob and 6 bytes or
    // less (header and the integer), so 986 bytes and more overflow.
    let sizes = [
        0usize,
        50,
        986,
        987,
        988,
        1500,
        1020 + 103 - 3,
        2100,
        3000,
        9000,
        70_000,
    ];
    for ps in [1024usize, 4096, 65536] {
        let mut w = Writer::new(ps, 4);
        let rows: Vec<(i64, Vec<V>)> = sizes
            .iter()
            .enumerate()
            .map(|(i, &n)| {
                (
                    i as i64 + 1,
                    vec![V::Blob(noise(n as u64, n)), V::Int(n as i64)],
                )
            })
            .collect();
        w.table("blobs", "CREATE TABLE blobs(data BLOB, n INTEGER)", &rows);
        let file = w.finish();
        if ps == 1024 {
            assert_eq!(w.chains.len(), 9, "overflow chains");
        }
        let db = Database::open(&file, None).unwrap();
        let got = db.rows(db.table("blobs").unwrap()).unwrap();
        assert_eq!(got.len(), sizes.len());
        for (r, &n) in got.iter().zip(&sizes) {
            assert_eq!(
                r.get(0).as_bytes().unwrap(),
                noise(n as u64, n),
                "{n} bytes, page {ps}"
            );
            assert_eq!(r.get(1), &Value::Integer(n as i64));
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn every_serial_type_reads_back() {
    let values = vec![
        V::Null,
        V::Int(0),
        V::Int(1),
        V::Int(-100),
        V::Int(-30_000),
        V::Int(8_000_000),
        V::Int(-2_000_000_000),
        V::Int(1 << 40),
        V::Int(i64::MIN),
        V::Real(-0.1),
        V::Text("héllo".into()),
        V::Blob(vec![0, 255, 7]),
        V::Int(3),
    ];
    let mut w = Writer::new(4096, 8);
    w.table(
        "v",
        "CREATE TABLE v(a,b,c,d,e,f,g,h,i,j REAL,k TEXT,l BLOB,m DOUBLE PRECISION)",
        &[(-5, values)],
    );
    let file = w.finish();
    let db = Database::open(&file, None).unwrap();
    let row = db.rows(db.table("v").unwrap()).unwrap().remove(0);
    assert_eq!(row.rowid, -5);
    let ints = [
        0,
        1,
        -100,
        -30_000,
        8_000_000,
        -2_000_000_000,
        1 << 40,
        i64::MIN,
    ];
    assert_eq!(row.get(0), &Value::Null);
    for (i, v) in ints.iter().enumerate() {
        assert_eq!(row.get(i + 1), &Value::Integer(*v), "column {}", i + 1);
    }
    assert_eq!(row.get(9), &Value::Real(-0.1));
    assert_eq!(row.get(10), &Value::Text(Cow::Borrowed("héllo")));
    assert_eq!(row.get(11), &Value::Blob(Cow::Borrowed(&[0u8, 255, 7][..])));
    // A whole number in a REAL column is stored as an integer, read as a real.
    assert_eq!(row.get(12), &Value::Real(3.0));
}

#[wasm_bindgen_test(unsupported = test)]
fn a_rosbag2_db3_gives_its_topics_and_messages_in_time_order() {
    let msgs = messages(120);
    for (topics_sql, ps) in [(TOPICS_NEW, 4096), (TOPICS_OLD, 1024)] {
        let mut w = Writer::new(ps, 3);
        let file = bag(&mut w, topics_sql, &msgs);
        let (got, end) = read(Db3Reader::new(), &file).unwrap();
        assert_eq!(got.topics.len(), 2);
        assert_eq!(
            got.topics[0],
            Topic {
                id: 1,
                name: "/scan".into(),
                msg_type: "sensor_msgs/LaserScan".into(),
                encoding: Encoding::Cdr,
            }
        );
        assert_eq!(got.topics[1].msg_type, "nav_msgs/Odometry");
        let want = expected(&msgs);
        assert_eq!(got.messages.len(), want.len());
        // Not id order: the timestamps step back within each group of 3.
        assert_ne!(got.messages[1].3, "message row 2");
        assert!(got.messages == want, "messages differ ({ps}-byte pages)");
        assert_eq!(end.container, "rosbag2 SQLite");
        assert_eq!(end.compression, ["none"]);
        assert_eq!(end.lost, None);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_db3_without_the_messages_or_topics_table_is_not_a_bag() {
    let mut w = Writer::new(1024, 4);
    w.table("topics", TOPICS_OLD, &[]);
    let err = read_err(&w.finish());
    assert_eq!(
        err,
        "this is an SQLite file but not a rosbag2 bag: it has no messages table"
    );
    let mut w = Writer::new(1024, 4);
    w.table("messages", MESSAGES, &[]);
    let err = read_err(&w.finish());
    assert!(err.ends_with("it has no topics table"), "{err}");
    let err = read_err(&noise(1, 5000));
    assert!(err.contains("not an SQLite database"), "{err}");
}

/// The bag at three moments: 30, 60 and 90 messages.
fn three_states(ps: usize) -> (Vec<Msg>, [Vec<u8>; 3]) {
    let msgs = messages(90);
    let state = |n: usize| bag(&mut Writer::new(ps, 3), TOPICS_NEW, &msgs[..n]);
    (msgs.clone(), [state(30), state(60), state(90)])
}

fn wal_mode(db: &[u8]) -> Vec<u8> {
    let mut db = db.to_vec();
    db[18] = 2;
    db[19] = 2;
    db
}

#[wasm_bindgen_test(unsupported = test)]
fn a_wal_adds_its_committed_transactions_and_the_last_valid_commit_wins() {
    let ps = 1024;
    let (msgs, [a, b, c]) = three_states(ps);
    let file = wal_mode(&a);
    let salts = (0x1234_5678, 0x9abc_def0);
    let run = |wal: Option<Vec<u8>>| {
        let mut r = Db3Reader::new();
        if let Some(w) = wal {
            for piece in w.chunks(777) {
                r.push_wal(piece);
            }
        }
        let (got, end) = read(r, &file).unwrap();
        (got.messages, end.lost)
    };
    // Without its WAL the file is as at the last checkpoint.
    assert_eq!(run(None).0, expected(&msgs[..30]));
    for big_endian in [false, true] {
        let both = wal(
            ps,
            big_endian,
            salts,
            &[
                Tx {
                    db: &b,
                    commit: true,
                },
                Tx {
                    db: &c,
                    commit: true,
                },
            ],
        );
        assert_eq!(run(Some(both.clone())), (expected(&msgs), None));
        // A torn frame inside the second transaction: the first commit wins.
        let mut torn = both.clone();
        let frame = 32 + (b.len() / ps + 2) * (24 + ps);
        torn[frame + 24 + 100] ^= 0x40;
        assert_eq!(run(Some(torn)).0, expected(&msgs[..60]));
    }
    // A second transaction that never committed: lost, and said so.
    let open = wal(
        ps,
        false,
        salts,
        &[
            Tx {
                db: &b,
                commit: true,
            },
            Tx {
                db: &c,
                commit: false,
            },
        ],
    );
    let (got, lost) = run(Some(open));
    assert_eq!(got, expected(&msgs[..60]));
    let lost = lost.expect("the uncommitted transaction is reported");
    assert!(
        lost.contains(&format!("{} page(s)", c.len() / ps)),
        "{lost}"
    );
    // Frames of an older WAL generation (other salts) after the header's.
    let new_gen = wal(
        ps,
        false,
        salts,
        &[Tx {
            db: &b,
            commit: true,
        }],
    );
    let old_gen = wal(
        ps,
        false,
        (1, 2),
        &[Tx {
            db: &c,
            commit: true,
        }],
    );
    let mixed = [&new_gen[..], &old_gen[32..]].concat();
    assert_eq!(run(Some(mixed)).0, expected(&msgs[..60]));
    // A WAL whose header checksum is wrong is ignored, and said so.
    let mut broken = wal(
        ps,
        false,
        salts,
        &[Tx {
            db: &c,
            commit: true,
        }],
    );
    broken[30] ^= 1;
    let (got, lost) = run(Some(broken));
    assert_eq!(got, expected(&msgs[..30]));
    assert!(lost.unwrap().contains("checksum"));
}

#[wasm_bindgen_test(unsupported = test)]
fn a_database_never_checkpointed_is_read_from_its_wal_alone() {
    let (msgs, [_, b, _]) = three_states(4096);
    let w = wal(
        4096,
        false,
        (5, 6),
        &[Tx {
            db: &b,
            commit: true,
        }],
    );
    let mut r = Db3Reader::new();
    r.push_wal(&w);
    let (got, _) = read(r, &[]).unwrap();
    assert_eq!(got.messages, expected(&msgs[..60]));
}

#[wasm_bindgen_test(unsupported = test)]
fn zstd_per_message_and_per_file() {
    use ruzstd::encoding::{compress_to_vec, CompressionLevel};
    let msgs = messages(40);
    let packed: Vec<Msg> = msgs
        .iter()
        .map(|(id, t, ts, d)| {
            (
                *id,
                *t,
                *ts,
                compress_to_vec(&d[..], CompressionLevel::Fastest),
            )
        })
        .collect();
    let file = bag(&mut Writer::new(4096, 4), TOPICS_NEW, &packed);
    let meta = Metadata {
        compression_format: "zstd".into(),
        compression_mode: "MESSAGE".into(),
        ..Metadata::default()
    };
    assert_eq!(meta.message_compression(), Ok(MessageCompression::Zstd));
    let (got, end) = read(Db3Reader::new().with_metadata(&meta).unwrap(), &file).unwrap();
    assert_eq!(got.messages, expected(&msgs));
    assert_eq!(end.compression, ["zstd"]);
    // The metadata says MESSAGE but a message is plain.
    let plain = bag(&mut Writer::new(4096, 4), TOPICS_NEW, &msgs);
    let err = read(Db3Reader::new().with_metadata(&meta).unwrap(), &plain)
        .err()
        .unwrap();
    assert!(err.message.contains("zstd"), "{err}");
    assert_eq!(err.topic.as_deref(), Some("/scan"));
    // FILE mode: the whole database is one zstd frame.
    let whole = compress_to_vec(&plain[..], CompressionLevel::Fastest);
    let (got, end) = read(Db3Reader::new(), &whole).unwrap();
    assert_eq!(got.messages, expected(&msgs));
    assert_eq!(end.compression, ["zstd"]);
}

/// A file with more than one leaf per table and overflowing messages: the
/// writer and the pages of the messages table.
fn damaged_base() -> (Writer, Vec<u8>, u32) {
    let mut w = Writer::new(1024, 3);
    let file = bag(&mut w, TOPICS_NEW, &messages(40));
    let root = w.tables.iter().find(|t| t.0 == "messages").unwrap().1;
    (w, file, root)
}

fn patch_u32(file: &mut [u8], page: u32, at: usize, v: u32) {
    let o = (page as usize - 1) * 1024 + at;
    file[o..o + 4].copy_from_slice(&v.to_be_bytes());
}

#[wasm_bindgen_test(unsupported = test)]
fn a_page_pointer_out_of_range_names_the_page() {
    let (_, mut file, root) = damaged_base();
    // The root's right-most child pointer.
    patch_u32(&mut file, root, 8, 9999);
    let err = read_err(&file);
    assert!(
        err.starts_with("page 9999: page number 9999 is out of range"),
        "{err}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn cycles_in_a_btree_or_an_overflow_chain_are_errors_not_hangs() {
    let (w, file, root) = damaged_base();
    // The root's right-most child pointing back at the root.
    let mut looped = file.clone();
    patch_u32(&mut looped, root, 8, root);
    let err = read_err(&looped);
    assert_eq!(
        err,
        format!("page {root}: the page is reached a second time: a cycle in the b-tree or an overflow chain")
    );
    // An overflow page whose next page is itself.
    let chain = w.chains.iter().find(|c| c.len() >= 2).unwrap();
    let mut looped = file.clone();
    patch_u32(&mut looped, chain[0], 0, chain[0]);
    let err = read_err(&looped);
    assert!(
        err.starts_with(&format!(
            "page {}: the page is reached a second time",
            chain[0]
        )),
        "{err}"
    );
    // A chain cut short (next = 0 too early).
    let mut cut = file.clone();
    patch_u32(&mut cut, chain[0], 0, 0);
    let err = read_err(&cut);
    assert!(err.contains("the overflow chain ends after"), "{err}");
}

#[wasm_bindgen_test(unsupported = test)]
fn cells_past_their_page_and_files_cut_short_are_errors() {
    let (w, file, _) = damaged_base();
    let leaf = *w.leaves.last().unwrap().first().unwrap();
    // The first cell pointer of a leaf aimed at the page's last byte.
    let mut bad = file.clone();
    let o = (leaf as usize - 1) * 1024 + 8;
    bad[o..o + 2].copy_from_slice(&1023u16.to_be_bytes());
    let err = read_err(&bad);
    assert!(
        err.starts_with(&format!(
            "page {leaf}: the cell at byte 1023 runs past the page"
        )),
        "{err}"
    );
    // A cell count that cannot fit the page.
    let mut bad = file.clone();
    let o = (leaf as usize - 1) * 1024 + 3;
    bad[o..o + 2].copy_from_slice(&600u16.to_be_bytes());
    let err = read_err(&bad);
    assert!(err.contains("600 cells do not fit"), "{err}");
    // A payload size claiming 2 GB.
    let mut bad = file.clone();
    let cell = u16::from_be_bytes([file[o + 5], file[o + 6]]) as usize;
    let c = (leaf as usize - 1) * 1024 + cell;
    bad[c..c + 5].copy_from_slice(&[0x87, 0xff, 0xff, 0xff, 0x7f]);
    let err = read_err(&bad);
    assert!(
        err.contains("overflow pages, more than the database's"),
        "{err}"
    );
    // Half the file.
    let err = read_err(&file[..file.len() / 2]);
    assert!(err.contains("past the end of the file"), "{err}");
    // UTF-16.
    let mut utf16 = file.clone();
    utf16[59] = 2;
    let err = read_err(&utf16);
    assert!(
        err.contains("UTF-16le: only UTF-8 databases are read"),
        "{err}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn a_65536_byte_page_size_is_written_as_1() {
    let msgs = messages(10);
    let file = bag(&mut Writer::new(65536, 4), TOPICS_OLD, &msgs);
    assert_eq!(&file[16..18], &[0, 1]);
    let (got, _) = read(Db3Reader::new(), &file).unwrap();
    assert_eq!(got.messages, expected(&msgs));
}

#[wasm_bindgen_test(unsupported = test)]
fn metadata_yaml_of_versions_5_and_9() {
    let v5 = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n  \
        duration:\n    nanoseconds: 123227530798\n  starting_time:\n    \
        nanoseconds_since_epoch: 1742407985965670153\n  message_count: 4594\n  \
        topics_with_message_count:\n    - topic_metadata:\n        name: /scan\n        \
        type: sensor_msgs/msg/LaserScan\n        serialization_format: cdr\n        \
        offered_qos_profiles: \"- history: 3\\n  depth: 0\"\n      message_count: 896\n  \
        compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    \
        - my_data_bag_0.db3\n";
    let m = Metadata::parse(v5).unwrap();
    assert_eq!((m.version, m.message_count), (5, 4594));
    assert_eq!(m.storage_identifier, "sqlite3");
    assert_eq!(m.duration_ns, 123_227_530_798);
    assert_eq!(m.starting_time_ns, 1_742_407_985_965_670_153);
    assert_eq!(m.relative_file_paths, ["my_data_bag_0.db3"]);
    assert_eq!(m.topics.len(), 1);
    assert_eq!(
        (
            m.topics[0].name.as_str(),
            m.topics[0].msg_type.as_str(),
            m.topics[0].message_count
        ),
        ("/scan", "sensor_msgs/LaserScan", 896)
    );
    assert_eq!(m.message_compression(), Ok(MessageCompression::None));
    let v9 =
        "rosbag2_bagfile_information:\n  compression_format: zstd\n  compression_mode: FILE\n  \
        message_count: 2\n  relative_file_paths:\n  - a.db3.zstd\n  ros_distro: jazzy\n  \
        storage_identifier: sqlite3\n  topics_with_message_count:\n  - message_count: 2\n    \
        topic_metadata:\n      name: /tf\n      offered_qos_profiles: []\n      \
        serialization_format: cdr\n      type: tf2_msgs/msg/TFMessage\n      \
        type_description_hash: RIHS01_e369\n  version: 9\n";
    let m = Metadata::parse(v9).unwrap();
    assert_eq!((m.version, m.ros_distro.as_str()), (9, "jazzy"));
    assert_eq!(m.topics[0].type_description_hash, "RIHS01_e369");
    assert_eq!(m.message_compression(), Ok(MessageCompression::None));
    let lz4 = Metadata {
        compression_format: "lz4".into(),
        compression_mode: "MESSAGE".into(),
        ..Metadata::default()
    };
    assert!(lz4.message_compression().unwrap_err().contains("lz4"));
    assert!(Metadata::parse("image: map.pgm\n")
        .unwrap_err()
        .contains("not a rosbag2 metadata file"));
}
