// Tiny ROS bags written here, for tests that must not depend on shared
// data: a ROS 1 bag (format 2.0, uncompressed chunks), an MCAP file
// (uncompressed chunks, with or without a summary section) and a rosbag2
// SQLite `.db3`, each holding a short drive round a ring corridor
// (LaserScan on /scan, Odometry on /odom), plus the means to break them:
// every record is built by a function that takes the fields a test may
// want to make lie (a chunk's size, its compression, its CRC, a scan's
// range count).
//
// Written from the formats' specifications, not from any library:
// * ROS 1: the ROS wiki's "Bags/Format/2.0" (records of `header_len u32,
//   header, data_len u32, data`; header fields `len u32` + `name=value`).
// * MCAP: <https://mcap.dev/spec> (records of `opcode u8, length u64,
//   body`; strings and byte arrays with a u32 length; little-endian).
// * SQLite: "Database File Format" (sqlite.org/fileformat2.html): a
//   100-byte header, b-tree pages, varints, records.
// * Messages: ROS 1 serialisation (packed, little-endian) and CDR (an
//   encapsulation header, then each primitive aligned to its size).

import { RING, rayHit } from './synthetic-log.mjs';

// ---------------------------------------------------------------------------
// Bytes

/**
 * Little-endian bytes appended one field at a time. With `cdr`, each
 * primitive is first aligned to a multiple of its size counted from byte 4
 * (after the encapsulation header), as CDR lays them out.
 */
export class Bytes {
  constructor({ cdr = false } = {}) {
    this.buf = Buffer.alloc(256);
    this.len = 0;
    this.cdr = cdr;
    if (cdr) this.raw([0, 1, 0, 0]); // plain CDR, little-endian
  }

  room(n) {
    if (this.len + n <= this.buf.length) return;
    const bigger = Buffer.alloc(Math.max(this.buf.length * 2, this.len + n));
    this.buf.copy(bigger, 0, 0, this.len);
    this.buf = bigger;
  }

  align(size) {
    if (!this.cdr) return this;
    while ((this.len - 4) % size !== 0) this.u8(0);
    return this;
  }

  raw(bytes) {
    this.room(bytes.length);
    this.buf.set(bytes, this.len);
    this.len += bytes.length;
    return this;
  }

  u8(v) { this.room(1); this.buf.writeUInt8(v, this.len); this.len += 1; return this; }
  u16(v) { this.align(2).room(2); this.buf.writeUInt16LE(v, this.len); this.len += 2; return this; }
  u32(v) { this.align(4).room(4); this.buf.writeUInt32LE(v >>> 0, this.len); this.len += 4; return this; }
  i32(v) { this.align(4).room(4); this.buf.writeInt32LE(v, this.len); this.len += 4; return this; }
  u64(v) { this.align(8).room(8); this.buf.writeBigUInt64LE(BigInt(v), this.len); this.len += 8; return this; }
  f32(v) { this.align(4).room(4); this.buf.writeFloatLE(v, this.len); this.len += 4; return this; }
  f64(v) { this.align(8).room(8); this.buf.writeDoubleLE(v, this.len); this.len += 8; return this; }

  /** A string: ROS 1 `u32` length + bytes; CDR the same with a NUL counted and written. */
  string(s) {
    const b = Buffer.from(s, 'utf8');
    if (this.cdr) return this.u32(b.length + 1).raw(b).u8(0);
    return this.u32(b.length).raw(b);
  }

  bytes() {
    return Buffer.from(this.buf.subarray(0, this.len));
  }
}

const concat = (parts) => Buffer.concat(parts.map((p) => Buffer.from(p)));

/** CRC-32 (IEEE 802.3, reflected, as zlib and MCAP compute it). */
const CRC_TABLE = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[n] = c >>> 0;
  }
  return t;
})();

export function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

// ---------------------------------------------------------------------------
// A drive to record: scans cast against the ring corridor, odometry

/**
 * `n` scans of a robot driving round the ring corridor at 10 Hz (the true
 * path as odometry, which is all a reader test needs): each `{t_ns, pose,
 * ranges}` with `beams` ranges over 180° (first beam at -90°).
 */
