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
import { MCAP_MAGIC, mcap } from './support/bags.mjs';
import { gridOf, mapBag } from './support/map-bags.mjs';
import { centredFrame, floorPlan, mapImage, mapYaml } from './support/synthetic-maps.mjs';

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
