// The world view: the map canvas. The Lab renders the world with tiny-skia
// straight into the canvas (`lab.draw(ctx)`); this module keeps the view
// (centre, scale, device pixel ratio, layers), tells the Lab what to draw,
// and draws on top what the renderer leaves out: robot names, the
// selected robot's turning handle, the wall being drawn with its length,
// the scale-bar label and grid spacing, the guided mode's markers and a
// one-line hint for the current tool.
//
// It only reads: the store (scenario, selection) and the few facts its
// hooks give (running, editable, the run's state, the tool, the wall being
// drawn). Anyone who changes something it shows calls `invalidate()`, and
// the next animation frame redraws.
import { View, clamp, handlePoint } from './geometry.js';
import { deg, fmt } from './dom.js';
import { darkerColour, robotColour } from './palette.js';

const LAYERS_KEY = 'slamlab.layers.v1';
const LAYER_NAMES = ['grid', 'laser', 'sonar', 'truth_path', 'odometry_path'];

export function metres(m) {
  return m < 1 ? `${Math.round(m * 100)} cm` : `${Number(m.toFixed(2))} m`;
}

export class WorldView {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {import('./state.js').Store} store
   * @param {{running: () => boolean, editable: () => boolean, state: () => any,
   *          readState: () => any, tool: () => string, preview: () => number[] | null,
   *          guided?: () => boolean}} hooks (guided: the guide is open and says what comes next)
   */
  constructor(canvas, store, hooks) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.store = store;
    this.hooks = hooks;
    this.view = new View();
    this.dpr = 1;
    this.sized = false;
    this.autoFit = true; // refit on resize until the user zooms or pans
    this.layers = { grid: true, laser: true, sonar: false, truth_path: true, odometry_path: true };
    this.marker = null; // where the camera frame picked in a film strip was taken
    this.guideMarkers = null; // selected frames the guided mode marks on the map
    this.pickMarkers = []; // the frames picked in the film strips, one per robot at most
    this.dirty = true;
  }

  /** Asks for a redraw on the next animation frame. */
  invalidate() {
    this.dirty = true;
  }

  get lab() {
    return this.store.lab;
  }

  /** The layer switches saved in this browser (a nicety: a bad entry is ignored). */
  restoreLayers() {
    try {
      const saved = JSON.parse(localStorage.getItem(LAYERS_KEY) ?? 'null');
      if (saved && typeof saved === 'object') {
        for (const k of LAYER_NAMES) if (typeof saved[k] === 'boolean') this.layers[k] = saved[k];
      }
    } catch {
      // ignore a bad layers entry
    }
  }

  setLayer(name, on) {
    this.layers[name] = on;
    try {
      localStorage.setItem(LAYERS_KEY, JSON.stringify(this.layers));
    } catch {
      // layers are a nicety
    }
    this.dirty = true;
  }

  resize() {
    const host = this.canvas.parentElement;
    const w = Math.max(1, host.clientWidth);
    const h = Math.max(1, host.clientHeight);
    this.dpr = clamp(window.devicePixelRatio || 1, 1, 2);
    this.canvas.width = Math.min(4096, Math.round(w * this.dpr));
    this.canvas.height = Math.min(4096, Math.round(h * this.dpr));
    this.view.width = w;
    this.view.height = h;
    if ((!this.sized || this.autoFit) && this.lab) {
      this.sized = true;
      this.fit();
    }
    this.dirty = true;
    // Resizing cleared the canvas: draw now rather than show a blank frame.
    if (this.lab && this.store.scenario) this.draw();
  }

  /** Fits the whole scenario into the canvas (and keeps refitting on resize). */
  fit() {
    if (!this.lab) return;
    this.autoFit = true;
    const v = this.view;
    if (this.store.scenario.walls.length === 0) {
      // Nothing to fit: show a 20 x 15 m floor to draw on.
      v.center = [10, 7.5];
      v.scale = Math.min(v.width / 22, v.height / 17);
    } else {
      // Keep a band clear at the top and bottom for the hint and the scale bar.
      const band = Math.round(34 * this.dpr);
      const r = this.lab.fitView(this.canvas.width, Math.max(1, this.canvas.height - 2 * band));
      v.center = r.center;
      v.scale = r.scale / this.dpr;
    }
    this.dirty = true;
  }

  /** Shows the world `points` with 2.5 m around them; null fits the whole scenario. */
  zoomTo(points) {
    if (!points) {
      this.fit();
      return;
    }
    const xs = points.map((p) => p[0]);
    const ys = points.map((p) => p[1]);
    const v = this.view;
    v.center = [(Math.min(...xs) + Math.max(...xs)) / 2, (Math.min(...ys) + Math.max(...ys)) / 2];
    const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) + 5;
    v.scale = clamp(Math.min(v.width, v.height) / span, 2, 2000);
    this.autoFit = false;
    this.dirty = true;
  }

  /** Zooms by `factor` about a canvas point (CSS px); the user took over the view. */
  zoomAt(px, py, factor) {
    this.view.zoomAt(px, py, factor);
    this.autoFit = false;
    this.dirty = true;
  }

  panBy(dx, dy) {
    this.view.panBy(dx, dy);
    this.autoFit = false;
    this.dirty = true;
  }

  pushView() {
    const v = this.view;
    const sel = this.store.selection;
    this.lab.setView({
      width: this.canvas.width,
      height: this.canvas.height,
      center: v.center,
      scale: v.scale * this.dpr,
      layers: this.layers,
      selected_wall: sel && sel.kind === 'wall' ? sel.index : null,
      selected_robot: sel && sel.kind === 'robot' ? sel.index : null,
      preview_wall: this.hooks.preview(),
      marker: this.marker ? this.marker.pose : null,
      marker_fov: this.marker ? (this.marker.fovDeg * Math.PI) / 180 : Math.PI / 3,
    });
  }

  /** Poses to label: live ones while a run exists, else the start poses. */
  robotPoses() {
    const st = this.hooks.state();
    const robots = this.store.scenario.robots;
    if (st && st.robots.length === robots.length && st.steps > 0) return st.robots.map((r) => r.truth);
    return robots.map((r) => r.start);
  }

  /** How far (m) the turning handle sits from the robot. */
  handleReach() {
    return Math.max(0.6, 30 / this.view.scale);
  }

  draw() {
    this.dirty = false;
    if (this.hooks.running()) this.hooks.readState(); // robot labels follow the robots every frame
    this.pushView();
    this.lab.draw(this.ctx);
    this.drawOverlay();
  }

  label(text, x, y, colour, align = 'left') {
    const ctx = this.ctx;
    // Keep labels inside the canvas.
    const w = ctx.measureText(text).width;
    if (align === 'left' && x + w > this.view.width - 4) x = Math.max(4, this.view.width - 4 - w);
    ctx.textAlign = align;
    ctx.lineJoin = 'round';
    ctx.lineWidth = 3;
    ctx.strokeStyle = 'rgba(255,255,255,0.9)';
    ctx.strokeText(text, x, y);
    ctx.fillStyle = colour;
    ctx.fillText(text, x, y);
  }

  /** Text and handles on top of the tiny-skia image (CSS pixels). */
  drawOverlay() {
    const ctx = this.ctx;
    const v = this.view;
    ctx.save();
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.font = '600 12px system-ui, sans-serif';
    ctx.textBaseline = 'alphabetic';
    this.drawProblemWalls();
    this.drawGuideMarkers();
    // Robot names next to the robots.
    const poses = this.robotPoses();
    this.store.scenario.robots.forEach((r, i) => {
      const [px, py] = v.toPx(poses[i]);
      const off = Math.max(10, 0.3 * v.scale);
      this.label(r.name, px + off, py - off, darkerColour(i));
    });
    this.drawHandle();
    // The wall being drawn: its length and direction next to the pointer.
    const preview = this.hooks.preview();
    if (preview) {
      const [x0, y0, x1, y1] = preview;
      const len = Math.hypot(x1 - x0, y1 - y0);
      const ang = deg(Math.atan2(y1 - y0, x1 - x0));
      const [px, py] = v.toPx([x1, y1]);
      this.label(`${fmt(len, 2)} m  ${fmt(ang, 0)}°  (${fmt(x1, 2)}, ${fmt(y1, 2)})`, px + 12, py - 10, '#123a80');
    }
    this.drawScale();
    // A one-line hint for the current tool in the top-left corner.
    const hint = this.hint();
    this.canvas.dataset.hint = hint; // what the canvas says, for the page tests
    if (hint) {
      ctx.font = '12.5px system-ui, sans-serif';
      const w = ctx.measureText(hint).width;
      ctx.fillStyle = 'rgba(255,255,255,0.85)';
      ctx.fillRect(8, 8, w + 14, 22);
      ctx.fillStyle = '#333';
      ctx.textAlign = 'left';
      ctx.fillText(hint, 15, 23);
    }
    ctx.restore();
  }

  /** Walls a robot overlaps (web/page/state.js `problemsInWords`), in red. */
  drawProblemWalls() {
    const walls = this.store.scenario.walls;
    const ctx = this.ctx;
    for (const p of this.store.problems) {
      const w = walls[p.wall];
      if (!w) continue;
      const [ax, ay] = this.view.toPx(w.from);
      const [bx, by] = this.view.toPx(w.to);
      ctx.strokeStyle = 'rgba(214, 20, 20, 0.8)';
      ctx.lineWidth = 7;
      ctx.lineCap = 'round';
      ctx.beginPath();
      ctx.moveTo(ax, ay);
      ctx.lineTo(bx, by);
      ctx.stroke();
    }
    ctx.lineCap = 'butt';
  }

  /** The guided mode's selected frames: a triangle where each kept picture
   *  was taken, pointing along the camera's axis; A', D and E labelled. */
  drawGuideMarkers() {
    const names = this.store.scenario.robots.map((r) => r.name);
    const picks = this.pickMarkers.map((m) => ({ ...m, label: `${names[m.robot] ?? ''} #${m.index}` }));
    const all = [...(this.guideMarkers ?? []), ...(picks.length > 1 ? picks : [])];
    if (!all.length) return;
    const ctx = this.ctx;
    for (const m of all) {
      const [px, py] = this.view.toPx(m.pose);
      const r = m.label ? 10 : 6;
      const [dx, dy] = [Math.cos(m.pose[2]), -Math.sin(m.pose[2])]; // screen y points down
      ctx.beginPath();
      ctx.moveTo(px + dx * r, py + dy * r);
      ctx.lineTo(px - 0.6 * r * (dx + dy), py - 0.6 * r * (dy - dx));
      ctx.lineTo(px - 0.6 * r * (dx - dy), py - 0.6 * r * (dy + dx));
      ctx.closePath();
      ctx.fillStyle = robotColour(m.robot);
      ctx.fill();
      ctx.lineWidth = m.label ? 2 : 1;
      ctx.strokeStyle = m.label ? '#111' : '#fff';
      ctx.stroke();
      if (m.label) {
        // Labels sit away from the middle of the labelled group, so that
        // A', D and E (a few decimetres apart) do not overprint each other.
        const [ox, oy] = m.labelDir ?? [0.7, 0.7];
        ctx.font = '700 13px system-ui, sans-serif';
        this.label(m.label, px + 16 * ox, py - 16 * oy + 4, '#111', ox < -0.3 ? 'right' : ox > 0.3 ? 'left' : 'center');
        ctx.font = '600 12px system-ui, sans-serif';
      }
    }
  }

  /** The turning handle of the selected robot (editing only). */
  drawHandle() {
    const sel = this.store.selection;
    if (!sel || sel.kind !== 'robot' || !this.hooks.editable()) return;
    const pose = this.store.scenario.robots[sel.index]?.start;
    if (!pose) return;
    const ctx = this.ctx;
    const [px, py] = this.view.toPx(pose);
    const [hx, hy] = this.view.toPx(handlePoint(pose, this.handleReach()));
    ctx.strokeStyle = '#b08000';
    ctx.lineWidth = 1.5;
    ctx.setLineDash([4, 3]);
    ctx.beginPath();
    ctx.moveTo(px, py);
    ctx.lineTo(hx, hy);
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = '#ffc800';
    ctx.strokeStyle = '#5a4200';
    ctx.beginPath();
    ctx.arc(hx, hy, 6, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    this.label(`${fmt(deg(pose[2]), 0)}°`, hx + 9, hy + 4, '#5a4200');
  }

  /** The scale-bar label (the bar itself is drawn by the renderer at x = 14,
   *  y = height - 18 device pixels) and the grid spacing beside it. */
  drawScale() {
    const ctx = this.ctx;
    const m = this.lab.viewMetrics();
    const barX = 14 / this.dpr;
    const barY = (this.canvas.height - 18) / this.dpr;
    const barW = m.scale_bar_m * this.view.scale;
    ctx.font = '600 12px system-ui, sans-serif';
    this.label(metres(m.scale_bar_m), barX, barY - 4, '#1e1e1e');
    if (this.layers.grid) {
      ctx.font = '12px system-ui, sans-serif';
      this.label(`grid ${metres(m.grid_m)}`, barX + barW + 10, barY + 6, '#444');
    }
  }

  hint() {
    if (this.hooks.running()) return '';
    const scenario = this.store.scenario;
    const sel = this.store.selection;
    if (!this.hooks.editable()) {
      return this.hooks.state()?.finished
        ? (this.hooks.guided?.() ? 'Run finished: the guide below says what comes next.'
          : scenario.robots.length >= 2 ? 'Run finished: merge the maps (Merge panel), or Reset (R) to run again or edit.'
            : 'Run finished: press Reset (R) to run again or to edit the map.')
        : 'Paused: press Reset (R) to edit the map.';
    }
    if (this.hooks.tool() === 'wall') return 'Wall tool: drag to draw a wall (snaps to 0.1 m and 15°; Alt or Shift: any angle). Esc: back to Select.';
    if (scenario.walls.length === 0) return 'Empty map: press Wall (W) and drag to draw walls.';
    if (sel?.kind === 'robot') return 'Drag the robot to move it; drag the yellow handle (or Shift-drag) to turn it. Delete removes it.';
    if (sel?.kind === 'wall') return 'Drag the wall to move it, or an end to reshape it. Delete removes it.';
    return 'Click a wall or robot to select it; drag to move it. Wall (W) draws walls.';
  }

  /** The whole scenario, fitted into a `w × h` image with the robots' names
   *  (PNG data URL); the on-screen view is restored on the next frame. */
  snapshot(w, h) {
    const c = document.createElement('canvas');
    c.width = w;
    c.height = h;
    const fit = this.lab.fitView(w, h);
    this.lab.setView({
      width: w, height: h, center: fit.center, scale: fit.scale, layers: this.layers,
      selected_wall: null, selected_robot: null, preview_wall: null, marker: null, marker_fov: Math.PI / 3,
    });
    const g = c.getContext('2d');
    this.lab.draw(g);
    const v = new View();
    Object.assign(v, { width: w, height: h, center: fit.center, scale: fit.scale });
    g.font = '600 12px system-ui, sans-serif';
    g.lineJoin = 'round';
    g.fillStyle = '#1e1e1e';
    g.fillText(metres(this.lab.viewMetrics().scale_bar_m), 14, h - 22); // the renderer's scale bar
    const robots = this.store.scenario.robots;
    this.robotPoses().forEach((p, i) => {
      const [px, py] = v.toPx(p);
      g.lineWidth = 3;
      g.strokeStyle = 'rgba(255,255,255,0.9)';
      g.strokeText(robots[i].name, px + 10, py - 10);
      g.fillStyle = darkerColour(i);
      g.fillText(robots[i].name, px + 10, py - 10);
    });
    this.dirty = true; // the next frame pushes the on-screen view back
    return c.toDataURL('image/png');
  }

  /** Client (page) coordinates of a world point, for scripted mouse input. */
  worldToClient(x, y) {
    const r = this.canvas.getBoundingClientRect();
    const [px, py] = this.view.toPx([x, y]);
    return [r.left + px, r.top + py];
  }
}
