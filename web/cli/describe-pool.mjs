// Worker threads that describe the run's camera frames while it is still
// running (crate/src/merge/described.rs says why that gives the same report).
//
// Every few simulated seconds the run loop calls dispatch(): the lab lists
// the frames a merge would describe that nobody has yet, they join a queue,
// and each worker is kept a few frames ahead, taking them in capture order
// (consecutive frames see the same walls, so a worker paints most wall
// textures once). collect() stores what came back in the lab. After the
// run, finish() has the main thread describe frames from the far end of the
// queue too, until the queue is empty and the workers are done. The merge
// then finds every frame described; any a worker could not do, it
// describes itself (and stderr says so).
import { Worker } from 'node:worker_threads';
import os from 'node:os';
import path from 'node:path';
import { compiledModule, pkgDir } from './wasm.mjs';
import { performance } from 'node:perf_hooks';
import { UsageError, wasmCall } from './args.mjs';

/**
 * Workers when --workers is not given: one per core but the main thread's,
 * at most 4; none on one core (the main thread then describes the frames
 * after the run, as it does with --workers 0).
 */
export function defaultWorkers() {
  const cores = os.availableParallelism?.() ?? os.cpus().length;
  return Math.max(0, Math.min(4, cores - 1));
}

/** The --workers option (a string or undefined) as a count. */
export function workersOf(options) {
  if (options.workers === undefined) return defaultWorkers();
  const n = Number(options.workers);
  if (!/^\d+$/.test(options.workers) || n > 64) {
    throw new UsageError(`--workers: '${options.workers}' is not a whole number from 0 to 64`);
  }
  return n;
}

/**
 * Frames a worker is handed ahead of what it has finished: while the robots
 * run, enough to keep it busy between two of the run loop's pauses; after
 * the run, few, so that the main thread and the workers share out the rest
 * of the queue evenly (a frame handed to a worker cannot be taken back).
 */
const AHEAD_DURING_RUN = 48;
const AHEAD_AFTER_RUN = 8;

export class DescribePool {
  /**
   * Starts `count` workers, each with a Lab of `lab`'s scenario. Frames may
   * be handed out at once: a worker's port queues them until it has loaded.
   */
  constructor(lab, method, count) {
    this.method = method;
    this.sent = new Set();
    this.queue = [];
    this.ahead = AHEAD_DURING_RUN;
    this.results = [];
    this.errors = [];
    this.waiting = null;
    const workerData = {
      module: compiledModule(),
      pkgJs: path.join(pkgDir(), 'slamlab.js'),
      scenarioJson: lab.scenarioJson(),
      method,
    };
    this.workers = Array.from({ length: count }, () => {
      const thread = new Worker(new URL('./frame-worker.mjs', import.meta.url), { workerData });
      const w = { thread, pending: 0, alive: true };
      thread.on('message', (msg) => {
        w.pending -= 1;
        if (msg.error) this.errors.push(`frame ${msg.index} of robot ${msg.robot}: ${msg.error}`);
        else this.results.push(msg);
        this.wake();
      });
      thread.on('error', (e) => {
        // The frames it held are described by the merge itself.
        w.alive = false;
        w.pending = 0;
        this.errors.push(`a worker stopped: ${e?.message ?? e}`);
        this.wake();
      });
      return w;
    });
  }

  wake() {
    if (this.waiting) {
      const resolve = this.waiting;
      this.waiting = null;
      resolve();
    }
  }

  /** Queues the frames the lab wants described that nobody has yet, and hands them out. */
  dispatch(lab) {
    const flat = lab.framesToDescribe(this.method);
    for (let k = 0; k < flat.length; k += 2) {
      const [robot, index] = [flat[k], flat[k + 1]];
      const key = `${robot}/${index}`;
      if (this.sent.has(key)) continue;
      this.sent.add(key);
      this.queue.push({ robot, index });
    }
    this.feed(lab);
  }

  /** Tops every live worker up to `this.ahead` frames from the front of the queue. */
  feed(lab) {
    for (const w of this.workers) {
      while (w.alive && w.pending < this.ahead && this.queue.length > 0) {
        const { robot, index } = this.queue.shift();
        w.thread.postMessage({ robot, index, spec: lab.frameSpecJson(robot, index) });
        w.pending += 1;
      }
    }
  }

  /** Stores the features that came back in the lab and hands out more. */
  collect(lab) {
    for (const { robot, index, packed } of this.results) {
      lab.storeDescribed(robot, index, this.method, packed);
    }
    this.results = [];
    this.feed(lab);
  }

  /** Lets the workers' messages in (the run loop is otherwise synchronous). */
  breathe() {
    return new Promise((resolve) => setImmediate(resolve));
  }

  /**
   * After the run: describes queued frames on this thread too, from the
   * back of the queue, until every frame handed out is back and stored.
   * Failures are reported on stderr (the merge describes those frames).
   */
  async finish(lab) {
    this.ahead = AHEAD_AFTER_RUN;
    this.dispatch(lab);
    for (;;) {
      this.collect(lab);
      if (this.queue.length > 0) {
        const { robot, index } = this.queue.pop();
        const packed = lab.describeFrameSpec(lab.frameSpecJson(robot, index), this.method);
        lab.storeDescribed(robot, index, this.method, packed);
        await this.breathe();
      } else if (this.workers.some((w) => w.alive && w.pending > 0)) {
        await new Promise((resolve) => {
          this.waiting = resolve;
        });
      } else {
        break;
      }
    }
    for (const e of this.errors) process.stderr.write(`describing frames: ${e}; the merge describes them itself\n`);
  }

  close() {
    for (const w of this.workers) w.thread.terminate();
  }
}

/**
 * Runs `lab` to the end of its scenario with `workers` worker threads
 * describing, meanwhile, the frames a merge with `method` will use; with 0
 * it only runs. Returns the run's time and the wait for the last frames
 * after it (ms). Progress goes to stderr when `progress` is set.
 */
export async function simulate(lab, method, workers, progress) {
  const total = JSON.parse(lab.stateJson()).total_steps;
  const pool = workers > 0 ? new DescribePool(lab, method, workers) : null;
  try {
    const tSim = performance.now();
    let done = 0;
    let lastReport = tSim;
    // Small slices keep the workers fed; without them, large ones.
    const slice = pool ? 100 : 500;
    while (done < total) {
      const n = wasmCall(() => lab.step(Math.min(slice, total - done)));
      if (n === 0) break;
      done += n;
      if (pool) {
        pool.collect(lab);
        pool.dispatch(lab);
        await pool.breathe();
      }
      const now = performance.now();
      if (progress && (now - lastReport > 1000 || done === total)) {
        process.stderr.write(`simulated ${(done / 10).toFixed(1)} / ${(total / 10).toFixed(1)} s\n`);
        lastReport = now;
      }
    }
    const simulateMs = performance.now() - tSim;
    const tWait = performance.now();
    if (pool) await pool.finish(lab);
    return { simulateMs, waitMs: pool ? performance.now() - tWait : 0 };
  } finally {
    // Also when the run throws: live workers would keep node from exiting.
    pool?.close();
  }
}
