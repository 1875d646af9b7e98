// The merge's matched-pair table (thesis Table 1): one row per frame of the
// first robot, one column per frame of the second, each checked pair a
// cell coloured by how many of its feature matches agree (web/page/merge-panel.js
// shows it while a merge runs).
//
// Readable at any size: cells are never smaller than MIN_CELL CSS pixels
// (a long run's table scrolls in its box instead of shrinking to dots), the
// canvas is drawn at the screen's pixel density, a legend names every
// colour, and the words under it say how many frames of each robot were
// kept and by which rule, and what a cell counts. By keyboard the
// table is one tab stop: the arrow keys move a cursor from cell to cell
// (Shift: ten at a time; Home/End: the row's ends), Enter opens the pair
// under the cursor, which starts on the best pair.
import { robotColour } from './palette.js';
import { el } from './dom.js';
import { fitCanvas } from './hidpi.js';

const BOX_W = 330; // the panel's width for the table
const MIN_CELL = 7;
const MAX_CELL = 16;
const X0 = 20;
const Y0 = 14;
const UNCHECKED = '#ffffff';
const EMPTY = '#b9b9b9'; // checked, nothing agreed
const BEST = '#e6550d';
const CURSOR = '#111';

/** A number in plain form: 0.5, 15, 0.05. */
const plain = (x) => String(Number(x.toFixed(2)));

/**
 * Why those frames were kept, from the merge's own rule (`lab.mergeSelection()`):
 * the automatic method keeps one per place and heading, the thesis method
 * the frames facing a wall squarely, some distance apart.
 */
export function keptRule(method, rule) {
  if (!rule) return '';
  if (method === 'thesis') {
    return ` (taken facing a wall squarely, sonars 4 and 5 within ${plain(rule.sonar_tolerance_m)} m of each other, ` +
      `at least ${plain(rule.min_separation_m)} m apart)`;
  }
  const m = plain(rule.min_motion_m);
  const d = plain((rule.min_turn_rad * 180) / Math.PI);
  return `: one per ${m} m or ${d}° (a frame taken within ${m} m and ${d}° of one already kept adds little)`;
}

const swatch = (style) => el('span', { class: 'swatch-box', style });

export class MatchTable {
  /** @param {{open: (row: number, col: number) => void, say: (text: string) => void}} hooks */
  constructor(hooks) {
    this.hooks = hooks;
    this.view = null;
    this.rule = null; // the merge's frame selection rule (lab.mergeSelection())
    this.cursor = null; // [row, col] of the keyboard cursor
    this.canvas = el('canvas', {
      id: 'merge-table', class: 'merge-table', width: String(BOX_W), height: '60', tabindex: '0',
      role: 'application', 'aria-roledescription': 'matched-pair table',
      'aria-label': 'Matched-pair table: arrow keys move between frame pairs, Enter opens one',
    });
    this.scroller = el('div', { class: 'merge-table-scroll' }, this.canvas);
    this.legend = el('div', { class: 'merge-legend', id: 'merge-legend' },
      el('span', {}, swatch(`background:${UNCHECKED};border:1px solid #aaa`), ' not checked'),
      el('span', {}, swatch(`background:${EMPTY}`), ' checked, no agreeing matches'),
      el('span', {}, swatch('background:linear-gradient(90deg,hsl(215 70% 88%),hsl(215 70% 35%))'), ' few → many agreeing matches'),
      el('span', {}, swatch(`border:3px solid ${BEST};background:transparent`), ' the best pair'));
    this.hint = el('p', { class: 'hint', id: 'merge-table-hint' });
    this.box = el('div', { class: 'merge-table-box', hidden: '' },
      el('div', { class: 'map-title', text: 'Matched-pair table' }), this.scroller, this.legend, this.hint);
    this.canvas.addEventListener('mousemove', (e) => this.hover(e));
    this.canvas.addEventListener('click', (e) => {
      const c = this.cellAt(e);
      if (!c) return;
      this.cursor = [c.row, c.col];
      this.draw();
      if (c.found) this.hooks.open(c.row, c.col);
    });
    this.canvas.addEventListener('keydown', (e) => this.key(e));
    this.canvas.addEventListener('focus', () => {
      if (!this.cursor) this.cursor = this.best() ?? [0, 0];
      this.draw();
      this.announce(false); // the status line keeps the verdict until a key moves the cursor
    });
    this.canvas.addEventListener('blur', () => this.draw());
  }

