// A CARMEN log replayed off the page's main thread (issue 21, the page).
//
// A module Web Worker that loads the same wasm build as the page and holds
// one `LogReplay` (crate/src/bindings/logs.rs): the page opens a log here,
// asks for a few scans at a time (its play, step and speed), and gets back
// how far the replay is and how many loops it has closed; the worker draws
// the replay (log-draw.js) into the page's canvas, handed over once with
// transferControlToOffscreen: the map as it grows (redrawn from the scans
// so far at their current poses, at most every MAP_EVERY_MS), the
// odometry's path beside SLAM's and each loop closure. At the end it
// settles the pose graph and hands back the map as PGM, PNG and YAML.
// Messages in: `{id, type: 'canvas' | 'open' | 'step' | 'finish', ...}`;
// out: `{id, ok, ...}` or `{id, ok: false, error}`.

import init, * as wasm from '../../pkg/slamlab.js';
import { drawReplay, mapPicture } from './log-draw.js';

const ready = init();
const MAP_EVERY_MS = 400;
let replay = null;
let canvas = null;
let picture = null;
let mapAt = -Infinity;
let view = null;

function message(e) {
  return e instanceof Error ? e.message : String(e);
}

/** Redraws the map from the scans so far, if it is time (or `force`). */
async function refreshMap(force) {
  const now = performance.now();
  if (!force && now - mapAt < MAP_EVERY_MS) return;
  if (!replay.drawLive()) return;
  picture = await mapPicture(replay.livePixels(), JSON.parse(replay.liveInfoJson()));
  mapAt = performance.now();
}

async function step({ n, size }) {
  const left = replay.step(n);
  view = JSON.parse(replay.viewJson());
  await refreshMap(left === 0);
  if (canvas) drawReplay(canvas, size, picture, view);
  return { done: view.done, total: view.total, closures: view.closures.length, left };
}

function finish() {
  const t0 = performance.now();
  replay.finish();
  const report = JSON.parse(replay.reportJson(JSON.stringify({ finish: performance.now() - t0 })));
  const pgm = replay.mapPgm();
  const png = replay.mapPng();
  const yaml = replay.mapYaml('log-map.pgm');
  const summary = { scans: report.scans.length, closures: report.loop_closures.length, map: report.map };
  return { result: { summary, files: { pgm, png, yaml } }, transfer: [pgm.buffer, png.buffer] };
}

const handlers = {
  canvas: (data) => {
    canvas = data.canvas;
    return {};
  },
  open: (data) => {
    replay?.free();
    replay = new wasm.LogReplay(new Uint8Array(data.bytes));
    picture = null;
    view = null;
    mapAt = -Infinity;
    return { records: replay.laserRecords() };
  },
  step: async (data) => step(data),
  redraw: (data) => {
    if (canvas && view) drawReplay(canvas, data.size, picture, view);
    return {};
  },
};

self.onmessage = async ({ data }) => {
  const { id, type } = data;
  try {
    await ready;
    if (type !== 'canvas' && type !== 'open' && !replay) throw new Error('open a log first');
    if (type === 'finish') {
      const out = finish();
      postMessage({ id, ok: true, ...out.result }, out.transfer);
      return;
    }
    const handler = handlers[type];
    if (!handler) throw new Error(`unknown request '${type}'`);
    postMessage({ id, ok: true, ...(await handler(data)) });
  } catch (e) {
    postMessage({ id, ok: false, error: message(e) });
  }
};
