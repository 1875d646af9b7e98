// A benchmark's relation errors as "Your log" shows them (log-panel.js,
// issue 54), for every robot whose log came with a `.relations` file
// (log-relations.js, in the log worker).
//
// A relation (R. Kümmerle et al., "On measuring the accuracy of SLAM
// algorithms", Autonomous Robots 27(4), 2009) is the pose of one scan seen
// from another, matched by the benchmark's authors and checked by hand.
// SLAM's error on it is how far its two poses of those scans disagree:
// δ = (p₁⁻¹ ⊕ p₂)⁻¹ ⊕ r, translational |δ.xy| (m) and rotational |δ.θ| (°).
// Shown here, as the replay goes (scoring the scans replayed so far) and
// at the end:
//   - per robot, how many relations were matched (both scans replayed) of
//     those in the file, and the mean ± standard deviation (largest) of
//     both errors, as `run-log --relations` reports them; once finished,
//     the relations checked against their own scans and the wheels, as
//     `run-log --check-relations` reports them (a reference has errors
//     too: on FR079 the relations lie further from their scans than the
//     SLAM does);
//   - a plot of each relation's translational error over the run (x: the
//     time of its later scan since the log's first scan), a point a
//     relation in its robot's colour, the mean dashed, the worst ringed
//     and numbered;
//   - the worst relations (the largest translational errors) in a table,
//     numbered as they are drawn on the map (log-draw.js); pointing at a
//     row, or focusing it, draws that relation stronger on the map and on
//     the plot (`onHighlight(robot name, index)`, or `(null)` when left).

import { el, fmt } from '../dom.js';
import { placeLabel, WORST_COLOUR } from './log-draw.js';
import { plotFrame } from './truth-plot.js';

export const RELATIONS_HTML = `
  <div id="log-relations" class="truth-plot" hidden>
    <h2>Relation errors: where SLAM went wrong</h2>
    <p class="real-stage">A relation (Kümmerle et al. 2009) is the pose of one scan seen from another, matched by the
      benchmark's authors and checked by hand. SLAM's error on it is how far its own two poses of those scans disagree:
      δ = (p₁⁻¹ ⊕ p₂)⁻¹ ⊕ r, in metres (translation) and degrees (rotation). Scored on the scans replayed so far.
      The plot: each relation's translational error, a point in its robot's colour (dashed: the mean), at the time of
      its later scan; the five worst are ringed and numbered, as on the map and in the table.</p>
    <ul id="log-rel-figures" class="truth-ate" aria-label="Each robot's relation errors"></ul>
    <div class="truth-row">
      <canvas id="log-rel-plot" aria-label="Each relation's translational error along the run, in its robot's colour"></canvas>
      <table id="log-rel-worst" class="bag-topics rel-worst">
        <caption>The worst relations, numbered as on the map: point at a row (or focus it) to see it there</caption>
        <thead><tr><th>#</th><th>robot</th><th class="num">t1 (s)</th><th class="num">t2 (s)</th><th class="num" title="The later scan's time since the log's first scan, as on the plot">at (s)</th>
          <th class="num">translation (m)</th><th class="num">rotation (°)</th></tr></thead>
        <tbody></tbody>
      </table>
    </div>
  </div>`;

/** A count as a person reads it: 1,172. */
const count = (n) => n.toLocaleString('en');

/** A robot's figures: matched of count, translation and rotation mean ± sd (max). */
function figures(r) {
  const q = r.relations;
  const left = q.count - q.matched;
  let note = '';
  if (!r.finished) note = `so far, on the ${count(r.done)} of ${count(r.total)} scans replayed`;
  else if (left && !r.whole) note = `the other ${count(left)} have a scan outside this stretch (records ${r.from}–${r.to}) and are not scored`;
  else if (!q.matched) note = `no scan of ${r.log} is within 1 ms of its stamps: is it this log's relations file?`;
  else if (left) note = `the other ${count(left)} have a stamp no scan is within 1 ms of`;
  const t = q.trans_m, a = q.rot_deg;
  return el(
    'li',
    {
      class: 'real-swatch',
      style: `--c:${r.colour}`,
      'data-robot': r.name,
      'data-matched': q.matched,
      'data-count': q.count,
      'data-trans-mean': t.mean,
      'data-rot-mean': a.mean,
    },
    el('b', { text: `${r.name}: matched ${count(q.matched)} of ${count(q.count)}` }),
    ` relations of ${q.file}${note ? ` (${note})` : ''}; `,
    el('span', { class: 'rel-trans', text: `translation ${fmt(t.mean, 4)} ± ${fmt(t.sd, 4)} m (max ${fmt(t.max, 4)} m)` }),
    ', ',
    el('span', { class: 'rel-rot', text: `rotation ${fmt(a.mean, 2)} ± ${fmt(a.sd, 2)}° (max ${fmt(a.max, 2)}°)` }),
    ...(q.check ? [el('br'), checked(q.check)] : []),
  );
}

