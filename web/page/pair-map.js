// Where the two frames of a pair were taken: a small map of the world's
// walls inside the pair view (web/page/pair-view.js), with each frame's
// camera marked in its robot's colour: a dot where the robot stood, its
// name and frame number ("robot1 #143", placed where it covers no other
// label and no dot), and the camera's view cone cut
// off at the walls it saw, whose visible stretch is drawn thick. A student
// who compares two look-alike frames then sees at a glance whether they
// show the same wall (a true match) or two different walls that only look
// the same (the false match of exercise 5).
//
// The cone is a small visibility fan: rays every degree or so across the
// camera's horizontal field of view, each stopped at the nearest wall it
// crosses (the ray–segment intersection, solved for the ray's length t and
// the wall's parameter u in [0, 1]). The poses are the ground truth the
// page shows for display; no estimate uses them.
//
// The canvas is drawn at the device pixel ratio (web/page/hidpi.js). Its
// world-to-canvas mapping is left on the canvas as `data-view`
// ("x0,y0,scale": logical px = (x − x0)·scale, (y0 − y)·scale) so that a
// test can find the marks from the poses, and the labels' boxes as
// `data-labels` (JSON `[[x, y, w, h]]`, logical px) so that it can check
// they stay apart.
import { fitCanvas } from './hidpi.js';
import { darkerColour, robotColour } from './palette.js';

const PAD_PX = 10;
const DOT_PX = 5;
const RAYS = 48;

/** Length along the ray (px, py) + t·(dx, dy) to the nearest wall, at most `far`. */
function castRay(walls, px, py, dx, dy, far) {
  let best = far;
  for (const { from: [ax, ay], to: [bx, by] } of walls) {
    const ex = bx - ax;
    const ey = by - ay;
    const den = dx * ey - dy * ex;
    if (Math.abs(den) < 1e-12) continue; // parallel
    const wx = ax - px;
    const wy = ay - py;
    const t = (wx * ey - wy * ex) / den;
    const u = (wx * dy - wy * dx) / den;
    if (t > 1e-6 && t < best && u >= 0 && u <= 1) best = t;
  }
  return best;
}

/** The world's bounding box over the walls and the marked poses, `[xmin, ymin, xmax, ymax]`. */
function bounds(walls, marks) {
  const xs = [...walls.flatMap((w) => [w.from[0], w.to[0]]), ...marks.map((m) => m.pose[0])];
  const ys = [...walls.flatMap((w) => [w.from[1], w.to[1]]), ...marks.map((m) => m.pose[1])];
  return [Math.min(...xs), Math.min(...ys), Math.max(...xs), Math.max(...ys)];
}

/** The fan's end points (world m) of a camera at `pose` with field of view `hfov` (rad). */
function viewFan(walls, pose, hfov, far) {
  const [x, y, th] = pose;
  const pts = [];
  for (let k = 0; k <= RAYS; k++) {
    const a = th - hfov / 2 + (hfov * k) / RAYS;
    const t = castRay(walls, x, y, Math.cos(a), Math.sin(a), far);
    pts.push([x + t * Math.cos(a), y + t * Math.sin(a), t < far]);
  }
  return pts;
}

/**
 * Draws the walls and `marks` (`{robot, name, frame, pose: [x, y, θ]}`,
 * robot = the robot's index for its colour) on `canvas`, `logicalW` wide,
 * with a camera field of view of `hfovDeg`. The height follows the world's
 * shape. Returns the mapping `{x0, y0, scale}`.
 */
