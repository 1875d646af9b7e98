// Worker threads that map some of the robots while the main thread runs the
// simulation (crate/src/slam/handoff.rs says why the run is the same bits).
//
// At the start, each robot chosen to map away hands its mapping over as
// bytes (Lab.sendMappingAway) to one worker, which keeps it as a SlamAway.
// After every slice of the run, send() takes the steps each away robot
// has made since (Lab.takeMappingSteps, its odometry poses and laser scans
// packed) and posts them to its worker, the buffer transferred; the worker
// maps them in order and answers with their SLAM poses, which the lab keeps
// for the frames it picks to describe meanwhile (picked by odometry's poses,
// they would mostly be frames the merge never asks for). pace() keeps the
// main thread at most a few slices ahead of a worker, so the packed steps
// waiting never take much memory. finish() asks every worker for its
// mappings back and hands them to the lab (Lab.bringMappingHome), which
// checks that each has seen every step. A worker that fails loses the
// mapping it held: the run then fails with its message (nothing else can
// rebuild it).
import { Worker } from 'node:worker_threads';
import path from 'node:path';
import { compiledModule, pkgDir } from './wasm.mjs';
import { Wakeup } from './wakeup.mjs';

/** Slices of the run a worker may have waiting before the main thread waits for it. */
const MAX_SLICES_AHEAD = 6;

/**
 * The main thread's share of simulating the world (lasers, sonars, motion,
 * camera poses) for one robot, in units of that robot's mapping. Measured
 * on the hour of BENCHMARKS.md (16 robots, 3,600 s): of the main thread's
 * 52 s, 31.6 s mapped its 8 robots (3.95 s a robot) and 20.4 s ran the
 * world, about a third of a robot's mapping per robot.
 */
const WORLD_PER_ROBOT = 1 / 3;

/**
 * The robots (indices of `robots` robots) that map away when `threads`
 * threads map. The main thread also runs the world, so it keeps fewer
 * robots than a worker: the mappings are shared so that every thread,
 * counting the world's share on the main thread, has about the same load,
 * and the robots it keeps are spread over the indices (robot 0 first).
 * (On the hour, keeping 8 of 16 the main thread was the run's critical
 * path, 61.6 s; keeping 5, 55.2 s; 3, 4 and 6: 57.0, 55.9 and 56.7 s.)
 */
export function robotsAway(robots, threads) {
  if (threads <= 0) return [];
  const perThread = (robots * (1 + WORLD_PER_ROBOT)) / (threads + 1);
  const keep = Math.max(0, Math.min(robots, Math.round(perThread - robots * WORLD_PER_ROBOT)));
  const kept = new Set(Array.from({ length: keep }, (_, j) => Math.floor((j * robots) / keep)));
  return Array.from({ length: robots }, (_, i) => i).filter((i) => !kept.has(i));
}

export class SlamPool {
  /**
   * Starts `count` workers and hands them the mappings of `robots`, in
   * turn. A worker's port queues messages until it has loaded. If a
   * hand-over fails, the workers started are stopped before it throws.
   */
  constructor(lab, robots, count) {
    this.errors = [];
    this.wakeup = new Wakeup();
    this.mappingMs = 0;
    this.estimates = [];
    const workerData = { module: compiledModule(), pkgJs: path.join(pkgDir(), 'slamlab.js') };
    this.workers = Array.from({ length: Math.min(count, robots.length) }, () => {
      const thread = new Worker(new URL('./slam-worker.mjs', import.meta.url), { workerData });
      // waiting: batches posted and not yet mapped (one per robot a slice).
      const w = { thread, robots: 0, waiting: 0, alive: true, home: new Map() };
      thread.on('message', (msg) => {
        if (msg.error) this.errors.push(msg.error);
        else if (msg.mapped) {
          w.waiting -= 1;
          this.estimates.push(msg);
        }
        else if (msg.bytes) w.home.set(msg.robot, msg.bytes);
        else if (msg.finished) {
          w.finished = true;
          this.mappingMs += msg.ms;
        }
        this.wakeup.wake();
      });
      thread.on('error', (e) => {
        w.alive = false;
        this.errors.push(`a mapping worker stopped: ${e?.message ?? e}`);
        this.wakeup.wake();
      });
      return w;
    });
    this.away = robots.map((robot, k) => ({ robot, worker: this.workers[k % this.workers.length] }));
    try {
      for (const { robot, worker } of this.away) {
        worker.robots += 1;
        const start = lab.sendMappingAway(robot);
        worker.thread.postMessage({ robot, start }, [start.buffer]);
      }
    } catch (e) {
      this.close();
      throw e;
    }
  }

  /** Throws what went wrong in a worker, if anything did. */
  check() {
    if (this.errors.length > 0) throw new Error(`mapping on a worker thread: ${this.errors.join('; ')}`);
  }

  /**
   * Hands the lab the SLAM poses the workers reported, then posts every
   * away robot's new steps to its worker.
   */
  send(lab) {
    this.check();
    for (const { robot, estimates } of this.estimates) lab.noteAwayEstimates(robot, estimates);
    this.estimates = [];
    for (const { robot, worker } of this.away) {
      const steps = lab.takeMappingSteps(robot);
      if (steps.length === 0) continue;
      worker.thread.postMessage({ robot, steps }, [steps.buffer]);
      worker.waiting += 1;
    }
  }

  /** Waits while a worker has more than a few slices of its robots' steps still to map. */
  async pace() {
    while (this.workers.some((w) => w.alive && w.waiting > MAX_SLICES_AHEAD * w.robots)) {
      await this.wakeup.next();
      this.check();
    }
  }

  /**
   * After the run: takes every mapping home. Returns the time the workers
   * spent mapping (ms, summed over workers).
   */
  async finish(lab) {
    this.send(lab);
    for (const w of this.workers) w.thread.postMessage({ finish: true });
    while (this.workers.some((w) => w.alive && !w.finished)) {
      await this.wakeup.next();
      this.check();
    }
    this.check();
    for (const { robot, worker } of this.away) {
      const bytes = worker.home.get(robot);
      if (!bytes) throw new Error(`mapping on a worker thread: robot ${robot}'s mapping did not come back`);
      lab.bringMappingHome(robot, bytes);
      worker.home.delete(robot);
    }
    return this.mappingMs;
  }

  close() {
    for (const w of this.workers) w.thread.terminate();
  }
}
