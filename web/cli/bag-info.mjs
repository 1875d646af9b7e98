// The `bag-info` command: what a ROS bag holds (ROS 1 `.bag`, MCAP, rosbag2
// `.db3` or folder), as `ros2 bag info` prints it: its files, size, storage,
// duration, messages, compression, and each topic's type, count and
// encoding; then what `run-log` would pick from it and why. Reads the bag
// with web/cli/bag-read.mjs; the reading is crate/src/formats/bag/.
import { performance } from 'node:perf_hooks';
import { LogReplay } from '../log-replay.js';
import { readBag } from './bag-read.mjs';
import { parseArgs, UsageError, wasmCall } from './args.mjs';

export const usage = `  node web/cli.mjs bag-info BAG [--json]
      what a ROS bag holds (.bag, .mcap, .db3 or a rosbag2 folder): topics, types,
      counts, duration, compression, and what run-log would pick from it`;

const kib = (n) => (n < 1 << 20 ? `${(n / 1024).toFixed(1)} KiB` : `${(n / (1 << 20)).toFixed(1)} MiB`);

/** What run-log would pick by default, or why it could not. */
function picks(bag) {
  try {
    const replay = bag.replay(LogReplay);
    const picked = replay.picked();
    replay.free();
    return picked;
  } catch (e) {
    return { error: e.message };
  }
}

function text(info, picked) {
  const lines = [
    `Files:             ${info.files.join(', ')}`,
    `Bag size:          ${kib(info.bytes)}`,
    `Storage id:        ${info.container}`,
    `Duration:          ${info.duration_s.toFixed(3)}s`,
    `Start:             ${info.start_s === null ? '-' : info.start_s.toFixed(3)} s`,
    `End:               ${info.end_s === null ? '-' : info.end_s.toFixed(3)} s`,
    `Messages:          ${info.messages}`,
    `Chunks:            ${info.chunks}`,
    `Compression:       ${info.compression.join(', ') || 'none'}`,
  ];
  info.topics.forEach((t, k) => {
    lines.push(`${k === 0 ? 'Topic information: ' : '                   '}Topic: ${t.name} | Type: ${t.type} | Count: ${t.count} | Serialization Format: ${t.encoding}`);
  });
  for (const l of info.lost) lines.push(`Lost:              ${l}`);
  if (picked.error) {
    lines.push(`run-log:           cannot replay: ${picked.error}`);
  } else {
    lines.push(`run-log picks:     scans ${picked.scan_topic} (${picked.scan_reason})`);
    lines.push(`                   odometry ${picked.odometry ?? 'none'} (${picked.odometry_reason})`);
    lines.push(`                   laser ${picked.laser_frame || '(no frame)'} on ${picked.base_frame || '(no frame)'} at [${picked.laser_offset.map((v) => v.toFixed(3)).join(', ')}] (${picked.offset_reason})`);
    lines.push(`                   ground truth ${picked.truth_topic ?? 'none'} (${picked.truth_reason})`);
  }
  return lines.join('\n');
}

async function bagInfo(argv, wasm) {
  const { positional, options } = parseArgs(argv, { json: 'flag' });
  if (positional.length !== 1) throw new UsageError('bag-info: expected exactly one BAG (a file or a rosbag2 folder)');
  const t0 = performance.now();
  const { bag, info } = await readBag(wasm, positional[0]);
  const picked = picks(bag);
  const out = { ...info, run_log: picked, timings_ms: { read: performance.now() - t0 } };
  if (options.json) process.stdout.write(JSON.stringify(out) + '\n');
  else console.log(text(info, picked));
  wasmCall(() => bag.free());
  return 0;
}

export const commands = { 'bag-info': bagInfo };
