// Map merging from the command line: `run` merges after simulating
// (web/cli/run.mjs), and `merge` writes the merged map as ROS map_server files.
import { writeFile } from 'node:fs/promises';
import path from 'node:path';
import { parseArgs, UsageError, wasmCall, openScenario } from './args.mjs';
import { workersOf } from './describe-pool.mjs';
import { simulate, mergeRobotMaps } from './run-loop.mjs';

export const METHODS = ['auto', 'thesis', 'map-only'];

export const usage = `  node web/cli.mjs merge SCENARIO.json --out FILE.yaml [--method auto|thesis|map-only] [--seed N] [--duration S] [--workers N]
      run the scenario (N worker threads describing frames and N mapping robots meanwhile, as for run), merge the robots' maps, and write the merged map as ROS map_server PGM + YAML (and a PNG)`;

/** Checks a --method value (undefined means the default, auto). */
export function methodOf(options) {
  const method = options.method ?? 'auto';
  if (!METHODS.includes(method)) {
    throw new UsageError(`--method: '${method}' is not one of ${METHODS.join(', ')}`);
  }
  return method;
}

/** One-paragraph summary of a merge report for people. */
export function describeMerge(merge) {
  if (!merge) return 'no merge';
  const lines = [`merge (${merge.method}): ${merge.status}, confidence ${merge.confidence.toFixed(2)}`];
  lines.push(`  ${merge.reason}`);
  for (const t of merge.transforms) {
    const e = merge.errors.find((x) => x.robot === t.robot);
    const err = e ? ` (off by ${e.error_m.toFixed(3)} m, ${e.error_deg.toFixed(2)} deg)` : '';
    lines.push(`  ${t.robot}: frame at x ${t.pose[0].toFixed(3)} m, y ${t.pose[1].toFixed(3)} m, ` +
      `theta ${(t.pose[2] * 180 / Math.PI).toFixed(2)} deg${err}`);
  }
  if (merge.unjoined.length > 0) lines.push(`  not joined: ${merge.unjoined.join(', ')}`);
  return lines.join('\n');
}

async function merge(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    out: 'value', method: 'value', seed: 'value', duration: 'value', workers: 'value',
  });
  if (positional.length !== 1) throw new UsageError('merge: expected exactly one SCENARIO.json');
  if (options.out === undefined) throw new UsageError('merge: --out FILE.yaml is required');
  if (!/\.ya?ml$/i.test(options.out)) throw new UsageError(`--out: '${options.out}' should end in .yaml`);
  const method = methodOf(options);
  const mappers = workersOf(options);
  const workers = method === 'map-only' ? 0 : mappers;
  const lab = await openScenario(positional[0], options, wasm);
  await simulate(lab, { method, workers, mappers, progress: false });
  const view = mergeRobotMaps(lab, method);
  const report = view.report;
  console.log(describeMerge(report));
  if (!report || report.status !== 'merged') {
    console.log('no merged map written');
    return 0;
  }
  const base = options.out.replace(/\.ya?ml$/i, '');
  const pgmPath = `${base}.pgm`;
  const pngPath = `${base}.png`;
  try {
    await writeFile(pgmPath, wasmCall(() => lab.mergedPgm()));
    await writeFile(pngPath, wasmCall(() => lab.mergedPng()));
    await writeFile(options.out, wasmCall(() => lab.mergedYaml(path.basename(pgmPath))));
  } catch (e) {
    if (e instanceof UsageError) throw e;
    throw new UsageError(`cannot write '${options.out}': ${e.code ?? e.message}`);
  }
  const info = report.merged_map;
  console.log(`merged map ${info.width} x ${info.height} cells at ${info.resolution_m} m -> ${options.out}, ${pgmPath}, ${pngPath}`);
  return 0;
}

export const commands = { merge };
