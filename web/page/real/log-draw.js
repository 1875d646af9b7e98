// Drawing log replays in the log worker (log-worker.js), one tile a robot:
// the map of the scans so far (walls dark, free space white, unknown left
// grey), the path the odometry believes (dashed grey) beside the path SLAM
// gives (in the robot's colour, moved by every loop closure), a bag's
// ground truth (dotted black: the true poses laid onto SLAM's frame by the
// rigid fit its ATE is taken after), each loop closure as an orange line
// between the two scans it joined, the worst relations of a benchmark's
// relations file (log-relations.js: both scans' current poses ringed with
// their headings, joined by a magenta line, numbered as the page's table
// lists them; the one the user points at drawn stronger, the others
// fainter), and the robot's current pose. A robot's
// poses and map share one frame (the log's odometry frame, the first scan
// at its odometry pose); its tile fits the map's known cells and the
// paths, then the user's view (zoom.js: zoomed and moved, the same for
// every tile) is applied. The user may hide SLAM's path, the odometry's
// and the loop closures (the request's `layers`).

import { clearCanvas, fitBox } from './fit.js';
import { outline } from './overlay.js';
import { applyView } from './zoom.js';

/** The colour of the worst relations (the page's legend uses it too). */
export const WORST_COLOUR = '#e6007e';

/** The live map as a picture: `grey` PGM shades top row first, `info` its MapInfo. */
export async function mapPicture(grey, info) {
  const { width: w, height: h } = info;
  const rgba = new Uint8ClampedArray(w * h * 4);
  let [c0, r0, c1, r1] = [w, h, -1, -1];
  for (let i = 0; i < w * h; i++) {
    const g = grey[i];
    if (g === 205) continue;
    const v = g < 128 ? 34 : 255;
    rgba[i * 4] = v;
    rgba[i * 4 + 1] = v;
    rgba[i * 4 + 2] = v;
    rgba[i * 4 + 3] = 255;
    const col = i % w, row = (i / w) | 0;
    [c0, r0, c1, r1] = [Math.min(c0, col), Math.min(r0, row), Math.max(c1, col), Math.max(r1, row)];
  }
  const bitmap = await createImageBitmap(new ImageData(rgba, w, h));
  const r = info.resolution_m, [ox, oy] = info.origin_m;
  const box = c1 < 0 ? null : [ox + c0 * r, oy + (h - 1 - r1) * r, ox + (c1 + 1) * r, oy + (h - r0) * r];
  return { bitmap, info, box };
}

function path(ctx, flat) {
  ctx.beginPath();
  for (let i = 0; i < flat.length; i += 3) ctx[i ? 'lineTo' : 'moveTo'](flat[i], flat[i + 1]);
  ctx.stroke();
}

/** The world box [x0, y0, x1, y1] to fit: the map's known cells and the paths. */
function bounds(picture, view, truth) {
  const b = picture?.box ? [...picture.box] : [Infinity, Infinity, -Infinity, -Infinity];
  for (const flat of [view.odometry, view.poses, truth?.poses ?? []]) {
    for (let i = 0; i < flat.length; i += 3) {
      b[0] = Math.min(b[0], flat[i] - 1);
      b[1] = Math.min(b[1], flat[i + 1] - 1);
      b[2] = Math.max(b[2], flat[i] + 1);
      b[3] = Math.max(b[3], flat[i + 1] + 1);
    }
  }
  return b;
}

/**
 * Draws one robot's replay into the tile `rect` ([left, top, width,
 * height] device pixels) of `ctx`: `robot.picture`, `robot.view`, its
 * SLAM path in `robot.colour`, its name when `label`; `view`: the user's
 * zoom ({k, x, y}, or null); `layers`: `{slam, odometry, closures}`, false
 * hides one.
 */
