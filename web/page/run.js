// The run controller: Run, Pause, Step and Reset, and the simulation's
// pace. The simulation lives in wasm; while running, the page's animation
// frame (web/app.js) first redraws what is due, then calls
// `advance(now, spentMs)`, which runs as many 0.1 s control steps as the
// speed asks for the time since the last frame, within what is left of the
// frame's time.
//
// The pace (issue 22: 16 robots at 20× ask 200 steps a second, 2-4 ms
// each). A fixed 12 ms of steps a frame gave 13-16 simulated s per s at
// 20×, the views (world, cameras) taking twice the simulation's time. Now
// steps the frame could not fit are owed, up to CATCH_UP_S of wall time's
// worth (a machine that cannot keep up runs slower rather than piling up
// steps), and the steps' time per frame (`budgetMs`) adapts: it grows by
// BUDGET_UP_MS each frame that ends with steps owed, up to what is left of
// FRAME_TASK_MS after the views, and shrinks by BUDGET_DOWN_MS, down to
// BUDGET_MIN_MS, each frame that does not. `strain()` says how far it has
// grown; the page redraws its views less often the more it is (web/app.js),
// so the simulation gets the time. Each step's cost is measured as it goes;
// the first frame of a run takes one step and the cap on a frame's steps
// doubles a frame, so that no unmeasured batch starts a long task. A batch
// is taken a step at a time and stops when its budget is spent: a step can
// cost several times the average, and 12-14 steps of 16 robots made 100-116
// ms frames when one of them did (a 45 s run at 20x,
// docs/history/issue-22-many-robots.md, round 6).
import { clamp } from './geometry.js';
import { fmt } from './dom.js';
import { setStatus } from './status.js';

const CONTROL_DT_S = 0.1; // one Lab step
const CATCH_UP_S = 0.5; // owed steps kept: at most this much wall time's worth at the speed
const STEP_COST_WEIGHT = 0.3; // weight of the newest frame in the step-cost estimate
const FRAME_TASK_MS = 40; // a frame's work (views and steps) at most, when steps are owed
const BUDGET_MIN_MS = 12; // the steps' time per frame when the run keeps up
const BUDGET_UP_MS = 2; // ... grows by this each frame that ends with steps owed
const BUDGET_DOWN_MS = 1; // ... and shrinks by this each frame that does not

export class RunController {
  /**
   * @param {import('./state.js').Store} store
   * @param {{guard: Function, cancelDrag: () => void, refreshPanels: () => void,
   *          refreshControls: () => void, readouts: (force: boolean) => void,
   *          invalidate: () => void}} hooks
   */
  constructor(store, hooks) {
    this.store = store;
    this.hooks = hooks;
    this.running = false;
    this.speed = 10; // simulated seconds per real second
    this.lastFrameMs = 0;
    this.stepCarry = 0; // steps owed (wanted by the speed, not yet taken)
    this.budgetMs = BUDGET_MIN_MS; // the steps' time per frame (see the top)
    this.stepMs = 0; // measured cost of one step (0: not measured yet)
    // Steps a frame may take at most: one on a run's first frame, and at
    // most twice the last frame's, so that no unmeasured batch can start a
    // long task (issue 22: 20 steps of 16 robots in one frame took 300+ ms).
    this.maxStepsPerFrame = 1;
    /** The run's state as last read (web/lab.js `state()`), or null. */
    this.state = null;
    for (const k of ['run', 'pause', 'step', 'reset']) this[k] = hooks.guard(this[k].bind(this));
  }

  get lab() {
    return this.store.lab;
  }

  /** The scenario can be edited only at t = 0, not running. */
  editable() {
    return !!this.lab && !this.running && this.lab.timeS() === 0;
  }

  readState() {
    this.state = this.lab.state();
    return this.state;
  }

  /** Stops running (a new scenario, an error); the run itself is kept. */
  halt() {
    this.running = false;
  }

  run() {
    if (this.running) return;
    const st = this.readState();
    if (st.finished) {
      setStatus('The run has reached its duration: Reset (R) to run again, or raise the duration.', 'warn');
      return;
    }
    const problems = this.store.problems;
    if (st.steps === 0 && problems.length) {
      setStatus(`Cannot run: ${problems[0].text}. Move the robot clear first.`, 'error');
      return;
    }
    this.hooks.cancelDrag();
    if (this.store.selection?.kind === 'wall') this.store.select(null);
    this.running = true;
    this.lastFrameMs = performance.now();
    this.stepCarry = 0;
    this.budgetMs = BUDGET_MIN_MS;
    this.maxStepsPerFrame = 1;
    setStatus(`Running at ${this.speed}× real time.`, 'info');
    this.hooks.refreshPanels();
    this.hooks.refreshControls();
  }

  pause() {
    if (!this.running) return;
    this.running = false;
    setStatus(`Paused at t = ${fmt(this.lab.timeS(), 1)} s.`, 'info');
    this.hooks.readouts(true);
    this.hooks.refreshPanels();
  }

