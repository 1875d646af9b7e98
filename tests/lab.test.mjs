// web/lab.js, the facade over the raw wasm-bindgen `Lab` that the page and
// the command line share: every binding method is reachable through it, and
// what it parses is exactly what the binding wrote. Needs the wasm build in
// web/pkg (`./build.sh build`).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { loadWasm } from '../web/cli/wasm.mjs';
import { Lab, buildInfo } from '../web/lab.js';

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
