// `run`: simulate a scenario headless, merge the robots' maps and print the
// report (the `run --json` document of docs/interfaces.md, as the binding
// writes it, byte for byte).
import { performance } from 'node:perf_hooks';
import { UsageError, parseArgs, wasmCall, openScenario } from './args.mjs';
import { workersOf } from './describe-pool.mjs';
import { methodOf, describeMerge } from './merge.mjs';
import { simulate, mergeRobotMaps } from './run-loop.mjs';

export const usage = `usage:
  node web/cli.mjs run SCENARIO.json [--seed N] [--duration S] [--method auto|thesis|map-only] [--json]
      [--workers N] [--frame-budget-mb MB]
      run the scenario headless, merge the robots' maps (default method: auto)
      and print a report (JSON with --json); N worker threads (default: one
      per core but the main thread's, at most 4) describe camera frames while
      the robots run, and as many map some of the robots; MB: memory all robots' stored frames may take with the
      features a merge describes in them (default 384, about 45 kB a frame;
      the store thins its frames beyond it)`;

async function run(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    seed: 'value', duration: 'value', json: 'flag', method: 'value', workers: 'value',
    'frame-budget-mb': 'value',
  });
  if (positional.length !== 1) throw new UsageError('run: expected exactly one SCENARIO.json');
  const method = methodOf(options);
  const mappers = workersOf(options);
  const workers = method === 'map-only' ? 0 : mappers;
  const t0 = performance.now();
  const lab = await openScenario(positional[0], options, wasm);
  const budget = frameBudgetOf(options);
  if (budget !== undefined) wasmCall(() => lab.setFrameBudget(budget));
  const { simulateMs, waitMs, mappingMs } = await simulate(lab, { method, workers, mappers, progress: true });
  mergeRobotMaps(lab, method);
  const totalMs = performance.now() - t0;
  const timings = { simulate: simulateMs, features: waitMs, slam: mappingMs, total: totalMs };
  if (options.json) {
    // In chunks as the binding makes them: the text of a long, crowded run
    // (75 MB for sixteen robots over an hour) is never held whole.
    wasmCall(() => lab.writeReport(timings, (chunk) => process.stdout.write(chunk)));
    process.stdout.write('\n');
  } else {
    printSummary(wasmCall(() => lab.report(timings)), simulateMs);
  }
  return 0;
}

/** --frame-budget-mb as bytes (undefined when not given). */
function frameBudgetOf(options) {
  const v = options['frame-budget-mb'];
  if (v === undefined) return undefined;
  const mb = Number(v);
  if (v.trim() === '' || !Number.isFinite(mb) || mb <= 0 || mb > 4000) {
    throw new UsageError(`--frame-budget-mb: '${v}' is not a number of megabytes above 0 and at most 4000`);
  }
  return Math.round(mb * 1024 * 1024);
}

/** The report for people. */
function printSummary(r, simulateMs) {
  console.log(`scenario ${r.scenario}, seed ${r.seed}: ${r.steps} steps (${r.duration_s.toFixed(1)} s simulated) in ${simulateMs.toFixed(0)} ms`);
  for (const robot of r.robots) {
    const e = robot.odometry_final_error;
    console.log(`  ${robot.name} (follows ${robot.follow} wall): path ${robot.path_length_m.toFixed(1)} m, ` +
      `bumps ${robot.bumps}, odometry off by ${e.position_m.toFixed(2)} m and ${e.heading_deg.toFixed(1)} deg at the end`);
  }
  console.log(describeMerge(r.merge));
  const t = r.timings_ms;
  console.log(`timings (ms): simulate ${t.simulate.toFixed(0)} (camera ${t.camera.toFixed(0)}, slam ${t.slam.toFixed(0)}), ` +
    `features ${t.features.toFixed(0)}, matching ${t.matching.toFixed(0)}, merge ${t.merge.toFixed(0)}, total ${t.total.toFixed(0)}`);
}

export const commands = { run };
