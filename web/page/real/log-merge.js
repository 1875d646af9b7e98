// Several robots' log maps joined by the automatic merge (issue 21, item 3).
//
// Two or more logs, or one log cut into stretches of its laser records,
// are replayed as robots of their own (log-worker.js). Logs carry no
// camera, so what can join them is the maps' own evidence: each robot's
// finished map goes to the saved-maps merge of `merge-maps`
// (web/saved-maps.js over crate/src/merge/saved/mod.rs: wall-surface
// points, rotations from Hough spectra, coarse correlation and refinement,
// then a verdict on the agreement) exactly as a saved ROS map would, PGM
// and YAML.
//
// Frames: a replay draws its map in the log's own odometry frame, the
// stretch's first scan at its odometry pose `s` (docs/interfaces.md,
// run-log). A robot knows nothing of where another started, so each map
// is handed to the merge in its robot's own frame, the first scan at the
// origin, as the simulated robots' maps are: the YAML origin (the pose of
// the image's lower-left corner) becomes s⁻¹ ∘ origin. The merge then
// reports each robot's frame in the first robot's frame; for two stretches
// of one log with true start poses T₁ and T₂ the truth is T₁⁻¹ ∘ T₂.
// The images themselves are not turned: the search works in image frames,
// so the frames only change how its answer is written.

import { SavedMaps } from '../../saved-maps.js';
import { compose } from './overlay.js';
import { previewOf } from './preview.js';

/** The inverse of a pose [x, y, theta]: `inverse(p) ∘ p` is the identity. */
export function inverse([x, y, t]) {
  const c = Math.cos(t), s = Math.sin(t);
  return [-c * x - s * y, s * x - c * y, -t];
}

/** Laser records `[from, to]` (inclusive) of each of `cut` near-equal stretches of a log of `records`. */
export function stretches(records, cut) {
  const n = Math.max(1, Math.min(Math.floor(cut) || 1, records));
  return Array.from({ length: n }, (_, k) => [Math.floor((k * records) / n), Math.floor(((k + 1) * records) / n) - 1]);
}

/** A ROS map_server YAML for `image` whose lower-left corner is at `origin` [x, y, yaw]. */
export function robotYaml(image, resolution, origin) {
  const o = origin.map((v) => Number(v.toFixed(6)));
  return `image: ${JSON.stringify(image)}\nresolution: ${resolution}\norigin: [${o.join(', ')}]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n`;
}

/**
 * A finished robot's map for the merge: `{name, yaml, image}` with its
 * YAML origin in the robot's own frame (its first scan at the origin).
 * `robot`: `{name, report, replay}` (report: the run-log report; replay:
 * its LogReplay, web/log-replay.js).
 */
export function robotMap({ name, report, replay }) {
  const start = report.scans[0].pose;
  const m = report.map;
  const origin = compose(inverse(start), [m.origin_m[0], m.origin_m[1], 0]);
  return { name: `${name}.yaml`, yaml: robotYaml(`${name}.pgm`, m.resolution_m, origin), imageName: `${name}.pgm`, image: replay.mapPgm() };
}

/**
 * Merges the finished robots' maps as saved maps (web/saved-maps.js on the
 * wasm-bindgen module `wasm`); `progress(text)` after each pair. Returns
 * `{savedMaps, report, files, groupFiles}`: the maps merged (a SavedMaps),
 * the merge-maps report (with `timings_ms.merge`), each group's merged map
 * (`groupFiles`) and the first group's (`files`, null when no robot joined
 * another). Robots of two buildings make two groups, each joined in the
 * frame of its first robot. The caller frees `savedMaps`.
 */
export function mergeRobots(wasm, robots, progress = () => {}) {
  const savedMaps = SavedMaps.open(wasm);
  try {
    for (const r of robots) {
      const m = robotMap(r);
      savedMaps.addMap(m.name, m.yaml, m.imageName, m.image);
    }
    const t0 = performance.now();
    const report = savedMaps.mergeWithProgress(progress);
    report.timings_ms = { merge: performance.now() - t0 };
    const files = savedMaps.groupFiles(report.merge);
    return { savedMaps, report, files: files.find((f) => f) ?? null, groupFiles: files };
  } catch (e) {
    savedMaps.free();
    throw e;
  }
}

/**
 * Every joined robot's map placed in its group's frame: the transforms of
 * each group of two or more robots (a robot is in one group), or the
 * report's own transforms when it lists no groups.
 */
export function joinedTransforms(merge) {
  const groups = (merge.groups ?? []).filter((g) => g.maps.length > 1);
  return groups.length ? groups.flatMap((g) => g.transforms) : merge.transforms;
}

/**
 * The joined maps for the overlay (overlay.js's `drawPlaced`): `[{map,
 * pose, name}]`, each joined robot's map in its group's frame and in its
 * robot's colour.
 */
export async function placedMaps({ savedMaps, report }, robots) {
  const placed = [];
  for (const t of joinedTransforms(report.merge)) {
    const i = robots.findIndex((r) => `${r.name}.yaml` === t.map);
    if (i < 0) continue;
    const info = savedMaps.mapInfo(i);
    const { thumb, ...preview } = await previewOf(savedMaps.mapPixels(i), info.width, info.height, robots[i].colour);
    thumb.close();
    placed.push({ map: { ...info, preview }, pose: t.pose, name: robots[i].name });
  }
  return placed;
}

/**
 * Each joined robot's SLAM path in its group's frame (its first robot's):
 * `[{name, colour, flat: [x, y, theta, ...]}]`, every pose p of the
 * replay's final poses (the log's frame) as merge ∘ s⁻¹ ∘ p, s the
 * robot's first.
 */
export function mergedPaths(report, robots) {
  const out = [];
  for (const t of joinedTransforms(report.merge)) {
    const r = robots.find((x) => `${x.name}.yaml` === t.map);
    if (!r?.report) continue;
    const to = compose(t.pose, inverse(r.report.scans[0].pose));
    out.push({ name: r.name, colour: r.colour, flat: r.report.scans.flatMap((s) => compose(to, s.pose)) });
  }
  return out;
}
