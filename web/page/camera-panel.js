// Camera views and film strips, one block per robot.
//
// Each block shows what the robot's camera sees (live, in colour; before a
// run, the view from its start pose) and, under it, a film strip of the
// frames captured so far (one per simulated second, as Fraps saved them in
// the thesis). Clicking a thumbnail shows that frame (the grey image the
// vision pipeline uses) and marks on the map where it was taken; "live"
// returns to the live view. Each robot keeps its own picked frame, so two
// robots' frames can be compared side by side (exercise 5), and a frame can
// be reached by its number.
//
// With many robots (up to 16) rendering every live view at every refresh
// took most of a frame (issue 22), so while a run goes only the blocks on
// screen (an IntersectionObserver tells which) render their live view and
// grow their strip; the others catch up when they scroll into view, and
// every block is brought up to date when the run pauses, steps or ends.
//
// A thumbnail is drawn only once it is on screen (scrolled into its strip's
// view; the newest, which a strip at its end scrolls on to show, at once),
// the others a few a frame: rendering one costs 0.1 ms where the wall textures
// it shows are cached and up to tens of milliseconds where they are not
// (crate/src/camera/texture.rs paints them on first use), and at 20× with
// 16 robots the strips on screen gained 80 frames a second, drawn at once
// when a strip grew (issue 22: 120-280 ms tasks). The strip's elements
// (its count, tab stops, clicks) are all there at once as before.
//
// By keyboard a strip is one tab stop (a roving tabindex): the arrow keys
// move from frame to frame and show each, Home and End go to the ends.

import { robotColour } from './palette.js';
import { spendFrame } from './budget.js';

const LIVE_INTERVAL_MS = 120; // live views refresh at about 8 per second
const LIVE_SHARE = [4, 12]; // ... and at most every 4 times what one took (12 when the run strains)
const STRIP_INTERVAL_MS = 500; // strips grow at most twice a second while running
const THUMB_W = 64;
const THUMB_SLICE_MS = 6; // thumbnails drawn a frame: until this much time is spent (at least one)
const FINAL_BUDGET_MS = 16; // a pause's refresh of the blocks, per frame

export class CameraPanel {
  /**
   * @param {HTMLElement} host
   * @param {{lab: () => any, onMarker: (m: {robot: number, index: number, pose: number[], fovDeg: number}[]) => void,
   *          onError: (e: unknown) => void}} hooks
   */
  constructor(host, hooks) {
    this.host = host;
    this.hooks = hooks;
    this.blocks = [];
    this.key = '';
    this.lastLiveMs = 0;
    this.turn = -1; // the on-screen block whose live view was refreshed last
    this.liveMs = 0; // what the last refresh took
    this.camera = { width: 320, height: 240, hfov_deg: 60 };
    /** Live renders per robot (for the page tests: hidden blocks render none while running). */
    this.liveDraws = [];
    /** Thumbnails on screen not drawn yet (canvas → [robot, index]). */
    this.pending = new Map();
    /** Blocks a pause or the run's end left to later frames. */
    this.stale = [];
    this.thumbSeen = typeof IntersectionObserver === 'undefined' ? null : new IntersectionObserver((entries) => {
      for (const e of entries) {
        if (!e.isIntersecting) continue;
        this.thumbSeen.unobserve(e.target);
        this.pending.set(e.target, [Number(e.target.dataset.robot), Number(e.target.dataset.index)]);
      }
    });
    this.seen = typeof IntersectionObserver === 'undefined' ? null : new IntersectionObserver((entries) => {
      for (const e of entries) {
        const b = this.blocks.find((x) => x.el === e.target);
        if (!b) continue;
        b.visible = e.isIntersecting;
        if (b.visible) this.lastLiveMs = 0; // catch up at the next frame
      }
    });
  }

  /** Rebuilds the blocks when the set of robots (or the camera) changes. */
  sync(scenario) {
    const lab = this.hooks.lab();
    if (!lab) return;
    this.camera = lab.camera();
    const key = JSON.stringify([scenario.robots.map((r) => r.name), this.camera]);
    if (key === this.key) return;
    this.key = key;
    this.host.replaceChildren();
    this.seen?.disconnect();
    this.thumbSeen?.disconnect();
    this.pending.clear();
    this.blocks = scenario.robots.map((r, i) => this.makeBlock(r.name, i));
    this.liveDraws = this.blocks.map(() => 0);
    this.picked();
    this.refresh(true);
  }

