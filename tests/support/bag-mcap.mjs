// A large bag for the page's memory test (tests/page-bags.test.mjs), made
// from a small real one: the messages of an uncompressed ROS 1 bag,
// repeated with their times shifted, written into a new MCAP file.
//
// Reading (ROS bag format 2.0, http://wiki.ros.org/Bags/Format/2.0): the
// file opens with `#ROSBAG V2.0\n`, then records. A record is a header and
// data, each preceded by its length (u32 little-endian); a header is a run
// of fields, each `len u32` then `name=value` (the value binary). The field
// `op` says what the record is: 0x03 the bag header, 0x05 a chunk (whose
// data holds more records; only compression `none` is read here), 0x07 a
// connection (header `conn`, `topic`; its data is again fields: `type`,
// `md5sum`, `message_definition`), 0x02 a message (header `conn` and
// `time`: u32 seconds, u32 nanoseconds; its data the serialized message),
// 0x04 / 0x06 the index (skipped).
//
// Writing (MCAP, https://mcap.dev/spec): the magic `\x89MCAP0\r\n`, then
// records `opcode u8, length u64, content`: a Header (0x01: profile,
// library), a Schema per message type (0x03: id u16, name, encoding
// `ros1msg`, the definition text), a Channel per topic (0x04: id u16,
// schema id u16, topic, message encoding `ros1`, metadata), the Messages
// (0x05: channel id u16, sequence u32, log time u64 ns, publish time u64
// ns, the message bytes), Data End (0x0F: the data section's CRC, 0 = not
// computed) and a Footer (0x02: no summary section: all zero), then the
// magic again. Strings are `u32 length` + UTF-8; a map is its byte
// length u32 then its key/value strings. No chunks and no summary: a
// reader reads such a file from its start to its end.
//
// The messages are written as the bag holds them, in ROS 1 serialization,
// each copy's times moved on by the bag's span (so time only grows): both
// the record's log time and, for messages that begin with a std_msgs/Header
// (seq u32, stamp: secs u32, nsecs u32), the header's stamp.
import { openSync, writeSync, closeSync } from 'node:fs';

const ROS1_MAGIC = '#ROSBAG V2.0\n';
const MCAP_MAGIC = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);

/** The fields of a ROS 1 record header (or connection data): name → Buffer. */
function fields(buf) {
  const out = new Map();
  let at = 0;
  while (at + 4 <= buf.length) {
    const len = buf.readUInt32LE(at);
    const field = buf.subarray(at + 4, at + 4 + len);
    const eq = field.indexOf(0x3d);
    if (eq < 0) throw new Error(`a header field without '=' at byte ${at}`);
    out.set(field.subarray(0, eq).toString('latin1'), field.subarray(eq + 1));
    at += 4 + len;
  }
  return out;
}

/** Calls `visit(header fields, data)` for each record of `buf` from `at`. */
function records(buf, at, visit) {
  while (at + 4 <= buf.length) {
    const hlen = buf.readUInt32LE(at);
    const header = fields(buf.subarray(at + 4, at + 4 + hlen));
    const dlen = buf.readUInt32LE(at + 4 + hlen);
    const data = buf.subarray(at + 8 + hlen, at + 8 + hlen + dlen);
    if (data.length !== dlen) throw new Error(`a record cut short at byte ${at}`);
    visit(header, data);
    at += 8 + hlen + dlen;
  }
}

/**
 * The connections and messages of an uncompressed ROS 1 bag (`bytes`, a
 * Buffer): `{connections: Map(conn → {topic, type, definition}),
 * messages: [{conn, timeNs: BigInt, data: Buffer}]}` in the bag's order.
 */
export function readRos1(bytes) {
  if (bytes.subarray(0, ROS1_MAGIC.length).toString('latin1') !== ROS1_MAGIC) throw new Error('not a ROS 1 bag 2.0');
  const connections = new Map();
  const messages = [];
  const visit = (header, data) => {
    const op = header.get('op')?.[0];
    if (op === 0x05) {
      const compression = header.get('compression').toString('latin1');
      if (compression !== 'none') throw new Error(`a chunk compressed with ${compression}: only 'none' is read here`);
      records(data, 0, visit);
    } else if (op === 0x07) {
      const conn = header.get('conn').readUInt32LE(0);
      const f = fields(data);
      connections.set(conn, {
        topic: header.get('topic').toString('utf8'),
        type: f.get('type').toString('utf8'),
        definition: f.get('message_definition').toString('utf8'),
      });
    } else if (op === 0x02) {
      const t = header.get('time');
      const timeNs = BigInt(t.readUInt32LE(0)) * 1_000_000_000n + BigInt(t.readUInt32LE(4));
      messages.push({ conn: header.get('conn').readUInt32LE(0), timeNs, data });
    }
  };
  records(bytes, ROS1_MAGIC.length, visit);
  return { connections, messages };
}

