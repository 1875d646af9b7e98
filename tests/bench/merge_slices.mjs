// How long the page's merge calls take: runs a scenario to its end in the
// wasm build, then advances the automatic merge as the page does
// (web/page/merge-panel.js: `mergeAdvance(2)` again and again) and reports,
// per stage, the number of calls, their total and the longest one. A call
// over 100 ms is a long task in the page.
//
//   node tests/bench/merge_slices.mjs SCENARIO.json [--units N]
//
// The calls over 100 ms are listed too (`long`: stage, the stage's units
// done before the call and in all, `#n` the call's place among those made
// at that progress, and its time), to find the unit that holds the page:
// with `--units 1`, `#0` of a pair's verdict is its rivals, `#1` the first
// rival's grid alignment, `#2` its map comparison, and so on.
//
// SLAMLAB_PKG=DIR measures another wasm build (web/cli/wasm.mjs).
import { readFileSync } from 'node:fs';
import { performance } from 'node:perf_hooks';
import { loadWasm } from '../../web/cli/wasm.mjs';

const args = process.argv.slice(2);
const file = args.find((a) => !a.startsWith('--'));
const unitsAt = args.indexOf('--units');
const units = unitsAt >= 0 ? Number(args[unitsAt + 1]) : 2;
if (!file || !(units >= 1)) {
  console.error('usage: node tests/bench/merge_slices.mjs SCENARIO.json [--units N]');
  process.exit(2);
}

const wasm = await loadWasm();
const lab = new wasm.Lab(readFileSync(file, 'utf8'));
const t0 = performance.now();
lab.runToEnd();
const runS = (performance.now() - t0) / 1000;

const stages = new Map();
const long = [];
let lastBefore = '';
let nth = 0;
let progress = JSON.parse(lab.mergeStart('auto'));
let calls = 0;
while (!progress.finished) {
  const stage = progress.stage;
  // `#n`: the call's place among the calls made at the same progress
  // (the steps of one pair's verdict or map search leave it unchanged).
  const at = `${progress.done} / ${progress.total}`;
  nth = at === lastBefore ? nth + 1 : 0;
  lastBefore = at;
  const before = `${at} #${nth}`;
  const t = performance.now();
  progress = JSON.parse(lab.mergeAdvance(units));
  const dt = performance.now() - t;
  calls += 1;
  const s = stages.get(stage) ?? { calls: 0, total_ms: 0, longest_ms: 0, over_100ms: 0 };
  s.calls += 1;
  s.total_ms += dt;
  s.longest_ms = Math.max(s.longest_ms, dt);
  if (dt > 100) {
    s.over_100ms += 1;
    long.push({ stage, before, ms: Math.round(dt) });
  }
  stages.set(stage, s);
}
const out = { scenario: file, units, run_s: +runS.toFixed(1), calls, stages: {}, long };
for (const [k, v] of stages) {
  out.stages[k] = {
    calls: v.calls,
    total_ms: Math.round(v.total_ms),
    longest_ms: Math.round(v.longest_ms),
    over_100ms: v.over_100ms,
  };
}
console.log(JSON.stringify(out, null, 1));
