// The `map` and `bench-slam` commands: a robot's occupancy grid as ROS
// map_server files, and the scan matcher's speed in this wasm build.
import { writeFile } from 'node:fs/promises';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { parseArgs, UsageError, wasmCall, openScenario } from './args.mjs';
import { simulate } from './run-loop.mjs';

export const usage = `  node web/cli.mjs map SCENARIO.json --robot NAME --out FILE.yaml [--seed N] [--duration S] [--mapper slam|odometry]
      run the scenario and write the robot's map as ROS map_server PGM + YAML (and a PNG beside them)
  node web/cli.mjs bench-slam SCENARIO.json [--robot NAME] [--duration S] [--runs N] [--json]
      time the scan matcher (one scan against the robot's map) in this wasm build`;

/** Opens the scenario file and runs it to its end (progress on stderr). */
async function runScenario(file, options, wasm) {
  const lab = await openScenario(file, options, wasm);
  await simulate(lab, { progress: true });
  return lab;
}

async function map(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    robot: 'value', out: 'value', seed: 'value', duration: 'value', mapper: 'value',
  });
  if (positional.length !== 1) throw new UsageError('map: expected exactly one SCENARIO.json');
  if (options.robot === undefined) throw new UsageError('map: --robot NAME is required');
  if (options.out === undefined) throw new UsageError('map: --out FILE.yaml is required');
  if (!/\.ya?ml$/i.test(options.out)) throw new UsageError(`--out: '${options.out}' should end in .yaml`);
  const mapper = options.mapper ?? 'slam';
  if (mapper !== 'slam' && mapper !== 'odometry') {
    throw new UsageError(`--mapper: '${mapper}' is not 'slam' or 'odometry'`);
  }
  const lab = await runScenario(positional[0], options, wasm);
  const robot = wasmCall(() => lab.robotIndex(options.robot));
  const base = options.out.replace(/\.ya?ml$/i, '');
  const pgmPath = `${base}.pgm`;
  const pngPath = `${base}.png`;
  const pgm = wasmCall(() => lab.mapPgm(robot, mapper));
  const png = wasmCall(() => lab.mapPng(robot, mapper));
  const yaml = wasmCall(() => lab.mapYaml(robot, mapper, path.basename(pgmPath)));
  try {
    await writeFile(pgmPath, pgm);
    await writeFile(pngPath, png);
    await writeFile(options.out, yaml);
  } catch (e) {
    throw new UsageError(`cannot write '${options.out}': ${e.code ?? e.message}`);
  }
  const info = lab.mapInfo(robot, mapper);
  const f = lab.slamFigures(robot);
  console.log(`${options.robot}: ${mapper} map ${info.width} x ${info.height} cells at ${info.resolution_m} m -> ${options.out}, ${pgmPath}, ${pngPath}`);
  console.log(`  ATE: SLAM ${f.ate_m.toFixed(3)} m, odometry ${f.odometry_ate_m.toFixed(3)} m; ` +
    `occupied cells on a wall: SLAM ${(100 * f.occupied_precision).toFixed(1)} %, odometry ${(100 * f.odometry_occupied_precision).toFixed(1)} %`);
  return 0;
}

async function benchSlam(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    robot: 'value', duration: 'value', runs: 'value', json: 'flag', seed: 'value',
  });
  if (positional.length !== 1) throw new UsageError('bench-slam: expected exactly one SCENARIO.json');
  const runs = Number(options.runs ?? 200);
  if (!Number.isInteger(runs) || runs < 1) throw new UsageError(`--runs: '${options.runs}' is not a positive whole number`);
  const lab = await runScenario(positional[0], { duration: options.duration ?? '60', seed: options.seed }, wasm);
  const robot = options.robot === undefined ? 0 : wasmCall(() => lab.robotIndex(options.robot));
  const times = [];
  for (let i = 0; i < runs; i++) {
    const t0 = performance.now();
    lab.benchMatchScan(robot);
    times.push(performance.now() - t0);
  }
  times.sort((a, b) => a - b);
  const out = { median_ms: times[Math.floor(runs / 2)], min_ms: times[0], runs, simd: wasm.simdEnabled() };
  if (options.json) console.log(JSON.stringify(out));
  else console.log(`scan matching: median ${out.median_ms.toFixed(3)} ms, min ${out.min_ms.toFixed(3)} ms over ${runs} runs (simd ${out.simd})`);
  return 0;
}

export const commands = { map, 'bench-slam': benchSlam };