const u16 = (v) => {
  const b = Buffer.alloc(2);
  b.writeUInt16LE(v);
  return b;
};
const u32 = (v) => {
  const b = Buffer.alloc(4);
  b.writeUInt32LE(v);
  return b;
};
const u64 = (v) => {
  const b = Buffer.alloc(8);
  b.writeBigUInt64LE(BigInt(v));
  return b;
};
const str = (s) => {
  const b = Buffer.from(s, 'utf8');
  return Buffer.concat([u32(b.length), b]);
};
const record = (opcode, ...parts) => {
  const content = Buffer.concat(parts);
  return Buffer.concat([Buffer.from([opcode]), u64(content.length), content]);
};

/** Does a message of `type` begin with a std_msgs/Header? (The types the lab reads that do.) */
const STAMPED = new Set(['sensor_msgs/LaserScan', 'nav_msgs/Odometry', 'geometry_msgs/PoseStamped']);

/**
 * Writes `copies` copies of the ROS 1 bag `bytes`' messages into a new
 * MCAP file at `file`, each copy `spanNs` (BigInt) later than the one
 * before (default: the bag's span plus the mean gap between messages).
 * Writes as it goes (never the whole file in memory). Returns `{bytes,
 * messages, spanNs}`: the file's size and the number of messages written.
 */
export function writeRepeatedMcap(file, bytes, copies, spanNs = null) {
  const { connections, messages } = readRos1(bytes);
  if (!messages.length) throw new Error('the bag holds no message');
  const first = messages[0].timeNs, last = messages.at(-1).timeNs;
  const span = spanNs ?? last - first + (last - first) / BigInt(Math.max(1, messages.length - 1));
  const fd = openSync(file, 'w');
  let size = 0;
  let sequence = 0;
  const write = (buf) => {
    writeSync(fd, buf);
    size += buf.length;
  };
  try {
    write(MCAP_MAGIC);
    write(record(0x01, str('ros1'), str('slamlab tests/support/bag-mcap.mjs')));
    const schemas = new Map();
    const channels = new Map();
    for (const [conn, c] of connections) {
      if (!schemas.has(c.type)) {
        schemas.set(c.type, schemas.size + 1);
        const def = Buffer.from(c.definition, 'utf8');
        write(record(0x03, u16(schemas.get(c.type)), str(c.type), str('ros1msg'), u32(def.length), def));
      }
      channels.set(conn, channels.size + 1);
      write(record(0x04, u16(channels.get(conn)), u16(schemas.get(c.type)), str(c.topic), str('ros1'), u32(0)));
    }
    for (let k = 0; k < copies; k++) {
      const shift = span * BigInt(k);
      const parts = [];
      let held = 0;
      for (const m of messages) {
        const c = connections.get(m.conn);
        if (!c) throw new Error(`a message on connection ${m.conn}, which the bag never declares`);
        const t = m.timeNs + shift;
        let data = m.data;
        if (STAMPED.has(c.type) && shift > 0n) {
          data = Buffer.from(m.data);
          const stamp = BigInt(data.readUInt32LE(4)) * 1_000_000_000n + BigInt(data.readUInt32LE(8)) + shift;
          data.writeUInt32LE(Number(stamp / 1_000_000_000n), 4);
          data.writeUInt32LE(Number(stamp % 1_000_000_000n), 8);
        }
        const rec = record(0x05, u16(channels.get(m.conn)), u32(sequence++), u64(t), u64(t), data);
        parts.push(rec);
        held += rec.length;
        if (held > 4 << 20) {
          write(Buffer.concat(parts));
          parts.length = 0;
          held = 0;
        }
      }
      if (parts.length) write(Buffer.concat(parts));
    }
    write(record(0x0f, u32(0)));
    write(record(0x02, u64(0), u64(0), u32(0)));
    write(MCAP_MAGIC);
  } finally {
    closeSync(fd);
  }
  return { bytes: size, messages: sequence, spanNs: span };
}