export function ringDrive(n = 60, beams = 181) {
  const out = [];
  const t0 = 1_700_000_000_000_000_000n;
  for (let i = 0; i < n; i++) {
    const u = (2 * Math.PI * i) / 140;
    const x = 6.5 * Math.cos(u), y = 3.5 * Math.sin(u);
    const th = Math.atan2(3.5 * Math.cos(u), -6.5 * Math.sin(u));
    const ranges = [];
    for (let b = 0; b < beams; b++) {
      const a = th - Math.PI / 2 + (Math.PI * b) / (beams - 1);
      ranges.push(rayHit([x, y], a, RING, 30));
    }
    out.push({ t_ns: t0 + BigInt(i) * 100_000_000n, pose: [x, y, th], ranges });
  }
  return out;
}

const secNsec = (tNs) => [Number(tNs / 1_000_000_000n), Number(tNs % 1_000_000_000n)];

// ---------------------------------------------------------------------------
// Messages: sensor_msgs/LaserScan and nav_msgs/Odometry

/**
 * A LaserScan in ROS 1 serialisation (`cdr: false`) or CDR. `count`
 * overrides the range count written before the ranges (a count that lies).
 */
export function laserScan(scan, { cdr = false, count } = {}) {
  const w = new Bytes({ cdr });
  const [sec, nsec] = secNsec(scan.t_ns);
  if (!cdr) w.u32(0); // header.seq
  if (cdr) w.i32(sec); else w.u32(sec);
  w.u32(nsec).string('laser');
  const n = scan.ranges.length;
  const step = n > 1 ? Math.PI / (n - 1) : 0;
  w.f32(-Math.PI / 2).f32(Math.PI / 2).f32(step).f32(0).f32(0.1).f32(0.02).f32(30);
  w.u32(count ?? n);
  for (const r of scan.ranges) w.f32(r);
  w.u32(0); // intensities
  return w.bytes();
}

/** A nav_msgs/Odometry (odom → base_link) at the scan's pose and time. */
export function odometry(scan, { cdr = false } = {}) {
  const w = new Bytes({ cdr });
  const [sec, nsec] = secNsec(scan.t_ns);
  if (!cdr) w.u32(0);
  if (cdr) w.i32(sec); else w.u32(sec);
  w.u32(nsec).string('odom').string('base_link');
  const [x, y, th] = scan.pose;
  for (const v of [x, y, 0, 0, 0, Math.sin(th / 2), Math.cos(th / 2)]) w.f64(v);
  for (let k = 0; k < 36 + 6 + 36; k++) w.f64(0); // covariance, twist, covariance
  return w.bytes();
}

/** A std_msgs/String (a topic that is neither scan nor pose). */
export function stringMsg(text, { cdr = false } = {}) {
  return new Bytes({ cdr }).string(text).bytes();
}

// ---------------------------------------------------------------------------
// ROS 1 bags, format 2.0

export const ROS1_MAGIC = '#ROSBAG V2.0\n';

/** One header field, `len u32` then `name=value`. */
function field(name, value) {
  const body = concat([Buffer.from(`${name}=`), value]);
  return concat([new Bytes().u32(body.length).bytes(), body]);
}
const u8f = (v) => Buffer.from([v]);
const u32f = (v) => new Bytes().u32(v).bytes();
const u64f = (v) => new Bytes().u64(v).bytes();
const timef = (tNs) => { const [s, n] = secNsec(tNs); return new Bytes().u32(s).u32(n).bytes(); };

/** A record: `header_len u32, header, data_len u32, data`. */
function record(fields, data) {
  const header = concat(fields);
  return concat([u32f(header.length), header, u32f(data.length), data]);
}

export const ros1 = {
  field,
  record,
  /** The bag header, padded to 4 KiB as rosbag writes it (so it can be rewritten in place). */
  bagHeader: (indexPos, connCount, chunkCount) => {
    const fields = [field('op', u8f(0x03)), field('index_pos', u64f(indexPos)), field('conn_count', u32f(connCount)), field('chunk_count', u32f(chunkCount))];
    const headerLen = concat(fields).length;
    return record(fields, Buffer.alloc(4096 - 4 - headerLen - 4, 0x20));
  },
  connection: (conn, topic, type) => record(
    [field('op', u8f(0x07)), field('conn', u32f(conn)), field('topic', Buffer.from(topic))],
    concat([field('topic', Buffer.from(topic)), field('type', Buffer.from(type)), field('md5sum', Buffer.from('*')), field('message_definition', Buffer.from(''))]),
  ),
  message: (conn, tNs, data) => record([field('op', u8f(0x02)), field('conn', u32f(conn)), field('time', timef(tNs))], data),
  /** A chunk; `size` (default: the records' length) may lie. */
  chunk: (compression, records, size = records.length) => record(
    [field('op', u8f(0x05)), field('compression', Buffer.from(compression)), field('size', u32f(size))],
    records,
  ),
  indexData: (conn, entries) => {
    const data = new Bytes();
    for (const [tNs, offset] of entries) {
      const [s, n] = secNsec(tNs);
      data.u32(s).u32(n).u32(offset);
    }
    return record([field('op', u8f(0x04)), field('ver', u32f(1)), field('conn', u32f(conn)), field('count', u32f(entries.length))], data.bytes());
  },
  chunkInfo: (chunkPos, startNs, endNs, counts) => {
    const data = new Bytes();
    for (const [conn, count] of counts) data.u32(conn).u32(count);
    return record(
      [field('op', u8f(0x06)), field('ver', u32f(1)), field('chunk_pos', u64f(chunkPos)), field('start_time', timef(startNs)), field('end_time', timef(endNs)), field('count', u32f(counts.size))],
      data.bytes(),
    );
  },
};

