// Where robots drove together, from the truth in a `run --json` report:
// the check of issue 22 that every pair of robots whose true paths overlap
// by at least 50 m^2 ends up in one merge group. Used by
// tests/crowd.test.mjs and tests/bench/crowd_groups.mjs.

/**
 * The cells (of `cell` m) a robot drove through: within `reach` m of its
 * true path (`[t, x, y, theta]` rows). Where two robots' cells meet is
 * where both drove.
 */
export function footprint(truth, cell = 0.5, reach = 1.5) {
  const cells = new Set();
  const k = Math.ceil(reach / cell);
  let last = null;
  for (const [, x, y] of truth) {
    if (last && Math.hypot(x - last[0], y - last[1]) < cell / 2) continue;
    last = [x, y];
    const [cx, cy] = [Math.floor(x / cell), Math.floor(y / cell)];
    for (let i = -k; i <= k; i++) {
      for (let j = -k; j <= k; j++) {
        const [px, py] = [(cx + i + 0.5) * cell, (cy + j + 0.5) * cell];
        if (Math.hypot(px - x, py - y) <= reach) cells.add(`${cx + i},${cy + j}`);
      }
    }
  }
  return cells;
}

/** Every pair of the report's robots with the area (m^2) both drove. */
export function overlaps(report, cell = 0.5) {
  const names = report.robots.map((x) => x.name);
  const prints = report.robots.map((x) => footprint(x.truth, cell));
  const out = [];
  for (let i = 0; i < names.length; i++) {
    for (let j = i + 1; j < names.length; j++) {
      let shared = 0;
      for (const c of prints[i]) if (prints[j].has(c)) shared += 1;
      out.push({ a: names[i], b: names[j], m2: shared * cell * cell });
    }
  }
  return out;
}
