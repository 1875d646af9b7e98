// The lab's reports do not change by accident.
//
// `node web/cli.mjs run SCENARIO --json` is the project's contract with the
// outside (docs/interfaces.md). A refactor must leave every report of every
// preset and exercise scenario identical, apart from the wall-clock
// `timings_ms` (at any depth). This suite runs each of them and compares the
// SHA-256 of the report, with every `timings_ms` removed and serialised by
// `JSON.stringify`, with the one recorded in tests/golden/reports.json. A
// few headline figures are recorded beside the hash so that a failure says
// what moved.
//
// A change that is meant to alter the reports re-records them, and its
// commit says why:
//
//     UPDATE_GOLDEN=1 node --test tests/reports.test.mjs
//
// Run by ./build.sh test after ./build.sh build (about 20 runs of 1-3 s).
import { after, test } from 'node:test';
import assert from 'node:assert/strict';
import { createHash } from 'node:crypto';
import { existsSync, readFileSync, readdirSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { ROOT as root, runCli } from './support/cli.mjs';

const goldenFile = path.join(root, 'tests', 'golden', 'reports.json');
const update = process.env.UPDATE_GOLDEN === '1';

/** Every scenario with the default method, and the preset with each other method. */
const runs = [
  ...readdirSync(path.join(root, 'scenarios'))
    .filter((f) => f.endsWith('.json'))
    .sort()
    .map((f) => [`scenarios/${f}`]),
  ['scenarios/thesis.json', '--method', 'thesis'],
  ['scenarios/thesis.json', '--method', 'map-only'],
];

/** The report without its wall-clock timings, at any depth. */
function withoutTimings(value) {
  if (Array.isArray(value)) return value.map(withoutTimings);
  if (value && typeof value === 'object') {
    const out = {};
    for (const [k, v] of Object.entries(value)) if (k !== 'timings_ms') out[k] = withoutTimings(v);
    return out;
  }
  return value;
}

/** What a failure should show: the verdict and each robot's headline figures. */
function headline(report) {
  return {
    status: report.merge.status,
    reason: report.merge.reason,
    transforms: report.merge.transforms,
    robots: report.robots.map((r) => ({ name: r.name, frames: r.frames, ate_m: r.slam?.ate_m })),
  };
}

const golden = existsSync(goldenFile) ? JSON.parse(readFileSync(goldenFile, 'utf8')) : {};
const recorded = {};

for (const args of runs) {
  const key = args.join(' ');
  test(`run ${key}: report identical to the recorded one`, () => {
    const r = runCli('run', ...args, '--json');
    assert.equal(r.code, 0, `run ${key} exited ${r.code}: ${r.stderr}`);
    const report = JSON.parse(r.stdout);
    const sha256 = createHash('sha256').update(JSON.stringify(withoutTimings(report))).digest('hex');
    const entry = { sha256, ...headline(report) };
    recorded[key] = entry;
    if (update) return;
    assert.ok(golden[key], `no recorded report for '${key}': record with UPDATE_GOLDEN=1`);
    assert.deepEqual(entry, golden[key], `report of '${key}' changed`);
  });
}

after(() => {
  if (!update) return;
  if (Object.keys(recorded).length !== runs.length) throw new Error('not recorded: every run must complete first');
  writeFileSync(goldenFile, JSON.stringify(recorded, null, 1) + '\n');
  console.error(`recorded ${runs.length} reports in ${path.relative(root, goldenFile)}`);
});
