// Bad ROS bags on the command line: `bag-info` and `run-log` on bags built
// here (tests/support/bags.mjs: a short drive round a ring corridor, /scan
// and /odom, as a ROS 1 bag, an MCAP file and a rosbag2 .db3), each then
// broken one way — cut inside a chunk, a wrong magic, an unknown
// compression, a chunk whose CRC or size lies, a LaserScan with no beams
// or whose range count lies, a .db3 without its messages table, a legacy
// format 1.2 bag, a bag without any LaserScan. Each must end in exit 2
// with a message naming the file (and the record or topic where the bag
// says so), or replay exactly what was complete and say what was lost;
// never an internal error, a Rust panic or a wasm trap. Needs no shared
// data. Run by ./build.sh test after ./build.sh build.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { runCli as run, tempDir } from './support/cli.mjs';
import {
  ringDrive, driveMessages, laserScan, ros1Bag, mcapFile, db3File, ros1, mcap, ROS1_MAGIC,
} from './support/bags.mjs';

const tmp = tempDir('bag-inputs');
const file = (name, bytes) => {
  const p = path.join(tmp, name);
  writeFileSync(p, bytes);
  return p;
};

/** `1234567` as `1,234,567`, as the readers write byte offsets. */
const commas = (n) => n.toLocaleString('en-US');

const SCANS = 60;
const drive = ringDrive(SCANS);
const ros1Messages = driveMessages(drive);
const cdrMessages = driveMessages(drive, { cdr: true });
// 20 messages a chunk: 10 odometry and 10 scans, so 6 chunks.
const PER_CHUNK = 20;
const SCANS_PER_CHUNK = PER_CHUNK / 2;
const stamps = drive.map((s) => Number(s.t_ns / 1000n) / 1e6);

/** Asserts a run printed no sign of a bug: no internal error, panic or trap. */
function noCrash(r, what) {
  const all = `${r.stdout}\n${r.stderr}`;
  for (const bad of ['internal error', 'panicked', 'RuntimeError', 'unreachable', 'Aborted']) {
    assert.ok(!all.includes(bad), `${what}: printed '${bad}':\n${all}`);
  }
  assert.notEqual(r.code, 1, `${what}: exit 1 (internal error)`);
}

/** Runs the CLI, asserts no crash, exit `code`, and every word of `words` in stderr. */
function expectRefused(args, words, what = args.join(' ')) {
  const r = run(...args);
  noCrash(r, what);
  assert.equal(r.code, 2, `${what}: exit ${r.code}, stderr:\n${r.stderr}`);
  for (const w of words) assert.ok(r.stderr.includes(w), `${what}: '${w}' missing from stderr:\n${r.stderr}`);
  assert.equal(r.stdout, '', `${what}: printed on stdout`);
  return r;
}

/** `run-log --json` that must succeed: the report. */
function replayed(bag, ...more) {
  const r = run('run-log', bag, '--json', ...more);
  noCrash(r, `run-log ${bag}`);
  assert.equal(r.code, 0, `run-log ${bag}: exit ${r.code}:\n${r.stderr}`);
  return JSON.parse(r.stdout);
}

/** `bag-info --json` that must succeed: the info. */
function info(bag) {
  const r = run('bag-info', bag, '--json');
  noCrash(r, `bag-info ${bag}`);
  assert.equal(r.code, 0, `bag-info ${bag}: exit ${r.code}:\n${r.stderr}`);
  return JSON.parse(r.stdout);
}

/** bag-info's text, which must succeed. */
function infoText(bag) {
  const r = run('bag-info', bag);
  noCrash(r, `bag-info ${bag}`);
  assert.equal(r.code, 0, `bag-info ${bag}: exit ${r.code}:\n${r.stderr}`);
  return r.stdout;
}

/** The scans' times of a report, in µs-rounded seconds. */
const times = (report) => report.scans.map((s) => s.time);

// ---------------------------------------------------------------------------
// The bags whole: what the broken ones are measured against

const good = {
  ros1: ros1Bag(ros1Messages, { perChunk: PER_CHUNK }),
  mcap: mcapFile(cdrMessages, { perChunk: PER_CHUNK }),
};
const goodRos1 = file('good.bag', good.ros1.bytes);
const goodMcap = file('good.mcap', good.mcap.bytes);

