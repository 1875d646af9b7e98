// The classroom exercises (docs/exercises/*.md) work as written.
//
// Every exercise page names its scenario file(s) on a line of its own,
//
//     Scenario: `scenarios/ex-featureless.json`
//
// and this suite checks that each named file exists, loads, and runs
// headless through the command line (`web/cli.mjs run FILE --json`, the whole
// duration: every exercise scenario takes under 10 s in node), that the
// report has its basic fields, and that the observation the page's "Notes
// for teachers" rely on still holds where it is robust: a verdict, a reason,
// an error bound, an ordering. Variants are the changes the page asks
// students to make; each is applied here to a copy of the scenario, and the
// page must show the change in the same words (`text`), so the page and the
// test cannot drift apart silently.
//
// Run by ./build.sh test after ./build.sh build: 14 runs of 3-10 s, 75-100 s in
// all on a 2-core machine. Alone: node --test tests/exercises.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync, readdirSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { ROOT as root, runCli, tempDir } from './support/cli.mjs';

const docs = path.join(root, 'docs', 'exercises');
const tmp = tempDir('exercises');

/** The side sonars sit this far from the robot's centre (crate/src/sensors/sonar.rs):
 *  a follower holding `distance` on the sonar keeps its centre this much further. */
const SONAR_OFFSET_M = 0.136;
/** The P2DX's wheelbase (m), for the heading drift a wheel scale error makes. */
const WHEELBASE_M = 0.33;

const pages = readdirSync(docs)
  .filter((f) => f.endsWith('.md') && f !== 'README.md')
  .sort();

