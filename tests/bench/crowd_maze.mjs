// The crowded maze of issue 22, as a scenario: a square maze of `cells` x
// `cells` cells of `cellM` metres (20 x 20 of 3 m: 60 x 60 m), carved as a
// perfect maze by a randomised depth-first search, then `open` (a fifth) of
// its remaining inner walls removed, so corridors form loops; `robots`
// robots in distinct random cells, at the cell centre, random heading,
// following the left and right wall in turn. Deterministic: the scenario is
// a function of the options (the seed drives a SplitMix64 stream).
//
//   node tests/bench/crowd_maze.mjs [--robots N] [--duration S] [--seed N]
//        [--cells N] [--cell-m M] [--open F] [--out FILE]
//
// writes the scenario JSON to FILE (stdout without --out). Used by the
// crowd test (tests/crowd.test.mjs) and the scaling table in BENCHMARKS.md.
import { writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

/** SplitMix64 (Steele, Lea and Flood 2014): uniform numbers in [0, 1). */
function splitmix(seed) {
  let s = BigInt.asUintN(64, BigInt(seed) * 0x9e3779b97f4a7c15n + 0x6372_6f77_64n);
  return () => {
    s = BigInt.asUintN(64, s + 0x9e3779b97f4a7c15n);
    let z = s;
    z = BigInt.asUintN(64, (z ^ (z >> 30n)) * 0xbf58476d1ce4e5b9n);
    z = BigInt.asUintN(64, (z ^ (z >> 27n)) * 0x94d049bb133111ebn);
    z ^= z >> 31n;
    return Number(z >> 11n) / 2 ** 53;
  };
}

/** The crowded-maze scenario (an object). */
export function crowdMaze({ cells = 20, cellM = 3, open = 0.2, robots = 16, duration = 3600, seed = 22 } = {}) {
  const rand = splitmix(seed);
  const pick = (n) => Math.floor(rand() * n);
  const n = cells;
  // east[x][y]: the wall between (x, y) and (x + 1, y); north likewise.
  const east = Array.from({ length: n }, () => new Array(n).fill(true));
  const north = Array.from({ length: n }, () => new Array(n).fill(true));
  const seen = Array.from({ length: n }, () => new Array(n).fill(false));
  const stack = [[0, 0]];
  seen[0][0] = true;
  while (stack.length > 0) {
    const [x, y] = stack[stack.length - 1];
    const next = [[x + 1, y], [x - 1, y], [x, y + 1], [x, y - 1]]
      .filter(([a, b]) => a >= 0 && b >= 0 && a < n && b < n && !seen[a][b]);
    if (next.length === 0) {
      stack.pop();
      continue;
    }
    const [a, b] = next[pick(next.length)];
    if (a !== x) east[Math.min(a, x)][y] = false;
    else north[x][Math.min(b, y)] = false;
    seen[a][b] = true;
    stack.push([a, b]);
  }
  // The inner walls left, in a fixed order; open a fraction of them.
  const inner = [];
  for (let x = 0; x < n; x++) {
    for (let y = 0; y < n; y++) {
      if (x + 1 < n && east[x][y]) inner.push(['e', x, y]);
      if (y + 1 < n && north[x][y]) inner.push(['n', x, y]);
    }
  }
  for (let k = inner.length - 1; k > 0; k--) {
    const j = pick(k + 1);
    [inner[k], inner[j]] = [inner[j], inner[k]];
  }
  const opened = Math.round(open * inner.length);
  const kept = inner.slice(opened).sort((p, q) => p[1] - q[1] || p[2] - q[2] || (p[0] < q[0] ? -1 : 1));
  const r3 = (v) => Math.round(v * 1000) / 1000;
  const size = n * cellM;
  const walls = [
    { from: [0, 0], to: [size, 0] },
    { from: [size, 0], to: [size, size] },
    { from: [size, size], to: [0, size] },
    { from: [0, size], to: [0, 0] },
  ];
  for (const [kind, x, y] of kept) {
    const [x0, y0] = [x * cellM, y * cellM];
    walls.push(kind === 'e'
      ? { from: [r3(x0 + cellM), r3(y0)], to: [r3(x0 + cellM), r3(y0 + cellM)] }
      : { from: [r3(x0), r3(y0 + cellM)], to: [r3(x0 + cellM), r3(y0 + cellM)] });
  }
  const taken = new Set();
  const robotList = [];
  for (let i = 0; i < Math.min(robots, n * n); i++) {
    let c = pick(n * n);
    while (taken.has(c)) c = (c + 1) % (n * n);
    taken.add(c);
    const theta = Math.round((rand() * 2 - 1) * Math.PI * 1e4) / 1e4;
    robotList.push({
      name: `robot${i + 1}`,
      start: [r3(((c % n) + 0.5) * cellM), r3((Math.floor(c / n) + 0.5) * cellM), theta],
      follow: i % 2 === 0 ? 'left' : 'right',
    });
  }
  return {
    name: `crowd-${n}x${n}-${robots}r-${duration}s-${seed}`,
    seed,
    duration_s: duration,
    walls,
    robots: robotList,
  };
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  const opt = {};
  let out = null;
  const names = { '--robots': 'robots', '--duration': 'duration', '--seed': 'seed', '--cells': 'cells', '--cell-m': 'cellM', '--open': 'open' };
  for (let k = 0; k < args.length; k += 2) {
    if (args[k] === '--out') out = args[k + 1];
    else if (names[args[k]] && Number.isFinite(Number(args[k + 1]))) opt[names[args[k]]] = Number(args[k + 1]);
    else {
      console.error(`crowd_maze: bad option ${args[k]} ${args[k + 1] ?? ''}`);
      process.exit(2);
    }
  }
  const text = JSON.stringify(crowdMaze(opt)) + '\n';
  if (out) writeFileSync(out, text);
  else process.stdout.write(text);
}
