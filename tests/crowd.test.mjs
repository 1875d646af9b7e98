// Issue 22, "Sixteen robots for an hour", on instances small enough for the
// test suite (the full 16 x 3600 s run is in BENCHMARKS.md):
// - the frame store thins its frames at a tiny budget while worker threads
//   hold some of them: the run completes and reports what it reports with
//   no workers;
// - robots whose mapping runs on worker threads report what they report
//   with no workers;
// - in a crowded maze (tests/bench/crowd_maze.mjs), every pair of robots
//   whose true paths overlap by at least 50 m^2 ends up in one of the
//   report's merge.groups[], and every transform in every group is right,
//   both checked against the ground truth;
// - with sixteen robots the merge checks a bounded number of robot pairs
//   (crate/src/merge/pairbudget.rs), says which it left out, and still
//   finds every overlapping group, checked the same way.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { crowdMaze } from './bench/crowd_maze.mjs';
import { runCli as run, tempDir } from './support/cli.mjs';
import { overlaps as overlapsOf } from './support/overlaps.mjs';

const tmp = tempDir('crowd');

/** A report without its wall-clock timings. */
function strip(text) {
  const j = JSON.parse(text);
  delete j.timings_ms;
  if (j.merge) delete j.merge.timings_ms;
  return j;
}

test('frames thinned while workers hold them: the run completes with the report of no workers', () => {
  // 3.4 MB: about 75 frames with their features for two robots, so each store thins
  // (drops every other frame, halves its rate) twice in 300 s while
  // two workers are describing its frames.
  const args = ['run', 'scenarios/thesis.json', '--json', '--frame-budget-mb', '3.4'];
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

test('robots mapped on worker threads: the report, loop closures and all, is that of no workers', () => {
  // The thesis's maze for 900 s, where both robots close loops: with one
  // worker, the second robot maps on it (crate/src/slam/handoff.rs,
  // web/cli/slam-pool.mjs).
  const args = ['run', 'scenarios/thesis.json', '--json', '--duration', '900'];
  const [alone, helped] = ['0', '1'].map((w) => run(...args, '--workers', w));
  assert.equal(alone.code, 0, alone.stderr);
  assert.equal(helped.code, 0, helped.stderr);
  const [a, b] = [strip(alone.stdout), strip(helped.stdout)];
  const closures = a.robots.map((r) => r.slam.loop_closures);
  assert.ok(closures[1] >= 1, `loop closures by robot: ${closures}`);
  assert.deepEqual(b, a);
  assert.ok(JSON.parse(helped.stdout).timings_ms.slam > 0, 'the mapping time on worker threads is counted');
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

/** Runs a crowded maze through the CLI; the parsed report. */
function runCrowd(options, name) {
  const file = path.join(tmp, `${name}.json`);
  writeFileSync(file, JSON.stringify(crowdMaze(options)));
  const r = run('run', file, '--json');
  assert.equal(r.code, 0, r.stderr);
  return JSON.parse(r.stdout);
}

/**
 * Checks a report's merge.groups[] against the truth: every robot in one
 * group, every pair of robots whose paths overlap by 50 m^2 in one group
 * (at least `minOverlapping` such pairs), and every transform of every
 * group right. Returns the overlapping pairs.
 */
function assertGroupsAgainstTruth(report, minOverlapping) {
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
  const overlaps = overlapsOf(report);
  const groupOf = Object.fromEntries(groups.flatMap((g, k) => g.robots.map((n) => [n, k])));
  const overlapping = overlaps.filter((o) => o.m2 >= 50);
  assert.ok(overlapping.length >= minOverlapping, `an instance with overlaps: ${JSON.stringify(overlaps)}`);
  for (const o of overlapping) {
    assert.equal(groupOf[o.a], groupOf[o.b], `${o.a} and ${o.b} drove ${o.m2} m^2 together but are not joined`);
  }
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
  return overlapping;
}

test('a crowded maze: every pair of robots whose paths overlap by 50 m^2 is joined, and no transform is wrong', () => {
  const report = runCrowd({ cells: 10, cellM: 3, open: 0.2, robots: 6, duration: 400, seed: 5 }, 'crowd');
  assertGroupsAgainstTruth(report, 3);
  assert.ok(report.merge.groups.some((g) => g.robots.length >= 3), 'a group of three or more');
});

test('sixteen robots: a bounded number of pairs is checked, and every overlapping group is still found', () => {
  const report = runCrowd({ cells: 12, cellM: 3, open: 0.2, robots: 16, duration: 240, seed: 22 }, 'crowd16');
  const n = report.robots.length;
  const { budget, pairs } = report.merge;
  assert.ok(budget, 'sixteen robots: the merge reports its pair budget');
  assert.equal(budget.pairs, n * (n - 1) / 2);
  assert.equal(pairs.length, budget.pairs);
  // k = ceil(log2 16 + log2(1 + F / 100) / 2) partners a robot, F its frames.
  const k = budget.partners_per_robot;
  assert.ok(k >= 4 && k <= 7, `partners per robot: ${k}`);
  // Frames are matched only for a robot's k likeliest partners by visual
  // votes, and maps searched only for its k likeliest by map overlap.
  const matched = pairs.filter((p) => p.check === 'full' || p.check === 'frames').length;
  assert.equal(matched, budget.matched);
  assert.ok(matched <= n * k && matched < budget.pairs / 2, `${matched} of ${budget.pairs} pairs matched`);
  assert.ok(budget.maps_searched <= n * k && budget.maps_searched < budget.pairs / 2, `${budget.maps_searched} map searches`);
  const none = pairs.filter((p) => p.check === 'none');
  assert.equal(none.length, budget.not_checked);
  assert.ok(none.length > 0, 'some pairs are not checked');
  for (const p of none) assert.equal(p.status, 'no_merge');
  assert.ok(none.some((p) => /not checked within the budget/.test(p.reason)), 'the reason says so');
  // The match tables of pairs left out are empty.
  for (const t of report.match_tables) {
    const p = pairs.find((q) => q.a === t.a && q.b === t.b);
    if (p.check === 'none' || p.check === 'maps') assert.equal(t.checked, 0, `${t.a} + ${t.b}`);
  }
  assertGroupsAgainstTruth(report, 5);
});
