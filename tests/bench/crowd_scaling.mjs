// The scaling table of issue 22 (BENCHMARKS.md): time and peak memory of
// `node web/cli.mjs run` (default workers) on crowded mazes
// (tests/bench/crowd_maze.mjs) against the number of robots, the duration
// and the world's size. Each row runs the CLI under `/usr/bin/time -v` and
// prints a markdown row with the command that made it, the report's
// timings_ms, the CPU time (user + sys, all threads), the peak RSS of the main process (node's worker threads
// included: they are threads of it), frames kept and dropped, the groups the
// merge reports, and the load average before the run (the machine is shared).
//
//   node tests/bench/crowd_scaling.mjs [ROW ...]     ROW: robots x duration x cells, e.g. 16x3600x20
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { loadavg, tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { crowdMaze } from './crowd_maze.mjs';

const root = path.join(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const tmp = mkdtempSync(path.join(tmpdir(), 'slamlab-scaling-'));
const rows = process.argv.slice(2).length > 0
  ? process.argv.slice(2)
  : ['1x300x20', '2x300x20', '4x300x20', '8x300x20', '16x300x20', '16x900x20', '16x3600x20', '8x300x10', '8x300x30'];

console.log('| robots | duration (s) | maze | command | total (s) | CPU user+sys (s) | simulate | features | matching | merge | peak RSS (MB) | frames kept / dropped (robot 1) | groups | load before |');
console.log('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|');
for (const row of rows) {
  const [robots, duration, cells] = row.split('x').map(Number);
  const file = path.join(tmp, `crowd-${row}.json`);
  writeFileSync(file, JSON.stringify(crowdMaze({ robots, duration, cells, seed: 22 })));
  const load = loadavg()[0].toFixed(1);
  const r = spawnSync('/usr/bin/time', ['-v', process.execPath, 'web/cli.mjs', 'run', file, '--json'], {
    cwd: root, encoding: 'utf8', maxBuffer: 1 << 30,
  });
  const command = `node tests/bench/crowd_maze.mjs --robots ${robots} --duration ${duration} --cells ${cells} --seed 22 --out S.json && /usr/bin/time -v node web/cli.mjs run S.json --json`;
  if (r.status !== 0) {
    console.log(`| ${robots} | ${duration} | ${cells}x${cells} | \`${command}\` | failed: ${r.stderr.split('\n').filter((l) => /error/.test(l)).join(' ')} |`);
    continue;
  }
  const rss = Number(/Maximum resident set size \(kbytes\): (\d+)/.exec(r.stderr)[1]) / 1024;
  const cpu = Number(/User time \(seconds\): ([\d.]+)/.exec(r.stderr)[1]) + Number(/System time \(seconds\): ([\d.]+)/.exec(r.stderr)[1]);
  const report = JSON.parse(r.stdout);
  const t = report.timings_ms;
  const s = (ms) => (ms / 1000).toFixed(1);
  const g = report.merge.groups.filter((x) => x.robots.length > 1).map((x) => x.robots.length).join('+') || 'none';
  console.log(`| ${robots} | ${duration} | ${cells}x${cells} (${cells * 3} m) | \`${command}\` | ${s(t.total)} | ${cpu.toFixed(1)} | ${s(t.simulate)} (SLAM ${s(t.slam)}, camera ${s(t.camera)}) | ${s(t.features)} | ${s(t.matching)} | ${s(t.merge)} | ${rss.toFixed(0)} | ${report.robots[0].frames} / ${report.robots[0].frames_dropped} | ${g} joined, ${report.merge.groups.filter((x) => x.robots.length === 1).length} alone | ${load} |`);
}
