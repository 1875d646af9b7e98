// `frames`: run a scenario and write every captured camera frame as PNG,
// with an index, as the thesis's Fraps folder plus its MATLAB log.
//
//   node web/cli.mjs frames SCENARIO.json --out DIR [--duration S] [--seed N]
//
// DIR/index.json lists one entry per frame: robot, index, time (s), odometry
// pose [x, y, theta] (the robot's odometry frame), true pose (world frame,
// for scoring only) and the PNG's file name.
import { mkdir, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { UsageError, parseArgs, openScenario } from './args.mjs';
import { simulate } from './run-loop.mjs';

export const usage = `  node web/cli.mjs frames SCENARIO.json --out DIR [--duration S] [--seed N]
      write every captured camera frame as PNG plus DIR/index.json`;

async function frames(argv, wasm) {
  const { positional, options } = parseArgs(argv, { out: 'value', duration: 'value', seed: 'value' });
  if (positional.length !== 1) throw new UsageError('frames: expected exactly one SCENARIO.json');
  if (!options.out) throw new UsageError('frames: --out DIR is required');
  const lab = await openScenario(positional[0], options, wasm);
  try {
    await mkdir(options.out, { recursive: true });
  } catch (e) {
    throw new UsageError(`cannot create '${options.out}': ${e.code ?? e.message}`);
  }
  await simulate(lab, { progress: false });
  const scenario = lab.scenario();
  const index = [];
  for (const [r, robot] of scenario.robots.entries()) {
    const metas = lab.frames(r);
    for (const m of metas) {
      const file = `${robot.name.replace(/[^\w.-]+/g, '_')}_${String(m.index).padStart(4, '0')}.png`;
      await writeFile(path.join(options.out, file), lab.framePng(r, m.index));
      index.push({ robot: robot.name, index: m.index, time: m.time_s, odometry: m.odometry, truth: m.truth, file });
    }
    process.stderr.write(`${robot.name}: ${metas.length} frames\n`);
  }
  const info = lab.camera();
  await writeFile(
    path.join(options.out, 'index.json'),
    JSON.stringify({ scenario: scenario.name, seed: scenario.seed, camera: info, frames: index }, null, 1) + '\n',
  );
  process.stderr.write(`wrote ${index.length} frames and index.json to ${options.out}\n`);
  return 0;
}

export const commands = { frames };
