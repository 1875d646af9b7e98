// The core of "Your log"'s merge of several robots (web/page/real/log-merge.js)
// in node, over the same wasm build as the page: how a log is cut into
// stretches, how a robot's map is handed to the merge in its own frame,
// and the merge of two stretches of one synthetic log against the truth
// (tests/support/synthetic-log.mjs knows every true pose), and of two logs
// of different worlds, which must not merge. The page test
// (tests/page-real.test.mjs) drives the same as a user.
//
// Needs the wasm build in web/pkg (`./build.sh build`). Run alone with
//   node --test tests/log-merge.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { loadWasm } from '../web/cli/wasm.mjs';
import { LogReplay } from '../web/log-replay.js';
import { inverse, mergedPaths, mergeRobots, robotMap, stretches } from '../web/page/real/log-merge.js';
import { compose } from '../web/page/real/overlay.js';
import { ringLog } from './support/synthetic-log.mjs';

const wasm = await loadWasm();
const wrap = (a) => Math.atan2(Math.sin(a), Math.cos(a));

/** A robot replaying laser records `from..=to` of `text`, finished. */
function robot(name, text, [from, to]) {
  const replay = LogReplay.open(wasm, new TextEncoder().encode(text));
  replay.setRange(from, to);
  replay.finish();
  return { name, replay, report: replay.report() };
}

test('a log of 211 records cut into 2, 3 and 300 stretches: near-equal, in order, no record lost', () => {
  assert.deepEqual(stretches(211, 2), [[0, 104], [105, 210]]);
  assert.deepEqual(stretches(211, 3), [[0, 69], [70, 139], [140, 210]]);
  assert.deepEqual(stretches(211, 1), [[0, 210]]);
  assert.deepEqual(stretches(211, 0), [[0, 210]], 'no cut is one stretch');
  const many = stretches(5, 300);
  assert.deepEqual(many, [[0, 0], [1, 1], [2, 2], [3, 3], [4, 4]], 'no more stretches than records');
});

test('inverse(p) ∘ p is the identity and p ∘ inverse(p) too', () => {
  const p = [3.2, -1.5, 2.4];
  for (const q of [compose(inverse(p), p), compose(p, inverse(p))]) {
    assert.ok(Math.hypot(q[0], q[1]) < 1e-12 && Math.abs(wrap(q[2])) < 1e-12, `${q}`);
  }
  assert.deepEqual(inverse([1, 2, 0]), [-1, -2, -0]);
});

test("a robot's map goes to the merge in its own frame: the YAML origin is s⁻¹ ∘ origin", () => {
  const hall = ringLog({ laps: 1.5, perLap: 140, world: 'hall' });
  const r = robot('hall-2', hall.text, [105, 210]);
  const m = robotMap(r);
  assert.equal(m.name, 'hall-2.yaml');
  assert.equal(m.imageName, 'hall-2.pgm');
  const origin = /origin: \[([^\]]+)\]/.exec(m.yaml)[1].split(', ').map(Number);
  // Back in the log's frame, the origin is the replay's own (yaw 0).
  const s = r.report.scans[0].pose;
  const back = compose(s, origin);
  assert.ok(Math.abs(back[0] - r.report.map.origin_m[0]) < 1e-5 && Math.abs(back[1] - r.report.map.origin_m[1]) < 1e-5, `${back}`);
  assert.ok(Math.abs(wrap(back[2])) < 1e-5);
  // The stretch starts heading 0 in truth, 105 steps of 0.004 rad of drift into the odometry; the origin's yaw undoes it.
  assert.ok(Math.abs(wrap(origin[2] + s[2])) < 1e-5, `origin ${origin}, start ${s}`);
  assert.ok(Math.abs(wrap(s[2] - 105 * 0.004)) < 0.02, `start ${s}`);
  assert.match(m.yaml, /^image: "hall-2\.pgm"\nresolution: 0\.05\norigin: \[/);
  r.replay.free();
});

test('two stretches of one log that overlap in space merge within 0.15 m and 1° of the truth', () => {
  const hall = ringLog({ laps: 1.5, perLap: 140, world: 'hall' });
  const robots = stretches(hall.truth.length, 2).map((part, k) => robot(`hall-${k + 1}`, hall.text, part));
  const { savedMaps, report, files } = mergeRobots(wasm, robots);
  assert.equal(report.merge.status, 'merged', report.merge.reason);
  const truth = compose(inverse(hall.truth[0]), hall.truth[105]);
  const [x, y, th] = report.merge.transforms[1].pose;
  assert.equal(report.merge.transforms[1].map, 'hall-2.yaml');
  const dist = Math.hypot(x - truth[0], y - truth[1]);
  const turn = (Math.abs(wrap(th - truth[2])) * 180) / Math.PI;
  assert.ok(dist < 0.15 && turn < 1, `hall-2 is ${dist} m and ${turn} deg off the truth ${truth}`);
  assert.match(new TextDecoder().decode(files.pgm.subarray(0, 2)), /P5/);
  assert.match(files.yaml, /image: "?merged\.pgm"?/);
  // Both paths in the merged frame (the first robot's) lie on the truth seen from there.
  const paths = mergedPaths(report, robots.map((r, k) => ({ ...r, colour: ['#111111', '#222222'][k] })));
  assert.deepEqual(paths.map((p) => [p.colour, p.flat.length / 3]), [['#111111', 105], ['#222222', 106]]);
  assert.ok(Math.hypot(paths[1].flat[0] - x, paths[1].flat[1] - y) < 1e-9, 'the second path starts at its frame');
  let worst = 0;
  for (const [k, p] of paths.entries()) {
    for (let i = 0; i < p.flat.length / 3; i++) {
      const t = compose(inverse(hall.truth[0]), hall.truth[k * 105 + i]);
      worst = Math.max(worst, Math.hypot(p.flat[3 * i] - t[0], p.flat[3 * i + 1] - t[1]));
    }
  }
  assert.ok(worst < 0.2, `a merged path is ${worst} m off the truth`);
  savedMaps.free();
});

test('two logs of different worlds do not merge, and say why', () => {
  const ring = ringLog({ laps: 2, perLap: 140 });
  const hall = ringLog({ laps: 1, perLap: 140, world: 'hall' });
  const robots = [robot('ring', ring.text, [0, 280]), robot('hall', hall.text, [0, 140])];
  const { savedMaps, report, files } = mergeRobots(wasm, robots);
  assert.equal(report.merge.status, 'no_merge');
  assert.match(report.merge.reason, /^too little common wall: \d+\.\d m of wall agree within 0\.15 m \(20 m needed\)$/);
  assert.deepEqual(report.merge.unjoined, ['hall.yaml']);
  assert.equal(files, null);
  savedMaps.free();
});
