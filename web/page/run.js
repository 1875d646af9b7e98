// The run controller: Run, Pause, Step and Reset, and the simulation's
// pace. The simulation lives in wasm; while running, the page's animation
// frame (web/app.js) calls `advance(now)`, which runs as many 0.1 s control
// steps as the speed asks for the time since the last frame, capped so a
// frame stays short (if the machine cannot keep up, the run slows down
// rather than piling up steps).
import { clamp } from './geometry.js';
import { fmt } from './dom.js';
import { setStatus } from './status.js';

const CONTROL_DT_S = 0.1; // one Lab step
const FRAME_BUDGET_MS = 12; // time per frame we allow for simulation steps

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
    this.stepCarry = 0;
    // Steps a frame may take, from the measured cost of a step. It starts at
    // one and at most doubles a frame, so that the first frame of a run (no
    // measure yet) or one fast step cannot start a long task (issue 22: 20
    // steps of 16 robots in the first frame took 300+ ms).
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

  /** Advances the simulation for one animation frame at `nowMs`. */
  advance(nowMs) {
    const dt = clamp((nowMs - this.lastFrameMs) / 1000, 0, 0.1);
    this.lastFrameMs = nowMs;
    const wanted = (this.speed * dt) / CONTROL_DT_S + this.stepCarry;
    let n = Math.floor(wanted);
    this.stepCarry = wanted - n;
    if (n > this.maxStepsPerFrame) {
      n = this.maxStepsPerFrame;
      this.stepCarry = 0; // the machine cannot keep up: slow down rather than pile up
    }
    if (n <= 0) return;
    const t0 = performance.now();
    const taken = this.lab.step(n);
    const perStep = (performance.now() - t0) / Math.max(1, taken);
    const fit = Math.floor(FRAME_BUDGET_MS / Math.max(perStep, 1e-3));
    this.maxStepsPerFrame = clamp(fit, 1, Math.min(1000, 2 * this.maxStepsPerFrame));
    this.hooks.invalidate();
    if (taken < n) this.afterSteps(taken, n);
    else if (this.lab.timeS() + 1e-9 >= this.store.scenario.duration_s) this.afterSteps(taken, taken + 1);
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