  step() {
    this.running = false;
    this.hooks.cancelDrag();
    const problems = this.store.problems;
    if (this.lab.timeS() === 0 && problems.length) {
      setStatus(`Cannot run: ${problems[0].text}. Move the robot clear first.`, 'error');
      return;
    }
    const taken = this.lab.step(1);
    this.afterSteps(taken, 1);
    if (taken === 1) setStatus(`Stepped to t = ${fmt(this.lab.timeS(), 1)} s.`, 'info');
    this.hooks.refreshPanels();
  }

  reset() {
    this.running = false;
    this.lab.reset();
    this.readState();
    this.hooks.readouts(true);
    this.hooks.refreshPanels();
    this.hooks.refreshControls();
    this.hooks.invalidate();
    const problems = this.store.problems;
    setStatus(
      problems.length ? `Back to t = 0. ${problems[0].text}.` : 'Back to t = 0: you can edit the scenario.',
      problems.length ? 'warn' : 'info',
    );
  }

  afterSteps(taken, asked) {
    const st = this.readState();
    this.hooks.invalidate();
    if (st.finished || taken < asked) this.finish(st);
    this.hooks.readouts(true);
    this.hooks.refreshControls();
  }

  /** The run reached its duration: every panel shows the final state, and
   *  the status line says what comes next (merging the maps). */
  finish(st) {
    this.running = false;
    this.hooks.refreshPanels();
    const next = st.robots.length >= 2
      ? 'Next: merge the robots\u2019 maps with Merge maps (Merge panel, on the right).'
      : 'Merging needs two robots: Reset (R) and Add robot to try it.';
    setStatus(`Run finished at t = ${fmt(st.time_s, 1)} s. ${next}`, 'ok');
    this.hooks.finished?.(st);
  }

  /** How far the steps' budget has grown to keep up with the speed: 0 (it
   *  keeps up within BUDGET_MIN_MS a frame) to 1 (it takes the frame). */
  strain() {
    return clamp((this.budgetMs - BUDGET_MIN_MS) / (FRAME_TASK_MS - BUDGET_MIN_MS), 0, 1);
  }

  /** Advances the simulation for one animation frame at `nowMs`, after the
   *  frame's other work took `spentMs`; returns the steps taken. */
  advance(nowMs, spentMs = 0) {
    const dt = clamp((nowMs - this.lastFrameMs) / 1000, 0, 0.25);
    this.lastFrameMs = nowMs;
    const wanted = (this.speed * dt) / CONTROL_DT_S + this.stepCarry;
    // At least one step, unless the views took half the frame already.
    const budget = Math.min(this.budgetMs, FRAME_TASK_MS - spentMs);
    const least = spentMs < FRAME_TASK_MS / 2 ? 1 : 0;
    const fit = this.stepMs > 0 ? Math.max(least, Math.floor(budget / this.stepMs)) : least;
    const n = Math.max(0, Math.min(Math.floor(wanted), fit, this.maxStepsPerFrame));
    this.stepCarry = Math.min(wanted - n, (this.speed * CATCH_UP_S) / CONTROL_DT_S);
    this.budgetMs = this.stepCarry >= 1
      ? Math.min(FRAME_TASK_MS, this.budgetMs + BUDGET_UP_MS)
      : Math.max(BUDGET_MIN_MS, this.budgetMs - BUDGET_DOWN_MS);
    if (n === 0) return 0;
    const { taken, ended, ms } = this.take(n, Math.max(budget, 0));
    // Steps a slow one left no time for are owed.
    this.stepCarry = Math.min(this.stepCarry + n - taken, (this.speed * CATCH_UP_S) / CONTROL_DT_S);
    const perStep = ms / Math.max(1, taken);
    this.stepMs = this.stepMs > 0 ? STEP_COST_WEIGHT * perStep + (1 - STEP_COST_WEIGHT) * this.stepMs : perStep;
    this.maxStepsPerFrame = Math.min(1000, 2 * this.maxStepsPerFrame);
    this.hooks.invalidate();
    if (ended || this.lab.timeS() + 1e-9 >= this.store.scenario.duration_s) this.afterSteps(taken, taken + 1);
    return taken;
  }

  /** Takes up to `n` steps one at a time, stopping once `budgetMs` is
   *  spent: a step can cost several times the average (a camera frame
   *  captured, a map grown), and the frame should not pay for the rest of
   *  the batch on top of it. The first step is always taken. Returns the
   *  steps taken, whether the run ended, and the time they took (ms). */
  take(n, budgetMs) {
    const t0 = performance.now();
    let taken = 0;
    let ended = false;
    while (taken < n && !ended) {
      const k = this.lab.step(1);
      taken += k;
      ended = k < 1;
      if (performance.now() - t0 >= budgetMs) break;
    }
    return { taken, ended, ms: performance.now() - t0 };
  }

  /** What the guided mode needs to know about the run. */
  info() {
    const st = this.readState();
    const s = this.store.scenario;
    return {
      steps: st.steps,
      time_s: st.time_s,
      finished: st.finished,
      running: this.running,
      duration_s: s.duration_s,
      robots: s.robots.map((r) => r.name),
      thesis: this.store.preset === 'thesis',
      name: s.name,
      seed: s.seed,
    };
  }
}
