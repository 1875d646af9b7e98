// Each robot's own map, in its own odometry frame, as it grows.
//
// Two mappers run side by side for every robot (crate/src/slam): the
// thesis's mapping at raw odometry poses, and SLAM, which corrects each pose
// by matching the scan against the map. The switch shows either; the small
// plot shows both robots' position error over time for both mappers (against
// the ground truth, which the mappers never see).
//
// Scoring a map against the truth (`slamFigures`) and drawing it cost a few
// milliseconds per robot; with 16 robots that took over a frame (issue 22).
// So while a run goes the panel refreshes at most every REFRESH_MS and
// only the blocks on screen (an IntersectionObserver tells which); when the
// run pauses, steps or ends, `refresh()` redraws and scores every block, so
// the figures shown are the final ones: from the next frame on, the blocks
// on screen first, as many a frame as FINAL_BUDGET_MS allows (at least
// one) (sixteen robots' maps of a 60 x 60 m maze took one 480 ms task at a
// pause, tests/bench/page_pause.mjs).

import { robotColour } from './palette.js';
import { fitCanvas } from './hidpi.js';
import { spendFrame } from './budget.js';

const REFRESH_MS = 500;
const MAP_W = 300;
const MAP_H = 210;
const PLOT_H = 70;
const FINAL_BUDGET_MS = 16; // a pause's redraw of the blocks, per frame

export class MapsPanel {
  /**
   * @param {HTMLElement} host
   * @param {{lab: () => any, scenario: () => any, onError: (e: unknown) => void,
   *          download: (name: string, data: BlobPart, type: string) => void}} hooks
   */
  constructor(host, hooks) {
    this.host = host;
    this.hooks = hooks;
    this.mapper = 'slam';
    this.key = '';
    this.lastMs = 0;
    this.turn = -1; // the on-screen block refreshed last while running
    this.blocks = [];
    /** Blocks a pause or the run's end left to later frames. */
    this.pending = [];
    /** Maps scored so far (for the page tests: bounded while running). */
    this.scored = 0;
    this.seen = typeof IntersectionObserver === 'undefined' ? null : new IntersectionObserver((entries) => {
      for (const e of entries) {
        const b = this.blocks.find((x) => x.el === e.target);
        if (b) b.visible = e.isIntersecting;
      }
    });
  }

  sync(scenario) {
    const key = JSON.stringify(scenario.robots.map((r) => r.name));
    if (key === this.key) return;
    this.key = key;
    this.host.replaceChildren();
    const bar = document.createElement('div');
    bar.className = 'map-switch';
    bar.setAttribute('role', 'radiogroup');
    bar.setAttribute('aria-label', 'Which map to show');
    for (const [value, text] of [['slam', 'SLAM (scan matching)'], ['odometry', 'odometry only (thesis)']]) {
      const label = document.createElement('label');
      const input = document.createElement('input');
      input.type = 'radio';
      input.name = 'mapper';
      input.value = value;
      input.checked = value === this.mapper;
      input.addEventListener('change', () => {
        this.mapper = value;
        this.refresh(true);
      });
      label.append(input, ` ${text}`);
      bar.append(label);
    }
    const note = document.createElement('p');
    note.className = 'hint';
    note.textContent =
      'Each robot maps in its own frame (its start is the origin). Dark: wall, light: free, grey: unknown; ' +
      'red: where the robot thinks it went, green: where it went.';
    this.empty = document.createElement('p');
    this.empty.className = 'hint';
    this.empty.textContent = 'The maps grow here while the robots run.';
    this.host.append(bar, note, this.empty);
    this.seen?.disconnect();
    this.blocks = scenario.robots.map((r, i) => this.makeBlock(r.name, i));
    this.refresh(true);
  }