test('the whole bags read and replay every scan: the writer is right', () => {
  assert.equal(good.ros1.chunks.length, 6);
  for (const [bag, container] of [[goodRos1, 'ROS 1 bag 2.0'], [goodMcap, 'MCAP']]) {
    const i = info(bag);
    assert.equal(i.container, container);
    assert.equal(i.messages, 2 * SCANS);
    assert.equal(i.chunks, 6);
    assert.deepEqual(i.lost, []);
    assert.deepEqual(i.topics.map((t) => [t.name, t.count]).sort(), [['/odom', SCANS], ['/scan', SCANS]]);
    const r = replayed(bag);
    assert.equal(r.scans.length, SCANS);
    assert.deepEqual(r.bag.lost, []);
    assert.deepEqual(times(r), stamps);
    assert.equal(r.bag.picked.scan_topic, '/scan');
    assert.equal(r.bag.picked.odometry, '/odom');
  }
});

test('an MCAP without a summary section replays fully, as with one', () => {
  const bytes = mcapFile(cdrMessages, { perChunk: PER_CHUNK, summary: false }).bytes;
  assert.ok(bytes.length < good.mcap.bytes.length - 200, 'the summary section is left out');
  const bag = file('no-summary.mcap', bytes);
  const i = info(bag);
  assert.equal(i.messages, 2 * SCANS);
  assert.deepEqual(i.lost, []);
  const r = replayed(bag);
  const whole = replayed(goodMcap);
  assert.equal(r.scans.length, SCANS);
  assert.deepEqual(r.bag.lost, []);
  assert.deepEqual(r.scans.map((s) => s.pose), whole.scans.map((s) => s.pose));
});

test('a rosbag2 .db3 written here reads and replays: the SQLite writer is right', () => {
  const dir = path.join(tmp, 'good-db3');
  mkdirSync(dir);
  writeFileSync(path.join(dir, 'good_0.db3'), db3File(cdrMessages));
  const i = info(dir);
  assert.equal(i.container, 'rosbag2 SQLite');
  assert.equal(i.messages, 2 * SCANS);
  assert.deepEqual(replayed(dir).scans.length, SCANS);
});

// ---------------------------------------------------------------------------
// Cut short: what was complete is replayed, and the loss is said

for (const kind of ['ros1', 'mcap']) {
  test(`${kind === 'ros1' ? 'a ROS 1 bag' : 'an MCAP file'} cut inside its 4th chunk replays the 3 chunks before, and says so`, () => {
    const { bytes, chunks } = good[kind];
    const c = chunks[3];
    const cut = file(`cut.${kind === 'ros1' ? 'bag' : 'mcap'}`, bytes.subarray(0, c.offset + Math.floor(c.length / 2)));
    const lost = `ends inside chunk 4 at byte ${commas(c.offset)}`;

    const i = info(cut);
    assert.equal(i.messages, 3 * PER_CHUNK);
    assert.equal(i.chunks, 3);
    assert.equal(i.lost.length, 1);
    assert.ok(i.lost[0].startsWith(`${cut}: `) && i.lost[0].includes(lost), i.lost[0]);
    assert.ok(i.lost[0].includes('the messages of that chunk are lost'), i.lost[0]);
    assert.match(infoText(cut), new RegExp(`^Lost: +${cut.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')}: .*${lost}`, 'm'));

    const r = replayed(cut);
    assert.equal(r.scans.length, 3 * SCANS_PER_CHUNK);
    assert.deepEqual(times(r), stamps.slice(0, 3 * SCANS_PER_CHUNK));
    assert.equal(r.bag.lost.length, 1);
    assert.ok(r.bag.lost[0].includes(lost), r.bag.lost[0]);

    const text = run('run-log', cut);
    noCrash(text, 'run-log text');
    assert.equal(text.code, 0);
    assert.ok(text.stdout.includes(`lost: ${cut}: `) && text.stdout.includes(lost), text.stdout);
  });
}

// ---------------------------------------------------------------------------
// Not a bag this reader reads

