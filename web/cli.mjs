#!/usr/bin/env node
// The lab's command line: the same wasm build as the page, run headless in node.
//
//   node web/cli.mjs run SCENARIO.json [--seed N] [--duration S] [--method auto|thesis|map-only] [--json]
//                                     [--workers N]
//
// While the robots run, worker threads (--workers; by default one per core but
// the main thread's, at most 4; 0 for none) describe the camera frames the
// merge will use; the report is the same with any number of them.
// Progress goes to stderr; with --json the report is the only thing on stdout.
// Exit status: 0 when the run completed, 2 on bad input (message on stderr),
// 1 on an internal error (a bug: please report it).
// Further commands (features, match, bench-surf, ...) come from web/cli/*.mjs.
import { performance } from 'node:perf_hooks';
import { loadWasm } from './cli/wasm.mjs';
import { UsageError, parseArgs, wasmCall, openScenario } from './cli/args.mjs';
import { methodOf, mergeLab, describeMerge } from './cli/merge.mjs';
import { simulate, workersOf } from './cli/describe-pool.mjs';

export { UsageError, parseArgs };

const USAGE = `usage:
  node web/cli.mjs run SCENARIO.json [--seed N] [--duration S] [--method auto|thesis|map-only] [--json]
      [--workers N]
      run the scenario headless, merge the robots' maps (default method: auto)
      and print a report (JSON with --json); N worker threads (default: one
      per core but the main thread's, at most 4) describe camera frames while
      the robots run`;

async function run(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    seed: 'value', duration: 'value', json: 'flag', method: 'value', workers: 'value',
  });
  if (positional.length !== 1) throw new UsageError('run: expected exactly one SCENARIO.json');
  const method = methodOf(options);
  const workers = method === 'map-only' ? 0 : workersOf(options);
  const t0 = performance.now();
  const lab = await openScenario(positional[0], options, wasm);
  const { simulateMs, waitMs } = await simulate(lab, method, workers, true);
  mergeLab(lab, method);
  const totalMs = performance.now() - t0;
  const report = wasmCall(() => lab.reportJson(JSON.stringify({ simulate: simulateMs, features: waitMs, total: totalMs })));
  if (options.json) {
    process.stdout.write(report + '\n');
  } else {
    const r = JSON.parse(report);
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
  return 0;
}

const commands = { run };
const usages = [USAGE];

// Commands contributed by other capabilities (each module exports `commands`
// and optionally `usage`).
for (const mod of ['./cli/camera.mjs', './cli/surf.mjs', './cli/slam.mjs', './cli/merge.mjs', './cli/run-log.mjs']) {
  try {
    const m = await import(mod);
    Object.assign(commands, m.commands);
    if (m.usage) usages.push(m.usage);
  } catch (e) {
    if (e.code !== 'ERR_MODULE_NOT_FOUND') throw e;
  }
}

async function main() {
  const [cmd, ...rest] = process.argv.slice(2);
  if (!cmd || cmd === '--help' || cmd === '-h' || cmd === 'help') {
    console.error(usages.join('\n'));
    return cmd ? 0 : 2;
  }
  const f = commands[cmd];
  if (!f) {
    console.error(`unknown command '${cmd}'\n${usages.join('\n')}`);
    return 2;
  }
  const wasm = await loadWasm();
  return await f(rest, wasm);
}

main().then(
  (code) => { process.exitCode = code ?? 0; },
  (e) => {
    if (e instanceof UsageError) {
      console.error(`error: ${e.message}`);
      process.exitCode = 2;
    } else {
      console.error(`internal error: ${e.stack ?? e}`);
      process.exitCode = 1;
    }
  },
);
