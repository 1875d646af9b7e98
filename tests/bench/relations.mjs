// The SLAM benchmark the field uses: the raw Freiburg logs (ROS 1 bags,
// real odometry, every scan) replayed through the lab's log SLAM as
// `run-log` does, scored against Kümmerle et al.'s hand-checked relations
// (../shared/data/bags/freiburg/*.relations; crate/src/slam/eval/
// benchmark_relations.rs), beside the published figures of scan matching,
// GMapping and graph mapping (Kümmerle et al., Autonomous Robots 2009) and
// Cartographer (Hess et al., ICRA 2016, Table I).
//
//   node tests/bench/relations.mjs [--halves] [--json] [LOG ...]
//
// LOG: aces, intel, mit-csail, fr079 (default: all four). --halves also
// replays each log's first and second half of its scans on their own
// (a check that the settings are not tuned to whole logs). Prints one
// table: mean ± sd (max) of the translational (m) and rotational (deg)
// relation errors, the published means, and the replay's speed against
// the log's own duration (real time).
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath } from 'node:url';
import { loadWasm } from '../../web/cli/wasm.mjs';
import { readBag } from '../../web/cli/bag-read.mjs';
import { LogReplay } from '../../web/log-replay.js';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const data = process.env.SLAMLAB_DATA ?? path.join(root, '..', 'shared', 'data');

/**
 * Published mean translational relation errors (m), as quoted in
 * ../shared/data/README.md: Kümmerle et al. 2009 (scan matching, GMapping,
 * graph mapping) and Hess et al. 2016, Table I (Cartographer).
 */
export const PUBLISHED = {
  aces: { scanMatching: 0.173, gmapping: 0.060, graphMapping: 0.044, cartographer: 0.0375 },
  intel: { scanMatching: 0.220, gmapping: 0.070, graphMapping: 0.031, cartographer: 0.0229 },
  'mit-csail': { scanMatching: 0.106, gmapping: 0.049, graphMapping: 0.004, cartographer: 0.0319 },
  fr079: { scanMatching: 0.258, gmapping: 0.061, graphMapping: 0.056, cartographer: 0.0452 },
};

/** Replays `log` (its scans `from..to`, or all) and scores it; returns the figures. */
export async function score(wasm, log, stretch = null) {
  const { bag, info } = await readBag(wasm, path.join(data, 'bags', 'freiburg', `${log}.bag`));
  const replay = bag.replay(LogReplay);
  bag.free();
  replay.setRelations(await readFile(path.join(data, 'bags', 'freiburg', `${log}.relations`), 'utf8'));
  const n = replay.laserRecords();
  let [from, to] = [0, n - 1];
  if (stretch === 'first') to = Math.floor(n / 2) - 1;
  if (stretch === 'second') from = Math.floor(n / 2);
  replay.setRange(from, to);
  const t0 = performance.now();
  replay.finish();
  const seconds = (performance.now() - t0) / 1000;
  const r = replay.report({});
  replay.free();
  const scans = r.scans;
  const span = scans[scans.length - 1].time - scans[0].time;
  return {
    log, stretch: stretch ?? 'whole', scans: scans.length, duration_s: span ?? info.duration_s,
    replay_s: seconds, real_time: span / seconds, closures: r.loop_closures.length,
    relations: { count: r.relations.count, matched: r.relations.matched, trans_m: r.relations.trans_m, rot_deg: r.relations.rot_deg },
  };
}

function row(s) {
  const p = PUBLISHED[s.log];
  const q = s.relations;
  const f = (v, d) => v.toFixed(d);
  return `| ${s.log}${s.stretch === 'whole' ? '' : ` (${s.stretch} half)`} | ${q.matched} | ` +
    `${f(q.trans_m.mean, 4)} ± ${f(q.trans_m.sd, 4)} (max ${f(q.trans_m.max, 3)}) | ` +
    `${f(q.rot_deg.mean, 3)} ± ${f(q.rot_deg.sd, 3)} (max ${f(q.rot_deg.max, 2)}) | ` +
    `${p.scanMatching} | ${p.gmapping} | ${p.graphMapping} | ${p.cartographer} | ` +
    `${q.trans_m.mean <= p.cartographer ? 'yes' : 'no'} | ${s.closures} | ${f(s.real_time, 0)}× |`;
}

async function main() {
  const args = process.argv.slice(2);
  const halves = args.includes('--halves');
  const json = args.includes('--json');
  const logs = args.filter((a) => !a.startsWith('--'));
  const wasm = await loadWasm();
  const out = [];
  for (const log of logs.length ? logs : Object.keys(PUBLISHED)) {
    if (!PUBLISHED[log]) throw new Error(`unknown log '${log}' (aces, intel, mit-csail, fr079)`);
    for (const stretch of halves ? [null, 'first', 'second'] : [null]) {
      const s = await score(wasm, log, stretch);
      out.push(s);
      if (!json) process.stderr.write(`${log} ${s.stretch}: ${s.relations.trans_m.mean.toFixed(4)} m\n`);
    }
  }
  if (json) {
    process.stdout.write(JSON.stringify(out) + '\n');
    return;
  }
  console.log('| log | relations | ours: translation (m) mean ± sd (max) | ours: rotation (deg) | scan matching | GMapping | graph mapping | Cartographer | ahead of Cartographer | loop closures | replay speed |');
  console.log('|---|---|---|---|---|---|---|---|---|---|---|');
  for (const s of out) console.log(row(s));
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  main().catch((e) => {
    console.error(e.stack ?? e);
    process.exitCode = 1;
  });
}