function drawRobot(ctx, rect, { dpr, view, layers = {} }, robot, label) {
  const { picture, view: replay, truth } = robot;
  const box = replay ? bounds(picture, replay, truth) : [0, 0, 0, 0];
  if (!(box[2] > box[0])) {
    // Nothing replayed yet: the tile's name only.
    if (label) drawName(ctx, rect, dpr, robot);
    return;
  }
  ctx.save();
  ctx.beginPath();
  ctx.rect(...rect);
  ctx.clip();
  const k = fitBox(ctx, box, rect, 10 * dpr) * applyView(ctx, view);
  if (picture) {
    const { info, bitmap } = picture;
    const r = info.resolution_m;
    ctx.save();
    ctx.transform(r, 0, 0, -r, info.origin_m[0], info.origin_m[1] + info.height * r);
    ctx.imageSmoothingEnabled = k * r < 1;
    ctx.drawImage(bitmap, 0, 0);
    ctx.restore();
  }
  ctx.lineJoin = 'round';
  ctx.lineWidth = (1.5 * dpr) / k;
  ctx.setLineDash([(6 * dpr) / k, (4 * dpr) / k]);
  ctx.strokeStyle = '#7a7a7a';
  if (layers.odometry !== false) path(ctx, replay.odometry);
  if (truth?.poses.length) {
    ctx.setLineDash([0.1 / k, (5 * dpr) / k]);
    ctx.lineCap = 'round';
    ctx.lineWidth = (3 * dpr) / k;
    ctx.strokeStyle = '#111';
    path(ctx, truth.poses);
    ctx.lineCap = 'butt';
  }
  ctx.setLineDash([]);
  ctx.lineWidth = (2 * dpr) / k;
  ctx.strokeStyle = robot.colour;
  if (layers.slam !== false) path(ctx, replay.poses);
  if (layers.closures !== false) drawClosures(ctx, replay.closures, k, dpr);
  if (robot.relations?.worst.length) drawWorst(ctx, replay.poses, robot.relations.worst, robot.highlight ?? -1, k, dpr);
  const n = replay.poses.length;
  if (n) {
    ctx.beginPath();
    ctx.arc(replay.poses[n - 3], replay.poses[n - 2], (5 * dpr) / k, 0, 2 * Math.PI);
    ctx.fillStyle = '#c81414';
    ctx.fill();
  }
  ctx.restore();
  if (label) drawName(ctx, rect, dpr, robot);
}

/** A robot's name in the top left corner of its tile, in its colour. */
function drawName(ctx, rect, dpr, robot) {
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.font = `bold ${13 * dpr}px sans-serif`;
  ctx.fillStyle = robot.colour;
  ctx.fillText(robot.name, rect[0] + 6 * dpr, rect[1] + 16 * dpr);
  ctx.restore();
}

