// A crowded run's merge groups against the truth (issue 22): which pairs of
// robots drove 50 m^2 or more together and whether each such pair was
// joined, and how far each joined robot's transform is from the truth.
//
// Usage: node web/cli.mjs run S.json --json > R.json
//        node tests/bench/crowd_groups.mjs R.json
import { readFileSync } from 'node:fs';
import { overlaps } from '../support/overlaps.mjs';

const report = JSON.parse(readFileSync(process.argv[2], 'utf8'));
const groupOf = Object.fromEntries(
  report.merge.groups.flatMap((g, k) => g.robots.map((n) => [n, k])),
);
const pairs = overlaps(report).filter((o) => o.m2 >= 50);
const apart = pairs.filter((o) => groupOf[o.a] !== groupOf[o.b]);
for (const o of apart) console.log(`not joined: ${o.a} and ${o.b} drove ${o.m2} m^2 together`);
const largest = {};
for (const o of overlaps(report)) {
  largest[o.a] = Math.max(largest[o.a] ?? 0, o.m2);
  largest[o.b] = Math.max(largest[o.b] ?? 0, o.m2);
}
const alone = report.merge.groups.filter((g) => g.robots.length === 1).map((g) => g.robots[0]);
const worst = (report.merge.errors ?? []).reduce(
  (w, e) => (e.error_m > w.error_m ? e : w), { error_m: 0, error_deg: 0, robot: '-' });
console.log(JSON.stringify({
  groups: report.merge.groups.map((g) => g.robots.length),
  pairs_over_50m2: pairs.length,
  not_joined: apart.length,
  alone: alone.map((n) => `${n} (largest overlap ${largest[n]} m^2)`),
  worst_transform: `${worst.robot}: ${worst.error_m} m, ${worst.error_deg} deg`,
}));
