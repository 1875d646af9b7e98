// SURF commands of the command line (shared/docs/interfaces.md):
//
//   node web/cli.mjs features IMAGE [--json]
//   node web/cli.mjs match IMAGE1 IMAGE2 [--json]
//   node web/cli.mjs bench-surf IMAGE [--runs N] [--pair IMAGE2] [--json]
//
// Each command is `async (args, wasm) => exitCode`, with `args` the words
// after the command name and `wasm` the loaded wasm-bindgen module
// (web/cli/wasm.mjs). Images are read here and decoded inside wasm, so node
// and the page see the same pixels; web/images.js hands the binding's
// documents back, as its text for --json and as objects otherwise. Progress and errors go to stderr; with
// --json the JSON is the only thing on stdout. Bad input: a message and exit 2
// (web/cli/args.mjs's UsageError; an error thrown by the decoder in wasm is
// bad input too, a wasm trap is a bug).
import { readFile } from 'node:fs/promises';
import { performance } from 'node:perf_hooks';
import { UsageError, parseArgs, wasmCall } from './args.mjs';
import * as images from '../images.js';

async function readImage(path) {
  try {
    return new Uint8Array(await readFile(path));
  } catch (e) {
    throw new UsageError(`cannot read ${path}: ${e.code ?? e.message}`);
  }
}

async function features(args, wasm) {
  const { positional, options } = parseArgs(args, { json: 'flag' });
  if (positional.length !== 1) throw new UsageError('features: expected one image');
  const bytes = await readImage(positional[0]);
  if (options.json) {
    process.stdout.write(wasmCall(() => images.featuresText(wasm, bytes)) + '\n');
  } else {
    const r = wasmCall(() => images.features(wasm, bytes));
    console.log(`${positional[0]}: ${r.width} x ${r.height}, ${r.keypoints.length} SURF keypoints`);
    for (const k of r.keypoints.slice(0, 10)) {
      console.log(
        `  x ${k.x.toFixed(2)}  y ${k.y.toFixed(2)}  scale ${k.scale.toFixed(2)}  ` +
          `orientation ${k.orientation.toFixed(3)} rad  laplacian ${k.laplacian > 0 ? '+1' : '-1'}`,
      );
    }
    if (r.keypoints.length > 10) console.log(`  … (--json for all, with descriptors)`);
  }
  return 0;
}

async function match(args, wasm) {
  const { positional, options } = parseArgs(args, { json: 'flag' });
  if (positional.length !== 2) throw new UsageError('match: expected two images');
  const [a, b] = await Promise.all(positional.map(readImage));
  if (options.json) {
    process.stdout.write(wasmCall(() => images.matchText(wasm, a, b)) + '\n');
  } else {
    const r = wasmCall(() => images.match(wasm, a, b));
    console.log(`${r.keypoints[0]} and ${r.keypoints[1]} keypoints, ${r.matches} matches, ${r.inliers} MSAC inliers`);
    if (r.homography) {
      const f = (v) => v.toFixed(5).padStart(12);
      console.log('homography (image 1 pixels -> image 2 pixels):');
      for (const row of r.homography) console.log('  ' + row.map(f).join(' '));
      console.log('matched region (image 1 corners in image 2): ' + r.quad.map(([x, y]) => `(${x.toFixed(1)}, ${y.toFixed(1)})`).join(' '));
      console.log(`shrinkage ${r.shrinkage.toFixed(3)}, shift (${r.shift[0].toFixed(1)}, ${r.shift[1].toFixed(1)}) px`);
    } else {
      console.log('no homography found');
    }
  }
  return 0;
}

function stats(times) {
  const sorted = [...times].sort((x, y) => x - y);
  const mid = sorted.length >> 1;
  const median = sorted.length % 2 ? sorted[mid] : (sorted[mid - 1] + sorted[mid]) / 2;
  return { median, min: sorted[0] };
}

