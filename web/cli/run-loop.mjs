// The command line's one run loop: every command that runs a scenario
// (run, merge, frames, map, bench-slam) steps the lab here, and every
// command that merges (run, merge) drives the merge here, over the facade
// web/lab.js.
//
// simulate() steps the lab to the end of its scenario in slices; with
// worker threads it keeps them fed between slices: some map some of the
// robots (web/cli/slam-pool.mjs), others describe the camera frames a
// merge will describe (web/cli/describe-pool.mjs), so that the report is
// the same for any number of workers. mergeRobotMaps() then merges the
// robots' maps in small units of work, reporting its stage on stderr.
import { performance } from 'node:perf_hooks';
import { wasmCall } from './args.mjs';
import { DescribePool } from './describe-pool.mjs';
import { SlamPool, robotsAway } from './slam-pool.mjs';

/** Control steps per slice: small ones keep workers fed; without them, large ones. */
const SLICE_WITH_WORKERS = 100;
const SLICE_ALONE = 500;

/**
 * Runs `lab` (a web/lab.js Lab) to the end of its scenario. With
 * `workers` > 0, that many worker threads describe, meanwhile, the frames a
 * merge with `method` will use, and with `mappers` > 0 that many map some
 * of the robots (robotsAway). Progress goes to stderr once a second and at
 * the end when `progress` is set. Returns the run's time (until every
 * mapping is home), the wait for the last frames after it, and the time
 * the mapping threads mapped (ms).
 */
export async function simulate(lab, { method = 'auto', workers = 0, mappers = 0, progress = true } = {}) {
  const total = lab.state().total_steps;
  const away = robotsAway(lab.scenario().robots.length, mappers);
  const slam = away.length > 0 ? new SlamPool(lab, away, mappers) : null;
  const pool = workers > 0 ? new DescribePool(lab, method, workers) : null;
  try {
    const tSim = performance.now();
    let done = 0;
    let lastReport = tSim;
    const slice = pool || slam ? SLICE_WITH_WORKERS : SLICE_ALONE;
    while (done < total) {
      const n = wasmCall(() => lab.step(Math.min(slice, total - done)));
      if (n === 0) break;
      done += n;
      if (slam) {
        // Not through wasmCall: what fails here is the program's, not the input's.
        slam.send(lab);
        await slam.pace();
      }
      if (pool) {
        pool.collect(lab);
        pool.pace(done, total);
        pool.dispatch(lab);
        await pool.breathe();
      }
      const now = performance.now();
      if (progress && (now - lastReport > 1000 || done === total)) {
        process.stderr.write(`simulated ${(done / 10).toFixed(1)} / ${(total / 10).toFixed(1)} s\n`);
        lastReport = now;
      }
    }
    const mappingMs = slam ? await slam.finish(lab) : 0;
    const simulateMs = performance.now() - tSim;
    const tWait = performance.now();
    if (pool) await pool.finish(lab);
    return { simulateMs, waitMs: pool ? performance.now() - tWait : 0, mappingMs };
  } finally {
    // Also when the run throws: live workers would keep node from exiting.
    pool?.close();
    slam?.close();
  }
}

/** Units of merge work between two looks at the clock. */
const MERGE_UNITS = 64;

/**
 * Merges the robots' maps of the lab's run with `method`, reporting progress on
 * stderr once a second and at each new stage. Returns the merge view
 * (tables and report).
 */
export function mergeRobotMaps(lab, method) {
  let progress = wasmCall(() => lab.mergeStart(method));
  let last = 0;
  let lastStage = '';
  while (!progress.finished) {
    progress = wasmCall(() => lab.mergeAdvance(MERGE_UNITS));
    const now = Date.now();
    if (progress.stage !== lastStage || now - last > 1000) {
      if (progress.total > 1) {
        process.stderr.write(`merge (${method}): ${progress.stage} ${progress.done} / ${progress.total}\n`);
      }
      last = now;
      lastStage = progress.stage;
    }
  }
  return wasmCall(() => lab.mergeView());
}
