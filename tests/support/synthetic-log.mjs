// A synthetic CARMEN laser log for the page tests: a robot drives `laps`
// times round a ring corridor (an outer 16 x 10 m wall, an inner block
// with notches, so places along the loop look different), its 181 beams
// cast exactly against the walls, its odometry turned by a small heading
// bias per step so that it drifts and the second lap meets the first one
// displaced — the case a loop closure mends. A second world (a hall with
// pillars) makes a log that shares nothing with the ring, and a third (a
// six-sided room, 'lab') one that shares nothing with either.

/** Wall segments [[x, y], [x, y]] of the ring. */
export const RING = (() => {
  const poly = (pts) => pts.map((p, i) => [p, pts[(i + 1) % pts.length]]);
  return [
    ...poly([[-8, -5], [8, -5], [8, 5], [-8, 5]]),
    ...poly([[-5, -2], [-1, -2], [-1, -2.6], [1, -2.6], [1, -2], [5, -2], [5, 2], [2, 2], [2, 2.5], [-3, 2.5], [-3, 2], [-5, 2]]),
    [[6.6, -5], [6.6, -4.2]], [[-8, 0.3], [-7.3, 0.3]], [[0, 5], [0, 4.3]],
  ];
})();

/** Distance along the ray from `o` in direction `a` to the nearest wall, or `max`. */
export function rayHit(o, a, walls, max) {
  const d = [Math.cos(a), Math.sin(a)];
  let best = max;
  for (const [p, q] of walls) {
    const e = [q[0] - p[0], q[1] - p[1]];
    const w = [p[0] - o[0], p[1] - o[1]];
    const cross = d[0] * e[1] - d[1] * e[0];
    if (Math.abs(cross) < 1e-12) continue;
    const along = (w[0] * e[1] - w[1] * e[0]) / cross;
    const on = (w[0] * d[1] - w[1] * d[0]) / cross;
    if (along > 0 && on >= 0 && on <= 1) best = Math.min(best, along);
  }
  return best;
}

/** The true pose at arc parameter s (one lap = 1): a rounded rectangle path in the corridor. */
function ringPose(s) {
  const u = 2 * Math.PI * (s % 1);
  const x = 6.5 * Math.cos(u), y = 3.5 * Math.sin(u);
  return [x, y, Math.atan2(3.5 * Math.cos(u), -6.5 * Math.sin(u))];
}

/**
 * Another world, nothing like the ring and like itself under no turn: an
 * irregular seven-sided hall (about 17 x 12 m), a square pillar in the
 * middle, two small ones and a short slanted wall, driven round on a
 * circle of 4 m radius.
 */
export const HALL = (() => {
  const poly = (pts) => pts.map((p, i) => [p, pts[(i + 1) % pts.length]]);
  return [
    ...poly([[-6, -6], [7, -6], [9, -1], [5, 6], [-6, 6], [-8, 2], [-8, -3]]),
    ...poly([[-1, -1], [1, -1], [1, 1], [-1, 1]]),
    ...poly([[5.5, 2], [6, 2], [6, 2.5], [5.5, 2.5]]),
    ...poly([[-3, -5.5], [-2.4, -5.5], [-2.4, -4.9], [-3, -4.9]]),
    [[-7.5, 4], [-6, 5.2]],
  ];
})();

function hallPose(s) {
  const u = 2 * Math.PI * (s % 1);
  return [4 * Math.cos(u), 4 * Math.sin(u), u + Math.PI / 2];
}

/**
 * A third world, like neither of the others and like itself under no
 * turn: a six-sided room (13 x 8.5 m) with two slanted corners, a pillar
 * off its middle, a small one in two corners each and a short slanted
 * wall under the ceiling's side, driven round on an ellipse.
 */
export const LAB = (() => {
  const poly = (pts) => pts.map((p, i) => [p, pts[(i + 1) % pts.length]]);
  return [
    ...poly([[-7, -4], [6, -4], [6, 1], [3, 4.5], [-4, 4.5], [-7, 2]]),
    ...poly([[-1, -0.5], [0.2, -0.5], [0.2, 0.5], [-1, 0.5]]),
    ...poly([[4.5, -3], [5, -3], [5, -2.5], [4.5, -2.5]]),
    ...poly([[-6, -3.2], [-5.5, -3.2], [-5.5, -2.7], [-6, -2.7]]),
    [[-2, 3.6], [-0.5, 4.2]],
  ];
})();

function labPose(s) {
  const u = 2 * Math.PI * (s % 1);
  return [-0.5 + 4 * Math.cos(u), 0.2 + 2.5 * Math.sin(u), Math.atan2(2.5 * Math.cos(u), -4 * Math.sin(u))];
}

const WORLDS = { ring: [RING, ringPose], hall: [HALL, hallPose], lab: [LAB, labPose] };

/**
 * The log's text: `laps` laps of `perLap` scans round the ring (`world:
 * 'ring'`) or the hall (`'hall'`), FLASER records (181 beams, 80 m "no
 * return") with ODOM records before them, odometry with a heading bias of
 * `bias` rad per step. Returns `{text, truth}` (`truth[i]`: the true pose
 * of laser record i, in the frame of the odometry's first pose).
 */
export function ringLog({ laps = 2, perLap = 140, bias = 0.004, world = 'ring' } = {}) {
  const [walls, pathPose] = WORLDS[world] ?? WORLDS.ring;
  const out = [`# a ${world} driven round, made by tests/support/synthetic-log.mjs`];
  const truth = [];
  let odo = null;
  let last = null;
  const n = Math.round(laps * perLap);
  for (let i = 0; i <= n; i++) {
    const p = pathPose(i / perLap);
    if (!last) odo = [...p];
    else {
      const c = Math.cos(last[2]), s = Math.sin(last[2]);
      const dx = p[0] - last[0], dy = p[1] - last[1];
      const fwd = c * dx + s * dy, side = -s * dx + c * dy;
      const turn = Math.atan2(Math.sin(p[2] - last[2]), Math.cos(p[2] - last[2])) + bias;
      const oc = Math.cos(odo[2]), os = Math.sin(odo[2]);
      odo = [odo[0] + oc * fwd - os * side, odo[1] + os * fwd + oc * side, odo[2] + turn];
    }
    last = p;
    truth.push(p);
    const ranges = [];
    for (let b = 0; b <= 180; b++) {
      const r = rayHit(p, p[2] + ((b - 90) * Math.PI) / 180, walls, 80);
      ranges.push(r >= 80 ? '80.00' : r.toFixed(3));
    }
    const pose = odo.map((v) => v.toFixed(5)).join(' ');
    const t = (1000 + 0.25 * i).toFixed(3);
    out.push(`ODOM ${pose} 0.4 0 0 ${t} sim ${t}`);
    out.push(`FLASER 181 ${ranges.join(' ')} ${pose} ${pose} ${t} sim ${t}`);
  }
  return { text: out.join('\n') + '\n', truth };
}
