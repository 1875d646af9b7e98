// The position error against a bag's ground truth, as "Your log" shows it
// under the replay (log-panel.js, issue 53): for each robot whose bag has
// ground truth, the distance between its SLAM pose and the true pose at
// each replayed scan (metres), over the time since its bag's first scan
// (seconds), in the robot's colour; and beside the plot each robot's ATE
// (the absolute trajectory error: the root mean square of those distances,
// after the one rigid motion that lays the truth best onto SLAM's path —
// the log worker takes both from the replay, `LogReplay.truth()`). A
// dashed line in the robot's colour marks its ATE on the plot. The plot's
// frame (`plotFrame`) serves the relation errors' plot too
// (relations-view.js).

import { el, fmt } from '../dom.js';

/** A round step for about `n` ticks over `span`. */
function niceStep(span, n) {
  const raw = span / n;
  const p = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((m) => m * p).find((s) => s >= raw) ?? 10 * p;
}

/**
 * Sizes `canvas` to its box in device pixels, clears it and draws a
 * plot's frame for x from 0 to about `xMax` and y from 0 to about `yMax`
 * (both rounded up to a step): grid lines at round steps, their values,
 * the axes' names. Returns `{ctx, dpr, X, Y, left, right, top, bottom}`,
 * `X` and `Y` taking a value to device pixels.
 */
export function plotFrame(canvas, xMax, yMax, xName, yName) {
  const c = canvas;
  const dpr = window.devicePixelRatio || 1;
  const [w, h] = [Math.max(1, Math.round(c.clientWidth * dpr)), Math.max(1, Math.round(c.clientHeight * dpr))];
  if (c.width !== w || c.height !== h) [c.width, c.height] = [w, h];
  const ctx = c.getContext('2d');
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, w, h);
  let [tMax, eMax] = [Math.max(xMax, 1e-9), Math.max(yMax, 1e-9)];
  const [tStep, eStep] = [niceStep(tMax, 6), niceStep(eMax, 3)];
  [tMax, eMax] = [Math.ceil(tMax / tStep) * tStep, Math.ceil(eMax / eStep) * eStep];
  const [left, right, top, bottom] = [58 * dpr, w - 12 * dpr, 10 * dpr, h - 34 * dpr];
  const X = (t) => left + ((right - left) * t) / tMax;
  const Y = (e) => bottom - ((bottom - top) * e) / eMax;
  ctx.font = `${11 * dpr}px sans-serif`;
  ctx.fillStyle = '#555';
  ctx.strokeStyle = '#ddd';
  ctx.lineWidth = dpr;
  ctx.textAlign = 'center';
  for (let t = 0; t <= tMax + 1e-9; t += tStep) {
    ctx.beginPath();
    ctx.moveTo(X(t), top);
    ctx.lineTo(X(t), bottom);
    ctx.stroke();
    ctx.fillText(String(Number(t.toPrecision(6))), X(t), bottom + 13 * dpr);
  }
  ctx.fillText(xName, (left + right) / 2, h - 4 * dpr);
  ctx.textAlign = 'right';
  for (let e = 0; e <= eMax + 1e-12; e += eStep) {
    ctx.beginPath();
    ctx.moveTo(left, Y(e));
    ctx.lineTo(right, Y(e));
    ctx.stroke();
    ctx.fillText(String(Number(e.toPrecision(6))), left - 5 * dpr, Y(e) + 4 * dpr);
  }
  ctx.save();
  ctx.translate(13 * dpr, (top + bottom) / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.textAlign = 'center';
  ctx.fillText(yName, 0, 0);
  ctx.restore();
  ctx.strokeStyle = '#888';
  ctx.strokeRect(left, top, right - left, bottom - top);
  return { ctx, dpr, X, Y, left, right, top, bottom };
}

export class ErrorPlot {
  /** `section`: the plot's box (hidden when no robot has ground truth), holding `canvas` and the `ate` list. */
  constructor(section, canvas, ate) {
    Object.assign(this, { section, canvas, ate });
  }

  /** Draws the robots' errors (`robots` as the log worker describes them, each `truth: {ate_m, errors}` or null). */
  show(robots) {
    const some = robots.filter((r) => r.truth?.errors.length);
    this.section.hidden = !some.length;
    if (!some.length) return;
    this.ate.replaceChildren(
      ...some.map((r) => {
        const e = r.truth.errors;
        return el(
          'li',
          { class: 'real-swatch', style: `--c:${r.colour}` },
          el('b', { text: `${r.name}: ATE ${fmt(r.truth.ate_m, 3)} m` }),
          ` (dashed) over ${e.length / 2} scans; now ${fmt(e[e.length - 1], 3)} m`,
        );
      }),
    );
    this.draw(some);
  }

  draw(robots) {
    // Time from each bag's first scan: the stretches of one bag share it.
    const start = new Map();
    for (const r of robots) start.set(r.log, Math.min(start.get(r.log) ?? Infinity, r.truth.errors[0]));
    let [tMax, eMax] = [1e-9, 1e-9];
    for (const r of robots) {
      const e = r.truth.errors;
      for (let i = 0; i < e.length; i += 2) {
        tMax = Math.max(tMax, e[i] - start.get(r.log));
        eMax = Math.max(eMax, e[i + 1]);
      }
    }
    const { ctx, dpr, X, Y, left, right } = plotFrame(this.canvas, tMax, eMax, 'time since the bag’s first scan (s)', 'position error (m)');
    for (const r of robots) {
      const e = r.truth.errors, t0 = start.get(r.log);
      ctx.strokeStyle = r.colour;
      ctx.lineWidth = 1.5 * dpr;
      ctx.setLineDash([]);
      ctx.beginPath();
      for (let i = 0; i < e.length; i += 2) ctx[i ? 'lineTo' : 'moveTo'](X(e[i] - t0), Y(e[i + 1]));
      ctx.stroke();
      ctx.setLineDash([6 * dpr, 4 * dpr]);
      ctx.lineWidth = dpr;
      ctx.beginPath();
      ctx.moveTo(left, Y(r.truth.ate_m));
      ctx.lineTo(right, Y(r.truth.ate_m));
      ctx.stroke();
    }
    ctx.setLineDash([]);
  }
}