  makeBlock(name, i) {
    const el = document.createElement('div');
    el.className = 'map-block';
    el.style.setProperty('--robot', robotColour(i));
    el.hidden = true;
    const title = document.createElement('div');
    title.className = 'map-title';
    title.textContent = `${name}'s map`;
    const canvas = document.createElement('canvas');
    canvas.className = 'map-view';
    canvas.width = MAP_W;
    canvas.height = MAP_H;
    canvas.setAttribute('role', 'img');
    canvas.setAttribute('aria-label', `${name}'s occupancy grid`);
    const figures = document.createElement('div');
    figures.className = 'map-figures';
    const plot = document.createElement('canvas');
    plot.className = 'map-plot';
    plot.width = MAP_W;
    plot.height = PLOT_H;
    plot.setAttribute('role', 'img');
    plot.setAttribute('aria-label', `${name}'s position error over time`);
    const links = document.createElement('div');
    links.className = 'map-links';
    const pgm = document.createElement('button');
    pgm.type = 'button';
    pgm.textContent = 'Download map (PGM + YAML)';
    pgm.addEventListener('click', () => this.downloadPgm(i, name));
    const png = document.createElement('button');
    png.type = 'button';
    png.textContent = 'PNG';
    png.setAttribute('aria-label', `Download ${name}'s map as PNG`);
    png.addEventListener('click', () => this.downloadPng(i, name));
    links.append(pgm, png);
    el.append(title, canvas, figures, plot, links);
    this.host.append(el);
    this.seen?.observe(el);
    return { el, visible: !this.seen, html: '', canvas, figures, plot, robot: i, name };
  }

  /** The position-error plots shown now, for the run summary: `[{name, src}]` (PNG data URLs). */
  plots() {
    const lab = this.hooks.lab();
    for (const b of this.pending.splice(0)) if (lab) this.drawBlock(lab, b);
    return this.blocks.filter((b) => !b.el.hidden).map((b) => ({ name: b.name, src: b.plot.toDataURL('image/png') }));
  }

  /** Called every animation frame while nothing else drew in it; one
   *  on-screen block a turn, so that each is refreshed about every
   *  REFRESH_MS and no frame draws and scores them all (issue 22: two
   *  blocks of a 16-robot run took 70 ms in one frame). */
  update(nowMs, changed) {
    if (this.pending.length) {
      this.drawAll(this.pending);
      return;
    }
    const shown = this.blocks.filter((b) => b.visible && !b.el.hidden);
    const gap = REFRESH_MS / Math.max(1, shown.length);
    if (!changed || nowMs - this.lastMs < gap) return;
    this.lastMs = nowMs;
    if (!shown.length) {
      this.refresh(false); // the first refresh of a run shows the blocks
      return;
    }
    this.turn = (this.turn + 1) % shown.length;
    this.refresh(false, shown[this.turn]);
  }

  /** Redraws every map, figure and plot: called when a run finishes,
   *  pauses or steps, so the panel shows the final state, not the one of
   *  up to REFRESH_MS ago — from the next frame on, the blocks on screen
   *  first, within FINAL_BUDGET_MS a frame. `all === false` (while running):
   *  only the blocks on screen, or only block `only`. */
  refresh(all = true, only = null) {
    const lab = this.hooks.lab();
    this.pending = [];
    if (!lab || !this.blocks.length) return;
    const started = lab.timeS() > 0;
    this.empty.hidden = started;
    for (const b of this.blocks) b.el.hidden = !started;
    if (!started) return;
    if (!all) {
      for (const b of this.blocks) if (b.visible && (!only || b === only)) this.drawBlock(lab, b);
      return;
    }
    // From the next frame on (the one that paused or ended the run has its
    // own work), on screen first, within the budget a frame.
    this.pending = [...this.blocks.filter((b) => b.visible), ...this.blocks.filter((b) => !b.visible)];
  }

  /** Draws `blocks` in order until FINAL_BUDGET_MS is spent (at least one);
   *  the rest wait in `pending` for the next frame's `update`. */
  drawAll(blocks) {
    const lab = this.hooks.lab();
    this.pending = lab ? spendFrame(blocks, FINAL_BUDGET_MS, (b) => this.drawBlock(lab, b)) : [];
  }

