// End-to-end tests of `node web/cli.mjs merge-maps` (web/cli/merge-maps.mjs)
// on small ROS map_server maps drawn here: exit codes and messages for bad
// input, the JSON report's shape, a merge of two maps cut from one floor
// plan with a known transform, a refusal of two different floor plans,
// and --out. Run by ./build.sh test after ./build.sh build.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync, existsSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { runCli, tempDir } from './support/cli.mjs';

const tmp = tempDir('maps');

const run = (...args) => runCli('merge-maps', ...args);

/** Distance from point p to segment [a, b]. */
function segDist([px, py], [[ax, ay], [bx, by]]) {
  const dx = bx - ax, dy = by - ay;
  const t = Math.max(0, Math.min(1, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)));
  return Math.hypot(px - ax - t * dx, py - ay - t * dy);
}

/** A floor plan 24 x 16 m: rooms off a corridor, a slanted wall, pillars. */
function plan(variant) {
  const w = variant ? 22 : 24, h = variant ? 15 : 16;
  const walls = [[[0, 0], [w, 0]], [[w, 0], [w, h]], [[w, h], [0, h]], [[0, h], [0, 0]],
    [[0, 6], [2, 6]], [[3, 6], [9, 6]], [[10, 6], [w, 6]], [[0, 8.5], [5, 8.5]], [[6, 8.5], [w, 8.5]]];
  const below = variant ? [4, 11, 17] : [4.2, 10.1, 13.3, 19.6];
  const above = variant ? [5, 12, 18] : [6.5, 8.2, 14.9, 21.1];
  for (const x of below) walls.push([[x, 0], [x, 6]]);
  for (const x of above) walls.push([[x, 8.5], [x, h]]);
  walls.push(variant ? [[3, 11], [8, 13]] : [[12, 10], [14.5, 12.5]]);
  if (!variant) walls.push([[1, 10], [3.5, 14]], [[20, 2], [22.5, 4.5]], [[16.5, 13], [18.5, 15.2]]);
  for (const [x, y] of variant ? [[2, 2], [14, 3]] : [[7, 2], [12.5, 3.5], [21, 1.5]]) {
    walls.push([[x, y], [x + 0.4, y]], [[x + 0.4, y], [x + 0.4, y + 0.4]], [[x + 0.4, y + 0.4], [x, y + 0.4]], [[x, y + 0.4], [x, y]]);
  }
  return { w, h, walls };
}

/** Writes a map of `fp` whose image's lower-left corner is at pose
 *  `frame` [x, y, theta] in the plan, `nx` x `ny` cells of 0.05 m, showing
 *  what `seen(x, y)` allows; YAML origin `origin`. Returns the YAML path. */
function writeMap(name, fp, frame, nx, ny, seen, origin = [0, 0, 0], ext = 'pgm') {
  const r = 0.05, [fx, fy, ft] = frame, c = Math.cos(ft), s = Math.sin(ft);
  const px = Buffer.alloc(nx * ny, 205);
  for (let row = 0; row < ny; row++) {
    const iy = ny - 1 - row;
    for (let ix = 0; ix < nx; ix++) {
      const lx = (ix + 0.5) * r, ly = (iy + 0.5) * r;
      const p = [fx + c * lx - s * ly, fy + s * lx + c * ly];
      if (p[0] < -0.1 || p[1] < -0.1 || p[0] > fp.w + 0.1 || p[1] > fp.h + 0.1 || !seen(p)) continue;
      px[row * nx + ix] = fp.walls.some((wl) => segDist(p, wl) <= 0.04) ? 0 : 254;
    }
  }
  writeFileSync(path.join(tmp, `${name}.pgm`), Buffer.concat([Buffer.from(`P5\n${nx} ${ny}\n255\n`), px]));
  const yaml = path.join(tmp, `${name}.yaml`);
  writeFileSync(yaml, `image: ${name}.${ext}\nresolution: 0.05\norigin: [${origin.join(', ')}]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n`);
  return yaml;
}

// A sees x <= 18, B sees x >= 5 in a frame turned by 0.9 rad; C is another plan.
const fp = plan(false);
const frameA = [-0.5, -0.5, 0];
const A = writeMap('a', fp, frameA, 400, 340, (p) => p[0] <= 18, [-2, 1, 0]);
const theta = 0.9, cx = 16, cy = 8, half = 12;
const frameB = [cx - (Math.cos(theta) * half - Math.sin(theta) * half), cy - (Math.sin(theta) * half + Math.cos(theta) * half), theta];
const B = writeMap('b', fp, frameB, 480, 480, (p) => p[0] >= 5);
const C = writeMap('c', plan(true), [-0.5, -0.5, 0.3], 480, 480, () => true);

