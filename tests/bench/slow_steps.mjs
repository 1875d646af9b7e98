// The slowest steps of a run in the wasm build, as the page takes them
// (one `Lab.step(1)` at a time), with the wasm memory before and after each
// (issue 22: was a long task of the page a slow step, or something else?).
//
// Usage: node tests/bench/slow_steps.mjs SCENARIO.json [COUNT]
// Needs ./build.sh build (SLAMLAB_PKG=DIR for another build). Prints the
// COUNT (default 12) slowest steps. The native twin is
// `cargo run --release -p slamlab --example run -- SCENARIO.json steps`.
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { performance } from 'node:perf_hooks';
import { pkgDir } from '../../web/cli/wasm.mjs';

const [file, count = '12'] = process.argv.slice(2);
if (!file) {
  console.error('usage: node tests/bench/slow_steps.mjs SCENARIO.json [COUNT]');
  process.exit(2);
}
const dir = pkgDir();
const mod = await import(pathToFileURL(path.join(dir, 'slamlab.js')).href);
const exports = mod.initSync({ module: new WebAssembly.Module(readFileSync(path.join(dir, 'slamlab_bg.wasm'))) });
const lab = new mod.Lab(readFileSync(file, 'utf8'));
const mb = () => Math.round(exports.memory.buffer.byteLength / 2 ** 20);
const steps = [];
for (let n = 1; ; n++) {
  const m0 = mb();
  const t0 = performance.now();
  if (lab.step(1) < 1) break;
  steps.push({ step: n, ms: performance.now() - t0, memory_mb: [m0, mb()] });
}
steps.sort((a, b) => b.ms - a.ms);
for (const s of steps.slice(0, Number(count))) {
  console.log(`step ${s.step}: ${s.ms.toFixed(1)} ms, wasm memory ${s.memory_mb[0]} -> ${s.memory_mb[1]} MB`);
}
