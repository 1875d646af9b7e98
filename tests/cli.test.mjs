// End-to-end tests of the command line (web/cli.mjs) on the wasm build.
// Run by ./build.sh test after ./build.sh build.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync, writeFileSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { CLI as cli, ROOT as root, runCli as run, tempDir } from './support/cli.mjs';

const tmp = tempDir('cli');

function scenarioFile(name, obj) {
  const p = path.join(tmp, name);
  writeFileSync(p, typeof obj === 'string' ? obj : JSON.stringify(obj));
  return p;
}


/** Parses a binary PGM: "P5", width, height, 255 (comment lines allowed
 *  between), one whitespace, then the w*h bytes. */
function readPgm(file) {
  const pgm = readFileSync(file);
  const header = pgm.subarray(0, 200).toString('latin1').match(/^P5(?:\s+|#[^\n]*\n)+(\d+)\s+(\d+)\s+255\s/);
  assert.ok(header, `a P5 header in ${file}`);
  return { w: Number(header[1]), h: Number(header[2]), data: pgm.subarray(header[0].length) };
}
test('run --json prints only the report, with aligned trajectories', () => {
  const r = run('run', 'scenarios/thesis.json', '--json', '--duration', '20');
  assert.equal(r.code, 0, r.stderr);
  const report = JSON.parse(r.stdout); // stdout is exactly one JSON document
  assert.equal(report.scenario, 'thesis');
  assert.equal(report.seed, 7);
  assert.equal(report.robots.length, 2);
  const thesis = JSON.parse(readFileSync(path.join(root, 'scenarios/thesis.json'), 'utf8'));
  for (const [i, robot] of report.robots.entries()) {
    assert.equal(robot.name, thesis.robots[i].name);
    assert.equal(robot.truth.length, 201);
    assert.equal(robot.odometry.length, 201);
    assert.deepEqual(robot.truth[0], [0, ...thesis.robots[i].start]);
    assert.deepEqual(robot.odometry[0], [0, 0, 0, 0]);
    // Rows are aligned on the same times, 0.1 s apart.
    for (let k = 0; k < 201; k++) {
      assert.equal(robot.truth[k][0], robot.odometry[k][0]);
      assert.ok(Math.abs(robot.truth[k][0] - k / 10) < 1e-9);
    }
    assert.equal(robot.bumps, 0);
    assert.ok(robot.path_length_m > 4 && robot.path_length_m < 7.5, `${robot.path_length_m}`);
  }
  assert.ok(report.timings_ms.simulate > 0);
  assert.ok(r.stderr.includes('simulated 20.0 / 20.0 s'), 'progress goes to stderr');
});

test('the same seed gives the same run; another seed another', () => {
  const a = run('run', 'scenarios/office.json', '--json', '--duration', '15', '--seed', '3');
  const b = run('run', 'scenarios/office.json', '--json', '--duration', '15', '--seed', '3');
  const c = run('run', 'scenarios/office.json', '--json', '--duration', '15', '--seed', '4');
  const strip = (s) => {
    const j = JSON.parse(s);
    delete j.timings_ms;
    if (j.merge) delete j.merge.timings_ms;
    return j;
  };
  assert.deepEqual(strip(a.stdout), strip(b.stdout));
  assert.equal(JSON.parse(a.stdout).seed, 3);
  assert.notDeepEqual(strip(a.stdout).robots[0].odometry, strip(c.stdout).robots[0].odometry);
});

test('a human-readable summary without --json', () => {
  const r = run('run', 'scenarios/loop.json', '--duration', '5');
  assert.equal(r.code, 0, r.stderr);
  assert.match(r.stdout, /scenario loop, seed 3: 50 steps/);
  assert.match(r.stdout, /robot1 \(follows right wall\)/);
});

const bad = [
  ['unknown key', { walls: [], robots: [{ name: 'a', start: [1, 1, 0], follow: 'left' }], speed: 2 }, /^error: speed: unknown key/m],
  ['non-finite number', { walls: [{ from: [0, 0], to: [1, null] }], robots: [] }, /^error: walls\[0\]\.to\[1\]: expected a number, found null/m],
  ['zero-length wall', { walls: [{ from: [2, 2], to: [2, 2] }], robots: [{ name: 'a', start: [5, 5, 0], follow: 'left' }] }, /^error: walls\[0\]: zero-length wall/m],
  ['robot inside a wall', { walls: [{ from: [0, 0], to: [4, 0] }], robots: [{ name: 'a', start: [2, 0.05, 0], follow: 'left' }] }, /^error: robots\[0\]\.start: robot 'a' starts inside or touching walls\[0\]/m],
  ['duplicate names', { walls: [], robots: [{ name: 'a', start: [1, 1, 0], follow: 'left' }, { name: 'a', start: [5, 1, 0], follow: 'left' }] }, /^error: robots\[1\]\.name: duplicate robot name 'a'/m],
  ['17 robots', { walls: [], robots: Array.from({ length: 17 }, (_, i) => ({ name: `r${i}`, start: [i * 2, 0, 0], follow: 'left' })) }, /^error: robots: 17 robots, at most 16 allowed/m],
  ['not JSON', '{"walls": [', /^error: not valid JSON/m],
];
for (const [what, content, pattern] of bad) {
  test(`bad scenario (${what}) exits 2 naming the problem`, () => {
    const r = run('run', scenarioFile(`${what.replace(/\W+/g, '_')}.json`, content), '--json');
    assert.equal(r.code, 2);
    assert.equal(r.stdout, '');
    assert.match(r.stderr, pattern);
  });
}

test('10,001 walls exit 2', () => {
  const walls = Array.from({ length: 10001 }, (_, i) => ({ from: [i, 50], to: [i, 51] }));
  const r = run('run', scenarioFile('walls.json', { walls, robots: [{ name: 'a', start: [0.5, 2, 0], follow: 'left' }] }));
  assert.equal(r.code, 2);
  assert.match(r.stderr, /walls: 10001 walls, at most 10000 allowed/);
});

test('bad command lines exit 2 with a message', () => {
  for (const [args, pattern] of [
    [['run'], /expected exactly one SCENARIO/],
    [['run', 'no/such/file.json'], /cannot read scenario 'no\/such\/file.json': ENOENT/],
    [['run', 'scenarios/thesis.json', '--seed', '-3'], /--seed: '-3' is not a whole number/],
    [['run', 'scenarios/thesis.json', '--seed', 'abc'], /--seed/],
    [['run', 'scenarios/thesis.json', '--duration', 'x'], /--duration: 'x' is not a number/],
    [['run', 'scenarios/thesis.json', '--duration', '0'], /duration_s: 0 is outside/],
    [['run', 'scenarios/thesis.json', '--duration'], /--duration needs a value/],
    [['run', 'scenarios/thesis.json', '--frobnicate'], /unknown option --frobnicate/],
    [['run', 'scenarios/thesis.json', '--method', 'magic'], /--method: 'magic' is not one of auto, thesis, map-only/],
    [['run', 'scenarios/thesis.json', '--workers', '-1'], /--workers: '-1' is not a whole number from 0 to 64/],
    [['run', 'scenarios/thesis.json', '--workers', '65'], /--workers: '65'/],
    [['merge', 'scenarios/thesis.json'], /--out FILE.yaml is required/],
    [['fly'], /unknown command 'fly'/],
    [[], /usage:/],
  ]) {
    const r = run(...args);
    assert.equal(r.code, 2, `${args.join(' ')}: ${r.stderr}`);
    assert.match(r.stderr, pattern, args.join(' '));
  }
});

test('frames writes one PNG per captured frame and an index', () => {
  const out = path.join(tmp, 'frames');
  const r = run('frames', 'scenarios/thesis.json', '--out', out, '--duration', '5');
  assert.equal(r.code, 0, r.stderr);
  const index = JSON.parse(readFileSync(path.join(out, 'index.json'), 'utf8'));
  assert.equal(index.scenario, 'thesis');
  // The camera as the scenario gives it, and its capture period (s).
  assert.deepEqual(index.camera, { width: 320, height: 240, hfov_deg: 60, period_s: 1 });
  // Two robots, a frame at t = 0, 1, ..., 5 s each.
  assert.equal(index.frames.length, 12);
  const thesis = JSON.parse(readFileSync(path.join(root, 'scenarios/thesis.json'), 'utf8'));
  for (const [k, f] of index.frames.entries()) {
    const robot = k < 6 ? 'robot1' : 'robot2';
    assert.equal(f.robot, robot);
    assert.equal(f.index, k % 6);
    assert.equal(f.time, k % 6);
    assert.equal(f.odometry.length, 3);
    assert.equal(f.truth.length, 3);
    if (f.index === 0) {
      assert.deepEqual(f.odometry, [0, 0, 0]);
      assert.deepEqual(f.truth, thesis.robots[k < 6 ? 0 : 1].start);
    }
    const png = readFileSync(path.join(out, f.file));
    assert.deepEqual([...png.subarray(0, 8)], [137, 80, 78, 71, 13, 10, 26, 10], 'a PNG signature');
    assert.equal(png.readUInt32BE(16), 320); // IHDR width
    assert.equal(png.readUInt32BE(20), 240); // IHDR height
    assert.equal(png[25], 0, 'colour type 0: greyscale');
  }
  assert.match(r.stderr, /wrote 12 frames/);
});

test('frames refuses bad input with exit 2', () => {
  for (const [args, pattern] of [
    [['frames', 'scenarios/thesis.json'], /--out DIR is required/],
    [['frames', '--out', path.join(tmp, 'x')], /expected exactly one SCENARIO/],
    [['frames', 'nope.json', '--out', path.join(tmp, 'x')], /cannot read scenario 'nope.json'/],
  ]) {
    const r = run(...args);
    assert.equal(r.code, 2, r.stderr);
    assert.match(r.stderr, pattern);
  }
});

test('map writes a ROS map_server PGM + YAML and a PNG', () => {
  const out = path.join(tmp, 'map', 'thesis.yaml');
  mkdirSync(path.dirname(out), { recursive: true });
  const r = run('map', 'scenarios/thesis.json', '--robot', 'robot2', '--out', out, '--duration', '20');
  assert.equal(r.code, 0, r.stderr);
  const yaml = readFileSync(out, 'utf8');
  assert.match(yaml, /^image: "?thesis\.pgm"?$/m);
  assert.match(yaml, /^resolution: 0\.05$/m);
  assert.match(yaml, /^origin: \[-?[\d.]+, -?[\d.]+, 0(\.0)?\]$/m);
  assert.match(yaml, /^negate: 0$/m);
  assert.match(yaml, /^occupied_thresh: 0\.65$/m);
  assert.match(yaml, /^free_thresh: 0\.196$/m);
  // Binary PGM: "P5", width, height, 255 (comment lines allowed between),
  // one whitespace, then w*h bytes of 254 / 0 / 205 only.
  const { w, h, data } = readPgm(path.join(path.dirname(out), 'thesis.pgm'));
  assert.equal(data.length, w * h);
  const counts = { 0: 0, 205: 0, 254: 0 };
  for (const v of data) {
    assert.ok(v in counts, `unexpected cell value ${v}`);
    counts[v] += 1;
  }
  assert.ok(counts[0] > 50 && counts[254] > 500 && counts[205] > 0, JSON.stringify(counts));
  const png = readFileSync(path.join(path.dirname(out), 'thesis.png'));
  assert.deepEqual([...png.subarray(1, 4)], [80, 78, 71]);
  // Bad input.
  for (const [args, pattern] of [
    [['map', 'scenarios/thesis.json', '--robot', 'nobody', '--out', out, '--duration', '1'], /no robot named 'nobody'/],
    [['map', 'scenarios/thesis.json', '--out', out], /--robot NAME is required/],
    [['map', 'scenarios/thesis.json', '--robot', 'robot1', '--out', out, '--mapper', 'magic'], /--mapper/],
  ]) {
    const b = run(...args);
    assert.equal(b.code, 2, b.stderr);
    assert.match(b.stderr, pattern);
  }
});

test('features and match keep the interface JSON', () => {
  const f = run('features', 'tests/data/coffee.png', '--json');
  assert.equal(f.code, 0, f.stderr);
  const feats = JSON.parse(f.stdout);
  assert.equal(feats.width, 640);
  assert.equal(feats.height, 480);
  assert.ok(feats.keypoints.length > 500, `${feats.keypoints.length} keypoints`);
  for (const k of feats.keypoints.slice(0, 50)) {
    for (const key of ['x', 'y', 'scale', 'orientation', 'laplacian', 'descriptor']) assert.ok(key in k, key);
    assert.ok([1, -1].includes(k.laplacian));
    assert.equal(k.descriptor.length, 64);
  }
  const m = run('match', 'tests/data/coffee.png', 'tests/data/coffee_rot12_s085.png', '--json');
  assert.equal(m.code, 0, m.stderr);
  const res = JSON.parse(m.stdout);
  assert.ok(res.matches > 100 && res.inliers > 100 && res.inliers <= res.matches);
  assert.equal(res.homography.length, 3);
  assert.equal(res.quad.length, 4);
  // The known warp: rotation 12° and scale 0.85 about the image centre.
  const H = res.homography;
  const project = ([x, y]) => {
    const w = H[2][0] * x + H[2][1] * y + H[2][2];
    return [(H[0][0] * x + H[0][1] * y + H[0][2]) / w, (H[1][0] * x + H[1][1] * y + H[1][2]) / w];
  };
  const c = Math.cos((12 * Math.PI) / 180) * 0.85;
  const s = Math.sin((12 * Math.PI) / 180) * 0.85;
  for (const p of [[100, 100], [540, 380], [319.5, 239.5]]) {
    const [dx, dy] = [p[0] - 319.5, p[1] - 239.5];
    const expected = [319.5 + c * dx - s * dy, 239.5 + s * dx + c * dy];
    const got = project(p);
    assert.ok(Math.hypot(got[0] - expected[0], got[1] - expected[1]) < 1.5, `${p} -> ${got} vs ${expected}`);
  }
  const bad = run('match', 'tests/data/coffee.png', 'tests/data/README.md', '--json');
  assert.equal(bad.code, 2);
  assert.match(bad.stderr, /not a PNG or JPEG/);
});

test('worker threads describing frames during the run change nothing in the report', () => {
  const strip = (s) => {
    const j = JSON.parse(s);
    delete j.timings_ms;
    if (j.merge) delete j.merge.timings_ms;
    return j;
  };
  for (const method of ['auto', 'thesis']) {
    const args = ['run', 'scenarios/thesis.json', '--json', '--method', method];
    const [none, one, three] = ['0', '1', '3'].map((w) => run(...args, '--workers', w));
    for (const r of [none, one, three]) assert.equal(r.code, 0, r.stderr);
    const alone = strip(none.stdout);
    assert.ok(alone.match_tables[0].rows.length > 0, `${method}: frames took part`);
    assert.ok(alone.match_tables[0].inliers.flat().some((n) => n > 0), `${method}: some pair matched`);
    assert.deepEqual(strip(one.stdout), alone, `${method}: one worker`);
    assert.deepEqual(strip(three.stdout), alone, `${method}: three workers`);
    assert.doesNotMatch(three.stderr, /describing frames/, 'no worker failed');
  }
});

test('run merges with the automatic method: the report carries the table, the verdict and the transform', () => {
  const r = run('run', 'scenarios/thesis.json', '--json');
  assert.equal(r.code, 0, r.stderr);
  const report = JSON.parse(r.stdout);
  assert.equal(report.method, 'auto');
  assert.equal(report.match_tables.length, 1);
  const t = report.match_tables[0];
  assert.equal(t.a, 'robot1');
  assert.equal(t.b, 'robot2');
  assert.equal(t.inliers.length, t.rows.length);
  for (const row of t.inliers) assert.equal(row.length, t.cols.length);
  assert.ok(t.rows.every((i) => Number.isInteger(i) && i >= 0 && i < report.robots[0].frames));
  assert.ok(t.inliers.flat().some((n) => n >= 10), 'some frame pairs share a place');
  const m = report.merge;
  assert.equal(m.status, 'merged', m.reason);
  assert.ok(m.confidence > 0 && m.confidence <= 1, `${m.confidence}`);
  assert.deepEqual(m.transforms.map((x) => x.robot), ['robot1', 'robot2']);
  assert.deepEqual(m.transforms[0].pose, [0, 0, 0]);
  // The truth: robot2's start pose seen from robot1's start pose.
  const thesis = JSON.parse(readFileSync(path.join(root, 'scenarios/thesis.json'), 'utf8'));
  const [x1, y1, t1] = thesis.robots[0].start;
  const [x2, y2, t2] = thesis.robots[1].start;
  const dx = x2 - x1;
  const dy = y2 - y1;
  const truth = [Math.cos(t1) * dx + Math.sin(t1) * dy, -Math.sin(t1) * dx + Math.cos(t1) * dy, t2 - t1];
  const [x, y, th] = m.transforms[1].pose;
  const dth = Math.atan2(Math.sin(th - truth[2]), Math.cos(th - truth[2]));
  assert.ok(Math.hypot(x - truth[0], y - truth[1]) < 0.1, `robot2's frame at ${x}, ${y}; truth ${truth}`);
  assert.ok(Math.abs(dth) < (1 * Math.PI) / 180, `heading off by ${dth} rad`);
  const e = m.errors.find((q) => q.robot === 'robot2');
  assert.ok(Math.abs(e.error_m - Math.hypot(x - truth[0], y - truth[1])) < 1e-3, 'the report scores the same error');
  for (const k of ['simulate', 'camera', 'slam', 'features', 'matching', 'merge', 'total']) {
    assert.ok(typeof report.timings_ms[k] === 'number' && report.timings_ms[k] >= 0, k);
  }
  assert.ok(report.timings_ms.features > 0 && report.timings_ms.matching > 0);
});

test('robots that never share a place: no_merge with the reason, only the first robot joined', () => {
  const room = (ox) => [
    { from: [ox, 0], to: [ox + 6, 0] }, { from: [ox + 6, 0], to: [ox + 6, 4] },
    { from: [ox + 6, 4], to: [ox, 4] }, { from: [ox, 4], to: [ox, 0] },
    { from: [ox + 2, 2], to: [ox + 4, 2] },
  ];
  const file = scenarioFile('apart.json', {
    name: 'apart', seed: 11, duration_s: 90,
    walls: [...room(0), ...room(20)],
    robots: [
      { name: 'a', start: [1, 1, 0], follow: 'left' },
      { name: 'b', start: [21, 1, 0.5], follow: 'right' },
    ],
  });
  for (const method of ['auto', 'map-only']) {
    const r = run('run', file, '--json', '--method', method);
    assert.equal(r.code, 0, r.stderr);
    const m = JSON.parse(r.stdout).merge;
    assert.equal(m.status, 'no_merge', `${method}: ${m.reason}`);
    assert.ok(m.reason.length > 10, m.reason);
    assert.deepEqual(m.transforms.map((x) => x.robot), ['a'], method);
  }
});

test('the thesis method and the map-only baseline report their own verdicts', () => {
  for (const method of ['thesis', 'map-only']) {
    // The thesis's method on the preset as it is (its 147 s, the thesis's run).
    const extra = method === 'thesis' ? [] : ['--duration', '200'];
    const r = run('run', 'scenarios/thesis.json', '--json', '--method', method, ...extra);
    assert.equal(r.code, 0, r.stderr);
    const report = JSON.parse(r.stdout);
    assert.equal(report.method, method);
    assert.ok(['merged', 'no_merge'].includes(report.merge.status));
    assert.ok(report.merge.reason.length > 0);
    if (method === 'thesis') {
      const t = report.match_tables[0];
      // The thesis compares every selected frame with every other.
      assert.equal(t.inliers.flat().length, t.rows.length * t.cols.length);
      assert.ok(t.rows.length >= 2 && t.cols.length >= 2, `${t.rows.length} x ${t.cols.length} selected frames`);
      // Issue 6's target: on the thesis preset, within 0.3 m and 3 degrees of the truth.
      assert.equal(report.merge.status, 'merged', report.merge.reason);
      const e = report.merge.errors.find((x) => x.robot === 'robot2');
      assert.ok(e.error_m <= 0.3 && Math.abs(e.error_deg) <= 3, JSON.stringify(e));
    }
  }
});

test('merge writes the merged map as ROS map_server PGM + YAML and a PNG', () => {
  const out = path.join(tmp, 'merged', 'thesis.yaml');
  mkdirSync(path.dirname(out), { recursive: true });
  const r = run('merge', 'scenarios/thesis.json', '--out', out);
  assert.equal(r.code, 0, r.stderr);
  assert.match(r.stdout, /merge \(auto\): merged/);
  const yaml = readFileSync(out, 'utf8');
  assert.match(yaml, /^image: "?thesis\.pgm"?$/m);
  assert.match(yaml, /^resolution: 0\.05/m);
  const { w, h, data } = readPgm(out.replace(/yaml$/, 'pgm'));
  assert.equal(data.length, w * h);
  assert.ok(w > 100 && h > 100, `${w} x ${h}`);
  // A merged map holds walls, free space and unknown cells, nothing else.
  const seen = new Set(data);
  assert.deepEqual([...seen].sort((a, b) => a - b), [0, 205, 254]);
  const png = readFileSync(out.replace(/yaml$/, 'png'));
  assert.deepEqual([...png.subarray(1, 4)], [0x50, 0x4e, 0x47]);
});
