// The `merge-maps` command: merge saved ROS map_server maps (YAML + PGM/PNG).
// Node reads the files and hands text and bytes to the saved-maps facade
// (web/saved-maps.js, over crate/src/bindings/maps.rs); the merge itself is
// crate/src/merge/saved/mod.rs.
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { performance } from 'node:perf_hooks';
import { MAX_SAVED_MAPS, SavedMaps, mapImagePath } from '../saved-maps.js';
import { isBag, readBag } from './bag-read.mjs';
import { parseArgs, UsageError, wasmCall } from './args.mjs';

export const usage = `  node web/cli.mjs merge-maps MAP.yaml MAP.yaml [MAP.yaml ...] [--out MERGED.yaml] [--json]
      merge two to sixteen saved ROS map_server maps (YAML + PGM/PNG) offline; with --out,
      write the merged map as PGM + YAML (+ PNG); nothing is written on no_merge. A MAP
      may also be a ROS bag (.bag, .mcap, .db3 or a rosbag2 folder) with a
      nav_msgs/OccupancyGrid topic: /map's last message, or the bag's only map topic`;

/** Reads one map — a YAML and the image it names, or a bag's map topic — into `maps` (a SavedMaps); returns its index. */
async function readMap(maps, file, wasm) {
  if (await isBag(wasm, file, 'map')) {
    const { bag } = await readBag(wasm, file);
    const index = wasmCall(() => maps.addBagMap(bag));
    bag.free();
    return index;
  }
  let yaml;
  try {
    yaml = await readFile(file, 'utf8');
  } catch (e) {
    throw new UsageError(`${file}: cannot read the map's YAML: ${e.code ?? e.message}`);
  }
  const image = wasmCall(() => mapImagePath(wasm, file, yaml));
  const imagePath = path.resolve(path.dirname(file), image);
  let bytes;
  try {
    bytes = await readFile(imagePath);
  } catch (e) {
    throw new UsageError(`${file}: image: cannot read '${image}' (${imagePath}): ${e.code ?? e.message}`);
  }
  return wasmCall(() => maps.addMap(file, yaml, image, bytes));
}

function describe(report) {
  const m = report.merge;
  const lines = [`merge: ${m.status} (confidence ${m.confidence.toFixed(2)}): ${m.reason}`];
  for (const t of m.transforms) {
    const [x, y, th] = t.pose;
    lines.push(`  ${t.map}: x ${x.toFixed(3)} m, y ${y.toFixed(3)} m, theta ${(th * 180 / Math.PI).toFixed(2)} deg`);
  }
  if (m.unjoined.length) lines.push(`  not joined: ${m.unjoined.join(', ')}`);
  return lines.join('\n');
}

async function writeMerged(maps, out) {
  const base = out.replace(/\.ya?ml$/i, '');
  const pgmPath = `${base}.pgm`;
  const pngPath = `${base}.png`;
  const pgm = wasmCall(() => maps.mergedPgm());
  const png = wasmCall(() => maps.mergedPng());
  const yaml = wasmCall(() => maps.mergedYaml(path.basename(pgmPath)));
  try {
    await writeFile(pgmPath, pgm);
    await writeFile(pngPath, png);
    await writeFile(out, yaml);
  } catch (e) {
    throw new UsageError(`--out: cannot write '${out}': ${e.code ?? e.message}`);
  }
  return [out, pgmPath, pngPath];
}

async function mergeSavedMaps(argv, wasm) {
  const { positional, options } = parseArgs(argv, { out: 'value', json: 'flag' });
  if (positional.length < 2) throw new UsageError('merge-maps: expected two or more MAP.yaml files');
  if (positional.length > MAX_SAVED_MAPS) throw new UsageError(`merge-maps: at most ${MAX_SAVED_MAPS} maps`);
  if (options.out !== undefined && !/\.ya?ml$/i.test(options.out)) {
    throw new UsageError(`--out: '${options.out}' should end in .yaml`);
  }
  const t0 = performance.now();
  const maps = SavedMaps.open(wasm);
  for (const file of positional) {
    const index = await readMap(maps, file, wasm);
    const info = maps.mapInfo(index);
    process.stderr.write(`read ${file}: ${info.width} x ${info.height} cells at ${info.resolution} m\n`);
  }
  const tRead = performance.now();
  const n = positional.length;
  process.stderr.write(`merging ${n} maps (${n * (n - 1) / 2} pairs)...\n`);
  const report = maps.merge();
  const tMerge = performance.now();
  for (const p of report.merge.pairs) process.stderr.write(`  ${p.a} + ${p.b}: ${p.status}: ${p.reason}\n`);
  let written = [];
  if (options.out !== undefined && report.merge.status === 'merged') {
    written = await writeMerged(maps, options.out);
    process.stderr.write(`wrote ${written.join(', ')}\n`);
  } else if (options.out !== undefined) {
    process.stderr.write(`no_merge: nothing written to ${options.out}\n`);
  }
  const tEnd = performance.now();
  report.timings_ms = { read: tRead - t0, merge: tMerge - tRead, write: tEnd - tMerge, total: tEnd - t0 };
  if (options.json) process.stdout.write(JSON.stringify(report) + '\n');
  else console.log(describe(report));
  maps.free();
  return 0;
}

export const commands = { 'merge-maps': mergeSavedMaps };