/**
 * The relations checked against their own scans and the wheels (a
 * finished replay): whom the witnesses contradict, how far the relations
 * and this robot each lie from what the scans settle, and the errors
 * against the relations neither contradicts.
 */
function checked(c) {
  const wheels = c.by_odometry ? `; where they pin nothing, the wheel odometry contradicts ${count(c.by_odometry)} more` : '';
  const v = c.relations_vs_scans, o = c.ours_vs_scans;
  return el(
    'span',
    {
      class: 'rel-check',
      'data-settled': c.settled,
      'data-by-scans': c.by_scans,
      'data-by-odometry': c.by_odometry,
      'data-relations-rot': v.rot_deg,
      'data-ours-rot': o.rot_deg,
    },
    `Checked against their own scans: the scans settle ${count(c.settled)} of ${count(c.checked)} relations and contradict ${count(c.by_scans)}${wheels}. ` +
      `Where the scans settle a pose, the relations lie ${fmt(v.trans_m, 4)} m and ${fmt(v.rot_deg, 2)}° from it, this robot ${fmt(o.trans_m, 4)} m and ${fmt(o.rot_deg, 2)}°. ` +
      `Against the ${count(c.uncontradicted)} relations neither contradicts: translation ${fmt(c.trans_m.mean, 4)} ± ${fmt(c.trans_m.sd, 4)} m, rotation ${fmt(c.rot_deg.mean, 2)} ± ${fmt(c.rot_deg.sd, 2)}°.`,
  );
}

export class RelationsView {
  /** `section`: the box (hidden when no robot has relations), holding the figures, the plot and the table. */
  constructor(section, onHighlight) {
    Object.assign(this, { section, onHighlight });
    this.list = section.querySelector('#log-rel-figures');
    this.canvas = section.querySelector('#log-rel-plot');
    this.body = section.querySelector('#log-rel-worst tbody');
    this.robots = [];
    this.hover = null;
    this.rowsKey = '';
    this.listKey = '';
    this.plotKey = '';
  }

  /**
   * Shows the robots' relation errors (`robots` as the log worker
   * describes them, each `relations` or null); what has not changed since
   * (the worker scores a playing replay a few times a second) is left.
   */
  show(robots) {
    const some = robots.filter((r) => r.relations);
    this.robots = some;
    this.section.hidden = !some.length;
    if (!some.length) {
      [this.listKey, this.plotKey, this.rowsKey] = ['', '', ''];
      return;
    }
    const scored = some.map((r) => [r.name, r.colour, r.relations.file, r.relations.matched, r.relations.count, r.relations.trans_m, r.relations.rot_deg]);
    const listKey = JSON.stringify([scored, some.map((r) => [r.done, r.total, r.finished, r.relations.check?.checked ?? null])]);
    if (listKey !== this.listKey) this.list.replaceChildren(...some.map(figures));
    this.listKey = listKey;
    this.table(some);
    const plotKey = JSON.stringify(scored);
    if (plotKey !== this.plotKey) this.draw();
    this.plotKey = plotKey;
  }