  makeBlock(name, i) {
    const el = document.createElement('div');
    el.className = 'cam-block';
    el.style.setProperty('--robot', robotColour(i));
    const head = document.createElement('div');
    head.className = 'cam-head';
    const title = document.createElement('span');
    title.className = 'cam-title';
    title.textContent = `${name} camera`;
    const what = document.createElement('span');
    what.className = 'cam-what';
    what.textContent = 'live';
    const live = document.createElement('button');
    live.type = 'button';
    live.className = 'cam-live';
    live.textContent = 'live';
    live.hidden = true;
    live.setAttribute('aria-label', `Back to ${name}'s live camera view`);
    live.addEventListener('click', () => this.select({ robot: i, index: null }));
    const goto = document.createElement('input');
    goto.type = 'number';
    goto.min = '0';
    goto.step = '1';
    goto.className = 'cam-goto';
    goto.placeholder = 'frame #';
    goto.setAttribute('aria-label', `Show ${name}'s frame number`);
    goto.addEventListener('change', () => this.goTo(i, goto));
    head.append(title, what, live, goto);
    const body = document.createElement('div');
    body.className = 'cam-body';
    const view = document.createElement('canvas');
    view.className = 'cam-view';
    view.width = this.camera.width;
    view.height = this.camera.height;
    view.setAttribute('role', 'img');
    view.setAttribute('aria-label', `What ${name}'s camera sees`);
    const strip = document.createElement('div');
    strip.className = 'cam-strip';
    strip.setAttribute('role', 'listbox');
    strip.setAttribute('aria-label', `${name}'s captured frames: arrow keys move, Home and End go to the ends`);
    strip.addEventListener('keydown', (e) => this.stripKey(e, i));
    const empty = document.createElement('p');
    empty.className = 'cam-empty';
    empty.textContent = 'Frames appear here once a second while the robots run.';
    strip.append(empty);
    body.append(view, strip);
    el.append(head, body);
    this.host.append(el);
    this.seen?.observe(el);
    return { el, visible: !this.seen, what, live, goto, view, ctx: view.getContext('2d'), strip, empty, shown: [], robot: i, selected: null };
  }

  /** Shows captured frame `index` in robot `robot`'s view (live again with
   *  index null; `null` for all: every view live). Other robots keep theirs. */
  select(choice) {
    const lab = this.hooks.lab();
    for (const b of this.blocks) {
      if (choice && choice.robot !== b.robot) continue;
      b.selected = choice ? choice.index : null;
      b.live.hidden = b.selected === null;
      for (const t of b.strip.querySelectorAll('.cam-thumb')) {
        const on = Number(t.dataset.index) === b.selected;
        t.classList.toggle('selected', on);
        t.setAttribute('aria-selected', String(on));
      }
      if (b.selected !== null && lab) {
        const m = lab.frame(b.robot, b.selected);
        lab.drawFrame(b.robot, b.selected, b.ctx);
        b.what.textContent = `frame ${m.index} · t = ${m.time_s.toFixed(1)} s (grey, as the vision pipeline sees it)`;
        b.pose = m.truth;
      } else {
        b.what.textContent = 'live';
      }
      this.rove(b);
    }
    this.picked();
    this.lastLiveMs = 0;
  }

  /** Tells the map where every picked frame was taken. */
  picked() {
    this.hooks.onMarker(this.blocks.filter((b) => b.selected !== null)
      .map((b) => ({ robot: b.robot, index: b.selected, pose: b.pose, fovDeg: this.camera.hfov_deg })));
  }

  /** The strip's one tab stop: the picked frame, else the newest. */
  rove(b) {
    const thumbs = [...b.strip.querySelectorAll('.cam-thumb')];
    const stop = thumbs.find((t) => Number(t.dataset.index) === b.selected) ?? thumbs[thumbs.length - 1];
    for (const t of thumbs) t.tabIndex = t === stop ? 0 : -1;
  }