/** The topics a test bag records, with their ROS 1 connection ids. */
export const TOPICS = [
  { conn: 0, topic: '/scan', type: 'sensor_msgs/LaserScan', ros2: 'sensor_msgs/msg/LaserScan' },
  { conn: 1, topic: '/odom', type: 'nav_msgs/Odometry', ros2: 'nav_msgs/msg/Odometry' },
];

/**
 * The messages of a drive, in time order: `{conn, t_ns, data}`, an
 * Odometry then a LaserScan per step. `scan(i, s)` may replace scan i's
 * bytes; `topics` picks which topics are written (by connection id).
 */
export function driveMessages(drive, { cdr = false, scan, topics = [0, 1] } = {}) {
  const out = [];
  drive.forEach((s, i) => {
    if (topics.includes(1)) out.push({ conn: 1, t_ns: s.t_ns, data: odometry(s, { cdr }) });
    if (topics.includes(0)) out.push({ conn: 0, t_ns: s.t_ns, data: scan ? scan(i, s) : laserScan(s, { cdr }) });
  });
  return out;
}

/**
 * A ROS 1 bag as `rosbag record` writes it: the bag header (4 KiB), then
 * chunks of `perChunk` messages (the connections first seen in a chunk at
 * its start), each followed by its index records, then the connections
 * again and a chunk info per chunk. `chunkOptions(k)` may give chunk k
 * (from 0) a `compression` name or a `size` that lie. Returns `{bytes,
 * chunks: [{offset, length, messages}]}`.
 */
export function ros1Bag(messages, { perChunk = 20, chunkOptions = () => ({}), magic = ROS1_MAGIC } = {}) {
  const conns = TOPICS.filter((t) => messages.some((m) => m.conn === t.conn));
  const parts = [];
  const chunks = [];
  const infos = [];
  const seen = new Set();
  let pos = magic.length + ros1.bagHeader(0, 0, 0).length;
  for (let k = 0; k * perChunk < messages.length; k++) {
    const mine = messages.slice(k * perChunk, (k + 1) * perChunk);
    const inner = [];
    let off = 0;
    const index = new Map();
    for (const m of mine) {
      if (!seen.has(m.conn)) {
        seen.add(m.conn);
        const t = TOPICS.find((c) => c.conn === m.conn);
        const c = ros1.connection(t.conn, t.topic, t.type);
        inner.push(c);
        off += c.length;
      }
      const r = ros1.message(m.conn, m.t_ns, m.data);
      if (!index.has(m.conn)) index.set(m.conn, []);
      index.get(m.conn).push([m.t_ns, off]);
      inner.push(r);
      off += r.length;
    }
    const o = chunkOptions(k);
    const chunk = ros1.chunk(o.compression ?? 'none', concat(inner), o.size);
    chunks.push({ offset: pos, length: chunk.length, messages: mine.length });
    const counts = new Map([...index].map(([c, e]) => [c, e.length]));
    infos.push([pos, mine[0].t_ns, mine[mine.length - 1].t_ns, counts]);
    parts.push(chunk);
    pos += chunk.length;
    for (const [c, e] of index) {
      const r = ros1.indexData(c, e);
      parts.push(r);
      pos += r.length;
    }
  }
  const indexPos = pos;
  for (const t of conns) parts.push(ros1.connection(t.conn, t.topic, t.type));
  for (const [p, a, b, counts] of infos) parts.push(ros1.chunkInfo(p, a, b, counts));
  const bytes = concat([Buffer.from(magic), ros1.bagHeader(indexPos, conns.length, chunks.length), ...parts]);
  return { bytes, chunks };
}

