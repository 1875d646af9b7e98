// `frames`: run a scenario and write every captured camera frame as PNG,
// with an index, as the thesis's Fraps folder plus its MATLAB log.
//
//   node web/cli.mjs frames SCENARIO.json --out DIR [--duration S] [--seed N]
//
// DIR/index.json lists one entry per frame: robot, index, time (s), odometry
// pose [x, y, theta] (the robot's odometry frame), true pose (world frame,
// for scoring only) and the PNG's file name.
import { readFile, mkdir, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { UsageError, parseArgs } from './args.mjs';

export const usage = `  node web/cli.mjs frames SCENARIO.json --out DIR [--duration S] [--seed N]
      write every captured camera frame as PNG plus DIR/index.json`;

function call(f) {
  try {
    return f();
  } catch (e) {
    if (e instanceof WebAssembly.RuntimeError) throw e;
    throw new UsageError(e.message ?? String(e));
  }
}

async function frames(argv, wasm) {
  const { positional, options } = parseArgs(argv, { out: 'value', duration: 'value', seed: 'value' });
  if (positional.length !== 1) throw new UsageError('frames: expected exactly one SCENARIO.json');
  if (!options.out) throw new UsageError('frames: --out DIR is required');
  let text;
  try {
    text = await readFile(positional[0], 'utf8');
  } catch (e) {
    throw new UsageError(`cannot read scenario '${positional[0]}': ${e.code ?? e.message}`);
  }
  const lab = call(() => new wasm.Lab(text));
  if (options.seed !== undefined) {
    if (!/^\d+$/.test(options.seed) || !Number.isSafeInteger(Number(options.seed))) {
      throw new UsageError(`--seed: '${options.seed}' is not a whole number from 0 to 2^53`);
    }
    call(() => lab.setSeed(Number(options.seed)));
  }
  if (options.duration !== undefined) {
    const d = Number(options.duration);
    if (options.duration.trim() === '' || !Number.isFinite(d)) {
      throw new UsageError(`--duration: '${options.duration}' is not a number of seconds`);
    }
    call(() => lab.setDuration(d));
  }
  const problems = JSON.parse(lab.problemsJson());
  if (problems.length > 0) throw new UsageError(problems[0].text);
  try {
    await mkdir(options.out, { recursive: true });
  } catch (e) {
    throw new UsageError(`cannot create '${options.out}': ${e.code ?? e.message}`);
  }
  call(() => lab.runToEnd());
  const scenario = JSON.parse(lab.scenarioJson());
  const index = [];
  for (const [r, robot] of scenario.robots.entries()) {
    const metas = JSON.parse(lab.framesJson(r));
    for (const m of metas) {
      const file = `${robot.name.replace(/[^\w.-]+/g, '_')}_${String(m.index).padStart(4, '0')}.png`;
      await writeFile(path.join(options.out, file), lab.framePng(r, m.index));
      index.push({ robot: robot.name, index: m.index, time: m.time_s, odometry: m.odometry, truth: m.truth, file });
    }
    process.stderr.write(`${robot.name}: ${metas.length} frames\n`);
  }
  const info = JSON.parse(lab.cameraInfo());
  await writeFile(
    path.join(options.out, 'index.json'),
    JSON.stringify({ scenario: scenario.name, seed: scenario.seed, camera: info, frames: index }, null, 1) + '\n',
  );
  process.stderr.write(`wrote ${index.length} frames and index.json to ${options.out}\n`);
  return 0;
}

export const commands = { frames };