/** Each loop closure: an orange line between the two scans it joined. */
function drawClosures(ctx, closures, k, dpr) {
  ctx.strokeStyle = '#e07b00';
  ctx.fillStyle = '#e07b00';
  ctx.lineWidth = (2.5 * dpr) / k;
  for (const c of closures) {
    const [ax, ay, bx, by] = c.segment;
    ctx.beginPath();
    ctx.moveTo(ax, ay);
    ctx.lineTo(bx, by);
    ctx.stroke();
    for (const [x, y] of [[ax, ay], [bx, by]]) {
      ctx.beginPath();
      ctx.arc(x, y, (3 * dpr) / k, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
}

/**
 * The worst relations (`worst`: [{scan1, scan2}], worst first) on the SLAM
 * poses `poses` (flat): each scan's pose a ring with a tick along its
 * heading, the two joined by a line (a white halo under it, so it shows
 * over walls and paths), numbered from 1 beside the line's middle;
 * `highlight` (an index, or -1) drawn stronger, the others fainter.
 */
function drawWorst(ctx, poses, worst, highlight, k, dpr) {
  const at = (i) => (3 * i + 2 < poses.length ? [poses[3 * i], poses[3 * i + 1], poses[3 * i + 2]] : null);
  const px = (n) => (n * dpr) / k;
  const order = [...worst.keys()].reverse(); // the worst drawn last, on top
  if (highlight >= 0) order.push(...order.splice(order.indexOf(highlight), 1));
  for (const i of order) {
    const [a, b] = [at(worst[i].scan1), at(worst[i].scan2)];
    if (!a || !b) continue;
    const strong = i === highlight;
    ctx.globalAlpha = highlight >= 0 && !strong ? 0.35 : 1;
    const [width, ring] = strong ? [3.5, px(11)] : [2.5, px(7)];
    for (const [colour, w] of [['#fff', width + 3], [WORST_COLOUR, width]]) {
      ctx.strokeStyle = colour;
      ctx.lineWidth = px(w);
      ctx.beginPath();
      ctx.moveTo(a[0], a[1]);
      ctx.lineTo(b[0], b[1]);
      for (const [x, y, th] of [a, b]) {
        ctx.moveTo(x + ring, y);
        ctx.arc(x, y, ring, 0, 2 * Math.PI);
        ctx.moveTo(x, y);
        ctx.lineTo(x + px(14) * Math.cos(th), y + px(14) * Math.sin(th));
      }
      ctx.stroke();
    }
  }
  ctx.globalAlpha = 1;
  // The numbers, the worst placed first, none over another; the one pointed at on top.
  const taken = [];
  const labels = worst.map((w, i) => {
    const [a, b] = [at(w.scan1), at(w.scan2)];
    return a && b ? label(ctx, taken, String(i + 1), (a[0] + b[0]) / 2, (a[1] + b[1]) / 2, dpr, i === highlight) : null;
  });
  for (const i of order) labels[i]?.();
}

/**
 * Where a label `w` × `h` (device pixels) goes beside the point (x, y):
 * above and right of it, moved up (then right) past the labels `taken`
 * ([left, top, w, h] each, the new one added).
 */
export function placeLabel(taken, x, y, w, h, gap) {
  let [left, top] = [x + gap, y - h - gap];
  const hits = (b) => left < b[0] + b[2] + 2 && b[0] < left + w + 2 && top < b[1] + b[3] + 2 && b[1] < top + h + 2;
  for (let tries = 0; taken.some(hits) && tries < 24; tries++) {
    if (tries % 4 === 3) [left, top] = [left + w + 4, y - h - gap];
    else top -= h + 4;
  }
  const box = [left, top, w, h];
  taken.push(box);
  return box;
}

/**
 * Places a number in a magenta box by world point (x, y) (placeLabel,
 * upright whatever the view's transform); returns the drawing of it, with
 * a line to the point when it was moved away.
 */
function label(ctx, taken, text, x, y, dpr, strong) {
  const p = ctx.getTransform().transformPoint(new DOMPoint(x, y));
  ctx.save();
  ctx.font = `bold ${(strong ? 14 : 12) * dpr}px sans-serif`;
  const w = ctx.measureText(text).width + 8 * dpr;
  ctx.restore();
  const h = (strong ? 18 : 16) * dpr;
  const [left, top] = placeLabel(taken, p.x, p.y, w, h, 4 * dpr);
  return () => {
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.strokeStyle = WORST_COLOUR;
    ctx.lineWidth = dpr;
    ctx.beginPath();
    ctx.moveTo(p.x, p.y);
    ctx.lineTo(left, top + h);
    ctx.stroke();
    ctx.fillStyle = WORST_COLOUR;
    ctx.fillRect(left, top, w, h);
    ctx.fillStyle = '#fff';
    ctx.font = `bold ${(strong ? 14 : 12) * dpr}px sans-serif`;
    ctx.textBaseline = 'middle';
    ctx.fillText(text, left + 4 * dpr, top + h / 2 + dpr / 2);
    ctx.restore();
  };
}

/**
 * Draws the robots' replays into `canvas` (`size`: {width, height, dpr} in
 * device pixels): one robot fills it; several share it in a grid of tiles,
 * each in its own frame (they are not joined until the merge), named.
 */
export function drawReplays(canvas, size, robots) {
  const { width, height, dpr } = size;
  const ctx = clearCanvas(canvas, width, height, '#e6e6e1');
  const n = robots.length;
  if (!n) return;
  const across = Math.min(n, Math.max(1, Math.round(Math.sqrt((n * width) / Math.max(1, height)))));
  const down = Math.ceil(n / across);
  const [w, h] = [width / across, height / down];
  ctx.strokeStyle = '#fff';
  ctx.lineWidth = 2 * dpr;
  for (const [i, robot] of robots.entries()) {
    const rect = [(i % across) * w, Math.floor(i / across) * h, w, h];
    if (n > 1) ctx.strokeRect(...rect);
    drawRobot(ctx, rect, size, robot, n > 1);
  }
}

/**
 * Draws `paths` ([{colour, flat}], log-merge.js's `mergedPaths`) over the
 * merged maps that overlay.js's `drawPlaced` drew into `canvas`: the same
 * box (the joined maps' known cells) fitted the same way, and the same
 * `zoom`, so the paths fall on their maps; each path in its robot's
 * colour, its start a dot.
 */
export function drawMergedPaths(canvas, { width, height, dpr, zoom = null }, placed, paths) {
  if (!placed.length) return;
  const b = [Infinity, Infinity, -Infinity, -Infinity];
  for (const { map, pose } of placed) {
    for (const [x, y] of outline(map, pose)) {
      [b[0], b[1], b[2], b[3]] = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
    }
  }
  const ctx = canvas.getContext('2d');
  ctx.save();
  const k = fitBox(ctx, b, [0, 0, width, height], 8 * dpr) * applyView(ctx, zoom);
  ctx.lineJoin = 'round';
  ctx.lineWidth = (2 * dpr) / k;
  for (const { colour, flat } of paths) {
    ctx.strokeStyle = colour;
    path(ctx, flat);
    ctx.beginPath();
    ctx.arc(flat[0], flat[1], (4 * dpr) / k, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
  }
  ctx.restore();
}
