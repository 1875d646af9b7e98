// The `run-log` command: replay a CARMEN laser log (FLASER / ROBOTLASER1 /
// RAWLASER1 + ODOM; .log, .clf, gzip-compressed or not) through the log SLAM
// (scan-to-map matching, pose graph, loop closures) and report every scan's
// final pose (docs/interfaces.md, "Real laser logs: run-log"), over the
// log replay's facade web/log-replay.js.
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { LogReplay } from '../log-replay.js';
import { parseArgs, UsageError, wasmCall } from './args.mjs';

export const usage = `  node web/cli.mjs run-log LOG [--json] [--out MAP.yaml] [--from N] [--to M]
      replay a CARMEN laser log (.log/.clf, gzip or not) through SLAM with loop
      closures; --from/--to pick laser records N..M (0-based); --out writes the
      map as ROS map_server PGM + YAML and a PNG`;

function wholeNumber(name, v) {
  if (v === undefined) return undefined;
  if (!/^\d+$/.test(v) || !Number.isSafeInteger(Number(v))) {
    throw new UsageError(`--${name}: '${v}' is not a whole number from 0`);
  }
  return Number(v);
}

async function runLog(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    json: 'flag', out: 'value', from: 'value', to: 'value',
  });
  if (positional.length !== 1) throw new UsageError('run-log: expected exactly one LOG file');
  if (options.out !== undefined && !/\.ya?ml$/i.test(options.out)) {
    throw new UsageError(`--out: '${options.out}' should end in .yaml`);
  }
  const from = wholeNumber('from', options.from) ?? 0;
  const to = wholeNumber('to', options.to);
  const file = positional[0];
  const t0 = performance.now();
  let bytes;
  try {
    bytes = await readFile(file);
  } catch (e) {
    throw new UsageError(`cannot read log '${file}': ${e.code ?? e.message}`);
  }
  const replay = wasmCall(() => LogReplay.open(wasm, bytes));
  const tParsed = performance.now();
  wasmCall(() => replay.setRange(from, to));
  let left = Infinity;
  let lastNote = performance.now();
  while (left > 0) {
    left = replay.step(200);
    if (!options.json && performance.now() - lastNote > 2000) {
      process.stderr.write(`  ${left} scans left\n`);
      lastNote = performance.now();
    }
  }
  const tSlam = performance.now();
  replay.finish();
  const tEnd = performance.now();
  const timings = {
    parse: tParsed - t0, slam: tSlam - tParsed, map: tEnd - tSlam, total: tEnd - t0,
  };
  if (options.out !== undefined) {
    const base = options.out.replace(/\.ya?ml$/i, '');
    const pgmPath = `${base}.pgm`;
    try {
      await writeFile(pgmPath, replay.mapPgm());
      await writeFile(`${base}.png`, replay.mapPng());
      await writeFile(options.out, replay.mapYaml(path.basename(pgmPath)));
    } catch (e) {
      throw new UsageError(`cannot write '${options.out}': ${e.code ?? e.message}`);
    }
  }
  if (options.json) {
    process.stdout.write(replay.reportText(timings) + '\n');
  } else {
    const r = replay.report(timings);
    const m = r.map;
    console.log(`${file}: ${r.scans.length} of ${r.laser_records} laser records replayed (${r.from}..${r.to}), ` +
      `${r.slam.keys} key scans, ${r.loop_closures.length} loop closures`);
    console.log(`  map ${m.width} x ${m.height} cells at ${m.resolution_m} m, origin (${m.origin_m[0].toFixed(2)}, ${m.origin_m[1].toFixed(2)})` +
      (options.out ? ` -> ${options.out}` : ''));
    console.log(`  timings (ms): parse ${timings.parse.toFixed(0)}, slam ${timings.slam.toFixed(0)}, ` +
      `map ${timings.map.toFixed(0)}, total ${timings.total.toFixed(0)}`);
  }
  return 0;
}

export const commands = { 'run-log': runLog };
