// The facades over the wasm build that the page and the command line share:
// web/lab.js (the raw `Lab`), web/saved-maps.js (`MapMerge`, the saved-maps
// merge), web/log-replay.js (`LogReplay`) and web/images.js (SURF on image
// files). Every binding method is reachable through its facade, what a
// facade parses is exactly what the binding wrote, the results are right
// (two synthetic maps merge to the transform that made them, a log written
// here replays to its true poses) and bad input throws an Error naming the
// problem. Needs the wasm build in web/pkg (`./build.sh build`).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { loadWasm } from '../web/cli/wasm.mjs';
import { Lab, buildInfo } from '../web/lab.js';
import { MAX_SAVED_MAPS, SavedMaps, mapImagePath, mapMaxCells } from '../web/saved-maps.js';
import { LogReplay } from '../web/log-replay.js';
import { BagFile } from '../web/bag-file.js';
import * as images from '../web/images.js';
import { centredFrame, floorPlan, mapImage, mapYaml } from './support/synthetic-maps.mjs';
import { rayHit } from './support/synthetic-log.mjs';

const wasm = await loadWasm();
const thesis = readFileSync(new URL('../scenarios/thesis.json', import.meta.url), 'utf8');

/** Binding methods the facade leaves out on purpose: pixels for tests and workers, and memory management. */
const RAW_ONLY = new Set([
  'constructor', '__destroy_into_raw', 'free',
  'cameraGray', 'frameGray', 'mergedRgba', 'groupMergedRgba', 'renderFrame', 'renderRgba', 'renderFrameSpec',
]);

test('every method of the binding has its facade method (parsed ones drop "Json")', () => {
  const raw = Object.getOwnPropertyNames(wasm.Lab.prototype).filter((n) => !RAW_ONLY.has(n));
  assert.ok(raw.length > 40, `${raw.length} binding methods`);
  const renamed = { cameraInfo: 'camera', frameSpecJson: 'frameSpec' };
  for (const name of raw) {
    const facade = renamed[name] ?? name.replace(/Json$/, '');
    assert.equal(typeof Lab.prototype[facade], 'function', `${name} -> Lab.${facade}`);
  }
});

test('parsed results are what the binding wrote', () => {
  const lab = Lab.open(wasm, JSON.parse(thesis)); // an object is accepted as well as text
  assert.equal(lab.scenarioText(), lab.raw.scenarioJson());
  assert.deepEqual(lab.scenario(), JSON.parse(lab.raw.scenarioJson()));
  assert.equal(lab.scenario().walls.length, 19);
  assert.deepEqual(lab.problems(), []);
  assert.equal(lab.step(30), 30);
  const st = lab.state();
  assert.deepEqual(st, JSON.parse(lab.raw.stateJson()));
  assert.equal(st.steps, 30);
  assert.ok(Math.abs(st.time_s - 3) < 1e-9, `t = ${st.time_s}`);
  assert.deepEqual(lab.camera(), JSON.parse(lab.raw.cameraInfo()));
  assert.deepEqual(lab.frames(0), JSON.parse(lab.raw.framesJson(0)));
  assert.equal(lab.frames(0).length, lab.frameCount(0));
  assert.deepEqual(lab.slamFigures(1), JSON.parse(lab.raw.slamFiguresJson(1)));
  assert.deepEqual(lab.fitView(640, 480), JSON.parse(lab.raw.fitView(640, 480)));
  // The report's text is the binding's, byte for byte; report() parses it.
  const text = lab.reportText({ total: 1 });
  assert.equal(text, lab.raw.reportJson(JSON.stringify({ total: 1 })));
  assert.deepEqual(lab.report({ total: 1 }), JSON.parse(text));
  lab.raw.free();
});

test('writeReport hands out the report text in chunks, byte for byte, and passes on a failed write', () => {
  const lab = Lab.open(wasm, thesis);
  lab.setDuration(600);
  assert.equal(lab.step(6000), 6000); // 600 s of two robots: three trajectories each, well over one 1 MiB chunk
  const timings = { simulate: 2, total: 3 };
  const text = lab.reportText(timings);
  const chunks = [];
  lab.writeReport(timings, (chunk) => chunks.push(chunk));
  assert.ok(chunks.length >= 2, `${chunks.length} chunks for ${text.length} bytes`);
  assert.ok(chunks.every((c) => c instanceof Uint8Array && c.length > 0));
  assert.ok(chunks.slice(0, -1).every((c) => c.length === 1 << 20), 'full chunks of 1 MiB but the last');
  assert.equal(Buffer.concat(chunks).toString('utf8'), text);
  assert.throws(
    () => lab.writeReport(timings, () => { throw new Error('disk full'); }),
    /writing the report: disk full/,
  );
  // The lab and its run are still there after the failed write.
  assert.equal(lab.reportText(timings), text);
  lab.raw.free();
});

