// Where the two frames of a pair were taken: a small map of the world's
// walls inside the pair view (web/page/pair-view.js), with each frame's
// camera marked in its robot's colour: a dot where the robot stood, its
// name and frame number ("robot1 #143"), and the camera's view cone cut
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
// test can find the marks from the poses.
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
  for (const m of marks) drawLabel(ctx, m, px(m.pose[0]), py(m.pose[1]), logicalW, logicalH);
  // the dots last, so that no label covers where a robot stood
  for (const m of marks) {
    ctx.beginPath();
    ctx.arc(px(m.pose[0]), py(m.pose[1]), DOT_PX, 0, 2 * Math.PI);
    ctx.fillStyle = robotColour(m.robot);
    ctx.fill();
    ctx.lineWidth = 1.5;
    ctx.strokeStyle = '#fff';
    ctx.stroke();
  }
  return { x0, y0, scale };
}

/** "robot1 #143" beside the dot, on the side away from the view cone, kept inside the canvas. */
function drawLabel(ctx, m, x, y, w, h) {
  const text = `${m.name} #${m.frame}`;
  ctx.font = '600 11px system-ui, sans-serif';
  const tw = ctx.measureText(text).width;
  // behind the camera: opposite its heading (canvas y grows downwards)
  const bx = -Math.cos(m.pose[2]);
  const by = Math.sin(m.pose[2]);
  let lx = x + bx * 12 + (bx < -0.3 ? -tw : bx > 0.3 ? 0 : -tw / 2);
  let ly = y + by * 12 + (by > 0.3 ? 10 : by < -0.3 ? 0 : 4);
  lx = Math.min(Math.max(lx, 2), w - tw - 2);
  ly = Math.min(Math.max(ly, 11), h - 3);
  ctx.lineWidth = 3;
  ctx.strokeStyle = 'rgba(255,255,255,0.9)';
  ctx.strokeText(text, lx, ly);
  ctx.fillStyle = darkerColour(m.robot);
  ctx.fillText(text, lx, ly);
}
