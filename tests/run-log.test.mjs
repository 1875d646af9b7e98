// The `run-log` command on small logs made here (a robot driving round a
// furnished room, ranges cast exactly): the report's fields, --from/--to,
// --out, gzip input, and the exit status of bad input (2, naming the line).
// Run by ./build.sh test after ./build.sh build.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync, readFileSync, existsSync } from 'node:fs';
import { gzipSync } from 'node:zlib';
import path from 'node:path';
import { CLI as cli, ROOT as root, runCli as run, tempDir } from './support/cli.mjs';

const tmp = tempDir('runlog');

// A 12 x 8 m room with two pillars: wall segments [x1, y1, x2, y2].
const walls = [
  [-6, -4, 6, -4], [6, -4, 6, 4], [6, 4, -6, 4], [-6, 4, -6, -4],
  [-1, -1, 0, -1], [0, -1, 0, 0], [0, 0, -1, 0], [-1, 0, -1, -1],
  [3, 1, 3.5, 1], [3.5, 1, 3.5, 2.5], [3.5, 2.5, 3, 2.5], [3, 2.5, 3, 1],
];

function cast(x, y, a, max) {
  const dx = Math.cos(a), dy = Math.sin(a);
  let best = max;
  for (const [x1, y1, x2, y2] of walls) {
    const ex = x2 - x1, ey = y2 - y1;
    const den = dx * ey - dy * ex;
    if (Math.abs(den) < 1e-12) continue;
    const t = ((x1 - x) * ey - (y1 - y) * ex) / den;
    const u = ((x1 - x) * dy - (y1 - y) * dx) / den;
    if (t > 0 && u >= 0 && u <= 1 && t < best) best = t;
  }
  return best;
}

/** A loop round the room: 181-beam FLASER records whose odometry drifts
 *  (a heading bias), ODOM records between them; returns text and truth. */
function makeLog(n = 160) {
  const lines = ['# made by tests/run-log.test.mjs', 'PARAM robot_frontlaser_offset 0.0 nohost 0'];
  const truth = [];
  let odo = null;
  let prev = null;
  for (let i = 0; i < n; i++) {
    const s = (2 * Math.PI * i) / (n - 1);
    const p = { x: 4.5 * Math.cos(s), y: 2.8 * Math.sin(s), theta: 0 };
    const q = { x: -4.5 * Math.sin(s), y: 2.8 * Math.cos(s) };
    p.theta = Math.atan2(q.y, q.x);
    if (prev === null) {
      odo = { ...p };
    } else {
      // The true step in the previous pose's frame, turned by a bias.
      const c = Math.cos(prev.theta), sn = Math.sin(prev.theta);
      const ddx = p.x - prev.x, ddy = p.y - prev.y;
      const lx = c * ddx + sn * ddy, ly = -sn * ddx + c * ddy;
      const dth = Math.atan2(Math.sin(p.theta - prev.theta), Math.cos(p.theta - prev.theta)) + 0.004;
      const oc = Math.cos(odo.theta), os = Math.sin(odo.theta);
      odo = { x: odo.x + oc * lx - os * ly, y: odo.y + os * lx + oc * ly, theta: odo.theta + dth };
    }
    prev = p;
    truth.push(p);
    const ranges = [];
    for (let b = 0; b < 181; b++) {
      const r = cast(p.x, p.y, p.theta - Math.PI / 2 + (Math.PI * b) / 180, 81.91);
      ranges.push(r >= 81.91 ? '81.91' : r.toFixed(3));
    }
    const o = `${odo.x.toFixed(5)} ${odo.y.toFixed(5)} ${odo.theta.toFixed(5)}`;
    const t = (100 + 0.5 * i).toFixed(3);
    lines.push(`ODOM ${o} 0.3 0 0 ${t} host ${t}`);
    lines.push(`FLASER 181 ${ranges.join(' ')} ${o} ${o} ${t} host ${t}`);
  }
  return { text: lines.join('\n') + '\n', truth };
}

const { text, truth } = makeLog();
const plain = path.join(tmp, 'room.log');
writeFileSync(plain, text);
const gz = path.join(tmp, 'room.clf.gz');
writeFileSync(gz, gzipSync(text));

function relative(a, b) {
  const c = Math.cos(a[2]), s = Math.sin(a[2]);
  const dx = b[0] - a[0], dy = b[1] - a[1];
  return [c * dx + s * dy, -s * dx + c * dy, Math.atan2(Math.sin(b[2] - a[2]), Math.cos(b[2] - a[2]))];
}