test('framesToDescribe pairs up the binding\'s flat [robot, frame, ...] list', () => {
  const lab = Lab.open(wasm, thesis);
  lab.step(100);
  const flat = [...lab.raw.framesToDescribe('auto')];
  const pairs = lab.framesToDescribe('auto');
  assert.ok(pairs.length > 0, 'ten seconds of run leave frames to describe');
  assert.deepEqual(pairs.flatMap((p) => [p.robot, p.index]), flat);
  lab.raw.free();
});

test('bad input throws the binding\'s message; the scenario is kept', () => {
  const lab = Lab.open(wasm, thesis);
  assert.throws(() => lab.setScenario('{"walls": 3}'), /walls/);
  assert.equal(lab.scenario().name, 'thesis');
  assert.throws(() => Lab.open(wasm, 'not json'), Error);
  lab.raw.free();
});

test('buildInfo reads the version, SIMD and the robot colours', () => {
  const info = buildInfo(wasm);
  assert.equal(info.version, wasm.version());
  assert.equal(info.simd, wasm.simdEnabled());
  assert.ok(info.colours.length >= 2 && info.colours.every((c) => c.length === 3));
});

// --- The saved-maps merge (web/saved-maps.js over `MapMerge`) -------------------------

/**
 * Two maps of one 30 x 20 m floor plan (tests/support/synthetic-maps.mjs):
 * A sees x <= 19.5 m, its image's lower-left corner at (-0.5, -0.5) in the
 * plan and its YAML origin (-2, 1); B sees x >= 9 m, turned by 0.9 rad.
 * `truth`: B's map frame in A's map frame.
 */
function twoSavedMaps() {
  const plan = floorPlan(30, 20, 7);
  const frameA = [-0.5, -0.5, 0], originA = [-2, 1, 0];
  const frameB = centredFrame(18, 10, 0.9, 640, 640);
  const a = { name: 'a.yaml', yaml: mapYaml('a.pgm', originA), imageName: 'a.pgm', image: mapImage(plan, frameA, 640, 440, ([x]) => x <= 19.5) };
  const b = { name: 'b.yaml', yaml: mapYaml('b.pgm'), imageName: 'b.pgm', image: mapImage(plan, frameB, 640, 640, ([x]) => x >= 9) };
  const truth = [frameB[0] - (frameA[0] - originA[0]), frameB[1] - (frameA[1] - originA[1]), frameB[2]];
  return { a, b, truth };
}

const add = (maps, m) => maps.addMap(m.name, m.yaml, m.imageName, m.image);

/** How far `pose` is from `truth`: [metres, degrees]. */
function offBy(pose, truth) {
  const turn = Math.atan2(Math.sin(pose[2] - truth[2]), Math.cos(pose[2] - truth[2]));
  return [Math.hypot(pose[0] - truth[0], pose[1] - truth[1]), (Math.abs(turn) * 180) / Math.PI];
}

/** Names a facade must have for each raw method, listed by the raw class's prototype. */
function facadeNames(rawClass, renamed = {}) {
  const skip = new Set(['constructor', '__destroy_into_raw', 'free']);
  return Object.getOwnPropertyNames(rawClass.prototype)
    .filter((n) => !skip.has(n))
    .map((n) => [n, renamed[n] ?? n.replace(/Json$/, '')]);
}

test('every method of MapMerge, LogReplay and BagFile has its facade method (parsed ones drop "Json")', () => {
  for (const [raw, facade, least] of [[wasm.MapMerge, SavedMaps, 11], [wasm.LogReplay, LogReplay, 12], [wasm.BagFile, BagFile, 8]]) {
    const names = facadeNames(raw);
    assert.ok(names.length >= least, `${names.length} methods of ${raw.name}`);
    for (const [name, wrapped] of names) {
      assert.equal(typeof facade.prototype[wrapped], 'function', `${name} -> ${facade.name}.${wrapped}`);
    }
    assert.equal(typeof facade.prototype.free, 'function');
  }
});

