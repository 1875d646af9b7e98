// Issue 22, "Sixteen robots for an hour", on instances small enough for the
// test suite (the full 16 x 3600 s run is in BENCHMARKS.md):
// - the frame store thins its frames at a tiny budget while worker threads
//   hold some of them: the run completes and reports what it reports with
//   no workers;
// - in a crowded maze (tests/bench/crowd_maze.mjs), every pair of robots
//   whose true paths overlap by at least 50 m^2 ends up in one of the
//   report's merge.groups[], and every transform in every group is right,
//   both checked against the ground truth.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { crowdMaze } from './bench/crowd_maze.mjs';
import { runCli as run, tempDir } from './support/cli.mjs';

const tmp = tempDir('crowd');

/** A report without its wall-clock timings. */
function strip(text) {
  const j = JSON.parse(text);
  delete j.timings_ms;
  if (j.merge) delete j.merge.timings_ms;
  return j;
}

test('frames thinned while workers hold them: the run completes with the report of no workers', () => {
  // 0.05 MB: about 75 frames a robot for two robots, so each store thins
  // (drops every other frame, halves its rate) twice in 300 s while
  // two workers are describing its frames.
  const args = ['run', 'scenarios/thesis.json', '--json', '--frame-budget-mb', '0.05'];
  const alone = run(...args, '--workers', '0');
  const helped = run(...args, '--workers', '2');
  assert.equal(alone.code, 0, alone.stderr);
  assert.equal(helped.code, 0, helped.stderr);
  const [a, b] = [strip(alone.stdout), strip(helped.stdout)];
  for (const r of a.robots) {
    assert.ok(r.frames_dropped >= 30, `${r.name}: ${r.frames_dropped} frames dropped at the budget`);
    // Thinned: the capture rate halved, so fewer than the 301 a frame a second gives.
    assert.ok(r.frames + r.frames_dropped < 250, `${r.name}: ${r.frames} kept, ${r.frames_dropped} dropped`);
  }
  assert.ok(a.match_tables[0].rows.length > 0, 'frames took part in the merge');
  assert.deepEqual(b, a);
  const bad = run('run', 'scenarios/thesis.json', '--json', '--frame-budget-mb', 'x');
  assert.equal(bad.code, 2);
  assert.match(bad.stderr, /--frame-budget-mb: 'x' is not a number of megabytes/);
});

/** The pose of frame `b` in frame `a` (both [x, y, theta] in one frame). */
function relative(a, b) {
  const [dx, dy] = [b[0] - a[0], b[1] - a[1]];
  const [c, s] = [Math.cos(a[2]), Math.sin(a[2])];
  return [c * dx + s * dy, -s * dx + c * dy, wrap(b[2] - a[2])];
}

function wrap(t) {
  return Math.atan2(Math.sin(t), Math.cos(t));
}

/**
 * The cells (of `cell` m) a robot drove through: within `reach` m of its
 * true path. Where two robots' cells meet is where both drove.
 */
function footprint(truth, cell = 0.5, reach = 1.5) {
  const cells = new Set();
  const k = Math.ceil(reach / cell);
  let last = null;
  for (const [, x, y] of truth) {
    if (last && Math.hypot(x - last[0], y - last[1]) < cell / 2) continue;
    last = [x, y];
    const [cx, cy] = [Math.floor(x / cell), Math.floor(y / cell)];
    for (let i = -k; i <= k; i++) {
      for (let j = -k; j <= k; j++) {
        const [px, py] = [(cx + i + 0.5) * cell, (cy + j + 0.5) * cell];
        if (Math.hypot(px - x, py - y) <= reach) cells.add(`${cx + i},${cy + j}`);
      }
    }
  }
  return cells;
}

test('a crowded maze: every pair of robots whose paths overlap by 50 m^2 is joined, and no transform is wrong', () => {
  const scenario = crowdMaze({ cells: 10, cellM: 3, open: 0.2, robots: 6, duration: 400, seed: 5 });
  const file = path.join(tmp, 'crowd.json');
  writeFileSync(file, JSON.stringify(scenario));
  const r = run('run', file, '--json');
  assert.equal(r.code, 0, r.stderr);
  const report = JSON.parse(r.stdout);
  const names = report.robots.map((x) => x.name);
  const groups = report.merge.groups;
  // Every robot in exactly one group; robot 1's group is the top-level join.
  assert.deepEqual(groups.flatMap((g) => g.robots).sort(), [...names].sort());
  assert.deepEqual(groups[0].transforms, report.merge.transforms.length > 0
    ? report.merge.transforms : [{ robot: names[0], pose: [0, 0, 0] }]);
  for (const g of groups) {
    assert.deepEqual(g.transforms.map((t) => t.robot), g.robots);
    assert.deepEqual(g.transforms[0].pose, [0, 0, 0]);
    if (g.robots.length === 1) assert.match(g.reason, /joined no other robot/);
  }
  // The truth: where the robots drove, and each start pose.
  const byName = Object.fromEntries(report.robots.map((x) => [x.name, x]));
  const prints = report.robots.map((x) => footprint(x.truth));
  const overlaps = [];
  for (let i = 0; i < names.length; i++) {
    for (let j = i + 1; j < names.length; j++) {
      let shared = 0;
      for (const c of prints[i]) if (prints[j].has(c)) shared += 1;
      overlaps.push({ a: names[i], b: names[j], m2: shared * 0.25 });
    }
  }
  const groupOf = Object.fromEntries(groups.flatMap((g, k) => g.robots.map((n) => [n, k])));
  const overlapping = overlaps.filter((o) => o.m2 >= 50);
  assert.ok(overlapping.length >= 3, `an instance with overlaps: ${JSON.stringify(overlaps)}`);
  for (const o of overlapping) {
    assert.equal(groupOf[o.a], groupOf[o.b], `${o.a} and ${o.b} drove ${o.m2} m^2 together but are not joined`);
  }
  assert.ok(groups.some((g) => g.robots.length >= 3), 'a group of three or more');
  // No transform is wrong: each robot's frame in its group's first robot's
  // frame, against the start poses.
  for (const g of groups) {
    const first = byName[g.robots[0]].truth[0].slice(1);
    for (const t of g.transforms) {
      const truth = relative(first, byName[t.robot].truth[0].slice(1));
      const err = Math.hypot(t.pose[0] - truth[0], t.pose[1] - truth[1]);
      const deg = Math.abs(wrap(t.pose[2] - truth[2])) * 180 / Math.PI;
      assert.ok(err < 0.5 && deg < 3, `${t.robot} in ${g.robots[0]}'s frame: off by ${err.toFixed(2)} m, ${deg.toFixed(1)} deg`);
    }
  }
});