  /** Arrow keys inside a strip: move to the next or previous frame and show it. */
  stripKey(e, robot) {
    const b = this.blocks[robot];
    const thumbs = [...b.strip.querySelectorAll('.cam-thumb')];
    const k = thumbs.indexOf(document.activeElement);
    if (k < 0) return;
    const to = { ArrowLeft: k - 1, ArrowRight: k + 1, ArrowUp: k - 1, ArrowDown: k + 1, Home: 0, End: thumbs.length - 1 }[e.key];
    if (to === undefined) return;
    e.preventDefault();
    e.stopPropagation();
    const t = thumbs[Math.max(0, Math.min(thumbs.length - 1, to))];
    this.select({ robot, index: Number(t.dataset.index) });
    t.focus();
  }

  /** The frame-number box: shows that frame and scrolls the strip to it. */
  goTo(robot, input) {
    const b = this.blocks[robot];
    const index = Number(input.value);
    const t = b.strip.querySelector(`.cam-thumb[data-index="${index}"]`);
    if (!t) {
      input.setCustomValidity(`No frame ${input.value} yet (frames 0 to ${b.shown.length - 1}).`);
      input.reportValidity();
      return;
    }
    input.setCustomValidity('');
    this.select({ robot, index });
    b.strip.scrollLeft = t.offsetLeft - b.strip.offsetLeft - b.strip.clientWidth / 2;
  }

  /** Called every animation frame; `changed` when the world moved or was
   *  edited, `strain` (0 to 1) how hard the run strains to keep its speed
   *  (web/page/run.js). Returns whether it drew anything. */
  update(nowMs, changed, strain = 0) {
    if (this.stale.length) {
      this.refreshStale(this.stale);
      return true;
    }
    const drew = this.drawPending();
    if (!this.blocks.length || !changed) return drew;
    // One on-screen block per turn, so that each refreshes about every
    // LIVE_INTERVAL_MS and no single frame renders them all.
    // And at most every LIVE_SHARE times what the last refresh took, so that
    // live views take at most a quarter of the time however many are on
    // screen (issue 22: four 16-robot views in turn took a render a frame),
    // and a twelfth when the simulation needs the time to keep its speed.
    const shown = this.blocks.filter((b) => b.visible);
    const share = LIVE_SHARE[0] + strain * (LIVE_SHARE[1] - LIVE_SHARE[0]);
    const gap = Math.max(LIVE_INTERVAL_MS / Math.max(1, shown.length), share * this.liveMs);
    if (!shown.length || nowMs - this.lastLiveMs < gap) return drew;
    this.lastLiveMs = nowMs;
    this.turn = (this.turn + 1) % shown.length;
    const t0 = performance.now();
    this.refreshBlock(shown[this.turn], false);
    this.liveMs = performance.now() - t0;
    return true;
  }

  /** Redraws the live views and grows the strips: every block when
   *  `force` (from the next frame on, those on screen first, within a
   *  frame's budget each), else only those on screen now. */
  refresh(force) {
    const lab = this.hooks.lab();
    this.stale = [];
    if (!lab) return;
    const shown = this.blocks.filter((b) => b.visible);
    if (!force) for (const b of shown) this.refreshBlock(b, false);
    else this.stale = [...shown, ...this.blocks.filter((b) => !b.visible)]; // from the next frame on
  }

  /** Brings `blocks` up to date (a pause, the run's end), in order, until
   *  FINAL_BUDGET_MS is spent, at least one; the rest wait in `stale` for
   *  the next frames (sixteen robots' views and strips at once were most of
   *  a 480 ms task at a pause, tests/bench/page_pause.mjs). */
  refreshStale(blocks) {
    this.stale = spendFrame(blocks, FINAL_BUDGET_MS, (b) => this.refreshBlock(b, true));
  }