test('two saved maps of one floor merge through the facade to the transform that made them', () => {
  const { a, b, truth } = twoSavedMaps();
  const maps = SavedMaps.open(wasm);
  assert.equal(add(maps, a), 0);
  assert.equal(add(maps, b), 1);
  const info = maps.mapInfo(0);
  assert.deepEqual(info, { name: 'a.yaml', width: 640, height: 440, resolution: 0.05, origin: [-2, 1, 0] });
  assert.deepEqual(maps.mapInfo(1), JSON.parse(maps.raw.mapInfoJson(1)));
  const pixels = maps.mapPixels(0);
  assert.ok(pixels instanceof Uint8Array && pixels.length === 640 * 440, `${pixels.length} pixels`);
  assert.ok(pixels.includes(0) && pixels.includes(254) && pixels.includes(205), 'walls, free space and unknown');
  const lines = [];
  const report = maps.mergeWithProgress((line) => lines.push(line));
  assert.ok(lines.length >= 1, 'a progress line per pair');
  const m = report.merge;
  assert.equal(m.status, 'merged', m.reason);
  assert.deepEqual(report.maps.map((x) => x.name), ['a.yaml', 'b.yaml']);
  assert.deepEqual(m.transforms[0], { map: 'a.yaml', pose: [0, 0, 0] });
  const [metres, degrees] = offBy(m.transforms[1].pose, truth);
  assert.ok(metres < 0.1 && degrees < 0.5, `b is ${metres} m and ${degrees}° off the truth ${truth}`);
  // The report is the binding's, parsed once; report() reads it again after the merge.
  assert.deepEqual(maps.report(), report);
  assert.deepEqual(maps.report(), JSON.parse(maps.raw.reportJson()));
  // The merged map: bytes and YAML pass through.
  assert.equal(new TextDecoder().decode(maps.mergedPgm().subarray(0, 2)), 'P5');
  assert.deepEqual([...maps.mergedPng().subarray(1, 4)], [0x50, 0x4e, 0x47]); // "PNG"
  assert.match(maps.mergedYaml('joined.pgm'), /^image: "?joined\.pgm"?$/m);
  maps.free();
});

test('refine through the facade takes a pose, answers the pair in the order the merge judged it', () => {
  const { a, b, truth } = twoSavedMaps();
  const maps = SavedMaps.open(wasm);
  add(maps, a);
  add(maps, b);
  maps.merge();
  // A guess 0.4 m and 3° off the truth comes back near the truth.
  const pair = maps.refine(0, 1, [truth[0] + 0.4, truth[1] - 0.2, truth[2] + 0.05]);
  assert.deepEqual([pair.a, pair.b], ['a.yaml', 'b.yaml']);
  assert.equal(pair.status, 'merged', pair.reason);
  assert.match(pair.reason, /^refined from your guess/);
  const [metres, degrees] = offBy(maps.report().merge.transforms[1].pose, truth);
  assert.ok(metres < 0.1 && degrees < 0.5, `refined b is ${metres} m and ${degrees}° off`);
  // Asked the other way round (a's frame in b's), the pair comes back as a, b with the guess inverted.
  const c = Math.cos(truth[2]), s = Math.sin(truth[2]);
  const inverse = [-c * truth[0] - s * truth[1], s * truth[0] - c * truth[1], -truth[2]];
  const back = maps.refine(1, 0, inverse);
  assert.deepEqual([back.a, back.b], ['a.yaml', 'b.yaml']);
  assert.ok(offBy(back.guess, truth)[0] < 1e-6, `guess ${back.guess}`);
  maps.free();
});

