// One animation frame's work while the page is open (issue 22): redraw
// what is due, then advance the run in the time left of the frame, and let
// the panels follow. The composition root (web/app.js) calls `run(now)`
// from requestAnimationFrame and hands the parts it composes to the
// constructor; this module owns only the pacing between them.
//
// While running, the world view is redrawn at most every WORLD_FRAME_MS
// and at most every WORLD_SHARE times what its last drawing took (16
// robots' laser rays took 20-40 ms to draw, more than a frame's steps), so
// that drawing leaves most of the time to the simulation; the more the run
// strains to keep its speed (web/page/run.js `strain()`), the less often.
// A frame that drew the world leaves the cameras (a live view costs as much
// as the world, more where its wall textures are not cached yet) to the
// next one, so that the two do not add up in one task; the maps wait for a
// frame in which neither drew. The simulation takes what is left.
//
// Frames that leave the page alone. Each frame that writes to the page
// (a canvas, a readout) costs the browser its own work after it — style,
// layout, paint, layerize, commit: 12-16 ms a frame with 16 robots (a
// `devtools.timeline` trace, tests/bench/page_trace.mjs), as much as four
// simulation steps. So the more the run strains, the more frames only step:
// a frame touches the page at most every strain × VIEW_GAP_MS, and the
// frames between give the simulation their whole time.
import { FrameTimes } from './frame-times.js';

const WORLD_FRAME_MS = 33; // the world view's redraw interval while running (about 30 per second)
const WORLD_SHARE = [3, 8]; // ... and at most every 3 times its drawing time (8 when the run strains)
const VIEW_GAP_MS = 100; // frames that draw anything come at most this often when the run strains fully

export class FramePacer {
  /**
   * @param {object} parts the page's parts: `runner` (run.js), `view`
   *   (world-view.js), `cameraPanel`, `mapsPanel`, `mergePanel`, `guide`,
   *   `toolbar`.
   */
  constructor(parts) {
    this.parts = parts;
    this.lastWorldMs = 0;
    this.worldDrawMs = 0;
    this.camerasNext = false; // the world was drawn last frame: this one is the cameras'
    this.lastViewMs = 0; // the last frame that could write to the page
    this.times = new FrameTimes(); // where each frame's time goes, for the benchmarks
  }

  /** The frame at `now` (ms); a throw is the caller's to report. */
  run(now) {
    const { runner, view, cameraPanel, mapsPanel, mergePanel, guide, toolbar } = this.parts;
    const t = this.times;
    const start = performance.now();
    t.begin();
    try {
      const running = runner.running;
      const strain = running ? runner.strain() : 0;
      if (running && now - this.lastViewMs < strain * VIEW_GAP_MS) {
        const steps = t.time('steps', () => runner.advance(now, 0));
        t.end({ steps, strain: Math.round(100 * strain) / 100 });
        return;
      }
      this.lastViewMs = now;
      const share = WORLD_SHARE[0] + strain * (WORLD_SHARE[1] - WORLD_SHARE[0]);
      const gap = Math.max(WORLD_FRAME_MS, share * this.worldDrawMs);
      const changed = view.dirty && (!running || (now - this.lastWorldMs >= gap && !this.camerasNext));
      if (changed) {
        const t0 = performance.now();
        t.time('world', () => view.draw());
        this.worldDrawMs = performance.now() - t0;
        this.lastWorldMs = now;
      }
      this.camerasNext = running && changed;
      const cameras = !this.camerasNext && t.time('cameras', () => cameraPanel.update(now, changed || running, strain));
      // Not in a frame the cameras drew in: after a pause both panels catch
      // up a block at a time, and one of each a frame made it long.
      if (!cameras && (!running || !changed)) t.time('maps', () => mapsPanel.update(now, changed || running));
      t.time('merge', () => mergePanel.update(now));
      t.time('guide', () => guide.update(now));
      if (running) t.time('readouts', () => toolbar.readouts(false));
      const spent = performance.now() - start;
      const steps = running ? t.time('steps', () => runner.advance(now, spent)) : 0;
      t.end({ steps, strain: Math.round(100 * strain) / 100 });
    } catch (e) {
      t.end();
      throw e;
    }
  }

  /** Where the frames' time went since the last `reset` (frame-times.js). */
  report(reset = false) {
    const r = this.times.report();
    if (reset) this.times.reset();
    return r;
  }
}
