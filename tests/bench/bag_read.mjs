// How fast a ROS bag is read and its messages decoded, in node with the
// wasm build (BENCHMARKS.md): the bag is read from disk in 8 MiB pieces and
// pushed into a BagFile exactly as `run-log` does (web/cli/bag-read.mjs),
// up to `finish()`, by which time every LaserScan, Odometry and tf message
// has been decoded. Several runs in one process; prints each run and the
// minimum and median. tests/bench/bag_read_rosbags.py does the same with
// the Python `rosbags` library, for a side-by-side figure.
//
//   node tests/bench/bag_read.mjs [BAG] [--runs N]
//
// BAG defaults to bags/freiburg/intel.bag under ../shared/data (or
// $SLAMLAB_DATA). Needs `./build.sh build`.
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath } from 'node:url';
import { loadWasm } from '../../web/cli/wasm.mjs';
import { readBag } from '../../web/cli/bag-read.mjs';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const data = process.env.SLAMLAB_DATA ?? path.join(root, '..', 'shared', 'data');

const args = process.argv.slice(2);
let runs = 5;
let bagPath = path.join(data, 'bags', 'freiburg', 'intel.bag');
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--runs') runs = Number(args[++i]);
  else bagPath = args[i];
}
if (!Number.isInteger(runs) || runs < 1) throw new Error('--runs: a whole number from 1');

const wasm = await loadWasm();
const DECODED = new Set(['sensor_msgs/LaserScan', 'nav_msgs/Odometry']);
const times = [];
let decoded = 0;
for (let k = 0; k < runs; k++) {
  const t0 = performance.now();
  const { bag, info } = await readBag(wasm, bagPath);
  const dt = performance.now() - t0;
  bag.free();
  times.push(dt);
  decoded = info.topics.filter((t) => DECODED.has(t.type)).reduce((a, t) => a + t.count, 0);
  console.log(`run ${k + 1}: ${dt.toFixed(0)} ms (${info.messages} messages, ${decoded} LaserScan + Odometry)`);
}
times.sort((a, b) => a - b);
const median = times[Math.floor(times.length / 2)];
console.log(`${path.basename(bagPath)}: wasm (${wasm.simdEnabled() ? 'SIMD128' : 'scalar'}) in node: ` +
  `${decoded} LaserScan + Odometry messages decoded; min ${times[0].toFixed(0)} ms, median ${median.toFixed(0)} ms over ${runs} runs`);