  /** Robot `b`'s map, figures and plot at the lab's state now. */
  drawBlock(lab, b) {
    try {
      const ctx = fitCanvas(b.canvas, MAP_W, MAP_H);
      lab.drawMap(ctx, b.robot, this.mapper, b.canvas.width, b.canvas.height);
      const f = lab.slamFigures(b.robot);
      this.scored++;
      const pct = (x) => `${(100 * x).toFixed(0)} %`;
      const html =
        `<span>position error (ATE): <b>SLAM ${f.ate_m.toFixed(2)} m</b> · odometry ${f.odometry_ate_m.toFixed(2)} m</span>` +
        `<span>cells on a real wall: SLAM ${pct(f.occupied_precision)} · odometry ${pct(f.odometry_occupied_precision)}</span>` +
        `<span title="Share of the building's walls (their length) that the map shows">` +
        `walls mapped: SLAM ${pct(f.wall_coverage)} · odometry ${pct(f.odometry_wall_coverage)}</span>`;
      if (html !== b.html) b.figures.innerHTML = b.html = html;
      const rows = lab.slamErrors(b.robot, 150).rows;
      // The series is sampled every few steps: end it at the last step.
      const t = lab.timeS();
      if (rows.length && rows[rows.length - 1][0] < t - 1e-9) rows.push([t, f.final_error_m, f.odometry_final_error_m]);
      this.plot(b, rows);
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  /** Position error over time: SLAM solid, odometry dashed. */
  plot(b, rows) {
    const c = fitCanvas(b.plot, MAP_W, PLOT_H);
    const [w, h] = [MAP_W, PLOT_H];
    c.clearRect(0, 0, w, h);
    c.fillStyle = '#fff';
    c.fillRect(0, 0, w, h);
    const last = rows[rows.length - 1];
    b.plot.dataset.last = last ? JSON.stringify(last) : '';
    if (rows.length < 2) return;
    const tMax = rows[rows.length - 1][0] || 1;
    const eMax = Math.max(0.1, ...rows.map((r) => Math.max(r[1], r[2])));
    const x = (t) => 30 + ((w - 36) * t) / tMax;
    const y = (e) => h - 12 - ((h - 20) * e) / eMax;
    c.strokeStyle = '#ccc';
    c.beginPath();
    c.moveTo(30, y(0));
    c.lineTo(w - 6, y(0));
    c.stroke();
    c.fillStyle = '#555';
    c.font = '10px sans-serif';
    c.fillText(`${eMax.toFixed(1)} m`, 0, 10);
    c.fillText('0', 18, y(0) + 3);
    c.fillText(`${tMax.toFixed(0)} s`, w - 30, h - 1);
    for (const [k, dash] of [[2, [4, 3]], [1, []]]) {
      c.setLineDash(dash);
      c.strokeStyle = k === 1 ? '#c0392b' : '#7f6a5a';
      c.beginPath();
      rows.forEach((r, i) => (i ? c.lineTo(x(r[0]), y(r[k])) : c.moveTo(x(r[0]), y(r[k]))));
      c.stroke();
    }
    c.setLineDash([]);
    // Legend with line samples, and what is plotted (right-aligned).
    for (const [x0, colour, dash, text] of [[40, '#c0392b', [], 'SLAM'], [92, '#7f6a5a', [4, 3], 'odometry']]) {
      c.strokeStyle = colour;
      c.setLineDash(dash);
      c.beginPath();
      c.moveTo(x0, 7);
      c.lineTo(x0 + 14, 7);
      c.stroke();
      c.fillStyle = colour;
      c.fillText(text, x0 + 17, 10);
    }
    c.setLineDash([]);
    c.fillStyle = '#555';
    c.textAlign = 'right';
    c.fillText('position error over time', w - 4, 10);
    c.textAlign = 'left';
  }

  downloadPgm(i, name) {
    const lab = this.hooks.lab();
    try {
      const base = `${name.replace(/[^\w.-]+/g, '_')}_${this.mapper}`;
      this.hooks.download(`${base}.pgm`, lab.mapPgm(i, this.mapper), 'image/x-portable-graymap');
      this.hooks.download(`${base}.yaml`, lab.mapYaml(i, this.mapper, `${base}.pgm`), 'text/yaml');
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  downloadPng(i, name) {
    const lab = this.hooks.lab();
    try {
      const base = `${name.replace(/[^\w.-]+/g, '_')}_${this.mapper}`;
      this.hooks.download(`${base}.png`, lab.mapPng(i, this.mapper), 'image/png');
    } catch (e) {
      this.hooks.onError(e);
    }
  }
}