  table() {
    return this.view?.tables?.[0] ?? null;
  }

  best() {
    const t = this.table();
    return t?.best ? [t.best[0], t.best[1]] : null;
  }

  /** A new (or grown) merge view; `method` words the hint. */
  show(view) {
    if (view !== this.view && this.view?.tables?.[0]?.pair !== view?.tables?.[0]?.pair) this.cursor = null;
    this.view = view;
    this.draw();
    // Once the table is complete, bring the best pair into the box.
    const best = this.best();
    if (view?.progress?.finished && best && !this.shownBest) {
      this.shownBest = true;
      const g = this.geometry();
      this.scroller.scrollLeft = X0 + best[1] * g.cell - this.scroller.clientWidth / 2;
      this.scroller.scrollTop = Y0 + best[0] * g.cell - this.scroller.clientHeight / 2;
    }
  }

  reset() {
    this.view = null;
    this.rule = null;
    this.cursor = null;
    this.shownBest = false;
  }

  geometry() {
    const t = this.table();
    if (!t) return null;
    const rows = Math.max(1, t.rows);
    const cols = Math.max(1, t.cols);
    const cell = Math.max(MIN_CELL, Math.min(MAX_CELL, Math.floor((BOX_W - X0 - 4) / cols)));
    return { t, rows, cols, cell, w: Math.max(BOX_W, X0 + cols * cell + 4), h: Y0 + rows * cell + 4 };
  }