test('a wrong magic is refused by both commands, naming the file and what it starts with', () => {
  const v3 = file('v3.bag', Buffer.concat([Buffer.from('#ROSBAG V3.0\n'), good.ros1.bytes.subarray(ROS1_MAGIC.length)]));
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, v3], [v3, 'not a ROS 1 bag', '#ROSBAG V3.0']);
  }
  // An MCAP whose magic lost a byte is no bag at all; the name says it should be one.
  const broken = Buffer.from(good.mcap.bytes);
  broken[5] = 0x31; // "\x89MCAP1\r\n"
  const m = file('magic.mcap', broken);
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, m], [m, 'not a ROS bag', 'MCAP']);
  }
  // Empty, and shorter than any magic.
  const empty = file('empty.bag', Buffer.alloc(0));
  const short = file('short.mcap', good.mcap.bytes.subarray(0, 5));
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, empty], [empty, 'the file is empty']);
    expectRefused([cmd, short], [short, 'not a ROS bag']);
  }
});

test('a legacy #ROSRECORD V1.2 bag is refused with what it is and how to convert it', () => {
  const legacy = file('legacy.bag', Buffer.concat([
    Buffer.from('#ROSRECORD V1.2\n'),
    ros1.record([ros1.field('op', Buffer.from([0x02]))], Buffer.alloc(8)),
  ]));
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, legacy], [legacy, 'old format 1.2', 'rosbag filter']);
  }
});

// ---------------------------------------------------------------------------
// Chunks that cannot be opened

test('an unknown compression is refused, naming the chunk and the compression', () => {
  const r1 = ros1Bag(ros1Messages, { perChunk: PER_CHUNK, chunkOptions: (k) => (k === 1 ? { compression: 'zip' } : {}) });
  const bag = file('zip.bag', r1.bytes);
  const m1 = mcapFile(cdrMessages, { perChunk: PER_CHUNK, chunkOptions: (k) => (k === 1 ? { compression: 'brotli' } : {}) });
  const mc = file('brotli.mcap', m1.bytes);
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, bag], [bag, `chunk 2 at byte ${commas(r1.chunks[1].offset)}`, '"zip"', 'none, bz2 or lz4']);
    expectRefused([cmd, mc], [mc, `chunk 2 at byte ${commas(m1.chunks[1].offset)}`, '"brotli"', 'zstd, lz4 or none']);
  }
});

test('an MCAP chunk whose CRC lies is skipped: the other chunks replay, the loss is said', () => {
  const m = mcapFile(cdrMessages, { perChunk: PER_CHUNK, chunkOptions: (k) => (k === 2 ? { crc: 0x12345678 } : {}) });
  const bag = file('crc.mcap', m.bytes);
  const lost = `chunk 3 at byte ${commas(m.chunks[2].offset)} is skipped, its messages lost: its CRC-32 says 0x12345678`;
  const i = info(bag);
  assert.equal(i.messages, 5 * PER_CHUNK);
  assert.ok(i.lost.length === 1 && i.lost[0].includes(lost), i.lost.join('\n'));
  assert.ok(infoText(bag).includes(`Lost:              ${bag}: ${lost}`));
  const r = replayed(bag);
  const kept = [...stamps.slice(0, 2 * SCANS_PER_CHUNK), ...stamps.slice(3 * SCANS_PER_CHUNK)];
  assert.deepEqual(times(r), kept);
  assert.ok(r.bag.lost[0].includes(lost));
});

test('a ROS 1 chunk whose size field lies is skipped: the other chunks replay, the loss is said', () => {
  const r1 = ros1Bag(ros1Messages, {
    perChunk: PER_CHUNK,
    chunkOptions: (k) => (k === 2 ? { size: 4000 } : {}),
  });
  const bag = file('size.bag', r1.bytes);
  const whole = r1.chunks[2].length;
  assert.ok(whole > 4000);
  const lost = `chunk 3 at byte ${commas(r1.chunks[2].offset)} is skipped, its messages lost: its size field says 4,000 bytes uncompressed`;
  const i = info(bag);
  assert.equal(i.messages, 5 * PER_CHUNK);
  assert.equal(i.chunks, 5);
  assert.ok(i.lost.length === 1 && i.lost[0].includes(lost), i.lost.join('\n'));
  const r = replayed(bag);
  const kept = [...stamps.slice(0, 2 * SCANS_PER_CHUNK), ...stamps.slice(3 * SCANS_PER_CHUNK)];
  assert.deepEqual(times(r), kept);
  assert.ok(r.bag.lost[0].includes(lost));
});

