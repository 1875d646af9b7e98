// Where an animation frame's time goes (issue 22): the page's frame
// (web/app.js) times each of its parts — the simulation's steps, the world
// view, the camera and maps panels, the merge, the guided mode, the
// readouts — and keeps the totals and the parts of the slowest frames.
// The benchmarks read them (`window.slamlab.frameTimes()`,
// tests/bench/page_perf.mjs `--parts`); the page itself never does.

const WORST = 8; // how many of the slowest frames are kept, parts and all

export class FrameTimes {
  constructor() {
    this.reset();
  }

  /** Starts counting afresh. */
  reset() {
    this.total = {};
    this.frames = 0;
    this.worst = [];
    this.current = null;
  }

  /** A frame begins; its parts are timed with `time` until `end`. */
  begin() {
    this.current = { start: performance.now(), parts: {} };
  }

  /** Runs `fn`, adding its duration to part `name` of this frame. */
  time(name, fn) {
    const t0 = performance.now();
    try {
      return fn();
    } finally {
      const c = this.current;
      if (c) c.parts[name] = (c.parts[name] ?? 0) + performance.now() - t0;
    }
  }

  /** The frame ends: adds its parts to the totals and keeps it if among the slowest. */
  end(extra = {}) {
    const c = this.current;
    if (!c) return;
    this.current = null;
    const ms = performance.now() - c.start;
    this.frames++;
    for (const [k, v] of Object.entries(c.parts)) this.total[k] = (this.total[k] ?? 0) + v;
    this.total.frame = (this.total.frame ?? 0) + ms;
    if (this.worst.length < WORST || ms > this.worst[this.worst.length - 1].ms) {
      this.worst.push({ ms, ...extra, parts: c.parts });
      this.worst.sort((a, b) => b.ms - a.ms);
      this.worst.length = Math.min(this.worst.length, WORST);
    }
  }

  /** The totals (ms) and the slowest frames, rounded for reading. */
  report() {
    const r = (x) => Math.round(x * 10) / 10;
    const round = (o) => Object.fromEntries(Object.entries(o).map(([k, v]) => [k, typeof v === 'number' ? r(v) : v]));
    return {
      frames: this.frames,
      total_ms: round(this.total),
      worst: this.worst.map((w) => ({ ...round(w), parts: round(w.parts) })),
    };
  }
}