  /** Robot `b`'s live view (unless a frame is picked) and strip. */
  refreshBlock(b, force) {
    const lab = this.hooks.lab();
    if (!lab) return;
    try {
      if (b.selected === null) {
        lab.drawCamera(b.robot, b.ctx);
        this.liveDraws[b.robot]++;
      }
      this.syncStrip(lab, b, force);
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  syncStrip(lab, b, force) {
    // While running, a strip grows at most every STRIP_INTERVAL_MS: reading
    // the robot's frame list is linear in its length (issue 22: at 50× two
    // strips re-read hundreds of frames ten times a second).
    const now = performance.now();
    if (!force && now - (b.stripMs ?? -Infinity) < STRIP_INTERVAL_MS) return;
    const count = lab.frameCount(b.robot);
    if (!force && count === b.shown.length) return;
    b.stripMs = now;
    const metas = lab.frames(b.robot);
    const have = new Set(metas.map((m) => m.index));
    // Frames can vanish (a reset, or thinning at the memory cap).
    if (b.shown.some((k) => !have.has(k))) {
      for (const t of [...b.strip.querySelectorAll('.cam-thumb')]) {
        if (!have.has(Number(t.dataset.index))) t.remove();
      }
      b.shown = b.shown.filter((k) => have.has(k));
      if (b.selected !== null && !have.has(b.selected)) this.select({ robot: b.robot, index: null });
    }
    const shown = new Set(b.shown);
    // Thumbnails are rendered at their own size, not drawn full size and
    // scaled down (issue 22: the strip's frames were most of the camera cost).
    const tw = Math.min(THUMB_W, this.camera.width);
    const th = Math.max(1, Math.round((tw * this.camera.height) / this.camera.width));
    const atEnd = b.strip.scrollLeft + b.strip.clientWidth >= b.strip.scrollWidth - 4;
    // A strip at its end scrolls on to show its newest frames: those it
    // shows are drawn now (no blank flashes), the others once scrolled to.
    const fresh = metas.filter((m) => !shown.has(m.index));
    const drawNow = atEnd ? Math.ceil(b.strip.clientWidth / tw) + 1 : 0;
    fresh.forEach((m, k) => {
      const t = document.createElement('canvas');
      t.className = 'cam-thumb';
      t.width = tw;
      t.height = th;
      t.dataset.robot = String(b.robot);
      t.dataset.index = String(m.index);
      if (this.thumbSeen && k < fresh.length - drawNow) this.thumbSeen.observe(t);
      else lab.drawFrameThumb(b.robot, m.index, tw, t.getContext('2d'));
      t.tabIndex = -1;
      t.setAttribute('role', 'option');
      t.setAttribute('aria-selected', 'false');
      t.setAttribute('aria-label', `frame ${m.index} at ${m.time_s.toFixed(0)} s`);
      t.title = `frame ${m.index} · t = ${m.time_s.toFixed(1)} s — click to view it and see where it was taken`;
      const pick = () => this.select({ robot: b.robot, index: m.index });
      t.addEventListener('click', pick);
      t.addEventListener('keydown', (e) => {
        if (e.key === 'Enter' || e.key === ' ') {
          e.preventDefault();
          e.stopPropagation();
          pick();
        }
      });
      b.strip.append(t);
      b.shown.push(m.index);
    });
    b.empty.hidden = b.shown.length > 0;
    b.strip.dataset.frames = String(b.shown.length);
    b.goto.hidden = b.shown.length === 0;
    b.goto.max = String(Math.max(0, ...b.shown));
    this.rove(b);
    if (atEnd) b.strip.scrollLeft = b.strip.scrollWidth;
  }

  /** Draws thumbnails that came on screen, newest first, for up to
   *  THUMB_SLICE_MS (at least one); the rest wait for the next frame. */
  drawPending() {
    if (!this.pending.size) return false;
    const lab = this.hooks.lab();
    if (!lab) return false;
    const t0 = performance.now();
    const order = [...this.pending].sort((a, b) => b[1][1] - a[1][1]);
    for (const [t, [robot, index]] of order) {
      this.pending.delete(t);
      if (!t.isConnected) continue;
      try {
        lab.drawFrameThumb(robot, index, t.width, t.getContext('2d'));
      } catch {
        // The frame was thinned away since: the next strip update removes it.
      }
      if (performance.now() - t0 >= THUMB_SLICE_MS) break;
    }
    return true;
  }
}