// ---------------------------------------------------------------------------
// MCAP

export const MCAP_MAGIC = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);

const op = {
  HEADER: 0x01, FOOTER: 0x02, SCHEMA: 0x03, CHANNEL: 0x04, MESSAGE: 0x05, CHUNK: 0x06,
  MESSAGE_INDEX: 0x07, CHUNK_INDEX: 0x08, STATISTICS: 0x0b, SUMMARY_OFFSET: 0x0e, DATA_END: 0x0f,
};

/** A record: `opcode u8, length u64, body`. */
function mrecord(opcode, body) {
  return concat([Buffer.from([opcode]), new Bytes().u64(body.length).bytes(), body]);
}

export const mcap = {
  op,
  record: mrecord,
  header: () => mrecord(op.HEADER, new Bytes().string('ros2').string('slamlab tests').bytes()),
  schema: (id, name) => {
    const def = Buffer.from('# a definition\n');
    return mrecord(op.SCHEMA, new Bytes().u16(id).string(name).string('ros2msg').u32(def.length).raw(def).bytes());
  },
  channel: (id, schemaId, topic) => mrecord(op.CHANNEL, new Bytes().u16(id).u16(schemaId).string(topic).string('cdr').u32(0).bytes()),
  message: (channel, seq, tNs, data) => mrecord(op.MESSAGE, new Bytes().u16(channel).u32(seq).u64(tNs).u64(tNs).raw(data).bytes()),
  /**
   * A chunk of `records`, uncompressed; `compression` (default ''), `size`
   * (uncompressed size) and `crc` (default: the records' CRC-32) may lie.
   */
  chunk: (records, startNs, endNs, { compression = '', size = records.length, crc = crc32(records) } = {}) => mrecord(op.CHUNK,
    new Bytes().u64(startNs).u64(endNs).u64(size).u32(crc).string(compression).u64(records.length).raw(records).bytes()),
  messageIndex: (channel, entries) => {
    const w = new Bytes().u16(channel).u32(entries.length * 16);
    for (const [t, o] of entries) w.u64(t).u64(o);
    return mrecord(op.MESSAGE_INDEX, w.bytes());
  },
  dataEnd: (crc = 0) => mrecord(op.DATA_END, new Bytes().u32(crc).bytes()),
  footer: (summaryStart = 0, summaryOffsetStart = 0) => mrecord(op.FOOTER, new Bytes().u64(summaryStart).u64(summaryOffsetStart).u32(0).bytes()),
};

/**
 * An MCAP file as `ros2 bag record` writes it (the mcap storage plugin):
 * magic, Header, chunks of `perChunk` messages (the schemas and channels
 * first used in a chunk at its start), a message index per channel after
 * each chunk, Data End, and with `summary` a summary section (the schemas,
 * channels, statistics and chunk indexes, and its summary offsets), the
 * Footer and the closing magic. `chunkOptions(k)` may make chunk k lie.
 * Returns `{bytes, chunks: [{offset, length, messages}]}`.
 */
