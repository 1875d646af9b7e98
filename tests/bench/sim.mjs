// Benchmark of the simulation and renderer in the wasm build, in node
// (BENCHMARKS.md). Run by `./build.sh bench` after `./build.sh build`.
//
// Simulation: each preset for its full duration, all sensors on, as
// robot-steps per second. Rendering: ms per 960 x 720 frame of the thesis
// preset mid-run (laser rays, paths, grid), rendered inside wasm.
import { readFileSync } from 'node:fs';
import { performance } from 'node:perf_hooks';
import { loadWasm } from '../../web/cli/wasm.mjs';

const wasm = await loadWasm();
const median = (v) => v.sort((a, b) => a - b)[Math.floor(v.length / 2)];
const build = wasm.simdEnabled() ? 'SIMD128' : 'scalar';

for (const name of ['thesis', 'office', 'loop', 'maze']) {
  const text = readFileSync(new URL(`../../scenarios/${name}.json`, import.meta.url), 'utf8');
  const rates = [];
  for (let k = 0; k < 5; k++) {
    const lab = new wasm.Lab(text);
    const t0 = performance.now();
    lab.runToEnd();
    const dt = (performance.now() - t0) / 1000;
    const st = JSON.parse(lab.stateJson());
    rates.push((st.steps * st.robots.length) / dt);
    lab.free();
  }
  console.log(`wasm (${build}) simulate ${name.padEnd(7)} ${median(rates).toFixed(0).padStart(9)} robot-steps/s`);
}

const lab = new wasm.Lab(readFileSync(new URL('../../scenarios/thesis.json', import.meta.url), 'utf8'));
lab.fitView(960, 720);
lab.step(1500);
const times = [];
for (let k = 0; k < 200; k++) {
  const t0 = performance.now();
  lab.renderFrame();
  times.push(performance.now() - t0);
}
console.log(`wasm (${build}) render 960x720 ${median(times).toFixed(2)} ms/frame`);

// Camera: ms per grey frame (noise-free view from robot1 at t = 150 s,
// textures already cached), at the default 320 x 240 and at 640 x 480.
for (const [w, h] of [[320, 240], [640, 480]]) {
  const scenario = JSON.parse(readFileSync(new URL('../../scenarios/thesis.json', import.meta.url), 'utf8'));
  scenario.camera = { width: w, height: h };
  const cam = new wasm.Lab(JSON.stringify(scenario));
  cam.step(1500);
  cam.cameraGray(0); // warm the texture cache
  const t = [];
  for (let k = 0; k < 50; k++) {
    const t0 = performance.now();
    cam.cameraGray(0);
    t.push(performance.now() - t0);
  }
  console.log(`wasm (${build}) camera ${w}x${h} ${median(t).toFixed(2)} ms/frame`);
  cam.free();
}

// A whole thesis run with capture (301 frames per robot) against one
// without, per simulated step.
{
  const text = readFileSync(new URL('../../scenarios/thesis.json', import.meta.url), 'utf8');
  const lab = new wasm.Lab(text);
  const t0 = performance.now();
  lab.runToEnd();
  const ms = performance.now() - t0;
  console.log(`wasm (${build}) thesis run, 300 s with cameras: ${ms.toFixed(0)} ms (${(ms / 3000).toFixed(3)} ms per step)`);

  // Captured frames are stored as pose and noise seed and rendered when
  // looked at: ms per stored frame (with its pixel noise), over robot1's
  // frames, once with the wall textures still to generate and once with
  // them cached.
  const n = lab.frameCount(0);
  for (const pass of ['textures generated', 'textures cached']) {
    const t = [];
    for (let k = 0; k < n; k++) {
      const t0 = performance.now();
      lab.frameGray(0, k);
      t.push(performance.now() - t0);
    }
    console.log(`wasm (${build}) stored frame 320x240 (${pass}): ${median(t).toFixed(2)} ms/frame median over ${n}`);
  }
  lab.free();
}