/** B's map frame in A's map frame: (frameA ⊕ originA⁻¹)⁻¹ ⊕ frameB. */
function truthBinA() {
  // A's map frame in the plan: frameA ⊕ inverse([-2, 1, 0]) = frameA shifted by (2, -1).
  const ax = frameA[0] + 2, ay = frameA[1] - 1;
  return [frameB[0] - ax, frameB[1] - ay, frameB[2]];
}

test('two maps of one floor merge to the known transform, JSON on stdout only', () => {
  const out = path.join(tmp, 'merged.yaml');
  const r = run(A, B, '--json', '--out', out);
  assert.equal(r.code, 0, r.stderr);
  const report = JSON.parse(r.stdout);
  assert.deepEqual(report.maps.map((m) => [m.name, m.width, m.height, m.resolution]), [[A, 400, 340, 0.05], [B, 480, 480, 0.05]]);
  const m = report.merge;
  assert.equal(m.status, 'merged', m.reason);
  assert.match(m.reason, /\d/);
  assert.ok(m.confidence > 0 && m.confidence <= 1);
  assert.deepEqual(m.transforms[0], { map: A, pose: [0, 0, 0] });
  assert.equal(m.transforms[1].map, B);
  const [x, y, th] = m.transforms[1].pose, [tx, ty, tt] = truthBinA();
  assert.ok(Math.hypot(x - tx, y - ty) < 0.1, `off by ${Math.hypot(x - tx, y - ty)} m`);
  assert.ok(Math.abs(th - tt) < 0.5 * Math.PI / 180, `off by ${(th - tt) * 180 / Math.PI} deg`);
  assert.deepEqual(m.unjoined, []);
  assert.equal(m.pairs.length, 1);
  assert.equal(m.pairs[0].status, 'merged');
  assert.equal(typeof report.timings_ms.total, 'number');
  assert.match(r.stderr, /merging 2 maps/);
  for (const f of ['merged.yaml', 'merged.pgm', 'merged.png']) assert.ok(existsSync(path.join(tmp, f)), f);
  assert.match(readFileSync(out, 'utf8'), /image: "merged.pgm"/);
  // The merged map reads back as a map.
  const again = run(out, A, '--json');
  assert.equal(again.code, 0, again.stderr);
});

test('two different floor plans are refused, and --out writes nothing', () => {
  const out = path.join(tmp, 'never.yaml');
  const r = run(A, C, '--json', '--out', out);
  assert.equal(r.code, 0, r.stderr);
  const m = JSON.parse(r.stdout).merge;
  assert.equal(m.status, 'no_merge', m.reason);
  assert.deepEqual(m.unjoined, [C]);
  assert.deepEqual(m.transforms, [{ map: A, pose: [0, 0, 0] }]);
  assert.ok(!existsSync(out));
  assert.ok(!existsSync(path.join(tmp, 'never.pgm')));
});

function badYaml(name, text) {
  const p = path.join(tmp, name);
  writeFileSync(p, text);
  return p;
}

test('bad input exits 2 with a message naming the file and the field', () => {
  const cases = [
    [badYaml('noimage.yaml', 'image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n'), 'noimage.yaml: image:'],
    [badYaml('nores.yaml', 'image: a.pgm\norigin: [0, 0, 0]\n'), 'nores.yaml: resolution:'],
    [badYaml('negres.yaml', 'image: a.pgm\nresolution: -0.05\norigin: [0, 0, 0]\n'), 'negres.yaml: resolution:'],
    [badYaml('nanres.yaml', 'image: a.pgm\nresolution: .nan\norigin: [0, 0, 0]\n'), 'nanres.yaml: resolution:'],
    [badYaml('noorigin.yaml', 'image: a.pgm\nresolution: 0.05\n'), 'noorigin.yaml: origin:'],
    [badYaml('notimage.yaml', 'image: a.yaml\nresolution: 0.05\norigin: [0, 0, 0]\n'), 'notimage.yaml: image:'],
  ];
  writeFileSync(path.join(tmp, 'huge.pgm'), 'P5\n5000 5000\n255\n');
  cases.push([badYaml('huge.yaml', 'image: huge.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n'), 'huge.yaml: image:']);
  for (const [file, message] of cases) {
    const r = run(A, file, '--json');
    assert.equal(r.code, 2, `${file}: ${r.stderr}`);
    assert.ok(r.stderr.includes(message), `${message} in ${r.stderr}`);
    assert.equal(r.stdout, '');
  }
  assert.equal(run(A).code, 2);
  assert.equal(run(A, path.join(tmp, 'absent.yaml')).code, 2);
  assert.equal(run(A, B, '--bogus').code, 2);
  assert.equal(run(A, B, '--out', 'x.txt').code, 2);
});
