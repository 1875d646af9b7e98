// The `run-log` command: replay a recorded laser log through the log SLAM
// (scan-to-map matching, pose graph, loop closures) and report every scan's
// final pose (docs/interfaces.md, "Real laser logs: run-log"), over the log
// replay's facade web/log-replay.js. The log is a CARMEN log (FLASER /
// ROBOTLASER1 / RAWLASER1 + ODOM; .log, .clf, gzip-compressed or not) or a
// ROS bag (ROS 1 .bag, MCAP, rosbag2 .db3 or folder; read in pieces by
// web/cli/bag-read.mjs), told apart by the file's first bytes.
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { LogReplay } from '../log-replay.js';
import { isBag, readBag } from './bag-read.mjs';
import { parseArgs, UsageError, wasmCall } from './args.mjs';

export const usage = `  node web/cli.mjs run-log LOG [--json] [--out MAP.yaml] [--from N] [--to M] [--trajectory OUT.tum] [--relations FILE [--check-relations]]
                          [--scan-topic T] [--odom-topic T | --odom-frame NONE] [--truth-topic T]
      replay a CARMEN laser log (.log/.clf, gzip or not) or a ROS bag (.bag, .mcap,
      .db3, or a rosbag2 folder) through SLAM with loop closures; --from/--to pick
      laser records N..M (0-based); --out writes the map as ROS map_server PGM + YAML
      and a PNG; --trajectory writes the SLAM poses in TUM format (for evo). For a
      bag: --scan-topic picks the LaserScan topic, --odom-topic the odometry (tf: the
      moving transform of /tf), --odom-frame NONE maps by scan matching alone,
      --truth-topic the ground truth (NONE: none; by default a pose topic named as
      ground truth or from motion capture); --relations
      scores the replay against a benchmark's relation file (Kümmerle et al. 2009: t1 t2 x y
      z roll pitch yaw per line): the report's relations, mean, sd and max of the errors;
      --check-relations also checks each relation against its own two scans and, where
      they pin nothing, the wheel odometry: the report's relation_check`;

/** The SLAM poses as a TUM trajectory: `time x y z qx qy qz qw` per scan. */
function tum(report) {
  const rows = report.scans.map((s) => {
    const [x, y, th] = s.pose;
    return `${s.time.toFixed(6)} ${x} ${y} 0 0 0 ${Math.sin(th / 2)} ${Math.cos(th / 2)}`;
  });
  return `# timestamp x y z qx qy qz qw (run-log: ${report.frame})\n${rows.join('\n')}\n`;
}

/** A CARMEN log's replay, or a bag's replay of the topics `options` pick. */
async function openLog(wasm, file, options) {
  const bagOnly = ['scan-topic', 'odom-topic', 'odom-frame', 'truth-topic'].filter((k) => options[k] !== undefined);
  if (options['odom-frame'] !== undefined && options['odom-frame'].toUpperCase() !== 'NONE') {
    throw new UsageError(`--odom-frame: '${options['odom-frame']}': only NONE (scan matching alone) is taken`);
  }
  if (options['odom-frame'] !== undefined && options['odom-topic'] !== undefined) {
    throw new UsageError('--odom-topic and --odom-frame NONE contradict each other');
  }
  if (await isBag(wasm, file, 'log')) {
    let lastNote = performance.now();
    const { bag } = await readBag(wasm, file, (done, total) => {
      if (!options.json && performance.now() - lastNote > 2000) {
        process.stderr.write(`  read ${(done / (1 << 20)).toFixed(0)} of ${(total / (1 << 20)).toFixed(0)} MiB\n`);
        lastNote = performance.now();
      }
    });
    const noTruth = options['truth-topic']?.toUpperCase() === 'NONE';
    const picks = {
      scan_topic: options['scan-topic'],
      odom_topic: options['odom-topic'],
      odom_none: options['odom-frame'] !== undefined,
      truth_topic: noTruth ? undefined : options['truth-topic'],
      truth_none: noTruth,
    };
    const replay = wasmCall(() => bag.replay(LogReplay, picks));
    bag.free();
    return replay;
  }
  if (bagOnly.length) throw new UsageError(`--${bagOnly[0]}: '${file}' is a CARMEN log, not a ROS bag`);
  let bytes;
  try {
    bytes = await readFile(file);
  } catch (e) {
    throw new UsageError(`cannot read log '${file}': ${e.code ?? e.message}`);
  }
  return wasmCall(() => LogReplay.open(wasm, bytes));
}

function wholeNumber(name, v) {
  if (v === undefined) return undefined;
  if (!/^\d+$/.test(v) || !Number.isSafeInteger(Number(v))) {
    throw new UsageError(`--${name}: '${v}' is not a whole number from 0`);
  }
  return Number(v);
}

