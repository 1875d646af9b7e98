// Plane geometry for the editor: the view transform (world metres <-> canvas
// pixels), snapping, and hit tests against walls and robot bodies.
//
// Conventions as in the Rust core: metres and radians, world x right, y up,
// theta counter-clockwise from +x. Only the view flips y:
//   pixel = ((x - cx) * scale + W/2,  H/2 - (y - cy) * scale)
// Pixels here are CSS pixels; the page multiplies by devicePixelRatio when it
// hands the view to the renderer.

/** P2DX body (m), centred on the pose: the renderer draws the same box. */
export const BODY_LENGTH_M = 0.455;
export const BODY_WIDTH_M = 0.381;

/** Grid the editor snaps to (m) and the angle step for walls and headings. */
export const SNAP_M = 0.1;
export const SNAP_ANGLE_RAD = Math.PI / 12; // 15 degrees

/** A pan/zoom view of the world onto a canvas of `width` x `height` CSS px. */
export class View {
  constructor() {
    this.width = 800;
    this.height = 600;
    this.center = [10, 7.5];
    this.scale = 40; // px per metre
  }

  toPx([x, y]) {
    return [(x - this.center[0]) * this.scale + this.width / 2, this.height / 2 - (y - this.center[1]) * this.scale];
  }

  toWorld([px, py]) {
    return [this.center[0] + (px - this.width / 2) / this.scale, this.center[1] - (py - this.height / 2) / this.scale];
  }

  /** Zooms by `factor`, keeping the world point under pixel (px, py) fixed. */
  zoomAt(px, py, factor) {
    const anchor = this.toWorld([px, py]);
    this.scale = clamp(this.scale * factor, 2, 2000);
    this.center = [anchor[0] - (px - this.width / 2) / this.scale, anchor[1] + (py - this.height / 2) / this.scale];
  }

  /** Moves the view by a pixel delta (content follows the pointer). */
  panBy(dxPx, dyPx) {
    this.center = [this.center[0] - dxPx / this.scale, this.center[1] + dyPx / this.scale];
  }
}

export function clamp(v, lo, hi) {
  return Math.min(hi, Math.max(lo, v));
}

/** Rounds to the 0.1 m grid, without float dust (0.30000000000000004). */
export function snap(v, step = SNAP_M) {
  return Number((Math.round(v / step) * step).toFixed(6));
}

export function snapPoint([x, y]) {
  return [snap(x), snap(y)];
}

/** Wraps an angle to (-pi, pi]. */
export function wrapAngle(a) {
  let r = a % (2 * Math.PI);
  if (r > Math.PI) r -= 2 * Math.PI;
  if (r <= -Math.PI) r += 2 * Math.PI;
  return r;
}

export function snapAngle(a) {
  return wrapAngle(Math.round(a / SNAP_ANGLE_RAD) * SNAP_ANGLE_RAD);
}

/**
 * The end of a wall being drawn from `from` towards the pointer `to`, on the
 * 0.1 m grid. Without `free` the pointer is first projected onto the nearest
 * direction that is a multiple of 15 degrees, so horizontal, vertical and
 * 45-degree walls come out exact and the others within a grid step of it.
 */
export function wallEnd(from, to, free) {
  if (free) return snapPoint(to);
  const dx = to[0] - from[0];
  const dy = to[1] - from[1];
  const a = snapAngle(Math.atan2(dy, dx));
  const along = Math.max(0, dx * Math.cos(a) + dy * Math.sin(a));
  return snapPoint([from[0] + along * Math.cos(a), from[1] + along * Math.sin(a)]);
}

/** Distance from point p to segment ab (m). */
export function distToSegment(p, a, b) {
  const vx = b[0] - a[0];
  const vy = b[1] - a[1];
  const l2 = vx * vx + vy * vy;
  let t = l2 > 0 ? ((p[0] - a[0]) * vx + (p[1] - a[1]) * vy) / l2 : 0;
  t = clamp(t, 0, 1);
  return Math.hypot(p[0] - (a[0] + t * vx), p[1] - (a[1] + t * vy));
}

/** Index of the wall nearest p within `tol` metres, or null. */
export function hitWall(walls, p, tol) {
  let best = null;
  let bestD = tol;
  walls.forEach((w, i) => {
    const d = distToSegment(p, w.from, w.to);
    if (d <= bestD) {
      bestD = d;
      best = i;
    }
  });
  return best;
}

/** Whether p lies on the body of a robot at pose [x, y, theta] (with margin m). */
export function onRobotBody(pose, p, margin = 0) {
  const [x, y, th] = pose;
  const dx = p[0] - x;
  const dy = p[1] - y;
  const c = Math.cos(th);
  const s = Math.sin(th);
  const lx = c * dx + s * dy;
  const ly = -s * dx + c * dy;
  return Math.abs(lx) <= BODY_LENGTH_M / 2 + margin && Math.abs(ly) <= BODY_WIDTH_M / 2 + margin;
}

/** Index of the top-most robot whose body contains p, or null. */
export function hitRobot(poses, p, margin) {
  for (let i = poses.length - 1; i >= 0; i--) {
    if (onRobotBody(poses[i], p, margin)) return i;
  }
  return null;
}

/** Where the turning handle of a robot sits (world), `reachM` ahead of it. */
export function handlePoint(pose, reachM) {
  return [pose[0] + reachM * Math.cos(pose[2]), pose[1] + reachM * Math.sin(pose[2])];
}
