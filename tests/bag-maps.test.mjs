// `merge-maps` takes a ROS bag whose nav_msgs/OccupancyGrid topic holds a
// robot's map (docs/interfaces.md, "Real maps: merge-maps"), beside saved
// map_server YAML maps: two maps of one synthetic floor, written as the
// last /map message of an MCAP (CDR), merge to the transform that made them.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { runCli } from './support/cli.mjs';
import { Bytes, MCAP_MAGIC, mcap } from './support/bags.mjs';
import { centredFrame, floorPlan, mapImage, mapYaml } from './support/synthetic-maps.mjs';

/** The cells of a binary PGM as nav_msgs/OccupancyGrid data: rows from the bottom, 0 free, 100 wall, -1 unknown. */
function gridOf(pgm) {
  const text = pgm.subarray(0, 32).toString('latin1');
  const [, w, h] = text.match(/^P5\s+(\d+)\s+(\d+)\s+255\s/).map(Number);
  const start = pgm.length - w * h;
  const data = new Int8Array(w * h);
  for (let row = 0; row < h; row++) {
    for (let col = 0; col < w; col++) {
      const v = pgm[start + (h - 1 - row) * w + col];
      data[row * w + col] = v === 254 ? 0 : v === 0 ? 100 : -1;
    }
  }
  return { w, h, data };
}

/** An OccupancyGrid in CDR: header, map metadata (origin at `origin` [x, y, yaw]), cells. */
function occupancyGrid({ w, h, data }, origin, res = 0.05) {
  const b = new Bytes({ cdr: true });
  b.i32(1700000000).u32(0).string('map');
  b.i32(0).u32(0).f32(res).u32(w).u32(h);
  b.f64(origin[0]).f64(origin[1]).f64(0);
  b.f64(0).f64(0).f64(Math.sin(origin[2] / 2)).f64(Math.cos(origin[2] / 2));
  b.u32(data.length).raw(Buffer.from(data.buffer));
  return b.bytes();
}

/** An MCAP holding one /map message (no chunks, no summary: a linear read takes it). */
function mapBag(grid, origin) {
  return Buffer.concat([
    MCAP_MAGIC, mcap.header(),
    mcap.schema(1, 'nav_msgs/msg/OccupancyGrid'), mcap.channel(1, 1, '/map'),
    mcap.message(1, 0, 1700000000000000000n, occupancyGrid(grid, origin)),
    mcap.dataEnd(), mcap.footer(), MCAP_MAGIC,
  ]);
}

test('a bag\'s /map merges with a saved map and with another bag\'s, to the transform that made them', () => {
  const dir = mkdtempSync(path.join(tmpdir(), 'slamlab-bag-maps-'));
  try {
    const plan = floorPlan(30, 20, 7);
    const frameA = [-0.5, -0.5, 0];
    const frameB = centredFrame(18, 10, 0.9, 640, 640);
    const pgmA = mapImage(plan, frameA, 640, 440, ([x]) => x <= 19.5);
    const pgmB = mapImage(plan, frameB, 640, 640, ([x]) => x >= 9);
    // Map B's frame in map A's: B's image corner is at frameB in the plan,
    // A's at frameA; both maps' origins at their image corners.
    const truth = [frameB[0] - frameA[0], frameB[1] - frameA[1], frameB[2]];
    writeFileSync(path.join(dir, 'a.pgm'), pgmA);
    writeFileSync(path.join(dir, 'a.yaml'), mapYaml('a.pgm'));
    writeFileSync(path.join(dir, 'a.mcap'), mapBag(gridOf(pgmA), [0, 0, 0]));
    writeFileSync(path.join(dir, 'b.mcap'), mapBag(gridOf(pgmB), [0, 0, 0]));
    for (const first of ['a.yaml', 'a.mcap']) {
      const r = runCli('merge-maps', path.join(dir, first), path.join(dir, 'b.mcap'), '--json');
      assert.equal(r.code, 0, r.stderr);
      const report = JSON.parse(r.stdout);
      assert.deepEqual(report.maps.map((m) => [m.width, m.height, m.resolution]), [[640, 440, 0.05], [640, 640, 0.05]]);
      assert.equal(report.merge.status, 'merged', report.merge.reason);
      const pose = report.merge.transforms[1].pose;
      const turn = Math.abs(Math.atan2(Math.sin(pose[2] - truth[2]), Math.cos(pose[2] - truth[2])));
      assert.ok(Math.hypot(pose[0] - truth[0], pose[1] - truth[1]) < 0.1, `${first}: ${pose} vs ${truth}`);
      assert.ok(turn < 0.5 * Math.PI / 180, `${first}: ${pose} vs ${truth}`);
    }
    // A bag without any map says so and exits 2.
    writeFileSync(path.join(dir, 'empty.mcap'), Buffer.concat([MCAP_MAGIC, mcap.header(), mcap.dataEnd(), mcap.footer(), MCAP_MAGIC]));
    const r = runCli('merge-maps', path.join(dir, 'a.yaml'), path.join(dir, 'empty.mcap'));
    assert.equal(r.code, 2);
    assert.match(r.stderr, /empty\.mcap: no nav_msgs\/OccupancyGrid topic/);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});