export function mcapFile(messages, { perChunk = 20, summary = true, chunkOptions = () => ({}) } = {}) {
  const channelOf = (conn) => conn + 1; // MCAP channel ids; schema ids the same
  const parts = [MCAP_MAGIC, mcap.header()];
  let pos = parts.reduce((a, p) => a + p.length, 0);
  const seen = new Set();
  const chunks = [];
  const chunkIndexes = [];
  for (let k = 0; k * perChunk < messages.length; k++) {
    const mine = messages.slice(k * perChunk, (k + 1) * perChunk);
    const inner = [];
    let off = 0;
    const index = new Map();
    for (const [i, m] of mine.entries()) {
      const id = channelOf(m.conn);
      if (!seen.has(id)) {
        seen.add(id);
        const t = TOPICS.find((c) => c.conn === m.conn);
        for (const r of [mcap.schema(id, t.ros2), mcap.channel(id, id, t.topic)]) {
          inner.push(r);
          off += r.length;
        }
      }
      const r = mcap.message(id, k * perChunk + i, m.t_ns, m.data);
      if (!index.has(id)) index.set(id, []);
      index.get(id).push([m.t_ns, off]);
      inner.push(r);
      off += r.length;
    }
    const start = mine[0].t_ns, end = mine[mine.length - 1].t_ns;
    const chunk = mcap.chunk(concat(inner), start, end, chunkOptions(k));
    chunks.push({ offset: pos, length: chunk.length, messages: mine.length });
    parts.push(chunk);
    const chunkAt = pos;
    pos += chunk.length;
    const indexAt = pos;
    const offsets = new Bytes();
    for (const [id, e] of index) {
      offsets.u16(id).u64(pos);
      const r = mcap.messageIndex(id, e);
      parts.push(r);
      pos += r.length;
    }
    const o = offsets.bytes();
    chunkIndexes.push(mrecord(op.CHUNK_INDEX, new Bytes().u64(start).u64(end).u64(chunkAt).u64(chunk.length)
      .u32(o.length).raw(o).u64(pos - indexAt).string('').u64(chunk.length).u64(chunk.length).bytes()));
  }
  parts.push(mcap.dataEnd());
  pos += parts[parts.length - 1].length;
  let summaryStart = 0, offsetStart = 0;
  if (summary) {
    summaryStart = pos;
    const groups = [];
    const group = (opcode, records) => {
      groups.push([opcode, pos, records.reduce((a, r) => a + r.length, 0)]);
      for (const r of records) {
        parts.push(r);
        pos += r.length;
      }
    };
    const used = TOPICS.filter((t) => seen.has(channelOf(t.conn)));
    group(op.SCHEMA, used.map((t) => mcap.schema(channelOf(t.conn), t.ros2)));
    group(op.CHANNEL, used.map((t) => mcap.channel(channelOf(t.conn), channelOf(t.conn), t.topic)));
    const counts = new Bytes();
    for (const t of used) counts.u16(channelOf(t.conn)).u64(messages.filter((m) => m.conn === t.conn).length);
    const c = counts.bytes();
    group(op.STATISTICS, [mrecord(op.STATISTICS, new Bytes().u64(messages.length).u16(used.length).u32(used.length)
      .u32(0).u32(0).u32(chunks.length).u64(messages[0].t_ns).u64(messages[messages.length - 1].t_ns).u32(c.length).raw(c).bytes())]);
    group(op.CHUNK_INDEX, chunkIndexes);
    offsetStart = pos;
    for (const [g, start, length] of groups) {
      const r = mrecord(op.SUMMARY_OFFSET, new Bytes().u8(g).u64(start).u64(length).bytes());
      parts.push(r);
      pos += r.length;
    }
  }
  parts.push(mcap.footer(summaryStart, offsetStart), MCAP_MAGIC);
  return { bytes: concat(parts), chunks };
}

// ---------------------------------------------------------------------------
// rosbag2 SQLite (.db3)

const PAGE = 4096;

/** An SQLite varint: 7 bits a byte, big-endian, high bit = more (values < 2^56 here). */
function varint(v) {
  v = BigInt(v);
  const out = [];
  do {
    out.unshift(Number(v & 0x7fn));
    v >>= 7n;
  } while (v > 0n);
  for (let i = 0; i < out.length - 1; i++) out[i] |= 0x80;
  return Buffer.from(out);
}

/** A record (§2.1): header of serial types, then the values. Values: null, a JS integer / bigint, a string, a Buffer. */
function sqlRecord(values) {
  const types = [];
  const bodies = [];
  for (const v of values) {
    if (v === null) {
      types.push(0);
      bodies.push(Buffer.alloc(0));
    } else if (typeof v === 'string') {
      const b = Buffer.from(v, 'utf8');
      types.push(13 + 2 * b.length);
      bodies.push(b);
    } else if (Buffer.isBuffer(v)) {
      types.push(12 + 2 * v.length);
      bodies.push(v);
    } else {
      const b = Buffer.alloc(8);
      b.writeBigInt64BE(BigInt(v));
      types.push(6);
      bodies.push(b);
    }
  }
  const typeBytes = concat(types.map(varint));
  let headerLen = typeBytes.length + 1;
  if (varint(headerLen).length > 1) headerLen += varint(headerLen).length - 1;
  return concat([varint(headerLen), typeBytes, ...bodies]);
}

/** A table leaf page (type 0x0D) holding `cells`; `first` for page 1 (after the 100-byte header). */
function leafPage(cells, first = false) {
  const page = Buffer.alloc(PAGE);
  const base = first ? 100 : 0;
  let content = PAGE;
  const pointers = [];
  for (const c of cells) {
    content -= c.length;
    c.copy(page, content);
    pointers.push(content);
  }
  if (base + 8 + 2 * cells.length > content) throw new Error('leafPage: cells do not fit');
  page.writeUInt8(0x0d, base);
  page.writeUInt16BE(cells.length, base + 3);
  page.writeUInt16BE(content, base + 5);
  pointers.forEach((p, i) => page.writeUInt16BE(p, base + 8 + 2 * i));
  return page;
}