/** The scenario files a page names: every `Scenario: \`PATH\`` line. */
function scenariosOf(text) {
  return [...text.matchAll(/^Scenario: `([^`]+)`\s*$/gm)].map((m) => m[1]);
}

/** Runs `web/cli.mjs run FILE --json ARGS…` and returns the parsed report. */
function run(file, ...args) {
  const r = runCli('run', file, '--json', ...args);
  assert.equal(r.code, 0, `run ${file} ${args.join(' ')} exited ${r.code}: ${r.stderr}`);
  return JSON.parse(r.stdout);
}

/** A copy of a scenario with `change` applied, written to the temp dir. */
function variantFile(file, name, change) {
  const scenario = JSON.parse(readFileSync(path.join(root, file), 'utf8'));
  change(scenario);
  const out = path.join(tmp, `${name}.json`);
  writeFileSync(out, JSON.stringify(scenario));
  return { out, scenario };
}

/** What every report must have, whatever the exercise. */
function checkBasics(report, scenario) {
  const n = scenario.robots.length;
  assert.equal(report.scenario, scenario.name);
  assert.equal(report.seed, scenario.seed);
  assert.equal(report.duration_s, scenario.duration_s);
  assert.equal(report.steps, Math.round(scenario.duration_s * 10));
  assert.deepEqual(
    report.robots.map((r) => r.name),
    scenario.robots.map((r) => r.name),
  );
  for (const [i, robot] of report.robots.entries()) {
    for (const key of ['truth', 'odometry', 'estimate']) {
      assert.equal(robot[key].length, report.steps + 1, `${robot.name}.${key}`);
    }
    assert.deepEqual(robot.truth[0], [0, ...scenario.robots[i].start]);
    assert.ok(robot.path_length_m > 10, `${robot.name} drove ${robot.path_length_m} m`);
    assert.ok(robot.frames > 0);
    for (const key of ['ate_m', 'odometry_ate_m', 'occupied_precision', 'wall_coverage']) {
      assert.ok(Number.isFinite(robot.slam[key]), `${robot.name}.slam.${key}`);
    }
  }
  assert.equal(report.match_tables.length, (n * (n - 1)) / 2);
  const m = report.merge;
  assert.ok(['merged', 'no_merge'].includes(m.status), m.status);
  assert.equal(typeof m.reason, 'string');
  assert.ok(m.reason.length > 10, m.reason);
  assert.deepEqual(m.transforms[0], { robot: scenario.robots[0].name, pose: [0, 0, 0] });
  assert.equal(m.transforms.length + m.unjoined.length, n);
  assert.equal(m.pairs.length, (n * (n - 1)) / 2);
  assert.ok(report.timings_ms.total > 0);
}

/** The merge error of a robot's frame against the truth (m). */
function mergeError(report, name) {
  const e = report.merge.errors.find((x) => x.robot === name);
  assert.ok(e, `an error entry for ${name}`);
  return e.error_m;
}

/** Distance from point p to segment ab. */
function segmentDistance(p, a, b) {
  const dx = b[0] - a[0];
  const dy = b[1] - a[1];
  const t = Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)));
  return Math.hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
}

/** Median clearance a robot held, as its side sonar would read it: the true
 *  distance from its centre to the nearest wall, less the sonar's offset,
 *  after the first 20 s (the approach to the first wall). */
function medianClearance(robot, scenario) {
  const d = robot.truth
    .filter((row) => row[0] > 20)
    .map((row) => Math.min(...scenario.walls.map((w) => segmentDistance([row[1], row[2]], w.from, w.to))))
    .sort((a, b) => a - b);
  return d[d.length >> 1] - SONAR_OFFSET_M;
}

// Per page: the runs, each with what it shows. `variant` is the change the
// page asks for; `text` must appear in the page verbatim.
const checks = {
  '01-follow-distance.md': [
    {
      what: 'at 0.6 m both robots pass the door, hold the distance and the maps merge',
      check(report, scenario) {
        for (const robot of report.robots) {
          assert.equal(robot.bumps, 0);
          const c = medianClearance(robot, scenario);
          assert.ok(Math.abs(c - 0.6) < 0.05, `${robot.name} held ${c.toFixed(3)} m`);
          assert.ok(robot.slam.wall_coverage > 0.9, `${robot.name} coverage ${robot.slam.wall_coverage}`);
          // Each robot visits both rooms (the door is at x = 8 m).
          assert.ok(robot.truth.some((r) => r[1] < 8) && robot.truth.some((r) => r[1] > 8), robot.name);
        }
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        assert.ok(mergeError(report, 'robot2') < 0.1);
      },
    },
    {
      what: 'at 1.0 m neither robot gets through the 1.4 m door: no common place, no merge',
      text: '"distance": 1.0',
      variant: (s) => s.robots.forEach((r) => (r.distance = 1.0)),
      check(report, scenario) {
        for (const robot of report.robots) {
          const c = medianClearance(robot, scenario);
          assert.ok(Math.abs(c - 1.0) < 0.05, `${robot.name} held ${c.toFixed(3)} m`);
          assert.ok(robot.slam.wall_coverage < 0.75, `${robot.name} coverage ${robot.slam.wall_coverage}`);
        }
        const [r1, r2] = report.robots;
        assert.ok(r1.truth.every((r) => r[1] < 8), 'robot1 stays in the west room');
        assert.ok(r2.truth.every((r) => r[1] > 8), 'robot2 stays in the east room');
        assert.equal(report.merge.status, 'no_merge');
        assert.deepEqual(report.merge.unjoined, ['robot2']);
      },
    },
  ],
  '02-odometry-noise.md': [
    {
      what: 'default noise: odometry drifts by metres, SLAM does not, the maps merge',
      check(report) {
        for (const robot of report.robots) {
          assert.ok(robot.slam.odometry_ate_m > 0.5, `${robot.name} odometry ATE ${robot.slam.odometry_ate_m}`);
          assert.ok(robot.slam.ate_m < robot.slam.odometry_ate_m / 5, `${robot.name} SLAM ATE ${robot.slam.ate_m}`);
          assert.ok(robot.slam.odometry_occupied_precision < 0.6);
        }
        assert.equal(report.merge.status, 'merged', report.merge.reason);
      },
    },
    {
      what: 'every noise field 0: odometry equals the truth',
      text: '"wheel_slip": 0, "wheel_scale_error": [0, 0], "wheelbase_error": 0',
      variant: (s) => {
        s.noise = { wheel_slip: 0, wheel_scale_error: [0, 0], wheelbase_error: 0, sonar_std_m: 0, laser_std_m: 0 };
      },
      check(report) {
        for (const robot of report.robots) {
          assert.ok(robot.slam.odometry_ate_m < 1e-3, `${robot.name} odometry ATE ${robot.slam.odometry_ate_m}`);
          assert.ok(robot.slam.odometry_occupied_precision > 0.99);
        }
      },
    },
    {
      what: 'a scale error alone turns the odometry by (e_R - e_L) / b radians per metre',
      text: '"wheel_scale_error": [0.0025, -0.0025]',
      variant: (s) => {
        s.noise = { wheel_slip: 0, wheel_scale_error: [0.0025, -0.0025], wheelbase_error: 0 };
      },
      check(report) {
        for (const robot of report.robots) {
          const predicted = (((-0.0025 - 0.0025) / WHEELBASE_M) * robot.path_length_m * 180) / Math.PI;
          const measured = robot.odometry_final_error.heading_deg;
          assert.ok(Math.abs(measured - predicted) < 2, `${robot.name}: ${measured}° against ${predicted}°`);
          assert.ok(robot.slam.ate_m < 0.2, `${robot.name} SLAM ATE ${robot.slam.ate_m}`);
        }
      },
    },
  ],
  '03-slam-vs-odometry.md': [
    {
      what: 'SLAM beats odometry-only mapping by far on the thesis preset',
      // Run 300 s, as the page asks and its notes were measured.
      text: '--duration 300',
      variant: (s) => {
        s.duration_s = 300;
      },
      check(report) {
        for (const robot of report.robots) {
          const s = robot.slam;
          assert.ok(s.ate_m < s.odometry_ate_m / 5, `${robot.name}: ${s.ate_m} vs ${s.odometry_ate_m}`);
          assert.ok(s.occupied_precision > s.odometry_occupied_precision + 0.3, robot.name);
          assert.ok(s.wall_coverage > s.odometry_wall_coverage, robot.name);
        }
        assert.equal(report.merge.status, 'merged', report.merge.reason);
      },
    },
  ],
  '04-featureless-walls.md': [
    {
      what: 'plain walls: SLAM is as good as ever, vision finds nothing, the maps alone merge',
      check(report) {
        for (const robot of report.robots) assert.ok(robot.slam.ate_m < 0.1, `${robot.name} ATE ${robot.slam.ate_m}`);
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        assert.match(report.merge.reason, /maps alone agree/);
        assert.match(report.merge.reason, /vision: (no common place|too few inliers)/);
        assert.ok(report.merge.confidence <= 0.5, `map-only confidence ${report.merge.confidence}`);
        assert.deepEqual(report.merge.unjoined, []);
        assert.ok(mergeError(report, 'robot2') < 0.1);
      },
    },
    {
      what: "plain walls: the thesis method finds no pair with enough inliers",
      args: ['--method', 'thesis'],
      check(report) {
        assert.equal(report.method, 'thesis');
        assert.equal(report.merge.status, 'no_merge');
        assert.match(report.merge.reason, /inliers/);
      },
    },
  ],
  '05-repeated-textures.md': [
    {
      what: 'one texture everywhere: the automatic method rejects the look-alikes and merges right',
      check(report) {
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        assert.ok(mergeError(report, 'robot2') < 0.1);
        const pair = report.merge.pairs[0];
        assert.ok(pair.candidates > pair.support, `${pair.support} of ${pair.candidates} candidates agree`);
      },
    },
    {
      what: 'one texture everywhere: the thesis method trusts the best pair, a false match',
      args: ['--method', 'thesis'],
      check(report) {
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        assert.ok(mergeError(report, 'robot2') > 1, `robot2 off by ${mergeError(report, 'robot2')} m`);
      },
    },
  ],
  '06-camera-fov.md': [
    {
      what: '40° camera: the automatic method still merges',
      check(report) {
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        assert.ok(mergeError(report, 'robot2') < 0.1);
      },
    },
    {
      what: '40° camera: the thesis method finds no usable pair',
      args: ['--method', 'thesis'],
      check(report) {
        assert.equal(report.merge.status, 'no_merge');
      },
    },
    {
      what: "60° camera: the thesis method's K times f is the wall's distance the laser measures",
      text: '"hfov_deg": 60',
      variant: (s) => (s.camera.hfov_deg = 60),
      args: ['--method', 'thesis'],
      check(report) {
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        const d = report.merge.pairs[0].distance;
        assert.ok(Math.abs(d.hfov_rad - Math.PI / 3) < 1e-9);
        const f = 160 / Math.tan(d.hfov_rad / 2); // 320 px wide
        assert.ok(Math.abs(d.k_m_per_px * f - d.depth_a_m) < 1e-6, 'depth = K f');
        assert.ok(Math.abs(d.depth_a_m - d.laser_depth_a_m) / d.laser_depth_a_m < 0.1, `${d.depth_a_m} vs ${d.laser_depth_a_m}`);
        assert.ok(mergeError(report, 'robot2') < 0.1);
      },
    },
  ],
  '07-three-robots.md': [
    {
      what: 'three robots: all joined along the spanning tree, each within 0.1 m',
      check(report) {
        assert.equal(report.merge.status, 'merged', report.merge.reason);
        assert.deepEqual(
          report.merge.transforms.map((t) => t.robot),
          ['robot1', 'robot2', 'robot3'],
        );
        assert.deepEqual(report.merge.unjoined, []);
        for (const name of ['robot2', 'robot3']) assert.ok(mergeError(report, name) < 0.1, name);
      },
    },
  ],
};

test('every exercise page has a check here, and every check a page', () => {
  assert.ok(pages.length >= 6, `${pages.length} exercise pages`);
  assert.deepEqual(pages, Object.keys(checks).sort());
});

test('the index lists every exercise page, and every page it links exists', () => {
  const index = readFileSync(path.join(docs, 'README.md'), 'utf8');
  for (const page of pages) assert.ok(index.includes(`(${page})`), `README.md links ${page}`);
  for (const [, link] of index.matchAll(/\]\(([^)#]+\.md)\)/g)) {
    assert.ok(existsSync(path.join(docs, link)), `${link} exists`);
  }
});

for (const page of pages) {
  const text = readFileSync(path.join(docs, page), 'utf8');
  const files = scenariosOf(text);

  test(`${page}: names its scenario, its thesis section, steps, questions and notes for teachers`, () => {
    assert.ok(files.length >= 1, 'a `Scenario: `scenarios/….json`` line');
    for (const file of files) {
      assert.match(file, /^scenarios\/[\w.-]+\.json$/);
      assert.ok(existsSync(path.join(root, file)), `${file} exists`);
      assert.ok(text.includes(`node web/cli.mjs run ${file}`), `the CLI command for ${file}`);
    }
    assert.match(text, /^Thesis: .*§\d/m);
    for (const heading of ['## Steps', '## What to change', '## What to watch', '## Questions', '## Notes for teachers']) {
      assert.ok(text.includes(`\n${heading}\n`), heading);
    }
    // Every scenario file the page mentions anywhere exists.
    for (const [mention] of text.matchAll(/scenarios\/[\w.-]+\.json/g)) {
      assert.ok(existsSync(path.join(root, mention)), `${mention} (mentioned) exists`);
    }
  });

  const file = files[0];
  for (const [k, c] of (checks[page] ?? []).entries()) {
    test(`${page}: ${c.what}`, () => {
      let target = file;
      let scenario = JSON.parse(readFileSync(path.join(root, file), 'utf8'));
      if (c.variant) {
        assert.ok(text.includes(c.text), `the page asks for ${c.text}`);
        ({ out: target, scenario } = variantFile(file, `${page.replace(/\.md$/, '')}-${k}`, c.variant));
      }
      const report = run(target, ...(c.args ?? []));
      checkBasics(report, scenario);
      c.check(report, scenario);
    });
  }
}