  /** The worst relations' rows; made anew only when they change, keeping the row focused. */
  table(robots) {
    const rows = robots.flatMap((r) => r.relations.worst.map((w, k) => ({ r, w, k })));
    const key = JSON.stringify(rows.map(({ r, w }) => [r.name, w.t1, w.t2, w.trans_m, w.rot_deg]));
    if (key === this.rowsKey) return;
    this.rowsKey = key;
    const focused = this.body.contains(document.activeElement) ? [document.activeElement.dataset.robot, document.activeElement.dataset.k] : null;
    this.body.replaceChildren(
      ...rows.map(({ r, w, k }) => {
        const point = () => this.point(r.name, k);
        const leave = () => this.point(null, -1);
        return el(
          'tr',
          { tabindex: 0, 'data-robot': r.name, 'data-k': k, onmouseenter: point, onfocus: point, onmouseleave: leave, onblur: leave },
          el('td', {}, el('span', { class: 'rel-number', style: `background:${WORST_COLOUR}`, text: String(k + 1) })),
          el('td', { class: 'real-swatch', style: `--c:${r.colour}`, text: r.name }),
          el('td', { class: 'num', text: String(w.t1) }),
          el('td', { class: 'num', text: String(w.t2) }),
          el('td', { class: 'num', text: fmt(w.at, 1) }),
          el('td', { class: 'num', text: fmt(w.trans_m, 4) }),
          el('td', { class: 'num', text: fmt(w.rot_deg, 2) }),
        );
      }),
    );
    if (focused) this.body.querySelector(`tr[data-robot="${CSS.escape(focused[0])}"][data-k="${focused[1]}"]`)?.focus();
  }

  /** Points at robot `name`'s worst relation `k` (null: at none), on the plot here and on the map. */
  point(name, k) {
    const next = name === null ? null : { name, k };
    if (JSON.stringify(next) === JSON.stringify(this.hover)) return;
    this.hover = next;
    for (const tr of this.body.children) tr.classList.toggle('on', !!next && tr.dataset.robot === next.name && Number(tr.dataset.k) === next.k);
    this.draw();
    this.onHighlight(name, k);
  }

  /** The plot: each relation's translational error at its later scan's time, a point each; the mean dashed; the worst ringed. */
  draw() {
    const robots = this.robots;
    if (!robots.length || this.section.hidden) return;
    let [tMax, eMax] = [1e-9, 1e-9];
    for (const r of robots) {
      const e = r.relations.errors;
      for (let i = 0; i < e.length; i += 2) [tMax, eMax] = [Math.max(tMax, e[i]), Math.max(eMax, e[i + 1])];
    }
    const { ctx, dpr, X, Y, left, right } = plotFrame(this.canvas, tMax, eMax, 'time of the relation’s later scan since the log’s first scan (s)', 'translational error (m)');
    let drawn = 0;
    for (const r of robots) {
      const e = r.relations.errors;
      ctx.fillStyle = r.colour;
      ctx.globalAlpha = 0.75;
      for (let i = 0; i < e.length; i += 2) {
        ctx.beginPath();
        ctx.arc(X(e[i]), Y(e[i + 1]), 2 * dpr, 0, 2 * Math.PI);
        ctx.fill();
        drawn++;
      }
      ctx.globalAlpha = 1;
      if (r.relations.matched) {
        ctx.strokeStyle = r.colour;
        ctx.lineWidth = dpr;
        ctx.setLineDash([6 * dpr, 4 * dpr]);
        ctx.beginPath();
        ctx.moveTo(left, Y(r.relations.trans_m.mean));
        ctx.lineTo(right, Y(r.relations.trans_m.mean));
        ctx.stroke();
        ctx.setLineDash([]);
      }
    }
    ctx.font = `bold ${11 * dpr}px sans-serif`;
    ctx.textAlign = 'left';
    ctx.textBaseline = 'middle';
    const taken = [];
    for (const r of robots) {
      for (const [k, w] of r.relations.worst.entries()) {
        const strong = this.hover?.name === r.name && this.hover.k === k;
        const [x, y] = [X(w.at), Y(w.trans_m)];
        ctx.strokeStyle = WORST_COLOUR;
        ctx.lineWidth = (strong ? 3 : 1.5) * dpr;
        ctx.beginPath();
        ctx.arc(x, y, (strong ? 8 : 5) * dpr, 0, 2 * Math.PI);
        ctx.stroke();
        const text = String(k + 1);
        const [bx, by, , bh] = placeLabel(taken, x, y + 12 * dpr, ctx.measureText(text).width + 4 * dpr, 13 * dpr, 4 * dpr);
        ctx.fillStyle = WORST_COLOUR;
        ctx.fillText(text, bx + 2 * dpr, by + bh / 2);
        if (by + bh < y - 6 * dpr) {
          ctx.lineWidth = dpr;
          ctx.beginPath();
          ctx.moveTo(x, y);
          ctx.lineTo(bx, by + bh);
          ctx.stroke();
        }
      }
    }
    this.canvas.dataset.points = String(drawn);
  }
}
