// Synthetic ROS map_server maps for the page tests: a floor plan made by
// splitting a rectangle into rooms (binary space partition, a door in
// every wall, some slanted walls and pillars, all from a seed), and maps of
// it drawn as a robot's saved map would be: an image frame placed and
// turned anywhere on the plan, walls 0.05 m cells thick, free space where
// the map "saw", unknown elsewhere. The true pose of each map's frame is
// known, so a merge can be checked against it.

/** mulberry32: a small seeded generator (numbers in [0, 1)). */
export function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** A `w` x `h` m floor plan: `{w, h, walls: [[[x, y], [x, y]], ...]}`. */
export function floorPlan(w, h, seed) {
  const r = rng(seed);
  const walls = [[[0, 0], [w, 0]], [[w, 0], [w, h]], [[w, h], [0, h]], [[0, h], [0, 0]]];
  const split = (x0, y0, x1, y1, depth) => {
    const wide = x1 - x0, tall = y1 - y0;
    if (depth > 6 || (wide < 7 && tall < 7)) {
      // A room: sometimes a slanted wall or a pillar makes it unlike the others.
      if (r() < 0.4 && wide > 3 && tall > 3) {
        const ax = x0 + 0.8 + r() * (wide - 1.6), ay = y0 + 0.8 + r() * (tall - 1.6);
        const l = 1 + r() * 1.5, t = r() * Math.PI;
        walls.push([[ax, ay], [ax + l * Math.cos(t), ay + l * Math.sin(t)]].map(([x, y]) => [
          Math.min(x1 - 0.3, Math.max(x0 + 0.3, x)), Math.min(y1 - 0.3, Math.max(y0 + 0.3, y))]));
      }
      if (r() < 0.3 && wide > 3 && tall > 3) {
        const px = x0 + 1 + r() * (wide - 2.4), py = y0 + 1 + r() * (tall - 2.4);
        walls.push([[px, py], [px + 0.4, py]], [[px + 0.4, py], [px + 0.4, py + 0.4]],
          [[px + 0.4, py + 0.4], [px, py + 0.4]], [[px, py + 0.4], [px, py]]);
      }
      return;
    }
    const vertical = wide > tall ? r() < 0.8 : r() < 0.2;
    const f = 0.3 + 0.4 * r();
    if (vertical) {
      const x = x0 + f * wide, door = y0 + 0.3 + r() * (tall - 1.6);
      walls.push([[x, y0], [x, door]], [[x, door + 1], [x, y1]]);
      split(x0, y0, x, y1, depth + 1);
      split(x, y0, x1, y1, depth + 1);
    } else {
      const y = y0 + f * tall, door = x0 + 0.3 + r() * (wide - 1.6);
      walls.push([[x0, y], [door, y]], [[door + 1, y], [x1, y]]);
      split(x0, y0, x1, y, depth + 1);
      split(x0, y, x1, y1, depth + 1);
    }
  };
  split(0, 0, w, h, 0);
  return { w, h, walls };
}

function segDist(px, py, [[ax, ay], [bx, by]]) {
  const dx = bx - ax, dy = by - ay;
  const t = Math.max(0, Math.min(1, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy || 1)));
  return Math.hypot(px - ax - t * dx, py - ay - t * dy);
}

/**
 * A binary PGM of `plan` seen through an image whose lower-left corner is
 * at `frame` [x, y, theta] in the plan: `nx` x `ny` cells of `res` m, free
 * (254) inside the plan where `seen([x, y])`, walls (0) within 0.04 m of a
 * wall, unknown (205) elsewhere.
 */
export function mapImage(plan, frame, nx, ny, seen, res = 0.05) {
  const [fx, fy, ft] = frame, c = Math.cos(ft), s = Math.sin(ft);
  const world = (ix, iy) => {
    const lx = (ix + 0.5) * res, ly = (iy + 0.5) * res;
    return [fx + c * lx - s * ly, fy + s * lx + c * ly];
  };
  const inside = ([x, y]) => x >= 0 && y >= 0 && x <= plan.w && y <= plan.h && seen([x, y]);
  const px = new Uint8Array(nx * ny).fill(205);
  for (let iy = 0; iy < ny; iy++) {
    const row = (ny - 1 - iy) * nx;
    for (let ix = 0; ix < nx; ix++) if (inside(world(ix, iy))) px[row + ix] = 254;
  }
  for (const wall of plan.walls) {
    const [[ax, ay], [bx, by]] = wall;
    const n = Math.ceil(Math.hypot(bx - ax, by - ay) / (res / 3)) + 1;
    for (let k = 0; k <= n; k++) {
      const x = ax + ((bx - ax) * k) / n - fx, y = ay + ((by - ay) * k) / n - fy;
      const ix0 = Math.floor((c * x + s * y) / res), iy0 = Math.floor((-s * x + c * y) / res);
      for (let iy = iy0 - 1; iy <= iy0 + 1; iy++) {
        for (let ix = ix0 - 1; ix <= ix0 + 1; ix++) {
          if (ix < 0 || iy < 0 || ix >= nx || iy >= ny) continue;
          const p = world(ix, iy);
          if (inside(p) && segDist(p[0], p[1], wall) <= 0.04) px[(ny - 1 - iy) * nx + ix] = 0;
        }
      }
    }
  }
  return Buffer.concat([Buffer.from(`P5\n${nx} ${ny}\n255\n`), Buffer.from(px)]);
}

/** A map_server YAML naming `image`, with `origin` [x, y, yaw]. */
export function mapYaml(image, origin = [0, 0, 0], res = 0.05) {
  return `image: ${image}\nresolution: ${res}\norigin: [${origin.join(', ')}]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n`;
}

/** The image frame of an `nx` x `ny` map turned by `theta` with its centre at (cx, cy). */
export function centredFrame(cx, cy, theta, nx, ny, res = 0.05) {
  const hx = (nx * res) / 2, hy = (ny * res) / 2, c = Math.cos(theta), s = Math.sin(theta);
  return [cx - (c * hx - s * hy), cy - (s * hx + c * hy), theta];
}

/**
 * A `w` x `h` m floor plan that is the same turned by 180°: a `w / 2` wide
 * plan (floorPlan) and its copy turned about the middle of the rectangle.
 * Two full maps of it fit each other as well either way round, so the
 * automatic merge declines them as ambiguous.
 */
export function symmetricPlan(w, h, seed) {
  const half = floorPlan(w / 2, h, seed);
  const turn = ([x, y]) => [w - x, h - y];
  return { w, h, walls: [...half.walls, ...half.walls.map(([p, q]) => [turn(p), turn(q)])] };
}