test('bad input to the saved maps throws an Error naming the problem', () => {
  const { a, b } = twoSavedMaps();
  const maps = SavedMaps.open(wasm);
  assert.throws(() => maps.addMap('bad.yaml', 'resolution: 0.05\n', 'bad.pgm', a.image), (e) => e instanceof Error && /bad\.yaml/.test(e.message));
  assert.throws(() => maps.addMap('a.yaml', a.yaml, 'a.pgm', new Uint8Array([1, 2, 3])), (e) => e instanceof Error && /a\.pgm|a\.yaml/.test(e.message));
  add(maps, a);
  assert.throws(() => maps.merge(), /at least two maps/);
  assert.throws(() => maps.report(), /merge first/);
  assert.throws(() => maps.mapInfo(3), /no such map/);
  add(maps, b);
  assert.throws(() => maps.refine(0, 1, [0, 0, 0]), /refine: merge first/);
  maps.merge();
  assert.throws(() => maps.refine(0, 1, [1, 2]), /refine: the guess must be a pose \[x, y, theta\], got \[1,2\]/);
  assert.throws(() => maps.refine(0, 1, [0, NaN, 0]), /refine: the guess must be finite numbers/);
  assert.throws(() => maps.refine(0, 4, [0, 0, 0]), /refine: maps 0 and 4 are not a pair of the 2 maps opened/);
  for (let k = 2; k < MAX_SAVED_MAPS; k++) add(maps, b);
  assert.throws(() => add(maps, b), new RegExp(`b\\.yaml: at most ${MAX_SAVED_MAPS} maps`));
  maps.free();
  assert.equal(mapImagePath(wasm, 'x.yaml', a.yaml), 'a.pgm');
  assert.throws(() => mapImagePath(wasm, 'x.yaml', 'resolution: 0.05\n'), /x\.yaml/);
  assert.ok(mapMaxCells(wasm) >= 640 * 640, `${mapMaxCells(wasm)} cells`);
});

// --- The log replay (web/log-replay.js over `LogReplay`) ------------------------------

/**
 * A CARMEN log of `n` laser records, written here: a robot drives along
 * +x at 0.25 m a record down an 18 x 6 m hall with a pillar and a notch
 * (so places along it look different), its odometry drifting 0.02 m to
 * the left a record, each record an ODOM and a FLASER of 181 beams cast
 * exactly against the walls. Returns the bytes and the true poses (the
 * odometry's frame: the first record's odometry is the truth).
 */
function corridorLog(n) {
  const walls = [
    [[-3, -3], [15, -3]], [[15, -3], [15, 3]], [[15, 3], [-3, 3]], [[-3, 3], [-3, -3]],
    [[4, 1.5], [4.5, 1.5]], [[4.5, 1.5], [4.5, 2]], [[4.5, 2], [4, 2]], [[4, 2], [4, 1.5]],
    [[8, -3], [8, -2.2]], [[8, -2.2], [9, -2.2]], [[9, -2.2], [9, -3]],
  ];
  const lines = ['# made by tests/lab.test.mjs'];
  const truth = [];
  for (let i = 0; i < n; i++) {
    const p = [0.25 * i, 0.1 * Math.sin(i / 4), 0.05 * Math.sin(i / 5)];
    truth.push(p);
    const ranges = [];
    for (let k = 0; k <= 180; k++) ranges.push(rayHit(p, p[2] + ((k - 90) * Math.PI) / 180, walls, 80).toFixed(3));
    const pose = [p[0], p[1] + 0.02 * i, p[2]].map((v) => v.toFixed(5)).join(' ');
    const t = (100 + 0.2 * i).toFixed(3);
    lines.push(`ODOM ${pose} 0.5 0 0 ${t} test ${t}`);
    lines.push(`FLASER 181 ${ranges.join(' ')} ${pose} ${pose} ${t} test ${t}`);
  }
  return { bytes: new TextEncoder().encode(lines.join('\n') + '\n'), truth };
}

