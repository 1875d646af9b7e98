// A worker thread of `node web/cli.mjs run` that maps robots for the main
// thread (web/cli/slam-pool.mjs): its own instance of the wasm build, one
// SlamAway per robot it was handed. Messages in: {robot, start} (the
// mapping's bytes), {robot, steps} (a packed batch), {finish}; out:
// {robot, mapped, estimates} per batch (the SLAM poses of its steps), then
// at the finish {robot, bytes} per robot
// (buffers transferred) and {finished, ms}; or {error}.
import { parentPort, workerData } from 'node:worker_threads';
import { pathToFileURL } from 'node:url';
import { performance } from 'node:perf_hooks';

const wasm = await import(pathToFileURL(workerData.pkgJs).href);
wasm.initSync({ module: workerData.module });
const mappings = new Map();
let ms = 0;

function mapping(robot) {
  const m = mappings.get(robot);
  if (!m) throw new Error(`robot ${robot}'s mapping was never handed over`);
  return m;
}

parentPort.on('message', ({ robot, start, steps, finish }) => {
  try {
    const t0 = performance.now();
    if (start) {
      mappings.set(robot, new wasm.SlamAway(start));
    } else if (steps) {
      const m = mapping(robot);
      const from = m.steps() + 1;
      m.observe(steps);
      const estimates = m.estimatesFrom(from);
      ms += performance.now() - t0;
      parentPort.postMessage({ robot, mapped: true, estimates }, [estimates.buffer]);
    } else if (finish) {
      for (const [r, m] of mappings) {
        const bytes = m.finish();
        m.free();
        parentPort.postMessage({ robot: r, bytes }, [bytes.buffer]);
      }
      mappings.clear();
      parentPort.postMessage({ finished: true, ms });
    }
  } catch (e) {
    parentPort.postMessage({ error: `robot ${robot}: ${e?.message ?? e}` });
  }
});