export function drawPairMap(canvas, walls, marks, hfovDeg, logicalW) {
  const [xmin, ymin, xmax, ymax] = bounds(walls, marks);
  const spanX = Math.max(xmax - xmin, 1);
  const spanY = Math.max(ymax - ymin, 1);
  // as wide as the canvas, but no taller than it is wide (a long corridor is centred)
  const scale = Math.min((logicalW - 2 * PAD_PX) / spanX, (logicalW - 2 * PAD_PX) / spanY);
  const logicalH = Math.round(spanY * scale + 2 * PAD_PX);
  canvas.style.aspectRatio = `${logicalW} / ${logicalH}`;
  const ctx = fitCanvas(canvas, logicalW, logicalH);
  const x0 = xmin - (logicalW - spanX * scale) / 2 / scale;
  const y0 = ymax + PAD_PX / scale;
  const px = (x) => (x - x0) * scale;
  const py = (y) => (y0 - y) * scale;
  canvas.dataset.view = [x0, y0, scale].join(',');

  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, logicalW, logicalH);
  ctx.strokeStyle = '#555';
  ctx.lineWidth = 1.5;
  ctx.lineCap = 'round';
  for (const w of walls) {
    ctx.beginPath();
    ctx.moveTo(px(w.from[0]), py(w.from[1]));
    ctx.lineTo(px(w.to[0]), py(w.to[1]));
    ctx.stroke();
  }

  const far = Math.hypot(spanX, spanY);
  const hfov = (hfovDeg * Math.PI) / 180;
  for (const m of marks) {
    const fan = viewFan(walls, m.pose, hfov, far);
    ctx.fillStyle = robotColour(m.robot, 0.22);
    ctx.beginPath();
    ctx.moveTo(px(m.pose[0]), py(m.pose[1]));
    for (const [x, y] of fan) ctx.lineTo(px(x), py(y));
    ctx.closePath();
    ctx.fill();
    // the stretch of wall the camera saw, thick
    ctx.strokeStyle = robotColour(m.robot);
    ctx.lineWidth = 4;
    ctx.beginPath();
    fan.forEach(([x, y, hit], k) => {
      if (hit && k > 0 && fan[k - 1][2]) ctx.lineTo(px(x), py(y));
      else ctx.moveTo(px(x), py(y));
    });
    ctx.stroke();
  }
  const dots = marks.map((m) => [px(m.pose[0]), py(m.pose[1])]);
  const labels = placeLabels(ctx, marks, dots, logicalW, logicalH);
  labels.forEach((l, k) => drawLabel(ctx, marks[k], l));
  canvas.dataset.labels = JSON.stringify(labels.map((l) => [l.x, l.y, l.w, l.h].map((v) => Math.round(v * 10) / 10)));
  // the dots last, so that no label covers where a robot stood
  marks.forEach((m, k) => {
    ctx.beginPath();
    ctx.arc(dots[k][0], dots[k][1], DOT_PX, 0, 2 * Math.PI);
    ctx.fillStyle = robotColour(m.robot);
    ctx.fill();
    ctx.lineWidth = 1.5;
    ctx.strokeStyle = '#fff';
    ctx.stroke();
  });
  return { x0, y0, scale };
}

const LABEL_FONT = '600 11px system-ui, sans-serif';
const LABEL_H = 13; // the text's box: 10 px above the baseline, 3 below
const LABEL_ASCENT = 10;

/** How much two boxes `{x, y, w, h}` overlap (area, px²). */
function overlap(a, b) {
  const dx = Math.min(a.x + a.w, b.x + b.w) - Math.max(a.x, b.x);
  const dy = Math.min(a.y + a.h, b.y + b.h) - Math.max(a.y, b.y);
  return dx > 0 && dy > 0 ? dx * dy : 0;
}

/**
 * Where each "robot1 #143" goes: a box beside its dot that covers no other
 * label and no dot, inside the canvas. The first choice is behind the
 * camera (opposite its heading, away from its view cone); when that box is
 * taken, the next free one of eight directions around the dot, then the
 * same twice as far out; if every one is taken, the least covered. Returns
 * one box `{x, y, w, h}` (logical px, top-left corner) per mark.
 */
function placeLabels(ctx, marks, dots, w, h) {
  ctx.font = LABEL_FONT;
  const dotBoxes = dots.map(([x, y]) => ({ x: x - DOT_PX - 1, y: y - DOT_PX - 1, w: 2 * DOT_PX + 2, h: 2 * DOT_PX + 2 }));
  const placed = [];
  marks.forEach((m, k) => {
    const tw = ctx.measureText(`${m.name} #${m.frame}`).width;
    const [x, y] = dots[k];
    // behind the camera first (canvas y grows downwards), then around the dot
    const dirs = [[-Math.cos(m.pose[2]), Math.sin(m.pose[2])]];
    for (let a = 0; a < 8; a++) dirs.push([Math.cos((a * Math.PI) / 4), Math.sin((a * Math.PI) / 4)]);
    let best = null;
    for (const reach of [12, 24]) {
      for (const [bx, by] of dirs) {
        const cx = x + bx * reach;
        const cy = y + by * reach;
        // the box's side towards the dot sits at (cx, cy)
        let lx = bx < -0.3 ? cx - tw : bx > 0.3 ? cx : cx - tw / 2;
        let ly = by > 0.3 ? cy : by < -0.3 ? cy - LABEL_H : cy - LABEL_H / 2;
        lx = Math.min(Math.max(lx, 2), w - tw - 2);
        ly = Math.min(Math.max(ly, 2), h - LABEL_H - 2);
        const box = { x: lx, y: ly, w: tw, h: LABEL_H };
        const covered = [...placed, ...dotBoxes].reduce((s, b) => s + overlap(box, b), 0);
        if (!best || covered < best.covered) best = { box, covered };
        if (covered === 0) break;
      }
      if (best.covered === 0) break;
    }
    placed.push(best.box);
  });
  return placed;
}

/** Draws a mark's "robot1 #143" in its box, in the robot's darker colour on a white halo. */
function drawLabel(ctx, m, box) {
  const text = `${m.name} #${m.frame}`;
  ctx.font = LABEL_FONT;
  ctx.textAlign = 'left';
  ctx.lineWidth = 3;
  ctx.strokeStyle = 'rgba(255,255,255,0.9)';
  ctx.strokeText(text, box.x, box.y + LABEL_ASCENT);
  ctx.fillStyle = darkerColour(m.robot);
  ctx.fillText(text, box.x, box.y + LABEL_ASCENT);
}