test('a CARMEN log written here replays through the facade: one scan a record, finite poses on the truth', () => {
  const { bytes, truth } = corridorLog(40);
  const replay = LogReplay.open(wasm, bytes);
  assert.equal(replay.laserRecords(), 40);
  assert.equal(replay.drawLive(), false, 'no live map before the first scan');
  assert.equal(replay.step(10), 30);
  const view = replay.view();
  assert.deepEqual([view.done, view.total, view.odometry.length, view.poses.length], [10, 40, 30, 30]);
  assert.deepEqual(view, JSON.parse(replay.raw.viewJson()));
  assert.equal(replay.drawLive(), true);
  const live = replay.liveInfo();
  assert.equal(live.resolution_m, 0.05);
  assert.equal(replay.livePixels().length, live.width * live.height);
  replay.finish();
  const report = replay.report({ finish: 1.5 });
  assert.equal(report.scans.length, 40);
  assert.deepEqual(report.scans.map((s) => s.index), [...Array(40).keys()]);
  assert.deepEqual(report.timings_ms, { finish: 1.5 });
  // The odometry ends 0.78 m off; scan matching keeps SLAM's poses on the truth.
  const off = (p, i) => Math.hypot(p[0] - truth[i][0], p[1] - truth[i][1]);
  let worst = 0;
  for (const [i, s] of report.scans.entries()) {
    assert.ok([...s.pose, ...s.odometry].every(Number.isFinite), `scan ${i}: ${s.pose}`);
    worst = Math.max(worst, off(s.pose, i));
  }
  assert.ok(off(report.scans[39].odometry, 39) > 0.75, `odometry ${report.scans[39].odometry}`);
  assert.ok(worst < 0.15, `a pose is ${worst} m off the truth`);
  // The text is the binding's byte for byte (run-log --json prints it); report() parses it.
  const text = replay.reportText({ total: 2 });
  assert.equal(text, replay.raw.reportJson('{"total":2}'));
  assert.deepEqual(replay.report({ total: 2 }), JSON.parse(text));
  assert.equal(new TextDecoder().decode(replay.mapPgm().subarray(0, 2)), 'P5');
  assert.deepEqual([...replay.mapPng().subarray(1, 4)], [0x50, 0x4e, 0x47]);
  assert.match(replay.mapYaml('log.pgm'), /^image: "?log\.pgm"?$/m);
  replay.free();
});

test('a stretch of the log: setRange keeps records from..=to, a left-out or huge end means the last', () => {
  const { bytes } = corridorLog(30);
  const stretch = (from, to) => {
    const replay = LogReplay.open(wasm, bytes);
    replay.setRange(from, to);
    replay.finish();
    const r = replay.report();
    replay.free();
    return [r.from, r.to, r.scans.length, r.scans[0].index];
  };
  assert.deepEqual(stretch(5, 9), [5, 9, 5, 5]);
  assert.deepEqual(stretch(20), [20, 29, 10, 20]);
  assert.deepEqual(stretch(20, 2 ** 40), [20, 29, 10, 20]);
});

test('bad input to the log replay throws an Error naming the problem', () => {
  const bad = new TextEncoder().encode('ODOM 0 0 0 0 0 0 1 h 1\nFLASER 3 1.0 2.0\n');
  assert.throws(() => LogReplay.open(wasm, bad), (e) => e instanceof Error && /line 2/.test(e.message));
  const replay = LogReplay.open(wasm, corridorLog(10).bytes);
  assert.throws(() => replay.setRange(12, 20), (e) => e instanceof Error && /12/.test(e.message));
  assert.throws(() => replay.liveInfo(), /drawLive first/);
  replay.free();
});

// --- SURF on image files (web/images.js) ----------------------------------------------

test('features and match through the facade: the binding\'s documents, parsed once', () => {
  const coffee = readFileSync(new URL('./data/coffee.png', import.meta.url));
  const turned = readFileSync(new URL('./data/coffee_rot12_s085.png', import.meta.url));
  const text = images.featuresText(wasm, coffee);
  assert.equal(text, wasm.surf_features(coffee));
  const f = images.features(wasm, coffee);
  assert.deepEqual(f, JSON.parse(text));
  assert.deepEqual([f.width, f.height], [640, 480]);
  assert.ok(f.keypoints.length > 500 && f.keypoints.every((k) => k.descriptor.length === 64), `${f.keypoints.length} keypoints`);
  const m = images.match(wasm, coffee, turned);
  assert.deepEqual(m, JSON.parse(images.matchText(wasm, coffee, turned)));
  assert.ok(m.inliers > 100 && m.inliers <= m.matches, `${m.inliers} of ${m.matches}`);
  assert.deepEqual(m.keypoints[0], f.keypoints.length);
  // A flat grey canvas has no keypoints; its size comes back.
  const grey = new Uint8Array(64 * 48 * 4).fill(128);
  assert.deepEqual(images.featuresOfRgba(wasm, grey, 64, 48), { width: 64, height: 48, keypoints: [] });
  assert.throws(() => images.features(wasm, new Uint8Array([1, 2, 3])), (e) => e instanceof Error && /not a PNG or JPEG/.test(e.message));
  assert.throws(() => images.featuresOfRgba(wasm, grey, 65, 48), Error);
});
