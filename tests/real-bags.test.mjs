// Real-data suite: the command line on every shared ROS bag
// (../shared/data/bags, or $SLAMLAB_DATA/bags; a missing folder fails).
// `bag-info` lists each bag's topics with the counts the data's README
// gives; `run-log` replays the bags that are not the benchmark's (those
// are replayed by tests/real_bags.rs and tests/bench/relations.mjs).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync, rmSync } from 'node:fs';
import path from 'node:path';
import { ROOT, runCli, tempDir } from './support/cli.mjs';

const data = process.env.SLAMLAB_DATA ?? path.join(ROOT, '..', 'shared', 'data');
const bags = path.join(data, 'bags');

/** Each shared bag: its LaserScan topic and scan count, and its other topics' counts. */
const BAGS = {
  'freiburg/aces.bag': { '/scan': 7374 },
  'freiburg/intel.bag': { '/scan': 13631, '/odom': 26915 },
  'freiburg/fr079.bag': { '/scan': 4934, '/odom': 8951 },
  'freiburg/mit-csail.bag': { '/scan': 1988, '/odom': 1988, '/tf': 1988, '/tf_static': 2 },
  'ros2/mit-csail-zstd.mcap': { '/scan': 1988, '/odom': 1988 },
  'ros2/mit-csail-lz4.mcap': { '/scan': 1988, '/odom': 1988 },
  'ros2/mit-csail-db3': { '/scan': 1988, '/odom': 1988 },
  'other/cupoch-Mapping1.bag': { '/base_scan': 1727, '/base_pose_ground_truth': 1727 },
  'other/scan_tools-demo.bag': { '/scan': 360 },
  'other/mumble-hallway_room_loop': { '/scan': 896, '/imu_data': 3698 },
};

test('the shared bags are there', () => {
  assert.ok(existsSync(bags), `real data not found: ${bags} (set SLAMLAB_DATA to the shared data folder)`);
});

test('bag-info lists every shared bag\'s topics, counts and what run-log would pick', () => {
  for (const [bag, counts] of Object.entries(BAGS)) {
    const r = runCli('bag-info', path.join(bags, bag), '--json');
    assert.equal(r.code, 0, `${bag}: ${r.stderr}`);
    const info = JSON.parse(r.stdout);
    for (const [topic, n] of Object.entries(counts)) {
      const t = info.topics.find((x) => x.name === topic);
      assert.ok(t, `${bag}: no ${topic}`);
      assert.equal(t.count, n, `${bag} ${topic}`);
    }
    assert.deepEqual(info.lost, [], bag);
    assert.ok(info.run_log.scan_topic, `${bag}: ${JSON.stringify(info.run_log)}`);
  }
  // The text form names the storage and the picks.
  const text = runCli('bag-info', path.join(bags, 'ros2/mit-csail-db3')).stdout;
  assert.match(text, /Storage id:\s+rosbag2 SQLite/);
  assert.match(text, /run-log picks:\s+scans \/scan/);
});

test('run-log --check-relations checks each relation against its own scans and the wheels', () => {
  const bag = path.join(bags, 'freiburg/mit-csail.bag');
  const relations = path.join(bags, 'freiburg/mit-csail.relations');
  const r = runCli('run-log', bag, '--json', '--relations', relations, '--check-relations');
  assert.equal(r.code, 0, r.stderr);
  const report = JSON.parse(r.stdout);
  const c = report.relation_check;
  assert.equal(c.checked, report.relations.matched);
  assert.equal(c.uncontradicted + c.contradicted.length, c.checked);
  assert.ok(c.settled > 950 && c.settled <= c.checked, `${c.settled} settled`);
  assert.ok(c.by_scans >= 30 && c.by_scans <= 55, `${c.by_scans} contradicted by their scans`);
  assert.ok(c.contradicted.every((x) => x.by === 'scans' || x.by === 'odometry'));
  // Where the scans settle a pose, ours lies nearer it than the relations do.
  assert.ok(c.ours_vs_scans.trans_m < 0.6 * c.relations_vs_scans.trans_m, JSON.stringify(c.ours_vs_scans));
  assert.ok(c.trans_m.mean <= report.relations.trans_m.mean, `${c.trans_m.mean} against ${report.relations.trans_m.mean}`);
  // Without --relations there is nothing to check: a usage error.
  const bad = runCli('run-log', bag, '--check-relations');
  assert.equal(bad.code, 2);
  assert.match(bad.stderr, /--check-relations needs --relations FILE/);
});

test('run-log replays the bags without odometry by scan matching, and scores the one with ground truth', () => {
  const dir = tempDir();
  try {
    for (const [bag, scans] of [['other/scan_tools-demo.bag', 360], ['other/mumble-hallway_room_loop', 896], ['other/cupoch-Mapping1.bag', 1727]]) {
      const tum = path.join(dir, 'out.tum');
      const r = runCli('run-log', path.join(bags, bag), '--json', '--trajectory', tum, '--out', path.join(dir, 'map.yaml'));
      assert.equal(r.code, 0, `${bag}: ${r.stderr}`);
      const report = JSON.parse(r.stdout);
      assert.equal(report.scans.length, scans, bag);
      assert.equal(report.bag.picked.odometry, null, bag);
      assert.ok(report.scans.every((s) => s.odometry === null && s.pose.every(Number.isFinite)), bag);
      assert.equal(readFileSync(tum, 'utf8').trim().split('\n').length, scans + 1, bag);
      assert.ok(existsSync(path.join(dir, 'map.pgm')), bag);
      if (bag.includes('cupoch')) {
        assert.equal(report.bag.picked.truth_topic, '/base_pose_ground_truth');
        assert.equal(report.ground_truth.length, 1727);
        assert.ok(report.ate_m < 0.28, `ATE ${report.ate_m}`);
      } else {
        assert.equal(report.ground_truth, undefined, bag);
      }
    }
    // --truth-topic NONE: no ground truth, even where one is named so.
    const r = runCli('run-log', path.join(bags, 'other/cupoch-Mapping1.bag'), '--json', '--truth-topic', 'NONE');
    assert.equal(r.code, 0, r.stderr);
    assert.equal(JSON.parse(r.stdout).ate_m, undefined);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});
