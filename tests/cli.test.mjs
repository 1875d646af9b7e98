// End-to-end tests of the command line (web/cli.mjs) on the wasm build.
// Run by ./build.sh test after ./build.sh build.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, writeFileSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.join(path.dirname(fileURLToPath(import.meta.url)), '..');
const cli = path.join(root, 'web', 'cli.mjs');
const tmp = mkdtempSync(path.join(tmpdir(), 'slamlab-cli-'));

function run(...args) {
  const r = spawnSync(process.execPath, [cli, ...args], { cwd: root, encoding: 'utf8', maxBuffer: 1 << 28 });
  return { code: r.status, stdout: r.stdout, stderr: r.stderr };
}

function scenarioFile(name, obj) {
  const p = path.join(tmp, name);
  writeFileSync(p, typeof obj === 'string' ? obj : JSON.stringify(obj));
  return p;
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
  const strip = (s) => { const j = JSON.parse(s); delete j.timings_ms; return j; };
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
  assert.deepEqual(index.camera, { width: 320, height: 240, hfov_deg: 60 });
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
