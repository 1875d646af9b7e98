// Worker threads that describe the run's camera frames while it is still
// running (crate/src/merge/described_ahead.rs says why that gives the same report).
//
// Every few simulated seconds the run loop calls dispatch(): the lab lists
// the frames a merge would describe that nobody has yet, they join a queue,
// and each worker is kept a few frames ahead, taking them in capture order
// (consecutive frames see the same walls, so a worker paints most wall
// textures once). collect() stores what came back in the lab. After the
// run, finish() splits each remaining frame between the two halves of the
// work: a worker, whose wall textures are painted, only renders it, and the
// main thread, whose textures are not, runs SURF on the pixels. The merge
// then finds every frame described; any a worker could not do, it
// describes itself (and stderr says so).
//
// The frame store thins its frames when its memory budget is full
// (crate/src/camera/capture.rs), also frames listed, queued or out with a
// worker. A queued frame that is gone is not handed out; features that
// come back for a gone frame are dropped (the lab says so by returning
// false, and forgets what it kept of frames thinned later); the merge only
// asks for frames the store holds.
import { Worker } from 'node:worker_threads';
import os from 'node:os';
import path from 'node:path';
import { compiledModule, pkgDir } from './wasm.mjs';
import { UsageError } from './args.mjs';
import { Wakeup } from './wakeup.mjs';

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
 * run, enough to keep it busy between two of the run loop's pauses, but no
 * more than it will finish before the run ends (at its pace so far), since
 * a frame handed out cannot be taken back and the split of the work changes
 * when the run ends; after the run, a few to render, enough to keep it busy
 * while the main thread describes what it rendered before.
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
    this.returned = 0;
    this.grays = [];
    this.render = false;
    this.errors = [];
    this.wakeup = new Wakeup();
    const workerData = {
      module: compiledModule(),
      pkgJs: path.join(pkgDir(), 'slamlab.js'),
      scenarioJson: lab.scenarioText(),
      method,
    };
    this.workers = Array.from({ length: count }, () => {
      const thread = new Worker(new URL('./frame-worker.mjs', import.meta.url), { workerData });
      const w = { thread, pending: 0, alive: true };
      thread.on('message', (msg) => {
        w.pending -= 1;
        this.returned += 1;
        if (msg.error) this.errors.push(`frame ${msg.index} of robot ${msg.robot}: ${msg.error}`);
        else if (msg.gray) this.grays.push(msg);
        else this.results.push(msg);
        this.wakeup.wake();
      });
      thread.on('error', (e) => {
        // The frames it held are described by the merge itself.
        w.alive = false;
        w.pending = 0;
        this.errors.push(`a worker stopped: ${e?.message ?? e}`);
        this.wakeup.wake();
      });
      return w;
    });
  }

  /**
   * While the run is `done` steps of `total` in: sets how far ahead the
   * workers are fed from the frames they have returned per step so far.
   */
  pace(done, total) {
    const live = this.workers.filter((w) => w.alive).length;
    if (done === 0 || this.returned === 0 || live === 0) return;
    const willFinish = Math.ceil((this.returned / done / live) * (total - done));
    this.ahead = Math.max(AHEAD_AFTER_RUN, Math.min(AHEAD_DURING_RUN, willFinish));
  }

  /** Queues the frames the lab wants described that nobody has yet, and hands them out. */
  dispatch(lab) {
    for (const { robot, index } of lab.framesToDescribe(this.method)) {
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
        if (!lab.hasFrame(robot, index)) continue; // thinned while queued
        w.thread.postMessage({ robot, index, spec: lab.frameSpec(robot, index), render: this.render });
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
   * After the run: the workers only render what is left, and this thread
   * describes their pictures. (Describing a frame here in full would cost
   * this thread several times what rendering it costs a worker, as the
   * wall textures it shows are not painted here.) Returns once every frame
   * is back and stored. Failures are reported on stderr (the merge
   * describes those frames); with no worker left, this thread describes
   * the rest.
   */
  async finish(lab) {
    this.ahead = AHEAD_AFTER_RUN;
    this.render = true;
    this.dispatch(lab);
    for (;;) {
      this.collect(lab);
      const live = this.workers.filter((w) => w.alive);
      if (this.grays.length > 0) {
        const { robot, index, gray } = this.grays.shift();
        try {
          lab.describeRendered(robot, index, this.method, gray);
        } catch (e) {
          this.errors.push(`frame ${index} of robot ${robot}: ${e?.message ?? e}`);
        }
      } else if (this.queue.length > 0 && live.length === 0) {
        const { robot, index } = this.queue.pop();
        if (!lab.hasFrame(robot, index)) continue;
        const packed = lab.describeFrameSpec(lab.frameSpec(robot, index), this.method);
        lab.storeDescribed(robot, index, this.method, packed);
      } else if (live.some((w) => w.pending > 0)) {
        await this.wakeup.next();
        continue;
      } else {
        break;
      }
      await this.breathe();
    }
    for (const e of this.errors) process.stderr.write(`describing frames: ${e}; the merge describes them itself\n`);
  }

  close() {
    for (const w of this.workers) w.thread.terminate();
  }
}