/** An interior table page (type 0x05): `children` = [[page, maxRowid], …], the last the right-most. */
function interiorPage(children) {
  const page = Buffer.alloc(PAGE);
  const cells = children.slice(0, -1).map(([p, key]) => {
    const child = Buffer.alloc(4);
    child.writeUInt32BE(p);
    return concat([child, varint(key)]);
  });
  let content = PAGE;
  const pointers = [];
  for (const c of cells) {
    content -= c.length;
    c.copy(page, content);
    pointers.push(content);
  }
  page.writeUInt8(0x05, 0);
  page.writeUInt16BE(cells.length, 3);
  page.writeUInt16BE(content, 5);
  page.writeUInt32BE(children[children.length - 1][0], 8);
  pointers.forEach((p, i) => page.writeUInt16BE(p, 12 + 2 * i));
  return page;
}

/** A leaf cell: payload size, rowid, payload (whole: callers keep rows under the overflow threshold). */
function leafCell(rowid, values) {
  const payload = sqlRecord(values);
  if (payload.length > PAGE - 35) throw new Error('leafCell: a row this long would overflow');
  return concat([varint(payload.length), varint(rowid), payload]);
}

const TOPICS_SQL = 'CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL)';
const MESSAGES_SQL = 'CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp INTEGER NOT NULL, data BLOB NOT NULL)';

/**
 * A rosbag2 `.db3` (SQLite, 4 KiB pages, UTF-8, rollback journal) with a
 * `topics` table and, unless `messagesTable` is false, a `messages` table
 * of `messages` (`{conn, t_ns, data}`, CDR): topic row ids are
 * connection id + 1. Tables of one page are a leaf root; bigger ones an
 * interior root over leaves.
 */
export function db3File(messages, { messagesTable = true } = {}) {
  const pages = []; // pages[0] is page 1, filled last
  const alloc = () => { pages.push(null); return pages.length; };
  alloc();
  const table = (rows) => {
    const leaves = [];
    let cells = [], used = 8, maxRowid = 0;
    const flush = () => {
      const n = alloc();
      pages[n - 1] = leafPage(cells);
      leaves.push([n, maxRowid]);
      cells = [];
      used = 8;
    };
    for (const [rowid, values] of rows) {
      const c = leafCell(rowid, values);
      if (used + c.length + 2 > PAGE && cells.length) flush();
      cells.push(c);
      used += c.length + 2;
      maxRowid = rowid;
    }
    if (cells.length || leaves.length === 0) flush();
    if (leaves.length === 1) return leaves[0][0];
    const root = alloc();
    pages[root - 1] = interiorPage(leaves);
    return root;
  };
  const used = TOPICS.filter((t) => messages.some((m) => m.conn === t.conn));
  const topicsRoot = table(used.map((t) => [t.conn + 1, [null, t.topic, t.ros2, 'cdr', '']]));
  const schema = [[1, ['table', 'topics', 'topics', topicsRoot, TOPICS_SQL]]];
  if (messagesTable) {
    const root = table(messages.map((m, i) => [i + 1, [null, m.conn + 1, m.t_ns, m.data]]));
    schema.push([2, ['table', 'messages', 'messages', root, MESSAGES_SQL]]);
  }
  const page1 = leafPage(schema.map(([r, v]) => leafCell(r, v)), true);
  const h = Buffer.alloc(100);
  h.write('SQLite format 3\0', 0, 'latin1');
  h.writeUInt16BE(PAGE, 16);
  h.writeUInt8(1, 18); // write version: rollback journal
  h.writeUInt8(1, 19); // read version
  h.writeUInt8(0, 20); // reserved bytes per page
  h.writeUInt8(64, 21); // payload fractions, fixed by the format
  h.writeUInt8(32, 22);
  h.writeUInt8(32, 23);
  h.writeUInt32BE(1, 24); // change counter
  h.writeUInt32BE(pages.length, 28); // pages in the database
  h.writeUInt32BE(1, 40); // schema cookie
  h.writeUInt32BE(4, 44); // schema format
  h.writeUInt32BE(1, 56); // text encoding: UTF-8
  h.writeUInt32BE(1, 92); // version-valid-for = change counter
  h.writeUInt32BE(3045000, 96);
  h.copy(page1, 0);
  pages[0] = page1;
  return concat(pages);
}