test('run-log --json: one entry per scan, poses near the truth, better than odometry', () => {
  const r = run('run-log', gz, '--json');
  assert.equal(r.code, 0, r.stderr);
  const rep = JSON.parse(r.stdout);
  assert.equal(rep.scans.length, truth.length);
  assert.deepEqual(rep.scans.map((s) => s.index), truth.map((_, i) => i));
  assert.match(rep.frame, /odometry frame/);
  assert.equal(rep.scans[5].time, 102.5);
  for (const k of ['width', 'height', 'resolution_m', 'origin_m']) assert.ok(k in rep.map, k);
  for (const k of ['parse', 'slam', 'map', 'total']) assert.ok(rep.timings_ms[k] >= 0, k);
  // Relations 20 scans apart against the truth: SLAM under 5 cm, and
  // well under the drifting odometry's.
  let ours = 0, odom = 0, n = 0;
  const T = truth.map((p) => [p.x, p.y, p.theta]);
  for (let i = 0; i + 20 < T.length; i++) {
    const t = relative(T[i], T[i + 20]);
    const e = relative(rep.scans[i].pose, rep.scans[i + 20].pose);
    const o = relative(rep.scans[i].odometry, rep.scans[i + 20].odometry);
    ours += Math.hypot(e[0] - t[0], e[1] - t[1]);
    odom += Math.hypot(o[0] - t[0], o[1] - t[1]);
    n++;
  }
  assert.ok(ours / n < 0.05, `SLAM relation error ${ours / n}`);
  assert.ok(ours / n < odom / n / 4, `SLAM ${ours / n} vs odometry ${odom / n}`);
});

test('run-log --from/--to replays a stretch; --out writes PGM, YAML and PNG', () => {
  const out = path.join(tmp, 'room.yaml');
  const r = run('run-log', plain, '--from', '10', '--to', '40', '--out', out);
  assert.equal(r.code, 0, r.stderr);
  assert.match(r.stdout, /31 of 160 laser records replayed \(10\.\.40\)/);
  assert.ok(existsSync(path.join(tmp, 'room.pgm')) && existsSync(path.join(tmp, 'room.png')));
  assert.match(readFileSync(out, 'utf8'), /image: "room\.pgm"/);
  const j = JSON.parse(run('run-log', plain, '--from', '10', '--to', '40', '--json').stdout);
  assert.equal(j.scans[0].index, 10);
  assert.equal(j.scans.at(-1).index, 40);
});

test('run-log --trajectory writes the SLAM poses as a TUM trajectory, one line a scan', () => {
  const out = path.join(tempDir(), 'run.tum');
  const r = run('run-log', plain, '--json', '--trajectory', out);
  assert.equal(r.code, 0, r.stderr);
  const report = JSON.parse(r.stdout);
  const lines = readFileSync(out, 'utf8').trim().split('\n');
  assert.match(lines[0], /^# timestamp x y z qx qy qz qw/);
  const rows = lines.slice(1).map((l) => l.split(' ').map(Number));
  assert.equal(rows.length, report.scans.length);
  rows.forEach((row, k) => {
    const scan = report.scans[k];
    assert.equal(row.length, 8);
    assert.ok(Math.abs(row[0] - scan.time) < 1e-6, `time of scan ${k}`);
    assert.ok(Math.abs(row[1] - scan.pose[0]) < 1e-9 && Math.abs(row[2] - scan.pose[1]) < 1e-9, `position of scan ${k}`);
    assert.deepEqual([row[3], row[4], row[5]], [0, 0, 0]);
    // A rotation about z by the scan's heading: (0, 0, sin θ/2, cos θ/2).
    const th = 2 * Math.atan2(row[6], row[7]);
    const d = Math.atan2(Math.sin(th - scan.pose[2]), Math.cos(th - scan.pose[2]));
    assert.ok(Math.abs(d) < 1e-9 && Math.abs(Math.hypot(row[6], row[7]) - 1) < 1e-9, `heading of scan ${k}`);
  });
});

test('run-log: bad input exits 2 with a message naming the line', () => {
  const lines = text.split('\n');
  // Line 10 cut short in the middle of its ranges.
  lines[9] = lines[9].split(' ').slice(0, 60).join(' ');
  const bad = path.join(tmp, 'bad.log');
  writeFileSync(bad, lines.join('\n'));
  let r = run('run-log', bad, '--json');
  assert.equal(r.code, 2);
  assert.equal(r.stdout, '');
  assert.match(r.stderr, /line 10: FLASER record is truncated/);
  r = run('run-log', path.join(tmp, 'missing.log'));
  assert.equal(r.code, 2);
  assert.match(r.stderr, /cannot read log/);
  r = run('run-log', plain, '--from', 'x');
  assert.equal(r.code, 2);
  r = run('run-log', plain, '--from', '500');
  assert.equal(r.code, 2);
  assert.match(r.stderr, /--from 500/);
  const empty = path.join(tmp, 'empty.log');
  writeFileSync(empty, '# nothing\n');
  r = run('run-log', empty);
  assert.equal(r.code, 2);
  assert.match(r.stderr, /no laser records/);
});