test('a ROS 1 chunk record whose length lies throws the framing off: refused at the record after it', () => {
  // The chunk record's data length says 3 bytes more than it holds: the
  // chunk swallows the start of the index record after it.
  const { bytes, chunks } = good.ros1;
  const broken = Buffer.from(bytes);
  const c = chunks[1];
  const headerLen = broken.readUInt32LE(c.offset);
  const at = c.offset + 4 + headerLen;
  broken.writeUInt32LE(broken.readUInt32LE(at) + 3, at);
  const bag = file('length.bag', broken);
  const next = c.offset + c.length + 3;
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, bag], [`${bag}: the record at byte ${commas(next)}: `, 'runs past the header\'s end']);
  }
});

// ---------------------------------------------------------------------------
// Messages the lab cannot use

test('a LaserScan with no beams: bag-info lists the bag, run-log refuses it naming topic and message', () => {
  const zeroAt = 7;
  const msgs = driveMessages(drive, { scan: (i, s) => laserScan(i === zeroAt ? { ...s, ranges: [] } : s) });
  const bag = file('zero-beams.bag', ros1Bag(msgs, { perChunk: PER_CHUNK }).bytes);
  const text = infoText(bag);
  assert.match(text, /Topic: \/scan \| Type: sensor_msgs\/LaserScan \| Count: 60/);
  assert.match(text, /run-log: +cannot replay: .*\/scan, message 8: a scan with no beams/);
  expectRefused(['run-log', bag], [bag, '/scan', 'message 8', 'no beams']);
});

test('a LaserScan whose range count lies does not decode: refused naming file, chunk, topic and field', () => {
  const msgs = driveMessages(drive, { scan: (i, s) => laserScan(s, { count: i === 25 ? 1000 : undefined }) });
  const r1 = ros1Bag(msgs, { perChunk: PER_CHUNK });
  const bag = file('count.bag', r1.bytes);
  const cdr = driveMessages(drive, { cdr: true, scan: (i, s) => laserScan(s, { cdr: true, count: i === 25 ? 1000 : undefined }) });
  const m1 = mcapFile(cdr, { perChunk: PER_CHUNK });
  const mc = file('count.mcap', m1.bytes);
  // Scan 25 (from 0) is the 6th scan of chunk 3.
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, bag], [bag, `chunk 3 at byte ${commas(r1.chunks[2].offset)}`, 'topic /scan',
      'message 26 of the topic does not decode as sensor_msgs/LaserScan', 'ranges: 1000 floats claimed']);
    expectRefused([cmd, mc], [mc, `chunk 3 at byte ${commas(m1.chunks[2].offset)}`, 'topic /scan',
      'message 26 of the topic does not decode as sensor_msgs/LaserScan', 'ranges: 1000 floats claimed']);
  }
});

test('a bag without any LaserScan: bag-info lists its topics, run-log refuses it naming them', () => {
  const bag = file('odom-only.bag', ros1Bag(driveMessages(drive, { topics: [1] }), { perChunk: PER_CHUNK }).bytes);
  const i = info(bag);
  assert.deepEqual(i.topics.map((t) => [t.name, t.type, t.count]), [['/odom', 'nav_msgs/Odometry', SCANS]]);
  assert.deepEqual(i.scan_topics, []);
  assert.match(infoText(bag), /run-log: +cannot replay: .*no sensor_msgs\/LaserScan topic in the bag/);
  expectRefused(['run-log', bag], [bag, 'no sensor_msgs/LaserScan topic in the bag', '/odom (nav_msgs/Odometry)']);
});

test('a .db3 without its messages table is refused by both commands, naming the table', () => {
  const db = file('no-messages.db3', db3File(cdrMessages, { messagesTable: false }));
  for (const cmd of ['bag-info', 'run-log']) {
    expectRefused([cmd, db], [db, 'messages', 'not a rosbag2 bag']);
  }
});