async function runLog(argv, wasm) {
  const { positional, options } = parseArgs(argv, {
    json: 'flag', out: 'value', from: 'value', to: 'value', trajectory: 'value', relations: 'value', 'check-relations': 'flag',
    'scan-topic': 'value', 'odom-topic': 'value', 'odom-frame': 'value', 'truth-topic': 'value',
  });
  if (positional.length !== 1) throw new UsageError('run-log: expected exactly one LOG file');
  if (options.out !== undefined && !/\.ya?ml$/i.test(options.out)) {
    throw new UsageError(`--out: '${options.out}' should end in .yaml`);
  }
  const from = wholeNumber('from', options.from) ?? 0;
  const to = wholeNumber('to', options.to);
  const file = positional[0];
  const t0 = performance.now();
  const replay = await openLog(wasm, file, options);
  if (options.relations !== undefined) {
    let text;
    try {
      text = await readFile(options.relations, 'utf8');
    } catch (e) {
      throw new UsageError(`--relations: cannot read '${options.relations}': ${e.code ?? e.message}`);
    }
    wasmCall(() => replay.setRelations(text));
  }
  if (options['check-relations']) {
    if (options.relations === undefined) throw new UsageError('--check-relations needs --relations FILE');
    replay.setCheckRelations(true);
  }
  const tParsed = performance.now();
  wasmCall(() => replay.setRange(from, to));
  let left = Infinity;
  let lastNote = performance.now();
  while (left > 0) {
    left = replay.step(200);
    if (!options.json && performance.now() - lastNote > 2000) {
      process.stderr.write(`  ${left} scans left\n`);
      lastNote = performance.now();
    }
  }
  const tSlam = performance.now();
  replay.finish();
  const tEnd = performance.now();
  const timings = {
    parse: tParsed - t0, slam: tSlam - tParsed, map: tEnd - tSlam, total: tEnd - t0,
  };
  if (options.out !== undefined) {
    const base = options.out.replace(/\.ya?ml$/i, '');
    const pgmPath = `${base}.pgm`;
    try {
      await writeFile(pgmPath, replay.mapPgm());
      await writeFile(`${base}.png`, replay.mapPng());
      await writeFile(options.out, replay.mapYaml(path.basename(pgmPath)));
    } catch (e) {
      throw new UsageError(`cannot write '${options.out}': ${e.code ?? e.message}`);
    }
  }
  if (options.trajectory !== undefined) {
    try {
      await writeFile(options.trajectory, tum(replay.report(timings)));
    } catch (e) {
      throw new UsageError(`--trajectory: cannot write '${options.trajectory}': ${e.code ?? e.message}`);
    }
  }
  if (options.json) {
    process.stdout.write(replay.reportText(timings) + '\n');
  } else {
    const r = replay.report(timings);
    if (r.bag) {
      const p = r.bag.picked;
      console.log(`${file}: ${r.bag.container}; scans ${p.scan_topic}, odometry ${p.odometry ?? 'none'} (${p.odometry_reason})` +
        (p.truth_topic ? `, ground truth ${p.truth_topic}` : ''));
      for (const l of r.bag.lost) console.log(`  lost: ${l}`);
    }
    if (r.ate_m !== undefined) console.log(`  ATE against the ground truth: ${r.ate_m.toFixed(3)} m over ${r.ate_scans} scans`);
    if (r.relations) {
      const q = r.relations;
      console.log(`  relations: ${q.matched} of ${q.count} matched; translation ${q.trans_m.mean.toFixed(4)} ± ${q.trans_m.sd.toFixed(4)} m (max ${q.trans_m.max.toFixed(3)}), ` +
        `rotation ${q.rot_deg.mean.toFixed(3)} ± ${q.rot_deg.sd.toFixed(3)} deg (max ${q.rot_deg.max.toFixed(2)})`);
    }
    if (r.relation_check) {
      const c = r.relation_check;
      console.log(`  checked: the scans settle ${c.settled} of ${c.checked} relations and contradict ${c.by_scans}; ` +
        `the wheels contradict ${c.by_odometry} where the scans settle none`);
      console.log(`  where the scans settle a pose, the relations lie ${c.relations_vs_scans.trans_m.toFixed(4)} m / ` +
        `${c.relations_vs_scans.rot_deg.toFixed(3)} deg from it, ours ${c.ours_vs_scans.trans_m.toFixed(4)} m / ${c.ours_vs_scans.rot_deg.toFixed(3)} deg`);
      console.log(`  against the ${c.uncontradicted} relations contradicted by neither: translation ${c.trans_m.mean.toFixed(4)} ± ` +
        `${c.trans_m.sd.toFixed(4)} m, rotation ${c.rot_deg.mean.toFixed(3)} ± ${c.rot_deg.sd.toFixed(3)} deg`);
    }
    const m = r.map;
    console.log(`${file}: ${r.scans.length} of ${r.laser_records} laser records replayed (${r.from}..${r.to}), ` +
      `${r.slam.keys} key scans, ${r.loop_closures.length} loop closures`);
    console.log(`  map ${m.width} x ${m.height} cells at ${m.resolution_m} m, origin (${m.origin_m[0].toFixed(2)}, ${m.origin_m[1].toFixed(2)})` +
      (options.out ? ` -> ${options.out}` : ''));
    console.log(`  timings (ms): parse ${timings.parse.toFixed(0)}, slam ${timings.slam.toFixed(0)}, ` +
      `map ${timings.map.toFixed(0)}, total ${timings.total.toFixed(0)}`);
  }
  return 0;
}

export const commands = { 'run-log': runLog };