  draw() {
    const g = this.geometry();
    if (!g) return;
    const { t, rows, cols, cell, w, h } = g;
    this.canvas.style.width = `${w}px`;
    this.canvas.style.height = `${h}px`;
    this.canvas.dataset.cell = String(cell);
    const ctx = fitCanvas(this.canvas, w, h);
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, w, h);
    ctx.strokeStyle = '#aaa';
    ctx.lineWidth = 1;
    ctx.strokeRect(X0 - 0.5, Y0 - 0.5, cols * cell + 1, rows * cell + 1);
    const max = Math.max(1, ...t.cells.map((c) => c[2]));
    for (const [r, c, inl] of t.cells) {
      const v = inl / max;
      ctx.fillStyle = inl === 0 ? EMPTY : `hsl(215 70% ${88 - 53 * v}%)`;
      ctx.fillRect(X0 + c * cell, Y0 + r * cell, cell - 1, cell - 1);
      if (cell >= 14 && inl > 0) {
        ctx.fillStyle = v > 0.55 ? '#fff' : '#123';
        ctx.font = '8px system-ui, sans-serif';
        ctx.textAlign = 'center';
        ctx.fillText(String(inl), X0 + c * cell + cell / 2, Y0 + r * cell + cell / 2 + 3);
      }
    }
    const box = ([r, c], colour, width) => {
      ctx.strokeStyle = colour;
      ctx.lineWidth = width;
      ctx.strokeRect(X0 + c * cell - width / 2 - 1, Y0 + r * cell - width / 2 - 1, cell + width + 1, cell + width + 1);
    };
    if (t.best) box(t.best, BEST, 3);
    if (this.cursor && document.activeElement === this.canvas) box(this.cursor, CURSOR, 2);
    const names = this.view.robots;
    ctx.fillStyle = robotColour(t.a);
    ctx.font = '10px system-ui, sans-serif';
    ctx.textAlign = 'left';
    ctx.save();
    ctx.translate(10, Y0 + 2);
    ctx.rotate(Math.PI / 2);
    ctx.fillText(`${names[t.a].name}\u2019s frames ↓`, 0, 0);
    ctx.restore();
    ctx.fillStyle = robotColour(t.b);
    ctx.fillText(`${names[t.b].name}\u2019s frames →`, X0, 10);
    this.words(g);
  }

  words({ t, rows, cols }) {
    const names = this.view.robots;
    const [ra, rb] = [names[t.a], names[t.b]];
    const extra = this.view.tables.length > 1 ? ` (the first of ${this.view.tables.length} robot pairs)` : '';
    const thesis = this.view.method === 'thesis';
    const counts = thesis
      ? 'the feature matches that fit one homography between the two pictures (MSAC inliers, as in the thesis\u2019s Table 1)'
      : 'the feature matches that agree on one placement of the two maps (each feature is put on its wall ' +
        'with the laser\u2019s distance, then the pairs must agree on one rigid move)';
    const all = rows * cols;
    const checked = t.planned < all
      ? `${t.cells.length} of ${t.planned} pairs checked${extra}: not all ${all}, only each frame\u2019s few partners whose pictures look most alike. `
      : `${t.cells.length} of ${t.planned} pairs checked${extra}. `;
    this.hint.textContent =
      `${ra.name}: ${rows} of ${ra.captured} frames kept, ${rb.name}: ${cols} of ${rb.captured}` +
      `${keptRule(this.view.method, this.rule)}. ${checked}` +
      `A row is one of ${ra.name}\u2019s frames, a column one of ${rb.name}\u2019s; a cell counts ${counts}. ` +
      'Click a cell, or Tab to the table and use the arrow keys and Enter, to see a pair\u2019s matches.';
  }

  cellAt(e) {
    const g = this.geometry();
    if (!g) return null;
    const r = this.canvas.getBoundingClientRect();
    const x = ((e.clientX - r.left) * g.w) / r.width;
    const y = ((e.clientY - r.top) * g.h) / r.height;
    const col = Math.floor((x - X0) / g.cell);
    const row = Math.floor((y - Y0) / g.cell);
    if (row < 0 || col < 0 || row >= g.rows || col >= g.cols) return null;
    return { row, col, found: g.t.cells.find((c) => c[0] === row && c[1] === col) };
  }

  /** "robot1 frame 12 × robot2 frame 40: 23 agreeing matches of 60". */
  describe(row, col) {
    const t = this.table();
    const names = this.view.robots;
    const found = t.cells.find((c) => c[0] === row && c[1] === col);
    const head = `${names[t.a].name} frame ${names[t.a].frames[row]} × ${names[t.b].name} frame ${names[t.b].frames[col]}`;
    return found ? `${head}: ${found[2]} agreeing matches of ${found[3]}` : `${head}: not checked`;
  }

  hover(e) {
    const c = this.cellAt(e);
    this.canvas.title = c ? this.describe(c.row, c.col) : '';
  }

  announce(say = true) {
    if (!this.cursor || !this.table()) return;
    const text = this.describe(...this.cursor);
    this.canvas.setAttribute('aria-label', `Matched-pair table, ${text}. Arrow keys move, Enter opens the pair.`);
    if (say) this.hooks.say(text);
  }

  key(e) {
    const g = this.geometry();
    if (!g) return;
    const [r, c] = this.cursor ?? this.best() ?? [0, 0];
    const n = e.shiftKey ? 10 : 1;
    const moves = {
      ArrowUp: [r - n, c], ArrowDown: [r + n, c], ArrowLeft: [r, c - n], ArrowRight: [r, c + n],
      Home: [r, 0], End: [r, g.cols - 1],
    };
    if (e.key === 'Enter' || e.key === ' ') {
      // Without preventDefault the same Enter would press the Close button
      // that receives the focus when the pair view opens.
      e.preventDefault();
      const found = g.t.cells.find((x) => x[0] === r && x[1] === c);
      if (found) this.hooks.open(r, c);
      else this.hooks.say(`${this.describe(r, c)}: there is nothing to show.`);
      return;
    }
    const to = moves[e.key];
    if (!to) return;
    e.preventDefault();
    e.stopPropagation();
    this.cursor = [Math.max(0, Math.min(g.rows - 1, to[0])), Math.max(0, Math.min(g.cols - 1, to[1]))];
    this.draw();
    this.scrollTo(g);
    this.announce();
  }

  /** Keeps the cursor's cell inside the scrolling box. */
  scrollTo(g) {
    const [r, c] = this.cursor;
    const s = this.scroller;
    const x = X0 + c * g.cell;
    const y = Y0 + r * g.cell;
    if (x < s.scrollLeft + X0) s.scrollLeft = x - X0;
    else if (x + g.cell > s.scrollLeft + s.clientWidth) s.scrollLeft = x + g.cell - s.clientWidth + 4;
    if (y < s.scrollTop + Y0) s.scrollTop = y - Y0;
    else if (y + g.cell > s.scrollTop + s.clientHeight) s.scrollTop = y + g.cell - s.clientHeight + 4;
  }
}