// Times `run()` `runs` times after a short warm-up (the first calls compile
// and grow wasm memory).
function timeRuns(run, runs) {
  for (let i = 0; i < Math.min(3, runs); i++) run();
  const times = [];
  const cpu = [];
  let result = 0;
  for (let i = 0; i < runs; i++) {
    const c0 = process.cpuUsage();
    const t0 = performance.now();
    result = run();
    times.push(performance.now() - t0);
    const c = process.cpuUsage(c0);
    cpu.push((c.user + c.system) / 1000);
  }
  // CPU time of this process: unlike wall time, not inflated when other
  // processes share the cores (a 7 ms run preempted once takes 11 ms wall).
  const c = stats(cpu);
  return { ...stats(times), cpuMedian: c.median, cpuMin: c.min, result };
}

async function benchSurf(args, wasm) {
  const { positional, options } = parseArgs(args, { json: 'flag', runs: 'value', pair: 'value' });
  if (positional.length !== 1) throw new UsageError('bench-surf: expected one image');
  const runs = options.runs === undefined ? 30 : Number(options.runs);
  if (!Number.isInteger(runs) || runs < 1 || runs > 100000) throw new UsageError('--runs must be a whole number from 1');
  const bytes = await readImage(positional[0]);
  const simd = wasm.surf_simd();
  const bench = wasmCall(() => new wasm.SurfBench(bytes));
  let report;
  try {
    process.stderr.write(`bench-surf: ${bench.width()} x ${bench.height()}, ${runs} runs, ${simd ? 'SIMD128' : 'scalar'} build\n`);
    const t = timeRuns(() => bench.run(), runs);
    report = { median_ms: t.median, min_ms: t.min, keypoints: t.result, simd, cpu_median_ms: t.cpuMedian };
    // Per-stage medians (each stage alone, on the previous stage's output).
    const stages = {};
    for (const [name, fn] of [
      ['integral', () => bench.stage_integral()],
      ['detect', () => bench.stage_detect()],
      ['orientation', () => bench.stage_orientation()],
      ['describe', () => bench.stage_describe()],
    ]) {
      stages[name] = timeRuns(fn, runs).median;
    }
    report.stages_ms = stages;
  } finally {
    bench.free();
  }
  if (options.pair !== undefined) {
    const other = await readImage(options.pair);
    const pair = wasmCall(() => new wasm.SurfMatchBench(bytes, other));
    try {
      const t = timeRuns(() => pair.run(), runs);
      Object.assign(report, {
        match_median_ms: t.median,
        match_min_ms: t.min,
        match_cpu_median_ms: t.cpuMedian,
        inliers: t.result,
      });
    } finally {
      pair.free();
    }
  }
  if (options.json) {
    process.stdout.write(JSON.stringify(report) + '\n');
  } else {
    console.log(
      `detect + describe: median ${report.median_ms.toFixed(2)} ms, min ${report.min_ms.toFixed(2)} ms ` +
        `(CPU time median ${report.cpu_median_ms.toFixed(2)} ms), ` +
        `${report.keypoints} keypoints (${simd ? 'SIMD128' : 'scalar'} wasm)`,
    );
    const st = report.stages_ms;
    console.log(
      `  stages (median ms): integral ${st.integral.toFixed(2)}, detect ${st.detect.toFixed(2)}, ` +
        `orientation ${st.orientation.toFixed(2)}, describe ${st.describe.toFixed(2)}`,
    );
    if (report.match_median_ms !== undefined) {
      console.log(`match + MSAC: median ${report.match_median_ms.toFixed(2)} ms, min ${report.match_min_ms.toFixed(2)} ms, ${report.inliers} inliers`);
    }
  }
  return 0;
}

export const usage = `  node web/cli.mjs features IMAGE [--json]
      SURF keypoints of a PNG/JPEG image (x, y, scale, orientation, laplacian, 64-d descriptor)
  node web/cli.mjs match IMAGE1 IMAGE2 [--json]
      ratio-test matches, MSAC inliers, the homography IMAGE1 -> IMAGE2 and the matched quad
  node web/cli.mjs bench-surf IMAGE [--runs N] [--pair IMAGE2] [--json]
      time detect + describe (and matching + MSAC against IMAGE2) inside this wasm build`;

export const commands = { features, match, 'bench-surf': benchSurf };
