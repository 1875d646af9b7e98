// Drawing the joined maps in the first map's frame (the merged overlay),
// every map in its colour. This runs in the merge worker, into the page's
// overlay canvas handed over with transferControlToOffscreen, so the page's
// main thread does no drawing of large pictures at all.
//
// Frames, as in ROS: a map's YAML `origin` is the pose of its image's
// lower-left corner in the map's frame; the merge gives each joined map's
// frame as a pose in the first map's frame. So an image pixel (u, v) (v
// down from the top row) lands in the first map's frame at
//   pose ∘ origin ∘ (u · r, (h − v) · r)
// which is three canvas transforms after the view's own (metres to
// pixels, y up). The maps are multiplied onto white, so walls of two maps
// that agree show dark and a wall only one map has keeps its colour.

import { clearCanvas } from './fit.js';
import { applyView } from './zoom.js';

/** `a ∘ b` for poses [x, y, theta]. */
export function compose([ax, ay, at], [bx, by, bt]) {
  const c = Math.cos(at), s = Math.sin(at);
  return [ax + c * bx - s * by, ay + s * bx + c * by, at + bt];
}

/**
 * The outline of map `m`'s known cells (the ends of each known row of its
 * picture) in the frame where its map frame is `pose`.
 */
export function outline(m, pose) {
  const [x, y, t] = compose(pose, m.origin);
  const c = Math.cos(t), s = Math.sin(t);
  const { step, rows } = m.preview;
  const r = m.resolution;
  const out = [];
  for (const [row, c0, c1] of rows) {
    const v0 = (m.height - Math.min((row + 1) * step, m.height)) * r, v1 = (m.height - row * step) * r;
    const u0 = c0 * step * r, u1 = Math.min(c1 * step, m.width) * r;
    for (const [u, v] of [[u0, v0], [u1, v0], [u0, v1], [u1, v1]]) out.push([x + c * u - s * v, y + s * u + c * v]);
  }
  return out;
}

/** Draws map `m`'s picture with its map frame at `pose` (view transform set). */
function drawMap(ctx, m, pose) {
  const [x, y, t] = compose(pose, m.origin);
  const r = m.resolution;
  ctx.save();
  ctx.transform(Math.cos(t), Math.sin(t), -Math.sin(t), Math.cos(t), x, y);
  ctx.transform(r, 0, 0, -r, 0, m.height * r);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(m.preview.bitmap, 0, 0, m.width, m.height);
  ctx.restore();
}

/** A scale bar of a round length in the lower-left corner. */
function scaleBar(ctx, k, height, dpr) {
  const want = (120 * dpr) / k;
  const len = [0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500].find((l) => l >= want / 2) ?? 1000;
  const x0 = 12 * dpr, y0 = height - 12 * dpr;
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = 'rgba(255, 255, 255, 0.85)';
  ctx.fillRect(x0 - 4 * dpr, y0 - 20 * dpr, len * k + 8 * dpr, 24 * dpr);
  ctx.strokeStyle = '#222';
  ctx.lineWidth = 2 * dpr;
  ctx.beginPath();
  ctx.moveTo(x0, y0);
  ctx.lineTo(x0 + len * k, y0);
  ctx.stroke();
  ctx.fillStyle = '#222';
  ctx.font = `${12 * dpr}px sans-serif`;
  ctx.fillText(`${len} m`, x0, y0 - 5 * dpr);
}

/**
 * The view that fits `placed` into a `width` x `height` canvas: metres to
 * device pixels, `px = k x + e`, `py = f − k y` (y up). `spare` widens the
 * box on every side by that share of its size (room to drag a map around).
 */
export function fitView(placed, { width, height, dpr }, spare = 0) {
  let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
  for (const { map, pose } of placed) {
    for (const [x, y] of outline(map, pose)) {
      [x0, x1, y0, y1] = [Math.min(x0, x), Math.max(x1, x), Math.min(y0, y), Math.max(y1, y)];
    }
  }
  const mx = spare * (x1 - x0), my = spare * (y1 - y0);
  [x0, x1, y0, y1] = [x0 - mx, x1 + mx, y0 - my, y1 + my];
  const pad = 8 * dpr;
  const k = Math.min((width - 2 * pad) / (x1 - x0 || 1), (height - 2 * pad) / (y1 - y0 || 1));
  const ox = (width - k * (x1 - x0)) / 2, oy = (height - k * (y1 - y0)) / 2;
  return { k, e: ox - k * x0, f: oy + k * y1, width, height, dpr };
}

/**
 * Draws `placed` ([{map, pose}]: maps with their map frame's pose in one
 * common frame) into `canvas` (an OffscreenCanvas of the merge worker,
 * `width` x `height` device pixels, `dpr` of them a CSS pixel); `alpha`
 * the maps' opacity. `view` (from `fitView`) keeps the view still while a
 * map is dragged; without it the maps are fitted in. `zoom` ({k, x, y},
 * zoom.js) is the user's zoom and pan over that view. Returns the view used.
 */
export function drawPlaced(canvas, { width, height, dpr, alpha, zoom = null }, placed, view = null) {
  const ctx = clearCanvas(canvas, width, height, '#fff');
  if (!placed.length) return null;
  const v = view && view.width === width && view.height === height ? view : fitView(placed, { width, height, dpr });
  ctx.setTransform(v.k, 0, 0, -v.k, v.e, v.f);
  const z = applyView(ctx, zoom);
  ctx.globalAlpha = alpha;
  // Multiplied colours: where two maps' walls fall on each other they show dark.
  ctx.globalCompositeOperation = 'multiply';
  for (const { map, pose } of placed) drawMap(ctx, map, pose);
  ctx.globalCompositeOperation = 'source-over';
  ctx.globalAlpha = 1;
  scaleBar(ctx, v.k * z, height, dpr);
  return v;
}
